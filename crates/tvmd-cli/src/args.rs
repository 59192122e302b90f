//! The command line's arguments (clap): the commands and their options. The studies' options
//! convert into the library's plain request types.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(name = "tvmd-sim", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    /// The command.
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// The AFS atlas of a catalogue team: the exact attainable lateral forces (bracketed)
    /// against the elliptic cone, and the certified relaxation s* (docs/afs-atlas.md).
    Afs(AfsArgs),
    /// A Monte Carlo study: the scenario flown --runs times per team, allocator and
    /// model-error level with model errors and initial conditions drawn from stated
    /// distributions (docs/method.md, "Monte Carlo"); prints the success rate and writes
    /// flights.csv, groups.csv and box plots.
    Montecarlo(MonteCarloArgs),
    /// Every catalogue team with every allocator through a step, wind, a one-agent failure
    /// and model error: the README's results table (Markdown on stdout).
    Catalogue(CatalogueArgs),
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
        /// redistributed-pseudo-inverse, pseudo-inverse, weighted-pseudo-inverse,
        /// capped-redistribution, clarabel, clarabel-sequential).
        #[arg(long)]
        allocator: Option<String>,
        /// Run a null-space stage after the allocator: `margin`, or `inward-tilt=<rad>`
        /// (the scenario's `null_space`; see docs/method.md, "Null-space stage").
        #[arg(long, value_name = "OBJECTIVE")]
        null_space: Option<tvmd_scenario::NullSpaceConfig>,
        /// Fly the scenario with a catalogue team instead of its own (`team.preset`: a3-con,
        /// a4-inc, a6-inc, ..., t10-con; see `tvmd-sim afs`).
        #[arg(long)]
        team: Option<String>,
        /// Override the scenario's control law (`[law]`): offset-free (natural gains, the
        /// disturbance observer, the planned rates; the default of families and of files that
        /// name no law) or paper (the paper's law as published; docs/method.md).
        #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(tvmd_scenario::LAW_NAMES))]
        law: Option<String>,
        /// Detect agent faults from the wrench residual (`[fault_detection]` with the
        /// recommended detector): report (verdicts only) or mask (the controller masks a
        /// confirmed lost agent itself); needs the offset-free law (docs/method.md).
        #[arg(long, value_parser = ["report", "mask"])]
        detect: Option<String>,
        /// Turn on the agents' own reports (`[reports]` at the simulator's defaults, replacing
        /// the scenario's: 100 Hz, 20 ms latency, 0.05 N and 5 mrad of noise); the value says
        /// what a dead ESC reports: silent (nothing, the default) or zero (zero speed). With
        /// --detect the controller checks them (docs/fault-detection.md).
        #[arg(long, value_name = "DEAD_ESC", num_args = 0..=1, default_missing_value = "silent", value_parser = ["silent", "zero"])]
        reports: Option<String>,
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
        /// Override the scenario's control law (as `run --law`).
        #[arg(long, value_parser = law_parser())]
        law: Option<tvmd_scenario::LawConfig>,
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
        #[arg(long, default_value = tvmd_studies::allocation_bench::SET_PATH)]
        out: PathBuf,
        /// Seed of the generator.
        #[arg(long, default_value_t = tvmd_studies::allocation_bench::SEED)]
        seed: u64,
    },
    /// Evaluate allocators on the allocation set and print markdown tables.
    AllocationEval {
        /// The set file.
        #[arg(long, default_value = tvmd_studies::allocation_bench::SET_PATH)]
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
    /// Serve PX4 SITL as its simulator (simulator_mavlink, lockstep or real time) and fly a
    /// flight file's script with it (docs/px4.md, docs/px4-module.md).
    Px4(Px4Args),
}

