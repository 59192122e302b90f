//! `pickle` of `tvmd.StepOutput`: the core's output as one flat list of floats (every count,
//! flag and status is a small integer, exact in an `f64`; NaN and infinities kept), with the
//! agent count, the allocator's name and its report.

use nalgebra::{Matrix3, Vector3, Vector6};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use tvmd_core::{
    AgentCommand, AnyAllocator, ControlOutput, ForceProjection, LawOutput, NullSpaceReport,
    PlannerOutput, PlannerStatus,
};

use crate::allocation::AllocationData;
use crate::convert::CAPACITY;

/// The floats of one output, in a fixed order.
pub(crate) fn values(o: &ControlOutput<f64, CAPACITY>) -> Vec<f64> {
    let mut v = Vec::with_capacity(64 + 8 * CAPACITY);
    let p = &o.planner;
    v.extend(p.r_d.iter());
    let status = PlannerStatus::ALL.iter().position(|s| *s == p.status);
    v.extend([p.theta, f64::from(p.iterations), status.unwrap_or(0) as f64]);
    v.extend([
        o.projection.force.x,
        o.projection.force.y,
        o.projection.force.z,
    ]);
    v.extend([o.projection.t_tf, o.projection.t_eta]);
    v.extend(o.f_r.iter());
    let l = &o.law;
    for part in [&l.e_x, &l.e_r] {
        v.extend(part.iter());
    }
    for part in [&l.e_xi, &l.u_r, &l.u_d] {
        v.extend(part.iter());
    }
    v.extend([l.v_r, l.v_x]);
    let a = &o.allocation;
    v.extend(a.forces.iter().flat_map(|f| f.iter().copied()));
    v.extend(a.wrench.iter());
    v.extend([a.e_f, a.wrench_error, f64::from(a.rounds), flag(a.fallback)]);
    v.extend(a.saturated.iter().map(|s| flag(*s)));
    let s = &o.null_space;
    v.extend([
        flag(s.ran),
        f64::from(s.iterations),
        s.objective_before,
        s.objective_after,
    ]);
    v.extend([
        s.margin_before,
        s.margin_after,
        s.largest_force_change,
        s.wrench_drift,
    ]);
    v.extend(
        o.commands
            .iter()
            .flat_map(|c| [c.eta_x, c.eta_y, c.thrust, c.omega]),
    );
    v.push(o.command_clamp);
    v
}

fn flag(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// Reads [`values`]' order back.
struct Reader<'a>(core::slice::Iter<'a, f64>);

impl Reader<'_> {
    fn next(&mut self) -> PyResult<f64> {
        self.0.next().copied().ok_or_else(malformed)
    }

    fn count(&mut self) -> PyResult<u32> {
        let x = self.next()?;
        // Exact small integers only: anything else is not a pickled output.
        if x >= 0.0 && x <= f64::from(u32::MAX) && x.fract() == 0.0 {
            Ok(x as u32)
        } else {
            Err(malformed())
        }
    }

    fn flag(&mut self) -> PyResult<bool> {
        match self.count()? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(malformed()),
        }
    }

    fn vector3(&mut self) -> PyResult<Vector3<f64>> {
        Ok(Vector3::new(self.next()?, self.next()?, self.next()?))
    }

    fn vector6(&mut self) -> PyResult<Vector6<f64>> {
        let mut v = Vector6::zeros();
        for x in v.iter_mut() {
            *x = self.next()?;
        }
        Ok(v)
    }
}

fn malformed() -> PyErr {
    PyValueError::new_err("not the state of a pickled tvmd.StepOutput")
}

/// The output of [`values`]; `ValueError` when `values` is not one.
pub(crate) fn output(values: &[f64]) -> PyResult<ControlOutput<f64, CAPACITY>> {
    let mut r = Reader(values.iter());
    let mut r_d = Matrix3::zeros();
    for x in r_d.iter_mut() {
        *x = r.next()?;
    }
    let theta = r.next()?;
    let iterations = r.count()?;
    let status = *PlannerStatus::ALL
        .get(r.count()? as usize)
        .ok_or_else(malformed)?;
    let planner = PlannerOutput {
        r_d,
        theta,
        iterations,
        status,
    };
    let projection = ForceProjection {
        force: r.vector3()?,
        t_tf: r.next()?,
        t_eta: r.next()?,
    };
    let f_r = r.vector3()?;
    let law = LawOutput {
        e_x: r.vector3()?,
        e_r: r.vector3()?,
        e_xi: r.vector6()?,
        u_r: r.vector6()?,
        u_d: r.vector6()?,
        v_r: r.next()?,
        v_x: r.next()?,
    };
    let mut allocation = tvmd_core::Allocation {
        forces: [Vector3::zeros(); CAPACITY],
        wrench: Vector6::zeros(),
        e_f: 0.0,
        wrench_error: 0.0,
        rounds: 0,
        saturated: [false; CAPACITY],
        fallback: false,
    };
    for f in allocation.forces.iter_mut() {
        *f = r.vector3()?;
    }
    allocation.wrench = r.vector6()?;
    allocation.e_f = r.next()?;
    allocation.wrench_error = r.next()?;
    allocation.rounds = r.count()?;
    allocation.fallback = r.flag()?;
    for s in allocation.saturated.iter_mut() {
        *s = r.flag()?;
    }
    let null_space = NullSpaceReport {
        ran: r.flag()?,
        iterations: r.count()?,
        objective_before: r.next()?,
        objective_after: r.next()?,
        margin_before: r.next()?,
        margin_after: r.next()?,
        largest_force_change: r.next()?,
        wrench_drift: r.next()?,
    };
    let mut commands = [AgentCommand {
        eta_x: 0.0,
        eta_y: 0.0,
        thrust: 0.0,
        omega: 0.0,
    }; CAPACITY];
    for c in commands.iter_mut() {
        *c = AgentCommand {
            eta_x: r.next()?,
            eta_y: r.next()?,
            thrust: r.next()?,
            omega: r.next()?,
        };
    }
    let command_clamp = r.next()?;
    if r.0.next().is_some() {
        return Err(malformed());
    }
    Ok(ControlOutput {
        planner,
        projection,
        f_r,
        law,
        allocation,
        null_space,
        commands,
        command_clamp,
    })
}

/// The allocator's name as the library spells it (`ValueError` for another).
pub(crate) fn method(name: &str) -> PyResult<&'static str> {
    AnyAllocator::<f64, CAPACITY>::NAMES
        .iter()
        .find(|m| **m == name)
        .copied()
        .ok_or_else(malformed)
}

/// The allocation record of a restored output.
pub(crate) fn allocation(
    out: &ControlOutput<f64, CAPACITY>,
    n: usize,
    name: &str,
    report: Option<String>,
) -> PyResult<AllocationData> {
    if !(1..=CAPACITY).contains(&n) {
        return Err(malformed());
    }
    Ok(AllocationData::from_parts(
        out.allocation,
        n,
        method(name)?,
        report,
    ))
}
