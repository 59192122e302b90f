//! `tvmd.AttainableForceSpace` (eqs. 7-8), the force projection `K_f` (eqs. 12-13) and the
//! gimbal model (eq. 1 and its inverse), vectorized over NumPy arrays.

use nalgebra::Vector3;
use numpy::ndarray::{ArrayD, IxDyn, Zip};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use tvmd_core::gimbal::thrust_direction as core_thrust_direction;
use tvmd_core::{project_force, AttainableForceSpace, ForceProjection, GimbalCommand};

use crate::convert::{bool_or_array, count, scalar_or_array, scalars, shape_str, shaped, vectors3};
use crate::errors::OrRaise;
use crate::planner::relaxation_arg;
use crate::record::record;

/// A core AFS with the limits it was built from.
#[derive(Clone, Copy)]
pub(crate) struct AfsData {
    pub(crate) afs: AttainableForceSpace<f64>,
    sigma_x: f64,
    sigma_y: f64,
    max_thrust: f64,
}

impl PyAfs {
    /// Wraps a core AFS built with these limits.
    pub(crate) fn from_parts(
        afs: AttainableForceSpace<f64>,
        sigma_x: f64,
        sigma_y: f64,
        max_thrust: f64,
    ) -> Self {
        let inner = AfsData {
            afs,
            sigma_x,
            sigma_y,
            max_thrust,
        };
        Self { inner }
    }
}

fn afs_repr(a: &AfsData) -> String {
    let (n, n_x) = (a.afs.n(), a.afs.n_x());
    let (x, y, t) = (a.sigma_x, a.sigma_y, a.max_thrust);
    format!("AttainableForceSpace(n={n}, n_x={n_x}, sigma_x={x}, sigma_y={y}, max_thrust={t})")
}

