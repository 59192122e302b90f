//! `tvmd.AttainableForceSpace` (eqs. 7-8), the force projection `K_f` (eqs. 12-13) and the
//! gimbal model (eq. 1 and its inverse), vectorized over NumPy arrays.

use nalgebra::Vector3;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use tvmd_core::gimbal::thrust_direction as core_thrust_direction;
use tvmd_core::{project_force, AgentLimits, AttainableForceSpace, ForceProjection, GimbalCommand};

use crate::convert::{
    count, matrix, relaxation_arg, scalar_or_array, scalars, shaped, vectors, Int,
};
use crate::errors::OrRaise;
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
    /// Wraps a core AFS built with `limits`.
    pub(crate) fn of(afs: AttainableForceSpace<f64>, limits: &AgentLimits<f64>) -> Self {
        let (sigma_x, sigma_y, max_thrust) =
            (limits.sigma_x(), limits.sigma_y(), limits.max_thrust());
        Self {
            inner: AfsData {
                afs,
                sigma_x,
                sigma_y,
                max_thrust,
            },
        }
    }
}

fn afs_repr(a: &AfsData) -> String {
    let (n, n_x) = (a.afs.n(), a.afs.n_x());
    let (x, y, t) = (a.sigma_x, a.sigma_y, a.max_thrust);
    format!("AttainableForceSpace(n={n}, n_x={n_x}, sigma_x={x}, sigma_y={y}, max_thrust={t})")
}

record! {
    #[doc = include_str!("../docstrings/tvmd.AttainableForceSpace.txt")]
    "AttainableForceSpace" in "tvmd" => PyAfs(AfsData) repr afs_repr |_py, o| {
        /// Working agents.
        n => o.afs.n(),
        /// Working agents with even quarter turns.
        n_x => o.afs.n_x(),
        /// `n - n_x`.
        n_y => o.afs.n() - o.afs.n_x(),
        /// `sigma_x` (rad).
        sigma_x => o.sigma_x,
        /// `sigma_y` (rad).
        sigma_y => o.sigma_y,
        /// `sigma_Tf` (N).
        max_thrust => o.max_thrust,
        /// `n sigma_Tf` (N).
        max_force => o.afs.max_force(),
    }
    methods {
        #[new]
        #[pyo3(signature = (n, n_x, sigma_x, sigma_y, max_thrust))]
        fn new(n: Int, n_x: Int, sigma_x: f64, sigma_y: f64, max_thrust: f64) -> PyResult<Self> {
            let (n, n_x) = (count(&n, "n")?, count(&n_x, "n_x")?);
            let afs = AttainableForceSpace::new(n, n_x, sigma_x, sigma_y, max_thrust).or_raise()?;
            let inner = AfsData {
                afs,
                sigma_x,
                sigma_y,
                max_thrust,
            };
            Ok(Self { inner })
        }

        #[doc = include_str!("../docstrings/tvmd.AttainableForceSpace.semi_axes.txt")]
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
            let c_x = scalar_or_array(py, axes.iter().map(|a| a.c_x).collect(), &shape)?;
            let c_y = scalar_or_array(py, axes.iter().map(|a| a.c_y).collect(), &shape)?;
            PyTuple::new(py, [c_x, c_y])
        }

        /// `u^T C(u_z) u` (eq. 7): a float for (3,), an (N,) array for (N, 3).
        #[pyo3(signature = (u, relaxation = None, *, s = None))]
        fn quadratic_form<'py>(
            &self,
            py: Python<'py>,
            u: &Bound<'py, PyAny>,
            relaxation: Option<f64>,
            s: Option<f64>,
        ) -> PyResult<Bound<'py, PyAny>> {
            let s = relaxation_arg(relaxation, s, Some(1.0))?;
            let (u, leading) = vectors::<3>(u, "u")?;
            let q = u.iter().map(|v| self.inner.afs.quadratic_form(v, s)).collect();
            scalar_or_array(py, q, &leading)
        }

        /// Membership in the AFS (eq. 7): a bool for (3,), an (N,) bool array for (N, 3).
        #[pyo3(signature = (u, relaxation = None, *, s = None))]
        fn contains<'py>(
            &self,
            py: Python<'py>,
            u: &Bound<'py, PyAny>,
            relaxation: Option<f64>,
            s: Option<f64>,
        ) -> PyResult<Bound<'py, PyAny>> {
            let s = relaxation_arg(relaxation, s, Some(1.0))?;
            let (u, leading) = vectors::<3>(u, "u")?;
            let inside = u.iter().map(|v| self.inner.afs.contains(v, s)).collect();
            scalar_or_array(py, inside, &leading)
        }

        #[doc = include_str!("../docstrings/tvmd.AttainableForceSpace.project.txt")]
        fn project<'py>(
            &self,
            py: Python<'py>,
            u: &Bound<'py, PyAny>,
        ) -> PyResult<Bound<'py, PyTuple>> {
            let (u, leading) = vectors::<3>(u, "u")?;
            let p: Vec<_> = u.iter().map(|v| project_force(&self.inner.afs, v)).collect();
            let forces = p.iter().map(|p| p.force).collect();
            let t_tf = p.iter().map(|p| p.t_tf).collect();
            let t_eta = p.iter().map(|p| p.t_eta).collect();
            PyTuple::new(
                py,
                [
                    vectors_out(py, forces, &leading)?,
                    scalar_or_array(py, t_tf, &leading)?,
                    scalar_or_array(py, t_eta, &leading)?,
                ],
            )
        }
    }
}

