//! Running scenarios with the tvmd controller: one run ([`run_scenario`], optionally logging to
//! an MCAP file) and batches on one worker pool ([`run_many`], [`relaxation_sweep`]), which the
//! command line and the Python module call.

use std::any::Any;
use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use crate::control::recording::Recorder;
use crate::control::TvmdController;
use crate::control::{core_of_scenario, wire_config, AnyTvmdController, CoreController};
use crate::error::BoxedError;
use crate::flight::{FlightController, FlightInput, FlightOutput};
use crate::load::write_result_metadata;
use crate::sim::summary::Verdict;
use crate::sim::{RunResult, SampleRetention, SimOptions, Simulation};
use crate::sink::TickSink;
use crate::tick_log::McapSink;
use crate::SimError;
use tvmd_log::{LiveOptions, RunLog, METADATA_SCENARIO};
use tvmd_pil::{CycleRecording, PilTarget};
use tvmd_scenario::{Precision, Scenario};

/// A controller that reports the time of every call to a callback (for progress bars).
pub struct WithProgress<'a> {
    inner: &'a mut dyn FlightController,
    progress: &'a mut dyn FnMut(f64),
}

impl<'a> WithProgress<'a> {
    /// Wraps `inner`; `progress(t)` is called before each controller call.
    pub fn new(inner: &'a mut dyn FlightController, progress: &'a mut dyn FnMut(f64)) -> Self {
        Self { inner, progress }
    }
}

impl FlightController for WithProgress<'_> {
    fn step(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, BoxedError> {
        (self.progress)(input.t);
        self.inner.step(input)
    }
}

/// Writes the scenario into the log's metadata record [`METADATA_SCENARIO`].
pub fn write_scenario_metadata(log: &mut RunLog, scenario: &Scenario) -> Result<(), SimError> {
    let mut meta = BTreeMap::new();
    meta.insert("name".to_string(), scenario.name.clone());
    meta.insert("relaxation".to_string(), scenario.relaxation.to_string());
    meta.insert("allocator".to_string(), scenario.allocator.clone());
    meta.insert(
        "controller_precision".to_string(),
        scenario.controller_precision.to_string(),
    );
    meta.insert("toml".to_string(), scenario.to_toml_string()?);
    Ok(log.write_metadata(METADATA_SCENARIO, meta)?)
}

