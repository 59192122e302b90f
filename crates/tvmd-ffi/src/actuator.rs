//! Commands to normalized actuator outputs, as PX4's `actuator_motors` (motors in `[0, 1]`)
//! and `actuator_servos` (servos in `[-1, 1]`), through a channel map; and back.
//!
//! Each agent is a coaxial pair on a two-axis gimbal: both rotors turn at the same speed
//! (eq. 5: `omega_i = omega_i,P1 = omega_i,P2`), so an agent drives two motor channels with one
//! value, and two servo channels (`eta_x`, `eta_y`).
//!
//! - Motor value, `TVMD_MOTOR_CURVE_ROTOR_SPEED` (default, the rotor model of eq. 5):
//!   `omega / sigma_omega = sqrt(T / sigma_Tf)`. Use it with an output stage whose command is
//!   proportional to rotor speed: PX4 with `THR_MDL_FAC = 0` on an ESC that is linear in speed
//!   (e.g. RPM-controlled), since PX4 then passes the value through unchanged.
//!   `TVMD_MOTOR_CURVE_THRUST`: `T / sigma_Tf`, the normalized thrust PX4's own allocator
//!   publishes, for a PX4 output stage that linearizes thrust itself with `THR_MDL_FAC`.
//! - Servo value: `trim + direction * eta / range`, `range` the gimbal angle (rad) of a unit
//!   deflection from trim. The map is refused unless the whole gimbal travel `[-sigma, sigma]`
//!   lands inside `[-1, 1]`, so no admissible command is ever clipped.
//! - Unused channels are NaN, as PX4 marks a channel it does not drive; so are a failed
//!   agent's motors (PX4's "stopped": 0 would be an armed motor at its lowest command), and its
//!   servos are at trim.

use tvmd_core::command::command_tolerance;
use tvmd_core::AgentLimits;

use crate::handle::{controller, FfiController, TvmdController};
use crate::status::*;
use crate::types::TvmdAgentCommand;
use crate::TVMD_MAX_AGENTS;

/// `map.motor_curve`: `omega / sigma_omega` (eq. 5), the default.
pub const TVMD_MOTOR_CURVE_ROTOR_SPEED: u32 = 0;
/// `map.motor_curve`: `T / sigma_Tf`, normalized thrust.
pub const TVMD_MOTOR_CURVE_THRUST: u32 = 1;

/// Motor channels a map may use: PX4's `actuator_motors` has 12.
pub const TVMD_MOTOR_CHANNELS: u32 = 12;
/// Servo channels a map may use: PX4's `actuator_servos` has 8, so one stock output path
/// drives at most four two-axis agents.
pub const TVMD_SERVO_CHANNELS: u32 = 8;

/// Channels of each array of [`TvmdActuatorOutputs`], whatever the capacity: at least
/// `TVMD_MOTOR_CHANNELS` and `TVMD_SERVO_CHANNELS`.
pub const TVMD_OUTPUT_CHANNELS: usize = 16;

const _: () = assert!(TVMD_OUTPUT_CHANNELS >= TVMD_MOTOR_CHANNELS as usize);
const _: () = assert!(TVMD_OUTPUT_CHANNELS >= TVMD_SERVO_CHANNELS as usize);

/// One agent's channels.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdAgentChannels {
    /// The two `actuator_motors` channels of the coaxial pair (`0..TVMD_MOTOR_CHANNELS`).
    pub motor: [u32; 2],
    /// The `actuator_servos` channels of `[eta_x, eta_y]` (`0..TVMD_SERVO_CHANNELS`).
    pub servo: [u32; 2],
    /// Each servo's output at `eta = 0`, in `(-1, 1)`.
    pub servo_trim: [f32; 2],
    /// `+1` or `-1`: the sign of the servo output for a positive angle.
    pub servo_direction: [f32; 2],
    /// The gimbal angle (rad) of a unit deflection from trim, `> 0`.
    pub servo_range: [f32; 2],
}

/// The channel map of a team.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvmdActuatorMap {
    /// `sizeof(TvmdActuatorMap)`.
    pub size: u32,
    /// Must equal the controller's agent count.
    pub agent_count: u32,
    /// Per agent (the first `agent_count` are used).
    pub agents: [TvmdAgentChannels; TVMD_MAX_AGENTS],
    /// One of `TVMD_MOTOR_CURVE_*`.
    pub motor_curve: u32,
}

