//! One cycle's inputs and outputs as words, the recorded subset, hover answers and masks.

use tvmd_core::nalgebra::Vector3;
use tvmd_core::{
    AgentCommand, Allocation, ControlOutput, FailureMask, ForceProjection, HoverCapability,
    HoverLimit, LawOutput, PlannerOutput, PlannerStatus, Reference, RigidState,
};

use crate::*;

/// Appends one cycle's inputs ([`INPUT_WORDS`] words).
pub fn put_input(w: &mut Writer<'_>, s: &RigidState<f32>, r: &Reference<f32>) -> Option<()> {
    w.f32s(s.position.as_slice())?;
    w.m3(&s.attitude)?;
    w.f32s(s.angular_velocity.as_slice())?;
    w.f32s(s.velocity.as_slice())?;
    w.f32s(r.position.as_slice())?;
    w.f32s(r.velocity.as_slice())?;
    w.f32s(r.acceleration.as_slice())?;
    w.m3(&r.attitude)?;
    w.f32s(r.angular_velocity.as_slice())?;
    w.f32s(r.angular_acceleration.as_slice())
}

/// Reads one cycle's inputs written by [`put_input`].
pub fn get_input(r: &mut Reader<'_>) -> Option<(RigidState<f32>, Reference<f32>)> {
    let state = RigidState {
        position: r.v3()?,
        attitude: r.m3()?,
        angular_velocity: r.v3()?,
        velocity: r.v3()?,
    };
    let reference = Reference {
        position: r.v3()?,
        velocity: r.v3()?,
        acceleration: r.v3()?,
        attitude: r.m3()?,
        angular_velocity: r.v3()?,
        angular_acceleration: r.v3()?,
    };
    Some((state, reference))
}

fn status_code(s: PlannerStatus) -> u32 {
    match s {
        PlannerStatus::AlreadyFeasible => 0,
        PlannerStatus::Planned => 1,
        PlannerStatus::ZeroForce => 2,
        PlannerStatus::Unreachable => 3,
    }
}

fn status_of(code: u32) -> Option<PlannerStatus> {
    PlannerStatus::ALL.get(usize::try_from(code).ok()?).copied()
}

/// Appends `n` agents' commands (`eta_x`, `eta_y`, thrust, rotor speed each).
pub fn put_commands(w: &mut Writer<'_>, c: &[AgentCommand<f32>], n: usize) -> Option<()> {
    c.get(..n)?
        .iter()
        .try_for_each(|c| w.f32s(&[c.eta_x, c.eta_y, c.thrust, c.omega]))
}

/// Reads `n` agents' commands written by [`put_commands`] (the other slots idle).
pub fn get_commands(r: &mut Reader<'_>, n: usize) -> Option<[AgentCommand<f32>; AGENTS]> {
    let mut c = [AgentCommand::idle(); AGENTS];
    for c in c.get_mut(..n)? {
        let [eta_x, eta_y, thrust, omega] = r.array()?;
        *c = AgentCommand {
            eta_x,
            eta_y,
            thrust,
            omega,
        };
    }
    Some(c)
}

/// Appends the whole output of a cycle for `n` agents ([`output_words`]`(n)` words).
pub fn put_output(w: &mut Writer<'_>, o: &WireOutput, n: usize) -> Option<()> {
    let p = &o.planner;
    w.m3(&p.r_d)?;
    w.f32(p.theta)?;
    w.u32(p.iterations)?;
    w.u32(status_code(p.status))?;
    w.f32s(o.projection.force.as_slice())?;
    w.f32s(&[o.projection.t_tf, o.projection.t_eta])?;
    w.f32s(o.f_r.as_slice())?;
    let l = &o.law;
    for v in [&l.e_x, &l.e_r] {
        w.f32s(v.as_slice())?;
    }
    for v in [&l.e_xi, &l.u_r, &l.u_d] {
        w.f32s(v.as_slice())?;
    }
    w.f32s(&[l.v_r, l.v_x])?;
    let a = &o.allocation;
    a.forces
        .get(..n)?
        .iter()
        .try_for_each(|f| w.f32s(f.as_slice()))?;
    w.f32s(a.wrench.as_slice())?;
    w.f32s(&[a.e_f, a.wrench_error])?;
    w.u32(a.rounds)?;
    let saturated = a
        .saturated
        .iter()
        .enumerate()
        .fold(0u32, |m, (i, s)| m | (u32::from(*s) << i));
    w.u32(saturated)?;
    w.u32(u32::from(a.fallback))?;
    put_commands(w, &o.commands, n)?;
    w.f32(o.command_clamp)
}

