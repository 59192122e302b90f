//! The team as one rapier rigid body, the ground, and the physics step.
//!
//! # Frames and origin
//! The rapier body's origin is the team centre of mass, frame {C}. Agent positions `p_i` are
//! given in {C}; [`TeamBody::validate`] rejects teams whose mass-weighted positions do not
//! average to the origin, because `J_C = J_0 - sum m_i [p_i]x [p_i]x` is the inertia about the
//! origin and the model puts the origin at the centre of mass.
//!
//! # Ground
//! The ground is a fixed cuboid whose top face lies at `z = -TeamBody::rest_height()`, so a
//! level team resting on the ground has its centre of mass at `z = 0`. This matches the
//! paper's `x_0 = [0.5, -0.5, 0]` "at rest on the ground" and its reference, which starts
//! and ends at `z = 0`. (The contact model is soft: at rest the colliders sink by well under a
//! millimetre; see the landing test.)

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::{
    ColliderBuilder, IntegrationParameters, MassProperties, RigidBodyBuilder, RigidBodyHandle,
    SharedShape,
};
use rapier3d_f64::{math as rm, pipeline::PhysicsWorld as RapierWorld};
use serde::{Deserialize, Serialize};

use crate::math::{quarter_turn, skew};
use crate::{SimError, GRAVITY};

/// One agent of the team, as the physics sees it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentBody {
    /// Position `p_i` of the agent's frame in the team frame {C} (m).
    pub position: [f64; 3],
    /// Agent mass `m_i` (kg), a point mass at `p_i`.
    pub mass: f64,
    /// Orientation `psi_i = m_i pi/2` as the integer number of quarter turns `m_i` about z.
    pub quarter_turns: i32,
}

impl AgentBody {
    /// The exact rotation `R_z(m_i pi/2)` from the agent frame to the team frame.
    pub fn rotation(&self) -> Matrix3<f64> {
        quarter_turn(self.quarter_turns)
    }

    /// `p_i` as a nalgebra vector.
    pub fn position_vector(&self) -> Vector3<f64> {
        Vector3::from(self.position)
    }
}

/// Mass model and collision geometry of a team.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TeamBody {
    /// The agents.
    pub agents: Vec<AgentBody>,
    /// Navigator mass `m_0` (kg) at the centre (may be zero).
    pub navigator_mass: f64,
    /// Navigator inertia `J_0` about the centre (kg m^2, row-major, symmetric).
    pub navigator_inertia: [[f64; 3]; 3],
    /// Radius of the agents' ball colliders (m).
    pub collider_radius: f64,
}

/// Default radius of the agents' ball colliders (m).
pub const DEFAULT_COLLIDER_RADIUS: f64 = 0.05;

impl TeamBody {
    /// Four agents of mass `mass` at `(+-a, +-a, 0)` with the given quarter turns.
    ///
    /// Agent order as in `tvmd_core::presets`:
    /// `(+a, +a), (+a, -a), (-a, -a), (-a, +a)`. Massless navigator, collider radius
    /// [`DEFAULT_COLLIDER_RADIUS`].
    pub fn a4(a: f64, mass: f64, quarter_turns: [i32; 4]) -> Self {
        let corners = [[a, a, 0.0], [a, -a, 0.0], [-a, -a, 0.0], [-a, a, 0.0]];
        Self {
            agents: corners
                .iter()
                .zip(quarter_turns)
                .map(|(p, m)| AgentBody {
                    position: *p,
                    mass,
                    quarter_turns: m,
                })
                .collect(),
            navigator_mass: 0.0,
            navigator_inertia: [[0.0; 3]; 3],
            collider_radius: DEFAULT_COLLIDER_RADIUS,
        }
    }

