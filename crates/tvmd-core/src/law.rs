//! The full-pose geometric control law (eq. 12 and the Lyapunov function `Phi`), with the
//! paper's dynamics `G xi_dot = C(xi) xi + u + g_C` (eqs. 2-3), z up.
//!
//! Beyond the paper, each optional and off in [`crate::ControllerSettings::paper`]: offset-free
//! tracking ([`offset_free`]: a [`disturbance`] observer or [`integral`] action, under
//! [`anti_windup`]), gains that fit any team ([`gain_schedule`], [`natural_gains`]) and the
//! planned attitude's rates ([`attitude_rate`]).

use nalgebra::{Matrix3, Vector3, Vector6};

use crate::foundation::definite::is_symmetric_pd;
use crate::foundation::error::{ConfigError, ConfigField, InputError};
use crate::foundation::real::{lit, Real};
use crate::foundation::rotation::{validate_rotation as rotation, vee};

pub mod anti_windup;
pub mod attitude_rate;
pub mod disturbance;
pub mod gain_schedule;
pub mod integral;
pub mod natural_gains;
pub mod offset_free;

/// Controller gains. `K_xi = blockdiag(K_Omega, K_v)`: the paper's `K_xi` is diagonal, and a
/// block-diagonal one keeps the force request independent of the planned attitude (the order of `docs/method.md`).
/// Gains are not scaled by mass or inertia (the paper does not; the authors' MATLAB does).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains<T: Real> {
    k_x: Matrix3<T>,
    k_r: Matrix3<T>,
    k_omega: Matrix3<T>,
    k_v: Matrix3<T>,
}

impl<T: Real> Gains<T> {
    /// Diagonal gains: `K_x`, `K_R` and `K_xi = diag(K_Omega, K_v)` (order `[Omega; v]`).
    pub fn diagonal(k_x: [T; 3], k_r: [T; 3], k_xi: [T; 6]) -> Result<Self, ConfigError> {
        let [o1, o2, o3, v1, v2, v3] = k_xi;
        Self::new(
            Matrix3::from_diagonal(&Vector3::from(k_x)),
            Matrix3::from_diagonal(&Vector3::from(k_r)),
            Matrix3::from_diagonal(&Vector3::new(o1, o2, o3)),
            Matrix3::from_diagonal(&Vector3::new(v1, v2, v3)),
        )
    }

    /// Full gain matrices, each symmetric positive definite (symmetric so the Lyapunov values
    /// are quadratic forms, definite so each term of `Phi` is a norm).
    ///
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::NotSymmetricPositiveDefinite`]
    /// naming the gain.
    pub fn new(
        k_x: Matrix3<T>,
        k_r: Matrix3<T>,
        k_omega: Matrix3<T>,
        k_v: Matrix3<T>,
    ) -> Result<Self, ConfigError> {
        for (k, field) in [
            (&k_x, ConfigField::GainKx),
            (&k_r, ConfigField::GainKr),
            (&k_omega, ConfigField::GainKomega),
            (&k_v, ConfigField::GainKv),
        ] {
            if !k.iter().all(|x| x.is_finite()) {
                return Err(ConfigError::NonFinite { field });
            }
            if !is_symmetric_pd(k) {
                return Err(ConfigError::NotSymmetricPositiveDefinite { field });
            }
        }
        Ok(Self {
            k_x,
            k_r,
            k_omega,
            k_v,
        })
    }

    /// The paper's gains: `K_x = diag(0.4, 0.4, 1)`, `K_R = diag(12, 12, 1)`,
    /// `K_xi = diag(8, 8, 1.5, 0.8, 0.8, 2)`.
    pub fn paper() -> Self {
        let d =
            |a: f64, b: f64, c: f64| Matrix3::from_diagonal(&Vector3::new(lit(a), lit(b), lit(c)));
        Self {
            k_x: d(0.4, 0.4, 1.0),
            k_r: d(12.0, 12.0, 1.0),
            k_omega: d(8.0, 8.0, 1.5),
            k_v: d(0.8, 0.8, 2.0),
        }
    }

    /// `K_x`, position gain.
    pub fn k_x(&self) -> Matrix3<T> {
        self.k_x
    }

    /// `K_R`, attitude gain.
    pub fn k_r(&self) -> Matrix3<T> {
        self.k_r
    }

    /// `K_Omega`, angular-velocity block of `K_xi`.
    pub fn k_omega(&self) -> Matrix3<T> {
        self.k_omega
    }

    /// `K_v`, velocity block of `K_xi`.
    pub fn k_v(&self) -> Matrix3<T> {
        self.k_v
    }
}

/// The measured state: pose and body-frame twist `xi = [Omega; v]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidState<T: Real> {
    /// `x`, CoM position in the inertial frame (m), z up.
    pub position: Vector3<T>,
    /// `R`, body-to-inertial rotation.
    pub attitude: Matrix3<T>,
    /// `Omega`, body-frame angular velocity (rad/s).
    pub angular_velocity: Vector3<T>,
    /// `v`, body-frame linear velocity (`x_dot = R v`) (m/s).
    pub velocity: Vector3<T>,
}

impl<T: Real> RigidState<T> {
    /// At rest at `position`, level.
    pub fn at_rest(position: Vector3<T>) -> Self {
        Self {
            position,
            attitude: Matrix3::identity(),
            angular_velocity: Vector3::zeros(),
            velocity: Vector3::zeros(),
        }
    }

