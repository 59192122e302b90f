//! The plain C structs of the interface and their conversions to the core's types.
//!
//! Conventions: `f32` everywhere; SI units; z up; a 3x3 matrix is 9 floats row-major
//! (`m[3 * row + col]`); a boolean is a `uint32_t` (0 false, anything else true). Every struct
//! passed by pointer starts with `size`, which the caller sets to `sizeof` of the struct (the
//! library checks it against its own and returns `TVMD_ERR_SIZE` on a mismatch).

use tvmd_core::nalgebra::{Matrix3, Vector3};
use tvmd_core::{
    AgentCommand, AgentLimits, AgentSpec, ConfigError, Gains, HoverCapability, HoverLimit,
    PlannerStatus, Reference, RigidState,
};

use crate::fault::TvmdFaultDetection;
use crate::law::TvmdLaw;
use crate::status::{ConvertError, TvmdStatus};
use crate::TVMD_MAX_AGENTS;

/// One agent of the team (paper, "Modeling"): its gimbal centre, yaw and mass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdAgent {
    /// `p_i`, the gimbal centre in the team CoM frame `{C}` (m).
    pub position: [f32; 3],
    /// The yaw `psi_i = quarter_turns * pi/2`.
    pub quarter_turns: i32,
    /// `m_i` (kg), a point mass at `p_i`.
    pub mass: f32,
    /// The agent's own inertia about its centre in `{C}` axes (kg m^2), row-major; zeros for
    /// the paper's point-mass model.
    pub inertia: [f32; 9],
}

/// `limits.rotor_model`: `omega` normalized to 1 at `max_thrust` (`rho d^4 c_l = max_thrust`).
pub const TVMD_ROTOR_NORMALIZED: u32 = 0;
/// `limits.rotor_model`: the rotor constants of eq. (5), `T = rho d^4 c_l omega^2`, give
/// `max_thrust = rho d^4 c_l sigma_omega^2` and `omega` in rad/s (`max_thrust` is ignored).
pub const TVMD_ROTOR_CONSTANTS: u32 = 1;

/// Limits shared by every agent: gimbal limits and thrust range (eq. 6), rotor model (eq. 5).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdLimits {
    /// `sigma_x`, limit of `|eta_x|` (rad), in `(0, pi/2]`.
    pub sigma_x: f32,
    /// `sigma_y`, limit of `|eta_y|` (rad), in `(0, pi/2]`.
    pub sigma_y: f32,
    /// `sigma_Tf`, the maximum thrust of one agent (N) (with `TVMD_ROTOR_NORMALIZED`).
    pub max_thrust: f32,
    /// The idle thrust (N), in `[0, sigma_Tf)`.
    pub min_thrust: f32,
    /// `TVMD_ROTOR_NORMALIZED` or `TVMD_ROTOR_CONSTANTS`.
    pub rotor_model: u32,
    /// Air density `rho` (kg/m^3) (with `TVMD_ROTOR_CONSTANTS`).
    pub rho: f32,
    /// Rotor diameter `d` (m) (with `TVMD_ROTOR_CONSTANTS`).
    pub rotor_diameter: f32,
    /// Lift coefficient `c_l` (with `TVMD_ROTOR_CONSTANTS`).
    pub lift_coefficient: f32,
    /// `sigma_omega`, the maximum rotor speed (rad/s) (with `TVMD_ROTOR_CONSTANTS`).
    pub max_rotor_speed: f32,
}

/// The gains of eq. (12), each a symmetric positive definite 3x3 matrix, row-major.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdGains {
    /// `K_x`, position gain.
    pub k_x: [f32; 9],
    /// `K_R`, attitude gain.
    pub k_r: [f32; 9],
    /// `K_Omega`, angular-velocity block of `K_xi`.
    pub k_omega: [f32; 9],
    /// `K_v`, velocity block of `K_xi`.
    pub k_v: [f32; 9],
}