    /// `n` agents of mass `mass` evenly on a circle of `radius` in the `x-y` plane, agent `i`
    /// at angle `2 pi i / n`; every second agent turned a quarter turn when `inconsistent`
    /// (the layout of `tvmd_core::team::presets::ring`). Massless navigator.
    pub fn ring(n: usize, radius: f64, mass: f64, inconsistent: bool) -> Self {
        Self {
            agents: (0..n)
                .map(|i| {
                    let phase = std::f64::consts::TAU * i as f64 / n as f64;
                    AgentBody {
                        position: [radius * phase.cos(), radius * phase.sin(), 0.0],
                        mass,
                        quarter_turns: if inconsistent { (i % 2) as i32 } else { 0 },
                    }
                })
                .collect(),
            navigator_mass: 0.0,
            navigator_inertia: [[0.0; 3]; 3],
            collider_radius: DEFAULT_COLLIDER_RADIUS,
        }
    }

    /// A catalogue team (`tvmd_core::team::presets::Preset`) on a grid of `unit` metres with
    /// agents of `mass` kg, in the preset's agent order. Massless navigator, collider radius
    /// [`DEFAULT_COLLIDER_RADIUS`]. Errors when the core rejects the layout at that scale.
    pub fn preset(
        preset: tvmd_core::team::presets::Preset,
        unit: f64,
        mass: f64,
    ) -> Result<Self, tvmd_core::ConfigError> {
        let team: tvmd_core::TeamConfig<f64, 16> = preset.team_with(unit, mass)?;
        Ok(Self {
            agents: team
                .agents()
                .iter()
                .map(|a| AgentBody {
                    position: a.position.into(),
                    mass: a.mass,
                    quarter_turns: a.quarter_turns,
                })
                .collect(),
            navigator_mass: 0.0,
            navigator_inertia: [[0.0; 3]; 3],
            collider_radius: DEFAULT_COLLIDER_RADIUS,
        })
    }

    /// Half side of the paper's A4 square: `a = 0.5 sqrt(2)/2` m.
    pub fn paper_arm() -> f64 {
        0.5 * std::f64::consts::SQRT_2 / 2.0
    }

    /// The paper's A4-Inc team: `psi = [pi/2, pi/2, 0, 0]`, `m_i = 0.7` kg, massless navigator.
    pub fn a4_inc() -> Self {
        Self::a4(Self::paper_arm(), 0.7, [1, 1, 0, 0])
    }

    /// The consistent variant A4-Con: all `psi_i = 0`, otherwise as [`TeamBody::a4_inc`].
    pub fn a4_con() -> Self {
        Self::a4(Self::paper_arm(), 0.7, [0, 0, 0, 0])
    }

    /// Number of agents.
    pub fn len(&self) -> usize {
        self.agents.len()
    }

    /// True if the team has no agent.
    pub fn is_empty(&self) -> bool {
        self.agents.is_empty()
    }

    /// Team mass `m_C = m_0 + sum m_i`.
    pub fn mass(&self) -> f64 {
        self.navigator_mass + self.agents.iter().map(|a| a.mass).sum::<f64>()
    }

    /// Team inertia about the origin, `J_C = J_0 - sum m_i [p_i]x [p_i]x` (point-mass agents).
    pub fn inertia(&self) -> Matrix3<f64> {
        let mut j = crate::math::from_rows(&self.navigator_inertia);
        for a in &self.agents {
            let s = skew(&a.position_vector());
            j -= a.mass * s * s;
        }
        j
    }

    /// Height of the centre of mass above the ground when the team rests level on it:
    /// `collider_radius - min(0, min_i p_i.z)`.
    pub fn rest_height(&self) -> f64 {
        let lowest = self
            .agents
            .iter()
            .map(|a| a.position[2])
            .fold(0.0_f64, f64::min);
        self.collider_radius - lowest
    }

