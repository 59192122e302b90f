//! Every configuration error is reachable, typed and explained.

use nalgebra::{Matrix3, Vector3};
use tvmd_core::allocation::AllocatorOptions;
use tvmd_core::error::{ConfigField, GimbalAxis, MassOf};
use tvmd_core::team::presets;
use tvmd_core::{
    AgentLimits, AgentSpec, AnyAllocator, AttainableForceSpace, AttitudePlanner, ConfigError,
    FailureMask, Gains, Navigator, PlannerStatus, Relaxation, TeamConfig,
};

fn square_agents() -> Vec<AgentSpec<f64>> {
    let a = presets::PAPER_HALF_SIDE;
    [(a, a, 1), (a, -a, 1), (-a, -a, 0), (-a, a, 0)]
        .iter()
        .map(|&(x, y, m)| AgentSpec::new(Vector3::new(x, y, 0.0), m, 0.7))
        .collect()
}

fn limits() -> AgentLimits<f64> {
    presets::paper_limits()
}

fn build(agents: &[AgentSpec<f64>]) -> Result<TeamConfig<f64, 8>, ConfigError> {
    TeamConfig::new(agents, limits(), Navigator::default())
}

fn assert_message(e: ConfigError, needle: &str) {
    let text = e.to_string();
    assert!(text.contains(needle), "`{text}` should mention `{needle}`");
    let _: &dyn std::error::Error = &e;
}

#[test]
fn valid_team_builds_with_derived_quantities() {
    let team = build(&square_agents()).unwrap();
    assert_eq!(team.len(), 4);
    assert!((team.mass() - 2.8).abs() < 1e-12);
    let none = FailureMask::none();
    assert_eq!((team.n_x(&none), team.n_y(&none)), (2, 2));
    // J_C = -sum m_i [p_i]x^2: diag(m a^2 4, m a^2 4, 2 m a^2 4) for the square.
    let a2 = presets::PAPER_HALF_SIDE.powi(2);
    let j = team.inertia();
    assert!((j[(0, 0)] - 4.0 * 0.7 * a2).abs() < 1e-12);
    assert!((j[(2, 2)] - 8.0 * 0.7 * a2).abs() < 1e-12);
    assert_eq!(team.arrangement(), tvmd_core::Arrangement::Inc);
    assert_eq!(
        presets::a4_con::<f64, 4>().unwrap().arrangement(),
        tvmd_core::Arrangement::Con
    );
}

#[test]
fn no_agents() {
    let e = build(&[]).unwrap_err();
    assert_eq!(e, ConfigError::NoAgents);
    assert_message(e, "no");
    let team = build(&square_agents()).unwrap();
    let all = FailureMask::with_failed(&[0, 1, 2, 3]).unwrap();
    assert_eq!(team.validate_failures(&all), Err(ConfigError::NoAgents));
    assert_eq!(team.afs(&all), Err(ConfigError::NoAgents));
}

#[test]
fn too_many_agents() {
    let agents = square_agents();
    let e = TeamConfig::<f64, 3>::new(&agents, limits(), Navigator::default()).unwrap_err();
    assert_eq!(
        e,
        ConfigError::TooManyAgents {
            count: 4,
            capacity: 3
        }
    );
    assert_message(e, "capacity of 3");
    assert!(presets::ring::<f64, 4>(5, 1.0, true, limits()).is_err());
}

#[test]
fn non_finite_numbers() {
    let mut agents = square_agents();
    agents[2].position.y = f64::NAN;
    assert_eq!(
        build(&agents),
        Err(ConfigError::NonFinite {
            field: ConfigField::AgentPosition
        })
    );
    let mut agents = square_agents();
    agents[1].mass = f64::INFINITY;
    assert_eq!(
        build(&agents),
        Err(ConfigError::NonFinite {
            field: ConfigField::AgentMass
        })
    );
    let mut agents = square_agents();
    agents[0].inertia[(1, 1)] = f64::NAN;
    assert_eq!(
        build(&agents),
        Err(ConfigError::NonFinite {
            field: ConfigField::AgentInertia
        })
    );
    let e = AgentLimits::new(f64::NAN, 0.5, 10.0).unwrap_err();
    assert_eq!(
        e,
        ConfigError::NonFinite {
            field: ConfigField::SigmaX
        }
    );
    assert_message(e, "limits.sigma_x");
    let e = AgentLimits::new(0.5, 0.5, f64::INFINITY).unwrap_err();
    assert_eq!(
        e,
        ConfigError::NonFinite {
            field: ConfigField::MaxThrust
        }
    );
    let nav = Navigator {
        mass: f64::NAN,
        inertia: Matrix3::zeros(),
    };
    assert_eq!(
        TeamConfig::<f64, 8>::new(&square_agents(), limits(), nav),
        Err(ConfigError::NonFinite {
            field: ConfigField::NavigatorMass
        })
    );
    assert_eq!(
        Relaxation::new(f64::NAN),
        Err(ConfigError::NonFinite {
            field: ConfigField::Relaxation
        })
    );
}