/// `allocator`: the redistributed pseudo-inverse (the paper's).
pub const TVMD_ALLOCATOR_REDISTRIBUTED_PSEUDO_INVERSE: u32 = 0;
/// `allocator`: the plain pseudo-inverse.
pub const TVMD_ALLOCATOR_PSEUDO_INVERSE: u32 = 1;
/// `allocator`: the weighted pseudo-inverse with `agent_weights`.
pub const TVMD_ALLOCATOR_WEIGHTED_PSEUDO_INVERSE: u32 = 2;
/// `allocator`: the exact-boundary incremental redistribution, the default of
/// `tvmd_config_paper` (starts from the previous period's forces; `tvmd_reset` and
/// `tvmd_set_failures` forget them).
pub const TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION: u32 = 3;
/// `allocator`: the redistributed pseudo-inverse capped at a few rounds per period (default 2,
/// `allocator_round_cap` and `allocator_max_rounds` set it, at least 1): a bounded period where
/// a request loads most agents to their limits; what it cannot meet is in the output's `e_f`.
pub const TVMD_ALLOCATOR_CAPPED_REDISTRIBUTION: u32 = 4;

/// `allocator_round_cap`: the library's default cap of the exact-boundary redistribution's
/// walk, [`TVMD_DEFAULT_MAX_ROUNDS`] rounds per period, and of the capped redistribution, 2
/// rounds (the other allocators have no rounds to cap).
pub const TVMD_ROUND_CAP_DEFAULT: u32 = 0;
/// `allocator_round_cap`: exactly `allocator_max_rounds` walk rounds per period (`0`: the
/// walk's start alone, the redistributed pseudo-inverse or the previous forces), or rounds of
/// the capped redistribution (at least 1).
pub const TVMD_ROUND_CAP_ROUNDS: u32 = 1;
/// `allocator_round_cap`: no cap beyond the walk's own `2 n + 4` rounds (research: about
/// 166,000 Cortex-M4F instructions for the worst n = 4 allocation of the allocation set), or
/// one round per agent for the capped redistribution.
pub const TVMD_ROUND_CAP_UNCAPPED: u32 = 2;
/// Walk rounds of `TVMD_ROUND_CAP_DEFAULT` (the core's `DEFAULT_MAX_ROUNDS`).
pub const TVMD_DEFAULT_MAX_ROUNDS: u32 = 2;

const _: () = assert!(TVMD_DEFAULT_MAX_ROUNDS == tvmd_core::allocation::DEFAULT_MAX_ROUNDS);

/// Everything `tvmd_create` needs. `tvmd_config_default` fills the paper's team and settings
/// with the offset-free law (the library's default); `tvmd_config_paper` the same team with the
/// paper's law.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvmdConfig {
    /// `sizeof(TvmdConfig)`.
    pub size: u32,
    /// `n`, the number of agents, `1..=TVMD_MAX_AGENTS`.
    pub agent_count: u32,
    /// The agents (the first `agent_count` are used).
    pub agents: [TvmdAgent; TVMD_MAX_AGENTS],
    /// `m_0`, the navigator's mass at the team CoM (kg), `>= 0`.
    pub navigator_mass: f32,
    /// `J_0`, the navigator's inertia about the team CoM (kg m^2), row-major.
    pub navigator_inertia: [f32; 9],
    /// The agent limits.
    pub limits: TvmdLimits,
    /// The gains of eq. (12) (used as `law.gain_schedule` says; ignored with
    /// `TVMD_GAINS_NATURAL`).
    pub gains: TvmdGains,
    /// The AFS relaxation `s` of the planner, in `(0, 1]` (eq. 8).
    pub relaxation: f32,
    /// `g` (m/s^2).
    pub gravity: f32,
    /// The control period `dt` (s).
    pub period: f32,
    /// Non-zero: limit the gimbal rates to `rate_limits` (rad/s, `[eta_x, eta_y]`).
    pub rate_limited: u32,
    /// Gimbal rate limits (rad/s) when `rate_limited`.
    pub rate_limits: [f32; 2],
    /// One of `TVMD_ALLOCATOR_*`.
    pub allocator: u32,
    /// Per-agent weights `w_i > 0` of the weighted pseudo-inverse (the first `agent_count`
    /// are used; ignored by the other allocators).
    pub agent_weights: [f32; TVMD_MAX_AGENTS],
    /// One of `TVMD_ROUND_CAP_*`: how the exact-boundary redistribution's walk is capped per
    /// period (a bound on its work: the best admissible forces found so far, with their true
    /// `e_f`). Zero is the library's default cap; another allocator refuses
    /// `TVMD_ROUND_CAP_ROUNDS` (`TVMD_ERR_CONFIG_UNUSED_OPTION`) and takes the other two; an
    /// unknown value is `TVMD_ERR_ENUM_VALUE`.
    pub allocator_round_cap: u32,
    /// Walk rounds per period with `TVMD_ROUND_CAP_ROUNDS` (any number, `0` included);
    /// ignored otherwise.
    pub allocator_max_rounds: u32,
    /// Agent fault detection (all zeros: off), see `TvmdFaultDetection`.
    pub fault: TvmdFaultDetection,
    /// The law beyond the paper: gain schedule, offset-free action, planned-rate filter (all
    /// zeros: the paper's law).
    pub law: TvmdLaw,
}

