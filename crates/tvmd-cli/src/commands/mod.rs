//! One file per command; [`dispatch`] runs the one parsed.

mod montecarlo;
mod plot;
mod px4;
mod record;
mod report;
mod run;
mod sweep;

use tvmd_log::LiveOptions;
use tvmd_scenario::{Scenario, BUILTIN_NAMES};
use tvmd_sim::{RunRequest, ScenarioSource};
use tvmd_studies::allocation_bench;

use crate::args::{Cli, Command};
use crate::error::CliError;
use crate::interrupt::{catch_interrupts, INTERRUPT};

/// Runs the parsed command.
pub fn dispatch(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Afs(args) => {
            catch_interrupts();
            tvmd_studies::afs_atlas::run_until(&args.into(), Some(&INTERRUPT))
                .map(|(_, table)| print!("{table}"))
                .map_err(CliError::from)
        }
        Command::Montecarlo(args) => montecarlo::cmd_montecarlo(args.into()),
        Command::Catalogue(args) => {
            catch_interrupts();
            tvmd_studies::catalogue::run_and_write_until(&args.into(), Some(&INTERRUPT))
                .map(|table| print!("{table}"))
                .map_err(CliError::from)
        }
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
            law,
            detect,
            reports,
            precision,
            pil,
            live,
            live_host,
            live_port,
            live_speed,
            live_wait,
        } => run::cmd_run(run::RunArgs {
            scenario,
            out,
            no_log,
            plots,
            summary,
            relaxation,
            allocator,
            null_space,
            team,
            law,
            detect,
            reports,
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
        } => record::cmd_record_cycles(&scenario, &out, cycles, allocator),
        Command::Sweep {
            relaxations,
            scenario,
            plots,
            logs,
            summary,
            jobs,
            precision,
            allocator,
            law,
        } => RunRequest {
            scenario: ScenarioSource::NameOrFile(scenario),
            allocator,
            law,
            ..RunRequest::default()
        }
        .with_strings(precision.as_deref(), None, None)
        .map_err(CliError::from)
        .and_then(|request| sweep::cmd_sweep(&relaxations, &request, plots, logs, summary, jobs)),
        Command::Plot { logs, out } => plot::cmd_plot(&logs, &out),
        Command::AllocationSet { out, seed } => allocation_bench::write_set(&out, seed)
            .map(|m| println!("{m}"))
            .map_err(CliError::from),
        Command::AllocationEval {
            set,
            allocators,
            closed_loop,
            json,
        } => allocation_bench::evaluate_file(
            &set,
            &allocation_bench::allocator_names(&allocators),
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
        Command::Px4(args) => px4::cmd_px4(args),
    }
}
