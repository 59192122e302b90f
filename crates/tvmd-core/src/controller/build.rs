//! Building a controller where it lives. [`Controller::init_in`] writes each part straight into
//! the caller's storage and [`Controller::reconfigure`] rebuilds a running controller the same
//! way, so no whole controller is ever on the stack: with 16 agents in `f32` it is about 4 KB,
//! more than a flight stack's work queue has (PX4: 2.2-3.2 KB). Every fallible step runs before
//! the first write, so an error leaves the storage, or the running controller, untouched.

use core::mem::{ManuallyDrop, MaybeUninit};
use core::ptr::{addr_of_mut, read};

use crate::afs::hover::{hover_capability, HoverLimit, StoredHover};
use crate::afs::planner::AttitudePlanner;
use crate::afs::{AttainableForceSpace, Relaxation};
use crate::agent::admissible::AdmissibleSet;
use crate::agent::command::AgentCommand;
use crate::allocation::Allocator;
use crate::fault::ReportState;
use crate::foundation::error::ConfigError;
use crate::foundation::real::Real;
use crate::foundation::stored::Stored;
use crate::law::attitude_rate::AttitudeRateState;
use crate::law::offset_free::OffsetFreeState;
use crate::law::{Gains, Plant};
use crate::team::{FailureMask, TeamConfig};

use super::detection::FaultMonitor;
use super::guard::input_limit;
use super::settings::StoredSettings;
use super::{Controller, ControllerSettings};

/// What a controller derives from its team and settings for a failure mask: everything that
/// can fail, computed before anything is written.
// `repr(C)`: 8 B less code in the flash build than Rust's field order.
#[repr(C)]
struct Parts<T: Real, const N: usize> {
    failures: FailureMask<N>,
    plant: Plant<T>,
    gains: Gains<T>,
    afs: AttainableForceSpace<T>,
    input_limit: T,
    offset_free: OffsetFreeState<T>,
    attitude_rate: Stored<AttitudeRateState<T>>,
    admissible: AdmissibleSet<T>,
    fault: Stored<FaultMonitor<T, N>>,
}

impl<T: Real, const N: usize> Parts<T, N> {
    // Written in place and not inlined, here and in `write`: their temporaries then share the
    // stack one after the other instead of adding up in the caller's frame.
    #[inline(never)]
    fn write_in<'p>(
        slot: &'p mut MaybeUninit<Self>,
        team: &TeamConfig<T, N>,
        settings: &ControllerSettings<T>,
        failures: FailureMask<N>,
    ) -> Result<&'p Self, ConfigError> {
        settings.validate()?;
        // Also rejects a gravity whose weight m_C g overflows.
        let plant = Plant::new(team.mass(), team.inertia(), settings.gravity)?;
        let gains =
            settings
                .gain_schedule
                .resolve(&settings.gains, team.mass(), &team.inertia())?;
        team.validate_failures(&failures)?;
        let afs = team.afs(&failures)?;
        let attitude_rate = match settings.attitude_rate {
            Some(filter) => Stored::Present(AttitudeRateState::new(filter, settings.period)?),
            None => Stored::Absent,
        };
        let fault = FaultMonitor::new(settings, team, plant.weight())?;
        Ok(slot.write(Self {
            failures,
            input_limit: input_limit(team, &gains, settings.gravity),
            offset_free: OffsetFreeState::new(
                settings.offset_free.as_ref(),
                settings.period,
                afs.max_force(),
            ),
            admissible: AdmissibleSet::from_limits(team.limits()),
            plant,
            gains,
            afs,
            attitude_rate,
            fault,
        }))
    }
}

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// Builds the controller of [`Self::new`] in `slot`, part by part, and returns it there:
    /// the same checks, errors and controller, without the whole controller on the stack (for
    /// storage of the caller's, such as the C interface's handle). `allocator` makes the
    /// allocator, called once all checks passed, so that it is made where it lives. On an
    /// error `slot` is not written.
    ///
    /// ```
    /// use core::mem::MaybeUninit;
    /// use tvmd_core::{team::presets, Controller, ControllerSettings, ExactBoundaryRedistribution};
    /// let team = presets::a4_inc::<f32, 16>()?;
    /// let mut slot = MaybeUninit::uninit();
    /// let controller = Controller::init_in(
    ///     &mut slot,
    ///     &team,
    ///     &ControllerSettings::default(),
    ///     ExactBoundaryRedistribution::new,
    /// )?;
    /// assert!(controller.hover_capability().capable);
    /// # Ok::<(), tvmd_core::ConfigError>(())
    /// ```
    pub fn init_in<'s>(
        slot: &'s mut MaybeUninit<Self>,
        team: &TeamConfig<T, N>,
        settings: &ControllerSettings<T>,
        allocator: impl FnOnce() -> A,
    ) -> Result<&'s mut Self, ConfigError> {
        // SAFETY: `slot` is valid for writes and aligned; `build_at` initializes every field
        // when it returns `Ok`.
        let controller = unsafe {
            build_at(
                slot.as_mut_ptr(),
                team,
                settings,
                allocator,
                FailureMask::none(),
            )?;
            slot.assume_init_mut()
        };
        controller.classify_hover();
        Ok(controller)
    }

    /// The checks of [`Self::new`] for `team` and `settings` (the allocator checks its own
    /// options when it is built), without building the controller.
    // Not inlined, as `reconfigure`: the parts' frame is not the caller's.
    #[inline(never)]
    pub fn check(
        team: &TeamConfig<T, N>,
        settings: &ControllerSettings<T>,
    ) -> Result<(), ConfigError> {
        Parts::write_in(
            &mut MaybeUninit::uninit(),
            team,
            settings,
            FailureMask::none(),
        )
        .map(|_| ())
    }

    /// Replaces team, settings and allocator while flying: all or nothing. The controller is
    /// rebuilt in place with the running one's failure mask, landed flag, held commands (when
    /// they are admissible for the new team, agent by agent; otherwise idle) and offset-free
    /// estimate (when both run the same kind of action, clamped onto the new bounds). On an
    /// error the running controller is untouched and steps exactly as before. `allocator`
    /// makes the new allocator, in place, once all checks passed.
    #[inline(never)]
    pub fn reconfigure(
        &mut self,
        team: &TeamConfig<T, N>,
        settings: &ControllerSettings<T>,
        allocator: impl FnOnce() -> A,
    ) -> Result<(), ConfigError> {
        let (failures, offset_free, previous) = (self.failures, self.offset_free, self.previous);
        let this: *mut Self = self;
        // SAFETY: `this` is valid, aligned and initialized. A bitwise copy of the old
        // allocator is taken first: on an error `build_at` wrote nothing and the copy is
        // forgotten (the controller still owns the allocator); on success every field was
        // written again and the copy is the only owner, dropped here. Nothing but the
        // allocator owns anything to drop.
        unsafe {
            let old = ManuallyDrop::new(read(addr_of_mut!((*this).allocator)));
            build_at(this, team, settings, allocator, failures)?;
            drop(ManuallyDrop::into_inner(old));
        }
        self.classify_hover();
        self.offset_free.carry_over(&offset_free);
        self.previous = self.held_from(&previous);
        self.note_held_commands();
        Ok(())
    }

    /// The hover classification of the working agents (after `write`, on its own stack).
    #[inline(never)]
    fn classify_hover(&mut self) {
        self.hover =
            hover_capability(&self.effectiveness, &self.admissible, self.plant.weight()).into();
    }

    /// `previous` agent by agent where this controller admits it, otherwise idle.
    fn held_from(&self, previous: &[AgentCommand<T>; N]) -> [AgentCommand<T>; N] {
        let mut held = [AgentCommand::idle(); N];
        for (i, (slot, old)) in held.iter_mut().zip(previous).enumerate() {
            if self.admits(i, old) {
                *slot = *old;
            }
        }
        held
    }
}

