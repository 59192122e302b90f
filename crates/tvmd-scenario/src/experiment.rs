//! The built-in `paper-experiment`: the paper's manoeuvre under what its hardware experiment
//! met and its simulation left out (`docs/readings.md`, "The law that flies").

use tvmd_plant::actuators::{RotorLag, ServoModel};
use tvmd_plant::reference::{PaperTilt, ReferenceConfig};

use crate::{ExternalWrenchSpec, LawConfig, PlantError, Scenario, StateNoise};

/// Downward pull of the tether (N).
pub const TETHER_FORCE: f64 = 0.3;
/// Unmodelled yaw torque (N m, body frame): the rotors' residual drag torque.
pub const YAW_TORQUE: f64 = 0.03;

/// The scenario flown with `law`: A4-Inc takes off from the ground at the origin, climbs to
/// 1.5 m, tilts as the paper does (stage B, 4-10 s) and hovers to 20 s (no descent), with
///
/// - a tether pulling down with [`TETHER_FORCE`] and an unmodelled yaw torque [`YAW_TORQUE`];
/// - a thrust model error: agents 0 and 2 make 98% of their commanded thrust, and gimbal
///   offsets of 0.01 rad;
/// - servo dynamics (40 rad/s, damping 0.8, 6 rad/s) and a 30 ms rotor lag;
/// - state noise (1 mm, 1 cm/s, 2 mrad, 0.01 rad/s) and one controller period of latency.
///
/// The steady-state window is the last 4 s of hover.
pub(crate) fn paper_experiment(law: LawConfig) -> Scenario {
    let mut s = Scenario {
        duration: 20.0,
        initial_position: [0.0, 0.0, 0.0],
        reference: ReferenceConfig::PaperTilt(PaperTilt {
            descent: [30.0, 32.0],
            ..PaperTilt::default()
        }),
        law,
        plant: PlantError {
            thrust_efficiency: vec![0.98, 1.0, 0.98, 1.0],
            gimbal_offsets: vec![[0.01, 0.0], [0.0, 0.01], [-0.01, 0.0], [0.0, -0.01]],
            ..PlantError::nominal()
        },
        ..Scenario::default()
    };
    s.actuators.servo = Some(ServoModel {
        natural_frequency: 40.0,
        damping_ratio: 0.8,
        rate_limit: 6.0,
    });
    s.actuators.rotor_lag = Some(RotorLag {
        time_constant: 0.03,
    });
    s.disturbances.external_wrench = Some(ExternalWrenchSpec {
        force: [0.0, 0.0, -TETHER_FORCE],
        torque: [0.0, 0.0, YAW_TORQUE],
        start: 0.0,
        end: None,
    });
    s.disturbances.state_noise = Some(StateNoise {
        position: 0.001,
        velocity: 0.01,
        attitude: 0.002,
        angular_velocity: 0.01,
        seed: 1,
    });
    s.disturbances.feedback_latency = 1;
    s.success.steady_state_window = 4.0;
    s
}
