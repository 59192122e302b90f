//! `tvmd.sim.SimulationBatch`: tvmd-sim's `SimulationBatch`, many teams of one scenario stepped
//! together inside Rust on a worker pool (the GIL released), one call per batch step. The
//! observations come back as `(B, ...)` NumPy arrays; one team's error is its `errors` entry.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use tvmd_sim::sim::{BatchAction, SimOptions, SimulationBatch, TeamStep};
use tvmd_sim::SimError;

use crate::convert::{batch_commands_arg, batch_wrench_arg, shaped, table, Int};
use crate::errors::value_error;
use crate::runs::spec;

/// Many teams of one scenario stepped together inside Rust, one call per batch step.
///
/// `SimulationBatch(scenario="hover", *, count, jobs, ...)` (`Simulation`'s scenario
/// arguments). `reset`, `step_wrench((B, 6))` and `step((B, n, 3))` return a dict of `(B, ...)`
/// arrays (`t`, `position`, `velocity_world`, `angular_velocity`, `rotation`, `true_position`,
/// `reference_position`, `reference_velocity`, `reference_rotation`,
/// `reference_angular_velocity`, `done`, `saturation`
/// (B, n, 3): what the plant clamped off each team's last commands) and `errors` (one message
/// or None per team: a failed team does not stop the others).
#[pyclass(module = "tvmd.sim", name = "SimulationBatch")]
pub(crate) struct PySimulationBatch {
    batch: SimulationBatch,
    n: usize,
    max_thrust: f64,
}

/// A `(3,)` value of a team's step.
type Field = dyn Fn(&TeamStep) -> [f64; 3];

/// A `(3, 3)` value of a team's step.
type Matrix = dyn Fn(&TeamStep) -> nalgebra::Matrix3<f64>;

/// The `(B, ...)` arrays of every team's step of `n` agents (NaN for a team whose step failed).
fn arrays<'py>(
    py: Python<'py>,
    steps: &[Result<TeamStep, SimError>],
    n: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let b = steps.len();
    let nan3 = [f64::NAN; 3];
    let ok = |k: usize| steps.get(k).and_then(|s| s.as_ref().ok());
    let vec3 = |f: &Field| -> Vec<f64> { (0..b).flat_map(|k| ok(k).map_or(nan3, f)).collect() };
    let out = PyDict::new(py);
    let t: Vec<f64> = (0..b)
        .map(|k| ok(k).map_or(f64::NAN, |s| s.observation.t))
        .collect();
    out.set_item("t", shaped(py, t, &[b])?)?;
    let fields: [(&str, &Field); 7] = [
        ("position", &|s| s.observation.state.position.into()),
        ("velocity_world", &|s| s.observation.state.velocity.into()),
        ("angular_velocity", &|s| s.observation.state.omega.into()),
        ("true_position", &|s| s.observation.truth.position.into()),
        ("reference_position", &|s| {
            s.observation.reference.position.into()
        }),
        ("reference_velocity", &|s| {
            s.observation.reference.velocity.into()
        }),
        ("reference_angular_velocity", &|s| {
            s.observation.reference.omega.into()
        }),
    ];
    for (name, f) in fields {
        out.set_item(name, shaped(py, vec3(f), &[b, 3])?)?;
    }
    let matrices: [(&str, &Matrix); 2] = [
        ("rotation", &|s| s.observation.state.rotation),
        ("reference_rotation", &|s| s.observation.reference.rotation),
    ];
    for (name, f) in matrices {
        let values: Vec<f64> = (0..b)
            .flat_map(|k| {
                ok(k).map_or([f64::NAN; 9], |s| {
                    // Row-major: the transpose's column-major storage.
                    let mut rows = [0.0; 9];
                    rows.copy_from_slice(f(s).transpose().as_slice());
                    rows
                })
            })
            .collect();
        out.set_item(name, shaped(py, values, &[b, 3, 3])?)?;
    }
    // (B, n, 3): what the plant clamped off each team's last commands (NaN for a failed team,
    // so the shape holds when every team failed).
    let saturation: Vec<f64> = (0..b)
        .flat_map(|k| {
            let clamped = ok(k).map(|s| s.saturation.as_slice()).unwrap_or_default();
            (0..n).flat_map(move |i| {
                clamped
                    .get(i)
                    .map_or([f64::NAN; 3], |c| [c.eta_x, c.eta_y, c.thrust])
            })
        })
        .collect();
    out.set_item("saturation", shaped(py, saturation, &[b, n, 3])?)?;
    let done: Vec<bool> = (0..b).map(|k| ok(k).is_some_and(|s| s.finished)).collect();
    out.set_item("done", shaped(py, done, &[b])?)?;
    let errors: Vec<Option<String>> = steps
        .iter()
        .map(|s| s.as_ref().err().map(ToString::to_string))
        .collect();
    out.set_item("errors", errors)?;
    Ok(out)
}

impl PySimulationBatch {
    fn flags(&self, active: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<bool>>> {
        active
            .filter(|a| !a.is_none())
            .map(|a| a.extract::<Vec<bool>>())
            .transpose()
    }

    fn fly<'py>(
        &self,
        py: Python<'py>,
        action: BatchAction<'_>,
        active: Option<Vec<bool>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let batch = &self.batch;
        let steps = py
            .detach(|| batch.step(action, active.as_deref()))
            .map_err(value_error)?;
        arrays(py, &steps, self.n)
    }
}

