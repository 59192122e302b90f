//! One flight with PX4: the scenario's simulation, its MCAP log, the bridge as its controller,
//! PX4 started from a tree or connecting by itself, and the flight's report.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use serde::Serialize;
use tvmd_log::RunLog;
use tvmd_scenario::Scenario;
use tvmd_sim::load::write_result_metadata;
use tvmd_sim::runner::write_scenario_metadata;
use tvmd_sim::{McapSink, RunSummary, SampleRetention, SimOptions, Simulation, TickSink, Verdict};

use crate::bridge::{Bridge, BridgeTiming, LockstepStats, Pacing};
use crate::flight::FlightPlan;
use crate::gcs::GcsLink;
use crate::launch::{Px4Launch, Px4Process};
use crate::link::{Listener, BASE_PORT};
use crate::mapping::ControlMapping;
use crate::measure::{Events, WindowReport};
use crate::Px4Error;

/// A flight to fly.
#[derive(Clone, Debug)]
pub struct Px4Flight {
    /// The scenario: team, plant, disturbances, duration, controller period (PX4's sensor
    /// period), log settings. Its reference is only logged: PX4 flies its own setpoints.
    pub scenario: Scenario,
    /// The flight file.
    pub plan: FlightPlan,
    /// PX4's instance (ports 4560 + instance and 18570 + instance).
    pub instance: u8,
    /// The MCAP log to write.
    pub log: Option<PathBuf>,
    /// PX4 to start; `None`: wait for a PX4 started by the user.
    pub launch: Option<Px4Launch>,
    /// Wall time to wait for PX4 to connect.
    pub connect_timeout: Duration,
    /// Lockstep (PX4's default SITL build) or real time (a build without lockstep).
    pub pacing: Pacing,
    /// Wall time PX4 may take to answer one tick in lockstep.
    pub stall_timeout: Duration,
    /// Wall time PX4 may take from connecting to its first actuator controls.
    pub boot_timeout: Duration,
}

/// What a flight with PX4 showed.
#[derive(Clone, Debug, Serialize)]
pub struct Px4Report {
    /// The scenario's name.
    pub scenario: String,
    /// The flight file's description.
    pub flight: String,
    /// PX4's events.
    pub events: Events,
    /// The measured windows.
    pub windows: Vec<WindowReport>,
    /// PX4's status texts: simulated time, severity, text.
    pub texts: Vec<(f64, u8, String)>,
    /// PX4's texts that name a failsafe.
    pub failsafe_texts: Vec<String>,
    /// Estimator samples matched to the truth (position, attitude).
    pub estimator_samples: (usize, usize),
    /// How the bridge kept time with PX4.
    pub pacing: Pacing,
    /// The lockstep's accounting.
    pub lockstep: LockstepStats,
    /// Simulated seconds per wall second while in lockstep.
    pub realtime_factor: Option<f64>,
    /// Simulated time flown (s).
    pub sim_time: f64,
    /// Wall time of the flight from PX4's connection (s).
    pub wall_time: f64,
    /// The run's summary (truth against the scenario's reference); none on SIH.
    pub summary: Option<RunSummary>,
    /// The MCAP log.
    pub log: Option<String>,
    /// PX4's ulog, copied beside the MCAP log.
    pub ulog: Option<String>,
    /// The error that ended the flight, if any.
    pub error: Option<String>,
}