#[test]
fn gimbal_limits_outside_range() {
    for (sx, sy, axis, value) in [
        (0.0, 0.5, GimbalAxis::X, 0.0),
        (-0.1, 0.5, GimbalAxis::X, -0.1),
        (0.5, 1.6, GimbalAxis::Y, 1.6),
    ] {
        let e = AgentLimits::new(sx, sy, 10.0).unwrap_err();
        assert_eq!(e, ConfigError::GimbalLimit { axis, value });
        assert_message(e, "(0, pi/2]");
    }
    assert!(AgentLimits::new(std::f64::consts::FRAC_PI_2, 0.1, 10.0).is_ok());
}

#[test]
fn non_positive_masses() {
    let mut agents = square_agents();
    agents[3].mass = 0.0;
    let e = build(&agents).unwrap_err();
    assert_eq!(
        e,
        ConfigError::NonPositiveMass {
            of: MassOf::Agent(3),
            value: 0.0
        }
    );
    assert_message(e, "agent 3");
    let nav = Navigator {
        mass: -1.0,
        inertia: Matrix3::zeros(),
    };
    let e = TeamConfig::<f64, 8>::new(&square_agents(), limits(), nav).unwrap_err();
    assert_eq!(
        e,
        ConfigError::NonPositiveMass {
            of: MassOf::Navigator,
            value: -1.0
        }
    );
    assert_message(e, "navigator");
}

#[test]
fn non_positive_thrust() {
    assert_eq!(
        AgentLimits::new(0.5, 0.5, 0.0),
        Err(ConfigError::NonPositiveThrust {
            field: ConfigField::MaxThrust,
            value: 0.0
        })
    );
    assert_eq!(
        AgentLimits::from_rotor(0.5, 0.5, 1.2, -0.2, 0.1, 1000.0),
        Err(ConfigError::NonPositiveThrust {
            field: ConfigField::RotorDiameter,
            value: -0.2
        })
    );
    let e = limits().with_min_thrust(100.0).unwrap_err();
    assert_eq!(e, ConfigError::IdleThrust { value: 100.0 });
    assert_message(e, "idle");
}

#[test]
fn rotor_model_round_trip() {
    let l = AgentLimits::from_rotor(0.5, 0.7, 1.225, 0.2, 0.1, 900.0).unwrap();
    let k = 1.225 * 0.2f64.powi(4) * 0.1;
    assert!((l.max_thrust() - k * 900.0 * 900.0).abs() < 1e-9);
    assert!((l.max_speed() - 900.0).abs() < 1e-9);
    assert!((l.thrust_for_speed(l.speed_for_thrust(3.0)) - 3.0).abs() < 1e-12);
    // Without rotor constants, speed is normalized to 1 at maximum thrust.
    assert!((limits().max_speed() - 1.0).abs() < 1e-15);
}

#[test]
fn navigator_inertia_must_be_psd() {
    let asym = Navigator {
        mass: 1.0,
        inertia: Matrix3::new(1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
    };
    assert_eq!(
        TeamConfig::<f64, 8>::new(&square_agents(), limits(), asym),
        Err(ConfigError::NavigatorInertia)
    );
    let indefinite = Navigator {
        mass: 1.0,
        inertia: Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0)),
    };
    assert_eq!(
        TeamConfig::<f64, 8>::new(&square_agents(), limits(), indefinite),
        Err(ConfigError::NavigatorInertia)
    );
}

#[test]
fn rank_deficient_teams() {
    // One agent produces only 3 wrench directions.
    let e = build(&square_agents()[..1]).unwrap_err();
    assert!(matches!(e, ConfigError::RankDeficient { .. }), "{e:?}");
    assert_message(e, "rank 6");
    // Two agents at the same point cannot make torque about the line through them.
    let p = Vector3::new(0.3, 0.0, 0.0);
    let e = build(&[AgentSpec::new(p, 0, 0.7), AgentSpec::new(p, 1, 0.7)]).unwrap_err();
    assert!(matches!(e, ConfigError::RankDeficient { .. }), "{e:?}");
    // Losing three of four agents leaves rank 3.
    let team = build(&square_agents()).unwrap();
    let mask = FailureMask::with_failed(&[0, 1, 2]).unwrap();
    assert!(matches!(
        team.validate_failures(&mask),
        Err(ConfigError::RankDeficient { .. })
    ));
    // Losing one keeps rank 6.
    assert_eq!(
        team.validate_failures(&FailureMask::with_failed(&[1]).unwrap()),
        Ok(())
    );
}

