#!/usr/bin/env python3
"""Measures a PX4 flight from its ulog (PX4's estimate against its ground-truth topics) and checks
what the flight must show; the same measures for a flight on tvmd-sim and on PX4's SIH.

    analyze.py FLIGHT.ulg --hover A B [--step C D --step-north 1.0] [--tilt E F --tilt-min R]
               [--expect-flight] [--json OUT]

Positions are relative to where the vehicle was armed: the hover target is 1.5 m (--height)
above it, the step target `--step-north` metres north of that. Prints a JSON report; with
--expect-flight exits 1 unless the flight armed, flew (above 1 m), raised no failsafe and
no estimator failure flag while armed, and landed (on the ground and disarmed at the end);
with --tilt, unless the mean true roll over the tilt window reached --tilt-min and held.
Needs pyulog (pip install pyulog).
"""
import argparse
import json
import math
import sys

import numpy as np
from pyulog import ULog

EARTH_RADIUS = 6371000.0


def topic(ulog, name):
    for d in ulog.data_list:
        if d.name == name and d.multi_id == 0:
            return d.data
    return None


def seconds(data):
    return data["timestamp"] * 1e-6


def at(t_from, values, t_to):
    """`values` (sampled at t_from) at the times t_to (previous sample)."""
    k = np.clip(np.searchsorted(t_from, t_to, side="right") - 1, 0, len(t_from) - 1)
    return values[k]


def ned_from(lat, lon, alt, lat0, lon0, alt0):
    north = np.radians(lat - lat0) * EARTH_RADIUS
    east = np.radians(lon - lon0) * EARTH_RADIUS * math.cos(math.radians(lat0))
    return np.stack([north, east, -(alt - alt0)], axis=1)


def quat_rows(data):
    return np.stack([data[f"q[{i}]"] for i in range(4)], axis=1)


def angle_between(q1, q2):
    dot = np.abs(np.sum(q1 * q2, axis=1)) / (np.linalg.norm(q1, axis=1) * np.linalg.norm(q2, axis=1))
    return 2 * np.arccos(np.clip(dot, -1.0, 1.0))


