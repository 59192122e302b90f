//! `tvmd-sim montecarlo`.

use tvmd_studies::montecarlo::MonteCarloRequest;

use crate::error::CliError;
use crate::interrupt::{catch_interrupts, INTERRUPT};
use crate::progress::progress_bar;

pub fn cmd_montecarlo(args: MonteCarloRequest) -> Result<(), CliError> {
    let bar = std::sync::OnceLock::new();
    let progress = |done: usize, total: usize| {
        bar.get_or_init(|| progress_bar(total as u64, "flights"))
            .set_position(done as u64);
    };
    catch_interrupts();
    let out = tvmd_studies::montecarlo::run_until(&args, Some(&progress), Some(&INTERRUPT))?;
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
    if out.interrupted {
        return Err(CliError::Interrupted(format!(
            "stopped after {} of {} flights; the report above and its files hold those \
             (a partial study)",
            out.flights, out.total
        )));
    }
    Ok(())
}