#[test]
fn afs_and_planner_parameters() {
    assert_eq!(
        AttainableForceSpace::new(3, 4, 0.5, 0.5, 10.0),
        Err(ConfigError::AgentCount { n: 3, n_x: 4 })
    );
    assert_eq!(
        AttainableForceSpace::new(0, 0, 0.5, 0.5, 10.0),
        Err(ConfigError::NoAgents)
    );
    for s in [0.0, -0.5, 1.0 + 1e-12] {
        assert_eq!(
            Relaxation::new(s),
            Err(ConfigError::Relaxation { value: s })
        );
    }
    assert!(Relaxation::new(1.0).is_ok());
    let planner = AttitudePlanner::new(Relaxation::new(0.5).unwrap());
    assert_eq!(
        planner.with_tolerance(0.0, 10),
        Err(ConfigError::Parameter {
            field: ConfigField::PlannerTolerance
        })
    );
    assert_eq!(
        planner.with_tolerance(1e-6, 0),
        Err(ConfigError::Parameter {
            field: ConfigField::PlannerMaxIterations
        })
    );
}

#[test]
fn failure_mask_indices() {
    let e = FailureMask::<4>::with_failed(&[4]).unwrap_err();
    assert_eq!(e, ConfigError::FailureIndex { agent: 4 });
    assert_message(e, "agent 4");
    // A mask slot beyond the team's agents (but within capacity) is rejected too.
    let team = build(&square_agents()).unwrap();
    assert_eq!(
        team.validate_failures(&FailureMask::with_failed(&[6]).unwrap()),
        Err(ConfigError::FailureIndex { agent: 6 })
    );
}

#[test]
fn errors_name_their_field() {
    let e = AgentLimits::new(0.5, 2.0, 10.0).unwrap_err();
    assert_eq!(e.field(), Some(ConfigField::SigmaY));
    let e = AgentLimits::from_rotor(0.5, 0.5, 1.2, 0.2, -0.1, 1000.0).unwrap_err();
    assert_eq!(e.field(), Some(ConfigField::LiftCoefficient));
    assert_eq!(ConfigField::LiftCoefficient.as_str(), "limits.c_l");
    assert_eq!(ConfigError::NoAgents.field(), None);
    let e = Gains::diagonal([1.0; 3], [1.0, 0.0, 1.0], [1.0; 6]).unwrap_err();
    assert_eq!(e.field(), Some(ConfigField::GainKr));
    assert_message(e, "gains.k_r");
}

/// Each allocator option is refused by every allocator but its own, as `UnusedOption` naming it;
/// an unknown name is unknown whatever the options.
#[test]
fn every_option_is_refused_by_the_allocators_it_is_not_for() {
    type Any = AnyAllocator<f64, 4>;
    let with = |field| {
        let mut o = AllocatorOptions::<f64, 4>::default();
        match field {
            ConfigField::AllocatorWeights => o.agent_weights = Some([1.0; 4]),
            ConfigField::ClarabelWeights => o.wrench_weights = Some([1.0; 6]),
            ConfigField::ClarabelLambda => o.regularization = Some(1e-6),
            _ => o.max_rounds = Some(tvmd_core::RoundCap::Rounds(3)),
        }
        o
    };
    let owners: [(ConfigField, &[&str]); 4] = [
        (ConfigField::AllocatorWeights, &["weighted-pseudo-inverse"]),
        (
            ConfigField::ClarabelWeights,
            &["clarabel", "clarabel-sequential"],
        ),
        (
            ConfigField::ClarabelLambda,
            &["clarabel", "clarabel-sequential"],
        ),
        (
            ConfigField::AllocatorMaxRounds,
            &["exact-boundary-redistribution", "capped-redistribution"],
        ),
    ];
    let names = [
        "pseudo-inverse",
        "redistributed-pseudo-inverse",
        "exact-boundary-redistribution",
        "capped-redistribution",
        "weighted-pseudo-inverse",
        "clarabel",
        "clarabel-sequential",
    ];
    for (field, own) in owners {
        let options = with(field);
        for name in names {
            let result = Any::from_name(name, &options);
            if own.contains(&name) {
                if cfg!(feature = "clarabel") || !name.starts_with("clarabel") {
                    assert!(result.is_ok(), "{name} with its own {field:?}: {result:?}");
                }
            } else {
                assert_eq!(
                    result.unwrap_err(),
                    ConfigError::UnusedOption { field },
                    "{name} with {field:?}"
                );
            }
        }
        assert_eq!(
            Any::from_name("magic", &options).unwrap_err(),
            ConfigError::UnknownAllocator
        );
    }
}

