//! The log of one run: its context, channels, sinks and writer thread.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::Arc;

use foxglove::{Context, McapWriterHandle};

use nalgebra::{Matrix3, Vector3};

use crate::channels::Channels;
use crate::channels::Written;
use crate::writer::LogWriter;
use crate::{frame_transform, LiveOptions, LiveServer, LogChannels, LogError, LogMessage};

type McapFile = McapWriterHandle<BufWriter<File>>;

/// The log of one run: its own Foxglove context with every channel, and its sinks (an MCAP
/// file, a live server, or both).
pub struct RunLog {
    // The channels until the writer thread starts (with the first message), then the thread.
    channels: Option<LogChannels>,
    writer: Option<LogWriter>,
    written: Written,
    mcap: Option<McapFile>,
    // The temporary file the MCAP sink writes and the path it is renamed to when finished.
    mcap_paths: Option<(PathBuf, PathBuf)>,
    live: Option<LiveServer>,
    finished: bool,
    // Dropped last: the channels and sinks belong to it.
    context: Arc<Context>,
}

impl RunLog {
    /// A log with no sink yet (messages go nowhere until one is added).
    pub fn new() -> Self {
        let context = Context::new();
        let written = Written::default();
        Self {
            channels: Some(LogChannels {
                channels: Channels::new(&context),
                written: written.clone(),
            }),
            writer: None,
            written,
            mcap: None,
            mcap_paths: None,
            live: None,
            finished: false,
            context,
        }
    }

    /// A log writing to a new MCAP file at `path` (parent directories created). The file is
    /// written under a temporary name in the same directory and renamed onto `path` when the
    /// log is finished ([`crate::paths`]), so a reader, or a second run writing the same path,
    /// never sees a half-written file. I/O errors name the path ([`LogError::File`]).
    pub fn create(path: impl AsRef<Path>) -> Result<Self, LogError> {
        let mut log = Self::new();
        log.add_mcap(path)?;
        Ok(log)
    }

    /// Adds an MCAP file sink at `path` (at most one per log).
    pub fn add_mcap(&mut self, path: impl AsRef<Path>) -> Result<(), LogError> {
        let path = path.as_ref();
        const ACTION: &str = "write the MCAP log";
        if self.mcap.is_some() {
            return Err(LogError::InvalidArgument {
                name: "log".into(),
                reason: "the run already writes an MCAP file".into(),
            });
        }
        crate::paths::create_parent(path, ACTION)?;
        let temporary = crate::paths::temporary(path);
        let file = File::create(&temporary).map_err(LogError::file(ACTION, path))?;
        self.mcap_paths = Some((temporary, path.to_path_buf()));
        let file = BufWriter::new(file);
        // Chunks are compressed on the log's writer thread. mcap's default hands each chunk to
        // zstd's own worker pool (one thread per physical CPU), whose threads then compete with
        // the simulation loop for the cores, and with every other flight of a batch.
        let options = foxglove::McapWriteOptions::new()
            .compression_threads(0)
            // zstd level 1 rather than its default 3: paper-tilt's file grows 4% (1.37 MB against
            // 1.31 MB) and zstd was the writer thread's largest cost.
            .compression_level(1)
            .profile("")
            .library(concat!("tvmd-sim ", env!("CARGO_PKG_VERSION")));
        let handle = self
            .context
            .mcap_writer_with_options(options)
            .create(file)
            .map_err(|e| {
                if let Some((temporary, _)) = self.mcap_paths.take() {
                    let _ = std::fs::remove_file(temporary);
                }
                LogError::foxglove(e)
            })?;
        self.mcap = Some(handle);
        Ok(())
    }

    /// Starts a live server on this log's context ([`LiveServer`]); returns its address.
    pub fn serve(&mut self, options: &LiveOptions) -> Result<std::net::SocketAddr, LogError> {
        let server = LiveServer::start(&self.context, options)?;
        let addr = server.address();
        self.live = Some(server);
        Ok(addr)
    }

    /// The live server, if one was started.
    pub fn live(&self) -> Option<&LiveServer> {
        self.live.as_ref()
    }

    /// With a live server, publishes `t` and holds the run to its pace
    /// ([`LiveServer::pace`]); otherwise returns at once.
    pub fn pace(&mut self, t: f64) {
        if let Some(live) = self.live.as_mut() {
            live.pace(t);
        }
    }

