//! The control law (eq. 12): `Gains`, `State`, `Reference`, `Plant`, `LawOutput` and the
//! functions `force_request` and `control_wrench` binding `tvmd_core::law`.

use nalgebra::{Matrix3, Matrix6, Vector3};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use tvmd_core::law::{control_wrench as core_control_wrench, force_request as core_force_request};
use tvmd_core::law::{LawOutput, Plant};
use tvmd_core::{Gains, Reference, RigidState};

use crate::convert::{
    array1, check_finite, class_arg, finite_matrix3, finite_scalar, finite_vector3, float_array,
    matrix3, matrix3_or_diagonal, matrix_array, shape_error, vector3,
};
use crate::errors::OrRaise;
use crate::record::record;

/// Whether every off-diagonal entry is zero.
fn is_diagonal(m: &Matrix3<f64>) -> bool {
    m.iter().enumerate().all(|(k, x)| k % 4 == 0 || *x == 0.0)
}

// ---------------------------------------------------------------------------------------------
// Gains
// ---------------------------------------------------------------------------------------------

/// `K_xi` from a (6,) diagonal or a block-diagonal (6, 6) matrix: `(K_Omega, K_v)`.
fn k_xi_blocks(obj: &Bound<'_, PyAny>) -> PyResult<(Matrix3<f64>, Matrix3<f64>)> {
    let view = float_array(obj, "k_xi")?;
    let array = view.as_array();
    let values: Vec<f64> = array.iter().copied().collect();
    match (array.shape(), values.as_slice()) {
        ([6], [o1, o2, o3, v1, v2, v3]) => Ok((
            Matrix3::from_diagonal(&Vector3::new(*o1, *o2, *o3)),
            Matrix3::from_diagonal(&Vector3::new(*v1, *v2, *v3)),
        )),
        ([6, 6], _) => {
            let k = Matrix6::from_row_iterator(values.iter().copied());
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
                k.fixed_view::<3, 3>(0, 0).into_owned(),
                k.fixed_view::<3, 3>(3, 3).into_owned(),
            ))
        }
        (other, _) => Err(shape_error("k_xi", "(6,) (diagonal) or (6, 6)", other)),
    }
}

/// `Gains(k_x=[..], ...)` for diagonal gains, else `Gains(<full matrices>)`.
fn gains_repr(g: &Gains<f64>) -> String {
    let d = |m: &Matrix3<f64>| format!("[{}, {}, {}]", m.m11, m.m22, m.m33);
    if [g.k_x, g.k_r, g.k_omega, g.k_v].iter().all(is_diagonal) {
        let (x, r, o, v) = (d(&g.k_x), d(&g.k_r), d(&g.k_omega), d(&g.k_v));
        format!("Gains(k_x={x}, k_r={r}, k_omega={o}, k_v={v})")
    } else {
        "Gains(<full matrices>)".to_string()
    }
}

/// `blockdiag(K_Omega, K_v)` (6, 6).
fn k_xi<'py>(py: Python<'py>, g: &Gains<f64>) -> Bound<'py, PyArray2<f64>> {
    let mut k = Matrix6::zeros();
    k.fixed_view_mut::<3, 3>(0, 0).copy_from(&g.k_omega);
    k.fixed_view_mut::<3, 3>(3, 3).copy_from(&g.k_v);
    let values: Vec<f64> = k.transpose().iter().copied().collect();
    crate::convert::dense_array(py, 6, 6, &values)
}

