//! The bridge against a fake PX4 over loopback: lockstep, sensors, controls into the plant, and
//! the ends a real PX4 can bring (dies, stalls, never connects, a port in use), each with its
//! error and a readable log; the real-time pacing against a fake PX4 without lockstep, and a
//! build and a pacing that disagree. Each test has its own instance (ports 4560 + N).

use std::io::ErrorKind;
use std::net::TcpStream;
use std::path::PathBuf;
use std::thread;
use std::time::{Duration, Instant};

use mavlink::dialects::common::{
    HilActuatorControlsFlags, MavMessage, MavModeFlag, HIL_ACTUATOR_CONTROLS_DATA,
};
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};
use tvmd_px4::bridge::Pacing;
use tvmd_px4::flight::FlightPlan;
use tvmd_px4::{fly_px4, Px4Error, Px4Flight, Px4Report};
use tvmd_scenario::Scenario;

/// How the fake PX4 behaves after answering `answer` ticks.
#[derive(Clone, Copy)]
enum Then {
    /// Keep answering to the end.
    Fly,
    /// Close the connection (PX4 killed).
    Die,
    /// Keep the connection open and answer nothing (PX4 hung).
    Hang,
}

fn scenario(duration: f64) -> Scenario {
    Scenario::from_toml_str(&format!(
        r#"
        name = "fake-px4"
        duration = {duration}
        controller_period = 0.004
        initial_position = [0.0, 0.0, 0.0]
        [team]
        preset = "a4-con"
        [reference]
        kind = "hover"
        position = [0.0, 0.0, 1.0]
        "#
    ))
    .unwrap()
}

fn flight(instance: u8, duration: f64, log: Option<PathBuf>) -> Px4Flight {
    Px4Flight {
        scenario: scenario(duration),
        plan: FlightPlan::from_toml_str("[mapping]\nlayout = \"quad\"\n").unwrap(),
        instance,
        log,
        launch: None,
        pacing: Pacing::Lockstep,
        connect_timeout: Duration::from_secs(10),
        stall_timeout: Duration::from_millis(500),
        boot_timeout: Duration::from_secs(10),
    }
}

fn temp_log(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("tvmd-px4-{name}-{}.mcap", std::process::id()))
}

/// The fake PX4's clock.
#[derive(Clone, Copy)]
enum Clock {
    /// Lockstep: the sensors' time, the lockstep flag set (PX4's default SITL build).
    Lockstep,
    /// Its own wall clock from a large start (the host's uptime), no lockstep flag (a build
    /// without lockstep).
    Wall,
}

/// The fake PX4's clock at a start of 1000 s (PX4 without lockstep reads the host's uptime).
const WALL_START_USEC: u64 = 1_000_000_000;

/// Connects to the bridge and answers each HIL_SENSOR with `throttle` on the four motors, its
/// controls stamped by `clock`; returns the first and the last accelerometer z read (FRD,
/// m/s^2) and the sensors answered.
fn fake_px4(
    port: u16,
    throttle: f32,
    answer: usize,
    then: Then,
    clock: Clock,
) -> (f32, f32, usize) {
    let start = Instant::now();
    let stream = loop {
        match TcpStream::connect(("127.0.0.1", port)) {
            Ok(s) => break s,
            Err(_) if start.elapsed() < Duration::from_secs(10) => {
                thread::sleep(Duration::from_millis(5))
            }
            Err(e) => panic!("cannot connect to the bridge: {e}"),
        }
    };
    let mut writer = stream.try_clone().unwrap();
    let mut reader = MavlinkReader::new(stream);
    let (mut first, mut last, mut answered) = (f32::NAN, f32::NAN, 0);
    let connected = Instant::now();
    loop {
        let message = match reader.read_any_message::<MavMessage>() {
            Ok((_, m)) => m,
            Err(mavlink::error::MessageReadError::Io(e))
                if matches!(
                    e.kind(),
                    ErrorKind::UnexpectedEof | ErrorKind::ConnectionReset
                ) =>
            {
                return (first, last, answered)
            }
            Err(e) => panic!("fake PX4 read: {e:?}"),
        };
        let MavMessage::HIL_SENSOR(sensor) = message else {
            continue;
        };
        if first.is_nan() {
            first = sensor.zacc;
        }
        last = sensor.zacc;
        if answered == answer {
            match then {
                Then::Fly => {}
                Then::Die => return (first, last, answered),
                Then::Hang => {
                    thread::sleep(Duration::from_secs(3));
                    return (first, last, answered);
                }
            }
        }
        let mut controls = [0f32; 16];
        controls[..4].fill(throttle);
        let (time_usec, flags) = match clock {
            Clock::Lockstep => (
                sensor.time_usec,
                HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
            ),
            Clock::Wall => (
                WALL_START_USEC + connected.elapsed().as_micros() as u64,
                HilActuatorControlsFlags::empty(),
            ),
        };
        let reply = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
            time_usec,
            controls,
            mode: MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED,
            flags,
        });
        let header = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: 0,
        };
        if mavlink::write_versioned_msg(&mut writer, MavlinkVersion::V2, header, &reply).is_err() {
            return (first, last, answered);
        }
        answered += 1;
    }
}