    /// Writes an MCAP metadata record `name` with string key/value pairs (for example the
    /// scenario, see [`crate::METADATA_SCENARIO`]); a no-op without an MCAP file.
    pub fn write_metadata(
        &mut self,
        name: &str,
        values: BTreeMap<String, String>,
    ) -> Result<(), LogError> {
        if self.finished {
            return Err(LogError::LogFinished);
        }
        match &self.mcap {
            Some(m) => m.write_metadata(name, values).map_err(LogError::foxglove),
            None => Ok(()),
        }
    }

    /// Number of messages written so far by the writer thread; after [`RunLog::finish`], all
    /// of them.
    pub fn message_count(&self) -> u64 {
        self.written.load(Ordering::Relaxed)
    }

    /// Queues `job` for the log's writer thread, which builds and writes its messages there
    /// ([`crate::writer`]); waits while [`crate::writer::QUEUE_JOBS`] jobs are queued.
    pub fn submit(
        &mut self,
        job: impl FnOnce(&mut LogChannels) + Send + 'static,
    ) -> Result<(), LogError> {
        if self.finished {
            return Err(LogError::LogFinished);
        }
        if let Some(channels) = self.channels.take() {
            self.writer = Some(LogWriter::start(channels)?);
        }
        match &self.writer {
            Some(w) => w.submit(Box::new(job)),
            None => Err(LogError::LogFinished),
        }
    }

    /// Writes `msg` at simulation time `t` (s) on its channel (on the writer thread, after
    /// every message queued before it).
    pub fn write<M: LogMessage>(&mut self, t: f64, msg: M) -> Result<(), LogError> {
        self.submit(move |w| w.write(t, &msg))
    }

    /// Writes the pose of frame `team` in frame `world` (`foxglove.FrameTransform`).
    pub fn write_frame_transform(
        &mut self,
        t: f64,
        position: &Vector3<f64>,
        rotation: &Matrix3<f64>,
    ) -> Result<(), LogError> {
        let (position, rotation) = (*position, *rotation);
        self.submit(move |w| w.write(t, &frame_transform(t, &position, &rotation)))
    }

    /// Waits for the writer thread to write everything queued, finalises the MCAP file
    /// (summary, footer, flush) and stops the live server. Further writes fail with
    /// [`LogError::LogFinished`]; calling `finish` again is a no-op. A job that panicked on the
    /// writer thread is reported here ([`LogError::Foxglove`]), after the file is finalised.
    pub fn finish(&mut self) -> Result<(), LogError> {
        if self.finished {
            return Ok(());
        }
        self.finished = true;
        self.channels = None;
        let drained = self.writer.take().map_or(Ok(()), LogWriter::stop);
        if let Some(live) = self.live.take() {
            live.stop();
        }
        if let Some(m) = self.mcap.take() {
            let closed = m.close().map_err(LogError::foxglove).and_then(|mut file| {
                file.flush()?;
                Ok(())
            });
            if let Some((temporary, path)) = self.mcap_paths.take() {
                if let Err(e) = closed {
                    let _ = std::fs::remove_file(&temporary);
                    return Err(e);
                }
                crate::paths::rename_into_place(&temporary, &path, "write the MCAP log")?;
            }
        }
        drained
    }
}

impl Default for RunLog {
    fn default() -> Self {
        Self::new()
    }
}

impl Drop for RunLog {
    fn drop(&mut self) {
        // Best effort: finalise so the file stays a valid MCAP even on an error path.
        let _ = self.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{nanos, proto, timestamp, LogKind};

    #[test]
    fn kinds_name_their_topics_and_schemas_once() {
        let topics: std::collections::BTreeSet<_> =
            LogKind::ALL.iter().map(|k| k.topic()).collect();
        assert_eq!(topics.len(), LogKind::ALL.len());
        assert_eq!(LogKind::State.schema_name(), "tvmd.State");
        assert_eq!(LogKind::Scene.schema_name(), "foxglove.SceneUpdate");
        assert!(LogKind::Allocation.is_heavy() && !LogKind::State.is_heavy());
    }

    #[test]
    fn times_become_nanoseconds() {
        assert_eq!(nanos(1.5), 1_500_000_000);
        assert_eq!(nanos(-1.0), 0);
        assert_eq!(nanos(f64::NAN), 0);
        let ts = timestamp(2.25);
        assert_eq!((ts.sec(), ts.nsec()), (2, 250_000_000));
    }

    #[test]
    fn a_finished_log_refuses_writes() {
        let mut log = RunLog::new();
        log.finish().unwrap();
        let msg = proto::Lyapunov::default();
        assert!(matches!(log.write(0.0, msg), Err(LogError::LogFinished)));
        log.finish().unwrap();
    }
}
