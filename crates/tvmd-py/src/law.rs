//! The control law (eq. 12): `Gains`, `State`, `Reference`, `Plant`, `LawOutput` and the
//! functions `force_request` and `control_wrench` binding `tvmd_core::law`.

use nalgebra::{Matrix3, Matrix6, Vector3};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pyo3::{PyClass, PyTypeInfo};

use tvmd_core::law::{control_wrench as core_control_wrench, force_request as core_force_request};
use tvmd_core::law::{LawOutput, Plant};
use tvmd_core::{Gains, Reference, RigidState};

use crate::convert::{arg, array, check_finite, class_arg, finite, finite_scalar, matrix};
use crate::convert::{matrix3_or_diagonal, opt_arg, shape_error};
use crate::errors::OrRaise;
use crate::record::record;

/// Whether every off-diagonal entry is zero.
fn is_diagonal(m: &Matrix3<f64>) -> bool {
    m.iter().enumerate().all(|(k, x)| k % 4 == 0 || *x == 0.0)
}

/// `K_xi` from a (6,) diagonal or a block-diagonal (6, 6) matrix: `(K_Omega, K_v)`.
fn k_xi_blocks(obj: &Bound<'_, PyAny>) -> PyResult<(Matrix3<f64>, Matrix3<f64>)> {
    let k = match array(obj, "k_xi")?.shape() {
        [6] => Matrix6::from_diagonal(&arg(obj, "k_xi")?),
        [6, 6] => arg(obj, "k_xi")?,
        other => return Err(shape_error("k_xi", "(6,) (diagonal) or (6, 6)", other)),
    };
    let off = k
        .fixed_view::<3, 3>(0, 3)
        .amax()
        .max(k.fixed_view::<3, 3>(3, 0).amax());
    if off != 0.0 {
        return Err(PyValueError::new_err(
            "`k_xi` must be block diagonal, blockdiag(K_Omega, K_v): its off-diagonal 3x3 blocks must be zero",
        ));
    }
    Ok((
        k.fixed_view::<3, 3>(0, 0).into(),
        k.fixed_view::<3, 3>(3, 3).into(),
    ))
}

/// `Gains(k_x=[..], ...)` for diagonal gains, else `Gains(<full matrices>)`.
fn gains_repr(g: &Gains<f64>) -> String {
    let d = |m: &Matrix3<f64>| format!("[{}, {}, {}]", m.m11, m.m22, m.m33);
    let ks = [g.k_x(), g.k_r(), g.k_omega(), g.k_v()];
    if ks.iter().all(is_diagonal) {
        let [x, r, o, v] = ks.map(|k| d(&k));
        format!("Gains(k_x={x}, k_r={r}, k_omega={o}, k_v={v})")
    } else {
        "Gains(<full matrices>)".to_string()
    }
}

/// `blockdiag(K_Omega, K_v)`.
fn k_xi(g: &Gains<f64>) -> Matrix6<f64> {
    let mut k = Matrix6::zeros();
    k.fixed_view_mut::<3, 3>(0, 0).copy_from(&g.k_omega());
    k.fixed_view_mut::<3, 3>(3, 3).copy_from(&g.k_v());
    k
}

