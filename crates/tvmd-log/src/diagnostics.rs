//! The diagnostics schema: what a flight controller may report at each tick, recorded in the
//! simulator's samples and logged on `/planner`, `/control`, `/allocation`, `/lyapunov`,
//! `/hover` and `/fault` (messages of [`crate::proto`]). The field names are the MCAP messages'
//! and stay stable; tvmd-sim re-exports the module as `tvmd_sim::diagnostics`.

use serde::{Deserialize, Serialize};

/// Attitude-planner diagnostics (logged on `/planner`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlannerDiagnostics {
    /// Planned attitude `R_d`, row-major.
    pub r_d: [[f64; 3]; 3],
    /// Bisection angle `theta*` (rad); 0 when `R_d = R_r`.
    pub theta: f64,
    /// Thrust scaling `t_Tf`.
    pub t_tf: f64,
    /// Gimbal scaling `t_eta`.
    pub t_eta: f64,
    /// Whether `R_r` itself was feasible.
    pub reference_feasible: bool,
    /// Planned roll `atan2(R_d[2,1], R_d[2,2])` (rad).
    #[serde(default)]
    pub planned_roll: f64,
    /// How the planner reached `R_d` (e.g. `already-feasible`, `planned`).
    #[serde(default)]
    pub status: String,
    /// Bisection iterations used.
    #[serde(default)]
    pub iterations: u32,
}

/// Control-law diagnostics (logged on `/control`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ControlDiagnostics {
    /// `u_r = [tau; f]` before projection.
    pub u_r: [f64; 6],
    /// `u_d = blockdiag(I, K_f) u_r`.
    pub u_d: [f64; 6],
    /// `e_x` (m).
    pub e_x: [f64; 3],
    /// `e_v` (m/s).
    pub e_v: [f64; 3],
    /// `e_R`.
    pub e_r: [f64; 3],
    /// `e_Omega` (rad/s).
    pub e_omega: [f64; 3],
    /// Thrust scaling `t_Tf` of the force projection.
    #[serde(default)]
    pub t_tf: f64,
    /// Gimbal scaling `t_eta` of the force projection.
    #[serde(default)]
    pub t_eta: f64,
    /// Anything else the controller wants logged.
    #[serde(default, skip_serializing_if = "serde_json::Value::is_null")]
    pub extra: serde_json::Value,
}

/// Allocation diagnostics (logged on `/allocation`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AllocationDiagnostics {
    /// Wrench `M f` of the allocated agent forces, `[tau; f]`.
    pub wrench: [f64; 6],
    /// Allocation error `e_f = ||u_fd - u_f||` (N).
    pub e_f: f64,
    /// Per agent: whether the allocator saturated it.
    pub saturated: Vec<bool>,
    /// `||u_d - M f||` over the whole wrench.
    #[serde(default)]
    pub wrench_error: f64,
    /// Solve rounds (pseudo-inverse 1, redistribution up to `n`, Clarabel: iterations).
    #[serde(default)]
    pub rounds: u32,
    /// The allocator fell back to another method.
    #[serde(default)]
    pub fallback: bool,
    /// Allocated agent-frame forces `f_i` (N).
    #[serde(default)]
    pub forces: Vec<[f64; 3]>,
    /// Rotor speeds of the commands (normalised to 1 at maximum thrust unless rotor constants
    /// are given).
    #[serde(default)]
    pub rotor_speeds: Vec<f64>,
    /// What the null-space stage changed, when the scenario runs one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub null_space: Option<NullSpaceDiagnostics>,
}

/// The null-space stage's report of one period (`tvmd_core::NullSpaceReport`, in f64).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NullSpaceDiagnostics {
    /// Accepted steps (0: the allocator's forces unchanged).
    pub iterations: u32,
    /// The objective before and after.
    pub objective: [f64; 2],
    /// The smallest normalized margin to the admissible boundary, before and after.
    pub margin: [f64; 2],
    /// Largest change of one agent's force (N).
    pub largest_force_change: f64,
    /// `||M f' - M f||`, the wrench the stage moved (round-off).
    pub wrench_drift: f64,
}

