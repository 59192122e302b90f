//! `tvmd-sim`: run the paper's simulation (and other scenarios) with the tvmd controller, the
//! relaxation study, and plots.
//!
//! ```text
//! tvmd-sim run [SCENARIO|FILE.toml] [--out run.mcap | --no-log] [--plots DIR] [--summary FILE]
//!              [--relaxation S] [--allocator NAME] [--null-space margin|inward-tilt=RAD]
//!              [--precision f64|f32]
//!              [--pil cortex-m4|cortex-m7]
//! tvmd-sim sweep [--relaxations 0.25,0.5,0.75,1.0] [--scenario NAME|FILE] [--plots DIR]
//!                [--allocator NAME] [--precision f64|f32]
//! tvmd-sim plot RUN.mcap [MORE.mcap ...] --out DIR
//! tvmd-sim record-cycles [SCENARIO|FILE.toml] --out FILE [--cycles 1000] [--allocator NAME]
//! tvmd-sim allocation-set [--out benches/data/allocation_set.json] [--seed 16]
//! tvmd-sim allocation-eval [--set benches/data/allocation_set.json] [--allocators A,B]
//!                          [--closed-loop] [--json FILE]
//! tvmd-sim afs TEAM|all [--failed I | --each-failure] [--plots DIR] [--json FILE]
//! tvmd-sim list
//! tvmd-sim show NAME
//! ```
//!
//! SIGINT or SIGTERM during `run` or `sweep` stops the flights at their next controller tick:
//! the MCAP logs are finalised and the summary written with what was simulated (marked
//! `interrupted`), and the exit status is 130. A second signal exits at once.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use tvmd_sim::allocation_bench;
use tvmd_sim::control::hover_roll_limit;
use tvmd_sim::control::pil::PilTarget;
use tvmd_sim::log::LiveOptions;
use tvmd_sim::paths::{check_outputs, create_parent, file_stem};
use tvmd_sim::plot::{self, PlotSeries};
use tvmd_sim::runner::{
    check_batch_outputs, fly_live, record_cycles, run_many_until, sweep_specs, Flight, LiveView,
    RunSpec,
};
use tvmd_sim::scenario::{Overrides, Precision, Scenario, BUILTIN_NAMES};
use tvmd_sim::sim::{PaperMetrics, RunSummary, SampleRetention};
use tvmd_sim::SimError;

