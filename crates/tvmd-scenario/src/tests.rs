//! Scenario parsing, loading and the built-ins.

use super::*;
use tvmd_plant::actuators::FailureKind;
use tvmd_plant::ReferenceConfig;

#[test]
fn empty_file_is_paper_tilt() {
    let s = Scenario::from_toml_str("").unwrap();
    assert_eq!(s, Scenario::default());
    // The paper's manoeuvre, flown with the law that flies; the built-in names the paper's.
    assert_eq!(s.law, LawConfig::default());
    let paper = Scenario::builtin("paper-tilt").unwrap();
    assert!(paper.law.is_paper());
    assert_eq!(
        Scenario {
            law: LawConfig::paper(),
            ..s.clone()
        }
        .reference,
        paper.reference
    );
    assert_eq!(s.steps_per_control().unwrap(), 10);
    assert!((s.max_thrust().unwrap() - 2.0 * 0.7 * 9.81).abs() < 1e-12);
}

#[test]
fn wrong_type_names_the_field() {
    let e = Scenario::from_toml_str("relaxation = \"half\"\n").unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("relaxation"), "{msg}");
    let e = Scenario::from_toml_str("[gains]\nk_x = [1.0, 2.0]\n").unwrap_err();
    assert!(e.to_string().contains("k_x"), "{e}");
    let e = Scenario::from_toml_str("[[failures]]\nagent = 0\ntime = 1.0\nkind = \"explode\"\n")
        .unwrap_err();
    assert!(e.to_string().contains("kind"), "{e}");
}

#[test]
fn controller_precision_parses_round_trips_and_rejects_others() {
    let s = Scenario::from_toml_str("controller_precision = \"f32\"\n").unwrap();
    assert_eq!(s.controller_precision, Precision::F32);
    let again = Scenario::from_toml_str(&s.to_toml_string().unwrap()).unwrap();
    assert_eq!(again, s);
    assert_eq!(Scenario::default().controller_precision, Precision::F64);
    let e = Scenario::from_toml_str("controller_precision = \"f16\"\n").unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("controller_precision") && msg.contains("f32"),
        "{msg}"
    );
    for p in Precision::ALL {
        assert_eq!(p.as_str().parse::<Precision>().unwrap(), p);
        assert_eq!(p.to_string(), p.as_str());
    }
    let e = "double".parse::<Precision>().unwrap_err();
    assert!(
        matches!(&e, ScenarioError::InvalidScenario { field, .. } if field == "controller_precision"),
        "{e}"
    );
}

#[test]
fn unknown_key_is_rejected_by_name() {
    let e = Scenario::from_toml_str("relaxaton = 0.5\n").unwrap_err();
    assert!(e.to_string().contains("relaxaton"), "{e}");
    let e = Scenario::from_toml_str("[physics]\nstep = 0.001\n").unwrap_err();
    assert!(e.to_string().contains("step"), "{e}");
    let e = Scenario::from_toml_str("[physics]\ndt = \"x\"\n").unwrap_err();
    assert!(e.to_string().contains("physics.dt"), "{e}");
}

#[test]
fn full_example_parses() {
    let text = r#"
name = "custom"
duration = 3.0
controller_period = 0.005
relaxation = 1.0
[physics]
dt = 0.0005
[team]
agents = [
  { position = [0.3, 0.0, 0.0], mass = 0.5, quarter_turns = 0 },
  { position = [-0.3, 0.0, 0.0], mass = 0.5, quarter_turns = 3 },
]
navigator_mass = 0.2
[limits]
max_thrust = 12.0
[reference]
kind = "hover"
position = [0.0, 0.0, 1.0]
[actuators]
servo = { natural_frequency = 40.0, damping_ratio = 0.8, rate_limit = 6.0 }
rotor_lag = { time_constant = 0.03 }
[[failures]]
agent = 1
time = 2.0
kind = "stuck-gimbal"
controller_informed = false
[disturbances]
wind = [0.5, 0.0, 0.0]
external_wrench = { torque = [0.0, 0.0, 0.1], start = 1.0, end = 2.0 }
state_noise = { position = 0.01, seed = 7 }
"#;
    let s = Scenario::from_toml_str(text).unwrap();
    assert_eq!(s.steps_per_control().unwrap(), 10);
    assert_eq!(s.team_body().unwrap().len(), 2);
    assert_eq!(s.failures[0].kind, FailureKind::StuckGimbal);
    assert!(!s.failures[0].controller_informed);
    assert_eq!(s.disturbances.state_noise.unwrap().seed, 7);
    assert_eq!(s.max_thrust().unwrap(), 12.0);
    assert!(matches!(s.reference, ReferenceConfig::Hover { .. }));
}