    /// Errors if a field is not finite or the attitude is not a rotation.
    pub fn validate(&self) -> Result<(), InputError> {
        finite3(&self.position, "state.position")?;
        finite3(&self.angular_velocity, "state.angular_velocity")?;
        finite3(&self.velocity, "state.velocity")?;
        rotation(&self.attitude, "state.attitude")
    }
}

/// The reference: pose and its derivatives (feed-forward). Unknown derivatives are zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference<T: Real> {
    /// `x_r` (m).
    pub position: Vector3<T>,
    /// `x_r_dot` (m/s), inertial.
    pub velocity: Vector3<T>,
    /// `x_r_ddot` (m/s^2), inertial.
    pub acceleration: Vector3<T>,
    /// `R_r`, the reference attitude.
    pub attitude: Matrix3<T>,
    /// `Omega_d` (rad/s), body frame of the reference.
    pub angular_velocity: Vector3<T>,
    /// `Omega_d_dot` (rad/s^2).
    pub angular_acceleration: Vector3<T>,
}

impl<T: Real> Reference<T> {
    /// Hover level at `position`, zero feed-forward.
    pub fn hover(position: Vector3<T>) -> Self {
        Self {
            position,
            velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            attitude: Matrix3::identity(),
            angular_velocity: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
        }
    }

    /// Errors if a field is not finite or the attitude is not a rotation.
    pub fn validate(&self) -> Result<(), InputError> {
        finite3(&self.position, "reference.position")?;
        finite3(&self.velocity, "reference.velocity")?;
        finite3(&self.acceleration, "reference.acceleration")?;
        finite3(&self.angular_velocity, "reference.angular_velocity")?;
        finite3(&self.angular_acceleration, "reference.angular_acceleration")?;
        rotation(&self.attitude, "reference.attitude")
    }
}

fn finite3<T: Real>(v: &Vector3<T>, field: &'static str) -> Result<(), InputError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(InputError::NonFinite { field })
    }
}

/// Rigid-body parameters of the law: `G = blockdiag(J_C, m_C I)` and gravity, validated
/// ([`Plant::new`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plant<T: Real> {
    mass: T,
    inertia: Matrix3<T>,
    gravity: T,
}

