//! Exact f32 layouts of what crosses from the simulator to an f32 controller and back: the
//! controller's configuration ([`CoreConfig`]), one cycle's inputs (state and reference) and
//! outputs (the whole [`ControlOutput`], or the recorded subset), as little-endian `u32` words
//! holding `f32` bits, plus the CRC-32 of the PIL frames.
//!
//! Shared verbatim (`#[path]` include) by the simulator and the firmware in
//! `embedded/target-tests` (the cycle recording and the processor-in-the-loop link), so that
//! both sides encode, decode and build the controller with the same code: only `core` and
//! `tvmd_core`, no allocation.

use tvmd_core::nalgebra::{Matrix3, Vector3, Vector6};
use tvmd_core::{
    AgentCommand, AgentLimits, AgentSpec, Allocation, AnyAllocator, ConfigError, ControlOutput,
    Controller, ControllerSettings, FailureMask, ForceProjection, Gains, HoverCapability,
    HoverLimit, LawOutput, Navigator, PlannerOutput, PlannerStatus, RateLimits, Reference,
    Relaxation, RigidState, TeamConfig,
};

/// Agent capacity of the controller on both sides (the simulator's `MAX_AGENTS`).
pub const AGENTS: usize = 16;

/// The f32 controller both sides build.
pub type WireController = Controller<f32, AGENTS, AnyAllocator<f32, AGENTS>>;

/// The f32 output of one cycle.
pub type WireOutput = ControlOutput<f32, AGENTS>;

/// Words of one cycle's inputs: state (`x`, `R`, `Omega`, `v`: 18) and reference (`x_r`,
/// `v_r`, `a_r`, `R_r`, `Omega_r`, `Omega_dot_r`: 24).
pub const INPUT_WORDS: usize = 42;

/// Longest allocator name carried by a [`CoreConfig`].
pub const ALLOCATOR_NAME_BYTES: usize = 32;

/// Words of a [`CoreConfig`] of `n` agents.
pub const fn config_words(n: usize) -> usize {
    // n, then per agent x, y, z, quarter turns, mass; limits 3; navigator 1 + 9; gains 3 + 3 +
    // 6; relaxation, gravity, period; rate-limit flag + 2; allocator name.
    1 + 5 * n + 3 + 10 + 12 + 3 + 3 + ALLOCATOR_NAME_BYTES / 4
}

/// Words of a whole [`ControlOutput`] of `n` agents ([`put_output`]).
pub const fn output_words(n: usize) -> usize {
    // planner 12, projection 5, f_r 3, law 26, allocation 3n + 11, commands 4n, clamp 1.
    12 + 5 + 3 + 26 + 3 * n + 11 + 4 * n + 1
}

/// Words of the recorded subset of one cycle's output ([`put_recorded`]).
pub const fn recorded_words(n: usize) -> usize {
    // commands 4n, e_f, R_d 9, theta, status.
    4 * n + 12
}

/// [`put_recorded`]'s status word of a skipped cycle (a `CycleError`; the commands are the
/// held ones, the rest zero).
pub const STATUS_CYCLE_ERROR: u32 = 0xff;

/// First word of a cycle recording (`"TVRC"`; format in `tvmd_sim::control::recording`).
pub const RECORDING_MAGIC: u32 = u32::from_le_bytes(*b"TVRC");
/// Format version of a cycle recording.
pub const RECORDING_VERSION: u32 = 1;
/// Words of a cycle recording's header (magic, version, agents, cycles, configuration words).
pub const RECORDING_HEADER_WORDS: usize = 5;
/// Recording event flag: a failure mask was set before this cycle.
pub const EVENT_SET: u32 = 1 << 31;
/// Recording event flag: the core refused that mask.
pub const EVENT_REFUSED: u32 = 1 << 30;

/// Words of one recorded cycle of `n` agents: event, inputs, recorded outputs.
pub const fn cycle_words(n: usize) -> usize {
    1 + INPUT_WORDS + recorded_words(n)
}