/// mimalloc rather than glibc's malloc: rapier allocates and frees solver buffers every physics
/// step, and a logged run's tick records are freed on the log's writer thread, which made glibc's
/// arenas contend (BENCHMARKS.md, "Simulator real-time factor").
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Simulator of thrust-vectoring modular team UAVs with the tvmd controller in the loop.
#[derive(Parser, Debug)]
#[command(name = "tvmd-sim", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// The AFS atlas of a catalogue team: the exact attainable lateral forces (bracketed)
    /// against the elliptic cone, and the certified relaxation s* (docs/afs-atlas.md).
    Afs(tvmd_sim::afs_atlas::cli::AfsArgs),
    /// A Monte Carlo study: the scenario flown --runs times per team, allocator and
    /// model-error level with model errors and initial conditions drawn from stated
    /// distributions (docs/method.md, "Monte Carlo"); prints the success rate and writes
    /// flights.csv, groups.csv and box plots.
    Montecarlo(tvmd_sim::montecarlo::cli::MonteCarloArgs),
    /// Every catalogue team with every allocator through a step, wind, a one-agent failure
    /// and model error: the README's results table (Markdown on stdout).
    Catalogue(tvmd_sim::montecarlo::catalogue::CatalogueArgs),
    /// Run one scenario with the tvmd controller; print a summary, write the MCAP log, the
    /// summary JSON and (with --plots) the figures.
    Run {
        /// A built-in scenario name (see `tvmd-sim list`) or a TOML file.
        #[arg(default_value = "paper-tilt")]
        scenario: String,
        /// MCAP log to write (default: out/<scenario name>.mcap).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Do not write an MCAP log.
        #[arg(long, conflicts_with = "out")]
        no_log: bool,
        /// Directory for the PNG figures (state profile, Lyapunov candidates).
        #[arg(long)]
        plots: Option<PathBuf>,
        /// Summary JSON to write (default: beside the log as <log stem>.summary.json; none with
        /// --no-log).
        #[arg(long)]
        summary: Option<PathBuf>,
        /// Override the scenario's planner relaxation s.
        #[arg(long)]
        relaxation: Option<f64>,
        /// Override the scenario's allocator (exact-boundary-redistribution, the default;
        /// redistributed-pseudo-inverse, pseudo-inverse, weighted-pseudo-inverse, clarabel,
        /// clarabel-sequential).
        #[arg(long)]
        allocator: Option<String>,
        /// Run a null-space stage after the allocator: `margin`, or `inward-tilt=<rad>`
        /// (the scenario's `null_space`; see docs/method.md, "Null-space stage").
        #[arg(long, value_name = "OBJECTIVE")]
        null_space: Option<tvmd_sim::scenario::NullSpaceConfig>,
        /// Fly the scenario with a catalogue team instead of its own (`team.preset`: a3-con,
        /// a4-inc, a6-inc, ..., t10-con; see `tvmd-sim afs`).
        #[arg(long)]
        team: Option<String>,
        /// Override the scenario's controller precision: f64, or f32 (the flight
        /// configuration, `tvmd_core::Controller<f32, ..>`); the physics stays f64.
        #[arg(long, value_parser = ["f64", "f32"])]
        precision: Option<String>,
        /// Processor in the loop: run the f32 controller on an emulated target (QEMU
        /// mps2-an386 for cortex-m4, mps2-an500 for cortex-m7) while the physics stays here.
        /// Needs qemu-system-arm and the PIL firmware (`bash scripts/pil.sh build`, or
        /// TVMD_PIL_FIRMWARE=ELF).
        #[arg(long, value_parser = ["cortex-m4", "cortex-m7"])]
        pil: Option<String>,
        /// Serve the run live over Foxglove's WebSocket protocol (Foxglove app: Open
        /// connection -> Foxglove WebSocket -> ws://127.0.0.1:8765) at real-time pace.
        #[arg(long)]
        live: bool,
        /// Address the live server binds (127.0.0.1: this machine only).
        #[arg(long, default_value = "127.0.0.1", requires = "live")]
        live_host: String,
        /// Port of the live server (0: any free port, printed at start).
        #[arg(long, default_value_t = 8765, requires = "live")]
        live_port: u16,
        /// Simulated seconds per wall second of the live run.
        #[arg(long, default_value_t = 1.0, requires = "live")]
        live_speed: f64,
        /// Seconds to wait for a Foxglove client before flying (0: fly at once).
        #[arg(long, default_value_t = 60.0, requires = "live")]
        live_wait: f64,
    },
    /// Record the first control cycles of a scenario's f32 flight (the core's exact inputs and
    /// the host's outputs) for the target tests; the committed recording is
    /// `crates/tvmd-sim/tests/data/paper_tilt_f32.cycles`.
    RecordCycles {
        /// A built-in scenario name or a TOML file.
        #[arg(default_value = "paper-tilt")]
        scenario: String,
        /// File to write.
        #[arg(long)]
        out: PathBuf,
        /// Consecutive control cycles to record, from the first.
        #[arg(long, default_value_t = 1000)]
        cycles: usize,
        /// Override the scenario's allocator (the committed recording pins
        /// redistributed-pseudo-inverse, the paper's cycle).
        #[arg(long)]
        allocator: Option<String>,
    },
    /// The relaxation study: the scenario flown once per relaxation s (in parallel threads).
    Sweep {
        /// Relaxations s, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "0.25,0.5,0.75,1.0")]
        relaxations: Vec<f64>,
        /// A built-in scenario name or a TOML file.
        #[arg(long, default_value = "paper-tilt")]
        scenario: String,
        /// Directory for the relaxation-study figure (relaxation.png).
        #[arg(long)]
        plots: Option<PathBuf>,
        /// Directory for one MCAP log per run (<scenario>-s<s>.mcap); none by default.
        #[arg(long)]
        logs: Option<PathBuf>,
        /// JSON file for the table.
        #[arg(long)]
        summary: Option<PathBuf>,
        /// Worker threads (default: available cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Override the scenario's controller precision: f64, or f32 (the flight
        /// configuration, `tvmd_core::Controller<f32, ..>`); the physics stays f64.
        #[arg(long, value_parser = ["f64", "f32"])]
        precision: Option<String>,
        /// Override the scenario's allocator (as `run --allocator`).
        #[arg(long)]
        allocator: Option<String>,
    },
    /// Re-plot runs from their MCAP logs: figures of each run, and the relaxation-study figure
    /// when several logs are given.
    Plot {
        /// MCAP logs written by `tvmd-sim run` or `sweep --logs`.
        #[arg(required = true)]
        logs: Vec<PathBuf>,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
    },
    /// Write the seeded allocation benchmark set (attainable and certified-outside requests for
    /// A4-Inc, A6-Inc, A8-Inc, a 16-agent ring and A4-Inc with agent 1 failed).
    AllocationSet {
        /// File to write.
        #[arg(long, default_value = tvmd_sim::allocation_bench::SET_PATH)]
        out: PathBuf,
        /// Seed of the generator.
        #[arg(long, default_value_t = tvmd_sim::allocation_bench::SEED)]
        seed: u64,
    },
    /// Evaluate allocators on the allocation set and print markdown tables.
    AllocationEval {
        /// The set file.
        #[arg(long, default_value = tvmd_sim::allocation_bench::SET_PATH)]
        set: PathBuf,
        /// Allocators, comma-separated (default: every allocator of this build).
        #[arg(long, value_delimiter = ',')]
        allocators: Vec<String>,
        /// Also fly paper-tilt at s = 1 with each allocator.
        #[arg(long)]
        closed_loop: bool,
        /// JSON file for the rows.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// List the built-in scenarios.
    List,
    /// Print a built-in scenario as TOML (a starting point for a scenario file).
    Show {
        /// Built-in scenario name.
        name: String,
    },
}

