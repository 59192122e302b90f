//! tvmd-sim as PX4's simulator: PX4 SITL's `simulator_mavlink` connects to the bridge, which
//! flies the scenario's team on tvmd's plant in lockstep with PX4 (or in real time, for a PX4
//! build without lockstep).
//!
//! Modules, in import order (a module uses only modules above it):
//! - [`error`] ([`Px4Error`]);
//! - [`frames`] (tvmd's z-up frames against PX4's NED and FRD) and [`geo`] (the home point,
//!   PX4's map projection, the magnetic field, the standard atmosphere);
//! - [`sensors`] (IMU, magnetometer, barometer, GPS and ground truth with noise and biases)
//!   and [`mapping`] (the 16 HIL controls onto the team's actuators, as data);
//! - [`messages`] (the HIL messages), [`link`] (the simulator's TCP port) and [`gcs`] (the
//!   ground-station link over UDP);
//! - [`flight`] (the flight file: script, mapping, sensors, windows) and [`measure`] (what a
//!   flight showed);
//! - [`bridge`] (the bridge as the loop's flight controller, lockstep or real time),
//!   [`launch`] (PX4 started from a user's tree) and [`run`] (one flight, its log and its
//!   report).
//!
//! See the book's chapter "PX4 in the loop" (docs/px4.md).

#![warn(missing_docs)]

pub mod bridge;
pub mod error;
pub mod flight;
pub mod frames;
pub mod gcs;
pub mod geo;
pub mod launch;
pub mod link;
pub mod mapping;
pub mod measure;
pub mod messages;
pub mod run;
pub mod script;
pub mod sensors;

pub use error::Px4Error;
pub use flight::FlightPlan;
pub use run::{fly_px4, write_report, Px4Flight, Px4Report};