/// Normalized actuator outputs, 16 channels each (PX4's `actuator_motors` has 12 and
/// `actuator_servos` 8: copy the channels the vehicle uses).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvmdActuatorOutputs {
    /// `sizeof(TvmdActuatorOutputs)`, set by the caller.
    pub size: u32,
    /// Motor channels in `[0, 1]`; NaN when unused or the agent failed (stopped).
    pub motors: [f32; TVMD_OUTPUT_CHANNELS],
    /// Servo channels in `[-1, 1]`, NaN when unused.
    pub servos: [f32; TVMD_OUTPUT_CHANNELS],
}

fn size_ok<T>(size: u32) -> bool {
    usize::try_from(size).ok() == Some(core::mem::size_of::<T>())
}

/// The used channels of one kind; `TVMD_ERR_MAP_*` for an index at or beyond `limit` or a
/// repeat.
fn mark(
    used: &mut [bool; TVMD_OUTPUT_CHANNELS],
    channel: u32,
    limit: u32,
) -> Result<(), TvmdStatus> {
    let slot = usize::try_from(channel)
        .ok()
        .filter(|_| channel < limit)
        .and_then(|c| used.get_mut(c))
        .ok_or(TVMD_ERR_MAP_CHANNEL_RANGE)?;
    if *slot {
        return Err(TVMD_ERR_MAP_DUPLICATE_CHANNEL);
    }
    *slot = true;
    Ok(())
}

/// The map's agents, validated against the controller's team.
fn validate<'a>(
    map: &'a TvmdActuatorMap,
    controller: &FfiController,
) -> Result<&'a [TvmdAgentChannels], TvmdStatus> {
    if map.motor_curve != TVMD_MOTOR_CURVE_ROTOR_SPEED && map.motor_curve != TVMD_MOTOR_CURVE_THRUST
    {
        return Err(TVMD_ERR_ENUM_VALUE);
    }
    let n = controller.team().len();
    if usize::try_from(map.agent_count).ok() != Some(n) {
        return Err(TVMD_ERR_MAP_AGENT_COUNT);
    }
    let agents = map.agents.get(..n).ok_or(TVMD_ERR_MAP_AGENT_COUNT)?;
    let limits = controller.team().limits();
    let sigma = [limits.sigma_x(), limits.sigma_y()];
    let (mut motors, mut servos) = ([false; TVMD_OUTPUT_CHANNELS], [false; TVMD_OUTPUT_CHANNELS]);
    for agent in agents {
        for m in agent.motor {
            mark(&mut motors, m, TVMD_MOTOR_CHANNELS)?;
        }
        for s in agent.servo {
            mark(&mut servos, s, TVMD_SERVO_CHANNELS)?;
        }
        for (((trim, dir), range), sigma) in agent
            .servo_trim
            .iter()
            .zip(&agent.servo_direction)
            .zip(&agent.servo_range)
            .zip(sigma)
        {
            let usable = trim.is_finite()
                && (*dir == 1.0 || *dir == -1.0)
                && range.is_finite()
                && *range > 0.0
                && trim.abs() + sigma / range <= 1.0;
            if !usable {
                return Err(TVMD_ERR_MAP_SERVO);
            }
        }
    }
    Ok(agents)
}

/// A map and its controller, from raw pointers.
///
/// # Safety
/// Each pointer is null or points to its struct.
unsafe fn checked<'a>(
    handle: *const TvmdController,
    map: *const TvmdActuatorMap,
) -> Result<(&'a FfiController, &'a [TvmdAgentChannels], u32), TvmdStatus> {
    let map = map.as_ref().ok_or(TVMD_ERR_NULL_POINTER)?;
    if !size_ok::<TvmdActuatorMap>(map.size) {
        return Err(TVMD_ERR_SIZE);
    }
    let controller = controller(handle)?;
    Ok((controller, validate(map, controller)?, map.motor_curve))
}

/// Whether a command is finite and inside `E_f` (eq. 6) up to the core's round-off tolerance,
/// so that no output is clipped beyond round-off.
pub(crate) fn admissible(limits: &AgentLimits<f32>, c: &TvmdAgentCommand) -> bool {
    let tol = command_tolerance::<f32>();
    let within = |x: f32, hi: f32| x.is_finite() && x >= -tol * hi && x <= hi * (1.0 + tol);
    c.eta_x.is_finite()
        && c.eta_y.is_finite()
        && c.eta_x.abs() <= limits.sigma_x() + tol
        && c.eta_y.abs() <= limits.sigma_y() + tol
        && within(c.thrust, limits.max_thrust())
        && within(c.omega, limits.max_speed())
}

fn motor_value(curve: u32, limits: &AgentLimits<f32>, c: &TvmdAgentCommand) -> f32 {
    let value = if curve == TVMD_MOTOR_CURVE_THRUST {
        c.thrust / limits.max_thrust()
    } else {
        c.omega / limits.max_speed()
    };
    // Only round-off can leave [0, 1]: the command is inside E_f.
    value.clamp(0.0, 1.0)
}