record! {
    /// The force projection `K_f` of eqs. (12)-(13).
    "ForceProjection" in "tvmd" => PyForceProjection(ForceProjection<f64>) |py, o| {
        /// (3,) `K_f u_fr`.
        force => matrix(py, &o.force)?,
        /// `t_Tf`.
        t_tf as "t_Tf" => o.t_tf,
        /// `t_eta`.
        t_eta => o.t_eta,
    }
}

/// `numpy.broadcast_arrays` of finite float arguments: the common shape and each one's values.
fn broadcast<const K: usize>(
    py: Python<'_>,
    args: [(&Bound<'_, PyAny>, &str); K],
) -> PyResult<(Vec<usize>, [Vec<f64>; K])> {
    // Dtypes and finiteness are checked (and reported by name) before broadcasting.
    for (obj, name) in args {
        scalars(obj, name)?;
    }
    let arrays = py
        .import(pyo3::intern!(py, "numpy"))?
        .call_method1(
            pyo3::intern!(py, "broadcast_arrays"),
            PyTuple::new(py, args.map(|(obj, _)| obj))?,
        )
        .map_err(|e| PyValueError::new_err(format!("arguments do not broadcast together: {e}")))?;
    let (mut shape, mut values) = (Vec::new(), [const { Vec::new() }; K]);
    for ((slot, item), (_, name)) in values.iter_mut().zip(arrays.try_iter()?).zip(args) {
        (*slot, shape) = scalars(&item?, name)?;
    }
    Ok((shape, values))
}

/// An array of shape `leading + (3,)` from vectors.
fn vectors_out<'py>(
    py: Python<'py>,
    vectors: Vec<Vector3<f64>>,
    leading: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let values = vectors.iter().flat_map(|v| v.iter().copied()).collect();
    shaped(py, values, &[leading, &[3]].concat())
}

/// `f = T a_hat(eta_x, eta_y)` (eqs. 1 and 5), broadcast like NumPy.
#[pyfunction]
pub(crate) fn gimbal_force<'py>(
    py: Python<'py>,
    eta_x: &Bound<'py, PyAny>,
    eta_y: &Bound<'py, PyAny>,
    thrust: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let (shape, [ex, ey, t]) =
        broadcast(py, [(eta_x, "eta_x"), (eta_y, "eta_y"), (thrust, "thrust")])?;
    let f = ex.iter().zip(&ey).zip(&t);
    let f = f.map(|((ex, ey), t)| core_thrust_direction(*ex, *ey) * *t);
    vectors_out(py, f.collect(), &shape)
}

/// `a_hat(eta_x, eta_y)` of eq. (1).
#[pyfunction]
pub(crate) fn thrust_direction<'py>(
    py: Python<'py>,
    eta_x: &Bound<'py, PyAny>,
    eta_y: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let (shape, [ex, ey]) = broadcast(py, [(eta_x, "eta_x"), (eta_y, "eta_y")])?;
    let a = ex
        .iter()
        .zip(&ey)
        .map(|(ex, ey)| core_thrust_direction(*ex, *ey));
    vectors_out(py, a.collect(), &shape)
}

#[doc = include_str!("../docstrings/tvmd.gimbal_inverse.txt")]
#[pyfunction]
pub(crate) fn gimbal_inverse<'py>(
    py: Python<'py>,
    force: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyTuple>> {
    let (forces, leading) = vectors::<3>(force, "force")?;
    let cmds: Vec<_> = forces.iter().map(GimbalCommand::from_force).collect();
    let column = |f: fn(&GimbalCommand<f64>) -> f64| {
        scalar_or_array(py, cmds.iter().map(f).collect(), &leading)
    };
    PyTuple::new(
        py,
        [
            column(|c| c.eta_x)?,
            column(|c| c.eta_y)?,
            column(|c| c.thrust)?,
        ],
    )
}

/// Registers the AFS classes and the gimbal functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAfs>()?;
    m.add_class::<PyForceProjection>()?;
    m.add_function(wrap_pyfunction!(gimbal_force, m)?)?;
    m.add_function(wrap_pyfunction!(gimbal_inverse, m)?)?;
    m.add_function(wrap_pyfunction!(thrust_direction, m)?)?;
    Ok(())
}