record! {
    #[doc = include_str!("../docstrings/tvmd.Gains.txt")]
    "Gains" in "tvmd" => PyGains(Gains<f64>) repr gains_repr |py, o| {
        /// `K_x` (3, 3).
        k_x => matrix(py, &o.k_x())?,
        /// `K_R` (3, 3).
        k_r => matrix(py, &o.k_r())?,
        /// `K_Omega` (3, 3).
        k_omega => matrix(py, &o.k_omega())?,
        /// `K_v` (3, 3).
        k_v => matrix(py, &o.k_v())?,
        /// `K_xi` (6, 6).
        k_xi => matrix(py, &k_xi(o))?,
    }
    methods {
        #[new]
        fn new(
            k_x: &Bound<'_, PyAny>,
            k_r: &Bound<'_, PyAny>,
            k_xi: &Bound<'_, PyAny>,
        ) -> PyResult<Self> {
            let k_x = matrix3_or_diagonal(k_x, "k_x")?;
            let k_r = matrix3_or_diagonal(k_r, "k_r")?;
            let (k_omega, k_v) = k_xi_blocks(k_xi)?;
            let inner = Gains::new(k_x, k_r, k_omega, k_v).or_raise()?;
            Ok(Self { inner })
        }

        /// `pickle` support: `Gains(k_x, k_r, k_xi)` of the same matrices.
        #[allow(clippy::type_complexity)]
        fn __reduce__<'py>(
            slf: &Bound<'py, Self>,
        ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>))> {
            let (py, g) = (slf.py(), &slf.get().inner);
            let args = (matrix(py, &g.k_x())?, matrix(py, &g.k_r())?, matrix(py, &k_xi(g))?);
            Ok((slf.get_type().into_any(), args))
        }

        /// The paper's gains.
        #[staticmethod]
        fn paper() -> Self {
            Self {
                inner: Gains::paper(),
            }
        }
    }
}

/// The gains argument: `None` (the paper's) or a `Gains`.
pub(crate) fn gains_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Gains<f64>> {
    match obj.filter(|o| !o.is_none()) {
        None => Ok(Gains::paper()),
        Some(o) => class_arg::<PyGains>(o, "gains").map(|g| g.get().inner),
    }
}

/// `obj` if it is a `T` (`State` / `Reference`), else `T(**obj)` for a dict `obj` of known
/// keys with a `position`.
fn record_arg<'py, T: PyClass + PyTypeInfo>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    keys: &[&str],
) -> PyResult<Bound<'py, T>> {
    if let Ok(record) = obj.cast::<T>() {
        return Ok(record.clone());
    }
    let keys_list = keys.join(", ");
    let dict = obj.cast::<PyDict>().map_err(|_| {
        let class = T::NAME;
        PyTypeError::new_err(format!(
            "`{what}` must be a tvmd.{class} or a dict with keys {keys_list}"
        ))
    })?;
    for key in dict.keys() {
        let key: String = key
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("`{what}` keys must be strings")))?;
        if !keys.contains(&key.as_str()) {
            return Err(PyValueError::new_err(format!(
                "unknown key '{key}' in `{what}`; expected some of: {keys_list}"
            )));
        }
    }
    if dict.get_item("position")?.is_none() {
        return Err(PyValueError::new_err(format!(
            "`{what}` needs a 'position'"
        )));
    }
    Ok(obj
        .py()
        .get_type::<T>()
        .call((), Some(dict))?
        .cast_into::<T>()?)
}

/// A state argument: a `State` or a dict with the same keys (`position` required).
pub(crate) fn state_arg(obj: &Bound<'_, PyAny>) -> PyResult<RigidState<f64>> {
    let state = record_arg::<PyState>(obj, "state", PyState::FIELD_NAMES)?;
    Ok(state.get().inner)
}

/// A reference argument: a `Reference` or a dict with the same keys (`position` required).
pub(crate) fn reference_arg(obj: &Bound<'_, PyAny>) -> PyResult<Reference<f64>> {
    let reference = record_arg::<PyReference>(obj, "reference", PyReference::FIELD_NAMES)?;
    Ok(reference.get().inner)
}

record! {
    #[doc = include_str!("../docstrings/tvmd.State.txt")]
    "State" in "tvmd" => PyState(RigidState<f64>) |py, o| {
        /// `x` (3,) (m).
        position => matrix(py, &o.position)?,
        /// `R` (3, 3).
        attitude => matrix(py, &o.attitude)?,
        /// `Omega` (3,), body frame (rad/s).
        angular_velocity => matrix(py, &o.angular_velocity)?,
        /// `v` (3,), body frame (m/s).
        velocity => matrix(py, &o.velocity)?,
    }
    methods {
        #[new]
        #[pyo3(signature = (position, attitude = None, angular_velocity = None, velocity = None))]
        fn new(
            position: &Bound<'_, PyAny>,
            attitude: Option<&Bound<'_, PyAny>>,
            angular_velocity: Option<&Bound<'_, PyAny>>,
            velocity: Option<&Bound<'_, PyAny>>,
        ) -> PyResult<Self> {
            let inner = RigidState {
                position: arg(position, "state.position")?,
                attitude: opt_arg(attitude, "state.attitude", Matrix3::identity())?,
                angular_velocity: opt_arg(angular_velocity, "state.angular_velocity", Vector3::zeros())?,
                velocity: opt_arg(velocity, "state.velocity", Vector3::zeros())?,
            };
            Ok(Self { inner })
        }
    }
}

