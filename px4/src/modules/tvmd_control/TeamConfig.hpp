/* tvmd_control's parameters as a tvmd configuration and actuator map. Nothing here clamps or
 * repairs a value: the C interface checks the whole configuration (tvmd_reconfigure,
 * tvmd_actuator_map_validate) and refuses a bad one with its status. */
#pragma once

#include <cstdint>
#include <cstring>

#include <parameters/param.h>

#include "tvmd.h"

namespace tvmd_control
{

/* PX4's outputs carry at most four two-axis agents (8 servo channels). */
static constexpr int MAX_PARAM_AGENTS = 4;

/* The instanced team parameters TVMD_AG<i>_PX, _PY, _PZ (FRD) and _QT. */
struct AgentParamHandles {
	param_t px[MAX_PARAM_AGENTS];
	param_t py[MAX_PARAM_AGENTS];
	param_t pz[MAX_PARAM_AGENTS];
	param_t qt[MAX_PARAM_AGENTS];

	void find()
	{
		char name[17];

		for (int i = 0; i < MAX_PARAM_AGENTS; ++i) {
			snprintf(name, sizeof(name), "TVMD_AG%d_PX", i);
			px[i] = param_find(name);
			snprintf(name, sizeof(name), "TVMD_AG%d_PY", i);
			py[i] = param_find(name);
			snprintf(name, sizeof(name), "TVMD_AG%d_PZ", i);
			pz[i] = param_find(name);
			snprintf(name, sizeof(name), "TVMD_AG%d_QT", i);
			qt[i] = param_find(name);
		}
	}
};

/* The parameter values a configuration is made of (read by the module, so that this file
 * does not depend on its DEFINE_PARAMETERS). */
struct Settings {
	int32_t law;          // TVMD_LAW: 0 paper, 1 offset-free
	float position_frequency, position_damping, attitude_frequency, attitude_damping;
	float observer_bandwidth, max_torque, relaxation, rate_limit;
	int32_t allocator, allocator_max_rounds, law_rate_hz, fault_mode;
	int32_t agent_count;
	float agent_mass, navigator_mass, sigma_x, sigma_y, max_thrust;
	int32_t motor_curve;
	float servo_range_x, servo_range_y;
};

/* The configuration of `settings` and the agents' geometry: the library's configuration of
 * the chosen law, with the team and the settings replaced. The agents' positions are given
 * in PX4's body frame (FRD) and stored in tvmd's (x forward, y left, z up). Returns the
 * status of the library's configuration function; the configuration itself is checked by
 * tvmd_reconfigure. */
inline TvmdStatus config_from(const Settings &settings, const AgentParamHandles &agents,
			      TvmdConfig &config)
{
	std::memset(&config, 0, sizeof(config));
	config.size = sizeof(config);
	const TvmdStatus base = settings.law == 0 ? tvmd_config_paper(&config) : tvmd_config_default(&config);

	if (base != TVMD_OK) {
		return base;
	}

	if (settings.law != 0 && settings.law != 1) {
		return TVMD_ERR_ENUM_VALUE;
	}

	/* A count beyond what the parameters describe is refused as the library refuses one
	 * beyond its capacity. */
	if (settings.agent_count < 1) {
		return TVMD_ERR_CONFIG_NO_AGENTS;
	}

	if (settings.agent_count > MAX_PARAM_AGENTS || settings.agent_count > TVMD_MAX_AGENTS) {
		return TVMD_ERR_CONFIG_TOO_MANY_AGENTS;
	}

	config.agent_count = static_cast<uint32_t>(settings.agent_count);

	for (int i = 0; i < settings.agent_count; ++i) {
		float p[3] {};
		int32_t quarter_turns = 0;
		param_get(agents.px[i], &p[0]);
		param_get(agents.py[i], &p[1]);
		param_get(agents.pz[i], &p[2]);
		param_get(agents.qt[i], &quarter_turns);
		TvmdAgent &agent = config.agents[i];
		agent.position[0] = p[0];
		agent.position[1] = -p[1];
		agent.position[2] = -p[2];
		agent.quarter_turns = quarter_turns;
		agent.mass = settings.agent_mass;
		std::memset(agent.inertia, 0, sizeof(agent.inertia));  // the paper's point masses
	}

	config.navigator_mass = settings.navigator_mass;
	config.limits.sigma_x = settings.sigma_x;
	config.limits.sigma_y = settings.sigma_y;
	config.limits.max_thrust = settings.max_thrust;
	config.relaxation = settings.relaxation;
	config.period = settings.law_rate_hz > 0 ? 1.0f / static_cast<float>(settings.law_rate_hz) : 0.0f;
	config.allocator = static_cast<uint32_t>(settings.allocator);
	// TVMD_ALLOC_CAP: rounds per period, -1 uncapped; only the exact-boundary redistribution
	// (TVMD_ALLOC 3, its walk) and the capped redistribution (TVMD_ALLOC 4) have rounds to cap,
	// the others take the default.
	if (settings.allocator != static_cast<int32_t>(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION)
	    && settings.allocator != static_cast<int32_t>(TVMD_ALLOCATOR_CAPPED_REDISTRIBUTION)) {
		config.allocator_round_cap = TVMD_ROUND_CAP_DEFAULT;

	} else if (settings.allocator_max_rounds < 0) {
		config.allocator_round_cap = TVMD_ROUND_CAP_UNCAPPED;

	} else {
		config.allocator_round_cap = TVMD_ROUND_CAP_ROUNDS;
		config.allocator_max_rounds = static_cast<uint32_t>(settings.allocator_max_rounds);
	}
	config.rate_limited = settings.rate_limit > 0.0f ? 1u : 0u;
	config.rate_limits[0] = settings.rate_limit;
	config.rate_limits[1] = settings.rate_limit;
	config.fault.mode = static_cast<uint32_t>(settings.fault_mode);

	if (settings.law == 1) {
		for (int k = 0; k < 3; ++k) {
			config.law.position_frequency[k] = settings.position_frequency;
			config.law.position_damping[k] = settings.position_damping;
			config.law.attitude_frequency[k] = settings.attitude_frequency;
			config.law.attitude_damping[k] = settings.attitude_damping;
		}

		config.law.force_bandwidth = settings.observer_bandwidth;
		config.law.torque_bandwidth = settings.observer_bandwidth;
		config.law.max_torque = settings.max_torque;
	}

	return TVMD_OK;
}

/* The actuator map of the running controller: agent i on motors 2i, 2i+1 and servos 2i
 * (eta_x), 2i+1 (eta_y), the servo ranges and the motor curve of `settings`. */
inline TvmdStatus map_from(const TvmdController *controller, const Settings &settings, TvmdActuatorMap &map)
{
	std::memset(&map, 0, sizeof(map));
	map.size = sizeof(map);
	const TvmdStatus status = tvmd_actuator_map_default(controller, &map);

	if (status != TVMD_OK) {
		return status;
	}

	for (uint32_t i = 0; i < map.agent_count; ++i) {
		map.agents[i].servo_range[0] = settings.servo_range_x;
		map.agents[i].servo_range[1] = settings.servo_range_y;
	}

	map.motor_curve = static_cast<uint32_t>(settings.motor_curve);
	return tvmd_actuator_map_validate(controller, &map);
}

} // namespace tvmd_control