    /// Checks that the team is physically usable.
    ///
    /// Requires at least one agent, finite positive masses, a non-negative navigator mass, a
    /// symmetric positive-semidefinite navigator inertia, a positive collider radius, and the
    /// centre of mass at the origin (`|sum m_i p_i| / m_C <= 1e-9 (1 + max |p_i|)`).
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |m: String| Err(SimError::InvalidTeam(m));
        if self.agents.is_empty() {
            return bad("the team has no agent".into());
        }
        for (i, a) in self.agents.iter().enumerate() {
            if !(a.mass.is_finite() && a.mass > 0.0) {
                return bad(format!(
                    "agent {i}: mass must be finite and > 0, got {}",
                    a.mass
                ));
            }
            if a.position.iter().any(|c| !c.is_finite()) {
                return bad(format!("agent {i}: position is not finite"));
            }
        }
        if !(self.navigator_mass.is_finite() && self.navigator_mass >= 0.0) {
            return bad(format!(
                "navigator mass must be finite and >= 0, got {}",
                self.navigator_mass
            ));
        }
        let j0 = crate::math::from_rows(&self.navigator_inertia);
        if j0.iter().any(|c| !c.is_finite()) || (j0 - j0.transpose()).abs().max() > 1e-12 {
            return bad("navigator inertia must be finite and symmetric".into());
        }
        if j0.symmetric_eigenvalues().min() < -1e-12 {
            return bad("navigator inertia must be positive semidefinite".into());
        }
        if !(self.collider_radius.is_finite() && self.collider_radius > 0.0) {
            return bad(format!(
                "collider radius must be finite and > 0, got {}",
                self.collider_radius
            ));
        }
        let first_moment: Vector3<f64> = self
            .agents
            .iter()
            .map(|a| a.mass * a.position_vector())
            .sum();
        let scale = 1.0
            + self
                .agents
                .iter()
                .map(|a| a.position_vector().norm())
                .fold(0.0, f64::max);
        let com = first_moment / self.mass();
        if com.norm() > 1e-9 * scale {
            return bad(format!(
                "the centre of mass is at [{:.3e}, {:.3e}, {:.3e}], not at the origin: agent \
                 positions must be given relative to the team centre of mass",
                com.x, com.y, com.z
            ));
        }
        Ok(())
    }
}

/// Rigid-body state of the team: position and velocity of the centre of mass and attitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantState {
    /// Position `x` of the centre of mass in the world frame (m).
    pub position: Vector3<f64>,
    /// Attitude `R` (body to world).
    pub rotation: Matrix3<f64>,
    /// Velocity `x_dot` of the centre of mass in the world frame (m/s).
    pub velocity: Vector3<f64>,
    /// Body-frame angular velocity `Omega` (rad/s).
    pub omega: Vector3<f64>,
}

impl PlantState {
    /// At rest at `position` with identity attitude.
    pub fn at_rest(position: Vector3<f64>) -> Self {
        Self {
            position,
            rotation: Matrix3::identity(),
            velocity: Vector3::zeros(),
            omega: Vector3::zeros(),
        }
    }

    /// Body-frame linear velocity `v = R^T x_dot` (the twist's translational part).
    pub fn velocity_body(&self) -> Vector3<f64> {
        self.rotation.transpose() * self.velocity
    }

    /// True if every component is finite.
    pub fn is_finite(&self) -> bool {
        self.position.iter().all(|c| c.is_finite())
            && self.rotation.iter().all(|c| c.is_finite())
            && self.velocity.iter().all(|c| c.is_finite())
            && self.omega.iter().all(|c| c.is_finite())
    }
}

/// Physics settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhysicsConfig {
    /// Physics step (s); default 1 ms.
    pub dt: f64,
    /// Gravity magnitude (m/s^2) along `-z`; default 9.81.
    pub gravity: f64,
    /// Whether the ground exists; default true.
    pub ground: bool,
    /// Friction coefficient of the colliders (ground and team); default 1.0.
    pub friction: f64,
    /// Number of rapier solver iterations (substeps) per step; default 1. More substeps
    /// make the free flight's symplectic-Euler integration finer (its position error is
    /// about `dt / (2 n)` times the velocity change) but re-solve every ground contact each
    /// time: 4 cost `paper-tilt` about 50% more instructions than 1, for reproduction metrics
    /// that differ by at most 3.4e-5 m (BENCHMARKS.md). The number is the same in the air and
    /// on the ground: switching it near the ground made flights differ at touchdown by far
    /// more than that.
    pub solver_iterations: usize,
}