/// A cursor writing words into a buffer; every method returns `None` when it is full.
pub struct Writer<'a> {
    buf: &'a mut [u32],
    at: usize,
}

impl<'a> Writer<'a> {
    /// Writes from the start of `buf`.
    pub fn new(buf: &'a mut [u32]) -> Self {
        Self { buf, at: 0 }
    }

    /// Words written.
    pub fn len(&self) -> usize {
        self.at
    }

    /// Nothing written yet.
    pub fn is_empty(&self) -> bool {
        self.at == 0
    }

    /// One word.
    pub fn u32(&mut self, w: u32) -> Option<()> {
        *self.buf.get_mut(self.at)? = w;
        self.at += 1;
        Some(())
    }

    /// One float's bits.
    pub fn f32(&mut self, x: f32) -> Option<()> {
        self.u32(x.to_bits())
    }

    /// Floats.
    pub fn f32s(&mut self, xs: &[f32]) -> Option<()> {
        xs.iter().try_for_each(|x| self.f32(*x))
    }

    /// A matrix, row by row.
    pub fn m3(&mut self, m: &Matrix3<f32>) -> Option<()> {
        (0..3).try_for_each(|i| (0..3).try_for_each(|j| self.f32(*m.get((i, j))?)))
    }
}

/// A cursor reading words; every method returns `None` past the end.
pub struct Reader<'a> {
    words: &'a [u32],
    at: usize,
}

impl<'a> Reader<'a> {
    /// Reads from the start of `words`.
    pub fn new(words: &'a [u32]) -> Self {
        Self { words, at: 0 }
    }

    /// Words not read yet.
    pub fn remaining(&self) -> usize {
        self.words.len().saturating_sub(self.at)
    }

    /// One word.
    pub fn u32(&mut self) -> Option<u32> {
        let w = *self.words.get(self.at)?;
        self.at += 1;
        Some(w)
    }

    /// One float.
    pub fn f32(&mut self) -> Option<f32> {
        self.u32().map(f32::from_bits)
    }

    /// `K` floats.
    pub fn array<const K: usize>(&mut self) -> Option<[f32; K]> {
        let mut a = [0.0; K];
        for x in &mut a {
            *x = self.f32()?;
        }
        Some(a)
    }

    /// A vector.
    pub fn v3(&mut self) -> Option<Vector3<f32>> {
        self.array::<3>().map(Vector3::from)
    }

    /// A six-vector.
    pub fn v6(&mut self) -> Option<Vector6<f32>> {
        self.array::<6>().map(Vector6::from)
    }

    /// A matrix, row by row.
    pub fn m3(&mut self) -> Option<Matrix3<f32>> {
        let r = self.array::<9>()?;
        Some(Matrix3::new(
            r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8],
        ))
    }
}

/// Everything the simulator's f32 controller is built from, each value already rounded to f32
/// exactly as the simulator rounds it (module `config`): the team (agent positions, quarter
/// turns, masses, limits, navigator), the gains (`K_xi` diagonal in the order `[Omega; v]`),
/// relaxation `s`, gravity, period, optional rate limits and the allocator's name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoreConfig {
    /// Agents used (`<=` [`AGENTS`]).
    pub n: usize,
    /// Per agent: position (3), quarter turns, mass.
    pub agents: [([f32; 3], i32, f32); AGENTS],
    /// `sigma_x`, `sigma_y`, `sigma_Tf`.
    pub limits: [f32; 3],
    /// Navigator mass and inertia (row by row).
    pub navigator: (f32, [f32; 9]),
    /// Diagonal gains `K_x`, `K_R`, `K_xi`.
    pub gains: ([f32; 3], [f32; 3], [f32; 6]),
    /// Relaxation `s`.
    pub relaxation: f32,
    /// Gravity (m/s^2).
    pub gravity: f32,
    /// Controller period (s).
    pub period: f32,
    /// Controller rate limits of `eta_x`, `eta_y` (rad/s), if any.
    pub rate_limits: Option<[f32; 2]>,
    /// Allocator name, zero-padded.
    pub allocator: [u8; ALLOCATOR_NAME_BYTES],
}

