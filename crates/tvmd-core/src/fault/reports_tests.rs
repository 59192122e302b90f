#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
use super::*;
use crate::fault::report_check::*;
use crate::fault_detection::FAULT_ACTUATOR_LAG;
use crate::foundation::error::ConfigField;

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

/// The models warmed up on `commands` (from rest, 0.5 s of agreeing reports).
fn warm<const K: usize>(commands: &[AgentCommand<f64>; K]) -> ReportState<f64, K> {
    let check = ReportCheck::recommended();
    let mut s = ReportState::<f64, K>::new();
    for _ in 0..50 {
        for (i, c) in commands.iter().enumerate() {
            s.set(i, reading(c.thrust, c.eta_x, c.eta_y, 0.02), DT);
        }
        let v = s.update(
            &check,
            &check.gains(DT, LAG, MAX),
            commands,
            &FailureMask::none(),
        );
        assert_eq!(v, FaultVerdict::Nominal);
    }
    s
}

/// Runs `periods` periods at hover commands after a warm-up; agent 1 reports `report(k)` each
/// period (a new report every period, 20 ms old).
fn fly<const P: usize>(
    failures: &FailureMask<4>,
    report: impl Fn(usize) -> Option<(f64, f64, f64)>,
) -> [FaultVerdict<f64>; P] {
    let check = ReportCheck::recommended();
    let commands = [command(7.0, 0.1, -0.05); 4];
    let mut s = warm(&commands);
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
        s.update(&check, &check.gains(DT, LAG, MAX), &commands, failures)
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
        } => assert!((efficiency - 0.5).abs() < 1e-6),
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
    let commands = [command(7.0, 0.0, 0.0); 4];
    let mut s = warm(&commands);
    let none = FailureMask::none();
    for i in 0..4 {
        s.set(i, reading(7.0, 0.0, 0.0, 0.025), DT);
    }
    // No report arrives again: ages 0.025, 0.035, ... Past 0.1 s (the ninth period) a link loss.
    let mut named = None;
    for k in 0..12 {
        let v = s.update(&check, &check.gains(DT, LAG, MAX), &commands, &none);
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
    let mut s = warm(&commands);
    let verdicts: [_; 4] = core::array::from_fn(|k| {
        // The same report, measured once, 20 ms old at the first period.
        s.set(1, reading(0.0, 0.0, 0.0, 0.02 + DT * k as f64), DT);
        s.update(&check, &check.gains(DT, LAG, MAX), &commands, &none)
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

/// A servo: rate-limited at `rate` (rad/s), second order at `w_n` rad/s (damping 0.8) or
/// instantaneous below the limit (`w_n = None`).
#[derive(Clone, Copy)]
struct Servo {
    rate: f64,
    w_n: Option<f64>,
    angle: f64,
    speed: f64,
}

impl Servo {
    fn step(&mut self, target: f64) {
        let Some(w) = self.w_n else {
            let step = self.rate * DT;
            self.angle += (target - self.angle).clamp(-step, step);
            return;
        };
        for _ in 0..100 {
            let h = DT / 100.0;
            let acc = w * w * (target - self.angle) - 2.0 * 0.8 * w * self.speed;
            self.speed = (self.speed + acc * h).clamp(-self.rate, self.rate);
            self.angle += self.speed * h;
        }
    }
}

#[test]
fn a_changing_command_is_followed_within_the_lag_allowance() {
    // Healthy servos: the simulator's Monte Carlo one (second order at 40 rad/s, 6 rad/s) and
    // rate limits from the slowest stated to ten times faster: never named.
    for (rate, w_n) in [
        (6.0, Some(40.0)),
        (REPORT_SERVO_RATE, None),
        (3.0 * REPORT_SERVO_RATE, None),
        (10.0 * REPORT_SERVO_RATE, None),
    ] {
        let check = ReportCheck::<f64>::recommended();
        let mut s = ReportState::<f64, 1>::new();
        let none = FailureMask::none();
        // The real actuators, read 20 ms late: the model's rotor lag and `servo`.
        let mut thrust = 4.0;
        let servo = Servo {
            rate,
            w_n,
            angle: 0.0,
            speed: 0.0,
        };
        let mut servos = [servo; 2];
        // The last three states, oldest first.
        let mut history = [[thrust, 0.0, 0.0]; 3];
        let closed = 1.0 - (-DT / FAULT_ACTUATOR_LAG).exp();
        for k in 0..300 {
            let t = k as f64 * DT;
            // A tilt manoeuvre: thrust and angle steps, a ramp back, then a sine.
            let c = command(
                if k < 50 { 4.0 } else { 9.0 },
                match k {
                    0..100 => 0.0,
                    100..200 => 0.4,
                    _ => 0.4 - (k - 200) as f64 * 0.02,
                },
                (t * 2.0).sin() * 0.3,
            );
            let v = s.update(&check, &check.gains(DT, LAG, MAX), &[c], &none);
            assert_eq!(v, FaultVerdict::Nominal, "servo {rate} rad/s, period {k}");
            thrust += (c.thrust - thrust) * closed;
            servos[0].step(c.eta_x);
            servos[1].step(c.eta_y);
            history = [
                history[1],
                history[2],
                [thrust, servos[0].angle, servos[1].angle],
            ];
            let old = history[0];
            s.set(0, reading(old[0], old[1], old[2], 0.02), DT);
        }
    }
}

#[test]
fn settings_are_validated() {
    let ok = ReportCheck::new(0.1, 0.05, 40.0, 0.05, 0.0, 0.1, 2);
    assert!(ok.is_ok());
    for (bad, field) in [
        (
            ReportCheck::new(0.0, 0.05, 40.0, 0.05, 0.0, 0.1, 2),
            ConfigField::ReportTolerance,
        ),
        (
            ReportCheck::new(0.1, f64::NAN, 40.0, 0.05, 0.0, 0.1, 2),
            ConfigField::ReportTolerance,
        ),
        (
            ReportCheck::new(0.1, 0.05, -1.0, 0.05, 0.0, 0.1, 2),
            ConfigField::ReportServoRate,
        ),
        (
            ReportCheck::new(0.1, 0.05, 40.0, 0.05, -0.1, 0.1, 2),
            ConfigField::ReportLinkTimeout,
        ),
        (
            ReportCheck::new(0.1, 0.05, 40.0, 0.05, 0.0, 0.0, 2),
            ConfigField::ReportLinkTimeout,
        ),
        (
            ReportCheck::new(0.1, 0.05, 40.0, 0.05, 0.0, 0.1, 0),
            ConfigField::ReportPersistence,
        ),
    ] {
        assert_eq!(bad.unwrap_err().field(), Some(field));
    }
    let r = ReportCheck::<f32>::recommended();
    assert_eq!(r.persistence(), REPORT_PERSISTENCE);
    assert!(r.link_timeout() > 0.0 && r.thrust_tolerance() > 0.0);
}

#[test]
fn a_fast_rotor_following_a_chattering_command_is_not_named_but_a_dead_one_is() {
    // The allocation at the attainable set's boundary: 7 N, a dip to 2 N, back (measured in
    // the simulator's tilt). A rotor that follows each command at once, read 20 ms late.
    let check = ReportCheck::<f64>::recommended();
    let gains = check.gains(DT, LAG, MAX);
    let none = FailureMask::none();
    let mut s = warm(&[command(7.0, 0.0, 0.0)]);
    let thrust = |k: usize| if k % 7 == 3 { 2.0 } else { 7.0 };
    for k in 2..300 {
        s.set(0, reading(thrust(k - 2), 0.0, 0.0, 0.02), DT);
        let v = s.update(&check, &gains, &[command(thrust(k), 0.0, 0.0)], &none);
        assert_eq!(v, FaultVerdict::Nominal, "period {k}");
    }
    // The same rotor dead: named within two reports.
    let mut named = None;
    for k in 300..305 {
        s.set(0, reading(0.0, 0.0, 0.0, 0.02), DT);
        let v = s.update(&check, &gains, &[command(thrust(k), 0.0, 0.0)], &none);
        if matches!(v, FaultVerdict::Confirmed { .. }) {
            named.get_or_insert(k);
        }
    }
    assert!(named.is_some_and(|k| k <= 302), "{named:?}");
}
