//! Where the flight is on Earth: the home point, local offsets as latitude and longitude (PX4's
//! own projection), the magnetic field and the standard atmosphere at the home point.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Earth's radius of PX4's map projection (`CONSTANTS_RADIUS_OF_EARTH`, m).
pub const EARTH_RADIUS: f64 = 6_371_000.0;

/// The point tvmd's world origin sits on, and the magnetic field there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Home {
    /// Latitude (deg); Zurich's, PX4's simulators' default home.
    pub latitude: f64,
    /// Longitude (deg).
    pub longitude: f64,
    /// Altitude of tvmd's `z = 0` above mean sea level (m).
    pub altitude: f64,
    /// Earth's magnetic field in NED (gauss). Default: PX4's world magnetic model tables at the
    /// default home (declination 3.27 deg, inclination 63.14 deg, 0.482 G), so that EKF2's
    /// checks of the field against the model pass.
    pub magnetic_field_ned: [f64; 3],
}

impl Default for Home {
    fn default() -> Self {
        Self {
            latitude: 47.397742,
            longitude: 8.545594,
            altitude: 488.0,
            magnetic_field_ned: [0.217375, 0.012433, 0.429991],
        }
    }
}

impl Home {
    /// Latitude and longitude (deg) of a point `north`, `east` metres from home: PX4's
    /// azimuthal equidistant projection (`MapProjection::reproject`), so that PX4's local
    /// frame, whose origin EKF2 sets at its first GPS fix, matches tvmd's world frame.
    pub fn reproject(&self, north: f64, east: f64) -> (f64, f64) {
        let lat0 = self.latitude.to_radians();
        let lon0 = self.longitude.to_radians();
        let x = north / EARTH_RADIUS;
        let y = east / EARTH_RADIUS;
        let c = (x * x + y * y).sqrt();
        if c == 0.0 {
            return (self.latitude, self.longitude);
        }
        let (sin_c, cos_c) = c.sin_cos();
        let (sin_lat0, cos_lat0) = lat0.sin_cos();
        let lat = (cos_c * sin_lat0 + x * sin_c * cos_lat0 / c).asin();
        let lon = lon0 + (y * sin_c).atan2(c * cos_lat0 * cos_c - x * sin_lat0 * sin_c);
        (lat.to_degrees(), lon.to_degrees())
    }

    /// North and east offsets (m) of a latitude and longitude (deg) from home: the inverse of
    /// [`Home::reproject`] (`MapProjection::project`).
    pub fn project(&self, latitude: f64, longitude: f64) -> (f64, f64) {
        let (lat0, lon0) = (self.latitude.to_radians(), self.longitude.to_radians());
        let (lat, lon) = (latitude.to_radians(), longitude.to_radians());
        let (sin_lat0, cos_lat0) = lat0.sin_cos();
        let (sin_lat, cos_lat) = lat.sin_cos();
        let cos_d_lon = (lon - lon0).cos();
        let arg = (sin_lat0 * sin_lat + cos_lat0 * cos_lat * cos_d_lon).clamp(-1.0, 1.0);
        let c = arg.acos();
        let k = if c.abs() > 0.0 { c / c.sin() } else { 1.0 };
        let north = k * (cos_lat0 * sin_lat - sin_lat0 * cos_lat * cos_d_lon) * EARTH_RADIUS;
        let east = k * cos_lat * (lon - lon0).sin() * EARTH_RADIUS;
        (north, east)
    }

    /// The magnetic field in NED (gauss).
    pub fn field_ned(&self) -> Vector3<f64> {
        Vector3::from(self.magnetic_field_ned)
    }
}

/// Static pressure (hPa) and temperature (deg C) of the standard atmosphere (ISA, troposphere)
/// at `altitude` metres above mean sea level.
pub fn standard_atmosphere(altitude: f64) -> (f64, f64) {
    const P0: f64 = 101_325.0;
    const T0: f64 = 288.15;
    const LAPSE: f64 = 0.0065;
    // g M / (R L) for dry air.
    const EXPONENT: f64 = 5.255_88;
    let t = T0 - LAPSE * altitude;
    let p = P0 * (t / T0).powf(EXPONENT);
    (p / 100.0, t - 273.15)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproject_and_project_are_inverse_to_a_millimetre() {
        let home = Home::default();
        for (n, e) in [(0.0, 0.0), (1.0, 0.0), (0.0, -1.0), (123.4, -56.7)] {
            let (lat, lon) = home.reproject(n, e);
            let (n2, e2) = home.project(lat, lon);
            assert!(
                (n - n2).abs() < 1e-3 && (e - e2).abs() < 1e-3,
                "{n} {e} -> {n2} {e2}"
            );
        }
        // One metre north is 1/R rad of latitude.
        let (lat, lon) = home.reproject(1.0, 0.0);
        assert!((lat - home.latitude - (1.0 / EARTH_RADIUS).to_degrees()).abs() < 1e-12);
        assert!((lon - home.longitude).abs() < 1e-12);
    }

    #[test]
    fn atmosphere_at_sea_level_and_its_lapse() {
        let (p, t) = standard_atmosphere(0.0);
        assert!((p - 1013.25).abs() < 1e-9 && (t - 15.0).abs() < 1e-9);
        // About 0.12 hPa less per metre near the ground.
        let (p1, _) = standard_atmosphere(1.0);
        assert!((p - p1 - 0.12).abs() < 0.005, "{}", p - p1);
    }

    #[test]
    fn default_field_matches_the_model_it_was_read_from() {
        let b = Home::default().field_ned();
        let inclination = b.z.atan2((b.x * b.x + b.y * b.y).sqrt()).to_degrees();
        let declination = b.y.atan2(b.x).to_degrees();
        assert!((b.norm() - 0.48197).abs() < 1e-4);
        assert!((inclination - 63.144).abs() < 0.01 && (declination - 3.274).abs() < 0.01);
    }
}
