//! Closed-loop checks of the offset-free tracking, the natural-frequency gains and the landed
//! hold on a small RK4 rigid-body plant (`flight/mod.rs`): a constant unknown force and torque
//! with mass and inertia model error. `cargo test -p tvmd-core --test offset_free --
//! --nocapture` prints the numbers quoted in `docs/method.md`.

mod flight;

use flight::{fly, settling_time, worst_after, Body, Sample, Truth};
use tvmd_core::nalgebra::Vector3;
use tvmd_core::team::presets;
use tvmd_core::{
    ConfigError, ConfigField, Controller, ControllerSettings, DisturbanceObserver, FailureMask,
    FaultDetection, FaultResponse, GainSchedule, IntegralAction, NaturalGains, OffsetFree,
    RedistributedPseudoInverse, Reference, TeamConfig,
};

const HOVER: [f64; 3] = [0.0, 0.0, 1.5];

fn hover() -> Vector3<f64> {
    Vector3::from(HOVER)
}

/// The plant the A4-Inc controller does not know: 3% heavier, 4% more inertia, a constant
/// force (a gust's drag and a payload's weight) and torque (an off-centre payload).
fn disturbed_truth(team: &TeamConfig<f64, 4>) -> Truth {
    Truth {
        mass: team.mass() * 1.03,
        inertia: team.inertia() * 1.04,
        gravity: 9.81,
        force: Vector3::new(0.25, -0.15, -0.3),
        torque: Vector3::new(0.04, -0.03, 0.02),
    }
}

/// Position `w = 1.5` rad/s, attitude `w = 6` rad/s, both critically damped.
fn natural() -> NaturalGains<f64> {
    NaturalGains::uniform((1.5, 1.0), (6.0, 1.0)).unwrap()
}

/// `K_I = m w^3 / 4` and `J w^3 / 4` per axis: the third-order loop
/// `m s^3 + K_v s^2 + K_x s + K_I` is stable for `K_I < K_v K_x / m = 2 m w^3`.
fn integral(team: &TeamConfig<f64, 4>) -> IntegralAction<f64> {
    let kx = team.mass() * 1.5f64.powi(3) / 4.0;
    let j = team.inertia();
    let kr = [j[(0, 0)], j[(1, 1)], j[(2, 2)]].map(|ji| ji * 6.0f64.powi(3) / 4.0);
    IntegralAction::new([kx; 3], kr, 2.0).unwrap()
}

fn observer() -> DisturbanceObserver<f64> {
    DisturbanceObserver::new(10.0, 10.0, 2.0).unwrap()
}

fn controller(
    schedule: GainSchedule<f64>,
    offset_free: Option<OffsetFree<f64>>,
) -> Controller<f64, 4, RedistributedPseudoInverse> {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let settings = ControllerSettings {
        gain_schedule: schedule,
        offset_free,
        ..ControllerSettings::paper()
    };
    Controller::new(team, settings, RedistributedPseudoInverse).unwrap()
}

fn hover_flight(
    c: &mut Controller<f64, 4, RedistributedPseudoInverse>,
    duration: f64,
) -> Vec<Sample> {
    let truth = disturbed_truth(c.team());
    let mut body = Body::at(hover());
    fly(
        c,
        &truth,
        &mut body,
        |_| Reference::hover(hover()),
        duration,
    )
}

/// The final errors (last second) and the largest position error of a flight.
fn report(name: &str, s: &[Sample]) -> (f64, f64) {
    let end = s.last().unwrap().t;
    let x = worst_after(s, end - 1.0, |s| s.position_error);
    let r = worst_after(s, end - 1.0, |s| s.attitude_error);
    let peak = worst_after(s, 0.0, |s| s.position_error);
    let to_1cm = settling_time(s, 0.01);
    println!(
        "{name:36} final |e_x| {x:.2e} m, angle {r:.2e} rad, peak {peak:.3} m, within 1 cm after {to_1cm:.2} s"
    );
    (x, r)
}

