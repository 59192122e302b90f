//! `tvmd.Team`: the team configuration `Xi` (`tvmd_core::TeamConfig<f64, 64>`).

use nalgebra::{Matrix3, Vector3};
use pyo3::prelude::*;

use numpy::{PyArray1, PyArray2};
use tvmd_core::team::presets;
use tvmd_core::{AgentLimits, AgentSpec, Arrangement, FailureMask, Navigator, TeamConfig};

use crate::afs::PyAfs;
use crate::convert::{
    array1, check_finite, dense_array, float_array, indices, int_array, matrix3, matrix_array,
    rows, rows_array, shape_error, shape_str,
};
use crate::errors::{ConfigError, OrRaise};
use crate::law::PyPlant;
use crate::CAPACITY;

/// The team configuration `Xi = {(p_i, psi_i)}` with agent limits, masses and navigator
/// (paper, "Modeling"; eqs. 3-6), validated. Up to 64 agents.
///
/// Args:
///     positions: (n, 3) agent positions `p_i` in the team CoM frame {C} (m).
///     quarter_turns: (n,) integers `m_i`, the agent yaws `psi_i = m_i pi/2`.
///     masses: (n,) agent masses `m_i` (kg), or one mass for every agent.
///     sigma_x: gimbal limit `sigma_x` of `|eta_x|` (rad), in (0, pi/2] (eq. 6).
///     sigma_y: gimbal limit `sigma_y` of `|eta_y|` (rad), in (0, pi/2] (eq. 6).
///     max_thrust: `sigma_Tf`, the maximum thrust of one agent (N). Rotor speeds are then
///         normalized (`omega = 1` at maximum thrust); see `Team.from_rotor` for eq. (5).
///     min_thrust: idle thrust (N) in [0, max_thrust), the smallest thrust allocated.
///     navigator_mass: `m_0` (kg), >= 0.
///     navigator_inertia: `J_0` (3, 3), symmetric positive semi-definite; default 0.
///     agent_inertias: optional (n, 3, 3) inertias of the agents about their own CoM, in {C}
///         axes (extension of the paper's point-mass model).
///
/// Team mass `m_C = m_0 + sum m_i`, inertia `J_C = J_0 + sum (J_i - m_i [p_i]x [p_i]x)`.
///
/// Raises:
///     ConfigError (a ValueError): the core's validation failed (no agents, more than 64,
///         non-finite values, gimbal limits outside (0, pi/2], non-positive masses or thrust,
///         a bad navigator inertia, or `M(Xi)` not of rank 6).
///     ValueError / TypeError: wrong shapes or dtypes.
#[pyclass(module = "tvmd", name = "Team", frozen)]
pub struct PyTeam {
    pub(crate) inner: TeamConfig<f64, CAPACITY>,
}

