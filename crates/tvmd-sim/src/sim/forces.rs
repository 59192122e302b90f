//! The agents' body-frame forces of the plant, with its actuation error.

use nalgebra::Vector3;
use tvmd_plant::actuators::{agent_force_body, ActuatorCommand};
use tvmd_plant::physics::TeamBody;
use tvmd_scenario::PlantError;

/// The agents' body-frame forces (N) for their actuator outputs `outputs`, with the plant's
/// actuation error (gimbal offsets, rotor efficiency): the forces the plant applies.
pub fn agent_forces(
    outputs: &[ActuatorCommand],
    team: &TeamBody,
    plant: &PlantError,
) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(outputs.len());
    body_forces(outputs, team, plant, &mut out);
    out.iter().map(|f| [f.x, f.y, f.z]).collect()
}

/// The agents' body-frame forces for their actuator outputs, written over `out`.
pub(super) fn body_forces<'a>(
    outputs: impl IntoIterator<Item = &'a ActuatorCommand>,
    team: &TeamBody,
    plant: &PlantError,
    out: &mut Vec<Vector3<f64>>,
) {
    out.clear();
    let outputs = outputs.into_iter().zip(&team.agents);
    if plant.actuation_is_nominal() {
        out.extend(outputs.map(|(c, a)| agent_force_body(c, a.quarter_turns)));
    } else {
        // Model error: the gimbal reaches its angles off by the offsets and the rotor makes
        // a share of its thrust.
        out.extend(outputs.enumerate().map(|(i, (c, a))| {
            let [dx, dy] = plant.gimbal_offset(i);
            let real = ActuatorCommand {
                eta_x: c.eta_x + dx,
                eta_y: c.eta_y + dy,
                thrust: c.thrust * plant.efficiency(i),
            };
            agent_force_body(&real, a.quarter_turns)
        }));
    }
}
