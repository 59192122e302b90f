//! The flight metrics of a run ([`FlightMetrics`], defined in `docs/method.md`, "Flight
//! metrics"): settling time, steady-state, peak and integral errors of position and attitude,
//! force and moment errors, thrust efficiency and time saturated, each folded one sample at a
//! time.

use serde::{Deserialize, Serialize};

use super::rules::{ArgMax, Max, Min};
use crate::sim::sample::Sample;

/// Settling band: an error has settled once it stays within this share of its peak.
pub const SETTLING_SHARE: f64 = 0.02;

/// Smallest settling band of a position error (m): round-off and the ground's contact jitter
/// must not count as unsettled.
pub const POSITION_BAND_FLOOR: f64 = 1e-3;

/// Smallest settling band of an attitude error (rad).
pub const ATTITUDE_BAND_FLOOR: f64 = 1e-3;

/// The metrics of one error signal `e(t) >= 0` over a run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ErrorMetrics {
    /// Largest error (m or rad).
    pub peak: f64,
    /// Time of the peak (s).
    pub peak_time: f64,
    /// 2% settling time (s): the first sample time after which the error stays within
    /// `max(2% of the peak, floor)` to the end; `None` if the last sample lies outside.
    pub settling_time: Option<f64>,
    /// Steady-state error: the mean over the samples of the final window (m or rad); `None`
    /// if the run ended before the window.
    pub steady_state: Option<f64>,
    /// Integral of the absolute error `int e dt` (trapezoidal, m s or rad s).
    pub integral: f64,
    /// Root mean square over the samples.
    pub rms: f64,
}

/// A sample that no later sample reaches: its error and the time of the sample after it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SuffixMax {
    e: f64,
    next: Option<f64>,
}

/// [`ErrorMetrics`] folded one sample at a time.
#[derive(Clone, Debug)]
pub struct ErrorFold {
    floor: f64,
    steady_from: f64,
    peak: ArgMax,
    first: Option<f64>,
    /// The strict suffix maxima in time order (decreasing `e`): the last sample above any band
    /// is among them. One entry per sample at worst (a monotone decay), usually few.
    suffix_max: Vec<SuffixMax>,
    last: Option<(f64, f64)>,
    integral: f64,
    squares: f64,
    count: usize,
    steady: (f64, usize),
}

impl ErrorFold {
    /// An empty fold with settling-band `floor` and the steady-state window from
    /// `steady_from` (s) on.
    pub fn new(floor: f64, steady_from: f64) -> Self {
        Self {
            floor,
            steady_from,
            peak: ArgMax::default(),
            first: None,
            suffix_max: Vec::new(),
            last: None,
            integral: 0.0,
            squares: 0.0,
            count: 0,
            steady: (0.0, 0),
        }
    }

    /// Adds the error `e` of the sample at `t`; a NaN counts as an unbounded error.
    pub fn push(&mut self, t: f64, e: f64) {
        let e = if e.is_nan() { f64::INFINITY } else { e.abs() };
        self.first.get_or_insert(t);
        self.peak.push(t, e);
        // The top is always the previous sample: this one comes after it.
        if let Some(top) = self.suffix_max.last_mut() {
            top.next = Some(t);
        }
        while self.suffix_max.last().is_some_and(|m| m.e <= e) {
            self.suffix_max.pop();
        }
        self.suffix_max.push(SuffixMax { e, next: None });
        if let Some((t0, e0)) = self.last {
            self.integral += 0.5 * (e0 + e) * (t - t0);
        }
        self.last = Some((t, e));
        self.squares += e * e;
        self.count += 1;
        if t >= self.steady_from - 1e-9 {
            self.steady.0 += e;
            self.steady.1 += 1;
        }
    }

