//! A controller in memory a stray write may have changed (a C caller's handle): the counts,
//! indices and enum tags the cycle loops or branches on, checked raw before any reference to
//! the controller is made. Floats need no check (every bit pattern is one); the cycle's loops
//! are bounded by the capacity `N` and constant caps whatever the stored counts hold.
//!
//! Every tag the controller stores has a defined place and values, so that it can be checked
//! here: its optional parts are [`Stored`]s (not `Option`s, whose tags Rust does not lay out),
//! its enums are `repr(u8)` (RFC 2195: the tag is the first byte, and a variant's fields follow
//! as in a `repr(C)` struct), and its flags are `bool`s (0 or 1). Each type checks its own tags
//! next to its definition (`storage_intact`), and this check calls them all.

use core::ptr::addr_of;

use super::cycle::PendingRecord;
use super::detection::FaultMonitor;
use super::settings::StoredSettings;
use super::Controller;
use crate::afs::EllipticCone;
use crate::agent::admissible::AdmissibleSet;
use crate::agent::effectiveness::Effectiveness;
use crate::allocation::Allocator;
use crate::foundation::real::Real;
use crate::foundation::stored::Stored;
use crate::law::attitude_rate::AttitudeRateState;
use crate::law::offset_free::OffsetFreeState;

/// `HoverLimit`'s variants (`repr(u8)`, tags `0..4`).
const HOVER_LIMITS: u8 = 4;

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// Whether the controller at `this` holds, where the cycle reads them, an agent count in
    /// `1..=N` that agrees with the working count and the effectiveness's count of blocks,
    /// valid flags and tags (the failure mask, the hover classification, the allocator's
    /// variant and what it keeps, and every optional part and enum of the settings, the
    /// offset-free state, the planned-rate filter, the fault monitor, the pending record, the
    /// effectiveness and the cones), a finite hover margin at the plant's weight and an
    /// admissible set equal to the team's limits. A controller some write changed there is
    /// refused before it is used (the C interface answers `TVMD_ERR_CORRUPTED`); any other
    /// change leaves every loop bounded and every index checked. About `8 N + 80` loads,
    /// compares and additions; reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes that held a
    /// controller before (any of them may have changed since).
    pub unsafe fn storage_intact(this: *const Self) -> bool {
        Self::counts_intact(this) && Self::tags_intact(this)
    }

    /// The counts, the failure flags, the hover classification and the admissible set.
    ///
    /// # Safety
    /// As [`Self::storage_intact`].
    unsafe fn counts_intact(this: *const Self) -> bool {
        let len = addr_of!((*this).team.len).read();
        let working = addr_of!((*this).afs.n).read();
        let blocks = addr_of!((*this).effectiveness.working).read();
        let failed = addr_of!((*this).failures.failed).cast::<[u8; N]>().read();
        let capable = addr_of!((*this).hover.capable).cast::<u8>().read();
        let limit = addr_of!((*this).hover.limit).cast::<u8>().read();
        // Floats only from here: every bit pattern is a value, so reading them whole is sound.
        let margin = addr_of!((*this).hover.margin).read();
        let weight = addr_of!((*this).hover.weight).read();
        let plant = addr_of!((*this).plant).read();
        let limits = addr_of!((*this).team.limits).read();
        let admissible = addr_of!((*this).admissible).read();
        // Flags 0 or 1 (their OR has no other bit), and the working count (a second copy of the
        // team's size) the team's less the failed agents: a flag set past the team, or a
        // changed size, makes the two disagree. Four flags a word, branch-free: a word's flags
        // sum to its top byte times 0x01010101 (exact while each is 0 or 1, else refused).
        let (mut bits, mut failed_agents) = (0_u32, 0_usize);
        let mut words = failed.chunks_exact(4);
        for word in &mut words {
            let w = u32::from_le_bytes(<[u8; 4]>::try_from(word).unwrap_or([0xff; 4]));
            bits |= w;
            failed_agents += (w.wrapping_mul(0x0101_0101) >> 24) as usize;
        }
        for b in words.remainder() {
            bits |= u32::from(*b);
            failed_agents += usize::from(*b);
        }
        (1..=N).contains(&len)
            && bits & 0xfefe_fefe == 0
            && len.checked_sub(failed_agents) == Some(working)
            && blocks == working
            && capable <= 1
            && limit < HOVER_LIMITS
            && Stored::tag_intact(addr_of!((*this).hover.limiting_agent))
            && margin.is_finite()
            && weight == plant.weight()
            && AdmissibleSet::from_limits(&limits) == admissible
    }

    /// The tags of the optional parts and enums, each type's own check.
    ///
    /// # Safety
    /// As [`Self::storage_intact`].
    unsafe fn tags_intact(this: *const Self) -> bool {
        StoredSettings::storage_intact(addr_of!((*this).settings))
            && OffsetFreeState::storage_intact(addr_of!((*this).offset_free))
            && Stored::storage_intact(addr_of!((*this).attitude_rate), |r| {
                AttitudeRateState::storage_intact(r)
            })
            && Stored::storage_intact(addr_of!((*this).fault), |m| FaultMonitor::storage_intact(m))
            && Stored::storage_intact(addr_of!((*this).pending), |p| {
                PendingRecord::storage_intact(addr_of!((*p).1))
            })
            && EllipticCone::storage_intact(addr_of!((*this).full_cone))
            && EllipticCone::storage_intact(addr_of!((*this).planner_cone))
            && Effectiveness::storage_intact(addr_of!((*this).effectiveness))
            && A::storage_intact(addr_of!((*this).allocator))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use core::mem::ManuallyDrop;
    use core::ptr::addr_of_mut;

    use core::ptr::addr_of;
    use nalgebra::Vector3;

    use crate::allocation::{Allocator, AllocatorOptions, AnyAllocator, NullSpaceObjective};
    use crate::team::presets;
    use crate::{AgentReading, Controller, ControllerSettings, FailureMask, FaultDetection};
    use crate::{FaultResponse, NullSpaceStage, RateLimits, Reference, RigidState};

    type Checked = Controller<f32, 4, AnyAllocator<f32, 4>>;

    fn controller() -> ManuallyDrop<Checked> {
        let team = presets::a4_inc::<f32, 4>().unwrap();
        let c = Controller::new(team, ControllerSettings::paper(), AnyAllocator::default());
        // Never dropped: the tests leave invalid tags in it.
        ManuallyDrop::new(c.unwrap())
    }

    /// Writes `byte` at `at` (a field of the controller `c` points to) and checks `c`.
    unsafe fn intact_after<F>(c: *mut Checked, at: *mut F, byte: u8) -> bool {
        at.cast::<u8>().write(byte);
        Checked::storage_intact(c)
    }

    #[test]
    fn an_intact_controller_passes_and_so_does_one_with_failures_set() {
        let mut c = controller();
        assert!(unsafe { Checked::storage_intact(&*c) });
        let mut mask = FailureMask::none();
        mask.set(2, true).unwrap();
        c.set_failures(mask).unwrap();
        assert!(unsafe { Checked::storage_intact(&*c) });
    }

    #[test]
    fn a_changed_count_flag_or_tag_is_refused() {
        unsafe {
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            assert!(!intact_after(p, addr_of_mut!((*p).team.len), 5), "len 5");
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            assert!(!intact_after(p, addr_of_mut!((*p).team.len), 0), "len 0");
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            assert!(!intact_after(p, addr_of_mut!((*p).afs.n), 3), "working 3");
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            let blocks = addr_of_mut!((*p).effectiveness.working);
            assert!(!intact_after(p, blocks, 0x41), "blocks 0x41");
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            let flag = addr_of_mut!((*p).failures.failed).cast::<u8>();
            assert!(!intact_after(p, flag, 0x41), "flag 0x41");
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            assert!(
                !intact_after(p, flag_of(p, 1), 1),
                "a failed agent the count ignores"
            );
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            assert!(
                !intact_after(p, addr_of_mut!((*p).hover.limit), 4),
                "hover limit 4"
            );
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            assert!(
                !intact_after(p, addr_of_mut!((*p).hover.capable), 2),
                "capable 2"
            );
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            // Past the last variant with or without `clarabel` (5 or 7 variants).
            assert!(
                !intact_after(p, addr_of_mut!((*p).allocator), 7),
                "allocator 7"
            );
            let mut c = controller();
            let p: *mut Checked = &mut *c;
            addr_of_mut!((*p).admissible).cast::<f32>().write(-2.0);
            assert!(!Checked::storage_intact(p), "admissible set");
        }
    }

    /// The failure flag of agent `i`.
    unsafe fn flag_of(c: *mut Checked, i: usize) -> *mut u8 {
        addr_of_mut!((*c).failures.failed).cast::<u8>().add(i)
    }

    /// Settings that turn every optional stage on: rate limits, the null-space stage, the
    /// offset-free law's observer and planned-rate filter, and fault detection that masks.
    fn every_stage() -> ControllerSettings<f32> {
        ControllerSettings {
            rate_limits: Some(RateLimits::new(3.0, 3.0).unwrap()),
            null_space: Some(NullSpaceStage::new(NullSpaceObjective::Margin, 8).unwrap()),
            fault_detection: Some(FaultDetection::recommended(FaultResponse::Mask)),
            ..ControllerSettings::offset_free_law()
        }
    }

    /// A controller with every stage on, flown a few periods with an agent's report given,
    /// then a law stage on its own (its record pending), checked intact at each step.
    fn flown(allocator: &str) -> ManuallyDrop<Checked> {
        let team = presets::a4_inc::<f32, 4>().unwrap();
        let options = AllocatorOptions {
            agent_weights: Some([1.0, 2.0, 1.0, 2.0]),
            ..AllocatorOptions::default()
        };
        let options = if allocator == "weighted-pseudo-inverse" {
            options
        } else {
            AllocatorOptions::default()
        };
        let a = AnyAllocator::from_name(allocator, &options).unwrap();
        let mut c = ManuallyDrop::new(Controller::new(team, every_stage(), a).unwrap());
        assert!(unsafe { Checked::storage_intact(&*c) }, "{allocator}: new");
        let state = RigidState::at_rest(Vector3::new(0.1, 0.0, 1.0));
        let reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
        for k in 0..4 {
            c.step(&state, &reference).unwrap();
            if k == 1 {
                let reading = AgentReading::new(6.0, 0.0, 0.0, 0.0).unwrap();
                c.set_report(1, reading).unwrap();
            }
            assert!(
                unsafe { Checked::storage_intact(&*c) },
                "{allocator}: step {k}"
            );
        }
        c.law(&state, &reference).unwrap();
        assert!(c.pending.is_some() && c.fault_report().is_some());
        assert!(c.attitude_rate.is_some() && c.settings.null_space.is_some());
        assert!(
            unsafe { Checked::storage_intact(&*c) },
            "{allocator}: pending"
        );
        c
    }

    #[test]
    fn an_intact_controller_in_every_reachable_state_passes() {
        for name in AnyAllocator::<f32, 4>::NAMES {
            let mut c = flown(name);
            c.set_failures(FailureMask::with_failed(&[3]).unwrap())
                .unwrap();
            assert!(unsafe { Checked::storage_intact(&*c) }, "{name}: failures");
            c.reset();
            assert!(unsafe { Checked::storage_intact(&*c) }, "{name}: reset");
        }
    }

    #[test]
    fn an_invalid_tag_of_any_optional_part_or_enum_it_keeps_is_refused() {
        type Field = fn(*mut Checked) -> *mut u8;
        let fields: [(&str, Field, u8); 11] = [
            (
                "rate limits",
                |p| unsafe { addr_of_mut!((*p).settings.rate_limits).cast() },
                2,
            ),
            (
                "null space",
                |p| unsafe { addr_of_mut!((*p).settings.null_space).cast() },
                2,
            ),
            (
                "offset free",
                |p| unsafe { addr_of_mut!((*p).settings.offset_free).cast() },
                2,
            ),
            (
                "rate filter",
                |p| unsafe { addr_of_mut!((*p).settings.attitude_rate).cast() },
                2,
            ),
            (
                "detection",
                |p| unsafe { addr_of_mut!((*p).settings.fault_detection).cast() },
                2,
            ),
            (
                "schedule",
                |p| unsafe { addr_of_mut!((*p).settings.gain_schedule).cast() },
                3,
            ),
            (
                "rate state",
                |p| unsafe { addr_of_mut!((*p).attitude_rate).cast() },
                2,
            ),
            (
                "monitor",
                |p| unsafe { addr_of_mut!((*p).fault).cast() },
                0x41,
            ),
            (
                "pending",
                |p| unsafe { addr_of_mut!((*p).pending).cast() },
                2,
            ),
            (
                "limiting agent",
                |p| unsafe { addr_of_mut!((*p).hover.limiting_agent).cast() },
                2,
            ),
            (
                // Past the last variant with or without `clarabel` (5 or 7 variants).
                "allocator",
                |p| unsafe { addr_of_mut!((*p).allocator).cast() },
                7,
            ),
        ];
        for (name, field, byte) in fields {
            let mut c = flown("exact-boundary-redistribution");
            let p: *mut Checked = &mut *c;
            assert!(!unsafe { intact_after(p, field(p), byte) }, "{name}");
        }
        // What the parts hold, through each part's own check: the allocator's variant and
        // what it keeps (the exact-boundary walk's, the weighted factor's), the offset-free
        // state's kind, the monitor's report.
        for name in ["exact-boundary-redistribution", "weighted-pseudo-inverse"] {
            let c = flown(name);
            let p: *const Checked = &*c;
            let allocator = unsafe { addr_of!((*p).allocator) };
            // SAFETY: an intact controller, its allocator read raw.
            let refused = (0..core::mem::size_of::<AnyAllocator<f32, 4>>())
                .filter(|&k| {
                    let mut copy = core::mem::MaybeUninit::<AnyAllocator<f32, 4>>::uninit();
                    unsafe {
                        core::ptr::copy_nonoverlapping(allocator, copy.as_mut_ptr(), 1);
                        copy.as_mut_ptr().cast::<u8>().add(k).write(7);
                        !<AnyAllocator<f32, 4> as Allocator<f32, 4>>::storage_intact(copy.as_ptr())
                    }
                })
                .count();
            // 7: past every tag and flag (the allocator's too, with or without `clarabel`).
            // Refused: the variant's tag, then the variant's own tags (as in its module's
            // test): 2 + 4 x 6 or 1 + 4 + 1.
            let own = if name == "weighted-pseudo-inverse" {
                6
            } else {
                26
            };
            assert_eq!(refused, 1 + own, "{name}");
        }
        let mut c = flown("pseudo-inverse");
        let p: *mut Checked = &mut *c;
        // The cones' flags: one byte each refused (their other bytes are numbers), the byte
        // put back after each try.
        for cone in unsafe {
            [
                addr_of_mut!((*p).full_cone),
                addr_of_mut!((*p).planner_cone),
            ]
        } {
            let refused = (0..core::mem::size_of::<crate::EllipticCone<f32>>())
                .filter(|&k| unsafe {
                    let at = cone.cast::<u8>().add(k);
                    let old = at.read();
                    let refused = !intact_after(p, at, 2);
                    at.write(old);
                    refused
                })
                .count();
            assert_eq!(refused, 1);
        }
        assert!(
            !unsafe { intact_after(p, addr_of_mut!((*p).offset_free), 3) },
            "kind"
        );
    }
}
