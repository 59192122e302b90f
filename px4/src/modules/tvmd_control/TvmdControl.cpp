#include "TvmdControl.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>

#include <matrix/math.hpp>
#include <px4_platform_common/getopt.h>
#include <px4_platform_common/log.h>

using namespace time_literals;
using tvmd::px4::Mat3;
using tvmd::px4::Vec3;

namespace
{

/* tvmd's row-major attitude (z-up frames) as PX4's quaternion (body FRD to NED). */
void quaternion_ned(const float r_zup[9], float q[4])
{
	Mat3 r;
	std::memcpy(r.data(), r_zup, sizeof(float) * 9);
	const auto out = tvmd::px4::quaternion_from_rotation(tvmd::px4::flip(r));

	for (int i = 0; i < 4; ++i) { q[i] = out[i]; }
}

/* A tvmd vector (z-up world or body) in PX4's frame (NED or FRD). */
void flipped(const float v[3], float out[3])
{
	const Vec3 f = tvmd::px4::flip(v);

	for (int i = 0; i < 3; ++i) { out[i] = f[i]; }
}

} // namespace

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

int TvmdControl::config_task_main(int argc, char *argv[])
{
	TvmdControl *instance = get_instance();  // stored by task_spawn before init()

	if (instance != nullptr) {
		instance->run_configuration();
	}

	return 0;
}

void TvmdControl::run_configuration()
{
	while (_config_task.wait_for_request()) {
		apply_parameters();
		_config_task.done();
	}

	_config_task.exited();
}

