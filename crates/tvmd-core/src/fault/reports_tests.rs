#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
use super::*;
use crate::fault_detection::FAULT_ACTUATOR_LAG;

const LAG: f64 = FAULT_ACTUATOR_LAG;

const DT: f64 = 0.01;
const MAX: f64 = 12.0;

fn command(thrust: f64, eta_x: f64, eta_y: f64) -> AgentCommand<f64> {
    AgentCommand {
        eta_x,
        eta_y,
        thrust,
        omega: 0.0,
    }
}

fn reading(thrust: f64, eta_x: f64, eta_y: f64, age: f64) -> AgentReading<f64> {
    AgentReading::new(thrust, eta_x, eta_y, age).unwrap()
}

/// Runs `periods` periods at hover commands; agent 1 reports `report(k)` each period (a new
/// report every period, 20 ms old).
fn fly<const P: usize>(
    failures: &FailureMask<4>,
    report: impl Fn(usize) -> Option<(f64, f64, f64)>,
) -> [FaultVerdict<f64>; P] {
    let check = ReportCheck::recommended();
    let mut s = ReportState::<f64, 4>::new();
    let commands = [command(7.0, 0.1, -0.05); 4];
    core::array::from_fn(|k| {
        for i in 0..4 {
            let (t, x, y) = match i {
                1 => report(k),
                _ => Some((7.0, 0.1, -0.05)),
            }
            .unwrap_or((f64::NAN, 0.0, 0.0));
            if t.is_finite() {
                s.set(i, reading(t, x, y, 0.02), DT);
            }
        }
        s.update(&check, &commands, failures, MAX, DT, LAG)
    })
}

#[test]
fn agreeing_reports_name_nothing_and_a_dead_rotor_is_a_confirmed_loss() {
    let none = FailureMask::none();
    let v: [_; 20] = fly(&none, |_| Some((7.0 + 0.5, 0.1 + 0.03, -0.05)));
    assert!(v.iter().all(|v| *v == FaultVerdict::Nominal), "{v:?}");
    let v: [_; 6] = fly(&none, |k| {
        Some((if k >= 2 { 0.0 } else { 7.0 }, 0.1, -0.05))
    });
    assert_eq!(v[1], FaultVerdict::Nominal);
    assert_eq!(
        v[2],
        FaultVerdict::Suspected {
            agent: 1,
            kind: FaultKind::Loss,
            periods: 1
        }
    );
    assert_eq!(
        v[3],
        FaultVerdict::Confirmed {
            agent: 1,
            kind: FaultKind::Loss
        }
    );
    // A masked agent is not checked.
    let masked = FailureMask::with_failed(&[1]).unwrap();
    let v: [_; 6] = fly(&masked, |_| Some((0.0, 0.1, -0.05)));
    assert!(v.iter().all(|v| *v == FaultVerdict::Nominal), "{v:?}");
}

#[test]
fn half_speed_is_a_partial_loss_and_a_stuck_servo_a_stuck_gimbal() {
    let none = FailureMask::none();
    let v: [_; 3] = fly(&none, |_| Some((3.5, 0.1, -0.05)));
    match v[2] {
        FaultVerdict::Confirmed {
            agent: 1,
            kind: FaultKind::PartialLoss { efficiency },
        } => assert!((efficiency - 0.5).abs() < 1e-12),
        v => panic!("{v:?}"),
    }
    let v: [_; 3] = fly(&none, |_| Some((7.0, 0.1, 0.2)));
    assert_eq!(
        v[2],
        FaultVerdict::Confirmed {
            agent: 1,
            kind: FaultKind::StuckGimbal
        }
    );
}