impl<T: Real> Plant<T> {
    /// `m_C > 0`, `J_C` symmetric positive definite, `g > 0`, all finite, and the weight
    /// `m_C g` finite.
    ///
    /// Errors: [`ConfigError::NonFinite`], [`ConfigError::Parameter`] (a non-positive mass or
    /// gravity), [`ConfigError::NotSymmetricPositiveDefinite`] (the inertia),
    /// [`ConfigError::Overflow`] (the weight), naming [`ConfigField::PlantMass`],
    /// [`ConfigField::PlantInertia`] or [`ConfigField::Gravity`].
    pub fn new(mass: T, inertia: Matrix3<T>, gravity: T) -> Result<Self, ConfigError> {
        for (value, field) in [
            (mass, ConfigField::PlantMass),
            (gravity, ConfigField::Gravity),
        ] {
            if !value.is_finite() {
                return Err(ConfigError::NonFinite { field });
            }
            if value <= T::zero() {
                return Err(ConfigError::Parameter { field });
            }
        }
        if !inertia.iter().all(|x| x.is_finite()) {
            return Err(ConfigError::NonFinite {
                field: ConfigField::PlantInertia,
            });
        }
        if !is_symmetric_pd(&inertia) {
            return Err(ConfigError::NotSymmetricPositiveDefinite {
                field: ConfigField::PlantInertia,
            });
        }
        if !(mass * gravity).is_finite() {
            return Err(ConfigError::Overflow {
                quantity: "weight m_C g",
                field: ConfigField::Gravity,
            });
        }
        Ok(Self {
            mass,
            inertia,
            gravity,
        })
    }

    /// `m_C` (kg).
    pub fn mass(&self) -> T {
        self.mass
    }

    /// `J_C` (kg m^2).
    pub fn inertia(&self) -> Matrix3<T> {
        self.inertia
    }

    /// `g` (m/s^2), along `-e_3`.
    pub fn gravity(&self) -> T {
        self.gravity
    }

    /// `m_C g` (N), finite by construction.
    pub fn weight(&self) -> T {
        self.mass * self.gravity
    }
}

/// `u_fr`, the force part of `u_r` (team frame), which does not depend on `R_d`:
/// `u_fr = m R^T x_r_ddot - K_v e_v - R^T K_x e_x + m g R^T e_3` (`docs/method.md`, eq. 12 with
/// `g_C = [0; -m g R^T e_3]`), `e_v = v - R^T x_r_dot`.
pub fn force_request<T: Real>(
    plant: &Plant<T>,
    gains: &Gains<T>,
    state: &RigidState<T>,
    reference: &Reference<T>,
) -> Vector3<T> {
    let rt = state.attitude.transpose();
    let e_x = state.position - reference.position;
    let e_v = state.velocity - rt * reference.velocity;
    let weight = Vector3::new(T::zero(), T::zero(), plant.mass * plant.gravity);
    rt * (reference.acceleration * plant.mass - gains.k_x * e_x + weight) - gains.k_v * e_v
}

/// Everything the law computes in one period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawOutput<T: Real> {
    /// `e_x = x - x_r`.
    pub e_x: Vector3<T>,
    /// `e_R = 1/2 (R_d^T R - R^T R_d)^vee`.
    pub e_r: Vector3<T>,
    /// `e_xi = xi - xi_d = [e_Omega; e_v]`.
    pub e_xi: Vector6<T>,
    /// `u_r = [u_tau_r; u_fr]`.
    pub u_r: Vector6<T>,
    /// `u_d = blockdiag(I, K_f) u_r`.
    pub u_d: Vector6<T>,
    /// `V_R = Psi + ||e_Omega||_{K_Omega}`, `Psi = 1/2 tr(K_R (I - R_d^T R))`.
    pub v_r: T,
    /// `V_x = ||e_x||_{K_x} + ||e_v||_{K_v}`; `||a||_K = 1/2 a^T K a`.
    pub v_x: T,
}

/// The attitude part of eq. (12): `e_R`, `e_Omega` and the torque `u_tau_d` for the planned
/// attitude `r_d`, with `reference`'s `Omega_d`, `Omega_d_dot` (only those of `reference`
/// are read).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeLaw<T: Real> {
    /// `e_R = (R_d^T R - R^T R_d)^vee / 2` (rad, `{C}`).
    pub e_r: Vector3<T>,
    /// `e_Omega = Omega - R^T R_d Omega_d` (rad/s).
    pub e_omega: Vector3<T>,
    /// `u_tau_d` (N m, `{C}`).
    pub u_tau: Vector3<T>,
}