/// Runs `scenario` with [`AnyTvmdController`] (in the scenario's `controller_precision`) to its end.
///
/// With `log`, writes an MCAP file there (parent directories created, the scenario stored as
/// metadata); the file is finalised even if the run fails. `progress(t)` is called at every
/// controller tick.
pub fn run_scenario(
    scenario: &Scenario,
    log: Option<&Path>,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<RunResult, SimError> {
    run_scenario_on(scenario, None, log, progress)
}

/// [`run_scenario`] with the controller on `target`: in process for `None`, else on the
/// emulated target ([`AnyTvmdController::from_scenario_on`]; the scenario's precision must be
/// f32). The summary's `controller_target` says which.
pub fn run_scenario_on(
    scenario: &Scenario,
    target: Option<PilTarget>,
    log: Option<&Path>,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<RunResult, SimError> {
    run_scenario_until(scenario, target, log, progress, None)
}

/// [`run_scenario_on`], stopping at the next controller tick once `cancel` is set (a signal
/// handler's flag): the log is finalised with what was simulated and the summary says
/// `interrupted`.
pub fn run_scenario_until(
    scenario: &Scenario,
    target: Option<PilTarget>,
    log: Option<&Path>,
    progress: Option<&mut dyn FnMut(f64)>,
    cancel: Option<&AtomicBool>,
) -> Result<RunResult, SimError> {
    let spec = RunSpec {
        scenario: scenario.clone(),
        log: log.map(Path::to_path_buf),
        pil: target,
        samples: SampleRetention::All,
    };
    let flight = fly(&spec, progress, cancel)?;
    match flight.error {
        Some(error) => Err(error),
        None => Ok(flight.result),
    }
}

/// A flight that started: what was simulated, and the error that ended it early, if any.
#[derive(Debug)]
pub struct Flight {
    /// The samples and summary up to the end or the failure (the summary's `error` names it).
    pub result: RunResult,
    /// The failure while flying (divergence, controller error, log write), if any.
    pub error: Option<SimError>,
}

/// Flies `spec` (its scenario, log, target and sample retention) like
/// [`run_scenario_until`], keeping a failed flight's partial result: `Err` only when the
/// flight could not start (scenario, controller or log creation).
pub fn fly(
    spec: &RunSpec,
    progress: Option<&mut dyn FnMut(f64)>,
    cancel: Option<&AtomicBool>,
) -> Result<Flight, SimError> {
    fly_live(spec, None, progress, cancel)
}

/// A live view of one flight: where to serve it, and a callback told the server's address
/// once it listens (before it waits for a client, so a caller can print it).
pub struct LiveView<'a> {
    /// Server options.
    pub options: LiveOptions,
    /// Called with the address the server listens on.
    pub on_listen: &'a mut dyn FnMut(std::net::SocketAddr),
}

/// As [`fly`], also serving the flight live over Foxglove's WebSocket protocol when `live` is
/// given (the run then goes at the server's pace, real time by default).
pub fn fly_live(
    spec: &RunSpec,
    live: Option<LiveView<'_>>,
    progress: Option<&mut dyn FnMut(f64)>,
    cancel: Option<&AtomicBool>,
) -> Result<Flight, SimError> {
    let scenario = &spec.scenario;
    let mut controller = AnyTvmdController::from_scenario_on(scenario, spec.pil)?;
    let options = SimOptions {
        samples: spec.samples,
    };
    let mut sim = Simulation::with_options(scenario, options)?;
    let mut log = match (spec.log.as_deref(), &live) {
        (None, None) => None,
        (path, _) => {
            let mut l = RunLog::new();
            if let Some(path) = path {
                l.add_mcap(path)?;
                write_scenario_metadata(&mut l, scenario)?;
            }
            Some(l)
        }
    };
    if let (Some(view), Some(log)) = (live, log.as_mut()) {
        let address = log.serve(&view.options)?;
        (view.on_listen)(address);
        if let Some(server) = log.live() {
            server.wait_for_client(cancel);
        }
    }
    let mut sink = log.as_mut().map(McapSink::new);
    let sink = sink.as_mut().map(|s| s as &mut dyn TickSink);
    let run = match progress {
        Some(p) => sim.run_until(&mut WithProgress::new(&mut controller, p), sink, cancel),
        None => sim.run_until(&mut controller, sink, cancel),
    };
    let (mut result, mut error) = match run {
        Ok(result) => (result, None),
        Err(e) => (sim.take_result(), Some(e)),
    };
    let target = controller.target_label();
    judge(&mut result, target.clone(), error.as_ref(), scenario);
    if let Some(log) = log.as_mut() {
        // The outcome goes into the file (for `load_run`) before it is finalised.
        let written = match spec.log {
            Some(_) => write_result_metadata(log, &result),
            None => Ok(()),
        };
        let finished = written.and(log.finish().map_err(SimError::from));
        if let (Err(e), None) = (finished, error.as_ref()) {
            error = Some(e);
            judge(&mut result, target, error.as_ref(), scenario);
        }
    }
    Ok(Flight { result, error })
}

/// The summary's controller target, error and verdict.
fn judge(result: &mut RunResult, target: String, error: Option<&SimError>, scenario: &Scenario) {
    result.summary.controller_target = target;
    result.summary.error = error.map(ToString::to_string);
    result.summary.verdict = Verdict::judge(&result.summary, &scenario.success);
}

/// One run of a batch: a validated scenario and the MCAP log to write, if any.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSpec {
    /// The scenario (overrides applied, validated).
    pub scenario: Scenario,
    /// MCAP log to write (parent directories are created).
    pub log: Option<PathBuf>,
    /// The emulated target the controller runs on (processor in the loop), or `None` for the
    /// host.
    pub pil: Option<PilTarget>,
    /// Which samples the result keeps (the summary covers every tick either way).
    pub samples: SampleRetention,
}

impl RunSpec {
    /// A run of `scenario` (overrides applied) with the controller on `pil`. On a target the
    /// controller precision becomes f32, the precision the PIL firmware runs; `precision` is
    /// the one the caller asked for explicitly, and asking for f64 on a target is an error
    /// naming `controller_precision`.
    pub fn on_target(
        mut scenario: Scenario,
        log: Option<PathBuf>,
        pil: Option<PilTarget>,
        precision: Option<Precision>,
    ) -> Result<Self, SimError> {
        if let Some(target) = pil {
            if precision == Some(Precision::F64) {
                return Err(SimError::invalid_field(
                    "controller_precision",
                    format!(
                        "the {target} PIL firmware runs the f32 controller; drop the f64 \
                         precision or the PIL target"
                    ),
                ));
            }
            if scenario.null_space.is_some() {
                return Err(SimError::invalid_field("null_space", format!(
                        "the {target} PIL firmware runs without the null-space stage; drop                          `null_space` or the PIL target"
                    )));
            }
            scenario.controller_precision = Precision::F32;
        }
        Ok(Self {
            scenario,
            log,
            pil,
            samples: SampleRetention::All,
        })
    }
}