record! {
    /// The elliptic-cone approximation of the attainable force space (AFS) of `n` working agents,
    /// `n_x` of them with even quarter turns (eqs. 7-8):
    ///
    /// `u_f in AFS  <=>  u_f^T C(u_fz) u_f <= 1  and  ||u_f|| <= n sigma_Tf`,
    /// `C = diag(1/c_x^2, 1/c_y^2, 0)`,
    /// `c_x(z, s) = g(n_x, s sigma_y, z) + g(n_y, s sigma_x, z)`,
    /// `c_y(z, s) = g(n_x, s sigma_x, z) + g(n_y, s sigma_y, z)`,
    /// `g(n_k, sigma, z) = n_k sigma_Tf` if `sigma >= pi/2`, else `(n_k/n)(1 - delta(n_k)) |z| tan(sigma)`.
    ///
    /// A force with `z <= 0` is outside unless a semi-axis comes from the `sigma >= pi/2` branch;
    /// the thrust bound is closed (`<=`). `s` in (0, 1] is the relaxation of the planner.
    ///
    /// Also available from a team: `team.afs(failed=None)`.
    ///
    /// Raises:
    ///     ConfigError: `n = 0`, `n_x > n`, or invalid limits.
    "AttainableForceSpace" in "tvmd" => PyAfs(AfsData) repr afs_repr |_py, o| {
        /// `n`, the number of working agents.
        n => o.afs.n(),
        /// `n_x`, working agents with even quarter turns.
        n_x => o.afs.n_x(),
        /// `n_y = n - n_x`.
        n_y => o.afs.n() - o.afs.n_x(),
        /// `sigma_x` (rad).
        sigma_x => o.sigma_x,
        /// `sigma_y` (rad).
        sigma_y => o.sigma_y,
        /// `sigma_Tf` (N), the maximum thrust of one agent.
        max_thrust => o.max_thrust,
        /// `n sigma_Tf` (N), the largest attainable force magnitude.
        max_force => o.afs.max_force(),
    }
    methods {
        #[new]
        #[pyo3(signature = (n, n_x, sigma_x, sigma_y, max_thrust))]
        fn new(n: i64, n_x: i64, sigma_x: f64, sigma_y: f64, max_thrust: f64) -> PyResult<Self> {
            let (n, n_x) = (count(n, "n")?, count(n_x, "n_x")?);
            let afs = AttainableForceSpace::new(n, n_x, sigma_x, sigma_y, max_thrust).or_raise()?;
            Ok(Self::from_parts(afs, sigma_x, sigma_y, max_thrust))
        }

        /// The semi-axes `(c_x(z, s), c_y(z, s))` of eq. (8) at height `z`.
        ///
        /// Args:
        ///     z: a float or an array of heights (N).
        ///     relaxation: `s` in (0, 1], default 1 (`s=` is an alias).
        ///
        /// Returns:
        ///     `(c_x, c_y)`: floats for a scalar `z`, else arrays of `z`'s shape.
        #[pyo3(signature = (z, relaxation = None, *, s = None))]
        fn semi_axes<'py>(
            &self,
            py: Python<'py>,
            z: &Bound<'py, PyAny>,
            relaxation: Option<f64>,
            s: Option<f64>,
        ) -> PyResult<Bound<'py, PyTuple>> {
            let s = relaxation_arg(relaxation, s, Some(1.0))?;
            let (values, shape) = scalars(z, "z")?;
            let axes: Vec<_> = values.iter().map(|z| self.inner.afs.semi_axes(*z, s)).collect();
            let c_x = scalar_or_array(py, &shape, axes.iter().map(|a| a.c_x).collect())?;
            let c_y = scalar_or_array(py, &shape, axes.iter().map(|a| a.c_y).collect())?;
            PyTuple::new(py, [c_x, c_y])
        }

        /// `u^T C(u_z) u = (u_x/c_x)^2 + (u_y/c_y)^2` (eq. 7); a zero semi-axis gives 0 for a zero
        /// component and `inf` otherwise.
        ///
        /// Args:
        ///     u: (3,) force or (N, 3) forces in the team frame (N).
        ///     relaxation: `s` in (0, 1], default 1 (`s=` is an alias).
        ///
        /// Returns:
        ///     a float for (3,) input, else an (N,) array.
        #[pyo3(signature = (u, relaxation = None, *, s = None))]
        fn quadratic_form<'py>(
            &self,
            py: Python<'py>,
            u: &Bound<'py, PyAny>,
            relaxation: Option<f64>,
            s: Option<f64>,
        ) -> PyResult<Bound<'py, PyAny>> {
            let s = relaxation_arg(relaxation, s, Some(1.0))?;
            let batch = vectors3(u, "u")?;
            let q = batch
                .vectors
                .iter()
                .map(|v| self.inner.afs.quadratic_form(v, s))
                .collect();
            scalar_or_array(py, &batch.leading, q)
        }

        /// Membership in the approximated AFS (eq. 7) with relaxation `s`.
        ///
        /// Args:
        ///     u: (3,) force or (N, 3) forces in the team frame (N).
        ///     relaxation: `s` in (0, 1], default 1 (`s=` is an alias).
        ///
        /// Returns:
        ///     a bool for (3,) input, else an (N,) bool array.
        ///
        /// Raises:
        ///     ValueError: NaN/inf in `u`, or `s` outside (0, 1].
        #[pyo3(signature = (u, relaxation = None, *, s = None))]
        fn contains<'py>(
            &self,
            py: Python<'py>,
            u: &Bound<'py, PyAny>,
            relaxation: Option<f64>,
            s: Option<f64>,
        ) -> PyResult<Bound<'py, PyAny>> {
            let s = relaxation_arg(relaxation, s, Some(1.0))?;
            let batch = vectors3(u, "u")?;
            let inside = batch
                .vectors
                .iter()
                .map(|v| self.inner.afs.contains(v, s))
                .collect();
            bool_or_array(py, &batch.leading, inside)
        }

        /// The force projection `K_f` of eqs. (12)-(13) (with `s = 1`):
        /// `t_Tf = min(1, n sigma_Tf / ||u||)`, `u' = t_Tf u`,
        /// `t_eta = min(1, sqrt(1 / (u'^T C(u'_z) u')))`, `K_f = diag(t_eta t_Tf, t_eta t_Tf, t_Tf)`.
        ///
        /// Args:
        ///     u: (3,) requested force `u_fr` or (N, 3) forces in the team frame (N).
        ///
        /// Returns:
        ///     `(K_f u, t_Tf, t_eta)`: a (3,) array and two floats for (3,) input, else (N, 3),
        ///     (N,) and (N,) arrays.
        fn project<'py>(
            &self,
            py: Python<'py>,
            u: &Bound<'py, PyAny>,
        ) -> PyResult<Bound<'py, PyTuple>> {
            let batch = vectors3(u, "u")?;
            let projections: Vec<_> = batch
                .vectors
                .iter()
                .map(|v| project_force(&self.inner.afs, v))
                .collect();
            let forces: Vec<f64> = projections
                .iter()
                .flat_map(|p| [p.force.x, p.force.y, p.force.z])
                .collect();
            let mut force_shape = batch.leading.clone();
            force_shape.push(3);
            let t_tf = projections.iter().map(|p| p.t_tf).collect();
            let t_eta = projections.iter().map(|p| p.t_eta).collect();
            PyTuple::new(
                py,
                [
                    shaped(py, &force_shape, forces)?,
                    scalar_or_array(py, &batch.leading, t_tf)?,
                    scalar_or_array(py, &batch.leading, t_eta)?,
                ],
            )
        }
    }
}

