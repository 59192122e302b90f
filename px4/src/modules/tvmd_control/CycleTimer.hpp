/* The time a stage takes, in wall-clock microseconds. PX4's perf counters read hrt time, which
 * in SITL's lockstep is the simulated clock: there every cycle reads 0 us. This timer reads the
 * host's steady clock in SITL and hrt on a flight controller (where the two agree), so that
 * `tvmd_control status` and tvmd_control_status give a cycle time in SITL too. */
#pragma once

#include <cstdint>

#if defined(__PX4_NUTTX)
#include <drivers/drv_hrt.h>
#else
#include <chrono>
#endif

namespace tvmd_control
{

class CycleTimer
{
public:
	void begin() { _start = now_ns(); }

	void end()
	{
		const float us = static_cast<float>(now_ns() - _start) * 1e-3f;
		_last_us = us;
		_max_us = us > _max_us ? us : _max_us;
		_sum_us += static_cast<double>(us);
		++_count;
	}

	float last_us() const { return _last_us; }
	float max_us() const { return _max_us; }
	float mean_us() const { return _count > 0 ? static_cast<float>(_sum_us / static_cast<double>(_count)) : 0.f; }
	uint32_t count() const { return _count; }

private:
	static uint64_t now_ns()
	{
#if defined(__PX4_NUTTX)
		return static_cast<uint64_t>(hrt_absolute_time()) * 1000u;
#else
		return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
						     std::chrono::steady_clock::now().time_since_epoch()).count());
#endif
	}

	uint64_t _start{0};
	float _last_us{0.f};
	float _max_us{0.f};
	double _sum_us{0.0};
	uint32_t _count{0};
};

} // namespace tvmd_control
