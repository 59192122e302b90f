/* Every status of the tvmd C interface that is not TVMD_OK is reported, never swallowed: each
 * is counted per stage (published in tvmd_control_status) and printed with its name, at most
 * once a second per stage unless the status changes. */
#pragma once

#include <cstdint>

#include <drivers/drv_hrt.h>
#include <px4_platform_common/log.h>

#include "tvmd.h"

namespace tvmd_control
{

enum Stage : uint8_t { LAW, ATTITUDE, ALLOCATE, OUTPUT, CONFIG, LANDED, FAILURES, STAGE_COUNT };

class StatusLog
{
public:
	/* Records `status` of `stage`; prints it when it is an error that is new, changed or a
	 * second old. */
	void record(Stage stage, TvmdStatus status)
	{
		Entry &e = _entries[stage];
		e.last = status;

		if (status == TVMD_OK) {
			return;
		}

		++e.errors;
		const hrt_abstime now = hrt_absolute_time();

		if (status != e.printed || now - e.printed_at > 1000000) {
			PX4_ERR("%s: %s (%u refused so far)", name(stage), tvmd_status_name(status),
				static_cast<unsigned>(e.errors));
			e.printed = status;
			e.printed_at = now;
		}
	}

	TvmdStatus last(Stage stage) const { return _entries[stage].last; }
	uint32_t errors(Stage stage) const { return _entries[stage].errors; }

	static const char *name(Stage stage)
	{
		switch (stage) {
		case LAW: return "law (tvmd_law)";

		case ATTITUDE: return "attitude (tvmd_attitude)";

		case ALLOCATE: return "allocation (tvmd_allocate)";

		case OUTPUT: return "outputs (tvmd_actuator_outputs)";

		case CONFIG: return "parameters (tvmd_reconfigure)";

		case LANDED: return "landed (tvmd_set_landed)";

		case FAILURES: return "failures (tvmd_set_failures)";

		default: return "?";
		}
	}

private:
	struct Entry {
		TvmdStatus last{TVMD_OK};
		TvmdStatus printed{TVMD_OK};
		hrt_abstime printed_at{0};
		uint32_t errors{0};
	};

	Entry _entries[STAGE_COUNT] {};
};

} // namespace tvmd_control
