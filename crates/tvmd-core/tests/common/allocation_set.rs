//! The allocation benchmark set (`benches/data/allocation_set.json`, issue 16) read with
//! `serde_json` alone, so tvmd-core's tests and examples use it without the studies crate.
//! Each team is built as `tvmd_studies::allocation_bench::team` builds it.

#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::Vector6;
use tvmd_core::team::presets;
use tvmd_core::{FailureMask, Real, TeamConfig};

/// The committed set, as the benchmark and the studies read it.
pub const SET_JSON: &str = include_str!("../../../../benches/data/allocation_set.json");

/// The 16-agent ring's radius (`tvmd_studies::allocation_bench::RING16_RADIUS`).
pub const RING16_RADIUS: f64 = 1.8;

/// One team of the set: its preset name, failed agents, and every request (kind, wrench).
pub struct SetTeam {
    /// `a4_inc`, `a6_inc`, `a8_inc`, `ring16_inc`.
    pub team: String,
    /// Failed agents.
    pub failed: Vec<usize>,
    /// `(kind, u = [u_tau; u_f])` in the set's order.
    pub requests: Vec<(String, Vector6<f64>)>,
}

impl SetTeam {
    /// `a4_inc` or `a4_inc-f1`.
    pub fn id(&self) -> String {
        let failed: Vec<String> = self.failed.iter().map(|i| format!("-f{i}")).collect();
        format!("{}{}", self.team, failed.concat())
    }

    /// The number of agents of the team (intact).
    pub fn size(&self) -> usize {
        match self.team.as_str() {
            "a4_inc" => 4,
            "a6_inc" => 6,
            "a8_inc" => 8,
            _ => 16,
        }
    }

    /// The team with capacity `N` (its size) and its failure mask.
    pub fn build<T: Real, const N: usize>(&self) -> (TeamConfig<T, N>, FailureMask<N>) {
        let team = match self.team.as_str() {
            "a4_inc" => presets::a4_inc(),
            "a6_inc" => presets::a6_inc(),
            "a8_inc" => presets::a8_inc(),
            _ => presets::ring(
                16,
                nalgebra::convert(RING16_RADIUS),
                true,
                presets::paper_limits(),
            ),
        }
        .unwrap();
        (team, FailureMask::with_failed(&self.failed).unwrap())
    }

    /// Whether request `k` is attainable by construction.
    pub fn attainable(kind: &str) -> bool {
        !matches!(kind, "force-norm" | "torque-norm" | "downward")
    }
}

/// Every team of the committed set.
pub fn teams() -> Vec<SetTeam> {
    let v: serde_json::Value = serde_json::from_str(SET_JSON).unwrap();
    v["teams"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| SetTeam {
            team: t["team"].as_str().unwrap().to_string(),
            failed: t["failed"]
                .as_array()
                .unwrap()
                .iter()
                .map(|i| i.as_u64().unwrap() as usize)
                .collect(),
            requests: t["requests"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| {
                    let w: Vec<f64> = r["wrench"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|x| x.as_f64().unwrap())
                        .collect();
                    (
                        r["kind"].as_str().unwrap().to_string(),
                        Vector6::from_column_slice(&w),
                    )
                })
                .collect(),
        })
        .collect()
}
