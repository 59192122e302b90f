//! Finite but unusable configurations (issue 13, Deliver 1): values whose derived quantities
//! overflow the float type, inertias and gains that are not symmetric positive (semi-)definite,
//! and plants and gravities that are not positive. Each is a typed error naming its field, in
//! f32 and in f64.

use nalgebra::{Matrix3, Vector3};
use tvmd_core::law::Plant;
use tvmd_core::team::presets;
use tvmd_core::{
    AgentLimits, AgentSpec, ConfigError, ConfigField, Controller, ControllerSettings, Gains,
    Navigator, Real, RedistributedPseudoInverse, TeamConfig,
};

fn square<T: Real>(mass: T, half_side: T) -> [AgentSpec<T>; 4] {
    let a = half_side;
    [(a, a, 1), (a, -a, 1), (-a, -a, 0), (-a, a, 0)]
        .map(|(x, y, m)| AgentSpec::new(Vector3::new(x, y, T::zero()), m, mass))
}

fn build<T: Real>(agents: &[AgentSpec<T>]) -> Result<TeamConfig<T, 8>, ConfigError> {
    TeamConfig::new(agents, presets::paper_limits(), Navigator::default())
}

fn overflow_field(e: ConfigError) -> ConfigField {
    match e {
        ConfigError::Overflow { field, .. } => {
            assert!(
                e.to_string().contains("not finite in this float type"),
                "{e}"
            );
            field
        }
        other => panic!("expected Overflow, got {other:?}"),
    }
}

#[test]
fn huge_agent_masses_are_rejected_not_summed_to_infinity() {
    // Each mass is finite; the team mass (f64) or the weight m_C g overflows.
    let e = build(&square(1e308, 0.35)).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::AgentMass);
    assert_eq!(e.field(), Some(ConfigField::AgentMass));
    let e = build(&square(1e307, 0.35)).unwrap_err();
    assert!(e.to_string().contains("weight"), "{e}");
    let e = build(&square(1e38_f32, 0.35)).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::AgentMass);
    // Large but representable teams still build.
    assert!(build(&square(1e300, 0.35)).is_ok());
    assert!(build(&square(1e30_f32, 0.35)).is_ok());
}

#[test]
fn huge_positions_overflow_the_inertia_or_the_gram_matrix() {
    let e = build(&square(0.7, 1e200)).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::AgentPosition);
    let e = build(&square(0.7_f32, 1e20)).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::AgentPosition);
    // Even with a tiny mass: p_i^2 overflows before it is weighted.
    let e = build(&square(1e-300, 1e160)).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::AgentPosition);
    assert!(build(&square(0.7, 1e3)).is_ok());
}

#[test]
fn huge_thrust_overflows_the_total() {
    let limits = AgentLimits::new(0.5, 0.7, f64::MAX / 2.0).unwrap();
    let e =
        TeamConfig::<f64, 8>::new(&square(0.7, 0.35), limits, Navigator::default()).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::MaxThrust);
    // The rotor model's products overflow although each constant is finite.
    let e = AgentLimits::from_rotor(0.5, 0.5, 1.2, 1e80, 0.1, 1000.0).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::RotorDiameter);
    let e = AgentLimits::from_rotor(0.5, 0.5, 1.2, 0.2, 0.1, 1e200).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::MaxRotorSpeed);
    let e = AgentLimits::<f32>::from_rotor(0.5, 0.5, 1.2, 0.2, 1e-10, 1e25).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::MaxRotorSpeed);
}

#[test]
fn agent_inertia_must_be_symmetric_psd() {
    let with_inertia = |j: Matrix3<f64>| {
        let mut agents = square(0.7, 0.35);
        agents[2].inertia = j;
        build(&agents)
    };
    let skew = Matrix3::new(1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0) * 1e-3;
    let e = with_inertia(skew).unwrap_err();
    assert_eq!(e, ConfigError::AgentInertia { agent: 2 });
    assert_eq!(e.field(), Some(ConfigField::AgentInertia));
    assert!(e.to_string().contains("agent 2"), "{e}");
    let negative = -Matrix3::identity() * 1e-3;
    assert_eq!(
        with_inertia(negative),
        Err(ConfigError::AgentInertia { agent: 2 })
    );
    // Positive diagonal but indefinite.
    let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0) * 1e-3;
    assert_eq!(
        with_inertia(indefinite),
        Err(ConfigError::AgentInertia { agent: 2 })
    );
    // Semi-definite (a thin rod) is fine, as is zero (the paper's point mass).
    let rod = Matrix3::from_diagonal(&Vector3::new(1e-3, 1e-3, 0.0));
    assert!(with_inertia(rod).is_ok());
    assert!(with_inertia(Matrix3::zeros()).is_ok());
}

#[test]
fn team_inertia_is_positive_definite_for_every_valid_team() {
    for team in [
        presets::a4_inc::<f64, 8>().unwrap(),
        presets::ring(3, 0.5, true, presets::paper_limits()).unwrap(),
        presets::ring(8, 0.5, false, presets::paper_limits()).unwrap(),
    ] {
        let j = team.inertia();
        assert!(j.symmetric_eigenvalues().min() > 0.0, "{j}");
    }
    // Collinear teams (singular point-mass J_C) are refused by the rank check first.
    let line = [-0.5, 0.0, 0.5].map(|x| AgentSpec::new(Vector3::new(x, 0.0, 0.0), 1, 0.7));
    assert!(matches!(
        build(&line),
        Err(ConfigError::RankDeficient { .. })
    ));
    assert_eq!(ConfigField::TeamInertia.as_str(), "team.inertia");
}