/// A finished run of a batch: what was asked and what came out.
#[derive(Debug)]
pub struct RunOutcome {
    /// The run.
    pub spec: RunSpec,
    /// Its result; a panic inside the run is reported as [`SimError::Internal`].
    pub result: Result<RunResult, SimError>,
}

/// Progress callback of a batch: `progress(k, t)` at every controller tick of run `k`. Called
/// from the worker threads.
pub type Progress<'a> = &'a (dyn Fn(usize, f64) + Sync);

/// Worker threads for `runs` runs: `jobs` or the available cores, at least 1, at most `runs`.
pub fn worker_count(jobs: Option<usize>, runs: usize) -> usize {
    crate::pool::worker_count(jobs, runs)
}

fn panic_message(payload: &(dyn Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string())
}

/// One run of a batch, a panic caught as [`SimError::Internal`].
fn run_guarded(
    k: usize,
    spec: &RunSpec,
    progress: Option<Progress<'_>>,
    cancel: Option<&AtomicBool>,
) -> Result<RunResult, SimError> {
    let flown = catch_unwind(AssertUnwindSafe(|| match progress {
        Some(p) => fly(spec, Some(&mut |t| p(k, t)), cancel),
        None => fly(spec, None, cancel),
    }));
    match flown {
        Ok(Ok(Flight { error: Some(e), .. })) | Ok(Err(e)) => Err(e),
        Ok(Ok(Flight { result, .. })) => Ok(result),
        Err(p) => Err(SimError::Internal(panic_message(p.as_ref()))),
    }
}

/// Runs every spec with [`run_scenario`] on [`worker_count`]`(jobs, len)` threads (the calling
/// thread is one of them) and returns the outcomes in input order. Runs are independent and
/// deterministic, so the results do not depend on `jobs`.
pub fn run_many(
    specs: Vec<RunSpec>,
    jobs: Option<usize>,
    progress: Option<Progress<'_>>,
) -> Vec<RunOutcome> {
    run_many_until(specs, jobs, progress, None)
}

/// [`run_many`], stopping once `cancel` is set: the running flights stop at their next
/// controller tick (logs finalised, summaries `interrupted`), the ones not started report
/// [`SimError::Interrupted`].
pub fn run_many_until(
    specs: Vec<RunSpec>,
    jobs: Option<usize>,
    progress: Option<Progress<'_>>,
    cancel: Option<&AtomicBool>,
) -> Vec<RunOutcome> {
    let results = crate::pool::map_in_order(&specs, worker_count(jobs, specs.len()), |k, spec| {
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            Err(SimError::Interrupted)
        } else {
            run_guarded(k, spec, progress, cancel)
        }
    });
    specs
        .into_iter()
        .zip(results)
        .map(|(spec, result)| RunOutcome {
            spec,
            result: result
                .unwrap_or_else(|| Err(SimError::Internal("a run did not finish".into()))),
        })
        .collect()
}

/// The runs of a relaxation study: `base` once per `s` in `relaxations`, named
/// `<name>-s<s>`, each validated, logged to `<log_dir>/<name>-s<s>.mcap` if `log_dir` is given.
pub fn sweep_specs(
    base: &Scenario,
    relaxations: &[f64],
    log_dir: Option<&Path>,
) -> Result<Vec<RunSpec>, SimError> {
    relaxations
        .iter()
        .map(|&s| {
            let mut scenario = base.clone();
            scenario.relaxation = s;
            scenario.name = format!("{}-s{s}", base.name);
            scenario.validate()?;
            let stem = tvmd_log::paths::file_stem(&scenario.name);
            let log = log_dir.map(|d| d.join(format!("{stem}.mcap")));
            Ok(RunSpec {
                scenario,
                log,
                pil: None,
                samples: SampleRetention::All,
            })
        })
        .collect()
}

/// Checks a batch's logs before any run starts ([`tvmd_log::paths::check_outputs`]): two runs
/// writing one file would corrupt it, and `extra` outputs (a summary) must differ from them.
pub fn check_batch_outputs(specs: &[RunSpec], extra: &[(String, &Path)]) -> Result<(), SimError> {
    check_batch_paths(specs, extra, &[])
}

/// [`check_batch_outputs`], and no log or `extra` output is one of `inputs` (the batch's
/// scenario files, `(role, path)`).
pub fn check_batch_paths(
    specs: &[RunSpec],
    extra: &[(String, &Path)],
    inputs: &[(String, &Path)],
) -> Result<(), SimError> {
    let mut outputs: Vec<(String, &Path)> = specs
        .iter()
        .enumerate()
        .filter_map(|(k, s)| {
            Some((
                format!("the log of run {k} ({})", s.scenario.name),
                s.log.as_deref()?,
            ))
        })
        .collect();
    outputs.extend(extra.iter().cloned());
    Ok(tvmd_log::paths::check_outputs(&outputs, inputs)?)
}

