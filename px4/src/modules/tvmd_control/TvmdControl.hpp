/* tvmd_control: tvmd's full-pose controller for a thrust-vectoring modular team (TVMD) as one
 * PX4 module, in place of a position controller, an attitude controller and the control
 * allocation. It runs the tvmd C interface (tvmd.h) through the adapter's cascade
 * (tvmd_px4.hpp): the law (attitude planner and the full-pose law) on vehicle_local_position
 * at TVMD_LAW_HZ, the attitude stage and the allocation on every vehicle_angular_velocity
 * sample, both on the rate_ctrl work queue (one thread, so the controller handle is never
 * used from two at once); a parameter change in a task of its own with the stack the
 * reconfiguration needs, which holds the handle meanwhile (ConfigTask.hpp). It publishes actuator_motors, actuator_servos and
 * tvmd_control_status. */
#pragma once

#include <drivers/drv_hrt.h>
#include <lib/perf/perf_counter.h>
#include <px4_platform_common/module.h>
#include <px4_platform_common/module_params.h>
#include <px4_platform_common/px4_work_queue/WorkItem.hpp>
#include <uORB/Publication.hpp>
#include <uORB/Subscription.hpp>
#include <uORB/SubscriptionCallback.hpp>
#include <uORB/SubscriptionInterval.hpp>
#include <uORB/topics/actuator_motors.h>
#include <uORB/topics/actuator_servos.h>
#include <uORB/topics/failure_detector_status.h>
#include <uORB/topics/manual_control_setpoint.h>
#include <uORB/topics/parameter_update.h>
#include <uORB/topics/takeoff_status.h>
#include <uORB/topics/trajectory_setpoint.h>
#include <uORB/topics/tvmd_control_status.h>
#include <uORB/topics/tvmd_pose_setpoint.h>
#include <uORB/topics/vehicle_angular_velocity.h>
#include <uORB/topics/vehicle_attitude.h>
#include <uORB/topics/vehicle_command.h>
#include <uORB/topics/vehicle_constraints.h>
#include <uORB/topics/vehicle_control_mode.h>
#include <uORB/topics/vehicle_land_detected.h>
#include <uORB/topics/vehicle_local_position.h>
#include <uORB/topics/vehicle_status.h>
#include <uORB/topics/vehicle_thrust_setpoint.h>

#include <Takeoff.hpp>

#include "ConfigTask.hpp"
#include "CycleTimer.hpp"
#include "StatusLog.hpp"
#include "TeamConfig.hpp"
#include "tvmd_px4.hpp"

using namespace time_literals;

class TvmdControl : public ModuleBase<TvmdControl>, public ModuleParams, public px4::WorkItem
{
public:
	TvmdControl();
	~TvmdControl() override;

	static int task_spawn(int argc, char *argv[]);
	static int custom_command(int argc, char *argv[]);
	static int print_usage(const char *reason = nullptr);
	int print_status() override;

	bool init();

	/* `tvmd_control pose`: a full-pose reference from the shell. */
	void publish_pose(const tvmd_pose_setpoint_s &pose) { _pose_pub.publish(pose); }

private:
	/* The law at the position loop's rate: a second work item on the same queue. */
	class LawItem : public px4::WorkItem
	{
	public:
		explicit LawItem(TvmdControl &owner) :
			px4::WorkItem("tvmd_control_law", px4::wq_configurations::rate_ctrl), _owner(owner) {}
		void Run() override { _owner.run_law(); }
	private:
		TvmdControl &_owner;
	};

	void Run() override;  // the rate loop: attitude stage, allocation, outputs
	void run_law();       // the position loop: the law stage

	/* The configuration task (ConfigTask.hpp): each request runs apply_parameters there. */
	static int config_task_main(int argc, char *argv[]);
	void run_configuration();

