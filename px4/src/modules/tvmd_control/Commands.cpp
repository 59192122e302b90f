/* tvmd_control's shell: start, status, pose, usage. */
#include "TvmdControl.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>

#include <matrix/math.hpp>
#include <px4_platform_common/log.h>

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