impl Default for PhysicsConfig {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            gravity: GRAVITY,
            ground: true,
            friction: 1.0,
            solver_iterations: 1,
        }
    }
}

/// A wrench applied on top of the agents' thrusts during one physics step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExtraWrench {
    /// Force through the centre of mass, in the world frame (N), e.g. wind.
    pub force_world: Vector3<f64>,
    /// Torque in the world frame (N m).
    pub torque_world: Vector3<f64>,
    /// Force through the centre of mass, in the body frame (N).
    pub force_body: Vector3<f64>,
    /// Torque in the body frame (N m).
    pub torque_body: Vector3<f64>,
}

/// How the flown body's mass differs from its team description (the mass part of a model
/// error): mass and inertia scales and the centre of mass's offset from the body origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassError {
    /// Mass over the team's `m_C`.
    pub mass_scale: f64,
    /// Inertia about the centre of mass over the team's `J`.
    pub inertia_scale: f64,
    /// Centre of mass in the body frame (m), against the team's (the body origin).
    pub com_offset: Vector3<f64>,
}

impl Default for MassError {
    fn default() -> Self {
        Self {
            mass_scale: 1.0,
            inertia_scale: 1.0,
            com_offset: Vector3::zeros(),
        }
    }
}

impl MassError {
    fn is_nominal(&self) -> bool {
        *self == Self::default()
    }
}

/// The rapier world holding the team body and the ground.
pub struct PhysicsWorld {
    world: RapierWorld,
    body: RigidBodyHandle,
    team: TeamBody,
    config: PhysicsConfig,
    time: f64,
    /// Mass rapier adds to the collider's: the navigator (nominal mass) and the payloads.
    additional: Vec<MassProperties>,
    /// The centre of mass in the body frame: where rapier's velocity and torque refer to. Zero
    /// for a nominal team (the body origin is the team's centre of mass by construction).
    com: Vector3<f64>,
}

fn to_rapier(v: &Vector3<f64>) -> rm::Vector {
    rm::Vector::new(v.x, v.y, v.z)
}

fn from_rapier(v: rm::Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

fn quat_to_rapier(r: &Matrix3<f64>) -> rm::Rotation {
    let q = UnitQuaternion::from_matrix(r);
    rm::Rotation::from_xyzw(q.i, q.j, q.k, q.w)
}

fn quat_from_rapier(q: &rm::Rotation) -> Matrix3<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q.w, q.x, q.y, q.z))
        .to_rotation_matrix()
        .into_inner()
}

fn mat_from_rapier(m: &rm::Matrix) -> Matrix3<f64> {
    // glam matrices are column-major: x_axis is the first column.
    Matrix3::from_columns(&[
        from_rapier(m.x_axis),
        from_rapier(m.y_axis),
        from_rapier(m.z_axis),
    ])
}

fn mat_to_rapier(m: &Matrix3<f64>) -> rm::Matrix {
    let c = |j: usize| to_rapier(&m.column(j).into_owned());
    rm::Matrix::from_cols(c(0), c(1), c(2))
}

impl PhysicsWorld {
    /// Builds the world: one dynamic body whose one collider is a compound of a ball per agent
    /// at `p_i`, carrying the point masses `m_i` at `p_i` and the navigator's `m_0`, `J_0` at the
    /// centre, plus the ground if enabled, and puts the body in `initial`.
    pub fn new(
        team: &TeamBody,
        config: &PhysicsConfig,
        initial: &PlantState,
    ) -> Result<Self, SimError> {
        Self::with_mass_error(team, config, initial, &MassError::default())
    }

