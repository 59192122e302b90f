/* tvmd_control's configuration: the parameters to a tvmd configuration and actuator map, in
 * the configuration task (ConfigTask.hpp), which holds the handle meanwhile. */
#include "TvmdControl.hpp"

#include <px4_platform_common/log.h>

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
