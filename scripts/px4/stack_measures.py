#!/usr/bin/env python3
"""The measures of a flight window, the same for tvmd_control and for the authors' modules, from
the flight's ulog and tvmd-sim px4's report (the truth); used by side_by_side.py.

    stack_measures.py STACK ULOG REPORT.px4.json [--failure T] [--json OUT]

STACK: `tvmd` (tvmd_control, airframe 4090: its status topic tvmd_control_status) or `authors`
(their modules, airframe 4007: attitude_planner_meta_data, control_allocation_meta_data and
control_allocator_status). For each of the report's windows `hover` and `tilt`:
  - from the report (the plant's truth): the hold against the window's target (rms, largest),
    the roll flown (mean, standard deviation, largest), EKF2's largest position error;
  - from PX4's ground-truth topics in the ulog: the true height's range, and the roll held
    (mean and standard deviation over the window's last 4 s: tvmd_control's tilt window starts
    with its stick, the authors' 2 s after theirs);
  - from the ulog: the planned roll, largest (tvmd_control's q_planned; the authors' planner's
    q_d); the unallocated force, largest (tvmd_control's e_f; the authors' allocator's asked
    force less its allocated one, N); the saturated periods: tvmd_control's rate-loop periods with an agent held by a limit (its
    counter saturated_periods over the window, of 250 a second), the authors' allocation periods
    whose redistribution stopped at an agent's boundary (the first increment of
    control_allocation_meta_data below 1, one record a period), and as a cross-check the share
    of control_allocator_status samples (logged every 200 ms) with an actuator saturated;
    the seconds of the window the logger dropped (`unlogged`: the authors' allocation records
    are the logged ones).
With --failure T (an agent lost at T s): the largest tilt (the body's z axis from the vertical)
in the 10 s after it and over the rest of the flight, the largest horizontal distance from the
hover point after it, when the tilt first passed 90 degrees (the vehicle lost: upside down),
when it reached the ground (true height below 0.1 m), how it ended (height, tilt, speed,
disarmed). Prints JSON. Needs numpy and pyulog.
"""
import argparse
import json
import math
import sys

import numpy as np
from pyulog import ULog

from analyze import EARTH_RADIUS, quat_rows, roll_of, seconds, topic

RATE_LOOP_HZ = 250.0  # tvmd_control's rate loop: every gyro sample in SITL
HELD = 4.0  # s: the end of a window where the roll is held (the tilt windows' stick came 2-4 s before)


def tilt_of(q):
    """The angle of the body's z axis from the vertical (rad)."""
    n = np.linalg.norm(q, axis=1)
    x, y = q[:, 1] / n, q[:, 2] / n
    return np.arccos(np.clip(1 - 2 * (x * x + y * y), -1.0, 1.0))


def windows(report):
    return {w["name"]: w for w in report.get("windows", [])}


class Truth:
    """PX4's ground-truth topics (the plant's state as the bridge sends it), NED from the start."""

    def __init__(self, ulog):
        gpos, att = topic(ulog, "vehicle_global_position_groundtruth"), topic(ulog, "vehicle_attitude_groundtruth")
        if gpos is None or att is None:
            raise SystemExit("error: the ulog has no ground-truth topics")
        self.t = seconds(gpos)
        lat0, lon0, alt0 = gpos["lat"][0], gpos["lon"][0], gpos["alt"][0]
        north = np.radians(gpos["lat"] - lat0) * EARTH_RADIUS
        east = np.radians(gpos["lon"] - lon0) * EARTH_RADIUS * math.cos(math.radians(lat0))
        self.ne = np.stack([north, east], axis=1)
        self.height = gpos["alt"] - alt0
        self.t_att = seconds(att)
        self.tilt = tilt_of(quat_rows(att))
        self.roll = roll_of(quat_rows(att))

    def heights(self, t0, t1):
        h = self.height[(self.t >= t0) & (self.t <= t1)]
        return (float(h.min()), float(h.max())) if len(h) else (None, None)


def tvmd_window(ulog, t0, t1):
    status = topic(ulog, "tvmd_control_status")
    if status is None:
        raise SystemExit("error: no tvmd_control_status in the ulog")
    t = seconds(status)
    inside = (t >= t0) & (t <= t1)
    before = t < t0
    count = status["saturated_periods"].astype(np.int64)
    start = int(count[before][-1]) if before.any() else 0
    saturated = int(count[inside][-1]) - start if inside.any() else None
    return {
        "planned_roll_max": float(np.nanmax(np.abs(roll_of(quat_rows(status, "q_planned")[inside])))),
        "unallocated_force_max": float(np.nanmax(status["force_unallocated"][inside])),
        "saturated_periods": saturated,
        "periods": int(round((t1 - t0) * RATE_LOOP_HZ)),
    }