    /// As [`PhysicsWorld::new`], flying a body whose mass, inertia and centre of mass differ
    /// from `team`'s by `error`; the body origin (the position [`PhysicsWorld::state`] reports
    /// and `p_i` refer to) stays the team's centre of mass.
    pub fn with_mass_error(
        team: &TeamBody,
        config: &PhysicsConfig,
        initial: &PlantState,
        error: &MassError,
    ) -> Result<Self, SimError> {
        team.validate()?;
        if !(config.dt.is_finite() && config.dt > 0.0) {
            return Err(SimError::InvalidScenario {
                field: "physics.dt".into(),
                reason: format!("must be finite and > 0, got {}", config.dt),
            });
        }
        if !initial.is_finite() {
            return Err(SimError::InvalidScenario {
                field: "initial state".into(),
                reason: "not finite".into(),
            });
        }
        let mut world = RapierWorld::new();
        // Rapier's performance counters are on by default and read the clock dozens of times
        // per step (0.9 us of a 5 us bare step in a ci-profile probe on a VM); nothing reads them.
        world.physics_pipeline.counters.disable();
        world.gravity = rm::Vector::new(0.0, 0.0, -config.gravity);
        world.integration_parameters = IntegrationParameters {
            dt: config.dt,
            num_solver_iterations: config.solver_iterations.max(1),
            ..IntegrationParameters::default()
        };

        let body = RigidBodyBuilder::dynamic()
            .can_sleep(false)
            .allow_fast_rotation(true)
            .gyroscopic_forces_enabled(true)
            .build();
        let body = world.bodies.insert(body);

        // One compound collider rather than a ball collider per agent: resting on the ground,
        // its contact manifolds are one collider pair that rapier clusters into one constraint
        // (one twist-friction row), where separate balls are one pair and one constraint each.
        // A probe of a four-ball team at rest: 21 -> 12 us per step (ci profile, 2-core VM);
        // in the air the two cost the same.
        let r = team.collider_radius;
        let balls = team
            .agents
            .iter()
            .map(|a| {
                let at = rm::Pose::from_translation(to_rapier(&a.position_vector()));
                (at, SharedShape::ball(r))
            })
            .collect();
        let point_masses: MassProperties = team
            .agents
            .iter()
            .map(|a| MassProperties::new(to_rapier(&a.position_vector()), a.mass, rm::Vector::ZERO))
            .sum();
        // The navigator has mass but no collider: the centre of mass (the origin) is a convex
        // combination of the agent positions, so a ball there can never be lower than the
        // lowest agent ball and never touch a flat ground first. A collider there would only
        // add a contact pair to every step near the ground.
        let j0 = crate::math::from_rows(&team.navigator_inertia);
        let navigator = (team.navigator_mass > 0.0 || j0.abs().max() > 0.0).then(|| {
            MassProperties::with_inertia_matrix(
                rm::Vector::ZERO,
                team.navigator_mass,
                mat_to_rapier(&j0),
            )
        });
        let (collider_mass, additional) = if error.is_nominal() {
            (point_masses, navigator.into_iter().collect())
        } else {
            // The whole nominal body, scaled about its centre of mass and moved.
            let nominal = navigator.map_or(point_masses, |n| point_masses + n);
            let inertia = nominal.reconstruct_inertia_matrix() * error.inertia_scale;
            let plant = MassProperties::with_inertia_matrix(
                nominal.local_com + to_rapier(&error.com_offset),
                nominal.mass() * error.mass_scale,
                inertia,
            );
            (plant, Vec::new())
        };
        let c = ColliderBuilder::compound(balls)
            .mass_properties(collider_mass)
            .friction(config.friction)
            .restitution(0.0);
        world.insert_collider(c, Some(body));
        if !additional.is_empty() {
            let sum: MassProperties = additional.iter().copied().sum();
            world.bodies[body].set_additional_mass_properties(sum, false);
        }
        world.bodies[body].recompute_mass_properties_from_colliders(&world.colliders);
        let com = if error.is_nominal() {
            Vector3::zeros()
        } else {
            from_rapier(world.bodies[body].local_center_of_mass())
        };

        if config.ground {
            // A cuboid, not a halfspace: a halfspace's infinite bounding box keeps every ball
            // in the narrow phase all flight long; the cuboid's pairs exist only near it.
            let half = 0.5;
            let ground = ColliderBuilder::cuboid(1000.0, 1000.0, half)
                .translation(rm::Vector::new(0.0, 0.0, -team.rest_height() - half))
                .friction(config.friction)
                .restitution(0.0);
            world.insert_collider(ground, None);
        }

        let mut out = Self {
            world,
            body,
            team: team.clone(),
            config: config.clone(),
            time: 0.0,
            additional,
            com,
        };
        out.set_state(initial);
        Ok(out)
    }

