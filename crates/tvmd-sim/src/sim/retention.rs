//! Which samples a run keeps ([`SampleRetention`]) and the store that keeps them
//! ([`SampleStore`]). The summary does not depend on it: the loop folds every tick into the
//! summary whether or not the sample is kept, so a run that keeps none runs in flat memory.

use crate::sim::sample::Sample;
use crate::SimError;

/// Most samples one run may keep in memory (about 1 KB each, so about 2 GB).
pub const MAX_KEPT_SAMPLES: usize = 2_000_000;

/// Which of a run's samples (one per controller tick) the [`crate::sim::RunResult`] holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SampleRetention {
    /// Every tick (the library's default): memory grows with the run, so a run keeps at most
    /// [`MAX_KEPT_SAMPLES`].
    #[default]
    All,
    /// At most this many, evenly spaced: every `stride`-th tick from the first, `stride` the
    /// smallest power of two that fits (a run shorter than the bound keeps every tick).
    AtMost(usize),
    /// None: memory stays flat however long the run (the summary and the log still see every
    /// tick).
    None,
}

impl SampleRetention {
    /// `Err` naming `duration` when a run of `ticks` ticks would keep more than
    /// [`MAX_KEPT_SAMPLES`].
    pub fn check(self, ticks: usize) -> Result<(), SimError> {
        let kept = match self {
            Self::All => ticks,
            Self::AtMost(n) => ticks.min(n),
            Self::None => 0,
        };
        if kept <= MAX_KEPT_SAMPLES {
            return Ok(());
        }
        Err(SimError::invalid_field(
            "duration",
            format!(
                "the run has {ticks} controller ticks and would keep {kept} samples in memory, \
                 more than {MAX_KEPT_SAMPLES}; keep fewer samples (`max_samples` in Python, \
                 `SampleRetention::AtMost` or `None` in Rust; the command line keeps none, or \
                 a bounded set for --plots)"
            ),
        ))
    }
}

/// The samples a run keeps under a [`SampleRetention`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleStore {
    retention: SampleRetention,
    stride: usize,
    samples: Vec<Sample>,
}

impl SampleStore {
    /// An empty store.
    pub fn new(retention: SampleRetention) -> Self {
        Self {
            retention,
            stride: 1,
            samples: Vec::new(),
        }
    }

    /// Offers the sample of controller tick `tick` (0, 1, 2, ... in order).
    pub fn push(&mut self, tick: usize, sample: impl FnOnce() -> Sample) {
        let bound = match self.retention {
            SampleRetention::None => return,
            SampleRetention::All => usize::MAX,
            SampleRetention::AtMost(n) => n,
        };
        if tick % self.stride != 0 || bound == 0 {
            return;
        }
        self.samples.push(sample());
        while self.samples.len() > bound {
            // Kept sample j is tick j * stride: keep the even j.
            self.stride *= 2;
            let mut j = 0;
            self.samples.retain(|_| {
                j += 1;
                j % 2 == 1
            });
        }
    }

    /// Controller ticks between kept samples (1: every tick).
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// The kept samples.
    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    /// Moves the kept samples out.
    pub fn take(&mut self) -> Vec<Sample> {
        std::mem::take(&mut self.samples)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(t: f64) -> Sample {
        crate::sim::summary::tests::sample(t, 0.0, None)
    }

    fn times(store: &SampleStore) -> Vec<f64> {
        store.samples().iter().map(|s| s.t).collect()
    }

    #[test]
    fn at_most_keeps_an_even_power_of_two_stride() {
        let mut store = SampleStore::new(SampleRetention::AtMost(4));
        for k in 0..4 {
            store.push(k, || at(k as f64));
        }
        assert_eq!(
            (times(&store), store.stride()),
            (vec![0.0, 1.0, 2.0, 3.0], 1)
        );
        for k in 4..11 {
            store.push(k, || at(k as f64));
        }
        // 11 ticks into 4: every 4th tick.
        assert_eq!((times(&store), store.stride()), (vec![0.0, 4.0, 8.0], 4));
        let mut one = SampleStore::new(SampleRetention::AtMost(1));
        (0..9).for_each(|k| one.push(k, || at(k as f64)));
        assert_eq!(times(&one), vec![0.0]);
    }

    #[test]
    fn all_none_and_zero() {
        let mut all = SampleStore::new(SampleRetention::All);
        let mut none = SampleStore::new(SampleRetention::None);
        let mut zero = SampleStore::new(SampleRetention::AtMost(0));
        for k in 0..5 {
            all.push(k, || at(k as f64));
            none.push(k, || panic!("no sample is built when none is kept"));
            zero.push(k, || panic!("no sample is built when none is kept"));
        }
        assert_eq!(all.samples().len(), 5);
        assert!(none.samples().is_empty() && zero.samples().is_empty());
        assert_eq!(all.take().len(), 5);
        assert!(all.samples().is_empty());
    }

    #[test]
    fn check_bounds_what_is_kept() {
        let too_many = MAX_KEPT_SAMPLES + 1;
        assert!(SampleRetention::All.check(too_many).is_err());
        assert!(SampleRetention::AtMost(too_many).check(too_many).is_err());
        assert!(SampleRetention::AtMost(1000).check(usize::MAX).is_ok());
        assert!(SampleRetention::None.check(usize::MAX).is_ok());
        let e = SampleRetention::All
            .check(too_many)
            .unwrap_err()
            .to_string();
        assert!(e.contains("duration") && e.contains("max_samples"), "{e}");
    }
}