/// Flies `flight`: listens on the simulator port, starts PX4 if asked, waits for it, flies the
/// scenario in lockstep, writes the log (also when the flight fails: what flew), stops PX4 and
/// keeps its ulog beside the log. `on_listen(port)` is called once the port is open.
///
/// `Err` when the flight could not start (bad settings, the port, PX4 never connecting); a
/// flight that started returns its report and, if it ended early, the error.
pub fn fly_px4(
    flight: &Px4Flight,
    on_listen: &mut dyn FnMut(u16),
) -> Result<(Px4Report, Option<Px4Error>), Px4Error> {
    let scenario = &flight.scenario;
    if scenario.disturbances.state_noise.is_some() {
        return Err(Px4Error::Config {
            field: "disturbances.state_noise".into(),
            reason: "PX4 reads sensors, not the state: give their noise in the flight file's \
                     [sensors] and leave the scenario's state noise out"
                .into(),
        });
    }
    scenario.validate().map_err(tvmd_sim::SimError::from)?;
    let team = scenario.team_body().map_err(tvmd_sim::SimError::from)?;
    let max_thrust = scenario.max_thrust().map_err(tvmd_sim::SimError::from)?;
    let mapping = ControlMapping::new(&flight.plan.mapping, team.len(), max_thrust)?;
    let mut sim = Simulation::with_options(
        scenario,
        SimOptions {
            samples: SampleRetention::None,
        },
    )?;
    let listener = Listener::bind(BASE_PORT + u16::from(flight.instance))?;
    on_listen(listener.port());
    let mut px4 = flight.launch.as_ref().map(Px4Process::start).transpose()?;
    let link = listener.accept(flight.connect_timeout, &mut || match px4.as_mut() {
        Some(p) => p.check_running(),
        None => Ok(()),
    })?;
    let gcs = GcsLink::new(flight.instance)?;
    let timing = BridgeTiming {
        period: scenario.controller_period,
        pacing: flight.pacing,
        stall_timeout: flight.stall_timeout,
        boot_timeout: flight.boot_timeout,
    };
    let mut bridge = Bridge::new(link, gcs, flight.plan.clone(), mapping, timing)?;
    let mut log = match &flight.log {
        Some(path) => {
            let mut l = RunLog::new();
            l.add_mcap(path).map_err(tvmd_sim::SimError::from)?;
            write_scenario_metadata(&mut l, scenario)?;
            Some(l)
        }
        None => None,
    };
    let start = Instant::now();
    let run = {
        let mut sink = log.as_mut().map(McapSink::new);
        let sink = sink.as_mut().map(|s| s as &mut dyn TickSink);
        sim.run(&mut bridge, sink)
    };
    let wall_time = start.elapsed().as_secs_f64();
    let (mut result, mut error) = match run {
        Ok(result) => (result, None),
        Err(e) => (sim.take_result(), Some(unwrap_px4(e))),
    };
    result.summary.controller_target = "px4-sitl".into();
    result.summary.error = error.as_ref().map(ToString::to_string);
    result.summary.verdict = Verdict::judge(&result.summary, &scenario.success);
    if let Some(l) = log.as_mut() {
        let written =
            write_result_metadata(l, &result).and(l.finish().map_err(tvmd_sim::SimError::from));
        if let (Err(e), None) = (written, error.as_ref()) {
            error = Some(e.into());
        }
    }
    let ulog = px4.take().and_then(Px4Process::stop).and_then(|ulog| {
        let log = flight.log.as_ref()?;
        let beside = log.with_extension("ulg");
        std::fs::copy(&ulog, &beside).ok()?;
        Some(beside.display().to_string())
    });
    let stats = bridge.stats();
    let record = bridge.record();
    let windows = flight
        .plan
        .window
        .iter()
        .map(|w| record.window(w))
        .collect();
    let texts = record.texts().to_vec();
    let failsafe_texts = failsafe_texts(&texts);
    let report = Px4Report {
        scenario: scenario.name.clone(),
        flight: flight.plan.description.clone(),
        events: record.events().clone(),
        windows,
        texts,
        failsafe_texts,
        estimator_samples: record.matched(),
        realtime_factor: stats.lockstep_from.and_then(|from| {
            let simulated = result.summary.time - from;
            (stats.lockstep_wall > 0.0).then(|| simulated / stats.lockstep_wall)
        }),
        pacing: flight.pacing,
        lockstep: stats,
        sim_time: result.summary.time,
        wall_time,
        summary: Some(result.summary),
        log: flight.log.as_ref().map(|p| p.display().to_string()),
        ulog,
        error: error.as_ref().map(ToString::to_string),
    };
    Ok((report, error))
}