    /// Attaches a point mass `mass` (kg) at `offset` (body frame, m), moving with the body: the
    /// body origin keeps its velocity and the centre of mass moves towards the payload.
    pub fn attach_payload(&mut self, mass: f64, offset: &Vector3<f64>) -> Result<(), SimError> {
        if !(mass.is_finite() && mass > 0.0 && offset.iter().all(|c| c.is_finite())) {
            return Err(SimError::InvalidScenario {
                field: "payloads".into(),
                reason: format!("mass {mass} kg at {offset:?} m: must be finite and > 0"),
            });
        }
        let before = self.state();
        self.additional.push(MassProperties::new(
            to_rapier(offset),
            mass,
            rm::Vector::ZERO,
        ));
        let sum: MassProperties = self.additional.iter().copied().sum();
        let rb = &mut self.world.bodies[self.body];
        rb.set_additional_mass_properties(sum, true);
        rb.recompute_mass_properties_from_colliders(&self.world.colliders);
        self.com = from_rapier(rb.local_center_of_mass());
        self.set_state(&before);
        Ok(())
    }

    /// The team description this world was built from.
    pub fn team(&self) -> &TeamBody {
        &self.team
    }

    /// The physics settings.
    pub fn config(&self) -> &PhysicsConfig {
        &self.config
    }

    /// Simulated time (s): number of steps taken times `dt`.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Height of the ground's top face (m), `-team.rest_height()`.
    pub fn ground_height(&self) -> f64 {
        -self.team.rest_height()
    }

    /// The body's mass as rapier computed it from the colliders.
    pub fn mass(&self) -> f64 {
        self.world.bodies[self.body].mass()
    }

    /// The body's inertia about its centre of mass, in the body frame, as rapier computed it.
    pub fn inertia(&self) -> Matrix3<f64> {
        let mp = &self.world.bodies[self.body].mass_properties().local_mprops;
        mat_from_rapier(&mp.reconstruct_inertia_matrix())
    }

    /// The body's centre of mass in the body frame, as rapier computed it: ~0 for a
    /// nominal team, moved by a model error or a payload.
    pub fn local_center_of_mass(&self) -> Vector3<f64> {
        from_rapier(self.world.bodies[self.body].local_center_of_mass())
    }

    /// Current state of the team body: the body origin (the team's centre of mass in the
    /// controller's model) and its velocity.
    pub fn state(&self) -> PlantState {
        let rb = &self.world.bodies[self.body];
        let rotation = quat_from_rapier(rb.rotation());
        let omega_world = from_rapier(rb.angvel());
        // rapier's linear velocity is the centre of mass's.
        let mut velocity = from_rapier(rb.linvel());
        if self.com != Vector3::zeros() {
            velocity -= omega_world.cross(&(rotation * self.com));
        }
        PlantState {
            position: from_rapier(rb.translation()),
            rotation,
            velocity,
            omega: rotation.transpose() * omega_world,
        }
    }

    /// Overwrites the body's state (teleport); contacts are re-detected at the next step.
    pub fn set_state(&mut self, state: &PlantState) {
        let omega_world = state.rotation * state.omega;
        let mut velocity = state.velocity;
        if self.com != Vector3::zeros() {
            velocity += omega_world.cross(&(state.rotation * self.com));
        }
        let rb = &mut self.world.bodies[self.body];
        rb.set_position(
            rm::Pose::from_parts(to_rapier(&state.position), quat_to_rapier(&state.rotation)),
            true,
        );
        rb.set_linvel(to_rapier(&velocity), true);
        rb.set_angvel(to_rapier(&omega_world), true);
    }