/// Set by SIGINT / SIGTERM: runs stop at their next controller tick.
static INTERRUPT: AtomicBool = AtomicBool::new(false);

/// Exit status after an interrupt (128 + SIGINT).
const INTERRUPTED_STATUS: u8 = 130;

/// Makes SIGINT / SIGTERM set [`INTERRUPT`] (a second one exits at once), for the commands
/// that fly: the others keep the default, immediate exit.
fn catch_interrupts() {
    // If no handler can be installed, a signal still ends the run, only without its log's
    // footer.
    let _ = ctrlc::set_handler(|| {
        if INTERRUPT.swap(true, Ordering::SeqCst) {
            std::process::exit(i32::from(INTERRUPTED_STATUS));
        }
    });
}

/// Errors of the command line.
#[derive(Debug)]
enum CliError {
    Sim(SimError),
    Other(String),
    /// Stopped by a signal; what was simulated has been written.
    Interrupted(String),
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Sim(e) => write!(f, "{e}"),
            Self::Other(m) | Self::Interrupted(m) => write!(f, "{m}"),
        }
    }
}

impl From<SimError> for CliError {
    fn from(e: SimError) -> Self {
        Self::Sim(e)
    }
}

impl From<std::io::Error> for CliError {
    fn from(e: std::io::Error) -> Self {
        Self::Sim(SimError::Io(e))
    }
}

