#!/usr/bin/env python3
"""Measures a flight of tvmd_control (tvmd's PX4 module) from its ulog and tvmd-sim px4's
report, and checks it against targets.

    tvmd_control.py ULOG REPORT.px4.json [--own SUMMARY.json] [--json OUT.json]
        [--hover-rms M] [--tilt-hold M] [--roll-tolerance RAD] [--refused-at T]
        [--failed-tilt RAD] [--failed-landing M]

ULOG: PX4's log of the flight (tvmd_control_status is in it: scripts/px4-module.sh adds it to
the logger's default topics). REPORT: tvmd-sim px4's `.px4.json` (the true position in the
flight file's windows `hover` and `tilt`). SUMMARY: `tvmd-sim run scripts/px4/tvmd_control/
own-tilt.toml --summary`: tvmd-sim's own flight of the same reference, whose largest planned
roll the module's in the window `tilt` must match within --roll-tolerance. --refused-at T: a bad parameter was set
at T s; tvmd_control must have refused it (config_status TVMD_ERR_CONFIG_RELAXATION = 33 at
T + 1 s) and kept flying. A flight with an agent failure (window `failed`, from the failure to
touchdown; window `down`, standing on the ground) is checked for the agent masked
(failed_agents), the land asked by tvmd_control on the lost hover certificate (PX4 in its
land mode within 1 s of the failure), the largest true roll and pitch in `failed` within
--failed-tilt and the place it stands in `down` within --failed-landing of the target; the
masked agents' motors are NaN by design (PX4's "stopped"). Prints one line per measure; exits
1 on a missed target.
"""
import argparse
import json
import math
import sys

import numpy as np
from pyulog import ULog

TVMD_ERR_CONFIG_RELAXATION = 33
NAVIGATION_STATE_AUTO_LAND = 18  # vehicle_status.nav_state


def topic(ulog, name):
    for d in ulog.data_list:
        if d.name == name:
            return d.data
    raise SystemExit(f"error: {name} is not in the ulog (was the tree built by scripts/px4-module.sh?)")


def roll_of(data, prefix):
    w, x, y, z = (data[f"{prefix}[{i}]"] for i in range(4))
    return np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))


