//! Semantic checks of a scenario ([`Scenario::validate`]): values that parse but make no sense,
//! each error naming the field by its dotted path.

use std::f64::consts::PI;

use crate::controller::ALLOCATOR_NAMES;
use crate::Scenario;
use crate::ScenarioError;
use tvmd_plant::reference::ReferenceConfig;

use crate::checks::*;
use crate::error::invalid;

impl Scenario {
    /// Checks values that parse but make no sense; errors name the field.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        check_pos("duration", self.duration)?;
        check_range("duration", self.duration, 0.0, MAX_DURATION)?;
        check_range("physics.dt", self.physics.dt, PHYSICS_DT[0], PHYSICS_DT[1])?;
        check_range(
            "controller_period",
            self.controller_period,
            self.physics.dt,
            MAX_CONTROLLER_PERIOD,
        )?;
        self.steps_per_control()?;
        if self.duration < self.controller_period {
            return Err(invalid(
                "duration",
                format!(
                    "{} s is shorter than one controller period ({} s): the run would record \
                     no sample",
                    self.duration, self.controller_period
                ),
            ));
        }
        let steps = self.duration / self.physics.dt;
        if steps > MAX_PHYSICS_STEPS {
            return Err(invalid(
                "duration",
                format!(
                    "{steps:.3e} physics steps exceed {MAX_PHYSICS_STEPS:e}; shorten the run or \
                     lengthen physics.dt"
                ),
            ));
        }
        let [lo, hi] = SOLVER_ITERATIONS;
        let iterations = self.physics.solver_iterations;
        if !(lo..=hi).contains(&iterations) {
            return Err(invalid(
                "physics.solver_iterations",
                format!("must be in [{lo}, {hi}], got {iterations}"),
            ));
        }
        check_range("physics.gravity", self.physics.gravity, 0.0, 100.0)?;
        let decimation = self.log.decimation;
        if !(1..=1_000_000).contains(&decimation) {
            return Err(invalid(
                "log.decimation",
                format!("must be in [1, 1000000] controller ticks, got {decimation}"),
            ));
        }
        check_range("log.scene_period", self.log.scene_period, 1e-6, 1e6)?;
        let success = &self.success;
        check_range(
            "success.steady_state_window",
            success.steady_state_window,
            self.controller_period,
            1e6,
        )?;
        for (field, bound) in [
            (
                "success.max_steady_state_position_error",
                success.max_steady_state_position_error,
            ),
            (
                "success.max_steady_state_attitude_error",
                success.max_steady_state_attitude_error,
            ),
            ("success.max_position_error", success.max_position_error),
            (
                "success.max_settling_time",
                success.max_settling_time.unwrap_or(0.0),
            ),
        ] {
            check_nonneg(field, &[bound])?;
        }
        check_nonneg("physics.friction", &[self.physics.friction])?;
        check_magnitude("initial_position", &self.initial_position, MAX_DISTANCE)?;
        if self.initial_position[2] < 0.0 {
            return Err(invalid(
                "initial_position",
                format!(
                    "z = {} m is below the ground (z = 0 rests the team on it)",
                    self.initial_position[2]
                ),
            ));
        }
        check_range("team.agent_mass", self.team.agent_mass, 1e-3, 1e3)?;
        check_range("team.navigator_mass", self.team.navigator_mass, 0.0, 1e4)?;
        if let Some(arm) = self.team.arm {
            check_range("team.arm", arm, 1e-3, 100.0)?;
        }
        check_pos(
            "failure_response.landing_acceleration",
            self.failure_response.landing_acceleration,
        )?;
        if !(self.relaxation > 0.0 && self.relaxation <= 1.0) {
            return Err(invalid(
                "relaxation",
                format!("must be in (0, 1], got {}", self.relaxation),
            ));
        }
        for (f, v) in [
            ("limits.sigma_x", self.limits.sigma_x),
            ("limits.sigma_y", self.limits.sigma_y),
        ] {
            if !(v > 0.0 && v <= PI) {
                return Err(invalid(f, format!("must be in (0, pi], got {v}")));
            }
        }
        if let Some(t) = self.limits.max_thrust {
            check_pos("limits.max_thrust", t)?;
        }
        if !ALLOCATOR_NAMES.contains(&self.allocator.as_str())
            && self.allocator != tvmd_core::allocation::CLARABEL
        {
            return Err(invalid(
                "allocator",
                format!(
                    "unknown allocator `{}` (known: {})",
                    self.allocator,
                    ALLOCATOR_NAMES.join(", ")
                ),
            ));
        }
        if self.allocator_max_rounds.is_some() {
            // The core's rule of which allocator takes the option (the name is checked above).
            let options = tvmd_core::AllocatorOptions::<f64, 1> {
                max_rounds: self.allocator_max_rounds,
                ..Default::default()
            };
            match tvmd_core::allocation::AllocatorChoice::new(&self.allocator, &options) {
                Err(tvmd_core::ConfigError::UnusedOption { .. }) => {
                    return Err(invalid(
                        "allocator_max_rounds",
                        format!(
                            "allocator `{}` takes no round cap (only `{}` and `{}` do)",
                            self.allocator,
                            tvmd_core::allocation::EXACT_BOUNDARY_REDISTRIBUTION,
                            tvmd_core::allocation::CAPPED_REDISTRIBUTION
                        ),
                    ));
                }
                Err(e) if e.field() == Some(tvmd_core::ConfigField::AllocatorMaxRounds) => {
                    return Err(invalid(
                        "allocator_max_rounds",
                        format!("{e} (`{}` needs at least 1)", self.allocator),
                    ));
                }
                _ => {}
            }
        }
        if let Some([x, y]) = self.controller_rate_limits {
            check_pos("controller_rate_limits[0]", x)?;
            check_pos("controller_rate_limits[1]", y)?;
        }
        if let Some(n) = &self.null_space {
            n.validate()?;
        }
        check_nonneg("gains.k_x", &self.gains.k_x)?;
        check_nonneg("gains.k_r", &self.gains.k_r)?;
        check_nonneg("gains.k_xi", &self.gains.k_xi)?;
        let team = self.team_body()?;
        match &self.reference {
            ReferenceConfig::PaperTilt(p) => {
                check_magnitude("reference.ascent_height", &[p.ascent_height], MAX_DISTANCE)?;
                check_magnitude("reference.roll_peak", &[p.roll_peak], PI)?;
                for (f, w) in [
                    ("reference.ascent", p.ascent),
                    ("reference.tilt", p.tilt),
                    ("reference.descent", p.descent),
                ] {
                    check_magnitude(f, &w, MAX_DURATION)?;
                    if w[1] <= w[0] {
                        return Err(invalid(
                            f,
                            format!("the window [{}, {}] s must end after it starts", w[0], w[1]),
                        ));
                    }
                }
            }
            ReferenceConfig::Hover { position, roll } => {
                check_magnitude("reference.position", position, MAX_DISTANCE)?;
                check_magnitude("reference.roll", &[*roll], PI)?;
            }
            ReferenceConfig::Step(s) => {
                check_magnitude("reference.initial", &s.initial, MAX_DISTANCE)?;
                check_magnitude("reference.target", &s.target, MAX_DISTANCE)?;
                check_magnitude("reference.time", &[s.time], MAX_DURATION)?;
            }
            ReferenceConfig::Sine(s) => {
                check_magnitude("reference.center", &s.center, MAX_DISTANCE)?;
                check_magnitude("reference.amplitude", &s.amplitude, MAX_DISTANCE)?;
                check_range("reference.frequency", s.frequency, 0.0, 100.0)?;
                check_magnitude("reference.start", &[s.start], MAX_DURATION)?;
                check_range("reference.ramp", s.ramp, 1e-3, MAX_DURATION)?;
            }
            ReferenceConfig::FigureEight(f) => {
                check_magnitude("reference.center", &f.center, MAX_DISTANCE)?;
                check_range("reference.size", f.size, 0.0, MAX_DISTANCE)?;
                check_range("reference.period", f.period, 0.01, MAX_DURATION)?;
                check_magnitude("reference.start", &[f.start], MAX_DURATION)?;
                check_range("reference.ramp", f.ramp, 1e-3, MAX_DURATION)?;
            }
        }
        if let Some(s) = &self.actuators.servo {
            check_pos("actuators.servo.natural_frequency", s.natural_frequency)?;
            // The servo is integrated at the physics step (semi-implicit Euler): stable while
            // w_n dt stays well below 2.
            if s.natural_frequency * self.physics.dt > 1.0 {
                return Err(invalid(
                    "actuators.servo.natural_frequency",
                    format!(
                        "{} rad/s is too fast for physics.dt = {} s: must be at most 1/dt = {} \
                         rad/s",
                        s.natural_frequency,
                        self.physics.dt,
                        1.0 / self.physics.dt
                    ),
                ));
            }
            check_nonneg("actuators.servo.damping_ratio", &[s.damping_ratio])?;
            check_pos("actuators.servo.rate_limit", s.rate_limit)?;
        }
        if let Some(l) = &self.actuators.rotor_lag {
            check_pos("actuators.rotor_lag.time_constant", l.time_constant)?;
        }
        if let Some(l) = &self.actuators.limits {
            check_pos("actuators.limits.sigma_x", l.sigma_x)?;
            check_pos("actuators.limits.sigma_y", l.sigma_y)?;
            check_pos("actuators.limits.max_thrust", l.max_thrust)?;
        }
        for (i, f) in self.failures.iter().enumerate() {
            if f.agent >= team.len() {
                return Err(invalid(
                    format!("failures[{i}].agent"),
                    format!(
                        "agent {} does not exist (the team has {})",
                        f.agent,
                        team.len()
                    ),
                ));
            }
            check_nonneg(&format!("failures[{i}].time"), &[f.time])?;
            check_nonneg(
                &format!("failures[{i}].informed_after"),
                &[f.informed_after],
            )?;
            if !f.controller_informed && f.informed_after != 0.0 {
                return Err(invalid(
                    format!("failures[{i}].informed_after"),
                    "a controller never informed (`controller_informed = false`) is never told \
                     late: drop one of the two",
                ));
            }
        }
        check_magnitude("disturbances.wind", &self.disturbances.wind, MAX_EXTERNAL)?;
        if let Some(w) = &self.disturbances.external_wrench {
            check_magnitude("disturbances.external_wrench.force", &w.force, MAX_EXTERNAL)?;
            check_magnitude(
                "disturbances.external_wrench.torque",
                &w.torque,
                MAX_EXTERNAL,
            )?;
            check_finite("disturbances.external_wrench.start", &[w.start])?;
            if let Some(e) = w.end {
                check_finite("disturbances.external_wrench.end", &[e])?;
                if e < w.start {
                    return Err(invalid(
                        "disturbances.external_wrench.end",
                        format!("ends at {e} s, before it starts ({} s)", w.start),
                    ));
                }
            }
        }
        if let Some(a) = &self.disturbances.air {
            a.validate()?;
        }
        self.plant.validate(team.len())?;
        for (i, p) in self.payloads.iter().enumerate() {
            p.validate(&format!("payloads[{i}]"))?;
        }
        check_magnitude("initial_attitude", &self.initial_attitude, 2.0 * PI)?;
        if self.physics.ground {
            // Tilted, an agent's ball swings below where it rests level.
            let r = tvmd_plant::math::from_roll_pitch_yaw(self.initial_attitude);
            let ground = -team.rest_height();
            let lowest = team
                .agents
                .iter()
                .map(|a| self.initial_position[2] + (r * a.position_vector()).z)
                .fold(f64::INFINITY, f64::min)
                - team.collider_radius;
            if lowest < ground - 1e-9 {
                return Err(invalid(
                    "initial_attitude",
                    format!(
                        "at z = {} m this attitude puts an agent {:.3} m below the ground: start \
                         higher",
                        self.initial_position[2],
                        ground - lowest
                    ),
                ));
            }
        }
        if let Some(n) = &self.disturbances.state_noise {
            check_nonneg(
                "disturbances.state_noise",
                &[n.position, n.velocity, n.attitude, n.angular_velocity],
            )?;
        }
        let latency = self.disturbances.feedback_latency;
        if latency > crate::disturbances::MAX_FEEDBACK_LATENCY {
            return Err(invalid(
                "disturbances.feedback_latency",
                format!(
                    "must be at most {} controller periods, got {latency}",
                    crate::disturbances::MAX_FEEDBACK_LATENCY
                ),
            ));
        }
        if let Some(links) = &self.links {
            links.validate()?;
        }
        if let Some(reports) = &self.reports {
            reports.validate(team.len(), self.physics.dt)?;
        }
        self.law.validate()?;
        if let Some(detection) = &self.fault_detection {
            detection.validate(&self.law.offset_free)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_values_name_the_field() {
        let e = Scenario::from_toml_str("relaxation = 1.5\n").unwrap_err();
        assert!(
            matches!(&e, ScenarioError::InvalidScenario { field, .. } if field == "relaxation"),
            "{e}"
        );
        let e = Scenario::from_toml_str("controller_period = 0.0125\n").unwrap_err();
        assert!(e.to_string().contains("controller_period"), "{e}");
        let e =
            Scenario::from_toml_str("[[failures]]\nagent = 7\ntime = 1.0\nkind = \"no-thrust\"\n")
                .unwrap_err();
        assert!(e.to_string().contains("failures[0].agent"), "{e}");
        for bad in ["-0.01", "nan", "inf"] {
            let e = Scenario::from_toml_str(&format!(
                "[[failures]]\nagent = 0\ntime = 1.0\nkind = \"no-thrust\"\ninformed_after = {bad}\n"
            ))
            .unwrap_err();
            assert!(e.to_string().contains("failures[0].informed_after"), "{e}");
        }
        let s = Scenario::from_toml_str(
            "[[failures]]\nagent = 0\ntime = 1.0\nkind = \"no-thrust\"\ninformed_after = 0.05\n",
        )
        .unwrap();
        assert_eq!(s.failures[0].informed_after, 0.05);
        // Told late, but never told: an option that would be ignored is refused.
        let e = Scenario::from_toml_str(
            "[[failures]]\nagent = 0\ntime = 1.0\nkind = \"no-thrust\"\ncontroller_informed = false\ninformed_after = 0.05\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("failures[0].informed_after"), "{e}");
    }

    #[test]
    fn the_round_cap_is_for_the_exact_boundary_walk_only() {
        let s = Scenario::from_toml_str("allocator_max_rounds = 2\n").unwrap();
        assert_eq!(s.allocator_max_rounds, Some(tvmd_core::RoundCap::Rounds(2)));
        assert_eq!(Scenario::default().allocator_max_rounds, None);
        let s = Scenario::from_toml_str(
            "allocator = \"capped-redistribution\"\nallocator_max_rounds = 3\n",
        )
        .unwrap();
        assert_eq!(s.allocator_max_rounds, Some(tvmd_core::RoundCap::Rounds(3)));
        let e = Scenario::from_toml_str(
            "allocator = \"capped-redistribution\"\nallocator_max_rounds = 0\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("allocator_max_rounds"), "{e}");
        for other in ["redistributed-pseudo-inverse", "pseudo-inverse", "clarabel"] {
            let e = Scenario::from_toml_str(&format!(
                "allocator = \"{other}\"\nallocator_max_rounds = 2\n"
            ))
            .unwrap_err();
            assert!(
                e.to_string().contains("allocator_max_rounds"),
                "{other}: {e}"
            );
        }
        assert!(Scenario::from_toml_str("allocator_max_rounds = -1\n").is_err());
    }
}