/// The capped redistribution by name: its rounds from `max_rounds` (at least 1; none: 2;
/// uncapped: every agent's), each allocation within them.
#[test]
fn the_capped_redistribution_takes_its_rounds_by_name() {
    use tvmd_core::nalgebra::Vector6;
    use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
    type Any = AnyAllocator<f64, 4>;
    let with = |cap| AllocatorOptions::<f64, 4> {
        max_rounds: cap,
        ..AllocatorOptions::default()
    };
    assert_eq!(
        Any::from_name(
            "capped-redistribution",
            &with(Some(tvmd_core::RoundCap::Rounds(0)))
        )
        .unwrap_err(),
        ConfigError::Parameter {
            field: ConfigField::AllocatorMaxRounds
        }
    );
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let e = team.effectiveness(&FailureMask::none());
    let sets = [AdmissibleSet::from_limits(team.limits()); 4];
    // Far beyond the attainable set: the redistribution would fix every agent in turn.
    let wrench = Vector6::new(40.0, -30.0, 5.0, 30.0, 20.0, 80.0);
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench,
    };
    for (cap, most) in [
        (Some(tvmd_core::RoundCap::Rounds(1)), 1),
        (None, 2),
        (Some(tvmd_core::RoundCap::Uncapped), 4),
    ] {
        let mut a = Any::from_name("capped-redistribution", &with(cap)).unwrap();
        let out = a.allocate(&request);
        assert!(
            out.rounds <= most && out.rounds >= 1,
            "{cap:?}: {}",
            out.rounds
        );
        for (f, set) in out.forces.iter().zip(&sets) {
            let cmd = tvmd_core::GimbalCommand::from_force(f);
            assert!(set.contains(&cmd, 1e-9), "{cap:?}: {f:?} outside");
        }
        assert!(out.wrench_error > 1.0, "the cap's price is reported");
    }
}

#[test]
fn allocators_by_name() {
    type Any = AnyAllocator<f64, 4>;
    let options = AllocatorOptions::default();
    for name in Any::NAMES {
        assert_eq!(Any::from_name(name, &options).unwrap().name(), *name);
    }
    assert_eq!(Any::NAMES[0], Any::DEFAULT_NAME);
    assert_eq!(Any::default().name(), Any::DEFAULT_NAME);
    let e = Any::from_name("magic", &options).unwrap_err();
    assert_eq!(e, ConfigError::UnknownAllocator);
    assert_message(e, "unknown allocator");
    let weighted = AllocatorOptions {
        agent_weights: Some([1.0, 2.0, 3.0, 4.0]),
        ..AllocatorOptions::default()
    };
    assert_eq!(
        Any::from_name("pseudo-inverse", &weighted).unwrap_err(),
        ConfigError::UnusedOption {
            field: ConfigField::AllocatorWeights
        }
    );
    match Any::from_name("weighted-pseudo-inverse", &weighted).unwrap() {
        AnyAllocator::WeightedPseudoInverse(w) => assert_eq!(w.weights(), &[1.0, 2.0, 3.0, 4.0]),
        other => panic!("{other:?}"),
    }
    let clarabel = Any::from_name("clarabel", &options);
    if cfg!(feature = "clarabel") {
        assert_eq!(clarabel.unwrap().name(), "clarabel");
    } else {
        assert_eq!(
            clarabel.unwrap_err(),
            ConfigError::AllocatorUnavailable { name: "clarabel" }
        );
        assert!(!Any::NAMES.contains(&"clarabel"));
    }
}

#[test]
fn planner_status_spelling() {
    let names: Vec<&str> = PlannerStatus::ALL.iter().map(|s| s.as_str()).collect();
    assert_eq!(
        names,
        ["already-feasible", "planned", "zero-force", "unreachable"]
    );
    assert_eq!(PlannerStatus::Planned.to_string(), "planned");
}

#[test]
fn admissible_sets_are_validated() {
    use tvmd_core::admissible::{AdmissibleSet, Interval};
    let ok = AdmissibleSet::new(
        Interval::symmetric(0.5),
        Interval { lo: -0.2, hi: 0.3 },
        Interval { lo: 0.0, hi: 10.0 },
    )
    .unwrap();
    assert_eq!(ok.eta_y(), Interval { lo: -0.2, hi: 0.3 });
    let reversed = AdmissibleSet::new(
        Interval { lo: 0.5, hi: -0.5 },
        Interval::symmetric(0.5),
        Interval { lo: 0.0, hi: 10.0 },
    );
    assert_eq!(
        reversed,
        Err(ConfigError::Parameter {
            field: ConfigField::SigmaX
        })
    );
    let nan = AdmissibleSet::new(
        Interval::symmetric(0.5),
        Interval::symmetric(0.5),
        Interval {
            lo: 0.0,
            hi: f64::NAN,
        },
    );
    assert_eq!(
        nan,
        Err(ConfigError::NonFinite {
            field: ConfigField::MaxThrust
        })
    );
}