/// Reads an output written by [`put_output`] (slots past `n`: zero forces, idle commands).
pub fn get_output(r: &mut Reader<'_>, n: usize) -> Option<WireOutput> {
    if n > AGENTS {
        return None;
    }
    let planner = PlannerOutput {
        r_d: r.m3()?,
        theta: r.f32()?,
        iterations: r.u32()?,
        status: status_of(r.u32()?)?,
    };
    let force = r.v3()?;
    let [t_tf, t_eta] = r.array()?;
    let projection = ForceProjection { force, t_tf, t_eta };
    let f_r = r.v3()?;
    let (e_x, e_r) = (r.v3()?, r.v3()?);
    let (e_xi, u_r, u_d) = (r.v6()?, r.v6()?, r.v6()?);
    let [v_r, v_x] = r.array()?;
    let law = LawOutput {
        e_x,
        e_r,
        e_xi,
        u_r,
        u_d,
        v_r,
        v_x,
    };
    let mut forces = [Vector3::zeros(); AGENTS];
    for f in forces.iter_mut().take(n) {
        *f = r.v3()?;
    }
    let wrench = r.v6()?;
    let [e_f, wrench_error] = r.array()?;
    let rounds = r.u32()?;
    let bits = r.u32()?;
    let saturated = core::array::from_fn(|i| i < n && bits & (1 << i) != 0);
    let fallback = r.u32()? != 0;
    let allocation = Allocation {
        forces,
        wrench,
        e_f,
        wrench_error,
        rounds,
        saturated,
        fallback,
    };
    let commands = get_commands(r, n)?;
    let command_clamp = r.f32()?;
    Some(ControlOutput {
        planner,
        projection,
        f_r,
        law,
        allocation,
        // The target runs without the null-space stage.
        null_space: tvmd_core::NullSpaceReport::off(),
        commands,
        command_clamp,
    })
}

/// Appends the recorded subset of a cycle ([`recorded_words`]`(n)` words): commands, `e_f`,
/// `R_d`, `theta` and the planner status; a skipped cycle (`out = None`) records the held
/// `commands`, zeros and [`STATUS_CYCLE_ERROR`].
pub fn put_recorded(
    w: &mut Writer<'_>,
    out: Option<&WireOutput>,
    commands: &[AgentCommand<f32>],
    n: usize,
) -> Option<()> {
    put_commands(w, commands, n)?;
    match out {
        Some(o) => {
            w.f32(o.allocation.e_f)?;
            w.m3(&o.planner.r_d)?;
            w.f32(o.planner.theta)?;
            w.u32(status_code(o.planner.status))
        }
        None => {
            w.f32s(&[0.0; 11])?;
            w.u32(STATUS_CYCLE_ERROR)
        }
    }
}

/// Appends a hover classification ([`HOVER_WORDS`] words).
pub fn put_hover(w: &mut Writer<'_>, h: &HoverCapability<f32>) -> Option<()> {
    w.u32(u32::from(h.capable))?;
    w.f32(h.margin)?;
    let agent = h
        .limiting_agent
        .map_or(Some(u32::MAX), |a| u32::try_from(a).ok())?;
    w.u32(agent)?;
    w.u32(match h.limit {
        HoverLimit::MaxThrust => 0,
        HoverLimit::MinThrust => 1,
        HoverLimit::GimbalX => 2,
        HoverLimit::GimbalY => 3,
    })?;
    w.f32(h.weight)
}

/// Words of [`put_hover`].
pub const HOVER_WORDS: usize = 5;

/// Reads a hover classification written by [`put_hover`].
pub fn get_hover(r: &mut Reader<'_>) -> Option<HoverCapability<f32>> {
    let capable = r.u32()? != 0;
    let margin = r.f32()?;
    let agent = r.u32()?;
    let limit = match r.u32()? {
        0 => HoverLimit::MaxThrust,
        1 => HoverLimit::MinThrust,
        2 => HoverLimit::GimbalX,
        3 => HoverLimit::GimbalY,
        _ => return None,
    };
    Some(HoverCapability {
        capable,
        margin,
        limiting_agent: (agent != u32::MAX).then_some(agent as usize),
        limit,
        weight: r.f32()?,
    })
}

/// A failure mask as bits (agent `i` failed: bit `i`).
pub fn mask_bits(mask: &FailureMask<AGENTS>) -> u32 {
    mask.as_array()
        .iter()
        .enumerate()
        .fold(0, |m, (i, f)| m | (u32::from(*f) << i))
}

/// The failure mask of [`mask_bits`].
pub fn mask_of(bits: u32) -> FailureMask<AGENTS> {
    let mut mask = FailureMask::none();
    for i in 0..AGENTS {
        // i < AGENTS: cannot fail.
        let _ = mask.set(i, bits & (1 << i) != 0);
    }
    mask
}

/// Applies a recorded cycle's event word to `ctl` in the simulator's order: the landed hold
/// ([`crate::EVENT_LANDED_SET`]), then the failure mask ([`crate::EVENT_SET`]). Returns
/// whether a mask was set; an error if the core accepted a mask the recording says it refused,
/// or the other way round.
pub fn replay_event(ctl: &mut crate::WireController, event: u32) -> Result<bool, &'static str> {
    if event & crate::EVENT_LANDED_SET != 0 {
        ctl.set_landed(event & crate::EVENT_LANDED != 0);
    }
    if event & crate::EVENT_SET == 0 {
        return Ok(false);
    }
    let refused = ctl.set_failures(mask_of(event)).is_err();
    if refused != (event & crate::EVENT_REFUSED != 0) {
        return Err("a failure mask was accepted on one side and refused on the other");
    }
    Ok(true)
}