/// The attitude part of eq. (12) alone (see [`AttitudeLaw`]); [`control_wrench`] uses it.
pub fn attitude_law<T: Real>(
    plant: &Plant<T>,
    gains: &Gains<T>,
    state: &RigidState<T>,
    reference: &Reference<T>,
    r_d: &Matrix3<T>,
) -> AttitudeLaw<T> {
    let r = &state.attitude;
    let rtrd = r.transpose() * r_d;
    let half: T = lit(0.5);
    let e_r = vee(&(r_d.transpose() * r - rtrd)) * half;
    let omega = state.angular_velocity;
    let omega_d = rtrd * reference.angular_velocity;
    let e_omega = omega - omega_d;
    let omega_d_dot = -omega.cross(&omega_d) + rtrd * reference.angular_acceleration;
    let j = plant.inertia;
    let u_tau =
        j * omega_d_dot - (j * omega).cross(&omega_d) - gains.k_omega * e_omega - gains.k_r * e_r;
    AttitudeLaw {
        e_r,
        e_omega,
        u_tau,
    }
}

/// The torque part of eq. (12) with the planned `R_d`, and the full `u_r`, `u_d`:
/// `u_tau_r = J xi_dot_dOmega - [J Omega]x Omega_d' - K_Omega e_Omega - K_R e_R`, with
/// `Omega_d' = R^T R_d Omega_d`, `xi_dot_dOmega = -Omega x Omega_d' + R^T R_d Omega_d_dot`
/// (taking `R_d_dot = R_d [Omega_d]x`), and `C(xi) = blockdiag([J Omega]x, -m [Omega]x)`.
///
/// ```
/// use tvmd_core::nalgebra::{Matrix3, Vector3};
/// use tvmd_core::law::{control_wrench, force_request, Plant};
/// use tvmd_core::{Gains, Reference, RigidState};
/// let plant = Plant::<f64>::new(2.8, Matrix3::identity() * 0.1, 9.81)?;
/// let gains = Gains::paper();
/// let state = RigidState::at_rest(Vector3::new(0.2, 0.0, 1.5));
/// let reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
/// let u_fr = force_request(&plant, &gains, &state, &reference);
/// // -K_x e_x plus the weight m g.
/// assert!((u_fr - Vector3::new(-0.08, 0.0, 2.8 * 9.81)).norm() < 1e-12);
/// let law = control_wrench(&plant, &gains, &state, &reference, &Matrix3::identity(), &u_fr,
///     &Matrix3::identity());
/// assert_eq!(law.u_d, law.u_r);
/// assert!((law.v_x - 0.5 * 0.4 * 0.04).abs() < 1e-15 && law.v_r == 0.0);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
pub fn control_wrench<T: Real>(
    plant: &Plant<T>,
    gains: &Gains<T>,
    state: &RigidState<T>,
    reference: &Reference<T>,
    r_d: &Matrix3<T>,
    u_fr: &Vector3<T>,
    k_f: &Matrix3<T>,
) -> LawOutput<T> {
    let r = &state.attitude;
    let rt = r.transpose();
    let half: T = lit(0.5);
    let e_x = state.position - reference.position;
    let e_v = state.velocity - rt * reference.velocity;
    let AttitudeLaw {
        e_r,
        e_omega,
        u_tau,
    } = attitude_law(plant, gains, state, reference, r_d);
    let psi = (gains.k_r * (Matrix3::identity() - r_d.transpose() * r)).trace() * half;
    let quad = |k: &Matrix3<T>, a: &Vector3<T>| a.dot(&(k * a)) * half;
    let u_f = k_f * u_fr;
    LawOutput {
        e_x,
        e_r,
        e_xi: Vector6::new(e_omega.x, e_omega.y, e_omega.z, e_v.x, e_v.y, e_v.z),
        u_r: Vector6::new(u_tau.x, u_tau.y, u_tau.z, u_fr.x, u_fr.y, u_fr.z),
        u_d: Vector6::new(u_tau.x, u_tau.y, u_tau.z, u_f.x, u_f.y, u_f.z),
        v_r: psi + quad(&gains.k_omega, &e_omega),
        v_x: quad(&gains.k_x, &e_x) + quad(&gains.k_v, &e_v),
    }
}
