/* tvmd_control's loops: the rate loop (Run: the failure mask, the attitude stage, the
 * allocation), the law (run_law: takeoff, the reference, the law stage, the land request).
 * Configure.cpp, Publish.cpp and Commands.cpp hold the rest of the class. */
#include "TvmdControl.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>

#include <matrix/math.hpp>
#include <px4_platform_common/log.h>

TvmdControl::TvmdControl() :
	ModuleParams(nullptr),
	WorkItem(MODULE_NAME, px4::wq_configurations::rate_ctrl)
{
	_agent_params.find();
	_map.size = sizeof(_map);
	_outputs.size = sizeof(_outputs);
	_hover.size = sizeof(_hover);
	_fault.size = sizeof(_fault);
}

TvmdControl::~TvmdControl()
{
	perf_free(_rate_perf);
	perf_free(_law_perf);
	perf_free(_rate_interval_perf);
	perf_free(_reconfigure_perf);
}

bool TvmdControl::init()
{
	if (tvmd_abi_version() != TVMD_ABI_VERSION) {
		PX4_ERR("libtvmd_ffi ABI %u, header %u: rebuild the module", static_cast<unsigned>(tvmd_abi_version()),
			static_cast<unsigned>(TVMD_ABI_VERSION));
		return false;
	}

	/* The creation (tvmd_create, 3,596 B of stack on a Cortex-M4F) in the configuration
	 * task, as every later parameter change: start() returns when it is done. */
	if (!_config_task.start(&TvmdControl::config_task_main)) {
		PX4_ERR("configuration task not started");
		return false;
	}

	_config_task.take_back();

	if (!_created) {
		PX4_ERR("no valid configuration: not started");
		_config_task.stop();
		return false;
	}

	/* PX4's takeoff timing: COM_SPOOLUP_TIME, MPC_TKO_RAMP_T (defaults where a build lacks them). */
	float spoolup = 1.f, ramp = 3.f;
	const param_t spoolup_param = param_find("COM_SPOOLUP_TIME"), ramp_param = param_find("MPC_TKO_RAMP_T");

	if (spoolup_param != PARAM_INVALID) { param_get(spoolup_param, &spoolup); }

	if (ramp_param != PARAM_INVALID) { param_get(ramp_param, &ramp); }

	_takeoff.setSpoolupTime(spoolup);
	_takeoff.setTakeoffRampTime(ramp);
	_takeoff_status_pub.advertise();
	_status_pub.advertise();

	const int32_t law_hz = _param_law_hz.get();
	_law_position_sub.set_interval_us(static_cast<uint32_t>(1000000 / (law_hz > 0 ? law_hz : 100)));

	if (!_angular_velocity_sub.registerCallback() || !_law_position_sub.registerCallback()) {
		PX4_ERR("callback registration failed");
		return false;
	}

	return true;
}

void TvmdControl::set_landed(bool landed)
{
	if (landed != _landed) {
		const TvmdStatus status = tvmd_set_landed(&_controller, landed ? 1 : 0);
		_log.record(tvmd_control::LANDED, status);

		if (status == TVMD_OK) {
			_landed = landed;
		}
	}
}

bool TvmdControl::update_takeoff(hrt_abstime timestamp_sample)
{
	_vehicle_constraints_sub.update(&_constraints);
	const float speed_up = std::isfinite(_constraints.speed_up) && _constraints.speed_up > 0.f ? _constraints.speed_up : 1.f;
	_takeoff.updateTakeoffState(_control_mode.flag_armed, _land_detected.landed, _constraints.want_takeoff, speed_up,
				    false, timestamp_sample);
	const float dt = _last_law_sample != 0 && timestamp_sample > _last_law_sample
			 ? static_cast<float>(timestamp_sample - _last_law_sample) * 1e-6f : 0.f;
	_last_law_sample = timestamp_sample;
	_takeoff.updateRamp(dt < 0.1f ? dt : 0.1f, speed_up);

	const uint8_t state = static_cast<uint8_t>(_takeoff.getTakeoffState());

	if (state != _takeoff_status_pub.get().takeoff_state) {
		_takeoff_status_pub.get().takeoff_state = state;
		_takeoff_status_pub.get().tilt_limit = NAN;
		_takeoff_status_pub.get().timestamp = hrt_absolute_time();
		_takeoff_status_pub.update();
	}

	/* Until the ramp-up the team stands on the ground: landed for the offset-free state (the
	 * ground's reaction is no disturbance), idle commands, no law. */
	const bool taken_off = _takeoff.getTakeoffState() >= TakeoffState::rampup;
	set_landed(!taken_off);

	if (!taken_off && !_ground_idle) {
		_log.record(tvmd_control::LAW, tvmd_reset(&_controller));  // the held command becomes idle
	}

	_ground_idle = !taken_off;

	if (!_control_mode.flag_armed) {
		_land_requested = false;
	}

	return taken_off;
}