record! {
    /// Gains of the control law (eq. 12): `K_x`, `K_R` and `K_xi = blockdiag(K_Omega, K_v)`
    /// (twist order `[Omega; v]`). Not scaled by mass or inertia.
    ///
    /// Args:
    ///     k_x: `K_x`, (3,) diagonal or (3, 3) symmetric with a positive diagonal.
    ///     k_r: `K_R`, (3,) diagonal or (3, 3).
    ///     k_xi: `K_xi`, (6,) diagonal or a block-diagonal (6, 6) matrix `blockdiag(K_Omega, K_v)`.
    ///
    /// Raises:
    ///     ConfigError: a gain is not finite, not symmetric or has a non-positive diagonal entry.
    ///     ValueError: wrong shapes, or a (6, 6) `k_xi` with non-zero off-diagonal blocks.
    "Gains" in "tvmd" => PyGains(Gains<f64>) repr gains_repr |py, o| {
        /// `K_x` (3, 3).
        k_x => matrix_array(py, &o.k_x),
        /// `K_R` (3, 3).
        k_r => matrix_array(py, &o.k_r),
        /// `K_Omega` (3, 3), the angular-velocity block of `K_xi`.
        k_omega => matrix_array(py, &o.k_omega),
        /// `K_v` (3, 3), the velocity block of `K_xi`.
        k_v => matrix_array(py, &o.k_v),
        /// `K_xi = blockdiag(K_Omega, K_v)` (6, 6).
        k_xi => k_xi(py, o),
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

        /// The paper's gains: `K_x = diag(0.4, 0.4, 1)`, `K_R = diag(12, 12, 1)`,
        /// `K_xi = diag(8, 8, 1.5, 0.8, 0.8, 2)`.
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
    match obj {
        None => Ok(Gains::paper()),
        Some(o) if o.is_none() => Ok(Gains::paper()),
        Some(o) => class_arg::<PyGains>(o, "gains").map(|g| g.get().inner),
    }
}

// ---------------------------------------------------------------------------------------------
// State and reference
// ---------------------------------------------------------------------------------------------

const STATE_KEYS: &[&str] = &["position", "attitude", "angular_velocity", "velocity"];
const REFERENCE_KEYS: &[&str] = &[
    "position",
    "velocity",
    "acceleration",
    "attitude",
    "angular_velocity",
    "angular_acceleration",
];

/// Reads a `State`/`Reference` argument: the class itself, or a dict of its keyword arguments
/// (`position` required, the rest optional), each value named `what.key` in errors.
struct Fields<'py> {
    what: &'static str,
    values: Vec<Option<Bound<'py, PyAny>>>,
    keys: &'static [&'static str],
}

impl<'py> Fields<'py> {
    fn from_dict(
        obj: &Bound<'py, PyAny>,
        what: &'static str,
        keys: &'static [&'static str],
    ) -> PyResult<Self> {
        let dict = obj.cast::<PyDict>().map_err(|_| {
            PyTypeError::new_err(format!(
                "`{what}` must be a tvmd.{} or a dict with keys {}",
                if what == "state" {
                    "State"
                } else {
                    "Reference"
                },
                keys.join(", ")
            ))
        })?;
        for key in dict.keys() {
            let key: String = key
                .extract()
                .map_err(|_| PyTypeError::new_err(format!("`{what}` keys must be strings")))?;
            if !keys.contains(&key.as_str()) {
                return Err(PyValueError::new_err(format!(
                    "unknown key '{key}' in `{what}`; expected some of: {}",
                    keys.join(", ")
                )));
            }
        }
        let values = keys
            .iter()
            .map(|k| dict.get_item(k))
            .collect::<PyResult<Vec<_>>>()?;
        if values.first().is_none_or(Option::is_none) {
            return Err(PyValueError::new_err(format!(
                "`{what}` needs a 'position'"
            )));
        }
        Ok(Fields { what, values, keys })
    }

    /// The 3-vector under `key` (default 0).
    fn vector(&self, key: usize) -> PyResult<Vector3<f64>> {
        match self
            .values
            .get(key)
            .and_then(|v| v.as_ref().filter(|v| !v.is_none()))
        {
            Some(v) => vector3(v, &self.name(key)),
            None => Ok(Vector3::zeros()),
        }
    }

    /// The rotation under `key` (default identity).
    fn rotation(&self, key: usize) -> PyResult<Matrix3<f64>> {
        match self
            .values
            .get(key)
            .and_then(|v| v.as_ref().filter(|v| !v.is_none()))
        {
            Some(v) => matrix3(v, &self.name(key)),
            None => Ok(Matrix3::identity()),
        }
    }

    fn name(&self, key: usize) -> String {
        format!(
            "{}.{}",
            self.what,
            self.keys.get(key).copied().unwrap_or("?")
        )
    }

    fn state(&self) -> PyResult<RigidState<f64>> {
        Ok(RigidState {
            position: self.vector(0)?,
            attitude: self.rotation(1)?,
            angular_velocity: self.vector(2)?,
            velocity: self.vector(3)?,
        })
    }

    fn reference(&self) -> PyResult<Reference<f64>> {
        Ok(Reference {
            position: self.vector(0)?,
            velocity: self.vector(1)?,
            acceleration: self.vector(2)?,
            attitude: self.rotation(3)?,
            angular_velocity: self.vector(4)?,
            angular_acceleration: self.vector(5)?,
        })
    }
}