impl CoreConfig {
    /// Appends the configuration's [`config_words`]`(n)` words.
    pub fn put(&self, w: &mut Writer<'_>) -> Option<()> {
        w.u32(u32::try_from(self.n).ok()?)?;
        for (p, turns, mass) in self.agents.get(..self.n)? {
            w.f32s(p)?;
            w.u32(*turns as u32)?;
            w.f32(*mass)?;
        }
        w.f32s(&self.limits)?;
        w.f32(self.navigator.0)?;
        w.f32s(&self.navigator.1)?;
        w.f32s(&self.gains.0)?;
        w.f32s(&self.gains.1)?;
        w.f32s(&self.gains.2)?;
        w.f32s(&[self.relaxation, self.gravity, self.period])?;
        match self.rate_limits {
            Some(r) => {
                w.u32(1)?;
                w.f32s(&r)?;
            }
            None => w.f32s(&[0.0; 3])?,
        }
        self.allocator
            .chunks(4)
            .try_for_each(|c| w.u32(u32::from_le_bytes([c[0], c[1], c[2], c[3]])))
    }

    /// Reads a configuration written by [`CoreConfig::put`].
    pub fn get(r: &mut Reader<'_>) -> Option<Self> {
        let n = usize::try_from(r.u32()?).ok().filter(|n| *n <= AGENTS)?;
        let mut agents = [([0.0; 3], 0, 0.0); AGENTS];
        for a in agents.iter_mut().take(n) {
            *a = (r.array()?, r.u32()? as i32, r.f32()?);
        }
        let limits = r.array()?;
        let navigator = (r.f32()?, r.array()?);
        let gains = (r.array()?, r.array()?, r.array()?);
        let [relaxation, gravity, period] = r.array()?;
        let flag = r.u32()?;
        let rates = r.array::<2>()?;
        let mut allocator = [0u8; ALLOCATOR_NAME_BYTES];
        for c in allocator.chunks_mut(4) {
            c.copy_from_slice(&r.u32()?.to_le_bytes());
        }
        Some(Self {
            n,
            agents,
            limits,
            navigator,
            gains,
            relaxation,
            gravity,
            period,
            rate_limits: (flag == 1).then_some(rates),
            allocator,
        })
    }

    /// The allocator's name (up to the first zero byte).
    pub fn allocator_name(&self) -> &str {
        let len = self.allocator.iter().position(|b| *b == 0);
        let bytes = self.allocator.get(..len.unwrap_or(ALLOCATOR_NAME_BYTES));
        bytes
            .and_then(|b| core::str::from_utf8(b).ok())
            .unwrap_or("")
    }

    /// The controller, built as the simulator builds it (`TvmdController::from_scenario`).
    pub fn build(&self) -> Result<WireController, ConfigError> {
        let mut agents = [AgentSpec::new(Vector3::zeros(), 0, 0.0); AGENTS];
        for (spec, (p, turns, mass)) in agents.iter_mut().zip(&self.agents) {
            *spec = AgentSpec::new(Vector3::from(*p), *turns, *mass);
        }
        let [sx, sy, tf] = self.limits;
        let limits = AgentLimits::new(sx, sy, tf)?;
        let i = self.navigator.1;
        let navigator = Navigator {
            mass: self.navigator.0,
            inertia: Matrix3::new(i[0], i[1], i[2], i[3], i[4], i[5], i[6], i[7], i[8]),
        };
        let team = TeamConfig::new(agents.get(..self.n).unwrap_or(&[]), limits, navigator)?;
        let gains = Gains::diagonal(self.gains.0, self.gains.1, self.gains.2)?;
        let rate_limits = match self.rate_limits {
            Some([x, y]) => Some(RateLimits::new(x, y)?),
            None => None,
        };
        let settings = ControllerSettings {
            gains,
            relaxation: Relaxation::new(self.relaxation)?,
            gravity: self.gravity,
            period: self.period,
            rate_limits,
            null_space: None,
            gain_schedule: tvmd_core::GainSchedule::AsGiven,
            offset_free: None,
            attitude_rate: None,
        };
        let alloc = AnyAllocator::from_name(self.allocator_name(), &Default::default())?;
        Controller::new(team, settings, alloc)
    }
}

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

