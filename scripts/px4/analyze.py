#!/usr/bin/env python3
"""Measures a PX4 flight from its ulog (PX4's estimate against its ground-truth topics) and checks
what the flight must show; the same measures for a flight on tvmd-sim and on PX4's SIH.

    analyze.py FLIGHT.ulg --hover A B [--step C D --step-north 1.0] [--tilt E F --tilt-min R]
               [--expect-flight | --expect-airborne] [--tilt-held STD] [--tilt-height M] [--json OUT]

Positions are relative to where the vehicle was armed: the hover target is 1.5 m (--height)
above it, the step target `--step-north` metres north of that. Prints a JSON report; with
--expect-flight exits 1 unless the flight armed, flew (above 1 m), raised no failsafe and
no estimator failure flag while armed, and landed (on the ground when it disarmed, and at the end);
--expect-airborne checks all but the landing; with --tilt, exits 1 unless the mean true roll
over the tilt window reached --tilt-min (and with --tilt-held, its standard deviation stayed
below it; with --tilt-height, the height stayed that close to the hover's mean height).
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


def param_at(ulog, name, t):
    """A parameter's value in force at time t (s): its last change before t, else its value at boot."""
    value = ulog.initial_parameters.get(name)
    for stamp, key, changed in ulog.changed_parameters:
        if key == name and stamp * 1e-6 <= t:
            value = changed
    return value


