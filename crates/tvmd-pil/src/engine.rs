//! Where the core's cycle runs: [`CoreEngine`], implemented by the in-process
//! [`CoreController`] and by the processor-in-the-loop link (module `pil`), and wrapped by the
//! cycle recorder (module `recording`). The simulator's `TvmdController` drives any of them alike.

use tvmd_core::{
    AgentCommand, AgentReading, AnyAllocator, FailureMask, FaultMasking, FaultReport,
    HoverCapability, Real, Reference, ReportError, RigidState,
};

/// Agent capacity of the controller the simulator runs (the core's const generic `N`).
pub const MAX_AGENTS: usize = 16;

/// The core controller type the simulator runs, in `T` (f32: the type a flight controller runs).
pub type CoreController<T> = tvmd_core::Controller<T, MAX_AGENTS, AnyAllocator<T, MAX_AGENTS>>;

/// The core's output of one cycle.
pub type CoreOutput<T> = tvmd_core::ControlOutput<T, MAX_AGENTS>;

/// Boxed error of an engine (and of the simulator's flight controllers): what ends a run.
pub type BoxedError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// A cycle the core skipped: its message (the [`tvmd_core::CycleError`]'s) and the commands
/// it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct SkippedCycle<T: Real> {
    /// `CycleError`'s message.
    pub message: String,
    /// The commands held.
    pub commands: [AgentCommand<T>; MAX_AGENTS],
}

/// The core's answer to a failure mask: the accepted mask's hover classification, or the
/// message of the [`tvmd_core::ConfigError`] that refused it.
pub type FailureAnswer<T> = Result<HoverCapability<T>, String>;

/// The core's answer to one cycle.
pub type CycleAnswer<T> = Result<CoreOutput<T>, SkippedCycle<T>>;

/// A core controller in `T`, wherever it runs. The outer `Result` is the engine's own failure
/// (a broken link to a target), which ends the run; the inner one is the core's answer.
pub trait CoreEngine<T: Real> {
    /// [`tvmd_core::Controller::set_failures`].
    fn set_failures(
        &mut self,
        mask: FailureMask<MAX_AGENTS>,
    ) -> Result<FailureAnswer<T>, BoxedError>;

    /// [`tvmd_core::Controller::failures`]: the mask the core accepted.
    fn failures(&self) -> FailureMask<MAX_AGENTS>;

    /// [`tvmd_core::Controller::set_landed`]: the team is on the ground (the offset-free
    /// state is cleared and held). Without an offset-free action it changes nothing.
    fn set_landed(&mut self, landed: bool) -> Result<(), BoxedError>;

    /// [`tvmd_core::Controller::step`].
    fn step(
        &mut self,
        state: &RigidState<T>,
        reference: &Reference<T>,
    ) -> Result<CycleAnswer<T>, BoxedError>;

    /// [`tvmd_core::Controller::fault_report`] of the last cycle (`None` by default: an
    /// engine without the detector).
    fn fault_report(&self) -> Option<FaultReport<T>> {
        None
    }

    /// [`tvmd_core::Controller::fault_masking`]: the last mask the core set itself.
    fn fault_masking(&self) -> Option<FaultMasking<T>> {
        None
    }

    /// [`tvmd_core::Controller::set_report`]: agent `agent`'s own report for the next cycle;
    /// the inner `Result` is the core's answer. By default an engine that does not carry the
    /// agents' reports (the processor-in-the-loop link, the cycle recorder): an error that
    /// ends the run, never a report dropped in silence.
    fn set_report(
        &mut self,
        agent: usize,
        reading: AgentReading<T>,
    ) -> Result<Result<(), ReportError>, BoxedError> {
        let _ = (agent, reading);
        Err("this engine does not carry the agents' reports ([reports])".into())
    }
}

impl<T: Real> CoreEngine<T> for CoreController<T> {
    fn set_failures(
        &mut self,
        mask: FailureMask<MAX_AGENTS>,
    ) -> Result<FailureAnswer<T>, BoxedError> {
        Ok(tvmd_core::Controller::set_failures(self, mask).map_err(|e| e.to_string()))
    }

    fn failures(&self) -> FailureMask<MAX_AGENTS> {
        *tvmd_core::Controller::failures(self)
    }

    fn set_landed(&mut self, landed: bool) -> Result<(), BoxedError> {
        tvmd_core::Controller::set_landed(self, landed);
        Ok(())
    }

    fn step(
        &mut self,
        state: &RigidState<T>,
        reference: &Reference<T>,
    ) -> Result<CycleAnswer<T>, BoxedError> {
        Ok(
            tvmd_core::Controller::step(self, state, reference).map_err(|e| SkippedCycle {
                message: e.to_string(),
                commands: e.commands,
            }),
        )
    }

    fn fault_report(&self) -> Option<FaultReport<T>> {
        tvmd_core::Controller::fault_report(self).copied()
    }

    fn fault_masking(&self) -> Option<FaultMasking<T>> {
        tvmd_core::Controller::fault_masking(self)
    }

    fn set_report(
        &mut self,
        agent: usize,
        reading: AgentReading<T>,
    ) -> Result<Result<(), ReportError>, BoxedError> {
        Ok(tvmd_core::Controller::set_report(self, agent, reading))
    }
}