impl From<serde_json::Error> for CliError {
    fn from(e: serde_json::Error) -> Self {
        Self::Sim(SimError::Json(e))
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Afs(args) => tvmd_sim::afs_atlas::cli::run(&args)
            .map(|(_, table)| print!("{table}"))
            .map_err(CliError::Sim),
        Command::Montecarlo(args) => cmd_montecarlo(&args),
        Command::Catalogue(args) => tvmd_sim::montecarlo::catalogue::run_and_write(&args)
            .map(|table| print!("{table}"))
            .map_err(CliError::Sim),
        Command::Run {
            scenario,
            out,
            no_log,
            plots,
            summary,
            relaxation,
            allocator,
            null_space,
            team,
            precision,
            pil,
            live,
            live_host,
            live_port,
            live_speed,
            live_wait,
        } => cmd_run(RunArgs {
            scenario,
            out,
            no_log,
            plots,
            summary,
            relaxation,
            allocator,
            null_space,
            team,
            precision,
            pil,
            live: live.then_some(LiveOptions {
                host: live_host,
                port: live_port,
                speed: live_speed,
                wait_for_client: live_wait,
            }),
        }),
        Command::RecordCycles {
            scenario,
            out,
            cycles,
            allocator,
        } => cmd_record_cycles(&scenario, &out, cycles, allocator),
        Command::Sweep {
            relaxations,
            scenario,
            plots,
            logs,
            summary,
            jobs,
            precision,
            allocator,
        } => precision_arg(precision.as_deref()).and_then(|precision| {
            cmd_sweep(
                &relaxations,
                &scenario,
                Overrides {
                    precision,
                    allocator,
                    ..Overrides::default()
                },
                plots,
                logs,
                summary,
                jobs,
            )
        }),
        Command::Plot { logs, out } => cmd_plot(&logs, &out),
        Command::AllocationSet { out, seed } => allocation_bench::cli::write_set(&out, seed)
            .map(|m| println!("{m}"))
            .map_err(CliError::from),
        Command::AllocationEval {
            set,
            allocators,
            closed_loop,
            json,
        } => allocation_bench::cli::evaluate(
            &set,
            &allocation_bench::cli::allocator_names(&allocators),
            closed_loop,
            json.as_deref(),
        )
        .map(|t| print!("{t}"))
        .map_err(CliError::from),
        Command::List => {
            for name in BUILTIN_NAMES {
                // Built-ins always exist.
                let d = Scenario::builtin(name)
                    .map(|s| s.description)
                    .unwrap_or_default();
                println!("{name:<24} {d}");
            }
            Ok(())
        }
        Command::Show { name } => Scenario::builtin(&name)
            .and_then(|s| s.to_toml_string())
            .map(|t| print!("{t}"))
            .map_err(CliError::from),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Interrupted(m)) => {
            eprintln!("interrupted: {m}");
            ExitCode::from(INTERRUPTED_STATUS)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn cmd_montecarlo(args: &tvmd_sim::montecarlo::cli::MonteCarloArgs) -> Result<(), CliError> {
    let bar = std::sync::OnceLock::new();
    let progress = |done: usize, total: usize| {
        bar.get_or_init(|| progress_bar(total as u64, "flights"))
            .set_position(done as u64);
    };
    let out = tvmd_sim::montecarlo::cli::run(args, Some(&progress))?;
    if let Some(b) = bar.get() {
        b.finish_and_clear();
    }
    print!("{}", out.table);
    println!(
        "success rate {:.1}% of {} flights",
        100.0 * out.success_rate,
        out.flights
    );
    println!("flights:  {}", out.files.flights.display());
    println!("groups:   {}", out.files.groups.display());
    for p in &out.files.plots {
        println!("plot:     {}", p.display());
    }
    Ok(())
}

fn progress_bar(ticks: u64, message: &str) -> ProgressBar {
    let target = if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(ticks), target);
    if let Ok(style) = ProgressStyle::with_template(
        "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} ticks (eta {eta})",
    ) {
        bar.set_style(style);
    }
    bar.set_message(message.to_string());
    bar
}

fn ticks_of(s: &Scenario) -> u64 {
    (s.duration / s.controller_period).ceil().max(1.0) as u64
}

/// Everything `run` writes to the summary JSON.
#[derive(Serialize)]
struct RunReport<'a> {
    scenario: &'a str,
    relaxation: f64,
    allocator: &'a str,
    /// The null-space stage (`margin`, `inward-tilt=<rad>`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    null_space: Option<String>,
    /// The controller's float type, `"f64"` or `"f32"`.
    controller_precision: Precision,
    /// Where the controller ran: `"host"` or the emulated target.
    controller_target: &'a str,
    /// `atan(c_y(1, s))`, the hover law's planned-roll limit.
    hover_roll_limit: Option<f64>,
    summary: &'a RunSummary,
    paper: PaperMetrics,
    log: Option<String>,
}

