//! The rules the summary applies to a run's samples, each kept incrementally (one sample at a
//! time, constant memory) so that a run of any length is summarised without keeping its
//! samples.

/// Spacing of the samples seen so far: `(last - first) / (count - 1)`, infinite for fewer than
/// two.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Spacing {
    first: Option<f64>,
    last: f64,
    count: usize,
}

impl Spacing {
    /// Counts a sample at `t`.
    pub fn push(&mut self, t: f64) {
        self.first.get_or_insert(t);
        self.last = t;
        self.count += 1;
    }

    /// The mean spacing (s).
    pub fn get(&self) -> f64 {
        match self.first {
            Some(first) if self.count > 1 => (self.last - first) / (self.count - 1) as f64,
            _ => f64::INFINITY,
        }
    }
}

/// The sample nearest to a time, if it lies within half a sample spacing: the one rule that
/// picks the sample "at" a time. Ties keep the first sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest<V> {
    target: f64,
    best: Option<(f64, V)>,
}

impl<V: Copy> Nearest<V> {
    /// No sample yet; looks for the one nearest `target` (s).
    pub fn new(target: f64) -> Self {
        Self { target, best: None }
    }

    /// Offers the sample at `t` with its `value`.
    pub fn push(&mut self, t: f64, value: V) {
        let closer = self
            .best
            .is_none_or(|(b, _)| (t - self.target).abs() < (b - self.target).abs());
        if closer {
            self.best = Some((t, value));
        }
    }

    /// The nearest sample's `(t, value)`, if within half of `spacing` (or the only one).
    pub fn get(&self, spacing: &Spacing) -> Option<(f64, V)> {
        self.best
            .filter(|(t, _)| (t - self.target).abs() <= 0.5 * spacing.get() + 1e-9)
    }
}

/// Time after `start` from which a value stays at or below `threshold` until `end`: the last
/// sample in `[start, end]` above the threshold, minus `start` (0 if none is above); `None` if
/// no sample in the window has a value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settling {
    start: f64,
    end: f64,
    threshold: f64,
    seen: bool,
    last_above: f64,
}

impl Settling {
    /// The rule for the window `[start, end]` and `threshold`.
    pub fn new(start: f64, end: f64, threshold: f64) -> Self {
        Self {
            start,
            end,
            threshold,
            seen: false,
            last_above: 0.0,
        }
    }

    /// Offers the sample at `t` with its value, if it has one.
    pub fn push(&mut self, t: f64, value: Option<f64>) {
        let inside = t >= self.start - 1e-9 && t <= self.end + 1e-9;
        if let (true, Some(v)) = (inside, value) {
            self.seen = true;
            if v > self.threshold {
                self.last_above = self.last_above.max(t - self.start);
            }
        }
    }

    /// The settling time (s).
    pub fn get(&self) -> Option<f64> {
        self.seen.then_some(self.last_above)
    }
}

/// The largest value offered (NaN ignored), `None` for none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Max(Option<f64>);

impl Max {
    /// Offers `v`.
    pub fn push(&mut self, v: f64) {
        self.0 = Some(self.0.map_or(v, |m| m.max(v)));
    }

    /// Offers `v` if there is one.
    pub fn push_some(&mut self, v: Option<f64>) {
        if let Some(v) = v {
            self.push(v);
        }
    }

    /// The largest value.
    pub fn get(&self) -> Option<f64> {
        self.0
    }

    /// The largest value, or 0 for none (for magnitudes).
    pub fn or_zero(&self) -> f64 {
        self.0.unwrap_or(0.0)
    }
}

/// The smallest value offered, `None` for none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Min(Option<f64>);

impl Min {
    /// Offers `v`.
    pub fn push(&mut self, v: f64) {
        self.0 = Some(self.0.map_or(v, |m| m.min(v)));
    }

    /// The smallest value.
    pub fn get(&self) -> Option<f64> {
        self.0
    }
}

/// The largest value and its time `(t, v)`; the first of equal maxima.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ArgMax(Option<(f64, f64)>);

impl ArgMax {
    /// Offers the value `v` at `t`.
    pub fn push(&mut self, t: f64, v: f64) {
        if self.0.is_none_or(|(_, m)| v > m) {
            self.0 = Some((t, v));
        }
    }

