//! The sensors PX4 reads from a simulator: IMU, magnetometer, barometer and GPS made from the
//! plant's state, with noise and biases, in PX4's frames and units, and the ground truth.
//!
//! The accelerometer reads the specific force `R^T (a - g)`, `a` the centre of mass's mean
//! acceleration over the last period (the velocity's change: thrust, wind, drag and ground
//! contact alike), so that a team resting on the ground reads `-g` along FRD's z, as a real
//! IMU does. It saturates at its range (`accel_range`, PX4's simulated 16 g): a touchdown's
//! one-tick impulse can exceed it, and PX4's `simulator_mavlink` packs each sample into an int16
//! at `g/2048` per count, where a larger one wraps round to the opposite sign (EKF2 then
//! integrates a false velocity); saturated, PX4 sees the sample as clipping, as with a real IMU.

use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};
use tvmd_plant::physics::PlantState;
use tvmd_plant::GRAVITY;

use crate::frames::{flip, quaternion_ned_frd, rotation_ned_frd};
use crate::geo::{standard_atmosphere, Home};
use crate::Px4Error;

/// HIL_SENSOR `fields_updated` bits (PX4's `SensorSource`): accelerometer, gyroscope,
/// magnetometer, barometer (pressure, altitude, temperature).
pub mod fields {
    /// x, y, z acceleration.
    pub const ACCEL: u32 = 0b111;
    /// x, y, z angular rate.
    pub const GYRO: u32 = 0b111_000;
    /// x, y, z magnetic field.
    pub const MAG: u32 = 0b111_000_000;
    /// Absolute pressure, pressure altitude and temperature.
    pub const BARO: u32 = 0b1_1010_0000_0000;
}

/// PX4's simulated accelerometer range (m/s^2): 32767.5 counts of `g/2048`, PX4's `CONSTANTS_ONE_G`
/// (`simulator_mavlink`'s int16 FIFO; 16 g less half a count).
pub const PX4_ACCEL_RANGE: f64 = 32767.5 * 9.80665 / 2048.0;

/// Noise, biases and rates of the simulated sensors (`[sensors]` of a flight file). Standard
/// deviations are per sample; defaults are those of PX4's Gazebo sensor plugins at 250 Hz
/// (gyroscope 0.0030 rad/s, accelerometer 0.029 m/s^2) with an RTK-grade GPS (2 cm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorConfig {
    /// Seed of the noise.
    pub seed: u64,
    /// Gyroscope noise (rad/s).
    pub gyro_noise: f64,
    /// Gyroscope bias, FRD (rad/s).
    pub gyro_bias: [f64; 3],
    /// Accelerometer noise (m/s^2).
    pub accel_noise: f64,
    /// Accelerometer bias, FRD (m/s^2).
    pub accel_bias: [f64; 3],
    /// Largest specific force each accelerometer axis reads (m/s^2): default PX4's simulated
    /// range, 16 g (32767.5 counts of `g/2048`: PX4 flags the sample as clipping and one count
    /// more would wrap its int16 to the opposite sign).
    pub accel_range: f64,
    /// Magnetometer noise (gauss).
    pub mag_noise: f64,
    /// Barometer noise (hPa; 0.012 hPa is about 0.1 m).
    pub baro_noise: f64,
    /// GPS horizontal position noise (m).
    pub gps_horizontal_noise: f64,
    /// GPS vertical position noise (m).
    pub gps_vertical_noise: f64,
    /// GPS velocity noise (m/s).
    pub gps_velocity_noise: f64,
    /// Magnetometer and barometer rate (Hz).
    pub mag_baro_rate: f64,
    /// GPS rate (Hz).
    pub gps_rate: f64,
    /// Ground-truth (HIL_STATE_QUATERNION) rate (Hz).
    pub truth_rate: f64,
}

impl Default for SensorConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            gyro_noise: 0.0030,
            gyro_bias: [0.0; 3],
            accel_noise: 0.029,
            accel_bias: [0.0; 3],
            accel_range: PX4_ACCEL_RANGE,
            mag_noise: 0.0005,
            baro_noise: 0.006,
            gps_horizontal_noise: 0.02,
            gps_vertical_noise: 0.03,
            gps_velocity_noise: 0.02,
            mag_baro_rate: 50.0,
            gps_rate: 10.0,
            truth_rate: 50.0,
        }
    }
}