/// Arguments of `tvmd-sim px4`.
#[derive(clap::Args, Debug, Clone)]
pub struct Px4Args {
    /// A built-in scenario name or a TOML file (team, plant, disturbances, duration; its
    /// controller period is PX4's sensor period).
    pub scenario: String,
    /// The flight file: script, control mapping, sensors, measured windows.
    #[arg(long)]
    pub flight: PathBuf,
    /// MCAP log to write (PX4's ulog is copied beside it as .ulg; the report as .px4.json).
    #[arg(long, default_value = "out/px4.mcap")]
    pub out: PathBuf,
    /// PX4's instance: it connects to TCP 4560 + N and serves its GCS link on UDP 18570 + N.
    #[arg(long, default_value_t = 0)]
    pub instance: u8,
    /// Start PX4 from this tree (built with `make px4_sitl_default`); without it, start PX4
    /// yourself (`PX4_SYS_AUTOSTART=... build/px4_sitl_default/bin/px4`).
    #[arg(long, value_name = "PX4_DIR")]
    pub px4_dir: Option<PathBuf>,
    /// The SITL build of the tree to start, a directory under its build/, with --px4-dir:
    /// px4_sitl_default (lockstep) or px4_sitl_nolockstep (wall clock, with --real-time).
    #[arg(long, default_value = tvmd_px4::launch::DEFAULT_BUILD, requires = "px4_dir")]
    pub px4_build: String,
    /// Pace the flight in real time for a PX4 build without lockstep (px4_sitl_nolockstep):
    /// sensors at PX4's rate on the wall clock, the newest controls applied, so that PX4's
    /// clock and its `perf` counters measure real time. Without it, lockstep.
    #[arg(long, conflicts_with = "sih")]
    pub real_time: bool,
    /// The airframe PX4 starts with (PX4_SYS_AUTOSTART), with --px4-dir.
    #[arg(long, default_value_t = 10016, requires = "px4_dir")]
    pub autostart: u32,
    /// A file of `param set` lines applied after the airframe, with --px4-dir.
    #[arg(long, requires = "px4_dir")]
    pub params: Option<PathBuf>,
    /// Fly the flight file's script on PX4's own SIH quadcopter instead (airframe 10040, real
    /// time, for comparison; measured from its ulog): needs --px4-dir.
    #[arg(long, requires = "px4_dir")]
    pub sih: bool,
    /// Seconds of wall time to wait for PX4 to connect.
    #[arg(long, default_value_t = 120.0)]
    pub connect_timeout: f64,
    /// Seconds of wall time PX4 may take to answer one tick in lockstep.
    #[arg(long, default_value_t = 10.0)]
    pub stall_timeout: f64,
}

