//! Reading a run's MCAP log back ([`read_run`]): the `tvmd.*` messages of each controller tick
//! and the metadata records, decoded with this crate's own structs ([`crate::proto`]).
//!
//! Every numeric field of the `tvmd.*` messages is a protobuf `double`, so the values read back
//! are the loop's f64 values bit for bit. A tick starts with its `/state` message; the other
//! messages of the tick follow it in the file (the loop writes them in that order), each
//! carrying the same time `t`. The heavy topics ([`crate::LogKind::is_heavy`]) are present only
//! on the ticks the scenario's `[log] decimation` kept.

use std::collections::BTreeMap;
use std::path::Path;

use prost::Message;

use crate::{proto, LogError};

/// The messages of one controller tick.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TickMessages {
    /// `/state`.
    pub state: proto::State,
    /// `/reference`.
    pub reference: Option<proto::Reference>,
    /// `/planner`.
    pub planner: Option<proto::Planner>,
    /// `/control` with the law's diagnostics.
    pub control: Option<proto::Control>,
    /// `/control` saying why the cycle was skipped or noting a failure (`cycle_error`,
    /// `failure_note`).
    pub note: Option<proto::Control>,
    /// `/allocation`.
    pub allocation: Option<proto::Allocation>,
    /// `/actuators`.
    pub actuators: Option<proto::Actuators>,
    /// `/lyapunov`.
    pub lyapunov: Option<proto::Lyapunov>,
    /// `/hover`.
    pub hover: Option<proto::Hover>,
    /// `/fault`.
    pub fault: Option<proto::Fault>,
}

/// A run's log as read back: its ticks in order and its metadata records by name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoggedRun {
    /// One entry per `/state` message, in file order.
    pub ticks: Vec<TickMessages>,
    /// The metadata records (e.g. [`crate::METADATA_SCENARIO`]), by name.
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// The file is damaged (truncated, a record cut or corrupt) after at least one tick: what
    /// stopped the reading. The ticks and metadata are those before the damage.
    pub damage: Option<String>,
}

fn read_err(what: impl std::fmt::Display) -> LogError {
    LogError::LogRead(what.to_string())
}

fn decode<M: Message + Default>(topic: &str, data: &[u8]) -> Result<M, LogError> {
    M::decode(data).map_err(|e| {
        read_err(format!(
            "`{topic}` message is not a tvmd protobuf message: {e}"
        ))
    })
}

/// The bytes of the MCAP file at `path`: a regular file (after links), refused before it is
/// opened otherwise (a FIFO would block, a device never end), and refused after its first
/// eight bytes unless they are MCAP's magic (a large file that is no log is not read whole);
/// at most the file's size is read. Errors name the path.
pub fn read_log_file(path: impl AsRef<Path>) -> Result<Vec<u8>, LogError> {
    use std::io::Read;
    const ACTION: &str = "read the MCAP log";
    let path = path.as_ref();
    let refuse = |reason: &str| LogError::File {
        action: ACTION,
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, reason.to_string()),
    };
    let meta = std::fs::metadata(path).map_err(LogError::file(ACTION, path))?;
    if !meta.is_file() {
        return Err(refuse("not a regular file (a directory, device or FIFO)"));
    }
    let file = std::fs::File::open(path).map_err(LogError::file(ACTION, path))?;
    let size = file.metadata().map_err(LogError::file(ACTION, path))?.len();
    let mut bytes = Vec::with_capacity(usize::try_from(size.min(1 << 30)).unwrap_or(0));
    let mut file = file.take(size);
    (&mut file)
        .take(mcap::MAGIC.len() as u64)
        .read_to_end(&mut bytes)
        .map_err(LogError::file(ACTION, path))?;
    if bytes.as_slice() != mcap::MAGIC {
        return Err(read_err(format!(
            "{}: not an MCAP file (it does not start with MCAP's magic)",
            path.display()
        )));
    }
    file.read_to_end(&mut bytes)
        .map_err(LogError::file(ACTION, path))?;
    Ok(bytes)
}