impl SensorConfig {
    /// Errors name a negative or non-finite noise, or a non-positive rate.
    pub fn check(&self) -> Result<(), Px4Error> {
        let bad = |name: &str, reason: String| Px4Error::Config {
            field: format!("sensors.{name}"),
            reason,
        };
        for (name, v) in [
            ("gyro_noise", self.gyro_noise),
            ("accel_noise", self.accel_noise),
            ("mag_noise", self.mag_noise),
            ("baro_noise", self.baro_noise),
            ("gps_horizontal_noise", self.gps_horizontal_noise),
            ("gps_vertical_noise", self.gps_vertical_noise),
            ("gps_velocity_noise", self.gps_velocity_noise),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, format!("must be finite and >= 0, got {v}")));
            }
        }
        for (name, v) in [
            ("accel_range", self.accel_range),
            ("mag_baro_rate", self.mag_baro_rate),
            ("gps_rate", self.gps_rate),
            ("truth_rate", self.truth_rate),
        ] {
            if !(v.is_finite() && v > 0.0) {
                let unit = if name == "accel_range" { "m/s^2" } else { "Hz" };
                return Err(bad(name, format!("must be > 0 {unit}, got {v}")));
            }
        }
        for (name, b) in [
            ("gyro_bias", self.gyro_bias),
            ("accel_bias", self.accel_bias),
        ] {
            if !b.iter().all(|x| x.is_finite()) {
                return Err(bad(name, format!("must be finite, got {b:?}")));
            }
        }
        Ok(())
    }
}

/// One IMU sample (and, when due, magnetometer and barometer) in PX4's frames and units: the
/// fields of HIL_SENSOR.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuReading {
    /// Specific force, FRD (m/s^2).
    pub accel: [f32; 3],
    /// Angular rate, FRD (rad/s).
    pub gyro: [f32; 3],
    /// Magnetic field, FRD (gauss).
    pub mag: [f32; 3],
    /// Static pressure (hPa).
    pub pressure: f32,
    /// Pressure altitude (m).
    pub pressure_alt: f32,
    /// Temperature (deg C).
    pub temperature: f32,
    /// Which fields are new ([`fields`]).
    pub fields_updated: u32,
}

/// One GPS fix in HIL_GPS's units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsReading {
    /// Latitude, longitude (degE7).
    pub lat: i32,
    /// Longitude (degE7).
    pub lon: i32,
    /// Altitude above mean sea level (mm).
    pub alt: i32,
    /// North, east, down velocity (cm/s).
    pub vel_ned: [i16; 3],
    /// Ground speed (cm/s).
    pub speed: u16,
    /// Course over ground (cdeg, 0..35999; 65535 when standing).
    pub cog: u16,
}

/// The ground truth in HIL_STATE_QUATERNION's units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthReading {
    /// Attitude, FRD to NED `[w, x, y, z]`.
    pub q: [f32; 4],
    /// Body rates, FRD (rad/s).
    pub rates: [f32; 3],
    /// Latitude, longitude (degE7), altitude (mm).
    pub lat_lon_alt: [i32; 3],
    /// Velocity NED (cm/s).
    pub vel_ned: [i16; 3],
    /// Specific force, FRD (mG).
    pub accel_mg: [i16; 3],
}

/// The sensor models of one flight: the home point, the noise and its generator.
pub struct SensorModel {
    config: SensorConfig,
    home: Home,
    rng: ChaCha8Rng,
}

