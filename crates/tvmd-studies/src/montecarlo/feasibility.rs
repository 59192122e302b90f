//! The feasibility verdict of a flight (`docs/monte-carlo.md`, "Feasible and infeasible
//! flights"): whether any admissible command of the plant as built can produce the wrench that
//! holds the reference, at every sampled instant of it.
//!
//! The plant as built is the team's exact wrench map with each agent's drawn efficiency and
//! gimbal offsets ([`AtlasModel::with_actuation`]) over the admissible commands (gimbal angles
//! in `|eta_x| <= sigma_x`, `|eta_y| <= sigma_y`, thrust in `[T_lo, sigma_Tf]`). The wrench
//! needed at time `t` of the reference, in the body frame at the reference attitude `R_r` and
//! about the model's centre of mass (the agents' blocks `M_i` are about it), is
//! `f = R_r^T (m (a_r + g e_3) - f_ext)`, `tau = c x f + J Omega_dot_r + Omega_r x J Omega_r -
//! tau_ext`, with the plant's mass `m`, centre of mass `c` and inertia `J` (payloads included
//! once attached) and the scenario's known external forces (steady wind force, drag of the air
//! at the reference's velocity, external wrench). The attainable set is not convex (the
//! gimbal's curved faces), so the verdict comes with a certificate either way:
//! - **feasible**: commands inside the box that produce the wrench (projected Gauss-Newton,
//!   [`crate::afs_atlas::inner::attain`], residual below `1e-10 n sigma_Tf`);
//! - **infeasible**: a multiplier `y` with `h(y) < y . w`, `h` the closed-form support
//!   function of the set: the wrench lies outside the set's convex hull (weak duality,
//!   [`crate::afs_atlas::outer`]);
//! - **undecided**: neither was found (inside the hull, no commands found).
//!
//! A flight is infeasible if one sampled instant is, feasible if every one is. Feasibility at
//! the reference attitude is what holding the full pose asks for; the study's success bounds
//! the attitude error to the planned attitude, so a flight judged infeasible may still hold its
//! position by tilting.

use nalgebra::{Matrix3, Vector3, Vector6};
use serde::{Deserialize, Serialize};
use tvmd_core::{FailureMask, GimbalCommand, TeamConfig};
use tvmd_scenario::Scenario;

use crate::afs_atlas::bound_ray;
use crate::afs_atlas::inner::attain;
use crate::afs_atlas::model::{AgentActuation, AtlasModel};
use crate::afs_atlas::outer::minimize_dual;
use crate::afs_atlas::ray::Ray;
use crate::StudyError;

/// Period at which the reference is sampled (s); the flight's last instant is sampled too.
pub const SAMPLE_PERIOD: f64 = 0.1;

/// The verdict of a flight or a wrench.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Feasibility {
    /// Every sampled wrench is attained by admissible commands (found and checked).
    Feasible,
    /// A sampled wrench lies outside the convex hull of the attainable set (a separating
    /// multiplier found and checked).
    Infeasible,
    /// Neither certificate found.
    Undecided,
}

impl Feasibility {
    /// `"feasible"`, `"infeasible"` or `"undecided"`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Feasible => "feasible",
            Self::Infeasible => "infeasible",
            Self::Undecided => "undecided",
        }
    }
}

/// One wrench's verdict with its certificate.
#[derive(Clone, Debug, PartialEq)]
pub enum WrenchVerdict {
    /// Admissible commands that produce the wrench.
    Feasible(Vec<GimbalCommand<f64>>),
    /// A multiplier `y` with `h(y) < y . w`.
    Infeasible(Vector6<f64>),
    /// Neither found.
    Undecided,
}

impl WrenchVerdict {
    /// The verdict without its certificate.
    pub fn feasibility(&self) -> Feasibility {
        match self {
            Self::Feasible(_) => Feasibility::Feasible,
            Self::Infeasible(_) => Feasibility::Infeasible,
            Self::Undecided => Feasibility::Undecided,
        }
    }
}

/// Whether `model` attains `target` (rows `[torque; force]`), with a certificate; `warm`:
/// commands to start the search from (the previous instant's).
pub fn wrench_verdict(
    model: &AtlasModel,
    target: &Vector6<f64>,
    warm: Option<&[GimbalCommand<f64>]>,
) -> WrenchVerdict {
    let level = model.level(target[5] / model.len() as f64);
    for start in warm.into_iter().chain([level.as_slice()]) {
        if let Some(x) = attain(model, target, start) {
            return WrenchVerdict::Feasible(x);
        }
    }
    // A ray from an attained point (level commands) through the target: an upper bound of the
    // ray's attainable `t` below the target's distance separates the target from the hull.
    let origin = model.wrench(&level);
    let distance = (target - origin).norm();
    if !(distance > 0.0 && distance.is_finite()) {
        return WrenchVerdict::Undecided;
    }
    let ray = Ray {
        origin,
        direction: (target - origin) / distance,
    };
    let separated = |y: &Vector6<f64>| {
        let margin = 1e-9 * model.scale() * y.norm();
        model.support(y).0 < y.dot(target) - margin
    };
    let dual = minimize_dual(model, &ray, &ray.direction);
    if separated(&dual.multiplier) {
        return WrenchVerdict::Infeasible(dual.multiplier);
    }
    let bound = bound_ray(model, &ray, &[dual.multiplier]);
    if separated(&bound.multiplier) {
        return WrenchVerdict::Infeasible(bound.multiplier);
    }
    let mut seeds = vec![model.support(&bound.multiplier).1, dual.commands];
    seeds.extend(bound.commands);
    for seed in &seeds {
        if let Some(x) = attain(model, target, seed) {
            return WrenchVerdict::Feasible(x);
        }
    }
    WrenchVerdict::Undecided
}

