//! Ctrl-C for every long call (`run`, `run_many`, `relaxation_sweep`, `monte_carlo`,
//! `afs_atlas`): the work runs on a scoped thread with the GIL released while the calling
//! thread checks for Python signals every [`SIGNAL_POLL`]; on a signal the work's cancel flag
//! is set, the work stops at its next check (a controller tick, a ray of the atlas) and is
//! joined, and the caller gets the signal's exception with what the work returned (a partial
//! result, to keep or to drop). A leaf: it imports no module of the crate.

use std::sync::atomic::{AtomicBool, Ordering};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// How often a waiting call looks for Python signals (Ctrl-C).
pub(crate) const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(20);

/// What an interruptible call ended with.
pub(crate) enum Ended<T> {
    /// The work finished.
    Finished(T),
    /// A signal handler raised `signal` (`KeyboardInterrupt`); `partial` is what the work
    /// returned after it was told to stop.
    Interrupted {
        /// The signal handler's exception.
        signal: PyErr,
        /// The work's result after the cancel flag was set.
        partial: T,
    },
}

/// Runs `work(cancel)` with the GIL released, honouring Ctrl-C within [`SIGNAL_POLL`] plus
/// the work's own reaction time. A panic of the work is a `RuntimeError`.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<Ended<T>> {
    let cancel = AtomicBool::new(false);
    let panicked = || PyRuntimeError::new_err("tvmd: a worker thread panicked");
    std::thread::scope(|scope| {
        let job = scope.spawn(|| work(&cancel));
        while !job.is_finished() {
            py.detach(|| std::thread::sleep(SIGNAL_POLL));
            if let Err(signal) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                // The work stops at its next check; join it so that its files are complete
                // (or not written) when the exception reaches the caller.
                let partial = py.detach(|| job.join()).map_err(|_| panicked())?;
                return Ok(Ended::Interrupted { signal, partial });
            }
        }
        job.join().map(Ended::Finished).map_err(|_| panicked())
    })
}
