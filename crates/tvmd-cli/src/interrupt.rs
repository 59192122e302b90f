//! SIGINT / SIGTERM: runs stop at their next controller tick.

use std::sync::atomic::{AtomicBool, Ordering};

/// Set by SIGINT / SIGTERM: runs stop at their next controller tick.
pub static INTERRUPT: AtomicBool = AtomicBool::new(false);

/// Exit status after an interrupt (128 + SIGINT).
pub const INTERRUPTED_STATUS: u8 = 130;

/// Makes SIGINT / SIGTERM set [`INTERRUPT`] (a second one exits at once), for the commands
/// that fly: the others keep the default, immediate exit.
pub fn catch_interrupts() {
    // If no handler can be installed, a signal still ends the run, only without its log's
    // footer.
    let _ = ctrlc::set_handler(|| {
        if INTERRUPT.swap(true, Ordering::SeqCst) {
            std::process::exit(i32::from(INTERRUPTED_STATUS));
        }
    });
}
