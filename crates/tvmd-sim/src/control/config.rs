//! The core's configuration of a scenario (crate `tvmd-scenario`'s [`tvmd_scenario::core_config`],
//! re-exported), and what the simulator adds: the hover roll limit of a scenario and the words an
//! f32 target builds its controller from ([`wire_config`]).

use tvmd_core::{FailureMask, Relaxation};
use tvmd_plant::math::from_rows;
use tvmd_scenario::core_float::{matrix_to_core, to_core, vector_to_core};
use tvmd_scenario::Scenario;

use super::MAX_AGENTS;
use crate::SimError;

pub use tvmd_scenario::core_config::{
    allocator, config_error, controller_settings, fault_detection, law_settings, team_config,
};

pub(super) fn invalid(field: &str, reason: impl Into<String>) -> SimError {
    SimError::invalid_field(field, reason)
}

/// `atan(c_y(1, s))`: the planned roll at which the planner saturates in hover for the
/// scenario's team, limits and relaxation `s` (a reproduction target, see `docs/method.md`),
/// computed in f64 whatever the scenario's precision.
pub fn hover_roll_limit(scenario: &Scenario, s: f64) -> Result<f64, SimError> {
    let team = team_config::<f64, MAX_AGENTS>(scenario)?;
    let afs = team.afs(&FailureMask::none()).map_err(config_error)?;
    let s = Relaxation::new(s).map_err(config_error)?;
    Ok(afs.semi_axes(1.0, s).c_y.atan())
}

/// The f32 controller's configuration of a scenario as the words an f32 target builds it from
/// ([`tvmd_wire::CoreConfig`]): every value rounded exactly as [`team_config`],
/// [`controller_settings`] and [`allocator`] round it. Errors name the scenario field, as
/// [`super::TvmdController::from_scenario`]'s do. The law (`[law]`) crosses as
/// [`tvmd_wire::LawWords`] of the f32 settings, with the fault detection and the allocator's
/// round cap: every setting the f32 controller flies with.
pub fn wire_config(scenario: &Scenario) -> Result<tvmd_wire::CoreConfig, SimError> {
    use tvmd_wire::{CoreConfig, LawWords, AGENTS, ALLOCATOR_NAME_BYTES};
    // Refused rather than flown without it: the target's firmware is built without the stage
    // (tvmd-core without its `null-space` feature, as the C interface).
    if scenario.null_space.is_some() {
        return Err(invalid(
            "null_space",
            "the null-space stage is not built into the target's firmware: fly it in process",
        ));
    }
    team_config::<f32, MAX_AGENTS>(scenario)?;
    let settings = controller_settings::<f32>(scenario)?;
    allocator::<f32, MAX_AGENTS>(&scenario.allocator, scenario.allocator_max_rounds)?;
    let body = scenario.team_body()?;
    let mut agents = [([0.0f32; 3], 0, 0.0f32); AGENTS];
    for (slot, a) in agents.iter_mut().zip(&body.agents) {
        let p = vector_to_core::<f32>(&a.position_vector());
        *slot = ([p.x, p.y, p.z], a.quarter_turns, to_core(a.mass));
    }
    let name = scenario.allocator.as_bytes();
    let mut allocator = [0u8; ALLOCATOR_NAME_BYTES];
    allocator
        .get_mut(..name.len())
        .ok_or_else(|| invalid("allocator", "name longer than 32 bytes"))?
        .copy_from_slice(name);
    let inertia = matrix_to_core::<f32>(&from_rows(&body.navigator_inertia));
    let g = &scenario.gains;
    Ok(CoreConfig {
        n: body.len(),
        agents,
        limits: [
            to_core(scenario.limits.sigma_x),
            to_core(scenario.limits.sigma_y),
            to_core(scenario.max_thrust()?),
        ],
        navigator: (
            to_core(body.navigator_mass),
            core::array::from_fn(|k| inertia[(k / 3, k % 3)]),
        ),
        gains: (g.k_x.map(to_core), g.k_r.map(to_core), g.k_xi.map(to_core)),
        relaxation: to_core(scenario.relaxation),
        gravity: to_core(scenario.physics.gravity),
        period: to_core(scenario.controller_period),
        rate_limits: scenario.controller_rate_limits.map(|r| r.map(to_core)),
        allocator,
        law: LawWords::of(&settings),
        fault_detection: settings.fault_detection,
        max_rounds: scenario.allocator_max_rounds.unwrap_or_default(),
    })
}
