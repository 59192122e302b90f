//! `tvmd.StepOutput`, everything one `Controller.step` computed, and its `NullSpaceReport`;
//! the stages' `LawStage` and `AllocationStage` (`Controller.law_stage`, `Controller.allocate`).

use pyo3::prelude::*;

use tvmd_core::{AllocationStage, ControlOutput, LawStage, NullSpaceReport};

use crate::afs::PyForceProjection;
use crate::allocation::{AllocationData, PyAllocation};
use crate::convert::{commands_array, matrix, CAPACITY};
use crate::law::PyLawOutput;
use crate::planner::PyPlannerResult;
use crate::record::record;
use crate::step_state;

/// One `Controller.step`: the core's output, the agent count and the allocation record.
pub(crate) struct StepData {
    out: Box<ControlOutput<f64, CAPACITY>>,
    n: usize,
    allocation: AllocationData,
}

impl StepData {
    /// The output of one step of a controller of `n` agents and its allocator's record.
    pub(crate) fn new(
        out: ControlOutput<f64, CAPACITY>,
        n: usize,
        allocation: AllocationData,
    ) -> Self {
        Self {
            out: Box::new(out),
            n,
            allocation,
        }
    }
}

record! {
    /// Everything one `Controller.step` computed, nested like the core's `ControlOutput`.
    "StepOutput" in "tvmd" => PyStepOutput(StepData) |py, o| {
        /// The planner's result (eqs. 9-11).
        planner => PyPlannerResult { inner: o.out.planner },
        /// The force projection `K_f` (eqs. 12-13).
        projection => PyForceProjection { inner: o.out.projection },
        /// (3,) `t_Tf R u_fr` (inertial).
        f_r => matrix(py, &o.out.f_r)?,
        /// The control law's output (eq. 12).
        law => PyLawOutput { inner: o.out.law },
        /// The allocation (eqs. 4 and 6).
        allocation => PyAllocation { inner: o.allocation.clone() },
        /// (n, 4) commands, columns `eta_x, eta_y, thrust, omega`.
        commands => commands_array(py, &o.out.commands, o.n)?,
        /// Largest clamp of the command inversion (rad, or relative to the largest thrust).
        command_clamp => o.out.command_clamp,
        /// What the null-space stage changed.
        null_space => PyNullSpaceReport { inner: o.out.null_space },
    }
    methods {
        /// `pickle` support: `StepOutput._restore` of the output's floats (NaN kept), the
        /// agent count, the allocator's name and its report: the same output, bit for bit.
        #[allow(clippy::type_complexity)]
        fn __reduce__<'py>(
            slf: &Bound<'py, Self>,
        ) -> PyResult<(Bound<'py, PyAny>, (Vec<f64>, usize, &'static str, Option<String>))> {
            let restore = slf.get_type().getattr(pyo3::intern!(slf.py(), "_restore"))?;
            let o = &slf.get().inner;
            let (method, report) = o.allocation.method_and_report();
            Ok((restore, (step_state::values(&o.out), o.n, method, report)))
        }

        /// The output of `__reduce__`'s data (`ValueError` if it is not one).
        #[staticmethod]
        fn _restore(values: Vec<f64>, n: usize, method: &str, report: Option<String>) -> PyResult<Self> {
            let out = step_state::output(&values)?;
            let allocation = step_state::allocation(&out, n, method, report)?;
            Ok(Self { inner: StepData::new(out, n, allocation) })
        }
    }
}

record! {
    #[doc = include_str!("../docstrings/tvmd.NullSpaceReport.txt")]
    "NullSpaceReport" in "tvmd" => PyNullSpaceReport(NullSpaceReport<f64>) |py, o| {
        /// The stage ran on this period's allocation.
        ran => o.ran,
        /// Accepted steps (0: the allocator's forces unchanged).
        iterations => o.iterations,
        /// The objective at the allocator's forces.
        objective_before => o.objective_before,
        /// The objective at the returned forces.
        objective_after => o.objective_after,
        /// Smallest normalized margin to the admissible boundary at the allocator's forces.
        margin_before => o.margin_before,
        /// The same at the returned forces.
        margin_after => o.margin_after,
        /// Largest change of one agent's force (N).
        largest_force_change => o.largest_force_change,
        /// `||M f' - M f||`, the wrench the stage moved (round-off).
        wrench_drift => o.wrench_drift,
    }
}

record! {
    /// The law stage of one period (`Controller.law_stage`): its planner, projection, `f_r`,
    /// law, and the body wrench to allocate.
    "LawStage" in "tvmd" => PyLawStage(LawStage<f64>) |py, o| {
        /// The planner's result (eqs. 9-11).
        planner => PyPlannerResult { inner: o.planner },
        /// The force projection `K_f` (eqs. 12-13).
        projection => PyForceProjection { inner: o.projection },
        /// (3,) `t_Tf R u_fr` (inertial).
        f_r => matrix(py, &o.f_r)?,
        /// The control law's output (eq. 12).
        law => PyLawOutput { inner: o.law },
        /// (6,) `u_d = [u_tau; u_f]` (N m, N; body frame): the wrench for `allocate`.
        wrench => matrix(py, &o.law.u_d)?,
    }
}

/// One `Controller.allocate`: the stage's output, the agent count and the allocation record.
pub(crate) struct AllocationStageData {
    stage: Box<AllocationStage<f64, CAPACITY>>,
    n: usize,
    allocation: AllocationData,
}

impl AllocationStageData {
    /// The stage of a controller of `n` agents and its allocator's record.
    pub(crate) fn new(
        stage: AllocationStage<f64, CAPACITY>,
        n: usize,
        allocation: AllocationData,
    ) -> Self {
        Self {
            stage: Box::new(stage),
            n,
            allocation,
        }
    }
}

record! {
    /// The allocation stage of one period (`Controller.allocate`): a body wrench to commands.
    "AllocationStage" in "tvmd" => PyAllocationStage(AllocationStageData) |py, o| {
        /// The allocation (eqs. 4 and 6): forces, `wrench = M f`, `e_f` (the force error),
        /// `wrench_error`, rounds, saturated agents.
        allocation => PyAllocation { inner: o.allocation.clone() },
        /// `||u_tau_d - u_tau||` (N m), the torque the team could not deliver.
        torque_error => o.stage.torque_error,
        /// (n, 4) commands, columns `eta_x, eta_y, thrust, omega`.
        commands => commands_array(py, &o.stage.commands, o.n)?,
        /// Largest clamp of the command inversion (rad, or relative to the largest thrust).
        command_clamp => o.stage.command_clamp,
        /// What the null-space stage changed.
        null_space => PyNullSpaceReport { inner: o.stage.null_space },
    }
}

/// Registers the step's classes.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyStepOutput>()?;
    m.add_class::<PyLawStage>()?;
    m.add_class::<PyAllocationStage>()?;
    m.add_class::<PyNullSpaceReport>()?;
    Ok(())
}