struct RunArgs {
    scenario: String,
    out: Option<PathBuf>,
    no_log: bool,
    plots: Option<PathBuf>,
    summary: Option<PathBuf>,
    relaxation: Option<f64>,
    allocator: Option<String>,
    null_space: Option<tvmd_sim::scenario::NullSpaceConfig>,
    team: Option<String>,
    precision: Option<String>,
    pil: Option<String>,
    live: Option<LiveOptions>,
}

/// The `--precision` argument (clap has checked the spelling; the parse names the field).
fn precision_arg(p: Option<&str>) -> Result<Option<Precision>, CliError> {
    Ok(p.map(str::parse).transpose()?)
}

fn cmd_record_cycles(
    scenario: &str,
    out: &Path,
    cycles: usize,
    allocator: Option<String>,
) -> Result<(), CliError> {
    let scenario = Scenario::load(scenario)?.with_overrides(&Overrides {
        allocator,
        ..Overrides::default()
    })?;
    let recording = record_cycles(&scenario, cycles)?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let bytes = recording.to_bytes();
    std::fs::write(out, &bytes)?;
    println!(
        "recorded {cycles} f32 control cycles of {} ({} agents, {} bytes): {}",
        scenario.name,
        recording.config.n,
        bytes.len(),
        out.display()
    );
    Ok(())
}

fn cmd_run(a: RunArgs) -> Result<(), CliError> {
    let precision = precision_arg(a.precision.as_deref())?;
    let pil = a
        .pil
        .as_deref()
        .map(str::parse::<PilTarget>)
        .transpose()
        .map_err(SimError::from)?;
    let scenario = Scenario::load(&a.scenario)?.with_overrides(&Overrides {
        relaxation: a.relaxation,
        allocator: a.allocator,
        precision,
        null_space: a.null_space,
        team: a.team,
    })?;
    let mut spec = RunSpec::on_target(scenario, None, pil, precision)?;
    let stem = file_stem(&spec.scenario.name);
    let log = if a.no_log {
        None
    } else {
        Some(
            a.out
                .unwrap_or_else(|| PathBuf::from(format!("out/{stem}.mcap"))),
        )
    };
    let summary_path = a
        .summary
        .or_else(|| log.as_ref().map(|l| l.with_extension("summary.json")));
    // Every output is checked, and its directory made, before the run starts.
    let mut outputs: Vec<(String, &Path)> = Vec::new();
    if let Some(l) = &log {
        outputs.push(("the log (--out)".into(), l));
    }
    if let Some(p) = &summary_path {
        outputs.push(("the summary (--summary)".into(), p));
        create_parent(p, "write the summary")?;
    }
    let input = Path::new(&a.scenario);
    let inputs: Vec<(String, &Path)> = if input.is_file() {
        vec![("scenario file".into(), input)]
    } else {
        Vec::new()
    };
    check_outputs(&outputs, &inputs)?;
    if let Some(dir) = &a.plots {
        std::fs::create_dir_all(dir).map_err(SimError::file("create the figure directory", dir))?;
    }
    // Memory stays flat: the summary folds every tick, the log streams it, and only the
    // figures need samples (a bounded, evenly spaced set).
    spec.log.clone_from(&log);
    spec.samples = plot_retention(a.plots.is_some());
    let scenario = &spec.scenario;
    catch_interrupts();
    let bar = progress_bar(ticks_of(scenario), &scenario.name);
    let mut tick = |_t: f64| bar.inc(1);
    let mut on_listen = |address: std::net::SocketAddr| {
        bar.suspend(|| {
            println!("live:     ws://{address} (Foxglove: Open connection -> Foxglove WebSocket)");
        });
    };
    let live = a.live.map(|options| LiveView {
        options,
        on_listen: &mut on_listen,
    });
    let flight = fly_live(&spec, live, Some(&mut tick), Some(&INTERRUPT));
    bar.finish_and_clear();
    let Flight { result, error } = flight?;
    let report = RunReport {
        scenario: &scenario.name,
        relaxation: scenario.relaxation,
        allocator: &scenario.allocator,
        null_space: scenario.null_space.map(|n| n.to_string()),
        controller_precision: scenario.controller_precision,
        controller_target: &result.summary.controller_target,
        hover_roll_limit: hover_roll_limit(scenario, scenario.relaxation).ok(),
        summary: &result.summary,
        paper: result.paper.clone(),
        log: log.as_ref().map(|p| p.display().to_string()),
    };
    print_run(&report);
    if let Some(p) = &summary_path {
        write_json(p, &report)?;
        println!("summary:  {}", p.display());
    }
    if let Some(l) = &log {
        println!("log:      {} (open in Foxglove)", l.display());
    }
    // A failed flight still leaves its log and a summary of what was simulated.
    if let Some(error) = error {
        return Err(CliError::Sim(error));
    }
    if result.summary.interrupted {
        return Err(CliError::Interrupted(format!(
            "stopped at t = {:.3} s of {} s; the log and summary hold what was simulated",
            result.summary.time, scenario.duration
        )));
    }
    if let Some(dir) = &a.plots {
        let series =
            PlotSeries::from_samples(&scenario.name, Some(scenario.relaxation), &result.samples);
        for p in plot::write_run_figures(&series, dir, &stem)? {
            println!("figure:   {}", p.display());
        }
        print_stride(result.sample_stride);
    }
    Ok(())
}