    /// `(t, v)` of the maximum.
    pub fn get(&self) -> Option<(f64, f64)> {
        self.0
    }
}

/// A rise of a value between two times.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Rise {
    /// `v(to) - v(from)`.
    pub rise: f64,
    /// Time of the preceding minimum (s).
    pub from: f64,
    /// The value at `from`.
    pub from_value: f64,
    /// Time of the peak (s).
    pub to: f64,
    /// The value at `to`.
    pub to_value: f64,
}

/// The largest rise `max_t (v(t) - min_{t' <= t} v(t'))` with the times of the minimum and
/// the peak (0 if the value never increases).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaxRise {
    best: Option<Rise>,
    low: Option<(f64, f64)>,
}

impl MaxRise {
    /// Offers the value `v` at `t`.
    pub fn push(&mut self, t: f64, v: f64) {
        let (lt, lv) = match self.low {
            Some((lt, lv)) if lv <= v => (lt, lv),
            _ => {
                self.low = Some((t, v));
                (t, v)
            }
        };
        if self.best.is_none_or(|b| v - lv > b.rise) {
            self.best = Some(Rise {
                rise: v - lv,
                from: lt,
                from_value: lv,
                to: t,
                to_value: v,
            });
        }
    }

    /// The largest rise.
    pub fn get(&self) -> Option<Rise> {
        self.best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_needs_a_sample_within_half_a_spacing() {
        let mut spacing = Spacing::default();
        let mut near = Nearest::new(0.025 - 1e-6);
        let mut far = Nearest::new(0.0451);
        for k in 0..5 {
            let t = k as f64 * 0.01;
            spacing.push(t);
            near.push(t, k);
            far.push(t, k);
        }
        assert!((spacing.get() - 0.01).abs() < 1e-15);
        assert_eq!(near.get(&spacing), Some((0.02, 2)));
        assert_eq!(far.get(&spacing), None);
        // One sample is "at" any time; none is at none.
        let mut one = Spacing::default();
        let mut only = Nearest::new(100.0);
        assert_eq!(only.get(&one), None);
        one.push(0.0);
        only.push(0.0, 7);
        assert_eq!(only.get(&one), Some((0.0, 7)));
    }

    #[test]
    fn ties_keep_the_first_sample() {
        let mut n = Nearest::new(1.0);
        n.push(0.5, 'a');
        n.push(1.5, 'b');
        assert_eq!(n.best, Some((0.5, 'a')));
        let mut m = ArgMax::default();
        for (t, v) in [(0.0, 1.0), (1.0, 3.0), (2.0, 3.0)] {
            m.push(t, v);
        }
        assert_eq!(m.get(), Some((1.0, 3.0)));
    }

    #[test]
    fn settling_is_the_last_exceedance_in_the_window() {
        let mut s = Settling::new(1.0, 3.0, 0.1);
        assert_eq!(s.get(), None);
        for (t, v) in [(0.5, 9.0), (1.0, 0.5), (2.0, 0.2), (2.5, 0.05), (4.0, 9.0)] {
            s.push(t, Some(v));
        }
        assert_eq!(s.get(), Some(1.0));
        let mut calm = Settling::new(0.0, 1.0, 0.1);
        calm.push(0.5, Some(0.0));
        calm.push(0.6, None);
        assert_eq!(calm.get(), Some(0.0));
    }

    #[test]
    fn rise_tracks_the_preceding_minimum() {
        let mut r = MaxRise::default();
        for (t, v) in [(0.0, 5.0), (1.0, 1.0), (2.0, 2.0), (3.0, 0.5), (4.0, 2.0)] {
            r.push(t, v);
        }
        let rise = r.get().unwrap();
        assert_eq!((rise.from, rise.to, rise.rise), (3.0, 4.0, 1.5));
        let mut falling = MaxRise::default();
        falling.push(0.0, 2.0);
        falling.push(1.0, 1.0);
        assert_eq!(falling.get().unwrap().rise, 0.0);
        let mut extremes = (Max::default(), Min::default());
        assert_eq!((extremes.0.or_zero(), extremes.1.get()), (0.0, None));
        for v in [2.0, f64::NAN, -1.0] {
            extremes.0.push(v);
            extremes.1.push(v);
        }
        assert_eq!(
            (extremes.0.get(), extremes.1.get()),
            (Some(2.0), Some(-1.0))
        );
    }
}