def roll_of(q):
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("ulog")
    p.add_argument("--hover", nargs=2, type=float, required=True, metavar=("FROM", "TO"))
    p.add_argument("--height", type=float, default=1.5)
    p.add_argument("--step", nargs=2, type=float, metavar=("FROM", "TO"))
    p.add_argument("--step-north", type=float, default=1.0)
    p.add_argument("--tilt", nargs=2, type=float, metavar=("FROM", "TO"))
    p.add_argument("--tilt-min", type=float, default=0.0)
    p.add_argument("--expect-flight", action="store_true")
    p.add_argument("--json")
    a = p.parse_args()

    u = ULog(a.ulog)
    status = topic(u, "vehicle_status")
    gpos, gpos_gt = topic(u, "vehicle_global_position"), topic(u, "vehicle_global_position_groundtruth")
    att, att_gt = topic(u, "vehicle_attitude"), topic(u, "vehicle_attitude_groundtruth")
    land = topic(u, "vehicle_land_detected")
    setpoint = topic(u, "vehicle_attitude_setpoint")
    flags = topic(u, "failsafe_flags")
    if any(x is None for x in (status, gpos, gpos_gt, att, att_gt, land)):
        sys.exit(f"{a.ulog}: a topic is missing (vehicle_status, vehicle_global_position(_groundtruth), "
                 "vehicle_attitude(_groundtruth), vehicle_land_detected)")

    t_status = seconds(status)
    armed = status["arming_state"] == 2
    arm_t = float(t_status[np.argmax(armed)]) if armed.any() else None
    t_gt = seconds(gpos_gt)
    origin = (gpos_gt["lat"][0], gpos_gt["lon"][0], gpos_gt["alt"][0])
    truth = ned_from(gpos_gt["lat"], gpos_gt["lon"], gpos_gt["alt"], *origin)
    start = at(t_gt, truth, np.array([arm_t if arm_t is not None else t_gt[0]]))[0]
    truth -= start
    t_est = seconds(gpos)
    est = ned_from(gpos["lat"], gpos["lon"], gpos["alt"], *origin) - start
    t_att, t_att_gt = seconds(att), seconds(att_gt)
    q_est, q_gt = quat_rows(att), quat_rows(att_gt)

    def window(t0, t1, target):
        inside = (t_gt >= t0) & (t_gt <= t1)
        pos = truth[inside]
        dist = np.linalg.norm(pos - target, axis=1)
        out = {"from": t0, "to": t1, "hold_max": float(dist.max()), "hold_rms": float(np.sqrt(np.mean(dist ** 2)))}
        outside = np.nonzero(dist > 0.1)[0]
        times = t_gt[inside]
        if len(outside) == 0:
            out["settling_time"] = 0.0
        elif outside[-1] + 1 < len(times):
            out["settling_time"] = float(times[outside[-1] + 1] - t0)
        else:
            out["settling_time"] = None
        te = t_est[(t_est >= t0) & (t_est <= t1)]
        err = np.linalg.norm(est[(t_est >= t0) & (t_est <= t1)] - at(t_gt, truth, te), axis=1)
        out["ekf_position_max"] = float(err.max())
        out["ekf_position_rms"] = float(np.sqrt(np.mean(err ** 2)))
        ta = t_att[(t_att >= t0) & (t_att <= t1)]
        aerr = angle_between(q_est[(t_att >= t0) & (t_att <= t1)], at(t_att_gt, q_gt, ta))
        out["ekf_attitude_max"] = float(aerr.max())
        out["ekf_attitude_rms"] = float(np.sqrt(np.mean(aerr ** 2)))
        roll = roll_of(q_gt[(t_att_gt >= t0) & (t_att_gt <= t1)])
        out["roll_mean"], out["roll_std"] = float(roll.mean()), float(roll.std())
        out["roll_max"] = float(np.abs(roll).max())
        if setpoint is not None and "q_d[0]" in setpoint:
            ts = seconds(setpoint)
            sel = (ts >= t0) & (ts <= t1)
            qd = np.stack([setpoint[f"q_d[{i}]"][sel] for i in range(4)], axis=1)
            if len(qd):
                out["planned_roll_max"] = float(np.abs(roll_of(qd)).max())
                out["planned_roll_mean"] = float(roll_of(qd).mean())
        return out

    report = {"ulog": a.ulog, "armed_at": arm_t}
    report["hover"] = window(*a.hover, np.array([0.0, 0.0, -a.height]))
    if a.step:
        report["step"] = window(*a.step, np.array([a.step_north, 0.0, -a.height]))
        inside = (t_gt >= a.step[0]) & (t_gt <= a.step[1])
        north = truth[inside][:, 0]
        report["step"]["overshoot"] = float(max(0.0, north.max() - a.step_north))
        reached = np.nonzero(north >= 0.9 * a.step_north)[0]
        # Rise time: from the step's command to 90 % of the way (a noise-independent measure).
        report["step"]["rise_time_90"] = float(t_gt[inside][reached[0]] - a.step[0]) if len(reached) else None
    if a.tilt:
        report["tilt"] = window(*a.tilt, np.array([0.0, 0.0, -a.height]))
    height = -truth[:, 2]
    report["max_height"] = float(height.max())
    report["final_height"] = float(height[-1])
    fs = status["failsafe"][armed] if armed.any() else np.array([])
    report["failsafe_while_armed"] = bool(fs.any())
    bad_flags = []
    if flags is not None:
        t_flags = seconds(flags)
        armed_at_flags = at(t_status, armed, t_flags)
        for key in ("attitude_invalid", "angular_velocity_invalid", "local_position_invalid",
                    "local_altitude_invalid", "local_velocity_invalid", "global_position_invalid"):
            if key in flags and (flags[key][armed_at_flags] > 0).any():
                bad_flags.append(key)
    report["estimator_failure_flags_while_armed"] = bad_flags
    report["landed_at_end"] = bool(land["landed"][-1])
    report["armed_at_end"] = bool(armed[-1])

    text = json.dumps(report, indent=2)
    print(text)
    if a.json:
        with open(a.json, "w") as f:
            f.write(text + "\n")
    problems = []
    if a.expect_flight:
        if arm_t is None:
            problems.append("never armed")
        if report["max_height"] < 1.0:
            problems.append(f"never airborne above 1 m (max {report['max_height']:.2f} m)")
        if report["failsafe_while_armed"]:
            problems.append("a failsafe while armed")
        if bad_flags:
            problems.append(f"estimator failure flags while armed: {bad_flags}")
        if not report["landed_at_end"] or report["armed_at_end"] or report["final_height"] > 0.2:
            problems.append("not landed and disarmed at the end")
    if a.tilt:
        tilt = report["tilt"]
        if abs(tilt["roll_mean"]) < a.tilt_min:
            problems.append(f"tilt not reached: mean roll {tilt['roll_mean']:.3f} rad < {a.tilt_min}")
        if tilt["roll_std"] > 0.05:
            problems.append(f"tilt not held: roll std {tilt['roll_std']:.3f} rad")
    for msg in problems:
        print(f"FAIL: {a.ulog}: {msg}", file=sys.stderr)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