/// The samples a command-line run keeps: a bounded set for figures, else none.
fn plot_retention(plots: bool) -> SampleRetention {
    if plots {
        SampleRetention::AtMost(plot::PLOT_SAMPLES)
    } else {
        SampleRetention::None
    }
}

/// Says when the figures show every `stride`-th controller tick only.
fn print_stride(stride: usize) {
    if stride > 1 {
        println!(
            "figures:  every {stride}th controller tick (at most {} samples per run)",
            plot::PLOT_SAMPLES
        );
    }
}

fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), CliError> {
    const ACTION: &str = "write the summary";
    create_parent(path, ACTION)?;
    std::fs::write(path, serde_json::to_string_pretty(value)? + "\n")
        .map_err(SimError::file(ACTION, path))?;
    Ok(())
}

fn opt(v: Option<f64>, unit: &str) -> String {
    v.map_or_else(|| "-".to_string(), |x| format!("{x:.6} {unit}"))
}

fn settled(t: Option<f64>) -> String {
    t.map_or_else(|| "not settled".to_string(), |x| format!("{x:.2} s"))
}

fn opt_e(v: Option<f64>, unit: &str) -> String {
    v.map_or_else(|| "-".to_string(), |x| format!("{x:.3e} {unit}"))
}

fn print_run(r: &RunReport<'_>) {
    let s = r.summary;
    let p = &r.paper;
    let mut rows: Vec<(&str, String)> = vec![
        ("scenario", r.scenario.to_string()),
        ("relaxation s", format!("{}", r.relaxation)),
        ("allocator", r.allocator.to_string()),
        ("controller precision", r.controller_precision.to_string()),
        ("controller target", r.controller_target.to_string()),
        ("simulated time", format!("{:.3} s", s.time)),
        (
            "wall time / RTF",
            format!(
                "{:.3} s / {:.1}x real time",
                s.wall_time, s.real_time_factor
            ),
        ),
        (
            "max position error",
            format!("{:.4} m", s.max_position_error),
        ),
        (
            "max pos. error t >= 4 s",
            format!("{:.4} m", s.max_position_error_after_4s),
        ),
        (
            "final position error",
            format!("{:.4} m", s.final_position_error),
        ),
        (
            "horizontal error 4 s/12 s",
            format!(
                "{} / {}",
                opt(s.horizontal_error_at_4s, "m"),
                opt(s.horizontal_error_at_12s, "m")
            ),
        ),
        ("max planned roll", opt(s.max_planned_roll, "rad")),
        ("atan(c_y(1, s))", opt(r.hover_roll_limit, "rad")),
        ("max actual roll", format!("{:.6} rad", s.max_roll)),
        (
            "stage-B attitude settling",
            opt(p.stage_b_attitude_settling, "s"),
        ),
        (
            "max e_f (at t)",
            format!("{} ({})", opt_e(s.max_e_f, "N"), opt(s.max_e_f_time, "s")),
        ),
        ("max e_f / (m_C g)", opt_e(s.max_e_f_over_weight, "")),
        ("final V_x", opt_e(s.final_v_x, "")),
        (
            "largest rise of V_x",
            p.max_v_x_rise.map_or_else(
                || "-".to_string(),
                |r| {
                    format!(
                        "{:.3e} -> {:.3e} ({:.2} s -> {:.2} s)",
                        r.from_value, r.to_value, r.from, r.to
                    )
                },
            ),
        ),
        (
            "thrust min / max",
            format!("{} / {}", opt(s.min_thrust, "N"), opt(s.max_thrust, "N")),
        ),
        (
            "max |eta_x| / |eta_y|",
            format!("{:.4} / {:.4} rad", s.max_abs_eta_x, s.max_abs_eta_y),
        ),
        ("saturated periods", s.saturated_periods.to_string()),
        ("skipped cycles", s.cycle_errors.to_string()),
        (
            "final position",
            format!(
                "[{:.4}, {:.4}, {:.4}] m",
                s.final_position[0], s.final_position[1], s.final_position[2]
            ),
        ),
        (
            "final speed",
            format!(
                "{:.2e} m/s",
                s.final_velocity.iter().map(|v| v * v).sum::<f64>().sqrt()
            ),
        ),
    ];
    let m = &s.metrics;
    if let Some(e) = &m.position {
        rows.push((
            "pos. settling / steady",
            format!(
                "{} / {}",
                settled(e.settling_time),
                opt(e.steady_state, "m")
            ),
        ));
    }
    if let Some(e) = &m.planned_attitude {
        rows.push((
            "R_d settling / steady",
            format!(
                "{} / {}",
                settled(e.settling_time),
                opt(e.steady_state, "rad")
            ),
        ));
    }
    if let Some(eta) = &m.thrust_efficiency {
        rows.push((
            "thrust efficiency mean/min",
            format!("{:.4} / {:.4}", eta.mean, eta.min),
        ));
    }
    rows.push((
        "verdict",
        if s.verdict.success {
            "success".to_string()
        } else {
            format!("FAILED: {}", s.verdict.failures.join("; "))
        },
    ));
    if let (Some(name), Some(n)) = (&r.null_space, &s.null_space) {
        rows.push(("null-space stage", name.clone()));
        rows.push((
            "margin mean / min",
            format!(
                "{:.3} -> {:.3} / {:.3} -> {:.3}",
                n.mean_margin_before, n.mean_margin_after, n.min_margin_before, n.min_margin_after
            ),
        ));
    }
    for (k, v) in rows {
        println!("{k:<26} {v}");
    }
}

