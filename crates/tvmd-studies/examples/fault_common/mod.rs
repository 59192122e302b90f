//! What the fault studies share (`fault_detection.rs`, `fault_reports.rs`): the flight phases,
//! the flight of a team with a Monte Carlo draw and the default conditions, a parallel map,
//! the delays of the detector's events and the median / worst of a column.

use tvmd_scenario::{FaultDetectionConfig, LawConfig, Scenario};
use tvmd_studies::montecarlo::{Conditions, Distributions, Draw};

pub const TEAMS: [&str; 3] = ["a4-inc", "a6-inc", "a8-inc"];

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    Hover,
    Wind,
    Tilt,
}

impl Phase {
    pub fn name(self) -> &'static str {
        match self {
            Self::Hover => "hover",
            Self::Wind => "wind",
            Self::Tilt => "tilt",
        }
    }

    /// When a fault strikes in this phase.
    pub fn fault_time(self) -> f64 {
        match self {
            Self::Hover | Self::Wind => 4.0,
            // Mid-tilt: the reference rolls over 4-10 s.
            Self::Tilt => 7.0,
        }
    }
}

/// The flight of `team` in `phase` with the offset-free law and `detection`, `edit` applied
/// (before the draw), the Monte Carlo draw `index` of the study seeded `seed` and
/// `conditions`.
pub fn flight(
    team: &str,
    phase: Phase,
    (seed, index): (u64, u64),
    detection: FaultDetectionConfig,
    conditions: &Conditions,
    edit: impl FnOnce(&mut Scenario),
) -> Result<Scenario, Box<dyn std::error::Error>> {
    let mut s = match phase {
        Phase::Hover => Scenario::builtin("hover")?,
        Phase::Wind => Scenario::builtin("wind")?,
        Phase::Tilt => Scenario::default(),
    };
    s.team.preset = Some(team.into());
    s.team.agents = None;
    s.law = LawConfig::default();
    s.fault_detection = Some(detection);
    edit(&mut s);
    let n = s.team_body()?.len();
    let mut s = Draw::new(&Distributions::default(), seed, index, n).apply(&s)?;
    conditions.apply(&mut s, seed, index);
    s.validate()?;
    Ok(s)
}

/// `f(k, item)` on `jobs` threads, the results in order (failed flights dropped).
pub fn map<T: Sync, R: Send>(
    items: &[T],
    jobs: usize,
    f: impl Fn(usize, &T) -> Option<R> + Sync,
) -> Vec<R> {
    tvmd_sim::pool::map_in_order(items, jobs, f)
        .into_iter()
        .flatten()
        .flatten()
        .collect()
}

/// `median / worst` with `digits` decimals, or `-` for none.
pub fn quantiles(mut v: Vec<f64>, digits: usize) -> String {
    if v.is_empty() {
        return "-".into();
    }
    v.sort_by(f64::total_cmp);
    format!("{:.digits$} / {:.digits$}", v[v.len() / 2], v[v.len() - 1])
}

/// The delay of `event` after the fault of `agent` at `t_f`: `Ok(None)` when nothing was
/// named, `Err(())` for another agent or an event before the fault.
pub fn delay_after(
    event: Option<tvmd_sim::FaultEvent>,
    agent: usize,
    t_f: f64,
) -> Result<Option<f64>, ()> {
    match event {
        None => Ok(None),
        Some(e) if e.agent == agent && e.time >= t_f => Ok(Some(e.time - t_f)),
        Some(_) => Err(()),
    }
}

/// One column of delays over `group`: how many runs had one, their `median / worst` with
/// `digits` decimals, and how many named another agent.
pub fn delay_column<R>(
    group: &[&R],
    delay: impl Fn(&R) -> Result<Option<f64>, ()>,
    digits: usize,
) -> (usize, String, usize) {
    let (mut delays, mut wrong) = (Vec::new(), 0);
    for r in group {
        match delay(r) {
            Ok(Some(d)) => delays.push(d),
            Ok(None) => {}
            Err(()) => wrong += 1,
        }
    }
    (delays.len(), quantiles(delays, digits), wrong)
}