fn fly(
    f: Px4Flight,
    throttle: f32,
    answer: usize,
    then: Then,
) -> (Px4Report, Option<Px4Error>, (f32, f32, usize)) {
    fly_clocked(f, throttle, answer, then, Clock::Lockstep)
}

fn fly_clocked(
    f: Px4Flight,
    throttle: f32,
    answer: usize,
    then: Then,
    clock: Clock,
) -> (Px4Report, Option<Px4Error>, (f32, f32, usize)) {
    let port = 4560 + u16::from(f.instance);
    let px4 = thread::spawn(move || fake_px4(port, throttle, answer, then, clock));
    let (report, error) = fly_px4(&f, &mut |_| {}).expect("the flight starts");
    (report, error, px4.join().unwrap())
}

#[test]
fn lockstep_flight_climbs_on_px4s_throttle_and_logs_every_tick() {
    let log = temp_log("lockstep");
    // 0.6 of each agent's sigma_Tf = 2 m_i g lifts the team at 0.2 g.
    let (report, error, (first, last, answered)) = fly(
        flight(201, 2.0, Some(log.clone())),
        0.6,
        usize::MAX,
        Then::Fly,
    );
    assert!(error.is_none(), "{error:?}");
    // Every tick answered in lockstep: 2 s at 250 Hz.
    assert_eq!(answered, 500);
    assert_eq!(report.lockstep.lockstep_from, Some(0.0));
    assert_eq!(report.lockstep.lockstep_ticks, 500);
    assert_eq!(report.lockstep.stale_controls, 0);
    // At rest the accelerometer reads -g (FRD z down); climbing, -1.2 g.
    assert!((first + 9.81).abs() < 0.2, "{first}");
    assert!((last + 1.2 * 9.81).abs() < 0.3, "{last}");
    // 0.2 g for 2 s: about 3.9 m up.
    let z = report.summary.as_ref().unwrap().final_position[2];
    assert!((z - 3.9).abs() < 0.3, "{z}");
    let run = tvmd_log::read_run(&log).unwrap();
    assert_eq!(run.ticks.len(), 500);
    std::fs::remove_file(&log).ok();
}

#[test]
fn px4_killed_mid_flight_ends_the_run_naming_px4_with_a_readable_log() {
    let log = temp_log("killed");
    let (report, error, (_, _, answered)) =
        fly(flight(202, 5.0, Some(log.clone())), 0.55, 100, Then::Die);
    assert_eq!(answered, 100);
    let error = error.expect("the run must fail").to_string();
    assert!(
        error.contains("PX4 closed the simulator connection"),
        "{error}"
    );
    assert!(report.error.as_deref() == Some(error.as_str()));
    assert!((report.sim_time - 0.4).abs() < 0.01, "{}", report.sim_time);
    let run = tvmd_log::read_run(&log).unwrap();
    assert_eq!(run.ticks.len(), 100);
    assert!(run.metadata.contains_key(tvmd_log::METADATA_RESULT));
    std::fs::remove_file(&log).ok();
}