/// The measured state: pose and body-frame twist.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdState {
    /// `sizeof(TvmdState)`.
    pub size: u32,
    /// `x`, CoM position, inertial frame (m), z up.
    pub position: [f32; 3],
    /// `R`, body-to-inertial rotation, row-major.
    pub attitude: [f32; 9],
    /// `Omega`, body-frame angular velocity (rad/s).
    pub angular_velocity: [f32; 3],
    /// `v`, body-frame linear velocity (m/s), `x_dot = R v`.
    pub velocity: [f32; 3],
}

/// The full-pose reference.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdReference {
    /// `sizeof(TvmdReference)`.
    pub size: u32,
    /// `x_r` (m).
    pub position: [f32; 3],
    /// `x_r_dot` (m/s), inertial.
    pub velocity: [f32; 3],
    /// `x_r_ddot` (m/s^2), inertial.
    pub acceleration: [f32; 3],
    /// `R_r`, the reference attitude, row-major.
    pub attitude: [f32; 9],
    /// `Omega_d` (rad/s), body frame of the reference.
    pub angular_velocity: [f32; 3],
    /// `Omega_d_dot` (rad/s^2).
    pub angular_acceleration: [f32; 3],
}

/// One agent's command (eq. 6): gimbal angles, thrust and rotor speed.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdAgentCommand {
    /// Inner gimbal angle `eta_x` (rad), `|eta_x| <= sigma_x`.
    pub eta_x: f32,
    /// Outer gimbal angle `eta_y` (rad), `|eta_y| <= sigma_y`.
    pub eta_y: f32,
    /// Thrust `T` (N), in `[min_thrust, max_thrust]` (0 for a failed agent).
    pub thrust: f32,
    /// Rotor speed `omega` of both coaxial rotors (eq. 5: `omega_P1 = omega_P2`).
    pub omega: f32,
}

impl From<&AgentCommand<f32>> for TvmdAgentCommand {
    fn from(c: &AgentCommand<f32>) -> Self {
        Self {
            eta_x: c.eta_x,
            eta_y: c.eta_y,
            thrust: c.thrust,
            omega: c.omega,
        }
    }
}

/// `planner_status`: `R_r^T f_r` already in the AFS, `R_d = R_r`.
pub const TVMD_PLANNER_ALREADY_FEASIBLE: u32 = 0;
/// `planner_status`: the search found the smallest feasible tilt (the planner saturating).
pub const TVMD_PLANNER_PLANNED: u32 = 1;
/// `planner_status`: `f_r = 0`, `R_d = R_r`.
pub const TVMD_PLANNER_ZERO_FORCE: u32 = 2;
/// `planner_status`: `||f_r|| > n sigma_Tf`, `b_zd` as close to `f_r` as the rotation allows.
pub const TVMD_PLANNER_UNREACHABLE: u32 = 3;