	/* Parameters to a configuration; applied all or nothing, a refused one reported and the
	 * last good one kept. Returns whether a controller is running. Runs in the configuration
	 * task, while it holds the handle. */
	bool apply_parameters();
	/* PX4's takeoff (mc_pos_control's TakeoffHandling): idle on the ground until the flight
	 * mode asks for a takeoff, then the law. Returns whether the law flies. */
	bool update_takeoff(hrt_abstime timestamp_sample);
	void set_landed(bool landed);
	void update_failures();
	TvmdReference reference_for(const vehicle_local_position_s &lp, const vehicle_attitude_s &att);
	void publish_outputs(const TvmdAllocationOutput &alloc, hrt_abstime timestamp_sample);
	/* The last mapped outputs (the held commands) again, without the handle. */
	void publish_held(hrt_abstime timestamp_sample);
	void publish_status(const TvmdAllocationOutput &alloc, hrt_abstime timestamp_sample);
	void request_land(const char *reason);

	alignas(8) TvmdController _controller {};
	TvmdConfig _config{};           // the last good configuration
	TvmdActuatorMap _map{};         // its actuator map
	bool _created{false};
	tvmd::px4::Cascade _cascade{&_controller};
	tvmd_control::StatusLog _log{};

	LawItem _law_item{*this};

	uORB::SubscriptionCallbackWorkItem _angular_velocity_sub{this, ORB_ID(vehicle_angular_velocity)};
	uORB::SubscriptionCallbackWorkItem _law_position_sub{&_law_item, ORB_ID(vehicle_local_position)};
	uORB::SubscriptionInterval _parameter_update_sub{ORB_ID(parameter_update), 1_s};
	uORB::Subscription _attitude_sub{ORB_ID(vehicle_attitude)};
	uORB::Subscription _local_position_sub{ORB_ID(vehicle_local_position)};
	uORB::Subscription _trajectory_setpoint_sub{ORB_ID(trajectory_setpoint)};
	uORB::Subscription _pose_setpoint_sub{ORB_ID(tvmd_pose_setpoint)};
	uORB::Subscription _manual_control_sub{ORB_ID(manual_control_setpoint)};
	uORB::Subscription _control_mode_sub{ORB_ID(vehicle_control_mode)};
	uORB::Subscription _land_detected_sub{ORB_ID(vehicle_land_detected)};
	uORB::Subscription _failure_detector_sub{ORB_ID(failure_detector_status)};
	uORB::Subscription _vehicle_constraints_sub{ORB_ID(vehicle_constraints)};
	uORB::Subscription _vehicle_status_sub{ORB_ID(vehicle_status)};

	uORB::Publication<actuator_motors_s> _motors_pub{ORB_ID(actuator_motors)};
	uORB::Publication<actuator_servos_s> _servos_pub{ORB_ID(actuator_servos)};
	uORB::Publication<tvmd_control_status_s> _status_pub{ORB_ID(tvmd_control_status)};
	uORB::Publication<tvmd_pose_setpoint_s> _pose_pub{ORB_ID(tvmd_pose_setpoint)};
	uORB::Publication<vehicle_command_s> _command_pub{ORB_ID(vehicle_command)};
	uORB::Publication<vehicle_thrust_setpoint_s> _thrust_pub{ORB_ID(vehicle_thrust_setpoint)};
	uORB::PublicationData<takeoff_status_s> _takeoff_status_pub{ORB_ID(takeoff_status)};

	TakeoffHandling _takeoff{};
	vehicle_constraints_s _constraints{};
	hrt_abstime _last_law_sample{0};
	bool _ground_idle{true};  // not taken off: idle commands, no law

