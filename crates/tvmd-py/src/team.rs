//! `tvmd.Team`: the team configuration `Xi` (`tvmd_core::TeamConfig<f64, 64>`).

use nalgebra::{Matrix3, Vector3};
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use tvmd_core::team::presets;
use tvmd_core::TeamConfig;
use tvmd_core::{AgentLimits, AgentSpec, Arrangement, FailureMask, HoverCapability, Navigator};
use tvmd_plant::AgentBody;
use tvmd_scenario::{LimitsConfig, TeamSpec};

use crate::afs::PyAfs;
use crate::convert::{array, check_finite, count, indices, int_array, matrix, opt_arg};
use crate::convert::{shape_error, shape_str, shaped, table, Int, CAPACITY};
use crate::errors::{ConfigError, OrRaise};
use crate::law::PyPlant;
use crate::record::record;
use crate::team_data::TeamData;

/// A `tvmd.Team` as the simulator's team and limits (`[team]` with explicit agents and
/// `[limits]` of a scenario): the same positions, quarter turns, masses, navigator, gimbal limits
/// and largest thrust. The simulator models agents as point masses without an idle thrust, so a
/// team with agent inertias or a `min_thrust` raises `ValueError`.
pub(crate) fn team_spec(team: &TeamConfig<f64, CAPACITY>) -> PyResult<(TeamSpec, LimitsConfig)> {
    let unsupported = |what: String| {
        PyValueError::new_err(format!(
            "`team`: the simulator cannot fly this tvmd.Team: {what}"
        ))
    };
    if let Some(i) = team
        .agents()
        .iter()
        .position(|a| a.inertia != Matrix3::zeros())
    {
        return Err(unsupported(format!(
            "agent {i} has an inertia (the simulator's agents are point masses)"
        )));
    }
    let limits = team.limits();
    if limits.min_thrust() != 0.0 {
        return Err(unsupported(format!(
            "min_thrust = {} (the simulator's teams idle at zero thrust)",
            limits.min_thrust()
        )));
    }
    let agents = team.agents().iter().map(AgentBody::from).collect();
    // Rows of J_0: the columns of its transpose.
    let j0 = team.navigator().inertia.transpose();
    let row = |r: usize| {
        let c = j0.column(r);
        [c.x, c.y, c.z]
    };
    let spec = TeamSpec {
        preset: None,
        agents: Some(agents),
        navigator_mass: team.navigator().mass,
        navigator_inertia: [row(0), row(1), row(2)],
        ..TeamSpec::default()
    };
    let limits = LimitsConfig {
        sigma_x: limits.sigma_x(),
        sigma_y: limits.sigma_y(),
        max_thrust: Some(limits.max_thrust()),
    };
    Ok((spec, limits))
}