bool TvmdControl::apply_parameters()
{
	updateParams();
	const tvmd_control::Settings settings{
		_param_law.get(), _param_pos_w.get(), _param_pos_z.get(), _param_att_w.get(), _param_att_z.get(),
		_param_obs_bw.get(), _param_max_trq.get(), _param_s.get(), _param_rate_lim.get(),
		_param_alloc.get(), _param_alloc_cap.get(), _param_law_hz.get(), _param_fault.get(),
		_param_ag_count.get(), _param_ag_mass.get(), _param_nav_mass.get(), _param_sig_x.get(),
		_param_sig_y.get(), _param_max_thr.get(), _param_mot_curve.get(), _param_sv_x_rng.get(),
		_param_sv_y_rng.get()};

	perf_begin(_reconfigure_perf);
	TvmdConfig config;
	TvmdStatus status = tvmd_control::config_from(settings, _agent_params, config);

	if (status == TVMD_OK) {
		status = _created ? tvmd_reconfigure(&_controller, &config)
			 : tvmd_create(&_controller, sizeof(_controller), &config);
	}

	TvmdActuatorMap map;

	if (status == TVMD_OK) {
		status = tvmd_control::map_from(&_controller, settings, map);

		if (status != TVMD_OK && _created) {
			/* The map does not fit the new team: back to the last good configuration. */
			const TvmdStatus back = tvmd_reconfigure(&_controller, &_config);

			if (back != TVMD_OK) {
				_log.record(tvmd_control::CONFIG, back);
			}
		}
	}

	perf_end(_reconfigure_perf);
	_log.record(tvmd_control::CONFIG, status);

	if (status != TVMD_OK) {
		if (_created) {
			PX4_ERR("parameters refused (%s): flying the last good configuration", tvmd_status_name(status));
		}

		return _created;
	}

	if (!_created) {
		_created = true;
		const TvmdStatus landed = tvmd_set_landed(&_controller, 1);
		_log.record(tvmd_control::LANDED, landed);
		_landed = true;
	}

	_config = config;
	_map = map;
	_hover.size = sizeof(_hover);
	const TvmdStatus hover = tvmd_hover_capability(&_controller, &_hover);
	_log.record(tvmd_control::FAILURES, hover);
	PX4_INFO("configuration accepted: %u agents, law %s, allocator %u", static_cast<unsigned>(config.agent_count),
		 settings.law == 0 ? "paper" : "offset-free", static_cast<unsigned>(config.allocator));
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

void TvmdControl::publish_outputs(const TvmdAllocationOutput &alloc, hrt_abstime timestamp_sample)
{
	/* On an error status alloc.commands are the held ones: map and send them all the same. */
	TvmdActuatorOutputs outputs;
	outputs.size = sizeof(outputs);
	const TvmdStatus status = tvmd_actuator_outputs(&_controller, &_map, alloc.commands, TVMD_MAX_AGENTS, &outputs);
	_log.record(tvmd_control::OUTPUT, status);

	if (status == TVMD_OK) {
		_outputs = outputs;
		_have_outputs = true;
	}

	publish_held(timestamp_sample);

	/* The collective thrust for PX4's land detector and hover thrust estimator, normalized by
	 * the team's largest thrust n sigma_Tf (FRD). */
	const float scale = static_cast<float>(_config.agent_count) * _config.limits.max_thrust;

	if (status == TVMD_OK && alloc.status == TVMD_OK && scale > 0.f) {
		vehicle_thrust_setpoint_s thrust{};
		thrust.timestamp_sample = timestamp_sample;
		float frd[3] {};

		if (!_ground_idle) {
			flipped(alloc.allocated_force, frd);
		}

		for (int i = 0; i < 3; ++i) { thrust.xyz[i] = frd[i] / scale; }

		thrust.timestamp = hrt_absolute_time();
		_thrust_pub.publish(thrust);
	}
}

void TvmdControl::publish_held(hrt_abstime timestamp_sample)
{
	if (!_have_outputs) {
		return;  // nothing good was ever mapped: publish nothing rather than a guess
	}

	actuator_motors_s motors{};
	actuator_servos_s servos{};
	tvmd::px4::actuators_from(_outputs, motors, servos);
	motors.timestamp_sample = timestamp_sample;
	servos.timestamp_sample = timestamp_sample;
	motors.timestamp = servos.timestamp = hrt_absolute_time();
	_motors_pub.publish(motors);
	_servos_pub.publish(servos);
}

void TvmdControl::publish_status(const TvmdAllocationOutput &alloc, hrt_abstime timestamp_sample)
{
	tvmd_control_status_s s{};
	s.timestamp_sample = timestamp_sample;
	const TvmdLawOutput &law = _cascade.law();

	if (_cascade.has_law()) {
		quaternion_ned(law.planned_attitude, s.q_planned);
		flipped(law.position_error, s.position_error);

	} else {
		for (int i = 0; i < 4; ++i) { s.q_planned[i] = NAN; }

		for (int i = 0; i < 3; ++i) { s.position_error[i] = NAN; }
	}

	std::memcpy(s.q_reference, _reference_q, sizeof(s.q_reference));
	s.planner_theta = law.planner_theta;
	s.planner_status = static_cast<uint8_t>(law.planner_status);
	s.planner_iterations = static_cast<uint8_t>(law.planner_iterations > 255 ? 255 : law.planner_iterations);
	flipped(_cascade.attitude().attitude_error, s.attitude_error);
	flipped(_cascade.requested().torque, s.torque_requested);
	flipped(_cascade.requested().force, s.force_requested);
	flipped(alloc.allocated_torque, s.torque_allocated);
	flipped(alloc.allocated_force, s.force_allocated);
	s.force_unallocated = alloc.force_error;
	s.torque_unallocated = alloc.torque_error;
	s.saturated = static_cast<uint16_t>(alloc.saturated);

	if (alloc.saturated != 0) {
		++_saturated_periods;
	}

	s.saturated_periods = _saturated_periods;

	/* The offset-free state after the latest allocation (tvmd_compensation; NaN before the
	 * first one); on the ground, where nothing is allocated, read from the handle (zero while
	 * landed). */
	TvmdCompensation compensation = _cascade.compensation();

	if (_ground_idle) {
		compensation.size = sizeof(compensation);
		_log.record(tvmd_control::ALLOCATE, tvmd_compensation(&_controller, &compensation));

	} else if (_cascade.report().compensation.last != TVMD_OK) {
		_log.record(tvmd_control::ALLOCATE, _cascade.report().compensation.last);
	}

	flipped(compensation.force, s.compensation_force);
	flipped(compensation.torque, s.compensation_torque);

	s.hover_capable = _hover.capable != 0;
	s.hover_margin = _hover.margin;
	s.failed_agents = static_cast<uint16_t>(_failed_agents);
	s.landed = _landed;
	s.fault_verdict = static_cast<uint8_t>(_fault.verdict);
	s.fault_agent = static_cast<int8_t>(_fault.agent);
	s.fault_kind = static_cast<uint8_t>(_fault.kind);
	s.fault_statistic = _fault.statistic;
	s.fault_threshold = _fault.threshold;
	s.law_status = static_cast<int16_t>(_log.last(tvmd_control::LAW));
	s.attitude_status = static_cast<int16_t>(_log.last(tvmd_control::ATTITUDE));
	s.allocate_status = static_cast<int16_t>(_log.last(tvmd_control::ALLOCATE));
	s.output_status = static_cast<int16_t>(_log.last(tvmd_control::OUTPUT));
	s.config_status = static_cast<int16_t>(_log.last(tvmd_control::CONFIG));
	s.law_errors = _log.errors(tvmd_control::LAW);
	s.attitude_errors = _log.errors(tvmd_control::ATTITUDE);
	s.allocate_errors = _log.errors(tvmd_control::ALLOCATE);
	s.output_errors = _log.errors(tvmd_control::OUTPUT);
	s.config_errors = _log.errors(tvmd_control::CONFIG);
	s.rate_loop_us = _rate_timer.last_us();
	s.law_us = _law_timer.last_us();
	s.timestamp = hrt_absolute_time();
	_status_pub.publish(s);
}

int TvmdControl::print_status()
{
	PX4_INFO("tvmd %s (ABI %u), %u agents, %s", tvmd_version(), static_cast<unsigned>(tvmd_abi_version()),
		 static_cast<unsigned>(_config.agent_count), _landed ? "landed" : "flying");
	perf_print_counter(_rate_perf);
	perf_print_counter(_rate_interval_perf);
	perf_print_counter(_law_perf);
	perf_print_counter(_reconfigure_perf);
	PX4_INFO("wall clock: attitude+allocation %u periods, mean %.1f us, max %.1f us; law %u periods, mean %.1f us, max %.1f us",
		 static_cast<unsigned>(_rate_timer.count()), static_cast<double>(_rate_timer.mean_us()),
		 static_cast<double>(_rate_timer.max_us()), static_cast<unsigned>(_law_timer.count()),
		 static_cast<double>(_law_timer.mean_us()), static_cast<double>(_law_timer.max_us()));

	PX4_INFO("configuration task (its own stack, %d B): %u parameter changes, %u rate periods held meanwhile",
		 tvmd_control::ConfigTask::STACK_SIZE, static_cast<unsigned>(_config_requests),
		 static_cast<unsigned>(_held_periods));

	for (int i = 0; i < tvmd_control::STAGE_COUNT; ++i) {
		const auto stage = static_cast<tvmd_control::Stage>(i);
		PX4_INFO("%s: last %s, %u refused", tvmd_control::StatusLog::name(stage), tvmd_status_name(_log.last(stage)),
			 static_cast<unsigned>(_log.errors(stage)));
	}

	PX4_INFO("hover certificate: %s, margin %.3f; failed agents 0x%x", _hover.capable ? "capable" : "NOT capable",
		 static_cast<double>(_hover.margin), static_cast<unsigned>(_failed_agents));
	return 0;
}

int TvmdControl::task_spawn(int argc, char *argv[])
{
	TvmdControl *instance = new TvmdControl();

	if (instance) {
		_object.store(instance);
		_task_id = task_id_is_work_queue;

		if (instance->init()) {
			return PX4_OK;
		}

	} else {
		PX4_ERR("alloc failed");
	}

	delete instance;
	_object.store(nullptr);
	_task_id = -1;
	return PX4_ERROR;
}

int TvmdControl::custom_command(int argc, char *argv[])
{
	if (argc >= 2 && strcmp(argv[0], "pose") == 0 && strcmp(argv[1], "off") == 0 && is_running()) {
		tvmd_pose_setpoint_s pose{};

		for (int i = 0; i < 4; ++i) { pose.q[i] = NAN; }

		for (int i = 0; i < 3; ++i) { pose.position[i] = NAN; }

		pose.timestamp = hrt_absolute_time();
		get_instance()->publish_pose(pose);
		return PX4_OK;
	}

	if (argc >= 4 && strcmp(argv[0], "pose") == 0) {
		if (!is_running()) {
			PX4_ERR("not running");
			return PX4_ERROR;
		}

		const float deg = static_cast<float>(M_PI) / 180.f;
		matrix::Quatf q{matrix::Eulerf(strtof(argv[1], nullptr) * deg, strtof(argv[2], nullptr) * deg,
						 strtof(argv[3], nullptr) * deg)};
		q.normalize();
		tvmd_pose_setpoint_s pose{};

		for (int i = 0; i < 4; ++i) { pose.q[i] = q(i); }

		for (int i = 0; i < 3; ++i) { pose.position[i] = argc >= 7 ? strtof(argv[4 + i], nullptr) : NAN; }

		if (!q.isAllFinite()) {
			PX4_ERR("pose: angles must be numbers (degrees)");
			return PX4_ERROR;
		}

		pose.timestamp = hrt_absolute_time();
		get_instance()->publish_pose(pose);
		return PX4_OK;
	}

	return print_usage("unknown command");
}

int TvmdControl::print_usage(const char *reason)
{
	if (reason) {
		PX4_WARN("%s\n", reason);
	}

	PRINT_MODULE_DESCRIPTION(
		R"DESCR_STR(
### Description
tvmd's full-pose controller for a thrust-vectoring modular team (TVMD): the attitude planner,
the full-pose law and the allocation to gimbal angles and rotor speeds (the tvmd C interface),
in place of the position and attitude controllers and the control allocator.
The law runs on vehicle_local_position (TVMD_LAW_HZ), the attitude stage and the allocation on
every vehicle_angular_velocity sample; it publishes actuator_motors, actuator_servos and
tvmd_control_status.

### Examples
Hold a 20 degree roll at the current position setpoint (until `pose off`, or for TVMD_POSE_TOUT
when that is not 0):
$ tvmd_control pose 20 0 0
$ tvmd_control pose off
)DESCR_STR");

	PRINT_MODULE_USAGE_NAME("tvmd_control", "controller");
	PRINT_MODULE_USAGE_COMMAND("start");
	PRINT_MODULE_USAGE_COMMAND_DESCR("pose", "Publish a full-pose reference: roll pitch yaw (deg) [north east down (m)], or off");
	PRINT_MODULE_USAGE_DEFAULT_COMMANDS();
	return 0;
}

extern "C" __EXPORT int tvmd_control_main(int argc, char *argv[])
{
	return TvmdControl::main(argc, argv);
}
