//! The log's writer thread: builds, encodes and writes a run's messages off the simulation
//! thread.
//!
//! Building the protobuf messages, encoding them, the SDK's dispatch and the MCAP chunk
//! compression cost about as much as the rest of a flight (`paper-tilt`: 231 M instructions on
//! this thread against 332 M for the loop, zstd 43% of them). On one thread the flight waits for
//! all of it; here the loop hands the ticks' owned values over a bounded queue, a batch at a
//! time, and goes on, so with a core to spare a logged flight takes about as long as the longer
//! of the two. The queue is bounded ([`QUEUE_JOBS`]): a writer that falls behind holds the loop
//! back instead of growing memory.
//! Jobs run in the order they were queued, so the file's message order is the loop's.

use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::JoinHandle;

use crate::LogChannels;
use crate::LogError;

/// A unit of work for the writer thread: builds messages from the values it owns and writes
/// them with [`LogChannels::write`].
pub type LogJob = Box<dyn FnOnce(&mut LogChannels) + Send + 'static>;

/// Jobs the queue holds before `LogWriter::submit` waits for the writer. The simulation loop
/// hands over its ticks in batches (`tvmd_sim`'s `BATCH_TICKS`, 50 ticks a job), so
/// this is 3,200 ticks (32 s of a 100 Hz flight, a few MB) at most; a live run's jobs are one
/// tick each and never queue up, as the run is paced to the wall clock.
pub const QUEUE_JOBS: usize = 64;

/// The writer thread and its queue.
pub(super) struct LogWriter {
    jobs: SyncSender<LogJob>,
    thread: JoinHandle<()>,
}

impl LogWriter {
    /// Starts the thread; it owns `channels` from now on.
    pub(super) fn start(mut channels: LogChannels) -> Result<Self, LogError> {
        let (jobs, queue) = sync_channel::<LogJob>(QUEUE_JOBS);
        let thread = std::thread::Builder::new()
            .name("tvmd-log".into())
            .spawn(move || {
                for job in queue {
                    job(&mut channels);
                }
            })
            .map_err(|e| LogError::Foxglove(format!("cannot start the log writer thread: {e}")))?;
        Ok(Self { jobs, thread })
    }

    /// Queues `job`, waiting while the queue is full. Fails only if the thread has died (a job
    /// panicked); [`LogWriter::stop`] then reports why.
    pub(super) fn submit(&self, job: LogJob) -> Result<(), LogError> {
        self.jobs
            .send(job)
            .map_err(|_| LogError::Foxglove("the log writer thread stopped".into()))
    }

    /// Runs every queued job, then ends the thread.
    pub(super) fn stop(self) -> Result<(), LogError> {
        drop(self.jobs);
        self.thread.join().map_err(|panic| {
            let why = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            LogError::Foxglove(format!("the log writer thread panicked: {why}"))
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::{proto, RunLog};

    #[test]
    fn jobs_run_in_order_and_are_all_written_by_finish() {
        let mut log = RunLog::new();
        for k in 0..3 * super::QUEUE_JOBS {
            let t = k as f64;
            log.submit(move |w| {
                w.write(
                    t,
                    &proto::Lyapunov {
                        t,
                        v_x: 0.0,
                        v_r: 0.0,
                    },
                )
            })
            .unwrap();
        }
        log.finish().unwrap();
        assert_eq!(log.message_count(), 3 * super::QUEUE_JOBS as u64);
    }

    #[test]
    fn a_panicking_job_surfaces_as_an_error_not_a_hang() {
        let mut log = RunLog::new();
        log.submit(|_| panic!("bad job")).unwrap();
        // Later jobs may or may not be accepted (the thread may not have died yet), but finish
        // reports the panic.
        let _ = log.submit(|_| ());
        let err = log.finish().unwrap_err().to_string();
        assert!(err.contains("bad job"), "{err}");
    }
}
