//! Continuous turbulence: the Dryden spectra with the low-altitude intensities and scale lengths
//! of MIL-F-8785C (3.7.2.3; the same as MIL-HDBK-1797's low-altitude Dryden form), realized as a
//! sum of sinusoids with seeded phases (`docs/method.md`, "Scenario families").
//!
//! The standard's field is frozen and sampled at the speed `V` at which it passes the vehicle
//! (Taylor's hypothesis). A hovering team does not move through the air; the field passes it
//! with the mean wind, so `V` is the steady wind's speed (at least [`MIN_SPEED`]). The standard
//! says the frozen field holds while the turbulence is small against `V`; a team in a calm with
//! strong turbulence is outside it, which is why a speed is required.
//!
//! With `h` the height above ground in feet (taken in [10, 1000] ft, the standard's low-altitude
//! range) and `W20` the wind speed 20 ft above ground:
//! `sigma_w = 0.1 W20`, `sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4`,
//! `L_w = h`, `L_u = L_v = h / (0.177 + 0.000823 h)^1.2`, and the one-sided spectra in the
//! temporal frequency `omega` (rad/s)
//! `Phi_u = sigma_u^2 (2 L_u / (pi V)) / (1 + (L_u omega / V)^2)`,
//! `Phi_v = sigma_v^2 (L_v / (pi V)) (1 + 3 (L_v omega / V)^2) / (1 + (L_v omega / V)^2)^2`
//! (and `Phi_w` likewise with `L_w`, `sigma_w`), each of which integrates to `sigma^2`.
//!
//! The realization `u(t) = sum_k sqrt(2 Phi(omega_k) d_omega_k) cos(omega_k t + phi_k)` is a
//! pure function of `t` and the seed: the same flight meets the same air at any step size, and
//! the field needs no state.

use serde::{Deserialize, Serialize};

/// Smallest speed at which the frozen field may pass the team (m/s).
pub const MIN_SPEED: f64 = 0.5;
/// `W20` of the standard's "light" turbulence: 15 kt (m/s).
pub const LIGHT_W20: f64 = 15.0 * KNOT;
/// `W20` of the standard's "moderate" turbulence: 30 kt (m/s).
pub const MODERATE_W20: f64 = 30.0 * KNOT;
/// `W20` of the standard's "severe" turbulence: 45 kt (m/s).
pub const SEVERE_W20: f64 = 45.0 * KNOT;

const KNOT: f64 = 1852.0 / 3600.0;
const FOOT: f64 = 0.3048;
/// Sinusoids per axis: log-spaced from a hundredth of the slowest corner to a hundred times the
/// fastest, which holds all but a few percent of each variance (tested).
const TERMS: usize = 64;

/// Dryden turbulence on top of the steady wind (`[disturbances.air.turbulence]`).
///
/// ```toml
/// [disturbances.air]
/// velocity = [3.0, 0.0, 0.0]          # the steady wind: it carries the field past the team
/// [disturbances.air.turbulence]
/// wind_speed_20ft = 7.72              # W20 (m/s): light 7.72, moderate 15.43, severe 23.15
/// altitude = 1.5                      # m above ground (scale lengths taken at 10 ft at least)
/// seed = 0
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Turbulence {
    /// Wind speed 20 ft (6.1 m) above ground, `W20` (m/s): sets the intensities.
    pub wind_speed_20ft: f64,
    /// Height above ground (m) of the scale lengths and intensities.
    pub altitude: f64,
    /// Intensity multiplier on every `sigma` (1: the standard's).
    pub scale: f64,
    /// Seed of the phases.
    pub seed: u64,
}

impl Default for Turbulence {
    fn default() -> Self {
        Self {
            wind_speed_20ft: LIGHT_W20,
            altitude: 1.5,
            scale: 1.0,
            seed: 0,
        }
    }
}

/// The standard's intensities and scale lengths at one height (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrydenParameters {
    /// `sigma_u = sigma_v`, horizontal (m/s).
    pub sigma_horizontal: f64,
    /// `sigma_w`, vertical (m/s).
    pub sigma_vertical: f64,
    /// `L_u = L_v` (m).
    pub length_horizontal: f64,
    /// `L_w` (m).
    pub length_vertical: f64,
}

impl DrydenParameters {
    /// The spectrum, intensity and scale length of axis `axis` (0 `u`, 1 `v`, else `w`).
    fn axis(&self, axis: usize) -> (Spectrum, f64, f64) {
        match axis {
            0 => (
                Spectrum::FirstOrder,
                self.sigma_horizontal,
                self.length_horizontal,
            ),
            1 => (
                Spectrum::SecondOrder,
                self.sigma_horizontal,
                self.length_horizontal,
            ),
            _ => (
                Spectrum::SecondOrder,
                self.sigma_vertical,
                self.length_vertical,
            ),
        }
    }
}

