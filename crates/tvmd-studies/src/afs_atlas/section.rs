//! Cross-sections of the exact attainable force set: at a vertical force `u_z` and a required
//! torque, the farthest attainable lateral force in each direction, bracketed; and the hover
//! ceiling, the largest vertical force at that torque with no lateral force.

use nalgebra::{Vector3, Vector6};
use std::sync::atomic::{AtomicBool, Ordering};
use tvmd_core::GimbalCommand;

use super::bracket::bound_ray;
use super::model::AtlasModel;
use super::ray::{Bracket, Ray, RayBound};

/// A cross-section to compute.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectionQuery {
    /// `u_z` (N), the team-frame vertical force.
    pub height: f64,
    /// The torque the agents must hold meanwhile (N m, team frame); zero by default.
    pub torque: Vector3<f64>,
    /// Directions, evenly spaced from `+x` counter-clockwise.
    pub directions: usize,
}

/// One direction of a cross-section.
#[derive(Clone, Debug)]
pub struct SectionPoint {
    /// The direction's angle from `+x` (rad).
    pub angle: f64,
    /// The attainable lateral force along it (N).
    pub radius: Bracket,
    /// Commands attaining `radius.lower`.
    pub commands: Option<Vec<GimbalCommand<f64>>>,
}

/// The bracketed boundary of the attainable lateral forces at one height and torque.
#[derive(Clone, Debug)]
pub struct CrossSection {
    /// The query.
    pub query: SectionQuery,
    /// One point per direction.
    pub points: Vec<SectionPoint>,
}

impl CrossSection {
    /// The widest bracket relative to its upper bound (`inf` when a direction was not attained).
    pub fn worst_relative_width(&self) -> f64 {
        self.points
            .iter()
            .map(|p| p.radius.width() / p.radius.upper.abs().max(1e-12))
            .fold(0.0, f64::max)
    }
}

/// The lateral ray at angle `angle`: `[tau; 0; 0; u_z] + t [0; cos; sin; 0]`.
pub fn lateral_ray(height: f64, torque: &Vector3<f64>, angle: f64) -> Ray {
    let (s, c) = angle.sin_cos();
    Ray {
        origin: Vector6::new(torque.x, torque.y, torque.z, 0.0, 0.0, height),
        direction: Vector6::new(0.0, 0.0, 0.0, c, s, 0.0),
    }
}

/// The bracketed radius of the attainable lateral forces along `angle`.
pub fn ray_radius(model: &AtlasModel, height: f64, torque: &Vector3<f64>, angle: f64) -> RayBound {
    bound_ray(model, &lateral_ray(height, torque, angle), &[])
}

/// The cross-section of the query, each direction's dual warm-started from its neighbour's
/// multiplier.
pub fn cross_section(model: &AtlasModel, query: &SectionQuery) -> CrossSection {
    cross_section_until(model, query, None)
}

/// [`cross_section`], stopping (with the directions bounded so far) once `cancel` is set.
pub fn cross_section_until(
    model: &AtlasModel,
    query: &SectionQuery,
    cancel: Option<&AtomicBool>,
) -> CrossSection {
    let k = query.directions.max(1);
    let mut previous: Option<Vector6<f64>> = None;
    let points = (0..k)
        .take_while(|_| !cancel.is_some_and(|c| c.load(Ordering::Relaxed)))
        .map(|i| {
            let angle = std::f64::consts::TAU * i as f64 / k as f64;
            let ray = lateral_ray(query.height, &query.torque, angle);
            let starts: Vec<Vector6<f64>> = previous.iter().copied().collect();
            let bound = bound_ray(model, &ray, &starts);
            previous = Some(bound.multiplier);
            SectionPoint {
                angle,
                radius: bound.bracket,
                commands: bound.commands,
            }
        })
        .collect();
    CrossSection {
        query: *query,
        points,
    }
}

/// The hover ceiling: the largest `u_z` attainable with no lateral force and `torque`, bracketed
/// (the ray `[tau; 0; 0; 0] + t e_z`).
pub fn hover_ceiling(model: &AtlasModel, torque: &Vector3<f64>) -> RayBound {
    let ray = Ray {
        origin: Vector6::new(torque.x, torque.y, torque.z, 0.0, 0.0, 0.0),
        direction: Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
    };
    bound_ray(model, &ray, &[])
}
