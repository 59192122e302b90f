//! The allocation benchmark set (issue 16, item 4): seeded requests for four teams (and one
//! degraded team), attainable by construction or certified outside the attainable set, and the
//! evaluation of every allocator of [`tvmd_core::AnyAllocator`] on them.
//!
//! The set is one JSON file (`benches/data/allocation_set.json`, one request a line), written
//! by [`AllocationSet::generate`] with [`SEED`] (`tvmd-sim allocation-set`) and read by
//! [`AllocationSet::from_json`], the criterion bench `benches/allocation.rs` and any JSON reader
//! (Python: `json.load`). Each request holds the wrench `u = [u_tau; u_f]` in the team frame and:
//! - attainable ones, the agent-frame forces `f` that produce it (`u = M f`, eq. 4), each inside
//!   its agent's `E_f` (eq. 6) by construction from gimbal angles and thrust in their ranges;
//! - outside ones, the certificate that no admissible `f` produces it (see [`Certificate`]).

mod commands;
mod evaluate;
mod generate;

pub use commands::{allocator_names, evaluate_file, write_set};
pub use evaluate::{
    closed_loop_rows, evaluate_requests, evaluate_set, markdown_by_kind, markdown_closed_loop,
    markdown_table, ClosedLoopRow, EvaluationRow, EXACT_TOLERANCE,
};
pub use generate::SET_TEAMS;

use serde::{Deserialize, Serialize};
use tvmd_core::team::presets;
use tvmd_core::{ConfigError, FailureMask, TeamConfig};

use crate::StudyError;

/// The seed of the committed set.
pub const SEED: u64 = 16;

/// The committed set, relative to the workspace root.
pub const SET_PATH: &str = "benches/data/allocation_set.json";

/// Radius of the 16-agent ring (m): its neighbours `2 pi r / 16 = 0.71` m apart, the side of the
/// paper's A4 square.
pub const RING16_RADIUS: f64 = 1.8;

/// The teams of the set, by preset name: A4-Inc, A6-Inc and A8-Inc (the authors' layouts,
/// `tvmd_core::team::presets`) and a 16-agent inconsistent ring of radius [`RING16_RADIUS`].
pub const TEAM_NAMES: [&str; 4] = ["a4_inc", "a6_inc", "a8_inc", "ring16_inc"];

/// Why a request is outside the attainable set, checkable from the team alone. With
/// `|eta_x| <= sigma_x < pi/2`, `|eta_y| <= sigma_y < pi/2` and `0 <= T <= sigma_Tf`, every
/// admissible `f_i` has `||f_i|| <= sigma_Tf` and `f_iz >= 0`, and `R_z(psi_i)` keeps both.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Certificate {
    /// `||u_f|| > bound = n sigma_Tf >= sum ||f_i||` (the working agents' thrust limits).
    ForceNorm,
    /// `||u_tau|| > bound = sigma_Tf sum ||p_i|| >= ||sum p_i x R_i f_i||`.
    TorqueNorm,
    /// `u_fz < bound = 0 <= sum f_iz` (no agent pushes down).
    Downward,
}

/// One request of the set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SetRequest {
    /// How it was made: `interior`, `thrust-bound`, `gimbal-bound`, `gimbal-corner`, `corner`,
    /// `mixed` (attainable), or the certificate's name (outside).
    pub kind: String,
    /// `u = [u_tau; u_f]` (N m, N).
    pub wrench: [f64; 6],
    /// Attainable requests: the generating agent-frame forces, one per agent (zero for failed
    /// agents).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub forces: Option<Vec<[f64; 3]>>,
    /// Outside requests: the certificate and its bound.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub certificate: Option<Certificate>,
    /// The certificate's bound (N or N m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bound: Option<f64>,
}

impl SetRequest {
    /// Whether it is attainable by construction (it carries generating forces).
    pub fn attainable(&self) -> bool {
        self.forces.is_some()
    }
}