impl Turbulence {
    /// The standard's turbulence with `W20 = wind_speed_20ft` at `altitude` (m), seed 0.
    pub fn standard(wind_speed_20ft: f64, altitude: f64) -> Self {
        Self {
            wind_speed_20ft,
            altitude,
            ..Self::default()
        }
    }

    /// The standard's mean wind at `altitude` (m/s): the logarithmic profile
    /// `W20 ln(h / z0) / ln(20 ft / z0)` with `z0 = 0.15 ft` (MIL-F-8785C 3.7.2.1, flight phase C:
    /// take-off, approach and landing, the regime a team hovering near the ground is in).
    pub fn mean_wind_speed(&self) -> f64 {
        const Z0: f64 = 0.15;
        let h = (self.altitude / FOOT).max(Z0);
        self.wind_speed_20ft * (h / Z0).ln() / (20.0 / Z0).ln()
    }

    /// The intensities and scale lengths (MIL-F-8785C low altitude, `h` taken in [10, 1000] ft).
    pub fn parameters(&self) -> DrydenParameters {
        let h = (self.altitude / FOOT).clamp(10.0, 1000.0);
        let k = 0.177 + 0.000823 * h;
        let sigma_w = 0.1 * self.wind_speed_20ft * self.scale;
        DrydenParameters {
            sigma_horizontal: sigma_w / k.powf(0.4),
            sigma_vertical: sigma_w,
            length_horizontal: h / k.powf(1.2) * FOOT,
            length_vertical: h * FOOT,
        }
    }

    /// The turbulent air velocity at `t` (m/s, world frame, z up), the field passing at
    /// `mean_wind` (world frame; its horizontal direction is the longitudinal axis `u`, x in a
    /// calm). The speed is taken as at least [`MIN_SPEED`].
    pub fn velocity_at(&self, t: f64, mean_wind: [f64; 3]) -> [f64; 3] {
        let p = self.parameters();
        let speed = norm(mean_wind).max(MIN_SPEED);
        let horizontal = mean_wind[0].hypot(mean_wind[1]);
        let (cu, su) = if horizontal > 1e-9 {
            (mean_wind[0] / horizontal, mean_wind[1] / horizontal)
        } else {
            (1.0, 0.0)
        };
        let [u, v, w] = [0, 1, 2].map(|axis| self.component(t, axis, &p, speed));
        [cu * u - su * v, su * u + cu * v, w]
    }

    /// The variance the realization of one axis holds (`sum a_k^2 / 2`, m^2/s^2), for the
    /// tests and the docs: a few percent under `sigma^2` (the tails outside the grid).
    pub fn realized_variance(&self, axis: usize, speed: f64) -> f64 {
        let p = self.parameters();
        let (spectrum, sigma, length) = p.axis(axis);
        terms(spectrum, sigma, length, speed.max(MIN_SPEED))
            .map(|(_, a)| 0.5 * a * a)
            .sum()
    }

    /// Axis `axis` (0 `u`, 1 `v`, 2 `w`) of the realization at `t`.
    fn component(&self, t: f64, axis: usize, p: &DrydenParameters, speed: f64) -> f64 {
        let (spectrum, sigma, length) = p.axis(axis);
        terms(spectrum, sigma, length, speed)
            .enumerate()
            .map(|(k, (omega, a))| a * (omega * t + phase(self.seed, axis as u64, k as u64)).cos())
            .sum()
    }
}

#[derive(Clone, Copy)]
enum Spectrum {
    /// Longitudinal: `2 L / (pi V) / (1 + x^2)`.
    FirstOrder,
    /// Lateral and vertical: `L / (pi V) (1 + 3 x^2) / (1 + x^2)^2`.
    SecondOrder,
}

/// The sinusoids `(omega_k, a_k)` of one axis: log-spaced frequencies around the corner `V / L`,
/// each with the spectrum's power over its cell.
fn terms(
    spectrum: Spectrum,
    sigma: f64,
    length: f64,
    speed: f64,
) -> impl Iterator<Item = (f64, f64)> {
    let corner = speed / length;
    // Cells of one ratio `r` from `corner / 100` to `100 corner`, each sampled at its geometric
    // middle: the edges by multiplication, not one exponential each.
    let ratio = (4.0 * std::f64::consts::LN_10 / TERMS as f64).exp();
    let middle = ratio.sqrt();
    let mut edge = corner * 1e-2;
    (0..TERMS).map(move |_| {
        let omega = edge * middle;
        let cell = edge * (ratio - 1.0);
        edge *= ratio;
        let x2 = (omega / corner).powi(2);
        let shape = match spectrum {
            Spectrum::FirstOrder => 2.0 / (1.0 + x2),
            Spectrum::SecondOrder => (1.0 + 3.0 * x2) / (1.0 + x2).powi(2),
        };
        let phi = sigma * sigma * shape / (std::f64::consts::PI * corner);
        (omega, (2.0 * phi * cell).sqrt())
    })
}

