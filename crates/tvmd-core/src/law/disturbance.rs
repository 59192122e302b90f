//! A disturbance observer of the unmodelled body wrench, one of the two offset-free options
//! ([`crate::OffsetFree::Observer`]; `docs/method.md#beyond-the-paper-offset-free-tracking`).
//!
//! The model of eqs. (2)-(3) with an unknown wrench `[d_tau; d_f]` (`d_f` in `{I}`):
//! `m_C x_ddot = R u_f - m_C g e_3 + d_f`, `J_C Omega_dot = u_tau - Omega x J_C Omega + d_tau`.
//! Each period the observer measures the momentum change over the last period against the
//! wrench that was allocated for it,
//!
//! ```text
//! d_f,meas   = (m_C x_dot_k - m_C x_dot_k-1) / dt - (R_k-1 u_f,k-1 - m_C g e_3)
//! d_tau,meas = (J_C Omega_k - J_C Omega_k-1) / dt - (u_tau,k-1 - Omega_k-1 x J_C Omega_k-1)
//! ```
//!
//! (`u_k-1 = M f`, the allocated wrench, so a saturated allocation does not bias it) and
//! low-passes it: `d^ <- d^ + gamma (d_meas - d^)`, `gamma = 1 - e^(-L dt)`, the exact first-order
//! filter of bandwidth `L` for a held input (stable for every `L dt`). For a constant `d` the
//! estimate's error decays as `(1 - gamma)^k`. The request subtracts the estimate:
//! `u_fr += -R^T d^_f`, `u_tau += -d^_tau`.

use core::ptr::addr_of;

use nalgebra::{Matrix3, Vector3, Vector6};

use crate::foundation::error::{positive, ConfigError, ConfigField};
use crate::foundation::linalg::wrench_parts;
use crate::foundation::real::Real;
use crate::foundation::stored::Stored;
use crate::law::anti_windup::{guarded, Saturation};
use crate::law::{Plant, RigidState};

/// Observer bandwidths `L_f`, `L_tau` (rad/s) and the bound on the torque estimate (N m).
/// Validated: each finite and positive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisturbanceObserver<T: Real> {
    force_bandwidth: T,
    torque_bandwidth: T,
    max_torque: T,
}