#[test]
fn fault_detection_parses_defaults_and_needs_the_observer() {
    assert_eq!(Scenario::default().fault_detection, None);
    let s = Scenario::from_toml_str(
        "[fault_detection]\nresponse = \"mask\"\n[[failures]]\nagent = 0\ntime = 1.0\n\
         kind = \"half-thrust\"\ncontroller_informed = false\n",
    )
    .unwrap();
    let d = s.fault_detection.unwrap();
    assert_eq!(d.response, crate::FaultResponseConfig::Mask);
    assert_eq!(
        (d.threshold, d.persistence),
        (crate::FAULT_THRESHOLD, crate::FAULT_PERSISTENCE)
    );
    assert_eq!(s.failures[0].kind, FailureKind::HalfThrust);
    // Round trip through TOML keeps it.
    let back = Scenario::from_toml_str(&toml::to_string(&s).unwrap()).unwrap();
    assert_eq!(back.fault_detection, s.fault_detection);
    for (text, field) in [
        (
            "[fault_detection]\nthreshold = 0.0\n",
            "fault_detection.threshold",
        ),
        (
            "[fault_detection]\npersistence = 0\n",
            "fault_detection.persistence",
        ),
        ("law = \"paper\"\n[fault_detection]\n", "fault_detection"),
    ] {
        let e = Scenario::from_toml_str(text).unwrap_err();
        assert!(
            matches!(&e, ScenarioError::InvalidScenario { field: f, .. } if f == field),
            "{text}: {e}"
        );
    }
}

#[test]
fn report_check_defaults_to_the_core_and_names_a_bad_field() {
    use tvmd_core::ReportCheck;
    let s = Scenario::from_toml_str("[fault_detection]\n").unwrap();
    let d = s.fault_detection.unwrap();
    assert_eq!(d.report_check, ReportCheckConfig::default());
    assert_eq!(
        *core_config::fault_detection::<f32>(&d)
            .unwrap()
            .report_check(),
        ReportCheck::<f32>::recommended()
    );
    let s = Scenario::from_toml_str(
        "[fault_detection.report_check]\nlink_timeout = 0.25\npersistence = 3\n\
         thrust_forget = 1.5\ncommand_delay = 0.0\n",
    )
    .unwrap();
    let d = s.fault_detection.unwrap();
    assert_eq!(d.report_check.servo_rate, 6.0);
    let core = core_config::fault_detection::<f64>(&d).unwrap();
    let check = core.report_check();
    assert_eq!(
        (
            check.link_timeout(),
            check.persistence(),
            check.thrust_forget()
        ),
        (0.25, 3, 1.5)
    );
    assert_eq!(check.command_delay(), 0.0);
    assert_eq!(check.angle_tolerance(), 0.05);
    let back = Scenario::from_toml_str(&toml::to_string(&s).unwrap()).unwrap();
    assert_eq!(back.fault_detection, s.fault_detection);
    for (key, value) in [
        ("thrust_tolerance", "0.0"),
        ("angle_tolerance", "-0.1"),
        ("servo_rate", "inf"),
        ("servo_lag", "nan"),
        ("command_delay", "-0.01"),
        ("link_timeout", "0.0"),
        ("persistence", "0"),
        ("persistence", "256"),
        ("thrust_forget", "0.0"),
        ("angle_forget", "-1.0"),
    ] {
        let text = format!("[fault_detection.report_check]\n{key} = {value}\n");
        let e = Scenario::from_toml_str(&text).unwrap_err();
        let field = format!("fault_detection.report_check.{key}");
        assert!(
            matches!(&e, ScenarioError::InvalidScenario { field: f, .. } if *f == field),
            "{text}: {e}"
        );
        // The core's conversion refuses it too, without the scenario's validation.
        let mut d = FaultDetectionConfig::default();
        let parsed: toml::Table = toml::from_str(&format!("{key} = {value}")).unwrap();
        d.report_check = toml::Value::Table(parsed).try_into().unwrap();
        assert!(core_config::fault_detection::<f32>(&d).is_err(), "{text}");
    }
    // A value f32 cannot hold is refused by the f32 controller, not rounded to zero.
    let mut d = FaultDetectionConfig::default();
    d.report_check.servo_lag = 1e-60;
    assert!(core_config::fault_detection::<f64>(&d).is_ok());
    assert!(matches!(
        core_config::fault_detection::<f32>(&d),
        Err(ScenarioError::InvalidScenario { field, .. }) if field == "fault_detection.report_check"
    ));
    assert!(Scenario::from_toml_str("[fault_detection.report_check]\nlag = 1.0\n").is_err());
}