/// Agent specs from the array arguments.
fn agent_specs(
    positions: &Bound<'_, PyAny>,
    quarter_turns: &Bound<'_, PyAny>,
    masses: &Bound<'_, PyAny>,
    agent_inertias: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<AgentSpec<f64>>> {
    let positions = table::<3>(positions, "positions", None)?;
    let n = positions.len();
    let turns = int_array(quarter_turns, "quarter_turns")?;
    if turns.shape() != [n] {
        return Err(shape_error(
            "quarter_turns",
            &shape_str(&[n]),
            turns.shape(),
        ));
    }
    let masses = array(masses, "masses")?;
    let masses: Vec<f64> = match masses.shape() {
        [] => masses.iter().copied().cycle().take(n).collect(),
        [k] if *k == n => masses.iter().copied().collect(),
        other => return Err(shape_error("masses", &format!("({n},) or ()"), other)),
    };
    let inertias = match agent_inertias.filter(|o| !o.is_none()) {
        None => vec![Matrix3::zeros(); n],
        Some(obj) => {
            let a = array(obj, "agent_inertias")?;
            if a.shape() != [n, 3, 3] {
                let expected = shape_str(&[n, 3, 3]);
                return Err(shape_error("agent_inertias", &expected, a.shape()));
            }
            let values: Vec<f64> = a.iter().copied().collect();
            values
                .chunks_exact(9)
                .map(Matrix3::from_row_slice)
                .collect()
        }
    };
    let agents = positions.iter().zip(&turns).zip(&masses).zip(&inertias);
    agents
        .map(|(((p, m), mass), inertia)| {
            let quarter_turns = i32::try_from(*m).map_err(|_| {
                PyValueError::new_err(format!(
                    "`quarter_turns` entry {m} is out of the 32-bit range"
                ))
            })?;
            let mut agent = AgentSpec::new(*p, quarter_turns, *mass);
            agent.inertia = *inertia;
            Ok(agent)
        })
        .collect()
}

/// A validated team from the shared arguments of `Team(...)` and `Team.from_rotor(...)`.
fn team(
    agents: PyResult<Vec<AgentSpec<f64>>>,
    limits: Result<AgentLimits<f64>, tvmd_core::ConfigError>,
    min_thrust: f64,
    navigator_mass: f64,
    navigator_inertia: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyTeam> {
    let agents = agents?;
    let limits = limits
        .and_then(|l| l.with_min_thrust(min_thrust))
        .or_raise()?;
    let inertia = opt_arg(navigator_inertia, "navigator_inertia", Matrix3::zeros())?;
    let navigator = Navigator {
        mass: navigator_mass,
        inertia,
    };
    PyTeam::wrap(TeamConfig::new(&agents, limits, navigator))
}

/// The failure mask of `failed` (None or agent indices), each index checked against `team`.
pub(crate) fn failure_mask(
    team: &TeamConfig<f64, CAPACITY>,
    failed: Option<&Bound<'_, PyAny>>,
) -> PyResult<FailureMask<CAPACITY>> {
    let mut mask = FailureMask::none();
    for index in indices(failed, "failed")? {
        let agent = index
            .get::<usize>()
            .filter(|i| *i < team.len())
            .ok_or_else(|| {
                ConfigError::new_err(format!(
                    "failure mask names agent {index}, which the team does not have"
                ))
            })?;
        mask.set(agent, true).or_raise()?;
    }
    Ok(mask)
}

impl PyTeam {
    fn wrap(team: Result<TeamConfig<f64, CAPACITY>, tvmd_core::ConfigError>) -> PyResult<Self> {
        team.or_raise().map(|inner| Self { inner })
    }
}

fn team_repr(t: &TeamConfig<f64, CAPACITY>) -> String {
    let l = t.limits();
    format!(
        "Team(n={}, arrangement='{}', n_x={}, mass={}, sigma_x={}, sigma_y={}, max_thrust={})",
        t.len(),
        arrangement(t),
        t.n_x(&FailureMask::none()),
        t.mass(),
        l.sigma_x(),
        l.sigma_y(),
        l.max_thrust()
    )
}

fn arrangement(t: &TeamConfig<f64, CAPACITY>) -> &'static str {
    match t.arrangement() {
        Arrangement::Con => "Con",
        Arrangement::Inc => "Inc",
    }
}

record! {
    #[doc = include_str!("../docstrings/tvmd.Team.txt")]
    "Team" in "tvmd" => PyTeam(TeamConfig<f64, CAPACITY>) repr team_repr |py, o| {
        /// The number of agents.
        n => o.len(),
        /// Agents with even `m_i`.
        n_x => o.n_x(&FailureMask::none()),
        /// Agents with odd `m_i`.
        n_y => o.n_y(&FailureMask::none()),
        /// `m_C` (kg).
        mass => o.mass(),
        /// `J_C` (3, 3) (kg m^2).
        inertia => matrix(py, &o.inertia())?,
        /// (n, 3) agent positions `p_i` (m).
        positions => shaped(py, o.agents().iter().flat_map(|a| a.position.iter().copied()).collect(), &[o.len(), 3])?,
        /// (n,) quarter turns `m_i`.
        quarter_turns => PyArray1::from_vec(py, o.agents().iter().map(|a| i64::from(a.quarter_turns)).collect()),
        /// (n,) agent masses (kg).
        masses => PyArray1::from_vec(py, o.agents().iter().map(|a| a.mass).collect()),
        /// "Con" if every `m_i` is even, else "Inc".
        arrangement => arrangement(o),
        /// `sigma_x` (rad).
        sigma_x => o.limits().sigma_x(),
        /// `sigma_y` (rad).
        sigma_y => o.limits().sigma_y(),
        /// `sigma_Tf` (N).
        max_thrust => o.limits().max_thrust(),
        /// The idle thrust (N).
        min_thrust => o.limits().min_thrust(),
        /// `rho d^4 c_l` of eq. (5).
        thrust_coefficient => o.limits().thrust_coefficient(),
        /// `m_0` (kg).
        navigator_mass => o.navigator().mass,
        /// `J_0` (3, 3) (kg m^2).
        navigator_inertia => matrix(py, &o.navigator().inertia)?,
    }
    methods {
    #[new]
    #[pyo3(signature = (positions, quarter_turns, masses, sigma_x, sigma_y, max_thrust, min_thrust = 0.0, navigator_mass = 0.0, navigator_inertia = None, agent_inertias = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        positions: &Bound<'_, PyAny>,
        quarter_turns: &Bound<'_, PyAny>,
        masses: &Bound<'_, PyAny>,
        sigma_x: f64,
        sigma_y: f64,
        max_thrust: f64,
        min_thrust: f64,
        navigator_mass: f64,
        navigator_inertia: Option<&Bound<'_, PyAny>>,
        agent_inertias: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let agents = agent_specs(positions, quarter_turns, masses, agent_inertias);
        let limits = AgentLimits::new(sigma_x, sigma_y, max_thrust);
        team(agents, limits, min_thrust, navigator_mass, navigator_inertia)
    }

    /// A team whose maximum thrust follows from the rotor constants of eq. (5).
    #[staticmethod]
    #[pyo3(signature = (positions, quarter_turns, masses, sigma_x, sigma_y, rho, d, c_l, sigma_omega, min_thrust = 0.0, navigator_mass = 0.0, navigator_inertia = None, agent_inertias = None))]
    #[allow(clippy::too_many_arguments)]
    fn from_rotor(
        positions: &Bound<'_, PyAny>,
        quarter_turns: &Bound<'_, PyAny>,
        masses: &Bound<'_, PyAny>,
        sigma_x: f64,
        sigma_y: f64,
        rho: f64,
        d: f64,
        c_l: f64,
        sigma_omega: f64,
        min_thrust: f64,
        navigator_mass: f64,
        navigator_inertia: Option<&Bound<'_, PyAny>>,
        agent_inertias: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let agents = agent_specs(positions, quarter_turns, masses, agent_inertias);
        let limits = AgentLimits::from_rotor(sigma_x, sigma_y, rho, d, c_l, sigma_omega);
        team(agents, limits, min_thrust, navigator_mass, navigator_inertia)
    }

    /// The paper's simulated team "A4 inc, 1 navigator".
    #[staticmethod]
    fn a4_inc() -> PyResult<Self> {
        Self::wrap(presets::a4_inc())
    }

    /// As `a4_inc()` with every agent aligned: the consistent A4 team.
    #[staticmethod]
    fn a4_con() -> PyResult<Self> {
        Self::wrap(presets::a4_con())
    }

    /// A team of the authors' catalogue by name (`Team.preset_names()`).
    #[staticmethod]
    fn preset(name: &str) -> PyResult<Self> {
        let preset = presets::Preset::from_name(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "unknown preset {name:?}; known: {}",
                Self::preset_names().join(", ")
            ))
        })?;
        Self::wrap(preset.team())
    }

    /// The catalogue's preset names, Con before Inc, by size.
    #[staticmethod]
    fn preset_names() -> Vec<&'static str> {
        presets::Preset::ALL.iter().map(|p| p.name()).collect()
    }

    /// `n` agents of 0.7 kg on a circle of `radius` (m).
    // Python shows a default only if it is a literal: the core's values (the paper's agents)
    // are the defaults, their digits the text signature (the tests compare the two).
    #[staticmethod]
    #[pyo3(
        signature = (n, radius, inconsistent, sigma_x = std::f64::consts::FRAC_PI_6, sigma_y = std::f64::consts::FRAC_PI_4, max_thrust = 2.0 * presets::PAPER_AGENT_MASS * presets::GRAVITY),
        text_signature = "(n, radius, inconsistent, sigma_x=0.5235987755982989, sigma_y=0.7853981633974483, max_thrust=13.734)"
    )]
    fn ring(
        n: Int,
        radius: f64,
        inconsistent: bool,
        sigma_x: f64,
        sigma_y: f64,
        max_thrust: f64,
    ) -> PyResult<Self> {
        let limits = AgentLimits::new(sigma_x, sigma_y, max_thrust).or_raise()?;
        Self::wrap(presets::ring(count(&n, "n")?, radius, inconsistent, limits))
    }

    /// `pickle` support: the team's data, rebuilt by `Team._restore`.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, pyo3::types::PyTuple>)> {
        let restore = slf.get_type().getattr("_restore")?;
        let args = TeamData::of(&slf.get().inner).args();
        Ok((restore, args.into_pyobject(slf.py())?))
    }

    /// The team of `__reduce__`'s data (the same team, bit for bit).
    #[classmethod]
    #[allow(clippy::too_many_arguments)]
    fn _restore(
        _cls: &Bound<'_, pyo3::types::PyType>,
        positions: Vec<[f64; 3]>,
        quarter_turns: Vec<i32>,
        masses: Vec<f64>,
        agent_inertias: Vec<[f64; 9]>,
        limits: (f64, f64, f64, f64, f64),
        navigator_mass: f64,
        navigator_inertia: [f64; 9],
    ) -> PyResult<Self> {
        let data = TeamData {
            positions,
            quarter_turns,
            masses,
            agent_inertias,
            limits,
            navigator_mass,
            navigator_inertia,
        };
        Self::wrap(data.team())
    }

    /// `M(Xi)` (6, 3n) of eq. (4); columns of failed agents are zero.
    #[pyo3(signature = (failed = None))]
    fn effectiveness<'py>(
        &self,
        py: Python<'py>,
        failed: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let mask = failure_mask(&self.inner, failed)?;
        let n = self.inner.len();
        let mut dense = vec![0.0; 18 * n];
        if !self.inner.effectiveness(&mask).write_dense(n, &mut dense) {
            return Err(PyValueError::new_err("internal error: effectiveness buffer size"));
        }
        shaped(py, dense, &[6, 3 * n])
    }

    #[doc = include_str!("../docstrings/tvmd.Team.wrench.txt")]
    #[pyo3(signature = (forces, failed = None))]
    fn wrench<'py>(
        &self,
        py: Python<'py>,
        forces: &Bound<'py, PyAny>,
        failed: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let mask = failure_mask(&self.inner, failed)?;
        let forces = padded_forces(forces, "forces", self.inner.len())?;
        matrix(py, &self.inner.effectiveness(&mask).wrench(&forces))
    }

    /// The AFS approximation (eqs. 7-8) of the working agents.
    #[pyo3(signature = (failed = None))]
    fn afs(&self, failed: Option<&Bound<'_, PyAny>>) -> PyResult<PyAfs> {
        let mask = failure_mask(&self.inner, failed)?;
        Ok(PyAfs::of(self.inner.afs(&mask).or_raise()?, self.inner.limits()))
    }

    /// The rigid-body parameters of the control law.
    #[pyo3(signature = (gravity = 9.81))]
    fn plant(&self, gravity: f64) -> PyResult<PyPlant> {
        PyPlant::create(self.inner.mass(), self.inner.inertia(), gravity)
    }

    #[doc = include_str!("../docstrings/tvmd.Team.hover_capability.txt")]
    #[pyo3(signature = (failed = None, gravity = 9.81))]
    fn hover_capability(
        &self,
        failed: Option<&Bound<'_, PyAny>>,
        gravity: f64,
    ) -> PyResult<PyHoverCapability> {
        let mask = failure_mask(&self.inner, failed)?;
        let inner = self.inner.hover_capability(&mask, gravity).or_raise()?;
        Ok(PyHoverCapability { inner })
    }
    }
}