/// A flight's verdict over its sampled reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlightFeasibility {
    /// The verdict: infeasible if an instant is, feasible if every one is.
    pub feasibility: Feasibility,
    /// The first instant judged infeasible (s), if any.
    pub first_infeasible: Option<f64>,
    /// Instants sampled.
    pub samples: usize,
}

/// The plant as built of a scenario: its exact wrench map, mass, centre of mass and inertia.
#[derive(Clone, Debug)]
pub struct Plant {
    model: AtlasModel,
    mass: f64,
    com: Vector3<f64>,
    inertia: Matrix3<f64>,
}

impl Plant {
    /// The plant `scenario` flies: its team with the plant error's efficiencies and gimbal
    /// offsets, mass, inertia and centre of mass (every agent working).
    pub fn new(scenario: &Scenario) -> Result<Self, StudyError> {
        let team: TeamConfig<f64, 16> = tvmd_scenario::core_config::team_config(scenario)?;
        let model = AtlasModel::new(&team, &FailureMask::default())
            .map_err(|e| StudyError::invalid_team(e.to_string()))?;
        let p = &scenario.plant;
        let actuation: Vec<AgentActuation> = model
            .agents
            .iter()
            .map(|&i| AgentActuation {
                efficiency: p.efficiency(i),
                gimbal_offset: p.gimbal_offset(i),
            })
            .collect();
        let model =
            model
                .with_actuation(&actuation)
                .map_err(|reason| StudyError::InvalidArgument {
                    name: "plant".into(),
                    reason,
                })?;
        Ok(Self {
            mass: team.mass() * p.mass_scale,
            com: Vector3::from(p.com_offset),
            inertia: team.inertia() * p.inertia_scale,
            model,
        })
    }

    /// The exact wrench map of the plant as built.
    pub fn model(&self) -> &AtlasModel {
        &self.model
    }

    /// The wrench (rows `[torque; force]`, body frame at `R_r`, about the model's centre of
    /// mass) that holds `scenario`'s reference at `t`.
    pub fn required_wrench(&self, scenario: &Scenario, t: f64) -> Vector6<f64> {
        let r = scenario.reference.at(t);
        let mut mass = self.mass;
        let mut moment = self.com * self.mass;
        for p in scenario.payloads.iter().filter(|p| p.time <= t) {
            mass += p.mass;
            moment += Vector3::from(p.offset) * p.mass;
        }
        let com = moment / mass;
        let d = &scenario.disturbances;
        let mut external = Vector3::from(d.wind);
        let mut external_torque = Vector3::zeros();
        if let Some(air) = &d.air {
            external += Vector3::from(air.force(t, r.velocity.into(), self.model.len()));
        }
        if let Some(e) = d.external_wrench.as_ref().filter(|e| e.active(t)) {
            external += Vector3::from(e.force);
            external_torque += Vector3::from(e.torque);
        }
        let gravity = Vector3::new(0.0, 0.0, scenario.physics.gravity);
        let force = r.rotation.transpose() * ((r.acceleration + gravity) * mass - external);
        let j = self.inertia;
        let torque =
            com.cross(&force) + j * r.omega_dot + r.omega.cross(&(j * r.omega)) - external_torque;
        Vector6::new(torque.x, torque.y, torque.z, force.x, force.y, force.z)
    }

    /// The verdict of `scenario`'s flight: the reference sampled every [`SAMPLE_PERIOD`] and at
    /// its end (an instant whose wrench equals the previous one's is not solved again).
    pub fn verdict(&self, scenario: &Scenario) -> FlightFeasibility {
        let steps = (scenario.duration / SAMPLE_PERIOD).ceil().max(0.0) as usize;
        let mut out = FlightFeasibility {
            feasibility: Feasibility::Feasible,
            first_infeasible: None,
            samples: 0,
        };
        let mut previous: Option<(Vector6<f64>, WrenchVerdict)> = None;
        for k in 0..=steps {
            let t = (k as f64 * SAMPLE_PERIOD).min(scenario.duration);
            let target = self.required_wrench(scenario, t);
            out.samples += 1;
            let verdict = match previous.take() {
                Some((w, v)) if w == target => v,
                Some((_, WrenchVerdict::Feasible(x))) => {
                    wrench_verdict(&self.model, &target, Some(&x))
                }
                _ => wrench_verdict(&self.model, &target, None),
            };
            match verdict.feasibility() {
                Feasibility::Infeasible => {
                    out.feasibility = Feasibility::Infeasible;
                    out.first_infeasible = Some(t);
                    return out;
                }
                Feasibility::Undecided => out.feasibility = Feasibility::Undecided,
                Feasibility::Feasible => {}
            }
            previous = Some((target, verdict));
        }
        out
    }
}

#[cfg(test)]
#[path = "feasibility_tests.rs"]
mod tests;