/// Reads the log at `path` ([`read_log_file`], [`read_run_bytes`]); errors name the path.
pub fn read_run(path: impl AsRef<Path>) -> Result<LoggedRun, LogError> {
    let path = path.as_ref();
    let bytes = read_log_file(path)?;
    read_run_bytes(&bytes).map_err(|e| match e {
        LogError::LogRead(m) => LogError::LogRead(format!("{}: {m}", path.display())),
        other => read_err(format!("{}: {other}", path.display())),
    })
}

/// Reads a run's log from the bytes of its MCAP file. Fails if the file is not MCAP, a
/// `tvmd.*` message does not decode, or the log has no `/state` message before any damage; a
/// file damaged after its first tick (a run cut short, a copy truncated) reads up to the
/// damage, which [`LoggedRun::damage`] states.
pub fn read_run_bytes(bytes: &[u8]) -> Result<LoggedRun, LogError> {
    let mut run = LoggedRun::default();
    let stream = mcap::MessageStream::new(bytes).map_err(|e| read_err(format!("not MCAP: {e}")))?;
    for m in stream {
        let m = match m {
            Ok(m) => m,
            // What precedes the damage is the run up to it, as MCAP's recovery tools read it.
            Err(e) if !run.ticks.is_empty() => {
                run.damage = Some(format!("damaged MCAP (truncated?): {e}"));
                break;
            }
            Err(e) => return Err(read_err(format!("corrupt MCAP: {e}"))),
        };
        let topic = m.channel.topic.as_str();
        let data = &*m.data;
        if topic == "/state" {
            run.ticks.push(TickMessages {
                state: decode(topic, data)?,
                ..Default::default()
            });
            continue;
        }
        let known = matches!(
            topic,
            "/reference"
                | "/planner"
                | "/control"
                | "/allocation"
                | "/actuators"
                | "/lyapunov"
                | "/hover"
                | "/fault"
        );
        if !known {
            continue;
        }
        let Some(tick) = run.ticks.last_mut() else {
            return Err(read_err(format!("a `{topic}` message before any `/state`")));
        };
        match topic {
            "/reference" => tick.reference = Some(decode(topic, data)?),
            "/planner" => tick.planner = Some(decode(topic, data)?),
            "/control" => {
                let c: proto::Control = decode(topic, data)?;
                if c.cycle_error.is_empty() && c.failure_note.is_empty() {
                    tick.control = Some(c);
                } else {
                    tick.note = Some(c);
                }
            }
            "/allocation" => tick.allocation = Some(decode(topic, data)?),
            "/actuators" => tick.actuators = Some(decode(topic, data)?),
            "/lyapunov" => tick.lyapunov = Some(decode(topic, data)?),
            "/fault" => tick.fault = Some(decode(topic, data)?),
            _ => tick.hover = Some(decode(topic, data)?),
        }
    }
    if run.ticks.is_empty() {
        return Err(read_err(
            "the log has no `/state` message (not a tvmd-sim run?)",
        ));
    }
    if run.damage.is_some() {
        let (metadata, data_whole) = before_damage(bytes);
        run.metadata = metadata;
        if !data_whole {
            // The damage cut the data: the last tick's messages may be cut with it.
            run.ticks.pop();
            if run.ticks.is_empty() {
                return Err(read_err(
                    "damaged MCAP: no whole controller tick before the damage",
                ));
            }
        }
        return Ok(run);
    }
    if let Some(summary) =
        mcap::Summary::read(bytes).map_err(|e| read_err(format!("corrupt MCAP summary: {e}")))?
    {
        for index in &summary.metadata_indexes {
            let meta = mcap::read::metadata(bytes, index)
                .map_err(|e| read_err(format!("corrupt MCAP metadata `{}`: {e}", index.name)))?;
            run.metadata.insert(meta.name, meta.metadata);
        }
    }
    Ok(run)
}

