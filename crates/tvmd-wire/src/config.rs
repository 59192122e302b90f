//! The f32 controller's configuration as words, and the controller built from it.

use tvmd_core::allocation::{AllocatorOptions, RoundCap};
use tvmd_core::nalgebra::{Matrix3, Vector3};
use tvmd_core::{
    AgentLimits, AgentSpec, AnyAllocator, ConfigError, Controller, ControllerSettings,
    FaultDetection, Gains, Navigator, RateLimits, Relaxation, TeamConfig,
};

use crate::fault::{get_fault_detection, put_fault_detection};
use crate::{LawWords, Reader, WireController, Writer, AGENTS, ALLOCATOR_NAME_BYTES};

/// Everything the simulator's f32 controller is built from, each value already rounded to f32
/// exactly as the simulator rounds it (module `config`): the team (agent positions, quarter
/// turns, masses, limits, navigator), the gains (`K_xi` diagonal in the order `[Omega; v]`),
/// relaxation `s`, gravity, period, optional rate limits, the allocator's name, the law
/// beyond the paper ([`LawWords`]), the fault detection and the allocator's round cap: every
/// setting the simulator's f32 controller flies with.
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
    /// Gain schedule, offset-free action and planned rates ([`LawWords::PAPER`]: the paper's).
    pub law: LawWords,
    /// The controller's fault detection, if any.
    pub fault_detection: Option<FaultDetection<f32>>,
    /// The exact-boundary redistribution's round cap, if any
    /// (`AllocatorOptions::max_rounds`), resolved: words `1, k` for `Rounds(k)`, `0, 0` for
    /// `Uncapped` (so the recordings of format 3, flown uncapped when the walk had no default
    /// cap, replay as they were flown).
    pub max_rounds: RoundCap,
}

impl CoreConfig {
    /// Appends the configuration's [`crate::config_words`]`(n)` words.
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
            .try_for_each(|c| w.u32(u32::from_le_bytes([c[0], c[1], c[2], c[3]])))?;
        self.law.put(w)?;
        put_fault_detection(w, self.fault_detection.as_ref())?;
        match self.max_rounds {
            RoundCap::Rounds(k) => w.u32(1).and_then(|()| w.u32(k)),
            RoundCap::Uncapped => w.f32s(&[0.0; 2]),
        }
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
        let law = LawWords::get(r)?;
        let fault_detection = get_fault_detection(r)?;
        let max_rounds = match (r.u32()?, r.u32()?) {
            (0, _) => RoundCap::Uncapped,
            (1, k) => RoundCap::Rounds(k),
            _ => return None,
        };
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
            law,
            fault_detection,
            max_rounds,
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
        let mut settings = ControllerSettings {
            gains,
            relaxation: Relaxation::new(self.relaxation)?,
            gravity: self.gravity,
            period: self.period,
            rate_limits,
            null_space: None,
            gain_schedule: tvmd_core::GainSchedule::AsGiven,
            offset_free: None,
            attitude_rate: None,
            fault_detection: self.fault_detection,
        };
        self.law.apply(&mut settings)?;
        let options = AllocatorOptions {
            max_rounds: Some(self.max_rounds),
            ..Default::default()
        };
        let alloc = AnyAllocator::from_name(self.allocator_name(), &options)?;
        Controller::new(team, settings, alloc)
    }
}