    /// Advances the world by one step `dt`.
    ///
    /// `agent_forces_body[i]` is agent `i`'s thrust force in the BODY frame (N), applied at
    /// the agent's position `p_i`; it is held constant during the step (as is `extra`).
    /// Gravity and ground contact are added by rapier.
    pub fn step(
        &mut self,
        agent_forces_body: &[Vector3<f64>],
        extra: &ExtraWrench,
    ) -> Result<(), SimError> {
        if agent_forces_body.len() != self.team.len() {
            return Err(SimError::InvalidCommand {
                t: self.time,
                reason: format!(
                    "{} agent forces for {} agents",
                    agent_forces_body.len(),
                    self.team.len()
                ),
            });
        }
        if agent_forces_body
            .iter()
            .any(|f| f.iter().any(|c| !c.is_finite()))
        {
            return Err(SimError::InvalidCommand {
                t: self.time,
                reason: "non-finite agent force".into(),
            });
        }
        // Body-frame forces turn with the body during the step; converting them with the
        // attitude predicted at mid-step, `R exp([Omega]x dt/2)`, instead of the attitude at
        // the step start removes the O(dt) lag of their direction.
        let s = self.state();
        let rotation =
            s.rotation * nalgebra::Rotation3::new(s.omega * (0.5 * self.config.dt)).into_inner();
        // Body-frame wrench about the centre of mass (the body origin).
        let mut force_body = extra.force_body;
        let mut torque_body = extra.torque_body;
        for (a, f) in self.team.agents.iter().zip(agent_forces_body) {
            force_body += f;
            torque_body += (a.position_vector() - self.com).cross(f);
        }
        let force = rotation * force_body + extra.force_world;
        let torque = rotation * torque_body + extra.torque_world;

        let rb = &mut self.world.bodies[self.body];
        rb.reset_forces(true);
        rb.reset_torques(true);
        rb.add_force(to_rapier(&force), true);
        rb.add_torque(to_rapier(&torque), true);
        self.world.step();
        self.time += self.config.dt;

        let rb = &self.world.bodies[self.body];
        let finite = [rb.translation(), rb.linvel(), rb.angvel()]
            .iter()
            .all(|v| v.is_finite())
            && rb.rotation().is_finite();
        if !finite {
            return Err(SimError::Diverged {
                t: self.time,
                what: "rigid-body state".into(),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel_err(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
        (a - b).abs().max() / b.abs().max()
    }

    #[test]
    fn rapier_mass_and_inertia_match_the_model() {
        let mut teams = vec![TeamBody::a4_inc(), TeamBody::a4_con()];
        // An irregular, non-planar team with a heavy navigator whose CoM is at the origin.
        let mut t = TeamBody {
            agents: vec![
                AgentBody {
                    position: [0.4, 0.1, 0.05],
                    mass: 0.7,
                    quarter_turns: 1,
                },
                AgentBody {
                    position: [-0.2, 0.3, -0.05],
                    mass: 0.7,
                    quarter_turns: 2,
                },
                AgentBody {
                    position: [-0.2, -0.4, 0.0],
                    mass: 0.7,
                    quarter_turns: 3,
                },
            ],
            navigator_mass: 0.3,
            navigator_inertia: [[0.01, 0.001, 0.0], [0.001, 0.02, 0.0], [0.0, 0.0, 0.03]],
            collider_radius: 0.04,
        };
        t.validate().unwrap();
        teams.push(t.clone());
        t.navigator_mass = 0.0;
        t.navigator_inertia = [[0.0; 3]; 3];
        teams.push(t);
        for team in teams {
            let w = PhysicsWorld::new(
                &team,
                &PhysicsConfig::default(),
                &PlantState::at_rest(Vector3::new(0.0, 0.0, 1.0)),
            )
            .unwrap();
            let dm = (w.mass() - team.mass()).abs() / team.mass();
            let dj = rel_err(&w.inertia(), &team.inertia());
            eprintln!("mass rel err {dm:.1e}, inertia rel err {dj:.1e}");
            assert!(dm < 1e-12, "mass {} vs {}", w.mass(), team.mass());
            assert!(
                dj < 1e-9,
                "inertia rel err {dj:e}:\n{}\n{}",
                w.inertia(),
                team.inertia()
            );
            assert!(w.local_center_of_mass().norm() < 1e-12);
        }
    }

    /// A model error and a payload move the centre of mass off the body origin: the mass
    /// properties follow, and the reported velocity stays the origin's (the finite difference
    /// of the reported position).
    #[test]
    fn mass_errors_and_payloads_keep_the_origin_state() {
        let team = TeamBody::a4_inc();
        let config = PhysicsConfig {
            gravity: 0.0,
            ground: false,
            ..PhysicsConfig::default()
        };
        let error = MassError {
            mass_scale: 1.1,
            inertia_scale: 1.5,
            com_offset: Vector3::new(0.05, -0.02, 0.01),
        };
        let initial = PlantState {
            omega: Vector3::new(0.3, -0.2, 0.5),
            velocity: Vector3::new(0.1, 0.0, 0.0),
            ..PlantState::at_rest(Vector3::new(0.0, 0.0, 1.0))
        };
        let mut w = PhysicsWorld::with_mass_error(&team, &config, &initial, &error).unwrap();
        assert!((w.mass() - 1.1 * team.mass()).abs() < 1e-12);
        assert!((w.local_center_of_mass() - error.com_offset).norm() < 1e-12);
        let j = w.inertia();
        assert!((j - team.inertia() * 1.5).abs().max() < 1e-12, "{j}");
        let s0 = w.state();
        assert!((s0.velocity - initial.velocity).norm() < 1e-12);
        assert!((s0.omega - initial.omega).norm() < 1e-12);
        w.attach_payload(0.3, &Vector3::new(0.2, 0.0, 0.0)).unwrap();
        assert!((w.mass() - (1.1 * team.mass() + 0.3)).abs() < 1e-12);
        let s1 = w.state();
        assert!((s1.velocity - s0.velocity).norm() < 1e-12);
        let com_velocity = |w: &PhysicsWorld, s: &PlantState| {
            s.velocity + (s.rotation * s.omega).cross(&(s.rotation * w.local_center_of_mass()))
        };
        let v0 = com_velocity(&w, &s1);
        let forces = vec![Vector3::zeros(); team.len()];
        let extra = ExtraWrench::default();
        for _ in 0..50 {
            let a = w.state();
            w.step(&forces, &extra).unwrap();
            let b = w.state();
            let fd = (b.position - a.position) / config.dt;
            let mid = 0.5 * (a.velocity + b.velocity);
            assert!((fd - mid).norm() < 1e-4, "{fd} vs {mid}");
        }
        // Free of forces, the centre of mass moves in a straight line at constant speed.
        let v = com_velocity(&w, &w.state());
        assert!((v - v0).norm() < 1e-9, "{v} vs {v0}");
    }

    #[test]
    fn off_centre_team_is_rejected() {
        let mut t = TeamBody::a4_inc();
        t.agents[0].position[0] += 0.01;
        assert!(matches!(t.validate(), Err(SimError::InvalidTeam(_))));
    }

    #[test]
    fn paper_team_numbers() {
        let t = TeamBody::a4_inc();
        assert!((t.mass() - 2.8).abs() < 1e-12);
        let a2 = TeamBody::paper_arm().powi(2);
        let j = t.inertia();
        assert!((j[(0, 0)] - 4.0 * 0.7 * a2).abs() < 1e-12);
        assert!((j[(2, 2)] - 8.0 * 0.7 * a2).abs() < 1e-12);
        assert!((t.rest_height() - DEFAULT_COLLIDER_RADIUS).abs() < 1e-15);
    }
}