/// Arguments of `tvmd-sim afs`.
#[derive(clap::Args, Debug, Clone)]
pub struct AfsArgs {
    /// A catalogue team (`a3-con` .. `a10-inc`, `t10-con`, `t10-inc`, `a4-diamond-inc`, ...)
    /// or `all`.
    pub team: String,
    /// Failed agents (0-based), comma-separated.
    #[arg(long, value_delimiter = ',')]
    pub failed: Vec<usize>,
    /// Also every one-agent failure of each team.
    #[arg(long, conflicts_with = "failed")]
    pub each_failure: bool,
    /// Comparison heights in multiples of m_C g, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0.5,1.0,1.5")]
    pub heights: Vec<f64>,
    /// Directions per cross-section.
    #[arg(long, default_value_t = 36)]
    pub directions: usize,
    /// Relaxation s of the compared cone.
    #[arg(long, default_value_t = 1.0)]
    pub relaxation: f64,
    /// Heights of the s* certification grid (from 0.1 to 0.9 of the hover ceiling).
    #[arg(long, default_value_t = 9)]
    pub certify_heights: usize,
    /// Torque the agents must hold (N m), `x,y,z`.
    #[arg(long, value_delimiter = ',', default_values_t = [0.0, 0.0, 0.0], allow_negative_numbers = true)]
    pub torque: Vec<f64>,
    /// Directory for the PNG cross-sections (`<team>[-failed-<i>].png`).
    #[arg(long)]
    pub plots: Option<PathBuf>,
    /// Write the rows as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

impl From<AfsArgs> for tvmd_studies::afs_atlas::AtlasRequest {
    fn from(a: AfsArgs) -> Self {
        Self {
            team: a.team,
            failed: a.failed,
            each_failure: a.each_failure,
            heights: a.heights,
            directions: a.directions,
            relaxation: a.relaxation,
            certify_heights: a.certify_heights,
            torque: a.torque,
            plots: a.plots,
            json: a.json,
        }
    }
}

/// Arguments of `tvmd-sim montecarlo`.
#[derive(clap::Args, Debug, Clone)]
pub struct MonteCarloArgs {
    /// A built-in scenario name (see `tvmd-sim list`) or a TOML file (default: the hover
    /// family, flown with the default law).
    #[arg(default_value = tvmd_studies::montecarlo::DEFAULT_SCENARIO)]
    pub scenario: String,
    /// Override the scenario's control law (`[law]`): offset-free (the default law) or paper
    /// (the paper's law as published, no integral action; docs/method.md).
    #[arg(long, value_parser = law_parser())]
    pub law: Option<tvmd_scenario::LawConfig>,
    /// Flights per team, allocator and model-error level.
    #[arg(long, default_value_t = 100)]
    pub runs: usize,
    /// Seed of every draw (flight k of a group always draws the same errors).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Catalogue teams, comma-separated (default: the scenario's).
    #[arg(long, value_delimiter = ',')]
    pub teams: Vec<String>,
    /// Allocators, comma-separated (default: the scenario's).
    #[arg(long, value_delimiter = ',')]
    pub allocators: Vec<String>,
    /// Model-error multipliers, comma-separated, one group each (default: 1).
    #[arg(long, value_delimiter = ',')]
    pub model_error: Vec<f64>,
    /// Mass error half-width (plant mass over the model's in `[1 - e, 1 + e]`).
    #[arg(long)]
    pub mass: Option<f64>,
    /// Inertia error half-width.
    #[arg(long)]
    pub inertia: Option<f64>,
    /// Centre-of-mass offset half-width per axis (m).
    #[arg(long)]
    pub com_offset: Option<f64>,
    /// Thrust efficiency loss half-width per agent (efficiency in `[1 - e, 1]`).
    #[arg(long)]
    pub thrust_efficiency: Option<f64>,
    /// Gimbal offset half-width per agent and axis (rad).
    #[arg(long)]
    pub gimbal_offset: Option<f64>,
    /// Initial horizontal offset half-width per axis (m).
    #[arg(long)]
    pub initial_position: Option<f64>,
    /// Largest initial tilt (rad, at most 2.5; the scenario must start in the air).
    #[arg(long)]
    pub initial_tilt: Option<f64>,
    /// Dryden turbulence in every flight (MIL-F-8785C low altitude): light, moderate, severe
    /// (W20 = 15, 30, 45 kt) or W20 in m/s; on the standard's mean wind where the scenario has
    /// none (docs/monte-carlo.md).
    #[arg(long, value_parser = parse_turbulence)]
    pub turbulence: Option<f64>,
    /// A 1-cos gust of this peak speed (m/s, 2 s, drawn heading and start) in every flight.
    #[arg(long)]
    pub gust: Option<f64>,
    /// Directory for `flights.csv`, `groups.csv` and the PNG figures (default:
    /// `out/montecarlo/<scenario>`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Worker threads (default: every core).
    #[arg(long)]
    pub jobs: Option<usize>,
}

impl From<MonteCarloArgs> for tvmd_studies::montecarlo::MonteCarloRequest {
    fn from(a: MonteCarloArgs) -> Self {
        Self {
            scenario: a.scenario,
            law: a.law,
            runs: a.runs,
            seed: a.seed,
            teams: a.teams,
            allocators: a.allocators,
            model_error: a.model_error,
            mass: a.mass,
            inertia: a.inertia,
            com_offset: a.com_offset,
            thrust_efficiency: a.thrust_efficiency,
            gimbal_offset: a.gimbal_offset,
            initial_position: a.initial_position,
            initial_tilt: a.initial_tilt,
            turbulence: a.turbulence,
            gust: a.gust,
            out: a.out,
            jobs: a.jobs,
        }
    }
}

/// Arguments of `tvmd-sim catalogue`.
#[derive(clap::Args, Debug, Clone)]
pub struct CatalogueArgs {
    /// Model-error flights per team and allocator.
    #[arg(long, default_value_t = 20)]
    pub runs: usize,
    /// Seed of the model-error draws.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Catalogue teams, comma-separated (default: all 20).
    #[arg(long, value_delimiter = ',')]
    pub teams: Vec<String>,
    /// Allocators, comma-separated (default: the four without the `clarabel` feature).
    #[arg(long, value_delimiter = ',')]
    pub allocators: Vec<String>,
    /// Override the tasks' control law (`[law]`): offset-free (the default law, the tasks'
    /// own) or paper (the paper's law as published, no integral action; docs/method.md).
    #[arg(long, value_parser = law_parser())]
    pub law: Option<tvmd_scenario::LawConfig>,
    /// Write `catalogue.csv` (one row per team and allocator, each over its flights) and
    /// `catalogue.md` here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Worker threads (default: every core).
    #[arg(long)]
    pub jobs: Option<usize>,
}

impl From<CatalogueArgs> for tvmd_studies::catalogue::CatalogueSettings {
    fn from(a: CatalogueArgs) -> Self {
        Self {
            runs: a.runs,
            seed: a.seed,
            teams: a.teams,
            allocators: a.allocators,
            law: a.law,
            out: a.out,
            jobs: a.jobs,
        }
    }
}

/// `--turbulence`: a level of the standard, or `W20` in m/s.
fn parse_turbulence(text: &str) -> Result<f64, String> {
    use tvmd_plant::turbulence::{LIGHT_W20, MODERATE_W20, SEVERE_W20};
    match text {
        "light" => Ok(LIGHT_W20),
        "moderate" => Ok(MODERATE_W20),
        "severe" => Ok(SEVERE_W20),
        _ => text
            .parse::<f64>()
            .map_err(|_| format!("`{text}`: light, moderate, severe, or W20 in m/s")),
    }
}

/// `--law`: one of [`tvmd_scenario::LAW_NAMES`] (listed in `--help`), as the scenario's law.
fn law_parser() -> impl clap::builder::TypedValueParser<Value = tvmd_scenario::LawConfig> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(tvmd_scenario::LAW_NAMES)
        .try_map(|name| name.parse::<tvmd_scenario::LawConfig>())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn montecarlo(args: &[&str]) -> Result<MonteCarloArgs, clap::Error> {
        let all = ["tvmd-sim", "montecarlo"].iter().chain(args);
        match Cli::try_parse_from(all)?.command {
            Command::Montecarlo(a) => Ok(a),
            other => panic!("parsed as {other:?}"),
        }
    }

    /// Issue 61: `montecarlo` with no arguments flies the default scenario with its own (the
    /// default) law; `--law` takes the law's names only.
    #[test]
    fn montecarlo_defaults_to_the_default_law_and_takes_law() {
        let plain = montecarlo(&[]).unwrap();
        assert_eq!(plain.scenario, tvmd_studies::montecarlo::DEFAULT_SCENARIO);
        assert_eq!(plain.law, None);
        let paper = montecarlo(&["paper-tilt", "--law", "offset-free"]).unwrap();
        assert_eq!(paper.law, Some(tvmd_scenario::LawConfig::default()));
        let e = montecarlo(&["--law", "pid"]).unwrap_err().to_string();
        assert!(e.contains("pid") && e.contains("offset-free"), "{e}");
        let sweep = Cli::try_parse_from(["tvmd-sim", "sweep", "--law", "paper"]).unwrap();
        assert!(matches!(
            sweep.command,
            Command::Sweep { law: Some(l), .. } if l.is_paper()
        ));
    }
}