/// What one `tvmd_step` produced.
///
/// On an error status ("hold"), `commands` are the last good period's commands (idle before
/// the first good period, or when the handle is not initialized): inside `E_f`, never NaN, to
/// be sent again. The diagnostics (`e_f`, `planned_attitude`, `planner_theta`,
/// `compensation_force`, `compensation_torque`) are NaN and `planner_status`/
/// `planner_iterations` 0 then: they were not computed this period.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvmdOutput {
    /// `sizeof(TvmdOutput)`, set by the caller.
    pub size: u32,
    /// The status `tvmd_step` returned.
    pub status: i32,
    /// `n`; commands beyond it are idle.
    pub agent_count: u32,
    /// Per-agent commands inside `E_f` (idle for failed agents).
    pub commands: [TvmdAgentCommand; TVMD_MAX_AGENTS],
    /// `e_f = ||u_fd - u_f||` (N), the allocation error of the force part.
    pub e_f: f32,
    /// `R_d`, the planned attitude, row-major.
    pub planned_attitude: [f32; 9],
    /// `theta*`, the planner's tilt from `b_zr` toward `f_r` (rad).
    pub planner_theta: f32,
    /// One of `TVMD_PLANNER_*`.
    pub planner_status: u32,
    /// The planner's search steps.
    pub planner_iterations: u32,
    /// The offset-free force (N, inertial frame) as it stands after this period: what the
    /// next period adds to its request before its own update (the observer's estimate of the
    /// unmodelled force is its negative). Zero without an offset-free action and while landed
    /// (`tvmd_set_landed`).
    pub compensation_force: [f32; 3],
    /// The offset-free torque (N m, body frame), as `compensation_force`.
    pub compensation_torque: [f32; 3],
}

impl TvmdOutput {
    /// The held output of an error: `commands`, NaN diagnostics, `status`.
    pub(crate) fn held(
        &mut self,
        status: TvmdStatus,
        agent_count: usize,
        commands: &[TvmdAgentCommand],
    ) {
        self.status = status;
        self.agent_count = u32::try_from(agent_count).unwrap_or(0);
        self.commands = [TvmdAgentCommand::default(); TVMD_MAX_AGENTS];
        for (slot, c) in self.commands.iter_mut().zip(commands) {
            *slot = *c;
        }
        self.e_f = f32::NAN;
        self.planned_attitude = [f32::NAN; 9];
        self.planner_theta = f32::NAN;
        self.planner_status = 0;
        self.planner_iterations = 0;
        self.compensation_force = [f32::NAN; 3];
        self.compensation_torque = [f32::NAN; 3];
    }
}

/// `hover.limit`: the maximum thrust `sigma_Tf`.
pub const TVMD_HOVER_LIMIT_MAX_THRUST: u32 = 0;
/// `hover.limit`: the idle thrust.
pub const TVMD_HOVER_LIMIT_MIN_THRUST: u32 = 1;
/// `hover.limit`: the inner gimbal limit `sigma_x`.
pub const TVMD_HOVER_LIMIT_GIMBAL_X: u32 = 2;
/// `hover.limit`: the outer gimbal limit `sigma_y`.
pub const TVMD_HOVER_LIMIT_GIMBAL_Y: u32 = 3;

/// Whether the working agents can hold hover with a margin (the core's `HoverCapability`),
/// classified when the failure mask is set.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdHover {
    /// `sizeof(TvmdHover)`, set by the caller.
    pub size: u32,
    /// Non-zero when the hover wrench is strictly inside the attainable set.
    pub capable: u32,
    /// The smallest normalized slack of any working agent (`<= 1`; `<= 0` at a bound).
    pub margin: f32,
    /// The agent whose slack is `margin`, or -1.
    pub limiting_agent: i32,
    /// The bound that agent is closest to, one of `TVMD_HOVER_LIMIT_*`.
    pub limit: u32,
    /// `m_C g` (N).
    pub weight: f32,
}