/// Lyapunov candidates (logged on `/lyapunov`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LyapunovDiagnostics {
    /// `V_x = ||e_x||_{K_x} + ||e_v||_{K_v}`.
    pub v_x: f64,
    /// `V_R = Psi(R, R_d) + ||e_Omega||_{K_Omega}`.
    pub v_r: f64,
}

/// The hover classification of the working agents (logged on `/hover`), reported at the tick
/// the controller accepted a new failure mask (`tvmd_core::Controller::set_failures`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HoverDiagnostics {
    /// The hover wrench is strictly inside the working agents' attainable wrench set.
    pub capable: bool,
    /// The certified margin (smallest normalized slack of any working agent; `<= 0`: none).
    pub margin: f64,
    /// The agent whose slack is the margin.
    #[serde(default)]
    pub limiting_agent: Option<usize>,
    /// The bound it is closest to (`max_thrust`, `min_thrust`, `gimbal_x`, `gimbal_y`).
    #[serde(default)]
    pub limit: String,
    /// The scenario's `failure_response` started a landing on this classification.
    #[serde(default)]
    pub landing: bool,
    /// The controller refused the new failure mask (the remaining team cannot produce every
    /// wrench) and keeps allocating to the agents it does not know have failed: why. The
    /// classification is then `capable: false` with no margin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refused: Option<String>,
}

/// The fault detector's verdict of one period (`tvmd_core::FaultVerdict`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FaultVerdictName {
    /// The residual is within the noise.
    #[default]
    Nominal,
    /// Above the threshold, no single agent explains it.
    Unexplained,
    /// One agent explains it, for fewer periods than the persistence.
    Suspected,
    /// One agent explained it for the persistence's periods.
    Confirmed,
}

/// What an isolated agent's residual looks like (`tvmd_core::FaultKind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FaultKindName {
    /// It delivers (almost) nothing.
    Loss,
    /// It delivers a fraction (`efficiency`).
    PartialLoss,
    /// Its force turned away from the command.
    StuckGimbal,
    /// Its reports stopped past the link timeout (named from the agents' reports only).
    LinkLoss,
}

/// Which check named the agent (`tvmd_core::FaultSource`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FaultSourceName {
    /// The wrench residual (the vehicle's motion).
    Residual,
    /// The agents' own reports checked against their commands.
    Reports,
}

/// The fault detector's report of one period (logged on `/fault`), when the controller runs
/// one (`[fault_detection]`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FaultDiagnostics {
    /// The residual in noise units, `||r||_Sigma`.
    pub statistic: f64,
    /// The threshold `k` it is compared with.
    pub threshold: f64,
    /// The verdict.
    pub verdict: FaultVerdictName,
    /// The isolated agent (suspected or confirmed).
    #[serde(default)]
    pub agent: Option<usize>,
    /// What its residual looks like.
    #[serde(default)]
    pub kind: Option<FaultKindName>,
    /// The fraction delivered, for a partial loss.
    #[serde(default)]
    pub efficiency: Option<f64>,
    /// Consecutive periods the agent has been the candidate (suspected).
    #[serde(default)]
    pub periods: u32,
    /// The agent the controller masked itself this period (`response = "mask"`).
    #[serde(default)]
    pub masked: Option<usize>,
    /// The check that named `agent` (none when no agent is named).
    #[serde(default)]
    pub source: Option<FaultSourceName>,
}

/// Optional diagnostics returned by a controller; every present part is logged and recorded.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Diagnostics {
    /// Planner.
    pub planner: Option<PlannerDiagnostics>,
    /// Control law.
    pub control: Option<ControlDiagnostics>,
    /// Allocation.
    pub allocation: Option<AllocationDiagnostics>,
    /// Lyapunov candidates.
    pub lyapunov: Option<LyapunovDiagnostics>,
    /// The controller skipped this cycle and held its previous commands, for this reason.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle_error: Option<String>,
    /// A note on the failure mask (e.g. the controller could not use the reported failures) or
    /// on the disarm after touchdown (`control::Touchdown`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure_note: Option<String>,
    /// The hover classification, at the tick a new failure mask was accepted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hover: Option<HoverDiagnostics>,
    /// The fault detector's report, when the controller runs one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fault: Option<FaultDiagnostics>,
}