/// The requests of one team (with its failed agents).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TeamRequests {
    /// One of [`TEAM_NAMES`].
    pub team: String,
    /// Failed agents (indices into the team), none for the intact team.
    pub failed: Vec<usize>,
    /// The requests.
    pub requests: Vec<SetRequest>,
}

impl TeamRequests {
    /// A label for tables: `A4-Inc`, `A4-Inc, agent 1 failed`, ...
    pub fn label(&self) -> String {
        let base = match self.team.as_str() {
            "a4_inc" => "A4-Inc".to_string(),
            "a6_inc" => "A6-Inc".to_string(),
            "a8_inc" => "A8-Inc".to_string(),
            "ring16_inc" => "ring-16-Inc".to_string(),
            other => other.to_string(),
        };
        match self.failed.as_slice() {
            [] => base,
            [i] => format!("{base}, agent {i} failed"),
            f => format!("{base}, agents {f:?} failed"),
        }
    }
}

/// The benchmark set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AllocationSet {
    /// The generator's seed.
    pub seed: u64,
    /// What the file is (for readers of the JSON).
    pub description: String,
    /// Per team.
    pub teams: Vec<TeamRequests>,
}

impl AllocationSet {
    /// Parses a set written by [`Self::to_json`].
    pub fn from_json(text: &str) -> Result<Self, StudyError> {
        Ok(serde_json::from_str(text)?)
    }

    /// The set as JSON, one request a line (shortest round-trip floats: the file reproduces
    /// every bit).
    pub fn to_json(&self) -> Result<String, StudyError> {
        let mut out = String::from("{\n");
        out += &format!("  \"seed\": {},\n", self.seed);
        out += &format!(
            "  \"description\": {},\n",
            serde_json::to_string(&self.description)?
        );
        out += "  \"teams\": [\n";
        for (t, team) in self.teams.iter().enumerate() {
            out += &format!(
                "    {{\"team\": {}, \"failed\": {}, \"requests\": [\n",
                serde_json::to_string(&team.team)?,
                serde_json::to_string(&team.failed)?
            );
            for (k, r) in team.requests.iter().enumerate() {
                let sep = if k + 1 < team.requests.len() { "," } else { "" };
                out += &format!("      {}{sep}\n", serde_json::to_string(r)?);
            }
            let sep = if t + 1 < self.teams.len() { "," } else { "" };
            out += &format!("    ]}}{sep}\n");
        }
        out += "  ]\n}\n";
        Ok(out)
    }
}

/// The team named `name` (one of [`TEAM_NAMES`]) with capacity `N`.
pub fn team<const N: usize>(name: &str) -> Result<TeamConfig<f64, N>, StudyError> {
    let built: Result<TeamConfig<f64, N>, ConfigError> = match name {
        "a4_inc" => presets::a4_inc(),
        "a6_inc" => presets::a6_inc(),
        "a8_inc" => presets::a8_inc(),
        "ring16_inc" => presets::ring(16, RING16_RADIUS, true, presets::paper_limits()),
        other => {
            return Err(StudyError::invalid_team(format!(
                "unknown benchmark team `{other}` (known: {})",
                TEAM_NAMES.join(", ")
            )))
        }
    };
    built.map_err(|e| StudyError::invalid_team(format!("{name}: {e}")))
}

/// The failure mask of `failed`, checked against the team (rank 6 left).
pub fn failure_mask<const N: usize>(
    team: &TeamConfig<f64, N>,
    failed: &[usize],
) -> Result<FailureMask<N>, StudyError> {
    let invalid =
        |e: ConfigError| StudyError::invalid_team(format!("failed agents {failed:?}: {e}"));
    let mask = FailureMask::with_failed(failed).map_err(invalid)?;
    team.validate_failures(&mask).map_err(invalid)?;
    Ok(mask)
}

/// The team's agent count (the capacity its evaluation uses).
pub fn team_size(name: &str) -> Result<usize, StudyError> {
    Ok(team::<16>(name)?.len())
}