def quat_rows(data, prefix="q"):
    return np.stack([data[f"{prefix}[{i}]"] for i in range(4)], axis=1)


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
    p.add_argument("--tilt-held", type=float, help="largest roll standard deviation over the tilt window")
    p.add_argument("--tilt-height", type=float,
                   help="largest distance of the height in the tilt window from the hover's mean height (m)")
    p.add_argument("--expect-flight", action="store_true")
    p.add_argument("--expect-airborne", action="store_true",
                   help="only: armed, above 1 m, no failsafe or estimator failure flag while armed")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter PX4 must hold from arming on (e.g. one the flight sets)")
    p.add_argument("--json")
    a = p.parse_args()

    u = ULog(a.ulog)
    status = topic(u, "vehicle_status")
    gpos, gpos_gt = topic(u, "vehicle_global_position"), topic(u, "vehicle_global_position_groundtruth")
    att, att_gt = topic(u, "vehicle_attitude"), topic(u, "vehicle_attitude_groundtruth")
    land = topic(u, "vehicle_land_detected")
    setpoint = topic(u, "vehicle_attitude_setpoint")
    flags = topic(u, "failsafe_flags")
    planner = topic(u, "attitude_planner_meta_data")
    allocation = topic(u, "control_allocation_meta_data")
    servos = topic(u, "actuator_servos")
    if any(x is None for x in (status, gpos, gpos_gt, att, att_gt)):
        sys.exit(f"{a.ulog}: a topic is missing (vehicle_status, vehicle_global_position(_groundtruth), "
                 "vehicle_attitude(_groundtruth))")

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
        out = {"from": t0, "to": t1, "hold_max": float(dist.max()), "hold_rms": float(np.sqrt(np.mean(dist ** 2))),
               "height_min": float(-pos[:, 2].max()), "height_max": float(-pos[:, 2].min()),
               "height_mean": float(-pos[:, 2].mean())}
        outside = np.nonzero(dist > 0.1)[0]
        times = t_gt[inside]
        if len(outside) == 0:
            out["settling_time"] = 0.0
        elif outside[-1] + 1 < len(times):
            out["settling_time"] = float(times[outside[-1] + 1] - t0)
        else:
            out["settling_time"] = None
        # The hold PX4 believes it flies (its estimate against the target): the truth's hold
        # minus this is what the estimated state costs the tracking.
        est_in = est[(t_est >= t0) & (t_est <= t1)]
        est_dist = np.linalg.norm(est_in - target, axis=1)
        out["hold_max_estimated"] = float(est_dist.max())
        out["hold_rms_estimated"] = float(np.sqrt(np.mean(est_dist ** 2)))
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
        # The planned attitude: the authors' planner publishes it in attitude_planner_meta_data,
        # PX4's stack in vehicle_attitude_setpoint.
        planned = planner if planner is not None else setpoint
        if planned is not None and "q_d[0]" in planned:
            ts = seconds(planned)
            sel = (ts >= t0) & (ts <= t1)
            qd = np.stack([planned[f"q_d[{i}]"][sel] for i in range(4)], axis=1)
            if len(qd):
                out["planned_roll_max"] = float(np.abs(roll_of(qd)).max())
                out["planned_roll_mean"] = float(roll_of(qd).mean())
        if allocation is not None:
            ta_ = seconds(allocation)
            sel = (ta_ >= t0) & (ta_ <= t1)
            asked = np.stack([allocation[f"control_sp[{i}]"][sel] for i in range(3, 6)], axis=1)
            got = np.stack([allocation[f"allocated_control[{i}]"][sel] for i in range(3, 6)], axis=1)
            if len(asked):
                # The authors' allocator's force it could not allocate (N, body frame).
                out["unallocated_force_max"] = float(np.linalg.norm(asked - got, axis=1).max())
                # The share of the asked change its redistribution allocated (the sum of its
                # increments, 1: all; it stops when an agent saturates and the rest lose rank).
                inc = np.stack([allocation[f"increment[{i}]"][sel] for i in range(4)], axis=1)
                out["allocated_share_min"] = float(np.where(inc > 0, inc, 0).sum(axis=1).min())
        if servos is not None:
            tv = seconds(servos)
            sel = (tv >= t0) & (tv <= t1)
            # Servo i's command in [-1, 1] spans CA_SV_TLi_MINA..MAXA (deg): even i eta_x, odd eta_y.
            largest = [0.0, 0.0]
            for i in range(8):
                lo = param_at(u, f"CA_SV_TL{i}_MINA", t0)
                hi = param_at(u, f"CA_SV_TL{i}_MAXA", t0)
                if lo is None or hi is None or not sel.any():
                    continue
                deg = np.abs(servos[f"control[{i}]"][sel]) * (hi - lo) / 2
                largest[i % 2] = max(largest[i % 2], float(np.nanmax(deg)))
            out["gimbal_command_max_deg"] = largest
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
        tilt = report["tilt"] = window(*a.tilt, np.array([0.0, 0.0, -a.height]))
        hover_height = report["hover"]["height_mean"]
        tilt["height_off_hover_max"] = max(hover_height - tilt["height_min"], tilt["height_max"] - hover_height)
    height = -truth[:, 2]
    report["max_height"] = float(height.max())
    report["final_height"] = float(height[-1]) + 0.0
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
    # Without PX4's land detector (the authors' airframe runs none): on the ground at the end.
    report["landed_at_end"] = bool(land["landed"][-1]) if land is not None else report["final_height"] < 0.2
    report["armed_at_end"] = bool(armed[-1])
    # Where it was when it disarmed (a disarm in the air would fall and still end on the ground).
    disarms = np.nonzero(armed[:-1] & ~armed[1:])[0]
    report["height_at_disarm"] = (float(-at(t_gt, truth, t_status[disarms[-1:] + 1])[0, 2]) + 0.0
                                  if len(disarms) else None)

    text = json.dumps(report, indent=2)
    print(text)
    if a.json:
        with open(a.json, "w") as f:
            f.write(text + "\n")
    problems = []
    if a.expect_flight or a.expect_airborne:
        if arm_t is None:
            problems.append("never armed")
        if report["max_height"] < 1.0:
            problems.append(f"never airborne above 1 m (max {report['max_height']:.2f} m)")
        if report["failsafe_while_armed"]:
            problems.append("a failsafe while armed")
        if bad_flags:
            problems.append(f"estimator failure flags while armed: {bad_flags}")
        at_disarm = report["height_at_disarm"]
        if a.expect_flight and (not report["landed_at_end"] or report["armed_at_end"] or report["final_height"] > 0.2
                                or at_disarm is None or at_disarm > 0.2):
            problems.append(f"not landed and disarmed at the end (height at the disarm: {at_disarm})")
    for item in a.param:
        name, _, want = item.partition("=")
        got = param_at(u, name, arm_t if arm_t is not None else 0.0)
        if got is None or abs(float(got) - float(want)) > 1e-6:
            problems.append(f"parameter {name} is {got} at arming, expected {want}")
    if a.tilt:
        tilt = report["tilt"]
        if abs(tilt["roll_mean"]) < a.tilt_min:
            problems.append(f"tilt not reached: mean roll {tilt['roll_mean']:.3f} rad < {a.tilt_min}")
        if a.tilt_held is not None and tilt["roll_std"] > a.tilt_held:
            problems.append(f"tilt not held: roll std {tilt['roll_std']:.3f} rad > {a.tilt_held}")
        if a.tilt_height is not None and tilt["height_off_hover_max"] > a.tilt_height:
            problems.append(f"height not held in the tilt: {tilt['height_min']:.2f}-{tilt['height_max']:.2f} m "
                            f"against {report['hover']['height_mean']:.2f} m in the hover "
                            f"(more than {a.tilt_height} m off)")
    for msg in problems:
        print(f"FAIL: {a.ulog}: {msg}", file=sys.stderr)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
