//! The seeded generator of the set: attainable requests `u = M f` from admissible `f` (gimbal
//! angles and thrust drawn in, or set on, their bounds), and requests outside the attainable set
//! with a certificate.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tvmd_core::gimbal::thrust_direction;
use tvmd_core::nalgebra::Vector3;
use tvmd_core::TeamConfig;

use super::{failure_mask, team, AllocationSet, Certificate, SetRequest, TeamRequests, SEED};
use crate::StudyError;

/// The capacity the generator builds every team with (the largest team's `n`).
const CAPACITY: usize = 16;

/// Attainable requests per team, by kind, in this order.
const ATTAINABLE: [(&str, usize); 6] = [
    ("interior", 16),
    ("thrust-bound", 8),
    ("gimbal-bound", 8),
    ("gimbal-corner", 8),
    ("corner", 8),
    ("mixed", 16),
];

/// Outside requests per team and certificate.
const OUTSIDE_PER_CERTIFICATE: usize = 4;

/// The teams (name, failed agents) of the set, in order: the four teams, then A4-Inc with agent
/// 1 failed (three agents, rank 6, no hover margin: the degraded case).
pub const SET_TEAMS: [(&str, &[usize]); 5] = [
    ("a4_inc", &[]),
    ("a6_inc", &[]),
    ("a8_inc", &[]),
    ("ring16_inc", &[]),
    ("a4_inc", &[1]),
];

/// Where one agent's gimbal angle or thrust lies.
#[derive(Clone, Copy)]
enum Place {
    /// Strictly inside, away from the bounds.
    Inside,
    /// On the upper or lower bound.
    Bound,
}

impl AllocationSet {
    /// The set of [`SET_TEAMS`] drawn with `seed` ([`SEED`] for the committed file).
    pub fn generate(seed: u64) -> Result<Self, StudyError> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut teams = Vec::new();
        for (name, failed) in SET_TEAMS {
            let t = team::<CAPACITY>(name)?;
            failure_mask(&t, failed)?;
            teams.push(TeamRequests {
                team: name.to_string(),
                failed: failed.to_vec(),
                requests: team_requests(&t, failed, &mut rng)?,
            });
        }
        Ok(Self {
            seed,
            description: "tvmd allocation benchmark set (tvmd-sim allocation-set): per team, \
                          wrenches u = [u_tau; u_f] (team frame) attainable by construction \
                          (u = M f with the listed admissible agent-frame forces f) and \
                          certified outside the attainable set (force-norm: |u_f| > bound = n \
                          sigma_Tf; torque-norm: |u_tau| > bound = sigma_Tf sum |p_i|; downward: \
                          u_fz < bound = 0)"
                .into(),
            teams,
        })
    }

    /// The committed set ([`SEED`]).
    pub fn committed_seed() -> Result<Self, StudyError> {
        Self::generate(SEED)
    }
}

fn team_requests(
    t: &TeamConfig<f64, CAPACITY>,
    failed: &[usize],
    rng: &mut ChaCha8Rng,
) -> Result<Vec<SetRequest>, StudyError> {
    let mask = failure_mask(t, failed)?;
    let m = t.effectiveness(&mask);
    let working: Vec<bool> = (0..t.len()).map(|i| !mask.is_failed(i)).collect();
    let attainable = |kind: &str, rng: &mut ChaCha8Rng| {
        let forces = draw_forces(t, &working, kind, rng);
        let mut full = [Vector3::zeros(); CAPACITY];
        for (slot, f) in full.iter_mut().zip(&forces) {
            *slot = Vector3::new(f[0], f[1], f[2]);
        }
        let u = m.wrench(&full);
        SetRequest {
            kind: kind.to_string(),
            wrench: [u[0], u[1], u[2], u[3], u[4], u[5]],
            forces: Some(forces),
            certificate: None,
            bound: None,
        }
    };
    let mut requests = Vec::new();
    for (kind, count) in ATTAINABLE {
        for _ in 0..count {
            requests.push(attainable(kind, rng));
        }
    }
    let n = working.iter().filter(|w| **w).count() as f64;
    let max_thrust = t.limits().max_thrust();
    let lever: f64 = t
        .working(&mask)
        .map(|(_, a)| a.position.norm())
        .sum::<f64>();
    let weight = t.mass() * tvmd_core::presets::GRAVITY;
    for certificate in [
        Certificate::ForceNorm,
        Certificate::TorqueNorm,
        Certificate::Downward,
    ] {
        for _ in 0..OUTSIDE_PER_CERTIFICATE {
            let mut u = attainable("mixed", rng).wrench;
            let scale = rng.random_range(1.05..2.0);
            let bound = match certificate {
                Certificate::ForceNorm => {
                    let b = n * max_thrust;
                    let f = Vector3::new(u[3], u[4], u[5]);
                    let f = f / f.norm() * (scale * b);
                    u[3..].copy_from_slice(f.as_slice());
                    b
                }
                Certificate::TorqueNorm => {
                    let b = max_thrust * lever;
                    let d = unit_vector(rng) * (scale * b);
                    u[..3].copy_from_slice(d.as_slice());
                    b
                }
                Certificate::Downward => {
                    u[5] = -(scale - 1.0) * weight;
                    0.0
                }
            };
            requests.push(SetRequest {
                kind: certificate_name(certificate).to_string(),
                wrench: u,
                forces: None,
                certificate: Some(certificate),
                bound: Some(bound),
            });
        }
    }
    Ok(requests)
}