record! {
    #[doc = include_str!("../docstrings/tvmd.Reference.txt")]
    "Reference" in "tvmd" => PyReference(Reference<f64>) |py, o| {
        /// `x_r` (3,).
        position => matrix(py, &o.position)?,
        /// `x_r_dot` (3,).
        velocity => matrix(py, &o.velocity)?,
        /// `x_r_ddot` (3,).
        acceleration => matrix(py, &o.acceleration)?,
        /// `R_r` (3, 3).
        attitude => matrix(py, &o.attitude)?,
        /// `Omega_d` (3,).
        angular_velocity => matrix(py, &o.angular_velocity)?,
        /// `Omega_d_dot` (3,).
        angular_acceleration => matrix(py, &o.angular_acceleration)?,
    }
    methods {
        #[new]
        #[pyo3(signature = (position, velocity = None, acceleration = None, attitude = None, angular_velocity = None, angular_acceleration = None))]
        fn new(
            position: &Bound<'_, PyAny>,
            velocity: Option<&Bound<'_, PyAny>>,
            acceleration: Option<&Bound<'_, PyAny>>,
            attitude: Option<&Bound<'_, PyAny>>,
            angular_velocity: Option<&Bound<'_, PyAny>>,
            angular_acceleration: Option<&Bound<'_, PyAny>>,
        ) -> PyResult<Self> {
            let zero = Vector3::zeros();
            let inner = Reference {
                position: arg(position, "reference.position")?,
                velocity: opt_arg(velocity, "reference.velocity", zero)?,
                acceleration: opt_arg(acceleration, "reference.acceleration", zero)?,
                attitude: opt_arg(attitude, "reference.attitude", Matrix3::identity())?,
                angular_velocity: opt_arg(angular_velocity, "reference.angular_velocity", zero)?,
                angular_acceleration: opt_arg(angular_acceleration, "reference.angular_acceleration", zero)?,
            };
            Ok(Self { inner })
        }

        /// Hover, level, at `position` with zero feed-forward.
        #[staticmethod]
        fn hover(position: &Bound<'_, PyAny>) -> PyResult<Self> {
            let position = arg(position, "reference.position")?;
            Ok(Self {
                inner: Reference::hover(position),
            })
        }
    }
}

impl PyPlant {
    /// A validated plant: `mass > 0`, `inertia` symmetric positive definite, `gravity > 0`,
    /// all finite (the core's checks, raised as `ConfigError`).
    pub(crate) fn create(mass: f64, inertia: Matrix3<f64>, gravity: f64) -> PyResult<Self> {
        finite_scalar(mass, "mass")?;
        check_finite(inertia.iter(), "inertia")?;
        finite_scalar(gravity, "gravity")?;
        Ok(Self {
            inner: Plant::new(mass, inertia, gravity).or_raise()?,
        })
    }
}

/// `Plant(mass=.., inertia=diag[..], gravity=..)`.
fn plant_repr(p: &Plant<f64>) -> String {
    let j = &p.inertia();
    let off = if is_diagonal(j) { "" } else { "+offdiag" };
    let (m, g) = (p.mass(), p.gravity());
    format!(
        "Plant(mass={m}, inertia=diag[{}, {}, {}]{off}, gravity={g})",
        j.m11, j.m22, j.m33
    )
}