/// The keyword arguments of a constructor as [`Fields`].
fn args<'py>(
    what: &'static str,
    keys: &'static [&'static str],
    values: &[Option<&Bound<'py, PyAny>>],
) -> Fields<'py> {
    Fields {
        what,
        values: values.iter().map(|v| v.cloned()).collect(),
        keys,
    }
}

/// A state argument: a `State` or a dict with the same keys (`position` required).
pub(crate) fn state_arg(obj: &Bound<'_, PyAny>) -> PyResult<RigidState<f64>> {
    match obj.cast::<PyState>() {
        Ok(state) => Ok(state.get().inner),
        Err(_) => Fields::from_dict(obj, "state", STATE_KEYS)?.state(),
    }
}

/// A reference argument: a `Reference` or a dict with the same keys (`position` required).
pub(crate) fn reference_arg(obj: &Bound<'_, PyAny>) -> PyResult<Reference<f64>> {
    match obj.cast::<PyReference>() {
        Ok(reference) => Ok(reference.get().inner),
        Err(_) => Fields::from_dict(obj, "reference", REFERENCE_KEYS)?.reference(),
    }
}

record! {
    /// The measured state: pose and body-frame twist `xi = [Omega; v]`.
    ///
    /// Args:
    ///     position: `x` (3,), CoM position in the inertial frame (m), z up.
    ///     attitude: `R` (3, 3), body-to-inertial rotation; default identity.
    ///     angular_velocity: `Omega` (3,), body frame (rad/s); default 0.
    ///     velocity: `v` (3,), body frame, `x_dot = R v` (m/s); default 0.
    ///
    /// Wherever a state is expected a dict with these keys is accepted too. Values are not
    /// validated here: `Controller.step` reports NaN/inf or a non-rotation attitude as a
    /// `CycleError`, the law functions as an `InputError`.
    "State" in "tvmd" => PyState(RigidState<f64>) |py, o| {
        /// `x` (3,) (m).
        position => array1(py, o.position.as_slice()),
        /// `R` (3, 3).
        attitude => matrix_array(py, &o.attitude),
        /// `Omega` (3,) (rad/s), body frame.
        angular_velocity => array1(py, o.angular_velocity.as_slice()),
        /// `v` (3,) (m/s), body frame.
        velocity => array1(py, o.velocity.as_slice()),
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
            let values = [Some(position), attitude, angular_velocity, velocity];
            let inner = args("state", STATE_KEYS, &values).state()?;
            Ok(Self { inner })
        }
    }
}

record! {
    /// The reference pose and its derivatives (feed-forward); unknown derivatives are zero.
    ///
    /// Args:
    ///     position: `x_r` (3,) (m).
    ///     velocity: `x_r_dot` (3,), inertial (m/s); default 0.
    ///     acceleration: `x_r_ddot` (3,), inertial (m/s^2); default 0.
    ///     attitude: `R_r` (3, 3), the reference attitude; default identity.
    ///     angular_velocity: `Omega_d` (3,), body frame of the reference (rad/s); default 0.
    ///     angular_acceleration: `Omega_d_dot` (3,) (rad/s^2); default 0.
    ///
    /// Wherever a reference is expected a dict with these keys is accepted too.
    "Reference" in "tvmd" => PyReference(Reference<f64>) |py, o| {
        /// `x_r` (3,).
        position => array1(py, o.position.as_slice()),
        /// `x_r_dot` (3,).
        velocity => array1(py, o.velocity.as_slice()),
        /// `x_r_ddot` (3,).
        acceleration => array1(py, o.acceleration.as_slice()),
        /// `R_r` (3, 3).
        attitude => matrix_array(py, &o.attitude),
        /// `Omega_d` (3,).
        angular_velocity => array1(py, o.angular_velocity.as_slice()),
        /// `Omega_d_dot` (3,).
        angular_acceleration => array1(py, o.angular_acceleration.as_slice()),
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
            let values = [Some(position), velocity, acceleration, attitude, angular_velocity, angular_acceleration];
            let inner = args("reference", REFERENCE_KEYS, &values).reference()?;
            Ok(Self { inner })
        }