/// Derives the parts (every fallible step) and, when all succeed, writes the controller at
/// `this`. On an error nothing is written. Not inlined: the parts' frame is not the caller's.
///
/// # Safety
/// `this` is valid for writes and aligned.
#[inline(never)]
unsafe fn build_at<T: Real, const N: usize, A: Allocator<T, N>>(
    this: *mut Controller<T, N, A>,
    team: &TeamConfig<T, N>,
    settings: &ControllerSettings<T>,
    allocator: impl FnOnce() -> A,
    failures: FailureMask<N>,
) -> Result<(), ConfigError> {
    let mut parts = MaybeUninit::uninit();
    let parts = Parts::write_in(&mut parts, team, settings, failures)?;
    write(this, team, settings, parts);
    let slot = addr_of_mut!((*this).allocator);
    make_at(slot, allocator);
    (*slot).configure(&*addr_of_mut!((*this).effectiveness));
    Ok(())
}

/// Writes what `make` returns at `at`, its temporary on this function's own frame. With the
/// exact-boundary redistribution's workspace an allocator can be kilobytes.
///
/// # Safety
/// `at` is valid for writes and aligned; what it held is overwritten, not dropped.
#[inline(never)]
unsafe fn make_at<A>(at: *mut A, make: impl FnOnce() -> A) {
    at.write(make());
}

/// Writes every field of the controller of `team`, `settings` and `parts` at `this` but the
/// allocator, the effectiveness model in place; the hover classification is a placeholder
/// until `classify_hover`. What `this` held is overwritten, not dropped.
///
/// # Safety
/// `this` is valid for writes and aligned.
#[inline(never)]
unsafe fn write<T: Real, const N: usize, A: Allocator<T, N>>(
    this: *mut Controller<T, N, A>,
    team: &TeamConfig<T, N>,
    settings: &ControllerSettings<T>,
    parts: &Parts<T, N>,
) {
    let &Parts {
        failures,
        plant,
        gains,
        afs,
        input_limit,
        offset_free,
        attitude_rate,
        admissible,
        fault,
    } = parts;
    addr_of_mut!((*this).team).write(*team);
    StoredSettings::write_from(addr_of_mut!((*this).settings), settings);
    addr_of_mut!((*this).gains).write(gains);
    addr_of_mut!((*this).offset_free).write(offset_free);
    addr_of_mut!((*this).attitude_rate).write(attitude_rate);
    addr_of_mut!((*this).fault).write(fault);
    addr_of_mut!((*this).reports).write(ReportState::new());
    addr_of_mut!((*this).pending).write(Stored::Absent);
    addr_of_mut!((*this).plant).write(plant);
    addr_of_mut!((*this).planner).write(AttitudePlanner::new(settings.relaxation));
    addr_of_mut!((*this).failures).write(failures);
    addr_of_mut!((*this).full_cone).write(afs.cone(Relaxation::none()));
    addr_of_mut!((*this).planner_cone).write(afs.cone(settings.relaxation));
    addr_of_mut!((*this).afs).write(afs);
    addr_of_mut!((*this).admissible).write(admissible);
    addr_of_mut!((*this).previous).write([AgentCommand::idle(); N]);
    addr_of_mut!((*this).input_limit).write(input_limit);
    let effectiveness = addr_of_mut!((*this).effectiveness);
    team.write_effectiveness(&failures, effectiveness);
    addr_of_mut!((*this).hover).write(StoredHover {
        capable: false,
        margin: T::zero(),
        limiting_agent: Stored::Absent,
        limit: HoverLimit::MaxThrust,
        weight: plant.weight(),
    });
}