impl SensorModel {
    /// The sensors of `config` at `home`; errors as [`SensorConfig::check`].
    pub fn new(config: SensorConfig, home: Home) -> Result<Self, Px4Error> {
        config.check()?;
        Ok(Self {
            rng: ChaCha8Rng::seed_from_u64(config.seed),
            config,
            home,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &SensorConfig {
        &self.config
    }

    /// The home point.
    pub fn home(&self) -> &Home {
        &self.home
    }

    fn noise3(&mut self, std: f64) -> Vector3<f64> {
        let mut g = || self.rng.sample::<f64, _>(StandardNormal) * std;
        Vector3::new(g(), g(), g())
    }

    fn noise(&mut self, std: f64) -> f64 {
        self.rng.sample::<f64, _>(StandardNormal) * std
    }

    /// The IMU sample of `state` with world acceleration `accel` (m/s^2, tvmd's world frame);
    /// with `mag_baro`, the magnetometer and barometer too.
    pub fn imu(&mut self, state: &PlantState, accel: &Vector3<f64>, mag_baro: bool) -> ImuReading {
        let r = &state.rotation;
        let gravity = Vector3::new(0.0, 0.0, -GRAVITY);
        let specific = flip(&(r.transpose() * (accel - gravity)));
        let range = self.config.accel_range;
        let accel_frd = (specific
            + Vector3::from(self.config.accel_bias)
            + self.noise3(self.config.accel_noise))
        .map(|a| a.clamp(-range, range));
        let gyro_frd = flip(&state.omega)
            + Vector3::from(self.config.gyro_bias)
            + self.noise3(self.config.gyro_noise);
        let mut reading = ImuReading {
            accel: f32x3(&accel_frd),
            gyro: f32x3(&gyro_frd),
            mag: [0.0; 3],
            pressure: 0.0,
            pressure_alt: 0.0,
            temperature: 0.0,
            fields_updated: fields::ACCEL | fields::GYRO,
        };
        if mag_baro {
            let frd_to_ned: Matrix3<f64> = rotation_ned_frd(r);
            let mag =
                frd_to_ned.transpose() * self.home.field_ned() + self.noise3(self.config.mag_noise);
            let altitude = self.home.altitude + state.position.z;
            let (pressure, temperature) = standard_atmosphere(altitude);
            reading.mag = f32x3(&mag);
            reading.pressure = (pressure + self.noise(self.config.baro_noise)) as f32;
            reading.pressure_alt = altitude as f32;
            reading.temperature = temperature as f32;
            reading.fields_updated |= fields::MAG | fields::BARO;
        }
        reading
    }

    /// The GPS fix of `state`.
    pub fn gps(&mut self, state: &PlantState) -> GpsReading {
        let h = self.config.gps_horizontal_noise;
        let p_ned = flip(&state.position)
            + Vector3::new(
                self.noise(h),
                self.noise(h),
                self.noise(self.config.gps_vertical_noise),
            );
        let v_ned = flip(&state.velocity) + self.noise3(self.config.gps_velocity_noise);
        let (lat, lon) = self.home.reproject(p_ned.x, p_ned.y);
        GpsReading {
            lat: deg_e7(lat),
            lon: deg_e7(lon),
            alt: ((self.home.altitude - p_ned.z) * 1e3).round() as i32,
            vel_ned: cm_s3(&v_ned),
            speed: cm_s_u16(v_ned.xy().norm()),
            cog: course(&v_ned),
        }
    }

    /// The ground truth of `state` with world acceleration `accel`.
    pub fn truth(&self, state: &PlantState, accel: &Vector3<f64>) -> TruthReading {
        let gravity = Vector3::new(0.0, 0.0, -GRAVITY);
        let specific = flip(&(state.rotation.transpose() * (accel - gravity)));
        let p_ned = flip(&state.position);
        let (lat, lon) = self.home.reproject(p_ned.x, p_ned.y);
        let q = quaternion_ned_frd(&state.rotation);
        let mg = |a: f64| (a / GRAVITY * 1e3).round().clamp(-32768.0, 32767.0) as i16;
        TruthReading {
            q: q.map(|c| c as f32),
            rates: f32x3(&flip(&state.omega)),
            lat_lon_alt: [
                deg_e7(lat),
                deg_e7(lon),
                ((self.home.altitude - p_ned.z) * 1e3).round() as i32,
            ],
            vel_ned: cm_s3(&flip(&state.velocity)),
            accel_mg: [mg(specific.x), mg(specific.y), mg(specific.z)],
        }
    }
}

fn f32x3(v: &Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

fn deg_e7(deg: f64) -> i32 {
    (deg * 1e7).round() as i32
}

fn cm_s3(v: &Vector3<f64>) -> [i16; 3] {
    let c = |x: f64| (x * 100.0).round().clamp(-32768.0, 32767.0) as i16;
    [c(v.x), c(v.y), c(v.z)]
}

fn cm_s_u16(x: f64) -> u16 {
    (x * 100.0).round().clamp(0.0, 65534.0) as u16
}

/// Course over ground (cdeg from north, clockwise), 65535 (unknown) below 0.1 m/s.
fn course(v_ned: &Vector3<f64>) -> u16 {
    if v_ned.xy().norm() < 0.1 {
        return u16::MAX;
    }
    let deg = v_ned.y.atan2(v_ned.x).to_degrees().rem_euclid(360.0);
    ((deg * 100.0).round() as u16) % 36000
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn quiet() -> SensorModel {
        let config = SensorConfig {
            gyro_noise: 0.0,
            accel_noise: 0.0,
            mag_noise: 0.0,
            baro_noise: 0.0,
            gps_horizontal_noise: 0.0,
            gps_vertical_noise: 0.0,
            gps_velocity_noise: 0.0,
            ..Default::default()
        };
        SensorModel::new(config, Home::default()).unwrap()
    }

    #[test]
    fn resting_level_team_reads_minus_g_down_and_the_field_of_home() {
        let mut s = quiet();
        let r = s.imu(
            &PlantState::at_rest(Vector3::zeros()),
            &Vector3::zeros(),
            true,
        );
        assert_eq!(r.accel, [0.0, 0.0, -GRAVITY as f32]);
        assert_eq!(r.gyro, [0.0; 3]);
        let b = Home::default().magnetic_field_ned;
        assert!(r
            .mag
            .iter()
            .zip(b)
            .all(|(m, b)| (f64::from(*m) - b).abs() < 1e-6));
        assert_eq!(
            r.fields_updated,
            fields::ACCEL | fields::GYRO | fields::MAG | fields::BARO
        );
        // The pressure of home's altitude.
        let (p, _) = standard_atmosphere(488.0);
        assert!((f64::from(r.pressure) - p).abs() < 1e-3);
    }

    #[test]
    fn a_touchdown_beyond_the_range_saturates_the_accelerometer_instead_of_wrapping() {
        let mut s = quiet();
        let level = PlantState::at_rest(Vector3::zeros());
        // 0.7 m/s stopped within one 4 ms tick: 175 m/s^2 up, past 16 g with gravity.
        let r = s.imu(&level, &Vector3::new(0.0, 0.0, 175.0), false);
        assert_eq!(r.accel[2], -PX4_ACCEL_RANGE as f32);
        // PX4 packs it as -32767 counts of g/2048 (its clipping mark), not past the int16.
        let counts = r.accel[2] / (9.80665f32 / 2048.0);
        assert!(counts < -32766.9 && counts > -32768.0, "{counts}");
        let bad = SensorConfig {
            accel_range: 0.0,
            ..Default::default()
        };
        let err = bad.check().unwrap_err().to_string();
        assert!(err.contains("accel_range"), "{err}");
    }

    #[test]
    fn climbing_lowers_the_pressure_and_raises_gps_altitude() {
        let mut s = quiet();
        let low = PlantState::at_rest(Vector3::zeros());
        let high = PlantState::at_rest(Vector3::new(0.0, 0.0, 10.0));
        let (a, b) = (
            s.imu(&low, &Vector3::zeros(), true),
            s.imu(&high, &Vector3::zeros(), true),
        );
        assert!(
            a.pressure - b.pressure > 1.0,
            "{} {}",
            a.pressure,
            b.pressure
        );
        assert_eq!(s.gps(&high).alt - s.gps(&low).alt, 10_000);
    }

    #[test]
    fn yawed_team_sees_the_field_turned_the_other_way() {
        // Yawed left (counter-clockwise from above) by 90 deg, the team's nose points west: the
        // north field is on its right (+y in FRD).
        let mut s = quiet();
        let state = PlantState {
            rotation: *Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2)
                .matrix(),
            ..PlantState::at_rest(Vector3::zeros())
        };
        let r = s.imu(&state, &Vector3::zeros(), true);
        let b = Home::default().magnetic_field_ned;
        assert!((f64::from(r.mag[1]) - b[0]).abs() < 1e-6, "{:?}", r.mag);
        assert!((f64::from(r.mag[2]) - b[2]).abs() < 1e-6);
    }

    #[test]
    fn gps_of_a_northward_flight() {
        let mut s = quiet();
        let state = PlantState {
            velocity: Vector3::new(2.0, 0.0, 1.0),
            ..PlantState::at_rest(Vector3::new(1.0, 0.0, 0.0))
        };
        let g = s.gps(&state);
        assert_eq!(g.vel_ned, [200, 0, -100]);
        assert_eq!(g.speed, 200);
        assert_eq!(g.cog, 0);
        let home = Home::default();
        let (n, e) = home.project(f64::from(g.lat) * 1e-7, f64::from(g.lon) * 1e-7);
        assert!((n - 1.0).abs() < 0.02 && e.abs() < 0.02, "{n} {e}");
        // West is a course of 270 deg.
        let west = PlantState {
            velocity: Vector3::new(0.0, 1.0, 0.0),
            ..PlantState::at_rest(Vector3::zeros())
        };
        assert_eq!(s.gps(&west).cog, 27000);
    }

    #[test]
    fn noise_has_its_configured_spread_and_a_seed_repeats_it() {
        let config = SensorConfig::default();
        let state = PlantState::at_rest(Vector3::zeros());
        let sample = |seed| {
            let mut s = SensorModel::new(SensorConfig { seed, ..config }, Home::default()).unwrap();
            (0..4000)
                .map(|_| f64::from(s.imu(&state, &Vector3::zeros(), false).gyro[0]))
                .collect::<Vec<_>>()
        };
        let a = sample(1);
        assert_eq!(a, sample(1));
        let std = (a.iter().map(|x| x * x).sum::<f64>() / a.len() as f64).sqrt();
        assert!((std / config.gyro_noise - 1.0).abs() < 0.05, "{std}");
    }

    #[test]
    fn negative_noise_is_refused_by_name() {
        let config = SensorConfig {
            baro_noise: -1.0,
            ..Default::default()
        };
        let e = SensorModel::new(config, Home::default())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("sensors.baro_noise"), "{e}");
    }
}