    /// The metrics so far, `None` before the first sample.
    pub fn get(&self) -> Option<ErrorMetrics> {
        let (peak_time, peak) = self.peak.get()?;
        let band = (SETTLING_SHARE * peak).max(self.floor);
        // The last sample above the band is the last suffix maximum above it.
        // An unbounded error (a NaN or infinity) never settles: its band would be unbounded.
        let settling_time = match self.suffix_max.iter().rev().find(|m| m.e > band) {
            _ if !peak.is_finite() => None,
            Some(m) => m.next,
            None => self.first,
        };
        Some(ErrorMetrics {
            peak,
            peak_time,
            settling_time,
            steady_state: (self.steady.1 > 0).then(|| self.steady.0 / self.steady.1 as f64),
            integral: self.integral,
            rms: (self.squares / self.count as f64).sqrt(),
        })
    }
}

/// Largest, mean and integral of a magnitude reported at some samples.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MagnitudeMetrics {
    /// Largest value.
    pub max: f64,
    /// Mean over the samples that report it.
    pub mean: f64,
    /// `int v dt` over the samples that report it (each holds until the next sample).
    pub integral: f64,
}

/// [`MagnitudeMetrics`] folded one sample at a time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct MagnitudeFold {
    max: Max,
    sum: f64,
    count: usize,
    integral: f64,
}

impl MagnitudeFold {
    fn push(&mut self, v: Option<f64>, dt: f64) {
        if let Some(v) = v {
            self.max.push(v);
            self.sum += v;
            self.count += 1;
            self.integral += v * dt;
        }
    }

    fn get(&self) -> Option<MagnitudeMetrics> {
        Some(MagnitudeMetrics {
            max: self.max.get()?,
            mean: self.sum / self.count as f64,
            integral: self.integral,
        })
    }
}

/// Mean and lowest thrust efficiency.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EfficiencyMetrics {
    /// Mean `||u_f|| / sum_i ||f_i||` over the samples that report it.
    pub mean: f64,
    /// Lowest.
    pub min: f64,
}

/// The flight metrics of a run (`docs/method.md`, "Flight metrics").
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightMetrics {
    /// Position error `||x - x_r||` (m); `None` for a run without samples.
    pub position: Option<ErrorMetrics>,
    /// Attitude error `angle(R, R_r)` to the reference (rad): includes what the planner gives up
    /// of an infeasible `R_r` on purpose.
    pub attitude: Option<ErrorMetrics>,
    /// Attitude error `angle(R, R_d)` to the planned attitude the control law tracks (rad), if
    /// the controller reported `R_d`.
    pub planned_attitude: Option<ErrorMetrics>,
    /// Force error `e_f = ||u_fd - u_f||` (N), if reported.
    pub force_error: Option<MagnitudeMetrics>,
    /// Moment error `e_tau = ||u_taud - u_tau||` (N m), if reported.
    pub moment_error: Option<MagnitudeMetrics>,
    /// Thrust efficiency, if reported.
    pub thrust_efficiency: Option<EfficiencyMetrics>,
    /// Time the allocator saturated at least one agent (s): saturated controller periods times
    /// the period.
    pub time_saturated: f64,
}

/// [`FlightMetrics`] folded one sample at a time.
#[derive(Clone, Debug)]
pub struct MetricsFold {
    period: f64,
    position: ErrorFold,
    attitude: ErrorFold,
    planned_attitude: ErrorFold,
    planned_seen: bool,
    force: MagnitudeFold,
    moment: MagnitudeFold,
    efficiency: (f64, usize, Min),
    saturated_periods: usize,
}

impl MetricsFold {
    /// An empty fold for samples every `period` (s), the steady-state window from
    /// `steady_from` (s) on.
    pub fn new(period: f64, steady_from: f64) -> Self {
        Self {
            period,
            position: ErrorFold::new(POSITION_BAND_FLOOR, steady_from),
            attitude: ErrorFold::new(ATTITUDE_BAND_FLOOR, steady_from),
            planned_attitude: ErrorFold::new(ATTITUDE_BAND_FLOOR, steady_from),
            planned_seen: false,
            force: MagnitudeFold::default(),
            moment: MagnitudeFold::default(),
            efficiency: (0.0, 0, Min::default()),
            saturated_periods: 0,
        }
    }