/// Agent specs from the array arguments.
fn agent_specs(
    positions: &Bound<'_, PyAny>,
    quarter_turns: &Bound<'_, PyAny>,
    masses: &Bound<'_, PyAny>,
    agent_inertias: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<AgentSpec<f64>>> {
    let positions = rows::<3>(positions, "positions", None)?;
    let n = positions.len();
    let (turns, turn_shape) = int_array(quarter_turns, "quarter_turns")?;
    if turn_shape != [n] {
        return Err(shape_error("quarter_turns", &shape_str(&[n]), &turn_shape));
    }
    let masses = {
        let view = float_array(masses, "masses")?;
        let array = view.as_array();
        match array.shape() {
            [] => vec![array.iter().copied().next().unwrap_or(f64::NAN); n],
            [k] if *k == n => array.iter().copied().collect(),
            other => return Err(shape_error("masses", &format!("({n},) or ()"), other)),
        }
    };
    let inertias: Vec<Matrix3<f64>> = match agent_inertias {
        None => vec![Matrix3::zeros(); n],
        Some(obj) if obj.is_none() => vec![Matrix3::zeros(); n],
        Some(obj) => {
            let view = float_array(obj, "agent_inertias")?;
            let array = view.as_array();
            if array.shape() != [n, 3, 3] {
                return Err(shape_error(
                    "agent_inertias",
                    &shape_str(&[n, 3, 3]),
                    array.shape(),
                ));
            }
            let values: Vec<f64> = array.iter().copied().collect();
            values
                .chunks_exact(9)
                .map(crate::convert::matrix_from_row_major)
                .collect()
        }
    };
    let mut agents = Vec::with_capacity(n);
    for (((p, m), mass), inertia) in positions.iter().zip(&turns).zip(&masses).zip(&inertias) {
        let quarter_turns = i32::try_from(*m).map_err(|_| {
            pyo3::exceptions::PyValueError::new_err(format!(
                "`quarter_turns` entry {m} is out of the 32-bit range"
            ))
        })?;
        let mut agent = AgentSpec::new(Vector3::from(*p), quarter_turns, *mass);
        agent.inertia = *inertia;
        agents.push(agent);
    }
    Ok(agents)
}

/// The navigator from its optional arguments.
fn navigator(mass: f64, inertia: Option<&Bound<'_, PyAny>>) -> PyResult<Navigator<f64>> {
    let inertia = match inertia {
        Some(obj) if !obj.is_none() => matrix3(obj, "navigator_inertia")?,
        _ => Matrix3::zeros(),
    };
    Ok(Navigator { mass, inertia })
}

/// The failure mask of `failed` (None or agent indices), each index checked against `team`.
pub(crate) fn failure_mask(
    team: &TeamConfig<f64, CAPACITY>,
    failed: Option<&Bound<'_, PyAny>>,
) -> PyResult<FailureMask<CAPACITY>> {
    let mut mask = FailureMask::none();
    for index in indices(failed, "failed")? {
        let agent = usize::try_from(index)
            .ok()
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

/// Indices of the failed agents of a mask.
pub(crate) fn failed_list(mask: &FailureMask<CAPACITY>, n: usize) -> Vec<usize> {
    (0..n).filter(|i| mask.is_failed(*i)).collect()
}

impl PyTeam {
    fn wrap(team: Result<TeamConfig<f64, CAPACITY>, tvmd_core::ConfigError>) -> PyResult<Self> {
        team.or_raise().map(|inner| Self { inner })
    }
}

#[pymethods]
impl PyTeam {
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
        let agents = agent_specs(positions, quarter_turns, masses, agent_inertias)?;
        let limits = AgentLimits::new(sigma_x, sigma_y, max_thrust)
            .and_then(|l| l.with_min_thrust(min_thrust))
            .or_raise()?;
        let navigator = navigator(navigator_mass, navigator_inertia)?;
        Self::wrap(TeamConfig::new(&agents, limits, navigator))
    }

    /// A team whose maximum thrust follows from the rotor constants of eq. (5):
    /// `T = rho d^4 c_l omega^2`, `sigma_Tf = T(sigma_omega)`. Rotor speeds `omega` of the
    /// commands are then in rad/s.
    ///
    /// Args:
    ///     positions, quarter_turns, masses, sigma_x, sigma_y: as for `Team(...)`.
    ///     rho: air density (kg/m^3). d: rotor diameter (m). c_l: lift coefficient.
    ///     sigma_omega: maximum rotor speed (rad/s).
    ///     min_thrust, navigator_mass, navigator_inertia, agent_inertias: as for `Team(...)`.
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
        let agents = agent_specs(positions, quarter_turns, masses, agent_inertias)?;
        let limits = AgentLimits::from_rotor(sigma_x, sigma_y, rho, d, c_l, sigma_omega)
            .and_then(|l| l.with_min_thrust(min_thrust))
            .or_raise()?;
        let navigator = navigator(navigator_mass, navigator_inertia)?;
        Self::wrap(TeamConfig::new(&agents, limits, navigator))
    }

    /// The paper's simulated team "A4 inc, 1 navigator": four agents at `(+-a, +-a, 0)`,
    /// `a = 0.5 sqrt(2)/2` m, in the order (+a,+a), (+a,-a), (-a,-a), (-a,+a) with
    /// `psi = [pi/2, pi/2, 0, 0]`; `m_i = 0.7` kg, navigator mass 0, `sigma_x = pi/6`,
    /// `sigma_y = pi/4`, `sigma_Tf = 2 m_i g`.
    #[staticmethod]
    fn a4_inc() -> PyResult<Self> {
        Self::wrap(presets::a4_inc())
    }

    /// As `Team.a4_inc()` with every agent aligned (`psi = 0`): the consistent A4 team.
    #[staticmethod]
    fn a4_con() -> PyResult<Self> {
        Self::wrap(presets::a4_con())
    }

    /// `n` agents of the paper's mass (0.7 kg) on a circle of `radius` (m) in the x-y plane,
    /// agent `i` at phase `2 pi i / n`; every second agent turned a quarter turn when
    /// `inconsistent` (A3..A10-like layouts).
    #[staticmethod]
    #[pyo3(signature = (n, radius, inconsistent, sigma_x = std::f64::consts::FRAC_PI_6, sigma_y = std::f64::consts::FRAC_PI_4, max_thrust = 2.0 * presets::PAPER_AGENT_MASS * presets::GRAVITY))]
    fn ring(
        n: i64,
        radius: f64,
        inconsistent: bool,
        sigma_x: f64,
        sigma_y: f64,
        max_thrust: f64,
    ) -> PyResult<Self> {
        let n = crate::convert::count(n, "n")?;
        let limits = AgentLimits::new(sigma_x, sigma_y, max_thrust).or_raise()?;
        Self::wrap(presets::ring(n, radius, inconsistent, limits))
    }

    /// `n`, the number of agents.
    #[getter]
    fn n(&self) -> usize {
        self.inner.len()
    }

    /// `n_x`: agents with even `m_i` (x gimbal axis along the team's x axis).
    #[getter]
    fn n_x(&self) -> usize {
        self.inner.n_x(&FailureMask::none())
    }

    /// `n_y = n - n_x`: agents with odd `m_i`.
    #[getter]
    fn n_y(&self) -> usize {
        self.inner.n_y(&FailureMask::none())
    }

    /// `m_C = m_0 + sum m_i`, the team mass (kg).
    #[getter]
    fn mass(&self) -> f64 {
        self.inner.mass()
    }

    /// `J_C` (3, 3), the team inertia about its CoM (kg m^2).
    #[getter]
    fn inertia<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_array(py, &self.inner.inertia())
    }

    /// (n, 3) agent positions `p_i` in {C} (m).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<[f64; 3]> = self
            .inner
            .agents()
            .iter()
            .map(|a| [a.position.x, a.position.y, a.position.z])
            .collect();
        rows_array(py, &rows)
    }

    /// (n,) int64 quarter turns `m_i` (`psi_i = m_i pi/2`).
    #[getter]
    fn quarter_turns<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let turns: Vec<i64> = self
            .inner
            .agents()
            .iter()
            .map(|a| i64::from(a.quarter_turns))
            .collect();
        PyArray1::from_vec(py, turns)
    }

    /// (n,) agent masses `m_i` (kg).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let masses: Vec<f64> = self.inner.agents().iter().map(|a| a.mass).collect();
        array1(py, &masses)
    }

    /// "Con" if every `m_i` is even (all gimbal axes aligned with the team's), else "Inc".
    #[getter]
    fn arrangement(&self) -> &'static str {
        match self.inner.arrangement() {
            Arrangement::Con => "Con",
            Arrangement::Inc => "Inc",
        }
    }

    /// `sigma_x` (rad), the limit of `|eta_x|`.
    #[getter]
    fn sigma_x(&self) -> f64 {
        self.inner.limits().sigma_x()
    }

    /// `sigma_y` (rad), the limit of `|eta_y|`.
    #[getter]
    fn sigma_y(&self) -> f64 {
        self.inner.limits().sigma_y()
    }

    /// `sigma_Tf` (N), the maximum thrust of one agent.
    #[getter]
    fn max_thrust(&self) -> f64 {
        self.inner.limits().max_thrust()
    }

    /// The idle thrust (N).
    #[getter]
    fn min_thrust(&self) -> f64 {
        self.inner.limits().min_thrust()
    }

    /// `rho d^4 c_l` of eq. (5) (N s^2/rad^2); equals `max_thrust` for normalized speeds.
    #[getter]
    fn thrust_coefficient(&self) -> f64 {
        self.inner.limits().thrust_coefficient()
    }

    /// `m_0` (kg).
    #[getter]
    fn navigator_mass(&self) -> f64 {
        self.inner.navigator().mass
    }

    /// `J_0` (3, 3) (kg m^2).
    #[getter]
    fn navigator_inertia<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_array(py, &self.inner.navigator().inertia)
    }

    /// `M(Xi)`, the (6, 3n) effectiveness matrix of eq. (4), rows `[torque; force]`: block `i`
    /// is `[[p_i]x R_z(psi_i); R_z(psi_i)]`, so the wrench is `u = M f` for the stacked
    /// agent-frame forces `f = [f_1; ...; f_n]`. Columns of failed agents are zero.
    ///
    /// Args:
    ///     failed: None or an iterable of failed agent indices.
    #[pyo3(signature = (failed = None))]
    fn effectiveness<'py>(
        &self,
        py: Python<'py>,
        failed: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let mask = failure_mask(&self.inner, failed)?;
        let n = self.inner.len();
        let mut dense = vec![0.0; 18 * n];
        if !self.inner.effectiveness(&mask).write_dense(n, &mut dense) {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "internal error: effectiveness buffer size",
            ));
        }
        Ok(dense_array(py, 6, 3 * n, &dense))
    }

    /// `u = M(Xi) f` (eq. 4): the (6,) wrench `[u_tau; u_f]` of the (n, 3) agent-frame forces
    /// `f_i`. Forces of failed agents are ignored.
    ///
    /// Raises:
    ///     ValueError: wrong shape, or NaN/inf forces.
    #[pyo3(signature = (forces, failed = None))]
    fn wrench<'py>(
        &self,
        py: Python<'py>,
        forces: &Bound<'py, PyAny>,
        failed: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let mask = failure_mask(&self.inner, failed)?;
        let forces = padded_forces(forces, "forces", self.inner.len())?;
        let u = self.inner.effectiveness(&mask).wrench(&forces);
        Ok(array1(py, u.as_slice()))
    }

    /// The attainable-force-space approximation (eqs. 7-8) of the working agents.
    ///
    /// Raises:
    ///     ConfigError: every agent failed, or a failure index the team does not have.
    #[pyo3(signature = (failed = None))]
    fn afs(&self, failed: Option<&Bound<'_, PyAny>>) -> PyResult<PyAfs> {
        let mask = failure_mask(&self.inner, failed)?;
        let inner = self.inner.afs(&mask).or_raise()?;
        let limits = self.inner.limits();
        Ok(PyAfs::from_parts(
            inner,
            limits.sigma_x(),
            limits.sigma_y(),
            limits.max_thrust(),
        ))
    }

    /// The rigid-body parameters of the control law: `m_C`, `J_C` and gravity `g`.
    #[pyo3(signature = (gravity = presets::GRAVITY))]
    fn plant(&self, gravity: f64) -> PyResult<PyPlant> {
        PyPlant::create(self.inner.mass(), self.inner.inertia(), gravity)
    }

    fn __repr__(&self) -> String {
        format!(
            "Team(n={}, arrangement='{}', n_x={}, mass={}, sigma_x={}, sigma_y={}, max_thrust={})",
            self.inner.len(),
            self.arrangement(),
            self.n_x(),
            self.inner.mass(),
            self.inner.limits().sigma_x(),
            self.inner.limits().sigma_y(),
            self.inner.limits().max_thrust()
        )
    }
}

/// `(n, 3)` finite forces, zero-padded to the capacity.
pub(crate) fn padded_forces(
    obj: &Bound<'_, PyAny>,
    name: &str,
    n: usize,
) -> PyResult<[Vector3<f64>; CAPACITY]> {
    let rows = rows::<3>(obj, name, Some(n))?;
    check_finite(rows.iter().flatten(), name)?;
    let mut forces = [Vector3::zeros(); CAPACITY];
    for (slot, r) in forces.iter_mut().zip(&rows) {
        *slot = Vector3::from(*r);
    }
    Ok(forces)
}

/// Registers `Team`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyTeam>()
}