/// PX4's status texts that name a failsafe, with their times.
fn failsafe_texts(texts: &[(f64, u8, String)]) -> Vec<String> {
    texts
        .iter()
        .filter(|(_, _, t)| t.to_lowercase().contains("failsafe"))
        .map(|(t, _, text)| format!("{t:.2} s: {text}"))
        .collect()
}

/// The bridge's own error out of the loop's controller error, so that the message names PX4
/// first.
fn unwrap_px4(e: tvmd_sim::SimError) -> Px4Error {
    match e {
        tvmd_sim::SimError::Controller { t, source } => match source.downcast::<Px4Error>() {
            Ok(px4) => *px4,
            Err(other) => Px4Error::Sim(tvmd_sim::SimError::Controller { t, source: other }),
        },
        other => Px4Error::Sim(other),
    }
}

/// The report as pretty JSON into `path`.
pub fn write_report(path: &Path, report: &Px4Report) -> Result<(), Px4Error> {
    let text = serde_json::to_string_pretty(report).map_err(|e| Px4Error::Config {
        field: "report".into(),
        reason: e.to_string(),
    })? + "\n";
    tvmd_log::paths::write_file(path, "write the PX4 flight report", text.as_bytes())
        .map_err(|e| Px4Error::Sim(e.into()))
}

/// Flies `plan`'s script on PX4's own simulator (SIH, real time) for `duration` seconds of
/// PX4's time: the comparison flight of a PX4 airframe without tvmd-sim. No truth reaches the
/// bridge: the flight is measured from its ulog (PX4's ground truth topics). Returns PX4's
/// events, texts and the ulog copied to `ulog`.
pub fn fly_sih(
    plan: &FlightPlan,
    launch: &Px4Launch,
    duration: f64,
    ulog: &Path,
) -> Result<Px4Report, Px4Error> {
    let mut px4 = Px4Process::start(launch)?;
    let mut gcs = GcsLink::new(launch.instance)?;
    let mut script = crate::script::Script::new(plan);
    let mut record = crate::measure::FlightRecord::new(plan.home);
    let start = Instant::now();
    // PX4's time: the newest time stamp of its messages.
    let mut t = 0.0f64;
    let mut heard = false;
    let limit = Duration::from_secs_f64(duration * 3.0 + 120.0);
    while t < duration {
        if start.elapsed() > limit {
            return Err(Px4Error::Stalled {
                t,
                waited: start.elapsed().as_secs_f64(),
            });
        }
        px4.check_running()?;
        for message in gcs.poll()? {
            if let crate::gcs::Telemetry::LocalPosition { t: tm, .. }
            | crate::gcs::Telemetry::Attitude { t: tm, .. } = message
            {
                t = t.max(tm);
            }
            record.telemetry(t, message);
        }
        let s = gcs.state();
        heard |= s.heartbeats > 0;
        record.px4_state(t, s.armed, s.landed_state, heard);
        // Until PX4 streams its time, a heartbeat now and then makes it talk to us.
        if t == 0.0 {
            gcs.heartbeat()?;
        } else {
            script.advance(t, &mut gcs)?;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let wall_time = start.elapsed().as_secs_f64();
    let copied = px4.stop().and_then(|u| {
        std::fs::copy(&u, ulog)
            .ok()
            .map(|_| ulog.display().to_string())
    });
    let texts = record.texts().to_vec();
    Ok(Px4Report {
        scenario: "sih".into(),
        flight: plan.description.clone(),
        events: record.events().clone(),
        windows: Vec::new(),
        failsafe_texts: failsafe_texts(&texts),
        texts,
        estimator_samples: (0, 0),
        pacing: Pacing::RealTime,
        lockstep: LockstepStats::default(),
        realtime_factor: Some(t / wall_time),
        sim_time: t,
        wall_time,
        summary: None,
        log: None,
        ulog: copied,
        error: None,
    })
}
