//! The work of one exact-boundary allocation, counted, and its worst case as a function of the
//! number of working agents, proved from the loop caps of `mod.rs` and `walk.rs`.

/// The work of one [`super::ExactBoundaryRedistribution`] allocation
/// ([`super::ExactBoundaryRedistribution::last_cost`]), and of its worst case ([`Self::bound`]).
///
/// The cost of a round is `O(n)` (one 6x6 `L D L^T` solve with the Gram matrix downdated by at
/// most two rank-one terms per agent, one line search over `6 n` closed-form constraint exits,
/// one step), so these counts bound the allocation's time up to a constant per agent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WalkCost {
    /// Rounds of the redistributed pseudo-inverse that gives the start (at most `n`).
    pub start_rounds: u32,
    /// Rounds of the walk (each: one direction, one line search, one step).
    pub rounds: u32,
    /// 6x6 Gram solves of the walk (the start's not included): one per direction, one more
    /// after a release, one for the shedding of internal forces.
    pub solves: u32,
    /// Held constraints let go (the active-set multiplier test).
    pub releases: u32,
    /// Line searches to the first boundary (one per round, one for the shedding).
    pub line_searches: u32,
}

impl WalkCost {
    /// The worst case with `n` working agents and the walk capped at `cap` rounds (no cap:
    /// `u32::MAX`), from the code's loop caps:
    /// - the start is the redistributed pseudo-inverse: at most `n` rounds;
    /// - the walk: at most `R = min(2 n + 4, cap)` rounds (the `while` of `allocate`), so at
    ///   most `R + 1` directions (the last may fail: nothing finite to step along);
    /// - a direction solves once, and once more when it releases a constraint; the second solve
    ///   never releases (`direction(r, false)`), so at most one release per direction, and at
    ///   most once per constraint (`ActiveSet::released`): `min(R + 1, 6 n)` releases;
    /// - the shedding of internal forces before the walk (a previous-period start only): one
    ///   solve and one line search;
    /// - one line search per round.
    ///
    /// So at most `R + 1 + releases + 1` solves and `R + 1` line searches; without a cap,
    /// `2 n + 4` rounds, `2 n + 5` releases, `4 n + 11` solves and `2 n + 5` line searches.
    pub const fn bound(n: usize, cap: u32) -> Self {
        // More agents than `u32::MAX / 8` cannot be held in memory; the cast is exact below it.
        let n = if n > (u32::MAX / 8) as usize {
            u32::MAX / 8
        } else {
            n as u32
        };
        let limit = 2 * n + 4;
        let rounds = if cap < limit { cap } else { limit };
        let directions = rounds + 1;
        let releases = if directions < 6 * n {
            directions
        } else {
            6 * n
        };
        Self {
            start_rounds: n,
            rounds,
            solves: directions + releases + 1,
            releases,
            line_searches: rounds + 1,
        }
    }

    /// Whether every count is at most `other`'s.
    pub const fn within(&self, other: &Self) -> bool {
        self.start_rounds <= other.start_rounds
            && self.rounds <= other.rounds
            && self.solves <= other.solves
            && self.releases <= other.releases
            && self.line_searches <= other.line_searches
    }
}