impl TvmdHover {
    pub(crate) fn fill(&mut self, hover: &HoverCapability<f32>) {
        self.capable = u32::from(hover.capable);
        self.margin = hover.margin;
        self.limiting_agent = hover
            .limiting_agent
            .and_then(|i| i32::try_from(i).ok())
            .unwrap_or(-1);
        self.limit = match hover.limit {
            HoverLimit::MaxThrust => TVMD_HOVER_LIMIT_MAX_THRUST,
            HoverLimit::MinThrust => TVMD_HOVER_LIMIT_MIN_THRUST,
            HoverLimit::GimbalX => TVMD_HOVER_LIMIT_GIMBAL_X,
            HoverLimit::GimbalY => TVMD_HOVER_LIMIT_GIMBAL_Y,
        };
        self.weight = hover.weight;
    }
}

/// The C code of a planner status.
pub fn planner_status_code(status: PlannerStatus) -> u32 {
    match status {
        PlannerStatus::AlreadyFeasible => TVMD_PLANNER_ALREADY_FEASIBLE,
        PlannerStatus::Planned => TVMD_PLANNER_PLANNED,
        PlannerStatus::ZeroForce => TVMD_PLANNER_ZERO_FORCE,
        PlannerStatus::Unreachable => TVMD_PLANNER_UNREACHABLE,
    }
}

pub(crate) fn vector(v: &[f32; 3]) -> Vector3<f32> {
    Vector3::from(*v)
}

pub(crate) fn matrix(m: &[f32; 9]) -> Matrix3<f32> {
    // Not `from_row_slice`: its length check is a panic path that only `opt-level = 3` removes.
    let [a, b, c, d, e, f, g, h, i] = *m;
    Matrix3::new(a, b, c, d, e, f, g, h, i)
}

pub(crate) fn row_major(m: &Matrix3<f32>) -> [f32; 9] {
    let mut out = [0.0; 9];
    for (slot, x) in out.iter_mut().zip(m.transpose().iter()) {
        *slot = *x;
    }
    out
}

impl TvmdState {
    pub(crate) fn to_core(self) -> RigidState<f32> {
        RigidState {
            position: vector(&self.position),
            attitude: matrix(&self.attitude),
            angular_velocity: vector(&self.angular_velocity),
            velocity: vector(&self.velocity),
        }
    }
}

impl TvmdReference {
    pub(crate) fn to_core(self) -> Reference<f32> {
        Reference {
            position: vector(&self.position),
            velocity: vector(&self.velocity),
            acceleration: vector(&self.acceleration),
            attitude: matrix(&self.attitude),
            angular_velocity: vector(&self.angular_velocity),
            angular_acceleration: vector(&self.angular_acceleration),
        }
    }
}

impl TvmdAgent {
    pub(crate) fn to_core(self) -> AgentSpec<f32> {
        let mut spec = AgentSpec::new(vector(&self.position), self.quarter_turns, self.mass);
        spec.inertia = matrix(&self.inertia);
        spec
    }
}

impl TvmdLimits {
    pub(crate) fn to_core(self) -> Result<AgentLimits<f32>, ConvertError> {
        let limits = match self.rotor_model {
            TVMD_ROTOR_NORMALIZED => AgentLimits::new(self.sigma_x, self.sigma_y, self.max_thrust)?,
            TVMD_ROTOR_CONSTANTS => AgentLimits::from_rotor(
                self.sigma_x,
                self.sigma_y,
                self.rho,
                self.rotor_diameter,
                self.lift_coefficient,
                self.max_rotor_speed,
            )?,
            _ => return Err(ConvertError::EnumValue),
        };
        Ok(limits.with_min_thrust(self.min_thrust)?)
    }
}

impl TvmdGains {
    pub(crate) fn to_core(self) -> Result<Gains<f32>, ConfigError> {
        Gains::new(
            matrix(&self.k_x),
            matrix(&self.k_r),
            matrix(&self.k_omega),
            matrix(&self.k_v),
        )
    }

    pub(crate) fn from_core(gains: &Gains<f32>) -> Self {
        Self {
            k_x: row_major(&gains.k_x()),
            k_r: row_major(&gains.k_r()),
            k_omega: row_major(&gains.k_omega()),
            k_v: row_major(&gains.k_v()),
        }
    }
}