/// The relaxation study: [`sweep_specs`] flown by [`run_many`]. An invalid `s` or a log path
/// given twice (the same `s` twice) is an error before any run starts.
pub fn relaxation_sweep(
    base: &Scenario,
    relaxations: &[f64],
    log_dir: Option<&Path>,
    jobs: Option<usize>,
    progress: Option<Progress<'_>>,
) -> Result<Vec<RunOutcome>, SimError> {
    let specs = sweep_specs(base, relaxations, log_dir)?;
    check_batch_outputs(&specs, &[])?;
    Ok(run_many(specs, jobs, progress))
}

/// Flies `scenario` with its f32 controller wrapped in a [`Recorder`] (whatever its `controller_precision`) and records
/// its first `cycles` control cycles. Errors: the scenario's, the flight's, or a flight with
/// fewer core cycles than asked.
pub fn record_cycles(scenario: &Scenario, cycles: usize) -> Result<CycleRecording, SimError> {
    let scenario = Scenario {
        controller_precision: Precision::F32,
        ..scenario.clone()
    };
    let config = wire_config(&scenario)?;
    let (core, n) = core_of_scenario::<f32>(&scenario)?;
    let mut controller: TvmdController<f32, Recorder<CoreController<f32>>> =
        TvmdController::new(Recorder::new(core, n), n).for_scenario(&scenario);
    let mut sim = Simulation::with_options(&scenario, SimOptions::default())?;
    sim.run(&mut controller, None)?;
    let recorder = controller.engine();
    if recorder.cycles() < cycles {
        return Err(SimError::invalid_field(
            "duration",
            format!(
                "the flight ran {} core cycles, fewer than the {cycles} to record",
                recorder.cycles()
            ),
        ));
    }
    Ok(recorder.recording(config, cycles))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicUsize;

    fn short(name: &str, relaxation: f64) -> Scenario {
        Scenario {
            name: name.into(),
            duration: 0.2,
            relaxation,
            ..Scenario::default()
        }
    }

    #[test]
    fn worker_count_is_clamped_to_the_runs() {
        assert_eq!(worker_count(Some(8), 3), 3);
        assert_eq!(worker_count(Some(0), 3), 1);
        assert_eq!(worker_count(Some(2), 0), 1);
        assert!(worker_count(None, 64) >= 1);
    }

    #[test]
    fn run_many_keeps_input_order_and_matches_single_runs() {
        let specs: Vec<RunSpec> = [("a", 0.25), ("b", 1.0), ("c", 0.5)]
            .iter()
            .map(|&(n, s)| RunSpec {
                scenario: short(n, s),
                log: None,
                pil: None,
                samples: SampleRetention::All,
            })
            .collect();
        let ticks = AtomicUsize::new(0);
        let outcomes = run_many(
            specs.clone(),
            Some(2),
            Some(&|_, _| {
                ticks.fetch_add(1, Ordering::Relaxed);
            }),
        );
        assert_eq!(ticks.into_inner(), 3 * 20);
        for (spec, outcome) in specs.iter().zip(&outcomes) {
            assert_eq!(&outcome.spec, spec);
            let single = run_scenario(&spec.scenario, None, None).unwrap();
            let batch = outcome.result.as_ref().unwrap();
            assert_eq!(batch.samples, single.samples);
            assert_eq!(batch.summary.scenario, spec.scenario.name);
        }
        assert!(run_many(Vec::new(), None, None).is_empty());
    }

    #[test]
    fn sweep_specs_name_log_and_validate_each_relaxation() {
        let base = short("base", 0.5);
        let specs = sweep_specs(&base, &[0.25, 1.0], Some(Path::new("logs"))).unwrap();
        let names: Vec<&str> = specs.iter().map(|s| s.scenario.name.as_str()).collect();
        assert_eq!(names, ["base-s0.25", "base-s1"]);
        assert_eq!(specs[1].scenario.relaxation, 1.0);
        assert_eq!(
            specs[0].log.as_deref(),
            Some(Path::new("logs/base-s0.25.mcap"))
        );
        let e = relaxation_sweep(&base, &[0.5, 1.5], None, None, None).unwrap_err();
        assert!(
            matches!(&e, SimError::Scenario(tvmd_scenario::ScenarioError::InvalidScenario { field, .. }) if field == "relaxation"),
            "{e}"
        );
    }
}