#[pymethods]
impl PySimulationBatch {
    #[new]
    #[pyo3(signature = (scenario = None, *, count, jobs = None, toml = None, team = None, relaxation = None, allocator = None, precision = None, null_space = None, law = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scenario: Option<&Bound<'_, PyAny>>,
        count: Int,
        jobs: Option<Int>,
        toml: Option<String>,
        team: Option<&Bound<'_, PyAny>>,
        relaxation: Option<f64>,
        allocator: Option<String>,
        precision: Option<String>,
        null_space: Option<String>,
        law: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let teams = count.to("count", 1, 1 << 20)?;
        let jobs = jobs.map(|j| j.to("jobs", 1, 1024)).transpose()?;
        let spec = spec(
            py,
            scenario,
            toml,
            team,
            relaxation,
            allocator,
            precision,
            null_space,
            law,
            None,
            (None, None),
        )?;
        // The batch keeps no samples: it is for many short steps, not for results.
        let options = SimOptions {
            samples: tvmd_sim::sim::SampleRetention::None,
        };
        let batch =
            SimulationBatch::new(&spec.scenario, teams, options, jobs).map_err(value_error)?;
        let (n, max_thrust) = batch
            .with(0, |s| (s.agents(), s.max_thrust()))
            .map_err(value_error)?;
        Ok(Self {
            batch,
            n,
            max_thrust,
        })
    }

    /// Resets the teams `indices` (default all), with optional `seeds`, (m, 3) `positions` and
    /// `attitudes_rpy`; every team's observation.
    #[pyo3(signature = (indices = None, *, seeds = None, positions = None, attitudes_rpy = None))]
    fn reset<'py>(
        &self,
        py: Python<'py>,
        indices: Option<Vec<Int>>,
        seeds: Option<Vec<Int>>,
        positions: Option<&Bound<'py, PyAny>>,
        attitudes_rpy: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let b = self.batch.len();
        let indices: Vec<usize> = match indices {
            Some(i) => i
                .iter()
                .map(|k| k.to("indices", 0, b as i128 - 1))
                .collect::<PyResult<_>>()?,
            None => (0..b).collect(),
        };
        let m = indices.len();
        let mut seen = vec![false; b];
        for &k in &indices {
            if seen.get_mut(k).is_some_and(|s| std::mem::replace(s, true)) {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "`indices` names team {k} twice (each team is reset once, with its own seed \
                     and pose)"
                )));
            }
        }
        let seeds: Option<Vec<u64>> = seeds
            .map(|s| {
                s.iter()
                    .map(|x| x.to("seeds", 0, i128::from(u64::MAX)))
                    .collect::<PyResult<_>>()
            })
            .transpose()?;
        if seeds.as_ref().is_some_and(|s| s.len() != m) {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "`seeds` must have one entry per reset team ({m})"
            )));
        }
        let pose =
            |obj: Option<&Bound<'py, PyAny>>, name: &str| -> PyResult<Option<Vec<[f64; 3]>>> {
                obj.filter(|o| !o.is_none())
                    .map(|o| {
                        let rows = table::<3>(o, name, Some(m))?;
                        crate::convert::check_finite(rows.iter().flat_map(|r| r.iter()), name)?;
                        Ok(rows.into_iter().map(Into::into).collect())
                    })
                    .transpose()
            };
        let positions = pose(positions, "positions")?;
        let attitudes = pose(attitudes_rpy, "attitudes_rpy")?;
        for (j, &k) in indices.iter().enumerate() {
            let seed = seeds.as_ref().and_then(|s| s.get(j).copied());
            let p = positions.as_ref().and_then(|p| p.get(j).copied());
            let a = attitudes.as_ref().and_then(|a| a.get(j).copied());
            self.batch.reset(k, seed, p, a).map_err(value_error)?;
        }
        let all = vec![false; b];
        self.fly(py, BatchAction::Wrench(&vec![[0.0; 6]; b]), Some(all))
    }

    /// Holds each team's (B, 6) body wrench for one controller period (only the `active` teams
    /// step); every team's observation.
    #[pyo3(signature = (wrenches, *, active = None))]
    fn step_wrench<'py>(
        &self,
        py: Python<'py>,
        wrenches: &Bound<'py, PyAny>,
        active: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let w = batch_wrench_arg(wrenches, self.batch.len())?;
        let active = self.flags(active)?;
        self.fly(py, BatchAction::Wrench(&w), active)
    }

    /// Holds each team's (B, n, 3) or (B, n, 4) commands for one controller period (only the
    /// `active` teams step); every team's observation.
    #[pyo3(signature = (commands, *, active = None, rotor_speeds = false))]
    fn step<'py>(
        &self,
        py: Python<'py>,
        commands: &Bound<'py, PyAny>,
        active: Option<&Bound<'py, PyAny>>,
        rotor_speeds: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let b = self.batch.len();
        let c = batch_commands_arg(commands, b, self.n, rotor_speeds, self.max_thrust)?;
        let active = self.flags(active)?;
        self.fly(py, BatchAction::Commands(&c), active)
    }

    /// The number of teams `B`.
    #[getter]
    fn n_teams(&self) -> usize {
        self.batch.len()
    }

    /// Number of agents `n` per team.
    #[getter]
    fn n_agents(&self) -> usize {
        self.n
    }

    /// Team mass `m_C` (kg).
    #[getter]
    fn mass(&self) -> PyResult<f64> {
        self.batch.with(0, |s| s.team().mass()).map_err(value_error)
    }

    /// Largest thrust of one agent `sigma_Tf` (N).
    #[getter]
    fn max_thrust(&self) -> f64 {
        self.max_thrust
    }

    /// The time one step holds its commands (s).
    #[getter]
    fn controller_period(&self) -> PyResult<f64> {
        self.batch
            .with(0, |s| s.scenario().controller_period)
            .map_err(value_error)
    }
}

/// Registers `SimulationBatch` on the `sim` submodule.
pub(crate) fn register(sim: &Bound<'_, PyModule>) -> PyResult<()> {
    sim.add_class::<PySimulationBatch>()
}