impl<T: Real> DisturbanceObserver<T> {
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::ObserverBandwidth`] or [`ConfigField::OffsetFreeTorqueBound`].
    pub fn new(
        force_bandwidth: T,
        torque_bandwidth: T,
        max_torque: T,
    ) -> Result<Self, ConfigError> {
        Ok(Self {
            force_bandwidth: positive(force_bandwidth, ConfigField::ObserverBandwidth)?,
            torque_bandwidth: positive(torque_bandwidth, ConfigField::ObserverBandwidth)?,
            max_torque: positive(max_torque, ConfigField::OffsetFreeTorqueBound)?,
        })
    }

    /// `L_f` (rad/s).
    pub fn force_bandwidth(&self) -> T {
        self.force_bandwidth
    }

    /// `L_tau` (rad/s).
    pub fn torque_bandwidth(&self) -> T {
        self.torque_bandwidth
    }

    /// The bound on `||d^_tau||` (N m).
    pub fn max_torque(&self) -> T {
        self.max_torque
    }
}

/// What the observer keeps of the last period: momenta and the model wrench it was given.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sample<T: Real> {
    /// `m_C x_dot` (`{I}`).
    momentum: Vector3<T>,
    /// `J_C Omega` (`{C}`).
    angular_momentum: Vector3<T>,
    /// `R u_f - m_C g e_3` (`{I}`).
    force: Vector3<T>,
    /// `u_tau - Omega x J_C Omega` (`{C}`).
    torque: Vector3<T>,
}

/// The estimates `d^_f` (N, `{I}`) and `d^_tau` (N m, `{C}`), bounded by
/// `||d^_f|| <= force_bound` and `||d^_tau|| <= max_torque`, and the last period's sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObserverState<T: Real> {
    observer: DisturbanceObserver<T>,
    period: T,
    /// `1 - e^(-L dt)` for force and torque.
    gamma: (T, T),
    force: Vector3<T>,
    torque: Vector3<T>,
    last: Stored<Sample<T>>,
    /// `(m_C x_dot, J_C Omega)` of this period's state, from [`Self::measure`] for
    /// [`Self::record`] (the same state: computed once per period).
    momenta: Stored<(Vector3<T>, Vector3<T>)>,
    /// The saturation of the last period, for the update that measures it.
    saturation: Saturation,
    /// This period's raw measurement `(d_f,meas, d_tau,meas)`, before the filter and the
    /// anti-windup (`None` before a measurement).
    measured: Stored<(Vector3<T>, Vector3<T>)>,
}

impl<T: Real> ObserverState<T> {
    /// Zero estimates and no sample, for a control period `dt` (validated by the caller).
    pub fn new(observer: DisturbanceObserver<T>, period: T) -> Self {
        let gamma = |l: T| T::one() - (-(l * period)).exp();
        Self {
            gamma: (
                gamma(observer.force_bandwidth),
                gamma(observer.torque_bandwidth),
            ),
            observer,
            period,
            force: Vector3::zeros(),
            torque: Vector3::zeros(),
            last: Stored::Absent,
            momenta: Stored::Absent,
            saturation: Saturation::NONE,
            measured: Stored::Absent,
        }
    }

    /// The force (`{I}`) and torque (`{C}`) the observer adds to the requested wrench:
    /// `-d^_f`, `-d^_tau`.
    pub fn compensation(&self) -> (Vector3<T>, Vector3<T>) {
        (-self.force, -self.torque)
    }

    /// The filter gains `(1 - e^(-L_f dt), 1 - e^(-L_tau dt))`.
    pub fn gains(&self) -> (T, T) {
        self.gamma
    }

    /// The estimates `(d^_f, d^_tau)`.
    pub fn estimate(&self) -> (Vector3<T>, Vector3<T>) {
        (self.force, self.torque)
    }

    /// This period's raw measurement `(d_f,meas, d_tau,meas)` (`{I}`, `{C}`): the momentum
    /// change against the model over the last period, unfiltered and not held by the
    /// anti-windup. `None` when this period measured nothing (no sample yet, after a reset).
    pub fn measurement(&self) -> Option<(Vector3<T>, Vector3<T>)> {
        self.measured.get()
    }

    /// The estimates set to `(d^_f, d^_tau)` = `(force, torque)` (`{I}`, `{C}`; non-finite
    /// values give zero), the rest as it is.
    pub fn reseed(&mut self, force: Vector3<T>, torque: Vector3<T>) {
        let finite = |v: Vector3<T>| {
            if v.iter().all(|x| x.is_finite()) {
                v
            } else {
                Vector3::zeros()
            }
        };
        self.force = finite(force);
        self.torque = finite(torque);
    }

    /// Zero estimates, no sample.
    pub fn reset(&mut self) {
        self.force = Vector3::zeros();
        self.torque = Vector3::zeros();
        self.last = Stored::Absent;
        self.momenta = Stored::Absent;
        self.saturation = Saturation::NONE;
        self.measured = Stored::Absent;
    }

    /// The estimates and the last sample of `old` (another observer's, e.g. before a
    /// reconfiguration), the torque clamped onto this observer's bound.
    pub fn carry_over(&mut self, old: &Self) {
        self.force = old.force;
        self.torque = guarded(&old.torque, &old.torque, false, self.observer.max_torque);
        self.last = old.last;
        self.momenta = Stored::Absent;
        self.measured = Stored::Absent;
        self.saturation = old.saturation;
    }

    /// Clamps the force estimate onto a new bound (e.g. a smaller team after a failure).
    pub fn rebound(&mut self, force_bound: T) {
        self.force = guarded(&self.force, &self.force, false, force_bound);
    }

    /// Start of a period: measures the last period's disturbance from the new `state` and
    /// updates the estimates (under the anti-windup rule with the last period's saturation).
    /// Without a sample (first period, after a reset) nothing changes.
    pub fn measure(&mut self, plant: &Plant<T>, state: &RigidState<T>, force_bound: T) {
        let (momentum, angular_momentum) = momenta(plant, state);
        self.momenta = Stored::Present((momentum, angular_momentum));
        self.measured = Stored::Absent;
        let Some(last) = self.last.get() else {
            return;
        };
        let dt = self.period;
        let d_f = (momentum - last.momentum) / dt - last.force;
        let d_tau = (angular_momentum - last.angular_momentum) / dt - last.torque;
        self.measured = Stored::Present((d_f, d_tau));
        let (g_f, g_tau) = self.gamma;
        let force = self.force + (d_f - self.force) * g_f;
        let torque = self.torque + (d_tau - self.torque) * g_tau;
        self.force = guarded(&self.force, &force, self.saturation.force, force_bound);
        self.torque = guarded(
            &self.torque,
            &torque,
            self.saturation.torque,
            self.observer.max_torque,
        );
    }

    /// End of a period: records the state and the allocated wrench `u = [u_tau; u_f]` (`{C}`)
    /// sent for the coming period, and this period's saturation. `state` is the one this
    /// period's [`Self::measure`] was given (its momenta are reused).
    pub fn record(
        &mut self,
        plant: &Plant<T>,
        state: &RigidState<T>,
        wrench: &Vector6<T>,
        saturation: Saturation,
    ) {
        let (momentum, angular_momentum) =
            self.momenta.take().unwrap_or_else(|| momenta(plant, state));
        let (u_tau, u_f) = wrench_parts(wrench);
        let weight = Vector3::new(T::zero(), T::zero(), plant.weight());
        let omega = state.angular_velocity;
        self.last = Stored::Present(Sample {
            momentum,
            angular_momentum,
            force: state.attitude * u_f - weight,
            torque: u_tau - omega.cross(&angular_momentum),
        });
        self.saturation = saturation;
    }
}

/// `(m_C x_dot, J_C Omega)`, `x_dot = R v`.
fn momenta<T: Real>(plant: &Plant<T>, state: &RigidState<T>) -> (Vector3<T>, Vector3<T>) {
    let j: Matrix3<T> = plant.inertia();
    (
        state.attitude * state.velocity * plant.mass(),
        j * state.angular_velocity,
    )
}

impl<T: Real> ObserverState<T> {
    /// Whether the state at `this` holds valid tags (its three [`Stored`]s and the saturation's
    /// flags). Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        Stored::tag_intact(addr_of!((*this).last))
            && Stored::tag_intact(addr_of!((*this).momenta))
            && Stored::tag_intact(addr_of!((*this).measured))
            && Saturation::storage_intact(addr_of!((*this).saturation))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn plant() -> Plant<f64> {
        Plant::new(
            2.0,
            Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3)),
            9.81,
        )
        .unwrap()
    }

    #[test]
    fn validates_settings() {
        assert_eq!(
            DisturbanceObserver::new(0.0f64, 1.0, 1.0),
            Err(ConfigError::Parameter {
                field: ConfigField::ObserverBandwidth
            })
        );
        assert_eq!(
            DisturbanceObserver::new(1.0f64, 1.0, -1.0),
            Err(ConfigError::Parameter {
                field: ConfigField::OffsetFreeTorqueBound
            })
        );
    }

    /// Exact Euler steps of the model with a constant disturbance: the estimate converges to
    /// it geometrically, at `(1 - gamma)^k`.
    #[test]
    fn converges_to_a_constant_disturbance() {
        let p = plant();
        let obs = DisturbanceObserver::new(10.0, 10.0, 5.0).unwrap();
        let mut s = ObserverState::new(obs, 0.01);
        let d_f = Vector3::new(0.5, -0.3, 1.0);
        let d_tau = Vector3::new(0.02, 0.0, -0.05);
        let mut state = RigidState::at_rest(Vector3::zeros());
        let wrench = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 2.0 * 9.81 - 0.5);
        for _ in 0..200 {
            s.measure(&p, &state, 100.0);
            s.record(&p, &state, &wrench, Saturation::NONE);
            // Body-fixed level team: x_ddot = (u_f - m g e3 + d_f) / m.
            let accel =
                (wrench.fixed_rows::<3>(3) - Vector3::new(0.0, 0.0, 2.0 * 9.81) + d_f) / 2.0;
            state.velocity += accel * 0.01;
            let w = state.angular_velocity;
            let gyro = w.cross(&(p.inertia() * w));
            let alpha = p.inertia().try_inverse().unwrap() * (d_tau - gyro);
            state.angular_velocity += alpha * 0.01;
        }
        let (f, t) = s.estimate();
        assert!((f - d_f).norm() < 1e-6, "{f}");
        // The gyroscopic term is in the model, so the torque converges too.
        assert!((t - d_tau).norm() < 1e-6, "{t}");
        assert_eq!(s.compensation(), (-f, -t));
    }

    #[test]
    fn bounded_and_finite_under_absurd_measurements() {
        let p = plant();
        let obs = DisturbanceObserver::new(50.0, 50.0, 0.3).unwrap();
        let mut s = ObserverState::new(obs, 1e-30);
        let mut state = RigidState::at_rest(Vector3::zeros());
        let wrench = Vector6::zeros();
        for k in 0..50 {
            s.measure(&p, &state, 20.0);
            s.record(&p, &state, &wrench, Saturation::NONE);
            state.velocity.x = if k % 2 == 0 { 1e300 } else { -1e300 };
            state.angular_velocity.y = f64::from(k) * 1e10;
        }
        let (f, t) = s.estimate();
        assert!(f.iter().chain(t.iter()).all(|x| x.is_finite()));
        assert!(f.norm() <= 20.0 * (1.0 + 1e-12) && t.norm() <= 0.3 * (1.0 + 1e-12));
        s.reset();
        assert_eq!(s.estimate(), (Vector3::zeros(), Vector3::zeros()));
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refuses};
    use core::ptr::addr_of_mut;

    #[test]
    fn an_invalid_sample_measurement_or_saturation_tag_is_refused() {
        let observer = DisturbanceObserver::new(10.0_f32, 10.0, 5.0).unwrap();
        let mut s = ObserverState::new(observer, 0.01);
        let plant = Plant::new(2.0, nalgebra::Matrix3::identity(), 9.81).unwrap();
        let state = RigidState::at_rest(Vector3::zeros());
        let check = ObserverState::<f32>::storage_intact;
        assert!(accepts(&s, check));
        for _ in 0..2 {
            s.measure(&plant, &state, 100.0);
            s.record(&plant, &state, &Vector6::zeros(), Saturation::NONE);
        }
        s.measure(&plant, &state, 100.0);
        assert!(s.last.is_some() && s.momenta.is_some() && s.measured.is_some());
        assert!(accepts(&s, check));
        assert!(refuses(
            &s,
            2,
            |p| unsafe { addr_of_mut!((*p).last).cast() },
            check
        ));
        assert!(refuses(
            &s,
            2,
            |p| unsafe { addr_of_mut!((*p).momenta).cast() },
            check
        ));
        assert!(refuses(
            &s,
            0x41,
            |p| unsafe { addr_of_mut!((*p).measured).cast() },
            check
        ));
        let torque =
            |p: *mut ObserverState<f32>| unsafe { addr_of_mut!((*p).saturation.torque).cast() };
        assert!(refuses(&s, 2, torque, check));
    }
}
