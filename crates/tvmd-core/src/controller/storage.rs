//! A controller in memory a stray write may have changed (a C caller's handle): the counts,
//! indices and enum tags the cycle loops or branches on, checked raw before any reference to
//! the controller is made. Floats need no check (every bit pattern is one); the cycle's loops
//! are bounded by the capacity `N` and constant caps whatever the stored counts hold.

use core::ptr::addr_of;

use super::Controller;
use crate::agent::admissible::AdmissibleSet;
use crate::allocation::Allocator;
use crate::foundation::real::Real;

/// `HoverLimit`'s variants (`repr(u8)`, tags `0..4`).
const HOVER_LIMITS: u8 = 4;

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// Whether the controller at `this` holds, where the cycle reads them, an agent count in
    /// `1..=N` that agrees with the working count and the effectiveness's count of blocks, valid flags and tags (the failure mask, the
    /// hover classification, the allocator's variant), a finite hover margin at the plant's
    /// weight and an admissible set equal to the team's limits. A controller
    /// some write changed there is refused before it is used (the C interface answers
    /// `TVMD_ERR_CORRUPTED`); any other change leaves every loop bounded and every index
    /// checked. About `2 N + 40` loads, compares and additions; reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes that held a
    /// controller before (any of them may have changed since).
    pub unsafe fn storage_intact(this: *const Self) -> bool {
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
            && margin.is_finite()
            && weight == plant.weight()
            && AdmissibleSet::from_limits(&limits) == admissible
            && A::storage_intact(addr_of!((*this).allocator))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use core::mem::ManuallyDrop;
    use core::ptr::addr_of_mut;

    use crate::allocation::AnyAllocator;
    use crate::team::presets;
    use crate::{Controller, ControllerSettings, FailureMask};

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
}
