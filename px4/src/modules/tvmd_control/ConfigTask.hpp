/* tvmd_control's configuration off the rate_ctrl work queue. A parameter change runs
 * tvmd_reconfigure, the creation tvmd_create, and both build a configuration with
 * tvmd_config_default: 3,620 B, 3,596 B and 3,044 B of stack on the Cortex-M4F at the 4-agent
 * capacity (docs/c-interface.md, Stack), more than NuttX's rate_ctrl queue has (3,150 B), and
 * no stock work queue but the estimator's (INS0-3, 6,000 B) has enough. So the configuration
 * runs in a task of the module's own (PX4's px4_task_spawn_cmd, STACK_SIZE B), and the
 * controller handle, which is not thread-safe, changes hands instead of being shared: the
 * rate_ctrl items hand it to the task with request() and stop calling into it; the task
 * configures and says done(); the rate loop takes it back with take_back(). One atomic state
 * (sequentially consistent) orders the two sides, so whatever the task wrote (the handle, the
 * configuration, the map, the hover certificate, the status log) is seen whole by the rate
 * loop after take_back(). Meanwhile the rate loop publishes the last mapped outputs (the held
 * commands) and the law waits. */
#pragma once

#include <px4_platform_common/atomic.h>
#include <px4_platform_common/log.h>
#include <px4_platform_common/sem.h>
#include <px4_platform_common/tasks.h>

namespace tvmd_control
{

class ConfigTask
{
public:
	/* tvmd_reconfigure's 3,620 B, about 1 KB of the module's own frame around it (the 624-B
	 * TvmdConfig, the 172-B actuator map, the settings) and PX4_INFO's formatting. */
	static constexpr int STACK_SIZE = 6000;

	enum State : int {
		IDLE = 0,       // the rate loop holds the handle
		REQUESTED = 1,  // handed to the task: configure
		DONE = 2,       // configured: the rate loop takes it back
	};

	ConfigTask()
	{
		px4_sem_init(&_wake, 0, 0);
		px4_sem_init(&_finished, 0, 0);
		px4_sem_setprotocol(&_wake, SEM_PRIO_NONE);
		px4_sem_setprotocol(&_finished, SEM_PRIO_NONE);
	}

	~ConfigTask()
	{
		stop();
		px4_sem_destroy(&_wake);
		px4_sem_destroy(&_finished);
	}

	ConfigTask(const ConfigTask &) = delete;
	ConfigTask &operator=(const ConfigTask &) = delete;

	/* Spawns the task with the first request (the creation) pending, and waits until it is
	 * done: the caller then takes the handle back. False if the task could not start. */
	bool start(px4_main_t entry)
	{
		_state.store(REQUESTED);
		_task = px4_task_spawn_cmd("tvmd_control_cfg", SCHED_DEFAULT, SCHED_PRIORITY_POSITION_CONTROL, STACK_SIZE,
					   entry, nullptr);

		if (_task < 0) {
			_task = -1;
			return false;
		}

		px4_sem_post(&_wake);

		while (_state.load() != DONE) {
			px4_sem_wait(&_finished);
		}

		return true;
	}

	/* Ends the task (after the configuration it runs, if any) and waits for it. */
	void stop()
	{
		if (_task < 0) {
			return;
		}

		_exit.store(true);
		px4_sem_post(&_wake);

		while (!_exited.load()) {
			px4_sem_wait(&_finished);
		}

		_task = -1;
	}

	/* The rate loop's side. */
	State state() const { return static_cast<State>(_state.load()); }
	void request()
	{
		_state.store(REQUESTED);
		px4_sem_post(&_wake);
	}
	void take_back() { _state.store(IDLE); }

	/* The task's side: blocks until a request (true) or the end (false). */
	bool wait_for_request()
	{
		for (;;) {
			if (_exit.load()) {
				return false;
			}

			if (_state.load() == REQUESTED) {
				return true;
			}

			px4_sem_wait(&_wake);
		}
	}
	void done()
	{
		_state.store(DONE);
		px4_sem_post(&_finished);
	}
	void exited()
	{
		_exited.store(true);
		px4_sem_post(&_finished);
	}

private:
	px4_sem_t _wake;
	px4_sem_t _finished;
	px4::atomic<int> _state{IDLE};
	px4::atomic<bool> _exit{false};
	px4::atomic<bool> _exited{false};
	int _task{-1};
};

} // namespace tvmd_control