/// A phase in `[0, 2 pi)` from the seed, the axis and the term (splitmix64).
fn phase(seed: u64, axis: u64, k: u64) -> f64 {
    let mut z = seed
        .wrapping_add(axis.wrapping_mul(0xD1B5_4A32_D192_ED03))
        .wrapping_add(k.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standards_low_altitude_parameters() {
        // At 10 ft: k = 0.18523; sigma_u = sigma_w / k^0.4, L_u = 10 ft / k^1.2.
        let t = Turbulence {
            wind_speed_20ft: MODERATE_W20,
            altitude: 1.5,
            ..Turbulence::default()
        };
        let p = t.parameters();
        let k: f64 = 0.177 + 0.00823;
        assert!((p.sigma_vertical - 0.1 * 30.0 * KNOT).abs() < 1e-12);
        assert!((p.sigma_horizontal / p.sigma_vertical - k.powf(-0.4)).abs() < 1e-12);
        assert!((p.length_vertical - 3.048).abs() < 1e-12, "{p:?}");
        assert!(
            (p.length_horizontal - 3.048 / k.powf(1.2)).abs() < 1e-9,
            "{p:?}"
        );
        // The standard's mean wind: W20 at 20 ft, 0.714 W20 at 1.5 m.
        assert!((Turbulence::standard(10.0, 20.0 * FOOT).mean_wind_speed() - 10.0).abs() < 1e-12);
        assert!((t.mean_wind_speed() / MODERATE_W20 - 0.7141).abs() < 1e-3);
        // Higher up the scale lengths grow and the horizontal intensity falls toward sigma_w.
        let high = Turbulence {
            altitude: 200.0,
            ..t
        }
        .parameters();
        assert!(high.length_vertical > 190.0 && high.length_horizontal > p.length_horizontal);
        assert!(high.sigma_horizontal < p.sigma_horizontal);
    }

    #[test]
    fn each_axis_holds_nearly_its_variance_and_none_more() {
        let t = Turbulence::default();
        let p = t.parameters();
        for (axis, sigma) in [
            (0, p.sigma_horizontal),
            (1, p.sigma_horizontal),
            (2, p.sigma_vertical),
        ] {
            for speed in [0.5, 3.0, 12.0] {
                let v = t.realized_variance(axis, speed) / (sigma * sigma);
                assert!((0.95..=1.0).contains(&v), "axis {axis} at {speed} m/s: {v}");
            }
        }
    }

    #[test]
    fn the_time_statistics_match_the_spectra() {
        // Over many correlation times the sample mean is near zero and the sample variance near
        // sigma^2; the longitudinal axis follows the mean wind's direction.
        let t = Turbulence {
            seed: 7,
            ..Turbulence::default()
        };
        let p = t.parameters();
        let wind = [0.0, 3.0, 0.0];
        let n = 40_000;
        let dt = 0.05;
        let mut sum = [0.0; 3];
        let mut sq = [0.0; 3];
        for i in 0..n {
            let w = t.velocity_at(i as f64 * dt, wind);
            for k in 0..3 {
                sum[k] += w[k];
                sq[k] += w[k] * w[k];
            }
        }
        let var = |k: usize| sq[k] / n as f64 - (sum[k] / n as f64).powi(2);
        let h2 = p.sigma_horizontal.powi(2);
        let v2 = p.sigma_vertical.powi(2);
        for (k, s2) in [(0, h2), (1, h2), (2, v2)] {
            assert!(
                (sum[k] / n as f64).abs() < 0.15 * s2.sqrt(),
                "mean {k}: {sum:?}"
            );
            assert!(
                (var(k) / s2 - 1.0).abs() < 0.25,
                "variance {k}: {} vs {s2}",
                var(k)
            );
        }
        // The same seed gives the same air; another seed other air.
        assert_eq!(t.velocity_at(1.25, wind), t.velocity_at(1.25, wind));
        let other = Turbulence { seed: 8, ..t };
        assert_ne!(t.velocity_at(1.25, wind), other.velocity_at(1.25, wind));
        // No intensity, no turbulence.
        let calm = Turbulence { scale: 0.0, ..t };
        assert_eq!(calm.velocity_at(3.0, wind), [0.0; 3]);
    }
}
