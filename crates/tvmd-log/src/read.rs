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

/// Reads the log at `path` ([`read_run_bytes`]); errors name the path.
pub fn read_run(path: impl AsRef<Path>) -> Result<LoggedRun, LogError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(LogError::file("read the MCAP log", path))?;
    read_run_bytes(&bytes).map_err(|e| match e {
        LogError::LogRead(m) => LogError::LogRead(format!("{}: {m}", path.display())),
        other => read_err(format!("{}: {other}", path.display())),
    })
}

/// Reads a run's log from the bytes of its MCAP file. Fails if the file is not MCAP, a
/// `tvmd.*` message does not decode, or the log has no `/state` message.
pub fn read_run_bytes(bytes: &[u8]) -> Result<LoggedRun, LogError> {
    let mut run = LoggedRun::default();
    let stream = mcap::MessageStream::new(bytes).map_err(|e| read_err(format!("not MCAP: {e}")))?;
    for m in stream {
        let m = m.map_err(|e| read_err(format!("corrupt MCAP: {e}")))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_that_are_not_mcap_are_refused() {
        let err = read_run_bytes(b"not an mcap file").unwrap_err();
        assert!(matches!(err, LogError::LogRead(_)), "{err}");
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