/// The certificate's kebab-case name (as serialized).
pub(super) fn certificate_name(c: Certificate) -> &'static str {
    match c {
        Certificate::ForceNorm => "force-norm",
        Certificate::TorqueNorm => "torque-norm",
        Certificate::Downward => "downward",
    }
}

/// A direction drawn uniformly on the unit sphere (rejection from the cube).
fn unit_vector(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if (0.1..=1.0).contains(&n) {
            return v / n;
        }
    }
}

/// The agent-frame forces of one attainable request of `kind` (zero for failed agents).
fn draw_forces(
    t: &TeamConfig<f64, CAPACITY>,
    working: &[bool],
    kind: &str,
    rng: &mut ChaCha8Rng,
) -> Vec<[f64; 3]> {
    let limits = t.limits();
    let (sx, sy, hi, lo) = (
        limits.sigma_x(),
        limits.sigma_y(),
        limits.max_thrust(),
        limits.min_thrust(),
    );
    // Which agents a partial kind puts on a bound: each with probability 1/2, at least one.
    let count = working.len();
    let mut chosen: Vec<bool> = (0..count).map(|_| rng.random_bool(0.5)).collect();
    if !chosen.iter().zip(working).any(|(c, w)| *c && *w) {
        if let Some(first) = working.iter().position(|w| *w) {
            chosen[first] = true;
        }
    }
    let angle = |limit: f64, place: Place, rng: &mut ChaCha8Rng| match place {
        Place::Inside => rng.random_range(-0.9..0.9) * limit,
        Place::Bound => {
            if rng.random_bool(0.5) {
                limit
            } else {
                -limit
            }
        }
    };
    let mut forces = Vec::with_capacity(count);
    for i in 0..count {
        let on = chosen[i];
        // (eta_x, eta_y, thrust) places; the thrust bound is the upper one except where "mixed"
        // draws the idle thrust.
        let (px, py, pt) = match kind {
            "interior" => (Place::Inside, Place::Inside, Place::Inside),
            "thrust-bound" if on => (Place::Inside, Place::Inside, Place::Bound),
            "gimbal-bound" if on => {
                if rng.random_bool(0.5) {
                    (Place::Bound, Place::Inside, Place::Inside)
                } else {
                    (Place::Inside, Place::Bound, Place::Inside)
                }
            }
            "gimbal-corner" if on => (Place::Bound, Place::Bound, Place::Inside),
            "corner" => (Place::Bound, Place::Bound, Place::Bound),
            "mixed" => match rng.random_range(0..5) {
                0 => (Place::Inside, Place::Inside, Place::Inside),
                1 => (Place::Inside, Place::Inside, Place::Bound),
                2 => (Place::Bound, Place::Inside, Place::Inside),
                3 => (Place::Inside, Place::Bound, Place::Bound),
                _ => (Place::Bound, Place::Bound, Place::Bound),
            },
            _ => (Place::Inside, Place::Inside, Place::Inside),
        };
        let eta_x = angle(sx, px, rng);
        let eta_y = angle(sy, py, rng);
        let thrust = match pt {
            Place::Inside => lo + rng.random_range(0.1..0.9) * (hi - lo),
            Place::Bound if kind == "mixed" && rng.random_range(0..4) == 0 => lo,
            Place::Bound => hi,
        };
        let f = if working[i] {
            thrust_direction(eta_x, eta_y) * thrust
        } else {
            Vector3::zeros()
        };
        forces.push([f.x, f.y, f.z]);
    }
    forces
}