#[test]
fn the_paper_law_keeps_a_steady_error_and_both_offset_free_laws_remove_it() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let natural = GainSchedule::Natural(natural());
    // The paper's law, with its own gains and with the natural ones: a steady offset.
    let paper = hover_flight(&mut controller(GainSchedule::AsGiven, None), 30.0);
    let (x, r) = report("paper gains, paper law", &paper);
    assert!(x > 0.3 && r > 5e-3, "{x} {r}");
    let plain = hover_flight(&mut controller(natural, None), 30.0);
    let (x, r) = report("natural gains, paper law", &plain);
    assert!(x > 0.02 && r > 1e-3, "{x} {r}");
    // Both offset-free laws converge to < 1 cm and < 1 mrad under the same disturbance.
    let o = Some(OffsetFree::Observer(observer()));
    let with_observer = hover_flight(&mut controller(natural, o), 30.0);
    let (xo, ro) = report("natural gains, observer", &with_observer);
    assert!(xo < 0.01 && ro < 1e-3, "{xo} {ro}");
    let i = Some(OffsetFree::Integral(integral(&team)));
    let with_integral = hover_flight(&mut controller(natural, i), 30.0);
    let (xi, ri) = report("natural gains, integral", &with_integral);
    assert!(xi < 0.01 && ri < 1e-3, "{xi} {ri}");
    // The paper's own (slow) gains with the observer: offset-free too.
    let slow = hover_flight(&mut controller(GainSchedule::AsGiven, o), 60.0);
    let (xs, rs) = report("paper gains, observer", &slow);
    assert!(xs < 0.01 && rs < 1e-3, "{xs} {rs}");
    // The observer rejects the disturbance before it builds an error: its peak is a fraction
    // of the integral's (the decision in docs/method.md).
    let peak = |s: &[Sample]| worst_after(s, 0.0, |s| s.position_error);
    assert!(peak(&with_observer) < 0.5 * peak(&with_integral));
}

/// A 0.5 m step in x from hover, no disturbance, no model error.
fn step_settling<const N: usize>(team: TeamConfig<f64, N>, schedule: GainSchedule<f64>) -> f64 {
    let truth = Truth {
        mass: team.mass(),
        inertia: team.inertia(),
        gravity: 9.81,
        force: Vector3::zeros(),
        torque: Vector3::zeros(),
    };
    let settings = ControllerSettings {
        gain_schedule: schedule,
        ..ControllerSettings::paper()
    };
    let mut c = Controller::new(team, settings, RedistributedPseudoInverse).unwrap();
    let mut body = Body::at(hover() + Vector3::new(0.5, 0.0, 0.0));
    let s = fly(
        &mut c,
        &truth,
        &mut body,
        |_| Reference::hover(hover()),
        40.0,
    );
    settling_time(&s, 0.01)
}

#[test]
fn natural_gains_give_every_team_the_same_settling_time() {
    let light = || presets::a4_inc::<f64, 8>().unwrap();
    let heavy = || presets::a8_con::<f64, 8>().unwrap();
    assert!(heavy().mass() > 1.5 * light().mass());
    let natural = GainSchedule::Natural(natural());
    let (tl, th) = (
        step_settling(light(), natural),
        step_settling(heavy(), natural),
    );
    let (pl, ph) = (
        step_settling(light(), GainSchedule::AsGiven),
        step_settling(heavy(), GainSchedule::AsGiven),
    );
    println!(
        "settling to 1 cm: natural {tl:.2} s (A4-Inc, {:.1} kg) / {th:.2} s (A8-Con, {:.1} kg); \
         paper gains {pl:.2} / {ph:.2} s",
        light().mass(),
        heavy().mass()
    );
    // w = 1.5, zeta = 1: about 4.9 s to 2% of a 0.5 m step.
    assert!((tl - th).abs() <= 0.05 * tl, "{tl} {th}");
    assert!(tl > 3.0 && tl < 8.0, "{tl}");
    // The paper's fixed gains do not: the heavier team is slower.
    assert!(ph > pl * 1.1, "{pl} {ph}");
}

#[test]
fn nothing_winds_up_while_landed() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    for kind in [
        OffsetFree::Observer(observer()),
        OffsetFree::Integral(integral(&team)),
    ] {
        let mut c = controller(GainSchedule::Natural(natural()), Some(kind));
        // On the ground, level, at rest, with the reference 1.5 m above: the ground holds the
        // team (the plant is not integrated), so the error never closes.
        let ground = Body::at(Vector3::zeros()).state();
        let reference = Reference::hover(hover());
        c.set_landed(true);
        for _ in 0..500 {
            c.step(&ground, &reference).unwrap();
            let comp = c.offset_free_compensation();
            assert_eq!((comp.force.norm(), comp.torque.norm()), (0.0, 0.0));
        }
        // Not landed, the same 5 s do move the state (so the hold is what kept it at zero).
        c.set_landed(false);
        for _ in 0..500 {
            c.step(&ground, &reference).unwrap();
        }
        let moved = c.offset_free_compensation().force.norm();
        println!("{kind:?}: not landed, 5 s on the ground move the force term to {moved:.3} N");
        assert!(moved > 0.1);
        c.reset();
        assert_eq!(c.offset_free_compensation().force.norm(), 0.0);
    }
}