/// Fills `map` with the default layout: agent `i` on motors `2i, 2i+1` and servos `2i`
/// (`eta_x`), `2i+1` (`eta_y`), trim 0, direction +1, range = the gimbal limit (so
/// `eta = +-sigma` is `+-1`), the rotor-speed curve. Teams of more than 4 agents need more
/// servo channels than PX4's `actuator_servos` has (`TVMD_ERR_MAP_CHANNEL_RANGE`). The caller sets `map->size` first.
///
/// # Safety
/// `handle` is null or a `TvmdController`; `map` is null or points to a `TvmdActuatorMap`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_actuator_map_default(
    handle: *const TvmdController,
    map: *mut TvmdActuatorMap,
) -> TvmdStatus {
    let Some(map) = map.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if !size_ok::<TvmdActuatorMap>(map.size) {
        return TVMD_ERR_SIZE;
    }
    let controller = match controller(handle) {
        Ok(c) => c,
        Err(status) => return status,
    };
    let n = controller.team().len();
    if 2 * n > TVMD_SERVO_CHANNELS as usize {
        return TVMD_ERR_MAP_CHANNEL_RANGE;
    }
    let limits = controller.team().limits();
    map.agent_count = u32::try_from(n).unwrap_or(0);
    map.motor_curve = TVMD_MOTOR_CURVE_ROTOR_SPEED;
    map.agents = [TvmdAgentChannels::default(); TVMD_MAX_AGENTS];
    for (i, agent) in (0u32..).zip(map.agents.iter_mut().take(n)) {
        *agent = TvmdAgentChannels {
            motor: [2 * i, 2 * i + 1],
            servo: [2 * i, 2 * i + 1],
            servo_trim: [0.0; 2],
            servo_direction: [1.0; 2],
            servo_range: [limits.sigma_x(), limits.sigma_y()],
        };
    }
    TVMD_OK
}

/// Checks `map` against the controller's team: agent count, motor channels below
/// `TVMD_MOTOR_CHANNELS` (12) and servo channels below `TVMD_SERVO_CHANNELS` (8), distinct per
/// kind, servo trim/direction/range usable, a known motor curve.
///
/// # Safety
/// As [`tvmd_actuator_map_default`].
#[no_mangle]
pub unsafe extern "C" fn tvmd_actuator_map_validate(
    handle: *const TvmdController,
    map: *const TvmdActuatorMap,
) -> TvmdStatus {
    match checked(handle, map) {
        Ok(_) => TVMD_OK,
        Err(status) => status,
    }
}

/// Maps `tvmd_step`'s commands (`commands`, `count` entries, normally `TvmdOutput.commands`
/// and `TVMD_MAX_AGENTS`) to normalized outputs through `map`. Failed agents (the controller's
/// mask) get NaN motors (PX4's "stopped") and servos at trim; channels no agent uses are NaN. A working agent's
/// command that is not finite or outside `E_f` is refused (`TVMD_ERR_ACTUATOR_VALUE`), never
/// clipped. On an error `outputs` is not written. Map `tvmd_step`'s output on an error status
/// too: its commands are the held ones.
///
/// # Safety
/// `commands` is null or points to `count` commands; the other pointers as
/// [`tvmd_actuator_map_default`], `outputs` writable.
#[no_mangle]
pub unsafe extern "C" fn tvmd_actuator_outputs(
    handle: *const TvmdController,
    map: *const TvmdActuatorMap,
    commands: *const TvmdAgentCommand,
    count: usize,
    outputs: *mut TvmdActuatorOutputs,
) -> TvmdStatus {
    let (Some(out), false) = (outputs.as_mut(), commands.is_null()) else {
        return TVMD_ERR_NULL_POINTER;
    };
    if !size_ok::<TvmdActuatorOutputs>(out.size) {
        return TVMD_ERR_SIZE;
    }
    let (controller, agents, curve) = match checked(handle, map) {
        Ok(c) => c,
        Err(status) => return status,
    };
    if count < agents.len() {
        return TVMD_ERR_SIZE;
    }
    let commands = core::slice::from_raw_parts(commands, agents.len());
    let limits = controller.team().limits();
    let failures = controller.failures();
    let working = commands
        .iter()
        .enumerate()
        .filter(|(i, _)| !failures.is_failed(*i));
    for (_, c) in working {
        if !admissible(limits, c) {
            return TVMD_ERR_ACTUATOR_VALUE;
        }
    }
    let mut motors = [f32::NAN; TVMD_OUTPUT_CHANNELS];
    let mut servos = [f32::NAN; TVMD_OUTPUT_CHANNELS];
    for (i, (agent, c)) in agents.iter().zip(commands).enumerate() {
        let failed = failures.is_failed(i);
        let motor = if failed {
            f32::NAN
        } else {
            motor_value(curve, limits, c)
        };
        let angles = if failed { [0.0; 2] } else { [c.eta_x, c.eta_y] };
        for m in agent.motor {
            if let Some(slot) = motors.get_mut(m as usize) {
                *slot = motor;
            }
        }
        for (k, eta) in angles.iter().enumerate() {
            let (Some(&channel), Some(&trim), Some(&dir), Some(&range)) = (
                agent.servo.get(k),
                agent.servo_trim.get(k),
                agent.servo_direction.get(k),
                agent.servo_range.get(k),
            ) else {
                continue;
            };
            if let Some(slot) = servos.get_mut(channel as usize) {
                // Within [-1, 1] by the map's validation; the bound only absorbs round-off.
                *slot = (trim + dir * eta / range).clamp(-1.0, 1.0);
            }
        }
    }
    out.motors = motors;
    out.servos = servos;
    TVMD_OK
}