record! {
    /// The force projection of eqs. (12)-(13): `K_f = diag(t_eta t_Tf, t_eta t_Tf, t_Tf)`.
    ///
    /// Attributes:
    ///     force: (3,) `K_f u_fr`.
    ///     t_Tf: `min(1, n sigma_Tf / ||u_fr||)`.
    ///     t_eta: `min(1, sqrt(1 / (u'^T C(u'_z) u')))`, `u' = t_Tf u_fr`.
    "ForceProjection" in "tvmd" => PyForceProjection(ForceProjection<f64>) |py, o| {
        /// (3,) `K_f u_fr`.
        force => crate::convert::array1(py, o.force.as_slice()),
        /// `t_Tf`.
        t_tf as "t_Tf" => o.t_tf,
        /// `t_eta`.
        t_eta => o.t_eta,
    }
}

/// The NumPy broadcast of several shapes, `None` if they do not broadcast.
fn broadcast_shape(shapes: &[&[usize]]) -> Option<Vec<usize>> {
    let ndim = shapes.iter().map(|s| s.len()).max().unwrap_or(0);
    let mut out = vec![1usize; ndim];
    for shape in shapes {
        for (dim, slot) in shape.iter().rev().zip(out.iter_mut().rev()) {
            if *slot == 1 {
                *slot = *dim;
            } else if *dim != 1 && *dim != *slot {
                return None;
            }
        }
    }
    Some(out)
}