#[test]
fn a_silent_agent_is_a_link_loss_only_past_the_timeout() {
    let check = ReportCheck::<f64>::recommended();
    let mut s = ReportState::<f64, 4>::new();
    let commands = [command(7.0, 0.0, 0.0); 4];
    let none = FailureMask::none();
    for i in 0..4 {
        s.set(i, reading(7.0, 0.0, 0.0, 0.025), DT);
    }
    // No report arrives again: ages 0.025, 0.035, ... Past 0.1 s (the ninth period) a link loss.
    let mut named = None;
    for k in 0..12 {
        let v = s.update(&check, &commands, &none, MAX, DT, LAG);
        if v != FaultVerdict::Nominal {
            named.get_or_insert((k, v));
        }
    }
    let (k, v) = named.unwrap();
    assert_eq!(k, 8);
    assert!(matches!(
        v,
        FaultVerdict::Confirmed {
            kind: FaultKind::LinkLoss,
            ..
        }
    ));
    // A stale report given again is not new and does not count twice.
    let mut s = ReportState::<f64, 4>::new();
    let verdicts: [_; 4] = core::array::from_fn(|k| {
        // The same report, measured once, 20 ms old at the first period.
        s.set(1, reading(0.0, 0.0, 0.0, 0.02 + DT * k as f64), DT);
        s.update(&check, &commands, &none, MAX, DT, LAG)
    });
    assert!(
        verdicts.iter().all(|v| matches!(
            v,
            FaultVerdict::Suspected {
                periods: 1,
                agent: 1,
                ..
            }
        )),
        "{verdicts:?}"
    );
}

#[test]
fn a_changing_command_is_followed_within_the_lag_allowance() {
    // Healthy servos from the slowest stated rate to ten times faster: never named.
    for servo in [
        REPORT_SERVO_RATE,
        3.0 * REPORT_SERVO_RATE,
        10.0 * REPORT_SERVO_RATE,
    ] {
        let check = ReportCheck::<f64>::recommended();
        let mut s = ReportState::<f64, 1>::new();
        let none = FailureMask::none();
        // The real actuators: the model's rotor lag, `servo` rad/s, read 20 ms late.
        let mut actual = [4.0, 0.0, 0.0];
        // The last three states, oldest first.
        let mut history = [actual; 3];
        let closed = 1.0 - (-DT / FAULT_ACTUATOR_LAG).exp();
        for k in 0..200 {
            let t = k as f64 * DT;
            // A tilt manoeuvre: thrust and angle steps, then a sine.
            let c = command(
                if k < 50 { 4.0 } else { 9.0 },
                if k < 100 { 0.0 } else { 0.4 },
                (t * 2.0).sin() * 0.3,
            );
            let v = s.update(&check, &[c], &none, MAX, DT, LAG);
            assert_eq!(v, FaultVerdict::Nominal, "servo {servo} rad/s, period {k}");
            actual[0] += (c.thrust - actual[0]) * closed;
            let step = servo * DT;
            actual[1] += (c.eta_x - actual[1]).clamp(-step, step);
            actual[2] += (c.eta_y - actual[2]).clamp(-step, step);
            history = [history[1], history[2], actual];
            let old = history[0];
            s.set(0, reading(old[0], old[1], old[2], 0.02), DT);
        }
    }
}

#[test]
fn settings_are_validated() {
    let ok = ReportCheck::new(0.1, 0.05, 40.0, 0.0, 0.1, 2);
    assert!(ok.is_ok());
    for (bad, field) in [
        (
            ReportCheck::new(0.0, 0.05, 40.0, 0.0, 0.1, 2),
            ConfigField::ReportTolerance,
        ),
        (
            ReportCheck::new(0.1, f64::NAN, 40.0, 0.0, 0.1, 2),
            ConfigField::ReportTolerance,
        ),
        (
            ReportCheck::new(0.1, 0.05, -1.0, 0.0, 0.1, 2),
            ConfigField::ReportServoRate,
        ),
        (
            ReportCheck::new(0.1, 0.05, 40.0, -0.1, 0.1, 2),
            ConfigField::ReportLinkTimeout,
        ),
        (
            ReportCheck::new(0.1, 0.05, 40.0, 0.0, 0.0, 2),
            ConfigField::ReportLinkTimeout,
        ),
        (
            ReportCheck::new(0.1, 0.05, 40.0, 0.0, 0.1, 0),
            ConfigField::ReportPersistence,
        ),
    ] {
        assert_eq!(bad.unwrap_err().field(), Some(field));
    }
    let r = ReportCheck::<f32>::recommended();
    assert_eq!(r.persistence(), REPORT_PERSISTENCE);
    assert!(r.link_timeout() > 0.0 && r.thrust_tolerance() > 0.0);
}