/// The inverse of [`tvmd_actuator_outputs`] (for tests and telemetry): the commands that
/// `outputs` encodes through `map`, into `commands` (`count >= agent_count` entries; the rest
/// are not written). Failed agents read as idle. `TVMD_ERR_ACTUATOR_VALUE` if a used channel
/// is not finite, outside its range, or an agent's two motor channels differ.
///
/// # Safety
/// `commands` is null or points to `count` writable commands; the other pointers as
/// [`tvmd_actuator_map_default`].
#[no_mangle]
pub unsafe extern "C" fn tvmd_actuator_commands(
    handle: *const TvmdController,
    map: *const TvmdActuatorMap,
    outputs: *const TvmdActuatorOutputs,
    commands: *mut TvmdAgentCommand,
    count: usize,
) -> TvmdStatus {
    let (Some(outputs), false) = (outputs.as_ref(), commands.is_null()) else {
        return TVMD_ERR_NULL_POINTER;
    };
    if !size_ok::<TvmdActuatorOutputs>(outputs.size) {
        return TVMD_ERR_SIZE;
    }
    let (controller, agents, curve) = match checked(handle, map) {
        Ok(c) => c,
        Err(status) => return status,
    };
    if count < agents.len() {
        return TVMD_ERR_SIZE;
    }
    let limits = controller.team().limits();
    let failures = controller.failures();
    let mut decoded = [TvmdAgentCommand::default(); TVMD_MAX_AGENTS];
    for (i, (agent, slot)) in agents.iter().zip(decoded.iter_mut()).enumerate() {
        if failures.is_failed(i) {
            continue;
        }
        let motor = |k: usize| {
            agent
                .motor
                .get(k)
                .and_then(|&m| outputs.motors.get(m as usize))
                .copied()
                .unwrap_or(f32::NAN)
        };
        let (m0, m1) = (motor(0), motor(1));
        // `contains` is false for NaN.
        if !(0.0..=1.0).contains(&m0) || m0 != m1 {
            return TVMD_ERR_ACTUATOR_VALUE;
        }
        let mut angles = [0.0f32; 2];
        for (k, angle) in angles.iter_mut().enumerate() {
            let (Some(&channel), Some(&trim), Some(&dir), Some(&range)) = (
                agent.servo.get(k),
                agent.servo_trim.get(k),
                agent.servo_direction.get(k),
                agent.servo_range.get(k),
            ) else {
                return TVMD_ERR_ACTUATOR_VALUE;
            };
            let value = outputs
                .servos
                .get(channel as usize)
                .copied()
                .unwrap_or(f32::NAN);
            if !(-1.0..=1.0).contains(&value) {
                return TVMD_ERR_ACTUATOR_VALUE;
            }
            *angle = (value - trim) * dir * range;
        }
        let (thrust, omega) = if curve == TVMD_MOTOR_CURVE_THRUST {
            let thrust = m0 * limits.max_thrust();
            (thrust, limits.speed_for_thrust(thrust))
        } else {
            let omega = m0 * limits.max_speed();
            (limits.thrust_for_speed(omega), omega)
        };
        *slot = TvmdAgentCommand {
            eta_x: angles[0],
            eta_y: angles[1],
            thrust,
            omega,
        };
    }
    let out = core::slice::from_raw_parts_mut(commands, agents.len());
    for (slot, c) in out.iter_mut().zip(&decoded) {
        *slot = *c;
    }
    TVMD_OK
}