/// The metadata records of a damaged file, read in file order up to the damage (its summary,
/// at the end, is lost), and whether its data section is whole (the damage came after it).
fn before_damage(bytes: &[u8]) -> (BTreeMap<String, BTreeMap<String, String>>, bool) {
    let mut metadata = BTreeMap::new();
    let mut data_whole = false;
    let Ok(records) = mcap::read::LinearReader::new_with_options(
        bytes,
        mcap::read::Options::IgnoreEndMagic.into(),
    ) else {
        return (metadata, data_whole);
    };
    for record in records.map_while(Result::ok) {
        match record {
            mcap::records::Record::Metadata(m) => {
                metadata.insert(m.name, m.metadata);
            }
            mcap::records::Record::DataEnd(_) => data_whole = true,
            _ => {}
        }
    }
    (metadata, data_whole)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_that_are_not_mcap_are_refused() {
        let err = read_run_bytes(b"not an mcap file").unwrap_err();
        assert!(matches!(err, LogError::LogRead(_)), "{err}");
    }

    #[test]
    fn files_that_are_not_regular_or_not_mcap_are_refused_before_they_are_read() {
        #[cfg(unix)]
        for special in ["/dev/zero", "/dev/null", "/"] {
            let err = read_log_file(special).unwrap_err().to_string();
            assert!(
                err.contains("not a regular file") && err.contains(special),
                "{err}"
            );
        }
        let dir = std::env::temp_dir().join(format!("tvmd-read-sparse-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let sparse = dir.join("sparse.mcap");
        let file = std::fs::File::create(&sparse).unwrap();
        // 1 TB of holes: refused on its first bytes, never read.
        file.set_len(1 << 40).unwrap();
        let err = read_log_file(&sparse).unwrap_err().to_string();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(
            err.contains("magic") && err.contains("sparse.mcap"),
            "{err}"
        );
    }

    #[test]
    fn a_missing_file_names_its_path() {
        let err = read_run("/nonexistent/dir/run.mcap")
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/dir/run.mcap"), "{err}");
    }

    #[test]
    fn a_log_is_read_back_tick_by_tick() {
        let dir = std::env::temp_dir().join(format!("tvmd-read-{}", std::process::id()));
        let path = dir.join("run.mcap");
        let mut log = crate::RunLog::create(&path).unwrap();
        let mut meta = BTreeMap::new();
        meta.insert("k".to_string(), "v".to_string());
        log.write_metadata("tvmd.test", meta).unwrap();
        for k in 0..3 {
            let t = f64::from(k) * 0.01 + 1e-17;
            let state = proto::State {
                t,
                position: vec![t, 0.1, 1.0 / 3.0],
                ..Default::default()
            };
            log.write(t, state).unwrap();
            log.write(
                t,
                proto::Lyapunov {
                    t,
                    v_x: t,
                    v_r: 2.0,
                },
            )
            .unwrap();
            let note = proto::Control {
                t,
                cycle_error: "skipped".into(),
                ..Default::default()
            };
            log.write(t, note).unwrap();
        }
        log.finish().unwrap();
        let run = read_run(&path).unwrap();
        assert_eq!(run.damage, None);
        // Cut anywhere after the first tick, the log reads up to the damage and says so.
        let bytes = std::fs::read(&path).unwrap();
        for keep in [bytes.len() - 1, bytes.len() - 100, bytes.len() / 2] {
            let cut = read_run_bytes(&bytes[..keep]);
            if let Ok(cut) = cut {
                assert!(cut.damage.is_some(), "{keep} of {} bytes", bytes.len());
                assert!(!cut.ticks.is_empty() && cut.ticks.len() <= 3);
                assert_eq!(cut.ticks[..], run.ticks[..cut.ticks.len()]);
            }
        }
        let cut = read_run_bytes(&bytes[..bytes.len() - 100]).unwrap();
        assert_eq!(cut.ticks, run.ticks, "only the summary section is lost");
        assert_eq!(cut.metadata["tvmd.test"]["k"], "v");
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(run.ticks.len(), 3);
        assert_eq!(
            run.ticks[2].state.position,
            vec![0.02 + 1e-17, 0.1, 1.0 / 3.0]
        );
        assert_eq!(run.ticks[1].lyapunov.as_ref().unwrap().v_x, 0.01 + 1e-17);
        assert!(run.ticks[0].control.is_none());
        assert_eq!(run.ticks[0].note.as_ref().unwrap().cycle_error, "skipped");
        assert_eq!(run.metadata["tvmd.test"]["k"], "v");
    }
}