record! {
    #[doc = include_str!("../docstrings/tvmd.Plant.txt")]
    "Plant" in "tvmd" => PyPlant(Plant<f64>) repr plant_repr |py, o| {
        /// `m_C` (kg).
        mass => o.mass(),
        /// `J_C` (3, 3) (kg m^2).
        inertia => matrix(py, &o.inertia())?,
        /// `g` (m/s^2).
        gravity => o.gravity(),
    }
    methods {
        #[new]
        #[pyo3(signature = (mass, inertia, gravity = 9.81))]
        fn new(mass: f64, inertia: &Bound<'_, PyAny>, gravity: f64) -> PyResult<Self> {
            Self::create(mass, arg(inertia, "inertia")?, gravity)
        }
    }
}

/// The validated common arguments of the law functions.
type LawArgs = (Plant<f64>, Gains<f64>, RigidState<f64>, Reference<f64>);

/// Reads [`LawArgs`].
fn law_args(
    plant: &Bound<'_, PyAny>,
    gains: &Bound<'_, PyAny>,
    state: &Bound<'_, PyAny>,
    reference: &Bound<'_, PyAny>,
) -> PyResult<LawArgs> {
    let plant = class_arg::<PyPlant>(plant, "plant")?.get().inner;
    let gains = class_arg::<PyGains>(gains, "gains")?.get().inner;
    let (state, reference) = (state_arg(state)?, reference_arg(reference)?);
    state.validate().or_raise()?;
    reference.validate().or_raise()?;
    Ok((plant, gains, state, reference))
}

#[doc = include_str!("../docstrings/tvmd.force_request.txt")]
#[pyfunction]
pub(crate) fn force_request<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    gains: &Bound<'py, PyAny>,
    state: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let (plant, gains, state, reference) = law_args(plant, gains, state, reference)?;
    matrix(py, &core_force_request(&plant, &gains, &state, &reference))
}

#[doc = include_str!("../docstrings/tvmd.control_wrench.txt")]
#[pyfunction]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub(crate) fn control_wrench(
    plant: &Bound<'_, PyAny>,
    gains: &Bound<'_, PyAny>,
    state: &Bound<'_, PyAny>,
    reference: &Bound<'_, PyAny>,
    R_d: &Bound<'_, PyAny>,
    u_fr: &Bound<'_, PyAny>,
    K_f: &Bound<'_, PyAny>,
) -> PyResult<PyLawOutput> {
    let (plant, gains, state, reference) = law_args(plant, gains, state, reference)?;
    let (r_d, u_fr) = (finite(R_d, "R_d")?, finite(u_fr, "u_fr")?);
    let k_f = matrix3_or_diagonal(K_f, "K_f")?;
    check_finite(k_f.iter(), "K_f")?;
    let inner = core_control_wrench(&plant, &gains, &state, &reference, &r_d, &u_fr, &k_f);
    Ok(PyLawOutput { inner })
}

record! {
    /// Everything the control law computes in one period (eq. 12).
    "LawOutput" in "tvmd" => PyLawOutput(LawOutput<f64>) |py, o| {
        /// (3,) `e_x = x - x_r`.
        e_x => matrix(py, &o.e_x)?,
        /// (3,) `e_R`.
        e_r as "e_R" => matrix(py, &o.e_r)?,
        /// (6,) `e_xi = [e_Omega; e_v]`.
        e_xi => matrix(py, &o.e_xi)?,
        /// (6,) `u_r = [u_tau_r; u_fr]`.
        u_r => matrix(py, &o.u_r)?,
        /// (6,) `u_d = blockdiag(I, K_f) u_r`.
        u_d => matrix(py, &o.u_d)?,
        /// `V_R`.
        v_r as "V_R" => o.v_r,
        /// `V_x`.
        v_x as "V_x" => o.v_x,
    }
}

/// Registers the law's classes and functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyGains>()?;
    m.add_class::<PyState>()?;
    m.add_class::<PyReference>()?;
    m.add_class::<PyPlant>()?;
    m.add_class::<PyLawOutput>()?;
    m.add_function(wrap_pyfunction!(force_request, m)?)?;
    m.add_function(wrap_pyfunction!(control_wrench, m)?)?;
    Ok(())
}
