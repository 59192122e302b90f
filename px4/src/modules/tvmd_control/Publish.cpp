/* tvmd_control's outputs: actuator_motors, actuator_servos, vehicle_thrust_setpoint and the
 * status topic tvmd_control_status. */
#include "TvmdControl.hpp"

#include <cstring>

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