def window(report, name, required=True):
    for w in report.get("windows", []):
        if w["name"] == name:
            return w
    if required:
        raise SystemExit(f"error: the report has no window `{name}`")
    return None


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("ulog")
    p.add_argument("report")
    p.add_argument("--own", help="tvmd-sim's own summary of the same reference")
    p.add_argument("--json", help="write the measures here")
    p.add_argument("--hover-rms", type=float, help="largest rms position error in the hover window (m)")
    p.add_argument("--tilt-hold", type=float, help="largest position error in the tilt window (m)")
    p.add_argument("--roll-tolerance", type=float, default=0.02)
    p.add_argument("--refused-at", type=float)
    p.add_argument("--failed-tilt", type=float, help="largest true roll or pitch in the window `failed` (rad)")
    p.add_argument("--failed-landing", type=float, help="largest position error in the window `down` (m)")
    a = p.parse_args()

    ulog = ULog(a.ulog, ["tvmd_control_status", "actuator_motors", "actuator_servos", "vehicle_status"])
    report = json.load(open(a.report))
    status = topic(ulog, "tvmd_control_status")
    t = status["timestamp"] * 1e-6
    m = {}
    problems = []

    hover, tilt = window(report, "hover"), window(report, "tilt", required=False)
    failed, down = window(report, "failed", required=False), window(report, "down", required=False)
    m["hover_hold_max"], m["hover_hold_rms"] = hover["hold_max"], hover["hold_rms"]
    m["hover_height_max"] = hover["height_max"]
    m["ekf_position_max_hover"], m["ekf_attitude_max_hover"] = hover["ekf_position_max"], hover["ekf_attitude_max"]
    planned = roll_of(status, "q_planned")
    # The manoeuvre's largest planned roll is the tilt window's; the flight's (touchdown
    # included, where the team stands on the ground before PX4 detects the landing) apart.
    m["planned_roll_max_flight"] = float(np.nanmax(planned))
    m["planned_roll_max"] = m["planned_roll_max_flight"]
    if tilt is not None:
        m["tilt_hold_max"], m["tilt_roll_max"] = tilt["hold_max"], tilt["roll_max"]
        in_tilt = (t >= tilt["from"]) & (t <= tilt["to"])
        m["planned_roll_max"] = float(np.nanmax(planned[in_tilt]))
        m["force_unallocated_max_tilt"] = float(np.nanmax(status["force_unallocated"][in_tilt]))
        m["saturated_periods_tilt"] = int(np.count_nonzero(status["saturated"][in_tilt]))
    masked = int(np.bitwise_or.reduce(status["failed_agents"].astype(np.int64)))
    m["failed_agents"] = masked
    if failed is not None:
        m["failed_tilt_max"] = max(failed["roll_max"], failed["pitch_max"])
        # How long after the failure the mask reached the controller (the told failure's
        # latency: the ground station's parameter over UDP; the plant fails in the meantime).
        told = (t >= failed["from"]) & (status["failed_agents"] != 0)
        m["mask_delay"] = float(t[told][0] - failed["from"]) if told.any() else None
        in_failed = (t >= failed["from"]) & (t <= failed["to"])
        m["force_unallocated_max_failed"] = float(np.nanmax(status["force_unallocated"][in_failed]))
        m["hover_capable_after_failure"] = bool(np.all(status["hover_capable"][in_failed]))
    m["saturated_periods"] = int(status["saturated_periods"][-1])
    flying = status["landed"] == 0
    m["rate_loop_us_mean"] = float(np.mean(status["rate_loop_us"][flying]))
    m["rate_loop_us_max"] = float(np.max(status["rate_loop_us"][flying]))
    m["law_us_mean"] = float(np.mean(status["law_us"][flying]))
    m["law_us_max"] = float(np.max(status["law_us"][flying]))
    for stage in ("law", "attitude", "allocate", "output", "config"):
        m[f"{stage}_errors"] = int(status[f"{stage}_errors"][-1])

    # No non-finite output: every driven channel of the n agents (motors and servos 0 to 2n-1;
    # n is TVMD_AG_COUNT, at most 4: the others are PX4's "disarmed" NaN), and the status's
    # wrench while flying.
    agents = int(ulog.initial_parameters.get("TVMD_AG_COUNT", 4))
    m["agents"] = agents
    nonfinite = 0
    for name in ("actuator_motors", "actuator_servos"):
        d = topic(ulog, name)
        for i in range(2 * agents):
            if name == "actuator_motors" and masked & (1 << (i // 2)):
                continue  # a masked agent's motors are stopped (NaN) by design
            nonfinite += int(np.count_nonzero(~np.isfinite(d[f"control[{i}]"])))
    for key in ("force_allocated", "torque_allocated", "force_requested", "torque_requested"):
        nonfinite += sum(int(np.count_nonzero(~np.isfinite(status[f"{key}[{i}]"][flying]))) for i in range(3))
    m["nonfinite_outputs"] = nonfinite

    vs = topic(ulog, "vehicle_status")
    if failed is not None:
        tv = vs["timestamp"] * 1e-6
        landing = (tv >= failed["from"]) & (vs["nav_state"] == NAVIGATION_STATE_AUTO_LAND)
        m["land_mode_after_failure"] = float(tv[landing][0] - failed["from"]) if landing.any() else None
    if down is not None:
        m["landed_position_error"] = down["hold_max"]
    m["armed"] = bool(np.any(vs["arming_state"] == 2))
    m["disarmed_at_end"] = bool(vs["arming_state"][-1] == 1)

    if a.own:
        own = json.load(open(a.own))["summary"]["max_planned_roll"]
        m["own_planned_roll_max"] = own
        m["planned_roll_difference"] = abs(m["planned_roll_max"] - own)
        if m["planned_roll_difference"] > a.roll_tolerance:
            problems.append(f"planned roll {m['planned_roll_max']:.4f} rad, tvmd-sim's own {own:.4f} rad: "
                            f"more than {a.roll_tolerance} rad apart")
    if a.refused_at is not None:
        after = (t >= a.refused_at + 1.0) & (t <= a.refused_at + 2.0)
        m["refused_status"] = int(status["config_status"][after][0]) if after.any() else None
        if m["refused_status"] != TVMD_ERR_CONFIG_RELAXATION or m["config_errors"] < 1:
            problems.append(f"the bad parameter at {a.refused_at} s was not refused "
                            f"(config_status {m['refused_status']}, config_errors {m['config_errors']})")
    if not m["armed"] or m["hover_height_max"] < 1.3:
        problems.append("not airborne: never armed or never above 1.3 m in the hover window")
    if not m["disarmed_at_end"]:
        problems.append("not landed and disarmed at the end")
    if a.hover_rms is not None and m["hover_hold_rms"] > a.hover_rms:
        problems.append(f"hover rms error {m['hover_hold_rms']:.4f} m above {a.hover_rms} m")
    if a.failed_tilt is not None or a.failed_landing is not None:
        if failed is None or down is None or masked == 0:
            problems.append("no agent was masked, or the report has no windows `failed` and `down`")
        else:
            if m["land_mode_after_failure"] is None or m["land_mode_after_failure"] > 1.0:
                problems.append(f"PX4 not in its land mode within 1 s of the failure ({m['land_mode_after_failure']})")
            if a.failed_tilt is not None and m["failed_tilt_max"] > a.failed_tilt:
                problems.append(f"tilt after the failure {m['failed_tilt_max']:.4f} rad above {a.failed_tilt} rad")
            if a.failed_landing is not None and m["landed_position_error"] > a.failed_landing:
                problems.append(f"landed {m['landed_position_error']:.4f} m from the target, above {a.failed_landing} m")
    if a.tilt_hold is not None and tilt is not None and m["tilt_hold_max"] > a.tilt_hold:
        problems.append(f"tilt position error {m['tilt_hold_max']:.4f} m above {a.tilt_hold} m")
    if m["nonfinite_outputs"]:
        problems.append(f"{m['nonfinite_outputs']} non-finite outputs")
    for stage in ("law", "attitude", "allocate", "output"):
        if m[f"{stage}_errors"]:
            problems.append(f"{m[stage + '_errors']} refused {stage} periods")

    for k, v in m.items():
        print(f"{k:<28} {v:.4f}" if isinstance(v, float) and math.isfinite(v) else f"{k:<28} {v}")
    if a.json:
        json.dump(m, open(a.json, "w"), indent=1)
    for problem in problems:
        print(f"error: {problem}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
