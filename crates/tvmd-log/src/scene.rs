//! The `/scene` topic: the team drawn in frame `team` as a `foxglove.SceneUpdate`.

use foxglove::messages::{
    ArrowPrimitive, Color, CubePrimitive, Duration, Pose, SceneEntity, SceneUpdate,
};
use nalgebra::{UnitQuaternion, Vector3};

use crate::LogError;
use crate::{fg_quaternion, fg_vector, timestamp, RunLog};
use tvmd_plant::TeamBody;

fn color(r: f64, g: f64, b: f64) -> Option<Color> {
    Some(Color { r, g, b, a: 1.0 })
}

fn pose(position: &Vector3<f64>, orientation: &UnitQuaternion<f64>) -> Option<Pose> {
    Some(Pose {
        position: Some(fg_vector(position)),
        orientation: Some(fg_quaternion(orientation)),
    })
}

fn cube(position: &Vector3<f64>, yaw: f64, size: [f64; 3], c: Option<Color>) -> CubePrimitive {
    CubePrimitive {
        pose: pose(
            position,
            &UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw),
        ),
        size: Some(fg_vector(&Vector3::from(size))),
        color: c,
    }
}

/// An arrow from `from` along `force`, `0.5 m` long at `max_thrust`; none for a zero force.
fn thrust_arrow(
    from: &Vector3<f64>,
    force: &Vector3<f64>,
    max_thrust: f64,
) -> Option<ArrowPrimitive> {
    let n = force.norm();
    if !(n > 1e-9 && max_thrust > 0.0) {
        return None;
    }
    // Foxglove arrows point along +x of their pose.
    let q = UnitQuaternion::rotation_between(&Vector3::x(), force).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI)
    });
    let len = 0.5 * n / max_thrust;
    Some(ArrowPrimitive {
        pose: pose(from, &q),
        shaft_length: 0.8 * len,
        shaft_diameter: 0.02,
        head_length: 0.2 * len,
        head_diameter: 0.05,
        color: color(0.1, 0.8, 0.2),
    })
}

/// The scene at `t`: one entity per agent (a cube at `p_i` turned by `psi_i`, blue if `m_i`
/// is even, orange if odd, red if failed, and an arrow along its body-frame force) and a grey
/// navigator cube at the centre, all frame-locked to `team`.
pub fn team_scene(
    t: f64,
    team: &TeamBody,
    forces_body: &[Vector3<f64>],
    failed: &[bool],
    max_thrust: f64,
) -> SceneUpdate {
    let entity = |id: String, cubes: Vec<CubePrimitive>, arrows: Vec<ArrowPrimitive>| SceneEntity {
        timestamp: Some(timestamp(t)),
        frame_id: "team".into(),
        id,
        lifetime: Some(Duration::new(0, 0)),
        frame_locked: true,
        cubes,
        arrows,
        ..Default::default()
    };
    let mut entities = Vec::with_capacity(team.len() + 1);
    for (i, a) in team.agents.iter().enumerate() {
        let p = a.position_vector();
        let c = if failed.get(i).copied().unwrap_or(false) {
            color(0.9, 0.1, 0.1)
        } else if a.quarter_turns.rem_euclid(2) == 0 {
            color(0.2, 0.4, 0.9)
        } else {
            color(0.95, 0.55, 0.1)
        };
        let yaw = f64::from(a.quarter_turns) * std::f64::consts::FRAC_PI_2;
        let arrow = forces_body
            .get(i)
            .and_then(|f| thrust_arrow(&p, f, max_thrust));
        entities.push(entity(
            format!("agent-{i}"),
            vec![cube(&p, yaw, [0.16, 0.12, 0.04], c)],
            arrow.into_iter().collect(),
        ));
    }
    entities.push(entity(
        "navigator".into(),
        vec![cube(
            &Vector3::zeros(),
            0.0,
            [0.1, 0.1, 0.05],
            color(0.5, 0.5, 0.5),
        )],
        Vec::new(),
    ));
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

impl RunLog {
    /// Writes [`team_scene`] on `/scene` (built on the writer thread from copies of the
    /// arguments).
    pub fn write_scene(
        &mut self,
        t: f64,
        team: &TeamBody,
        forces_body: &[Vector3<f64>],
        failed: &[bool],
        max_thrust: f64,
    ) -> Result<(), LogError> {
        let (team, forces_body, failed) = (team.clone(), forces_body.to_vec(), failed.to_vec());
        self.submit(move |w| {
            w.write(t, &team_scene(t, &team, &forces_body, &failed, max_thrust));
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_has_an_entity_per_agent_and_arrows_only_for_thrust() {
        let team = TeamBody::a4_inc();
        let mut forces = vec![Vector3::new(0.0, 0.0, 7.0); 4];
        forces[2] = Vector3::zeros();
        let scene = team_scene(1.0, &team, &forces, &[false, true, false, false], 14.0);
        assert_eq!(scene.entities.len(), 5);
        assert_eq!(scene.entities[4].id, "navigator");
        let arrows: Vec<usize> = scene.entities.iter().map(|e| e.arrows.len()).collect();
        assert_eq!(arrows, [1, 1, 0, 1, 0]);
        // Half of the maximum thrust draws a 0.25 m arrow, pointing up (+x turned onto +z).
        let a = &scene.entities[0].arrows[0];
        assert!((a.shaft_length + a.head_length - 0.25).abs() < 1e-12);
        let q = a.pose.as_ref().unwrap().orientation.as_ref().unwrap();
        let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z));
        assert!((q * Vector3::x() - Vector3::z()).norm() < 1e-12);
        // The failed agent is red.
        let red = scene.entities[1].cubes[0].color.as_ref().unwrap();
        assert!(red.r > 0.8 && red.g < 0.2);
    }
}