def authors_window(ulog, t0, t1):
    out = {}
    planner = topic(ulog, "attitude_planner_meta_data")
    if planner is not None:
        tp = seconds(planner)
        qd = quat_rows(planner, "q_d")[(tp >= t0) & (tp <= t1)]
        out["planned_roll_max"] = float(np.abs(roll_of(qd)).max()) if len(qd) else None
    meta = topic(ulog, "control_allocation_meta_data")
    if meta is not None:
        tm = seconds(meta)
        sel = (tm >= t0) & (tm <= t1)
        asked = np.stack([meta[f"control_sp[{i}]"][sel] for i in range(3, 6)], axis=1)
        got = np.stack([meta[f"allocated_control[{i}]"][sel] for i in range(3, 6)], axis=1)
        out["unallocated_force_max"] = float(np.linalg.norm(asked - got, axis=1).max()) if len(asked) else None
        # The redistribution's first step is capped at 1 (the whole request): below it an agent
        # reached its boundary and the period ended saturated.
        first = meta["increment[0]"][sel]
        out["saturated_periods"] = int(np.count_nonzero(first < 1.0 - 1e-6))
        out["periods"] = int(np.count_nonzero(sel))
    cas = topic(ulog, "control_allocator_status")
    if cas is not None:
        tc = seconds(cas)
        sel = (tc >= t0) & (tc <= t1)
        sat = np.stack([cas[f"actuator_saturation[{i}]"][sel] for i in range(16)], axis=1)
        out["status_saturated_samples"] = int(np.count_nonzero((sat != 0).any(axis=1)))
        out["status_samples"] = int(np.count_nonzero(sel))
    return out


def unlogged(ulog, t0, t1):
    """Seconds of [t0, t1] the logger dropped (its buffer full: a loaded machine's disk)."""
    return sum(max(0.0, min(t1, d.timestamp * 1e-6 + d.duration * 1e-3) - max(t0, d.timestamp * 1e-6))
               for d in ulog.dropouts)


def window_measures(stack, ulog, truth, w):
    m = {key: w.get(key) for key in ("from", "to", "hold_rms", "hold_max", "roll_mean", "roll_std", "roll_max",
                                       "ekf_position_max", "height_max")}
    m["height_min"], _ = truth.heights(w["from"], w["to"])
    # The roll held: the window's last HELD seconds (the roll-in before them), from the truth.
    held = (truth.t_att >= w["to"] - HELD) & (truth.t_att <= w["to"])
    m["roll_held_mean"], m["roll_held_std"] = float(truth.roll[held].mean()), float(truth.roll[held].std())
    m["unlogged"] = unlogged(ulog, w["from"], w["to"])
    m.update((tvmd_window if stack == "tvmd" else authors_window)(ulog, w["from"], w["to"]))
    return m


def failure_measures(ulog, truth, t_fail, hover_point=(0.0, 0.0)):
    after = truth.t_att >= t_fail
    tilt, ta = truth.tilt[after], truth.t_att[after]
    first10 = ta <= t_fail + 10.0
    m = {"failure_at": t_fail,
         "tilt_max_10s": float(tilt[first10].max()),
         "tilt_max": float(tilt.max())}
    over = np.nonzero(tilt > math.pi / 2)[0]
    m["upside_down_after"] = float(ta[over[0]] - t_fail) if len(over) else None
    gafter = truth.t >= t_fail
    tg, h = truth.t[gafter], truth.height[gafter]
    dist = np.linalg.norm(truth.ne[gafter] - np.array(hover_point), axis=1)
    ground = np.nonzero(h < 0.1)[0]
    m["ground_after"] = float(tg[ground[0]] - t_fail) if len(ground) else None
    m["ground_distance"] = float(dist[ground[0]]) if len(ground) else None
    m["horizontal_error_max_10s"] = float(dist[tg <= t_fail + 10.0].max())
    m["horizontal_error_max"] = float(dist.max())
    m["end_height"] = float(h[-1])
    m["end_tilt"] = float(tilt[-1])
    m["end_distance"] = float(dist[-1])
    if len(tg) > 10:
        step = np.linalg.norm(np.append(truth.ne[gafter][-1] - truth.ne[gafter][-10], h[-1] - h[-10]))
        m["end_speed"] = float(step / (tg[-1] - tg[-10]))
    status = topic(ulog, "vehicle_status")
    m["disarmed_at_end"] = bool(status["arming_state"][-1] == 1) if status is not None else None
    if status is not None:
        ts = seconds(status)
        disarm = np.nonzero((ts >= t_fail) & (status["arming_state"] == 1))[0]
        m["disarmed_after"] = float(ts[disarm[0]] - t_fail) if len(disarm) else None
    return m


def measure(stack, ulog_path, report_path, failure=None):
    ulog = ULog(ulog_path)
    report = json.load(open(report_path))
    truth = Truth(ulog)
    ws = windows(report)
    out = {"stack": stack, "ulog": ulog_path}
    for name in ("hover", "tilt"):
        if name in ws:
            out[name] = window_measures(stack, ulog, truth, ws[name])
    if failure is not None:
        out["failure"] = failure_measures(ulog, truth, failure)
        if "failed" in ws:
            out["failure"]["roll_pitch_max_10s"] = max(ws["failed"]["roll_max"], ws["failed"]["pitch_max"])
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("stack", choices=("tvmd", "authors"))
    p.add_argument("ulog")
    p.add_argument("report")
    p.add_argument("--failure", type=float, metavar="T", help="an agent was lost at T s")
    p.add_argument("--json")
    a = p.parse_args()
    m = measure(a.stack, a.ulog, a.report, a.failure)
    text = json.dumps(m, indent=1)
    print(text)
    if a.json:
        with open(a.json, "w") as f:
            f.write(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
