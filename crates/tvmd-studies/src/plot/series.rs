//! The data of a run's figures: from its samples or from its MCAP log.

use std::collections::BTreeMap;
use std::path::Path;

use prost::Message;
use tvmd_log::{proto, LogError, METADATA_SCENARIO};
use tvmd_sim::sim::Sample;

use crate::StudyError;

/// One time step of a plotted run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotPoint {
    /// Time (s).
    pub t: f64,
    /// `x` (m).
    pub position: [f64; 3],
    /// `x_r` (m).
    pub reference_position: [f64; 3],
    /// Roll, pitch, yaw of `R` (rad).
    pub roll_pitch_yaw: [f64; 3],
    /// Roll, pitch, yaw of `R_r` (rad).
    pub reference_roll_pitch_yaw: [f64; 3],
    /// Planned roll (rad).
    pub planned_roll: Option<f64>,
    /// `e_f` (N).
    pub e_f: Option<f64>,
    /// `V_x`.
    pub v_x: Option<f64>,
    /// `V_R`.
    pub v_r: Option<f64>,
}

impl PlotPoint {
    pub(super) fn position_error(&self) -> f64 {
        (0..3)
            .map(|i| (self.position[i] - self.reference_position[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// The time series of one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotSeries {
    /// Name shown in titles and legends (e.g. the scenario name).
    pub label: String,
    /// The planner relaxation `s` of the run, if known.
    pub relaxation: Option<f64>,
    /// The points, in time order.
    pub points: Vec<PlotPoint>,
}

fn read_err(what: impl Into<String>) -> StudyError {
    StudyError::Log(LogError::LogRead(what.into()))
}

fn arr3(v: &[f64], field: &str) -> Result<[f64; 3], StudyError> {
    <[f64; 3]>::try_from(v)
        .map_err(|_| read_err(format!("`{field}` has {} entries, not 3", v.len())))
}

impl PlotSeries {
    /// From a run's samples.
    pub fn from_samples(label: &str, relaxation: Option<f64>, samples: &[Sample]) -> Self {
        Self {
            label: label.to_string(),
            relaxation,
            points: samples
                .iter()
                .map(|s| PlotPoint {
                    t: s.t,
                    position: s.position,
                    reference_position: s.reference_position,
                    roll_pitch_yaw: s.roll_pitch_yaw,
                    reference_roll_pitch_yaw: s.reference_roll_pitch_yaw,
                    planned_roll: s.planned_roll,
                    e_f: s.e_f,
                    v_x: s.v_x,
                    v_r: s.v_r,
                })
                .collect(),
        }
    }

    /// From the bytes of an MCAP log written by the simulator: `/state`, `/reference`,
    /// `/planner`, `/allocation` and `/lyapunov` messages matched by log time; label and
    /// relaxation from the scenario metadata if present. Needs `/state` and `/reference`.
    pub fn from_mcap(bytes: &[u8]) -> Result<Self, StudyError> {
        let mut rows: BTreeMap<u64, PlotPoint> = BTreeMap::new();
        let mut seen_state = false;
        let mut seen_reference = false;
        let stream = mcap::MessageStream::new(bytes).map_err(|e| read_err(e.to_string()))?;
        for m in stream {
            let m = m.map_err(|e| read_err(e.to_string()))?;
            let topic = m.channel.topic.as_str();
            if !matches!(
                topic,
                "/state" | "/reference" | "/planner" | "/allocation" | "/lyapunov"
            ) {
                continue;
            }
            let row = rows.entry(m.log_time).or_default();
            row.t = m.log_time as f64 * 1e-9;
            let bad = |e: prost::DecodeError| {
                read_err(format!(
                    "`{topic}` message is not a tvmd protobuf message: {e}"
                ))
            };
            match topic {
                "/state" => {
                    seen_state = true;
                    let s = proto::State::decode(&*m.data).map_err(bad)?;
                    row.t = s.t;
                    row.position = arr3(&s.position, "/state.position")?;
                    row.roll_pitch_yaw = arr3(&s.roll_pitch_yaw, "/state.roll_pitch_yaw")?;
                }
                "/reference" => {
                    seen_reference = true;
                    let r = proto::Reference::decode(&*m.data).map_err(bad)?;
                    row.reference_position = arr3(&r.position, "/reference.position")?;
                    row.reference_roll_pitch_yaw =
                        arr3(&r.roll_pitch_yaw, "/reference.roll_pitch_yaw")?;
                }
                "/planner" => {
                    row.planned_roll =
                        Some(proto::Planner::decode(&*m.data).map_err(bad)?.planned_roll);
                }
                "/allocation" => {
                    row.e_f = Some(proto::Allocation::decode(&*m.data).map_err(bad)?.e_f);
                }
                _ => {
                    let l = proto::Lyapunov::decode(&*m.data).map_err(bad)?;
                    row.v_x = Some(l.v_x);
                    row.v_r = Some(l.v_r);
                }
            }
        }
        if !seen_state || !seen_reference {
            return Err(read_err(
                "the log has no `/state` or no `/reference` messages (not a tvmd-sim run?)",
            ));
        }
        let mut label = String::from("run");
        let mut relaxation = None;
        if let Ok(Some(summary)) = mcap::Summary::read(bytes) {
            for idx in summary
                .metadata_indexes
                .iter()
                .filter(|i| i.name == METADATA_SCENARIO)
            {
                if let Ok(meta) = mcap::read::metadata(bytes, idx) {
                    if let Some(n) = meta.metadata.get("name") {
                        label.clone_from(n);
                    }
                    relaxation = meta.metadata.get("relaxation").and_then(|s| s.parse().ok());
                }
            }
        }
        Ok(Self {
            label,
            relaxation,
            points: rows.into_values().collect(),
        })
    }

    /// Reads an MCAP file and calls [`PlotSeries::from_mcap`].
    pub fn from_mcap_file(path: impl AsRef<Path>) -> Result<Self, StudyError> {
        let path = path.as_ref();
        let bytes = tvmd_log::read_log_file(path)?;
        Self::from_mcap(&bytes).map_err(|e| match e {
            StudyError::Log(LogError::LogRead(m)) => {
                StudyError::Log(LogError::LogRead(format!("{}: {m}", path.display())))
            }
            other => other,
        })
    }

    pub(super) fn time_range(&self) -> (f64, f64) {
        let t0 = self.points.first().map_or(0.0, |p| p.t);
        let t1 = self.points.last().map_or(1.0, |p| p.t);
        (t0, if t1 > t0 { t1 } else { t0 + 1.0 })
    }

    pub(super) fn legend(&self) -> String {
        match self.relaxation {
            Some(s) => format!("s = {s}"),
            None => self.label.clone(),
        }
    }
}