#[test]
fn load_takes_a_builtin_name_or_a_file() {
    assert_eq!(
        Scenario::load("a4-con").unwrap(),
        Scenario::builtin("a4-con").unwrap()
    );
    assert!(matches!(
        Scenario::load("nope"),
        Err(ScenarioError::UnknownScenario { .. })
    ));
    let e = Scenario::load("missing-file.toml").unwrap_err();
    assert!(matches!(&e, ScenarioError::File { .. }), "{e}");
    assert!(e.to_string().contains("missing-file.toml"), "{e}");
    // Not a regular file: refused before it is opened (a FIFO would block, /dev/zero
    // never ends).
    #[cfg(unix)]
    {
        let e = Scenario::from_file("/dev/zero").unwrap_err().to_string();
        assert!(
            e.contains("not a regular file") && e.contains("/dev/zero"),
            "{e}"
        );
    }
    let dir = std::env::temp_dir().join(format!("tvmd-sim-load-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A file without the .toml suffix is still a file.
    let path = dir.join("scenario");
    std::fs::write(&path, "name = \"from-file\"\nrelaxation = 1.0\n").unwrap();
    let s = Scenario::load(path.to_str().unwrap()).unwrap();
    assert_eq!((s.name.as_str(), s.relaxation), ("from-file", 1.0));
    // A file that names no scenario runs under its file name, not as the default paper-tilt.
    let unnamed = dir.join("mine.toml");
    std::fs::write(&unnamed, "duration = 1.0\n").unwrap();
    let s = Scenario::load(unnamed.to_str().unwrap()).unwrap();
    assert_eq!((s.name.as_str(), s.duration), ("mine", 1.0));
    std::fs::write(&path, "[physics]\ndt = -1.0\n").unwrap();
    let e = Scenario::load(path.to_str().unwrap()).unwrap_err();
    assert!(
        e.to_string()
            .contains("invalid scenario field `physics.dt`"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn law_parses_names_tables_and_round_trips() {
    let law = |text: &str| Scenario::from_toml_str(text).map(|s| s.law);
    assert_eq!(law("law = \"paper\"\n").unwrap(), LawConfig::paper());
    assert_eq!(
        law("law = \"offset-free\"\n").unwrap(),
        LawConfig::default()
    );
    // A table states what differs from the default law.
    let t = law("[law]\ngains = \"team-scaled\"\nattitude_rate = \"off\"\n").unwrap();
    assert_eq!(t.gains, GainScheduleConfig::TeamScaled);
    assert_eq!(t.offset_free, OffsetFreeConfig::observer());
    assert_eq!(t.attitude_rate, AttitudeRateConfig::Off);
    let n = law("[law.gains.natural]\nposition_frequency = [1.0, 2.0, 3.0]\n").unwrap();
    let GainScheduleConfig::Natural(g) = n.gains else {
        panic!("{n:?}")
    };
    assert_eq!(g.position_frequency, [1.0, 2.0, 3.0]);
    assert_eq!(
        g.attitude_frequency,
        NaturalGainsConfig::default().attitude_frequency
    );
    let i = law(
        "[law]\noffset_free = { kind = \"integral\", k_x = [1.0, 1.0, 2.0], k_r = [0.5, 0.5, 0.5] }\n",
    )
    .unwrap();
    assert!(matches!(
        i.offset_free,
        OffsetFreeConfig::Integral { k_x: [1.0, 1.0, 2.0], max_torque, .. } if max_torque == 5.0
    ));
    let o = law("[law]\noffset_free = { kind = \"observer\", force_bandwidth = 4.0 }\n").unwrap();
    assert!(matches!(
        o.offset_free,
        OffsetFreeConfig::Observer { force_bandwidth, torque_bandwidth, .. }
            if force_bandwidth == 4.0 && torque_bandwidth == 10.0
    ));
    assert_eq!(
        law("[law]\noffset_free = \"off\"\n").unwrap().offset_free,
        OffsetFreeConfig::Off
    );
    for l in [LawConfig::paper(), LawConfig::default(), t, n, i, o] {
        let s = Scenario {
            law: l,
            ..Scenario::default()
        };
        let back = Scenario::from_toml_str(&s.to_toml_string().unwrap()).unwrap();
        assert_eq!(back.law, l);
    }
}

#[test]
fn bad_law_settings_name_the_field() {
    let err = |text: &str| Scenario::from_toml_str(text).unwrap_err().to_string();
    for (text, names) in [
        ("law = \"fast\"\n", &["law", "unknown law `fast`"][..]),
        ("[law]\ngains = \"scaled\"\n", &["law.gains", "scaled"]),
        ("[law]\nspeed = 1\n", &["law", "speed"]),
        (
            "[law]\noffset_free = { kind = \"kalman\" }\n",
            &["law.offset_free", "kalman", "observer, integral"],
        ),
        (
            "[law]\noffset_free = { kind = \"integral\", k_x = [1.0, 1.0, 1.0] }\n",
            &["law.offset_free", "k_r"],
        ),
        (
            "[law]\noffset_free = { kind = \"observer\", k_x = [1.0, 1.0, 1.0] }\n",
            &["law.offset_free", "k_x", "observer"],
        ),
        (
            "[law]\nattitude_rate = \"on\"\n",
            &["law.attitude_rate", "on"],
        ),
        (
            "[law]\nattitude_rate = { bandwidth = 20.0, rate = 1.0 }\n",
            &["law.attitude_rate", "rate"],
        ),
        (
            "[law.gains.natural]\nattitude_damping = [1.0, 0.0, 1.0]\n",
            &["law.gains.natural.attitude_damping[1]"],
        ),
        (
            "[law]\noffset_free = { kind = \"observer\", max_torque = -1.0 }\n",
            &["law.offset_free.max_torque"],
        ),
        (
            "[law]\nattitude_rate = { bandwidth = inf }\n",
            &["law.attitude_rate.bandwidth"],
        ),
        (
            "[disturbances]\nfeedback_latency = 5000\n",
            &["disturbances.feedback_latency", "5000"],
        ),
    ] {
        let e = err(text);
        for name in names {
            assert!(e.contains(name), "{text}: {e} lacks {name}");
        }
    }
}