#[test]
fn px4_hung_mid_flight_is_a_stall_with_a_readable_log() {
    let log = temp_log("stalled");
    let (report, error, _) = fly(flight(203, 5.0, Some(log.clone())), 0.55, 50, Then::Hang);
    let error = error.expect("the run must fail").to_string();
    assert!(
        error.contains("PX4 stalled") && error.contains("t = 0.200 s"),
        "{error}"
    );
    assert!((report.sim_time - 0.2).abs() < 0.01);
    assert_eq!(tvmd_log::read_run(&log).unwrap().ticks.len(), 50);
    std::fs::remove_file(&log).ok();
}

#[test]
fn px4_that_never_connects_is_named() {
    let mut f = flight(204, 1.0, None);
    f.connect_timeout = Duration::from_millis(300);
    let error = match fly_px4(&f, &mut |_| {}) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("nothing connected"),
    };
    assert!(
        error.contains("PX4 did not connect to TCP port 4764"),
        "{error}"
    );
}

#[test]
fn a_port_in_use_is_a_clear_error() {
    let taken = std::net::TcpListener::bind(("127.0.0.1", 4565 + 200)).unwrap();
    let f = flight(205, 1.0, None);
    let error = match fly_px4(&f, &mut |_| {}) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("the port is taken"),
    };
    assert!(
        error.contains("cannot listen for PX4 on TCP port 4765"),
        "{error}"
    );
    assert!(error.contains("--instance"), "{error}");
    drop(taken);
}

#[test]
fn real_time_flight_paces_the_wall_clock_and_applies_px4s_newest_controls() {
    let mut f = flight(206, 1.0, None);
    f.pacing = Pacing::RealTime;
    let (report, error, (first, last, answered)) =
        fly_clocked(f, 0.6, usize::MAX, Then::Fly, Clock::Wall);
    assert!(error.is_none(), "{error:?}");
    assert_eq!(report.pacing, Pacing::RealTime);
    // One tick a period on the wall clock: 1 s simulated takes at least 1 s (a tick is never
    // sent before its time), and every one of the 250 sensors reached PX4 (its answer to the
    // last may meet the link closed: the bridge does not wait for it).
    assert!(report.wall_time >= 1.0 - 0.004, "{}", report.wall_time);
    assert!((249..=250).contains(&answered), "{answered}");
    // Nothing waits for PX4: the first tick flies idle (its controls come after it), the
    // later ones the newest controls received.
    let from = report.lockstep.lockstep_from.expect("controls received");
    assert!((0.004..0.5).contains(&from), "{from}");
    assert_eq!(report.lockstep.stale_controls, 0);
    // PX4's clock read from the controls' stamps: its 1000 s at the connection, which comes a
    // little before the first tick (the bridge's set-up), less the loopback's latency (the
    // least over 250 answers).
    let offset = report
        .lockstep
        .px4_clock_offset
        .expect("PX4's clock learnt");
    assert!(offset > 999.9 && offset < 1002.0, "{offset}");
    assert!((first + 9.81).abs() < 0.2, "{first}");
    assert!((last + 1.2 * 9.81).abs() < 0.3, "{last}");
    // 0.2 g from the second tick for 1 s: about 1 m up.
    let z = report.summary.as_ref().unwrap().final_position[2];
    assert!((z - 0.98).abs() < 0.1, "{z}");
}

#[test]
fn a_build_and_a_pacing_that_disagree_are_named() {
    // PX4 without lockstep, the bridge in lockstep.
    let (_, error, _) = fly_clocked(
        flight(207, 1.0, None),
        0.5,
        usize::MAX,
        Then::Fly,
        Clock::Wall,
    );
    let error = error.expect("the run must fail").to_string();
    assert!(
        error.contains("PX4 runs without lockstep") && error.contains("--real-time"),
        "{error}"
    );
    // PX4 in lockstep, the bridge in real time.
    let mut f = flight(208, 1.0, None);
    f.pacing = Pacing::RealTime;
    let (_, error, _) = fly_clocked(f, 0.5, usize::MAX, Then::Fly, Clock::Lockstep);
    let error = error.expect("the run must fail").to_string();
    assert!(
        error.contains("PX4 runs in lockstep") && error.contains("px4_sitl_default"),
        "{error}"
    );
}