void TvmdControl::update_failures()
{
	failure_detector_status_s fd;

	if (_failure_detector_sub.update(&fd)) {
		/* Agent i drives motors 2i and 2i+1: either one failed masks the agent. */
		_detected_failures = 0;

		for (uint32_t i = 0; i < _config.agent_count; ++i) {
			if (fd.motor_failure_mask & (3u << (2 * i))) {
				_detected_failures |= 1u << i;
			}
		}
	}

	const uint32_t mask = _detected_failures | static_cast<uint32_t>(_param_fail_mask.get());

	if (mask == _failed_agents) {
		return;
	}

	TvmdHover hover;
	hover.size = sizeof(hover);
	const TvmdStatus status = tvmd_set_failures(&_controller, mask, &hover);
	_log.record(tvmd_control::FAILURES, status);

	if (status == TVMD_OK) {
		_failed_agents = mask;
		_hover = hover;
		PX4_WARN("agents masked as failed: 0x%x, hover %s", static_cast<unsigned>(mask),
			 hover.capable ? "capable" : "NOT capable");
	}
}

TvmdReference TvmdControl::reference_for(const vehicle_local_position_s &lp, const vehicle_attitude_s &att)
{
	_trajectory_setpoint_sub.update(&_trajectory_setpoint);
	_pose_setpoint_sub.update(&_pose_setpoint);
	_manual_control_sub.update(&_manual_control);
	const hrt_abstime now = hrt_absolute_time();
	const float timeout = _param_pose_tout.get();
	const bool pose_fresh = _pose_setpoint.timestamp != 0 && std::isfinite(_pose_setpoint.q[0])
				&& (timeout <= 0.f || now - _pose_setpoint.timestamp < static_cast<hrt_abstime>(timeout * 1e6f));

	/* Position: the pose setpoint's, else the trajectory setpoint's, else the last one held,
	 * else where the vehicle is (a setpoint's NaN means "not controlled"). */
	const float *position = _trajectory_setpoint.position;

	if (pose_fresh && std::isfinite(_pose_setpoint.position[0]) && std::isfinite(_pose_setpoint.position[1])
	    && std::isfinite(_pose_setpoint.position[2])) {
		position = _pose_setpoint.position;
	}

	if (std::isfinite(position[0]) && std::isfinite(position[1]) && std::isfinite(position[2]) && !_landed) {
		std::memcpy(_reference_position_ned, position, sizeof(_reference_position_ned));
		_have_reference_position = true;

	} else if (!_have_reference_position || _landed) {
		_reference_position_ned[0] = lp.x;
		_reference_position_ned[1] = lp.y;
		_reference_position_ned[2] = lp.z;
		_have_reference_position = true;
	}

	/* With the sticks on the attitude (TVMD_RC_TILT), their tilt is the reference attitude,
	 * not a horizontal acceleration: PX4's altitude mode turns stick tilt into an acceleration
	 * setpoint for a multicopter, which a team that tilts in place must not follow. */
	const bool sticks_on_attitude = _param_rc_tilt.get() > 0.f && _control_mode.flag_control_manual_enabled
					&& !pose_fresh;
	trajectory_setpoint_s sp{};

	for (int i = 0; i < 3; ++i) {
		const bool horizontal_by_sticks = sticks_on_attitude && i < 2;
		sp.position[i] = _reference_position_ned[i];
		sp.velocity[i] = std::isfinite(_trajectory_setpoint.velocity[i]) && !_landed && !horizontal_by_sticks
				 ? _trajectory_setpoint.velocity[i] : 0.f;
		sp.acceleration[i] = std::isfinite(_trajectory_setpoint.acceleration[i]) && !_landed && !horizontal_by_sticks
				     ? _trajectory_setpoint.acceleration[i] : 0.f;
	}

	/* Attitude: the pose setpoint's, else the sticks' roll and pitch (TVMD_RC_TILT), at the
	 * setpoint's yaw (the vehicle's own when the setpoint has none). */
	float q[4];

	if (pose_fresh) {
		std::memcpy(q, _pose_setpoint.q, sizeof(q));

	} else {
		/* A NaN yaw holds the last one (as PX4's attitude controller does), or the vehicle's
		 * own on the ground: following the vehicle's yaw would leave yaw uncontrolled. */
		if (std::isfinite(_trajectory_setpoint.yaw) && !_landed) {
			_reference_yaw = _trajectory_setpoint.yaw;

		} else if (_landed || !std::isfinite(_reference_yaw)) {
			_reference_yaw = matrix::Eulerf(matrix::Quatf(att.q)).psi();
		}

		const float yaw = _reference_yaw;
		float roll = 0.f, pitch = 0.f;
		const float tilt = _param_rc_tilt.get();

		if (tilt > 0.f && _control_mode.flag_control_manual_enabled && _manual_control.valid
		    && std::isfinite(_manual_control.roll) && std::isfinite(_manual_control.pitch)) {
			roll = tilt * _manual_control.roll;
			pitch = -tilt * _manual_control.pitch;  // stick forward: nose down
		}

		const matrix::Quatf qd{matrix::Eulerf(roll, pitch, yaw)};

		for (int i = 0; i < 4; ++i) { q[i] = qd(i); }
	}

	std::memcpy(_reference_q, q, sizeof(_reference_q));
	return tvmd::px4::reference_from(sp, q);
}