#[test]
fn an_unattainable_request_keeps_the_state_bounded_and_not_growing_while_saturated() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let capacity = team
        .afs(&tvmd_core::FailureMask::none())
        .unwrap()
        .max_force();
    for kind in [
        OffsetFree::Integral(integral(&team)),
        OffsetFree::Observer(observer()),
    ] {
        let mut c = controller(GainSchedule::Natural(natural()), Some(kind));
        // A downward pull larger than what the team can lift on top of its weight, and a
        // torque beyond the bound: the team sinks, the request saturates (no ground).
        let truth = Truth {
            force: Vector3::new(10.0, 0.0, -60.0),
            torque: Vector3::new(0.5, 0.0, 0.0),
            ..disturbed_truth(c.team())
        };
        let mut body = Body::at(hover());
        let s = fly(
            &mut c,
            &truth,
            &mut body,
            |_| Reference::hover(hover()),
            4.0,
        );
        let saturated = s.iter().filter(|s| s.saturation.force).count();
        assert!(saturated > 100, "{saturated}");
        for x in &s {
            assert!(x.compensation.0 <= capacity * (1.0 + 1e-12), "{x:?}");
            assert!(x.compensation.1 <= 2.0 * (1.0 + 1e-12), "{x:?}");
            // The integral updates with this period's flags: no growth while saturated.
            if matches!(kind, OffsetFree::Integral(_)) && x.saturation.force {
                assert!(
                    x.compensation.0 <= x.compensation_before * (1.0 + 1e-12),
                    "{x:?}"
                );
            }
        }
        // A failure shrinks the capacity: the kept state is re-bounded.
        let three = c
            .set_failures(tvmd_core::FailureMask::with_failed(&[0]).unwrap())
            .map(|_| c.afs().max_force());
        if let Ok(bound) = three {
            assert!(c.offset_free_compensation().force.norm() <= bound * (1.0 + 1e-12));
        }
    }
}

#[test]
fn the_authors_scaled_gains_are_faster_than_the_paper_reading() {
    // The paper's ascent from x_0 = [0.5, -0.5, 0] (stage A, 0-2 s) with no ground: the
    // horizontal error at 4 s under the two readings of the gains.
    let ascent = |t: f64| {
        let z = if t < 2.0 {
            0.75 * (1.0 - (std::f64::consts::PI * t / 2.0).cos())
        } else {
            1.5
        };
        let mut r = Reference::hover(Vector3::new(0.0, 0.0, z));
        if t < 2.0 {
            let w = std::f64::consts::PI / 2.0;
            r.velocity.z = 0.75 * w * (w * t).sin();
            r.acceleration.z = 0.75 * w * w * (w * t).cos();
        }
        r
    };
    let horizontal_at_4 = |schedule| {
        let mut c = controller(schedule, None);
        let truth = Truth {
            mass: c.team().mass(),
            inertia: c.team().inertia(),
            gravity: 9.81,
            force: Vector3::zeros(),
            torque: Vector3::zeros(),
        };
        let mut body = Body::at(Vector3::new(0.5, -0.5, 0.0));
        let s = fly(&mut c, &truth, &mut body, ascent, 4.0);
        let e = s.last().unwrap().e_x;
        (e.x * e.x + e.y * e.y).sqrt()
    };
    let paper = horizontal_at_4(GainSchedule::AsGiven);
    let scaled = horizontal_at_4(GainSchedule::TeamScaled);
    println!("horizontal error at 4 s: paper reading {paper:.3} m, team-scaled {scaled:.3} m");
    assert!(scaled < 0.5 * paper, "{paper} {scaled}");
}

#[test]
fn the_planned_rates_reduce_the_attitude_lag_behind_a_moving_planned_attitude() {
    // Stage B of paper-tilt from hover: the reference roll peaks at pi/3, beyond what the
    // team can hold, so the planner's R_d moves (and saturates). The attitude error against
    // R_d over 4-10 s, with the reference's Omega_d = 0 and with the planned rates.
    let lag = |attitude_rate| {
        let team = presets::a4_inc::<f64, 4>().unwrap();
        let settings = ControllerSettings {
            attitude_rate,
            ..ControllerSettings::paper()
        };
        let mut c = Controller::new(team, settings, RedistributedPseudoInverse).unwrap();
        let truth = Truth {
            mass: c.team().mass(),
            inertia: c.team().inertia(),
            gravity: 9.81,
            force: Vector3::zeros(),
            torque: Vector3::zeros(),
        };
        let mut body = Body::at(hover());
        let mut worst = 0.0f64;
        for k in 0..1000 {
            let t = 1.0 + f64::from(k) * 0.01;
            let phi = if (4.0..=10.0).contains(&t) {
                std::f64::consts::PI / 6.0 * (1.0 + ((t - 7.0) * std::f64::consts::PI / 3.0).cos())
            } else {
                0.0
            };
            let mut r = Reference::hover(hover());
            r.attitude = tvmd_core::rotation::roll(phi);
            let out = c.step(&body.state(), &r).unwrap();
            if t >= 4.5 {
                worst = worst.max(out.law.e_r.norm());
            }
            for _ in 0..10 {
                body = flight::rk4(&body, &truth, &out.allocation.wrench, 0.001);
            }
        }
        worst
    };
    let without = lag(None);
    let with = lag(Some(tvmd_core::AttitudeRateFilter::new(20.0, 5.0).unwrap()));
    println!("largest |e_R| against R_d over 4.5-11 s: reference rates {without:.2e}, planned rates {with:.2e}");
    assert!(with < 0.7 * without, "{without} {with}");
}