/// One row of the relaxation study.
#[derive(Serialize, Clone)]
struct SweepRow {
    relaxation: f64,
    controller_precision: Precision,
    allocator: String,
    max_planned_roll: Option<f64>,
    hover_roll_limit: f64,
    max_e_f: Option<f64>,
    max_e_f_time: Option<f64>,
    e_f_onset: Option<f64>,
    max_position_error_after_4s: f64,
    max_position_error_6_to_12s: Option<f64>,
    final_v_x: Option<f64>,
    saturated_periods: usize,
    real_time_factor: f64,
}

fn cmd_sweep(
    relaxations: &[f64],
    scenario_arg: &str,
    overrides: Overrides,
    plots: Option<PathBuf>,
    logs: Option<PathBuf>,
    summary: Option<PathBuf>,
    jobs: Option<usize>,
) -> Result<(), CliError> {
    let base = Scenario::load(scenario_arg)?.with_overrides(&overrides)?;
    let mut specs = sweep_specs(&base, relaxations, logs.as_deref())?;
    for spec in &mut specs {
        spec.samples = plot_retention(plots.is_some());
    }
    if specs.is_empty() {
        return Err(CliError::Other("no relaxation given".into()));
    }
    let extra: Vec<(String, &Path)> = summary
        .iter()
        .map(|p| ("the summary (--summary)".to_string(), p.as_path()))
        .collect();
    check_batch_outputs(&specs, &extra)?;
    if let Some(p) = &summary {
        create_parent(p, "write the summary")?;
    }
    catch_interrupts();
    let total: u64 = specs.iter().map(|s| ticks_of(&s.scenario)).sum();
    let bar = progress_bar(total, &format!("{} runs", specs.len()));
    let outcomes = run_many_until(specs, jobs, Some(&|_, _| bar.inc(1)), Some(&INTERRUPT));
    bar.finish_and_clear();
    if INTERRUPT.load(Ordering::SeqCst) {
        return Err(CliError::Interrupted(
            "the sweep was stopped; every started run's log is finalised".into(),
        ));
    }
    let mut rows = Vec::new();
    let mut series = Vec::new();
    let mut stride = 1;
    for outcome in outcomes {
        let sc = &outcome.spec.scenario;
        let r = outcome
            .result
            .map_err(|e| CliError::Other(format!("run {}: {e}", sc.name)))?;
        let s = &r.summary;
        let paper = &r.paper;
        rows.push(SweepRow {
            relaxation: sc.relaxation,
            controller_precision: sc.controller_precision,
            allocator: sc.allocator.clone(),
            max_planned_roll: s.max_planned_roll,
            hover_roll_limit: hover_roll_limit(sc, sc.relaxation)?,
            max_e_f: s.max_e_f,
            max_e_f_time: s.max_e_f_time,
            e_f_onset: paper.e_f_onset,
            max_position_error_after_4s: s.max_position_error_after_4s,
            max_position_error_6_to_12s: paper.max_position_error_6_to_12s,
            final_v_x: s.final_v_x,
            saturated_periods: s.saturated_periods,
            real_time_factor: s.real_time_factor,
        });
        series.push(PlotSeries::from_samples(
            &sc.name,
            Some(sc.relaxation),
            &r.samples,
        ));
        stride = stride.max(r.sample_stride);
    }
    println!(
        "controller precision: {}, allocator: {}",
        base.controller_precision, base.allocator
    );
    let na =
        |v: Option<f64>, prec: usize| v.map_or_else(|| "-".to_string(), |x| format!("{x:.prec$}"));
    println!(
        "{:>5} {:>11} {:>11} {:>10} {:>6} {:>9} {:>10} {:>10} {:>10} {:>6}",
        "s",
        "max phi_d",
        "atan(c_y)",
        "max e_f",
        "at t",
        "e_f onset",
        "|e_x|t>=4",
        "|e_x|6-12",
        "final V_x",
        "sat."
    );
    println!(
        "{:>5} {:>11} {:>11} {:>10} {:>6} {:>9} {:>10} {:>10} {:>10} {:>6}",
        "", "(rad)", "(rad)", "(N)", "(s)", "(s)", "(m)", "(m)", "", "(per.)"
    );
    for r in &rows {
        println!(
            "{:>5} {:>11.6} {:>11.6} {:>10.3e} {:>6.2} {:>9} {:>10.4} {:>10} {:>10.3e} {:>6}",
            r.relaxation,
            r.max_planned_roll.unwrap_or(f64::NAN),
            r.hover_roll_limit,
            r.max_e_f.unwrap_or(f64::NAN),
            r.max_e_f_time.unwrap_or(f64::NAN),
            na(r.e_f_onset, 2),
            r.max_position_error_after_4s,
            na(r.max_position_error_6_to_12s, 4),
            r.final_v_x.unwrap_or(f64::NAN),
            r.saturated_periods
        );
    }
    if let Some(p) = &summary {
        write_json(p, &rows)?;
        println!("summary:  {}", p.display());
    }
    if let Some(dir) = &plots {
        let path = dir.join("relaxation.png");
        plot::relaxation_study(&series, &path)?;
        println!("figure:   {}", path.display());
        print_stride(stride);
    }
    if let Some(dir) = &logs {
        println!("logs:     {}", dir.display());
    }
    Ok(())
}

fn cmd_plot(logs: &[PathBuf], out: &Path) -> Result<(), CliError> {
    let mut all = Vec::new();
    for path in logs {
        let series = PlotSeries::from_mcap_file(path)?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| series.label.clone());
        for p in plot::write_run_figures(&series, out, &stem)? {
            println!("figure:   {}", p.display());
        }
        all.push(series);
    }
    if all.len() > 1 {
        let path = out.join("relaxation.png");
        plot::relaxation_study(&all, &path)?;
        println!("figure:   {}", path.display());
    }
    Ok(())
}
