//! Hover capability of degraded teams (issue 13, Deliver 3), through the public paths a flight
//! controller uses: `Controller::set_failures`, `Controller::hover_capability` and
//! `TeamConfig::hover_capability`, in f32 and f64.

use tvmd_core::hover::hover_margin_tolerance;
use tvmd_core::team::presets;
use tvmd_core::{
    Controller, ControllerSettings, FailureMask, HoverLimit, Real, RedistributedPseudoInverse,
    TeamConfig,
};

fn controller<T: Real, const N: usize>(
    team: TeamConfig<T, N>,
) -> Controller<T, N, RedistributedPseudoInverse> {
    Controller::new(
        team,
        ControllerSettings::paper(),
        RedistributedPseudoInverse,
    )
    .unwrap()
}

fn a6_inc<T: Real>() -> TeamConfig<T, 6> {
    presets::ring(6, nalgebra::convert(0.5), true, presets::paper_limits()).unwrap()
}

fn a4_minus_one<T: Real>() {
    let mut c = controller(presets::a4_inc::<T, 4>().unwrap());
    assert!(c.hover_capability().capable);
    for lost in 0..4 {
        let mask = FailureMask::with_failed(&[lost]).unwrap();
        let hover = c.set_failures(mask).unwrap();
        // Rank 6 is kept (the mask is accepted) but hover is not held with a margin.
        assert_eq!(c.failures(), &mask);
        assert!(!hover.capable, "A4-Inc minus {lost}: {hover:?}");
        assert!(hover.margin <= hover_margin_tolerance::<T>(), "{hover:?}");
        assert!(matches!(
            hover.limit,
            HoverLimit::MaxThrust | HoverLimit::MinThrust
        ));
        assert_eq!(c.hover_capability(), hover);
        // The same classification from the team alone.
        let g: T = nalgebra::convert(presets::GRAVITY);
        assert_eq!(c.team().hover_capability(&mask, g).unwrap(), hover);
    }
    // Repairing the team restores the classification.
    assert!(c.set_failures(FailureMask::none()).unwrap().capable);
}

fn a6_minus_one<T: Real>() {
    let mut c = controller(a6_inc::<T>());
    let full = c.hover_capability();
    assert!(
        full.capable && full.margin > nalgebra::convert(0.99),
        "{full:?}"
    );
    for lost in 0..6 {
        let hover = c
            .set_failures(FailureMask::with_failed(&[lost]).unwrap())
            .unwrap();
        assert!(hover.capable, "A6-Inc minus {lost}: {hover:?}");
        assert!(hover.margin > nalgebra::convert(0.39), "{hover:?}");
        assert!(hover.margin < full.margin);
        assert_ne!(hover.limiting_agent, Some(lost));
    }
}

#[test]
fn a4_inc_minus_any_one_is_not_hover_capable_f64() {
    a4_minus_one::<f64>();
}

#[test]
fn a4_inc_minus_any_one_is_not_hover_capable_f32() {
    a4_minus_one::<f32>();
}

#[test]
fn a6_inc_minus_any_one_is_hover_capable_f64() {
    a6_minus_one::<f64>();
}

#[test]
fn a6_inc_minus_any_one_is_hover_capable_f32() {
    a6_minus_one::<f32>();
}

#[test]
fn a6_inc_minus_two_agents() {
    let team = a6_inc::<f64>();
    // Agents 0 and 2 lost: the CoM is strictly inside the others' polygon (1, 3, 4, 5), and
    // torque balance leaves one free parameter t: f_3 = f_5 = t, f_4 = (W - 3t)/2,
    // f_1 = (W - t)/2. At g = 9.81, W = 3 sigma_Tf, so f_1 <= sigma_Tf forces t = sigma_Tf:
    // exactly on the boundary, margin 0.
    let mask = FailureMask::with_failed(&[0, 2]).unwrap();
    let mut c = controller(team);
    let hover = c.set_failures(mask).unwrap();
    assert!(!hover.capable && hover.margin.abs() < 1e-9, "{hover:?}");
    assert_eq!(team.hover_capability(&mask, 9.81).unwrap(), hover);
    // At a lighter gravity t has room (W = 12.6 N at g = 3); at a heavy one nothing does.
    let light = team.hover_capability(&mask, 3.0).unwrap();
    assert!(light.capable && light.margin > 0.1, "{light:?}");
    let heavy = team.hover_capability(&mask, 100.0).unwrap();
    assert!(!heavy.capable && heavy.margin < 0.0, "{heavy:?}");
    // Agents 0 and 1 lost: the CoM lies on the line through agents 2 and 5 (opposite), so
    // torque balance forces agents 3 and 4 to zero thrust at any gravity (margin 0, exact).
    let adjacent = FailureMask::with_failed(&[0, 1]).unwrap();
    for g in [0.5, 3.0] {
        let h = team.hover_capability(&adjacent, g).unwrap();
        assert!(!h.capable && h.margin.abs() < 1e-9, "{g}: {h:?}");
        assert_eq!(h.limit, HoverLimit::MinThrust);
    }
    // At g = 9.81 agents 2 and 5 would each need W/2 = 20.6 N > sigma_Tf: margin -1.
    let h = team.hover_capability(&adjacent, 9.81).unwrap();
    assert!(!h.capable && (h.margin + 1.0).abs() < 1e-9, "{h:?}");
    assert_eq!(h.limit, HoverLimit::MaxThrust);
}

#[test]
fn team_hover_capability_validates_its_inputs() {
    let team = presets::a4_inc::<f64, 8>().unwrap();
    let e = team
        .hover_capability(&FailureMask::with_failed(&[5]).unwrap(), 9.81)
        .unwrap_err();
    assert_eq!(e, tvmd_core::ConfigError::FailureIndex { agent: 5 });
    let all = FailureMask::with_failed(&[0, 1, 2, 3]).unwrap();
    assert_eq!(
        team.hover_capability(&all, 9.81),
        Err(tvmd_core::ConfigError::NoAgents)
    );
    for g in [0.0, f64::NAN, 1e308] {
        let e = team.hover_capability(&FailureMask::none(), g).unwrap_err();
        assert_eq!(e.field(), Some(tvmd_core::ConfigField::Gravity), "{g}");
    }
    // Rank-deficient masks are classified (not capable), not refused.
    let two = FailureMask::with_failed(&[0, 1]).unwrap();
    assert!(!team.hover_capability(&two, 9.81).unwrap().capable);
}
