//! The exact-boundary walk's round cap per allocation: capped by default, so that a flight
//! controller's cycle has a bounded, stated worst case ([`super::WalkCost::bound`]).

/// Walk rounds of the default cap ([`RoundCap::default`]). Two: the allocation set's worst
/// requests take 12-15 rounds uncapped at 10,000-13,000 Cortex-M4F instructions each, while two
/// rounds keep 57 of its 64 attainable n = 4 requests exact (63 uncapped) and bound the whole
/// n = 4 cycle at about 46,000 instructions (`docs/allocation-benchmark.md`, "Worst case, cost
/// cap and target").
pub const DEFAULT_MAX_ROUNDS: u32 = 2;

/// How many rounds the exact-boundary redistribution may walk per allocation. `repr(u8)`: the
/// tag first, checked raw by [`crate::Controller::storage_intact`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum RoundCap {
    /// At most this many rounds (`Rounds(0)`: the walk's start alone, the redistributed
    /// pseudo-inverse or the previous forces, whichever does better). A capped walk returns the
    /// best forces it found, inside every agent's set, with their true wrench error.
    Rounds(u32),
    /// No cap beyond the walk's own `2 n + 4` rounds: the exact boundary's last corners, at up
    /// to about 166,000 Cortex-M4F instructions for one n = 4 allocation of the allocation set
    /// (research, not a flight controller's period).
    Uncapped,
}

impl Default for RoundCap {
    /// [`DEFAULT_MAX_ROUNDS`] rounds.
    fn default() -> Self {
        Self::Rounds(DEFAULT_MAX_ROUNDS)
    }
}

impl RoundCap {
    /// Whether the cap at `this` has one of the two tags.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        crate::foundation::stored::tag_below(this, 2)
    }

    /// The cap as a number of rounds (`u32::MAX` when uncapped: no walk reaches it), as
    /// [`super::WalkCost::bound`] takes it.
    pub const fn rounds(self) -> u32 {
        match self {
            Self::Rounds(k) => k,
            Self::Uncapped => u32::MAX,
        }
    }

    /// `Rounds(k)` for `Some(k)`, `Uncapped` for `None` (a cap given as an optional limit).
    pub const fn from_limit(limit: Option<u32>) -> Self {
        match limit {
            Some(k) => Self::Rounds(k),
            None => Self::Uncapped,
        }
    }
}