void TvmdControl::run_law()
{
	vehicle_local_position_s lp;

	if (!_law_position_sub.update(&lp) || _config_task.state() != tvmd_control::ConfigTask::IDLE) {
		return;  // no sample, or the configuration task holds the handle
	}

	if (!_have_attitude || !_have_angular_velocity || !lp.xy_valid || !lp.z_valid || !lp.v_xy_valid || !lp.v_z_valid) {
		return;  // no estimate yet: nothing to control
	}

	if (!update_takeoff(lp.timestamp_sample)) {
		return;  // on the ground: idle (the rate loop sends the held idle commands)
	}

	perf_begin(_law_perf);
	_law_timer.begin();
	const TvmdState state = tvmd::px4::state_from(lp, _attitude, _angular_velocity);
	const TvmdReference reference = reference_for(lp, _attitude);
	const TvmdStatus status = _cascade.position(state, reference);
	_log.record(tvmd_control::LAW, status);

	_fault.size = sizeof(_fault);

	if (tvmd_fault_report(&_controller, &_fault) != TVMD_OK) {
		_fault.verdict = 0;
	}

	/* The fault detector may have masked an agent itself: its hover certificate then. */
	if (_fault.masked_agent >= 0 && !_fault.masked_hover_capable) {
		_hover.capable = 0;
	}

	if (!_hover.capable && _control_mode.flag_armed && !_landed) {
		request_land("hover certificate lost");
	}

	/* Half a second of refused law periods: the fast loop flies on a stale law output. */
	const int32_t law_hz = _param_law_hz.get();

	if (_cascade.report().law.consecutive >= static_cast<uint32_t>(law_hz > 1 ? law_hz / 2 : 1)
	    && _control_mode.flag_armed && !_landed) {
		request_land("law refused for 0.5 s");
	}

	_law_timer.end();
	perf_end(_law_perf);
}

