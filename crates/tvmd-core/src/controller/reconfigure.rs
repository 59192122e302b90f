//! Changing a running controller without losing its state: cheap setters for the gains, the
//! relaxation and the rate limits, an all-or-nothing [`Controller::reconfigure`], and
//! [`Controller::seed_commands`] for a mode switch (the commands the vehicle flies now become
//! the held ones).

use crate::afs::planner::AttitudePlanner;
use crate::afs::Relaxation;
use crate::agent::command::AgentCommand;
use crate::agent::limits::RateLimits;
use crate::allocation::Allocator;
use crate::foundation::error::{ConfigError, InputError};
use crate::foundation::real::{lit, Real};
use crate::law::Gains;

use super::guard::input_limit;
use super::Controller;

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// New gains of eq. (12) (resolved by the settings' gain schedule for the team, as at
    /// [`Self::new`]); the input bound follows them. Errors leave the controller unchanged.
    pub fn set_gains(&mut self, gains: Gains<T>) -> Result<(), ConfigError> {
        let resolved =
            self.settings
                .gain_schedule
                .resolve(&gains, self.team.mass(), &self.team.inertia())?;
        self.settings.gains = gains;
        self.gains = resolved;
        self.input_limit = input_limit(&self.team, &self.gains, self.settings.gravity);
        Ok(())
    }

    /// A new AFS relaxation `s` of the planner (its tolerance and iteration cap kept).
    pub fn set_relaxation(&mut self, relaxation: Relaxation<T>) {
        let planner = AttitudePlanner::new(relaxation)
            .with_tolerance(self.planner.tolerance(), self.planner.max_iterations())
            .unwrap_or(AttitudePlanner::new(relaxation));
        self.set_planner(planner);
    }

    /// New gimbal rate limits (`None`: none), from the next period on.
    pub fn set_rate_limits(&mut self, rate_limits: Option<RateLimits<T>>) {
        self.settings.rate_limits = rate_limits.into();
    }

    /// The commands the vehicle flies now (a mode switch from another controller) become the
    /// held ones: what a refused period repeats and where rate limits start from. The
    /// allocator forgets its previous forces. Each working agent's command must lie in its
    /// admissible set `E_f` (eq. 6; gimbal and thrust limits, within the inversion's
    /// tolerance); a failed agent's or an unused slot's must be idle.
    ///
    /// Errors: [`InputError::NonFinite`] or [`InputError::OutOfRange`] naming `commands`; the
    /// held commands are unchanged then.
    pub fn seed_commands(&mut self, commands: &[AgentCommand<T>; N]) -> Result<(), InputError> {
        for (i, c) in commands.iter().enumerate() {
            let values = [c.eta_x, c.eta_y, c.thrust, c.omega];
            if !values.iter().all(|x| x.is_finite()) {
                return Err(InputError::NonFinite { field: "commands" });
            }
            if !self.admits(i, c) {
                return Err(InputError::OutOfRange {
                    field: "commands",
                    limit: 0.0,
                });
            }
        }
        self.previous = *commands;
        self.note_held_commands();
        self.allocator.reset();
        Ok(())
    }

    /// Whether agent `i` may hold `command`: inside its admissible set (gimbal and thrust
    /// limits, within the inversion's tolerance) when it works, idle when it failed or the slot
    /// is unused.
    pub(super) fn admits(&self, i: usize, command: &AgentCommand<T>) -> bool {
        if self.effectiveness.block(i).is_some() {
            self.admissible.contains(&command.gimbal(), lit(1e-4)) && command.omega >= T::zero()
        } else {
            *command == AgentCommand::idle()
        }
    }
}