        /// Hover, level, at `position` with zero feed-forward.
        #[staticmethod]
        fn hover(position: &Bound<'_, PyAny>) -> PyResult<Self> {
            Ok(Self {
                inner: Reference::hover(vector3(position, "reference.position")?),
            })
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Plant
// ---------------------------------------------------------------------------------------------

impl PyPlant {
    /// A plant of finite parameters.
    pub(crate) fn create(mass: f64, inertia: Matrix3<f64>, gravity: f64) -> PyResult<Self> {
        finite_scalar(mass, "mass")?;
        check_finite(inertia.iter(), "inertia")?;
        finite_scalar(gravity, "gravity")?;
        Ok(Self {
            inner: Plant {
                mass,
                inertia,
                gravity,
            },
        })
    }
}

/// `Plant(mass=.., inertia=diag[..], gravity=..)`.
fn plant_repr(p: &Plant<f64>) -> String {
    let j = &p.inertia;
    let off = if is_diagonal(j) { "" } else { "+offdiag" };
    let (m, g) = (p.mass, p.gravity);
    format!(
        "Plant(mass={m}, inertia=diag[{}, {}, {}]{off}, gravity={g})",
        j.m11, j.m22, j.m33
    )
}

record! {
    /// Rigid-body parameters of the law: `G = blockdiag(J_C, m_C I)` and gravity `g` along `-e_3`
    /// (eqs. 2-3). `team.plant(gravity=9.81)` builds it from a team.
    ///
    /// Args:
    ///     mass: `m_C` (kg).
    ///     inertia: `J_C` (3, 3) (kg m^2).
    ///     gravity: `g` (m/s^2).
    ///
    /// Raises:
    ///     ValueError: NaN/inf values or a wrong shape.
    "Plant" in "tvmd" => PyPlant(Plant<f64>) repr plant_repr |py, o| {
        /// `m_C` (kg).
        mass => o.mass,
        /// `J_C` (3, 3) (kg m^2).
        inertia => matrix_array(py, &o.inertia),
        /// `g` (m/s^2).
        gravity => o.gravity,
    }
    methods {
        #[new]
        #[pyo3(signature = (mass, inertia, gravity = tvmd_core::team::presets::GRAVITY))]
        fn new(mass: f64, inertia: &Bound<'_, PyAny>, gravity: f64) -> PyResult<Self> {
            Self::create(mass, matrix3(inertia, "inertia")?, gravity)
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Law functions
// ---------------------------------------------------------------------------------------------

/// `u_fr`, the force part of `u_r` in the team frame, which does not depend on `R_d`
/// (eq. 12 with `g_C = [0; -m g R^T e_3]`):
/// `u_fr = m R^T x_r_ddot - K_v e_v - R^T K_x e_x + m g R^T e_3`, `e_x = x - x_r`,
/// `e_v = v - R^T x_r_dot`.
///
/// Args:
///     plant: `Plant` (or `team.plant()`).
///     gains: `Gains`.
///     state: `State` or dict.
///     reference: `Reference` or dict.
///
/// Returns:
///     (3,) array.
///
/// Raises:
///     InputError (a ValueError): NaN/inf input or a non-rotation attitude.
#[pyfunction]
pub(crate) fn force_request<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    gains: &Bound<'py, PyAny>,
    state: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let plant = class_arg::<PyPlant>(plant, "plant")?.get();
    let gains = class_arg::<PyGains>(gains, "gains")?.get();
    let state = state_arg(state)?;
    let reference = reference_arg(reference)?;
    state.validate().or_raise()?;
    reference.validate().or_raise()?;
    let u_fr = core_force_request(&plant.inner, &gains.inner, &state, &reference);
    Ok(array1(py, u_fr.as_slice()))
}

/// The torque part of eq. (12) with the planned `R_d`, and the full `u_r`, `u_d`:
/// `e_R = 1/2 (R_d^T R - R^T R_d)^vee`, `e_xi = xi - [R^T R_d Omega_d; R^T x_r_dot]`,
/// `u_tau_r = J xi_dot_dOmega - [J Omega]x Omega_d' - K_Omega e_Omega - K_R e_R`,
/// `u_r = [u_tau_r; u_fr]`, `u_d = blockdiag(I, K_f) u_r`, and the Lyapunov values
/// `V_R = Psi + ||e_Omega||_{K_Omega}`, `Psi = 1/2 tr(K_R (I - R_d^T R))`,
/// `V_x = ||e_x||_{K_x} + ||e_v||_{K_v}` with `||a||_K = 1/2 a^T K a`.
///
/// Args:
///     plant, gains, state, reference: as for `force_request`.
///     R_d: (3, 3) planned attitude (from `AttitudePlanner.plan`).
///     u_fr: (3,) force request (from `force_request`).
///     K_f: (3, 3) force projection `diag(t_eta t_Tf, t_eta t_Tf, t_Tf)`, or its (3,) diagonal.
///
/// Returns:
///     LawOutput(e_x, e_R, e_xi, u_r, u_d, V_R, V_x).
///
/// Raises:
///     InputError / ValueError: NaN/inf input, a non-rotation attitude or wrong shapes.
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
    let plant = class_arg::<PyPlant>(plant, "plant")?.get();
    let gains = class_arg::<PyGains>(gains, "gains")?.get();
    let state = state_arg(state)?;
    let reference = reference_arg(reference)?;
    state.validate().or_raise()?;
    reference.validate().or_raise()?;
    let r_d = finite_matrix3(R_d, "R_d")?;
    let u_fr = finite_vector3(u_fr, "u_fr")?;
    let k_f = matrix3_or_diagonal(K_f, "K_f")?;
    check_finite(k_f.iter(), "K_f")?;
    let out = core_control_wrench(
        &plant.inner,
        &gains.inner,
        &state,
        &reference,
        &r_d,
        &u_fr,
        &k_f,
    );
    Ok(PyLawOutput { inner: out })
}

record! {
    /// Everything the control law computes in one period (eq. 12).
    ///
    /// Attributes:
    ///     e_x: (3,) `x - x_r`.
    ///     e_R: (3,) `1/2 (R_d^T R - R^T R_d)^vee`.
    ///     e_xi: (6,) `xi - xi_d = [e_Omega; e_v]`.
    ///     u_r: (6,) `[u_tau_r; u_fr]`.
    ///     u_d: (6,) `blockdiag(I, K_f) u_r`.
    ///     V_R: `Psi + ||e_Omega||_{K_Omega}`.
    ///     V_x: `||e_x||_{K_x} + ||e_v||_{K_v}`.
    "LawOutput" in "tvmd" => PyLawOutput(LawOutput<f64>) |py, o| {
        /// (3,) `e_x = x - x_r`.
        e_x => array1(py, o.e_x.as_slice()),
        /// (3,) `e_R`.
        e_r as "e_R" => array1(py, o.e_r.as_slice()),
        /// (6,) `e_xi = [e_Omega; e_v]`.
        e_xi => array1(py, o.e_xi.as_slice()),
        /// (6,) `u_r = [u_tau_r; u_fr]`.
        u_r => array1(py, o.u_r.as_slice()),
        /// (6,) `u_d = blockdiag(I, K_f) u_r`.
        u_d => array1(py, o.u_d.as_slice()),
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