#[test]
fn plant_is_validated() {
    let j = Matrix3::identity() * 0.1;
    let plant = Plant::<f64>::new(2.8, j, 9.81).unwrap();
    assert_eq!(
        (plant.mass(), plant.inertia(), plant.gravity()),
        (2.8, j, 9.81)
    );
    assert!((plant.weight() - 2.8 * 9.81).abs() < 1e-12);
    for (mass, gravity, field) in [
        (0.0, 9.81, ConfigField::PlantMass),
        (-1.0, 9.81, ConfigField::PlantMass),
        (2.8, 0.0, ConfigField::Gravity),
        (2.8, -9.81, ConfigField::Gravity),
    ] {
        let e = Plant::new(mass, j, gravity).unwrap_err();
        assert_eq!(e, ConfigError::Parameter { field });
        assert!(e.to_string().contains(field.as_str()), "{e}");
    }
    assert_eq!(
        Plant::new(f64::NAN, j, 9.81),
        Err(ConfigError::NonFinite {
            field: ConfigField::PlantMass
        })
    );
    assert_eq!(
        Plant::new(2.8, j, f64::INFINITY),
        Err(ConfigError::NonFinite {
            field: ConfigField::Gravity
        })
    );
    let not_spd = [
        Matrix3::new(1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        Matrix3::from_diagonal(&Vector3::new(1.0, 0.0, 1.0)),
        Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0),
    ];
    for inertia in not_spd {
        let e = Plant::new(2.8, inertia, 9.81).unwrap_err();
        assert_eq!(
            e,
            ConfigError::NotSymmetricPositiveDefinite {
                field: ConfigField::PlantInertia
            }
        );
        assert!(e.to_string().contains("symmetric positive definite"), "{e}");
    }
    let e = Plant::new(1e300, j, 1e10).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::Gravity);
    let e = Plant::<f32>::new(1e30, Matrix3::identity(), 1e10).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::Gravity);
}

#[test]
fn gains_must_be_symmetric_positive_definite() {
    let i = Matrix3::<f64>::identity();
    // Symmetric with a positive diagonal, yet indefinite: refused since issue 13.
    let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    let e = Gains::new(i, indefinite, i, i).unwrap_err();
    assert_eq!(
        e,
        ConfigError::NotSymmetricPositiveDefinite {
            field: ConfigField::GainKr
        }
    );
    // The message does not claim "positive and finite" for a non-symmetric matrix.
    let skew = Matrix3::new(1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    let e = Gains::new(i, i, i, skew).unwrap_err();
    assert_eq!(e.field(), Some(ConfigField::GainKv));
    let text = e.to_string();
    assert!(text.contains("symmetric positive definite") && !text.contains("positive and finite"));
    let mut nan = i;
    nan[(1, 1)] = f64::NAN;
    assert_eq!(
        Gains::new(nan, i, i, i),
        Err(ConfigError::NonFinite {
            field: ConfigField::GainKx
        })
    );
    assert!(Gains::new(i, i * 1e300, i * 1e-300, i).is_ok());
    assert!(Gains::<f32>::diagonal([0.4; 3], [12.0; 3], [1.0; 6]).is_ok());
}

#[test]
fn controller_gravity_is_bounded_by_the_weight() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let with_gravity = |gravity: f64| {
        let settings = ControllerSettings {
            gravity,
            ..ControllerSettings::paper()
        };
        Controller::new(team, settings, RedistributedPseudoInverse).map(|_| ())
    };
    let e = with_gravity(1e308).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::Gravity);
    for g in [0.0, -9.81, f64::NAN] {
        assert_eq!(
            with_gravity(g).unwrap_err().field(),
            Some(ConfigField::Gravity)
        );
    }
    assert!(with_gravity(1e300).is_ok());
    let team32 = presets::a4_inc::<f32, 4>().unwrap();
    let settings = ControllerSettings {
        gravity: 2e38_f32,
        ..ControllerSettings::paper()
    };
    let e = Controller::new(team32, settings, RedistributedPseudoInverse).unwrap_err();
    assert_eq!(overflow_field(e), ConfigField::Gravity);
}

/// A control period outside [1e-6, 1] s is refused, naming the period (a C caller's 1e-30 s).
#[test]
fn controller_period_is_bounded() {
    let team = presets::a4_inc::<f32, 4>().unwrap();
    let with_period = |period: f32| {
        let settings = ControllerSettings {
            period,
            ..ControllerSettings::paper()
        };
        Controller::new(team, settings, RedistributedPseudoInverse).map(|_| ())
    };
    for bad in [1e-30, 0.0, -0.01, 2.0, f32::NAN, f32::INFINITY] {
        assert_eq!(
            with_period(bad).unwrap_err().field(),
            Some(ConfigField::Period),
            "{bad}"
        );
    }
    for good in [1e-6, 0.0025, 0.01, 1.0] {
        assert!(with_period(good).is_ok(), "{good}");
    }
}

/// A null-space stage is linked with the cargo feature `null-space` (on by default); a build
/// without it (the C interface's) refuses the setting by name instead of ignoring it.
#[test]
fn a_null_space_stage_needs_its_feature() {
    use tvmd_core::{NullSpaceObjective, NullSpaceStage};
    let team = presets::a4_inc::<f32, 4>().unwrap();
    let settings = ControllerSettings {
        null_space: Some(NullSpaceStage::new(NullSpaceObjective::Margin, 8).unwrap()),
        ..ControllerSettings::paper()
    };
    let result = Controller::new(team, settings, RedistributedPseudoInverse);
    if cfg!(feature = "null-space") {
        assert!(result.is_ok());
    } else {
        assert_eq!(
            result.map(|_| ()).unwrap_err(),
            ConfigError::StageUnavailable {
                name: "null-space",
                feature: "null-space"
            }
        );
    }
}