/// `(n, 3)` finite forces, zero-padded to the capacity.
pub(crate) fn padded_forces(
    obj: &Bound<'_, PyAny>,
    name: &str,
    n: usize,
) -> PyResult<[Vector3<f64>; CAPACITY]> {
    let rows = table::<3>(obj, name, Some(n))?;
    check_finite(rows.iter().flatten(), name)?;
    let mut forces = [Vector3::zeros(); CAPACITY];
    forces.iter_mut().zip(rows).for_each(|(slot, r)| *slot = r);
    Ok(forces)
}

record! {
    #[doc = include_str!("../docstrings/tvmd.HoverCapability.txt")]
    "HoverCapability" in "tvmd" => PyHoverCapability(HoverCapability<f64>) |py, o| {
        /// The hover wrench is strictly inside the working agents' attainable set.
        capable => o.capable,
        /// Smallest normalized slack of any working agent in the certifying allocation.
        margin => o.margin,
        /// The agent whose slack is `margin`, or None.
        limiting_agent => o.limiting_agent,
        /// The bound it is closest to: "max_thrust", "min_thrust", "gimbal_x" or "gimbal_y".
        limit => o.limit.as_str(),
        /// `m_C g` (N).
        weight => o.weight,
    }
}

/// Registers `Team` and its `HoverCapability`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyTeam>()?;
    m.add_class::<PyHoverCapability>()
}
