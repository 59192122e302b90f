//! The rapier world holding the team body and the ground, and its step.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::{
    ColliderBuilder, IntegrationParameters, MassProperties, RigidBodyBuilder, RigidBodyHandle,
    SharedShape,
};
use rapier3d_f64::{math as rm, pipeline::PhysicsWorld as RapierWorld};

use super::{ExtraWrench, MassError, PhysicsConfig, PlantState, TeamBody};
use crate::PhysicsError;

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
    ) -> Result<Self, PhysicsError> {
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
    ) -> Result<Self, PhysicsError> {
        team.validate()?;
        if !(config.dt.is_finite() && config.dt > 0.0) {
            return Err(PhysicsError::InvalidScenario {
                field: "physics.dt".into(),
                reason: format!("must be finite and > 0, got {}", config.dt),
            });
        }
        if !initial.is_finite() {
            return Err(PhysicsError::InvalidScenario {
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
    pub fn attach_payload(&mut self, mass: f64, offset: &Vector3<f64>) -> Result<(), PhysicsError> {
        if !(mass.is_finite() && mass > 0.0 && offset.iter().all(|c| c.is_finite())) {
            return Err(PhysicsError::InvalidScenario {
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
    ) -> Result<(), PhysicsError> {
        if agent_forces_body.len() != self.team.len() {
            return Err(PhysicsError::InvalidCommand {
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
            return Err(PhysicsError::InvalidCommand {
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
            return Err(PhysicsError::Diverged {
                t: self.time,
                what: "rigid-body state".into(),
            });
        }
        Ok(())
    }
}