void TvmdControl::request_land(const char *reason)
{
	if (_land_requested) {
		return;
	}

	PX4_ERR("%s (hover margin %.3f): asking to land", reason, static_cast<double>(_hover.margin));
	vehicle_command_s cmd{};
	cmd.command = vehicle_command_s::VEHICLE_CMD_NAV_LAND;
	cmd.param4 = NAN;
	cmd.param5 = static_cast<double>(NAN);
	cmd.param6 = static_cast<double>(NAN);
	cmd.param7 = NAN;
	/* Addressed to this vehicle (MAV_SYS_ID, which SITL sets per instance), as PX4's own
	 * modules do: commander ignores a command for another system. */
	vehicle_status_s status{};
	_vehicle_status_sub.copy(&status);
	cmd.target_system = status.system_id;
	cmd.target_component = status.component_id;
	cmd.source_system = status.system_id;
	cmd.source_component = status.component_id;
	cmd.from_external = false;
	cmd.timestamp = hrt_absolute_time();
	_command_pub.publish(cmd);
	_land_requested = true;
}

void TvmdControl::Run()
{
	if (should_exit()) {
		_angular_velocity_sub.unregisterCallback();
		_law_position_sub.unregisterCallback();
		_config_task.stop();
		exit_and_cleanup();
		return;
	}

	perf_begin(_rate_perf);
	perf_count(_rate_interval_perf);

	if (_angular_velocity_sub.update(&_angular_velocity)) {
		_have_angular_velocity = true;
	}

	/* A parameter change: the handle goes to the configuration task (ConfigTask.hpp), and
	 * until it is back the held outputs are sent again. */
	const tvmd_control::ConfigTask::State config = _config_task.state();

	if (config == tvmd_control::ConfigTask::DONE) {
		_config_task.take_back();

	} else if (config == tvmd_control::ConfigTask::REQUESTED) {
		++_held_periods;
		publish_held(_angular_velocity.timestamp_sample);
		perf_end(_rate_perf);
		return;

	} else if (_parameter_update_sub.updated()) {
		parameter_update_s update;
		_parameter_update_sub.copy(&update);
		_config_task.request();
		++_config_requests;
		++_held_periods;
		publish_held(_angular_velocity.timestamp_sample);
		perf_end(_rate_perf);
		return;
	}

	_have_attitude |= _attitude_sub.update(&_attitude);
	_have_local_position |= _local_position_sub.update(&_local_position);
	_control_mode_sub.update(&_control_mode);
	_land_detected_sub.update(&_land_detected);

	if (!_have_attitude || !_have_local_position || !_have_angular_velocity) {
		perf_end(_rate_perf);
		return;
	}

	/* The failure mask at the rate loop's rate: a told failure reaches the allocation within
	 * one period, and tvmd_set_failures (2,572 B on a Cortex-M4F) runs under Run()'s frame,
	 * not under the law's larger one (docs/px4-module.md, On a flight controller). */
	update_failures();

	_rate_timer.begin();
	const TvmdState state = tvmd::px4::state_from(_local_position, _attitude, _angular_velocity);
	TvmdAllocationOutput alloc;
	std::memset(&alloc, 0, sizeof(alloc));
	alloc.size = sizeof(alloc);

	if (_ground_idle) {
		/* On the ground before the ramp-up: the held commands, idle since tvmd_reset (the
		 * fallback of tvmd_allocate without a wrench; its status says only that). */
		tvmd_allocate(&_controller, nullptr, &alloc);
		alloc.status = TVMD_OK;
		publish_outputs(alloc, _angular_velocity.timestamp_sample);
		_rate_timer.end();
		publish_status(alloc, _angular_velocity.timestamp_sample);
		perf_end(_rate_perf);
		return;
	}

	const TvmdStatus status = _cascade.attitude_and_allocate(state, &alloc);

	if (status != TVMD_OK && !_cascade.has_law() && status == TVMD_ERR_NOT_INITIALIZED) {
		/* No law period yet (waiting for the estimate): idle, not an error worth a message. */
	} else {
		const bool attitude_failed = _cascade.report().attitude.last != TVMD_OK;
		_log.record(attitude_failed ? tvmd_control::ATTITUDE : tvmd_control::ALLOCATE, status);
	}

	publish_outputs(alloc, _angular_velocity.timestamp_sample);
	_rate_timer.end();
	publish_status(alloc, _angular_velocity.timestamp_sample);
	perf_end(_rate_perf);
}