    /// Adds the next sample.
    pub fn push(&mut self, x: &Sample) {
        self.position.push(x.t, x.position_error());
        self.attitude.push(x.t, x.reference_attitude_error);
        if let Some(e) = x.attitude_error {
            self.planned_seen = true;
            self.planned_attitude.push(x.t, e);
        }
        self.force.push(x.e_f, self.period);
        self.moment.push(x.e_tau, self.period);
        if let Some(eta) = x.thrust_efficiency {
            self.efficiency.0 += eta;
            self.efficiency.1 += 1;
            self.efficiency.2.push(eta);
        }
        self.saturated_periods += usize::from(x.saturated_agents.is_some_and(|n| n > 0));
    }

    /// The metrics so far.
    pub fn get(&self) -> FlightMetrics {
        let (sum, count, min) = self.efficiency;
        FlightMetrics {
            position: self.position.get(),
            attitude: self.attitude.get(),
            planned_attitude: self
                .planned_seen
                .then(|| self.planned_attitude.get())
                .flatten(),
            force_error: self.force.get(),
            moment_error: self.moment.get(),
            thrust_efficiency: min.get().map(|min| EfficiencyMetrics {
                mean: sum / count as f64,
                min,
            }),
            time_saturated: self.saturated_periods as f64 * self.period,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fold(errors: &[(f64, f64)], steady_from: f64) -> ErrorMetrics {
        let mut f = ErrorFold::new(1e-3, steady_from);
        errors.iter().for_each(|&(t, e)| f.push(t, e));
        f.get().unwrap()
    }

    #[test]
    fn settling_is_the_sample_after_the_last_exceedance_of_the_band() {
        // Peak 1 at t = 1: band 0.02. The last sample above it is t = 3 (0.05, after a dip to
        // 0.01 at t = 2), so the error has settled from t = 4 on.
        let m = fold(
            &[
                (0.0, 0.5),
                (1.0, 1.0),
                (2.0, 0.01),
                (3.0, 0.05),
                (4.0, 0.015),
                (5.0, 0.0),
            ],
            4.0,
        );
        assert_eq!((m.peak, m.peak_time), (1.0, 1.0));
        assert_eq!(m.settling_time, Some(4.0));
        assert_eq!(m.steady_state, Some(0.0075));
        // Trapezoids: 0.75 + 0.505 + 0.03 + 0.0325 + 0.0075.
        assert!((m.integral - 1.325).abs() < 1e-12);
        let squares: f64 = [0.25, 1.0, 1e-4, 25e-4, 2.25e-4, 0.0].iter().sum();
        assert!((m.rms - (squares / 6.0).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn a_monotone_decay_and_an_unsettled_end() {
        let decay: Vec<(f64, f64)> = (0..100).map(|k| (k as f64, 0.9f64.powi(k))).collect();
        // 0.9^k <= 0.02 from k = 38 on (0.9^37 = 0.0203).
        assert_eq!(fold(&decay, 50.0).settling_time, Some(38.0));
        // Ending above the band: not settled; the window not reached: no steady state.
        let growing = fold(&[(0.0, 0.0), (1.0, 1.0)], 5.0);
        assert_eq!((growing.settling_time, growing.steady_state), (None, None));
        // Never above the band (the floor): settled from the first sample.
        assert_eq!(
            fold(&[(0.5, 1e-4), (1.0, 5e-4)], 0.0).settling_time,
            Some(0.5)
        );
        // A NaN is an unbounded error, never a settled one.
        let nan = fold(&[(0.0, 0.1), (1.0, f64::NAN)], 0.0);
        assert_eq!((nan.peak, nan.settling_time), (f64::INFINITY, None));
    }

    #[test]
    fn magnitudes_count_only_reporting_samples() {
        let mut f = MagnitudeFold::default();
        assert_eq!(f.get(), None);
        for v in [Some(1.0), None, Some(3.0)] {
            f.push(v, 0.01);
        }
        let m = f.get().unwrap();
        assert_eq!((m.max, m.mean), (3.0, 2.0));
        assert!((m.integral - 0.04).abs() < 1e-15);
    }
}