/// Broadcast views of three finite float arrays, and the common shape.
fn broadcast3(args: [(&Bound<'_, PyAny>, &str); 3]) -> PyResult<(Vec<usize>, [ArrayD<f64>; 3])> {
    let [a, b, c] = args.map(|(obj, name)| scalars(obj, name));
    let (a, b, c) = (a?, b?, c?);
    let shape = broadcast_shape(&[&a.1, &b.1, &c.1]).ok_or_else(|| {
        PyValueError::new_err(format!(
            "arguments do not broadcast together: shapes {}, {}, {}",
            shape_str(&a.1),
            shape_str(&b.1),
            shape_str(&c.1)
        ))
    })?;
    let full = |(values, s): (Vec<f64>, Vec<usize>)| -> PyResult<ArrayD<f64>> {
        let array = ArrayD::from_shape_vec(IxDyn(&s), values)
            .map_err(|e| PyValueError::new_err(format!("internal shape error: {e}")))?;
        array
            .broadcast(IxDyn(&shape))
            .map(|v| v.to_owned())
            .ok_or_else(|| PyValueError::new_err("arguments do not broadcast together"))
    };
    Ok((shape.clone(), [full(a)?, full(b)?, full(c)?]))
}

/// `f = T a_hat(eta_x, eta_y)`, `a_hat = [cos eta_x sin eta_y, -sin eta_x, cos eta_x cos eta_y]`
/// (eqs. 1 and 5): the agent-frame force of a gimbal command.
///
/// Args:
///     eta_x: inner gimbal angle(s) (rad).
///     eta_y: outer gimbal angle(s) (rad).
///     thrust: thrust(s) `T` (N).
///
/// The arguments broadcast like NumPy's.
///
/// Returns:
///     an array of shape `broadcast_shape + (3,)`: (3,) for scalars.
#[pyfunction]
pub(crate) fn gimbal_force<'py>(
    py: Python<'py>,
    eta_x: &Bound<'py, PyAny>,
    eta_y: &Bound<'py, PyAny>,
    thrust: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let (shape, [ex, ey, t]) =
        broadcast3([(eta_x, "eta_x"), (eta_y, "eta_y"), (thrust, "thrust")])?;
    let forces = Zip::from(&ex)
        .and(&ey)
        .and(&t)
        .map_collect(|ex, ey, t| core_thrust_direction(*ex, *ey) * *t);
    vectors_out(py, &shape, forces.iter())
}

/// `a_hat(eta_x, eta_y)` of eq. (1), the unit thrust direction in the agent frame.
///
/// Returns:
///     an array of shape `broadcast_shape + (3,)`.
#[pyfunction]
pub(crate) fn thrust_direction<'py>(
    py: Python<'py>,
    eta_x: &Bound<'py, PyAny>,
    eta_y: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let one = 1.0f64.into_pyobject(py)?.into_any();
    let (shape, [ex, ey, _]) = broadcast3([(eta_x, "eta_x"), (eta_y, "eta_y"), (&one, "one")])?;
    let dirs = Zip::from(&ex)
        .and(&ey)
        .map_collect(|ex, ey| core_thrust_direction(*ex, *ey));
    vectors_out(py, &shape, dirs.iter())
}

/// An array of shape `leading + (3,)` from vectors.
fn vectors_out<'a, 'py>(
    py: Python<'py>,
    leading: &[usize],
    vectors: impl Iterator<Item = &'a Vector3<f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    let values: Vec<f64> = vectors.flat_map(|v| [v.x, v.y, v.z]).collect();
    let mut shape = leading.to_vec();
    shape.push(3);
    shaped(py, &shape, values)
}

/// The allocation inverse of an agent force (paper, "Control Allocation"):
/// `T = ||f||`, `eta_x = asin(-f_y / T)`,
/// `eta_y = atan2(f_x / sgn(cos eta_x), f_z / sgn(cos eta_x))` (a zero force gives zeros).
///
/// Args:
///     force: (3,) or (N, 3) agent-frame force(s) (N).
///
/// Returns:
///     `(eta_x, eta_y, thrust)`, floats for (3,) input, else (N,) arrays, so that
///     `gimbal_force(*gimbal_inverse(f))` reproduces `f`.
#[pyfunction]
pub(crate) fn gimbal_inverse<'py>(
    py: Python<'py>,
    force: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyTuple>> {
    let batch = vectors3(force, "force")?;
    let cmds: Vec<GimbalCommand<f64>> = batch
        .vectors
        .iter()
        .map(GimbalCommand::from_force)
        .collect();
    let leading = &batch.leading;
    PyTuple::new(
        py,
        [
            scalar_or_array(py, leading, cmds.iter().map(|c| c.eta_x).collect())?,
            scalar_or_array(py, leading, cmds.iter().map(|c| c.eta_y).collect())?,
            scalar_or_array(py, leading, cmds.iter().map(|c| c.thrust).collect())?,
        ],
    )
}

/// Registers the AFS class and the gimbal functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAfs>()?;
    m.add_class::<PyForceProjection>()?;
    m.add_function(wrap_pyfunction!(gimbal_force, m)?)?;
    m.add_function(wrap_pyfunction!(gimbal_inverse, m)?)?;
    m.add_function(wrap_pyfunction!(thrust_direction, m)?)?;
    Ok(())
}