// Processor-in-the-loop frames: `FRAME_MAGIC`, kind (u16), sequence number (u16), payload
// length in bytes (u32, a multiple of 4, at most `MAX_PAYLOAD_BYTES`), the payload, and the
// CRC-32 of everything after the magic. Each host frame gets exactly one reply echoing its
// sequence number; the target sends `KIND_READY` once at boot.

/// First bytes of every frame.
pub const FRAME_MAGIC: [u8; 4] = *b"TVPL";
/// Bytes before the payload (magic, kind, sequence, length).
pub const FRAME_HEADER_BYTES: usize = 12;
/// Largest payload of a frame.
pub const MAX_PAYLOAD_BYTES: usize = 2048;
/// Protocol version, the payload of `KIND_READY`.
pub const PROTOCOL_VERSION: u32 = 1;
/// Host: configure the controller ([`CoreConfig`] words). Reply `KIND_CONFIGURED` or
/// `KIND_REFUSED`.
pub const KIND_CONFIGURE: u16 = 1;
/// Host: set the failure mask (one word of [`mask_bits`]). Reply `KIND_HOVER` or
/// `KIND_REFUSED`.
pub const KIND_SET_FAILURES: u16 = 2;
/// Host: one cycle ([`INPUT_WORDS`] words). Reply `KIND_OUTPUT` or `KIND_SKIPPED`.
pub const KIND_STEP: u16 = 3;
/// Target: booted (one word, [`PROTOCOL_VERSION`]).
pub const KIND_READY: u16 = 0x80;
/// Target: controller built (the agent count).
pub const KIND_CONFIGURED: u16 = 0x81;
/// Target: mask accepted ([`put_hover`] words).
pub const KIND_HOVER: u16 = 0x82;
/// Target: the cycle's output ([`put_output`] words).
pub const KIND_OUTPUT: u16 = 0x83;
/// Target: the cycle was skipped (held commands, [`put_commands`] words, then the message).
pub const KIND_SKIPPED: u16 = 0x84;
/// Target: configuration or mask refused (the message).
pub const KIND_REFUSED: u16 = 0x85;
/// Target: the request was malformed or arrived out of order (the message).
pub const KIND_ERROR: u16 = 0x86;

/// The header of a frame.
pub fn frame_header(kind: u16, seq: u16, payload_bytes: u32) -> [u8; FRAME_HEADER_BYTES] {
    let mut h = [0u8; FRAME_HEADER_BYTES];
    let (magic, rest) = h.split_at_mut(4);
    magic.copy_from_slice(&FRAME_MAGIC);
    let (k, rest) = rest.split_at_mut(2);
    k.copy_from_slice(&kind.to_le_bytes());
    let (s, len) = rest.split_at_mut(2);
    s.copy_from_slice(&seq.to_le_bytes());
    len.copy_from_slice(&payload_bytes.to_le_bytes());
    h
}

/// The CRC-32 of a frame: over the header after the magic, then the payload.
pub fn frame_crc(header: &[u8; FRAME_HEADER_BYTES], payload: &[u8]) -> u32 {
    let tail = header.get(4..).unwrap_or(&[]);
    !crc32_update(crc32_update(!0, tail), payload)
}

/// CRC-32 (IEEE 802.3, reflected, as zlib's `crc32`): `!crc32_update(!0, bytes)`.
/// Hand-written, bitwise: this file is shared with the firmware, which has no dependency for
/// it, and frames are short.
pub fn crc32_update(crc: u32, bytes: &[u8]) -> u32 {
    bytes.iter().fold(crc, |crc, b| {
        (0..8).fold(crc ^ u32::from(*b), |c, _| {
            if c & 1 != 0 {
                (c >> 1) ^ 0xedb8_8320
            } else {
                c >> 1
            }
        })
    })
}