	vehicle_attitude_s _attitude{};
	vehicle_local_position_s _local_position{};
	vehicle_angular_velocity_s _angular_velocity{};
	trajectory_setpoint_s _trajectory_setpoint{};
	tvmd_pose_setpoint_s _pose_setpoint{};
	manual_control_setpoint_s _manual_control{};
	vehicle_control_mode_s _control_mode{};
	vehicle_land_detected_s _land_detected{};
	bool _have_attitude{false};
	bool _have_local_position{false};
	bool _have_angular_velocity{false};
	bool _landed{true};
	bool _land_requested{false};
	uint32_t _failed_agents{0};
	uint32_t _detected_failures{0};  // agents with a motor in failure_detector_status
	TvmdHover _hover{};
	TvmdFaultReport _fault{};
	float _reference_position_ned[3] {};
	float _reference_q[4] {1.f, 0.f, 0.f, 0.f};
	float _reference_yaw{NAN};  // held while the setpoint's yaw is NaN
	bool _have_reference_position{false};

	TvmdActuatorOutputs _outputs{};  // the last good actuator outputs
	bool _have_outputs{false};
	uint32_t _saturated_periods{0};
	uint32_t _config_requests{0};  // parameter changes handed to the configuration task
	uint32_t _held_periods{0};     // rate periods that sent the held outputs meanwhile

	perf_counter_t _rate_perf{perf_alloc(PC_ELAPSED, MODULE_NAME": attitude+allocation")};
	perf_counter_t _law_perf{perf_alloc(PC_ELAPSED, MODULE_NAME": law")};
	perf_counter_t _rate_interval_perf{perf_alloc(PC_INTERVAL, MODULE_NAME": rate interval")};
	perf_counter_t _reconfigure_perf{perf_alloc(PC_ELAPSED, MODULE_NAME": reconfigure")};
	tvmd_control::CycleTimer _rate_timer{};
	tvmd_control::CycleTimer _law_timer{};

	DEFINE_PARAMETERS(
		(ParamInt<px4::params::TVMD_LAW>) _param_law,
		(ParamFloat<px4::params::TVMD_POS_W>) _param_pos_w,
		(ParamFloat<px4::params::TVMD_POS_Z>) _param_pos_z,
		(ParamFloat<px4::params::TVMD_ATT_W>) _param_att_w,
		(ParamFloat<px4::params::TVMD_ATT_Z>) _param_att_z,
		(ParamFloat<px4::params::TVMD_OBS_BW>) _param_obs_bw,
		(ParamFloat<px4::params::TVMD_MAX_TRQ>) _param_max_trq,
		(ParamFloat<px4::params::TVMD_S>) _param_s,
		(ParamInt<px4::params::TVMD_ALLOC>) _param_alloc,
		(ParamInt<px4::params::TVMD_ALLOC_CAP>) _param_alloc_cap,
		(ParamFloat<px4::params::TVMD_RATE_LIM>) _param_rate_lim,
		(ParamInt<px4::params::TVMD_LAW_HZ>) _param_law_hz,
		(ParamInt<px4::params::TVMD_FAULT>) _param_fault,
		(ParamFloat<px4::params::TVMD_POSE_TOUT>) _param_pose_tout,
		(ParamFloat<px4::params::TVMD_RC_TILT>) _param_rc_tilt,
		(ParamInt<px4::params::TVMD_MOT_CURVE>) _param_mot_curve,
		(ParamInt<px4::params::TVMD_FAIL_MASK>) _param_fail_mask,
		(ParamInt<px4::params::TVMD_AG_COUNT>) _param_ag_count,
		(ParamFloat<px4::params::TVMD_AG_MASS>) _param_ag_mass,
		(ParamFloat<px4::params::TVMD_NAV_MASS>) _param_nav_mass,
		(ParamFloat<px4::params::TVMD_SIG_X>) _param_sig_x,
		(ParamFloat<px4::params::TVMD_SIG_Y>) _param_sig_y,
		(ParamFloat<px4::params::TVMD_MAX_THR>) _param_max_thr,
		(ParamFloat<px4::params::TVMD_SV_X_RNG>) _param_sv_x_rng,
		(ParamFloat<px4::params::TVMD_SV_Y_RNG>) _param_sv_y_rng
	)

	tvmd_control::AgentParamHandles _agent_params{};

	/* Last: destroyed first, so the task has ended before anything it touches goes. */
	tvmd_control::ConfigTask _config_task{};
};