/// The offset-free law with fault detection masking a confirmed loss.
fn detecting(team: TeamConfig<f64, 4>) -> Controller<f64, 4, RedistributedPseudoInverse> {
    let settings = ControllerSettings {
        fault_detection: Some(FaultDetection::recommended(FaultResponse::Mask)),
        ..ControllerSettings::offset_free_law()
    };
    Controller::new(team, settings, RedistributedPseudoInverse).unwrap()
}

/// Hovers A4-Inc under the disturbed truth and cuts agent `lost`'s thrust at `cut` s: the
/// plant gets `M f - M_lost f_lost`. Returns the time the controller masked an agent, which
/// agent, and the largest statistic before the cut.
fn lose_agent(lost: usize, cut: f64) -> (Option<(f64, usize)>, f64, FailureMask<4>) {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let truth = disturbed_truth(&team);
    let blocks = *team.effectiveness(&FailureMask::none()).blocks();
    let mut c = detecting(team);
    let mut body = Body::at(hover());
    let dt = c.settings().period;
    let mut masked = None;
    let mut before = 0.0f64;
    for k in 0..((cut + 1.0) / dt).round() as usize {
        let t = k as f64 * dt;
        let out = c.step(&body.state(), &Reference::hover(hover())).unwrap();
        let report = c.fault_report().copied();
        if t < cut {
            before = before.max(report.map_or(0.0, |r| r.statistic));
        }
        if let (None, Some(m)) = (masked, c.fault_masking()) {
            masked = Some((t, m.agent));
        }
        let mut u = out.allocation.wrench;
        if t >= cut {
            u -= blocks[lost].get().unwrap() * out.allocation.forces[lost];
        }
        for _ in 0..10 {
            body = flight::rk4(&body, &truth, &u, dt / 10.0);
        }
    }
    (masked, before, *c.failures())
}

#[test]
fn a_lost_agent_is_detected_isolated_and_masked_by_the_controller() {
    let threshold = FaultDetection::<f64>::recommended(FaultResponse::Mask).threshold();
    for lost in 0..4 {
        let (masked, before, mask) = lose_agent(lost, 2.0);
        // No alarm before the cut under model error and a constant disturbance.
        assert!(
            before < threshold,
            "agent {lost}: statistic {before} before the cut"
        );
        let (t, agent) = masked.unwrap_or_else(|| panic!("agent {lost} never masked"));
        println!("agent {lost}: masked {agent} after {:.2} s", t - 2.0);
        assert_eq!(agent, lost);
        // The observer's bandwidth (10 rad/s) and the persistence bound the delay.
        assert!(t >= 2.0 && t - 2.0 <= 0.5, "agent {lost}: masked at {t}");
        assert!(mask.is_failed(lost) && (0..4).filter(|i| mask.is_failed(*i)).count() == 1);
    }
}

#[test]
fn fault_detection_needs_the_observer_and_reports_nothing_when_off() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let without_observer = ControllerSettings {
        fault_detection: Some(FaultDetection::recommended(FaultResponse::Report)),
        ..ControllerSettings::paper()
    };
    assert_eq!(
        Controller::new(team, without_observer, RedistributedPseudoInverse).unwrap_err(),
        ConfigError::Parameter {
            field: ConfigField::FaultResidual
        }
    );
    assert!(ControllerSettings::<f64>::paper().fault_detection.is_none());
    assert_eq!(
        FaultDetection::new(0.0f64, 5.0, 3, FaultResponse::Mask),
        Err(ConfigError::Parameter {
            field: ConfigField::FaultNoise
        })
    );
    let mut c = Controller::new(
        team,
        ControllerSettings::offset_free_law(),
        RedistributedPseudoInverse,
    )
    .unwrap();
    c.step(
        &tvmd_core::RigidState::at_rest(hover()),
        &Reference::hover(hover()),
    )
    .unwrap();
    assert!(c.fault_report().is_none() && c.fault_masking().is_none());
}
