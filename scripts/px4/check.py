#!/usr/bin/env python3
"""Checks a PX4 flight's measures against targets, or compares two flights' measures.

    check.py ANALYSIS.json BRIDGE_REPORT.json --hover-hold M --ekf-position M --ekf-attitude RAD --settle S
    check.py ANALYSIS_TVMD.json ANALYSIS_SIH.json --compare

ANALYSIS.json is scripts/px4/analyze.py's (from the ulog), BRIDGE_REPORT.json tvmd-sim px4's
(`.px4.json`: lockstep accounting). Prints one line per measure; exits 1 on a missed target.
"""
import argparse
import json
import sys


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("first")
    p.add_argument("second")
    p.add_argument("--hover-hold", type=float)
    p.add_argument("--ekf-position", type=float)
    p.add_argument("--ekf-attitude", type=float)
    p.add_argument("--settle", type=float)
    p.add_argument("--compare", action="store_true")
    a = p.parse_args()
    first = json.load(open(a.first))
    second = json.load(open(a.second))
    if a.compare:
        print(f"{'measure':<28} {'tvmd-sim':>10} {'SIH':>10}")
        for window in ("hover", "step"):
            for key in ("hold_max", "hold_rms", "settling_time", "rise_time_90", "overshoot", "ekf_position_max",
                        "ekf_attitude_max", "roll_std"):
                x, y = first.get(window, {}).get(key), second.get(window, {}).get(key)
                if x is None and y is None:
                    continue
                fmt = lambda v: "-" if v is None else f"{v:.3f}"
                print(f"{window + '.' + key:<28} {fmt(x):>10} {fmt(y):>10}")
        return
    hover, step = first["hover"], first.get("step", {})
    problems = []

    def check(name, value, limit):
        ok = value is not None and value <= limit
        print(f"{name:<34} {'-' if value is None else f'{value:.4f}':>10}  (target <= {limit}) {'ok' if ok else 'MISSED'}")
        if not ok:
            problems.append(name)

    if a.hover_hold is not None:
        check("hover hold (max distance, m)", hover["hold_max"], a.hover_hold)
    if a.ekf_position is not None:
        check("EKF2 position error in hover (m)", hover["ekf_position_max"], a.ekf_position)
    if a.ekf_attitude is not None:
        check("EKF2 attitude error in hover (rad)", hover["ekf_attitude_max"], a.ekf_attitude)
    if a.settle is not None and step:
        check("1 m step settling into 0.1 m (s)", step["settling_time"], a.settle)
    lockstep = second.get("lockstep", {})
    factor = second.get("realtime_factor")
    print(f"{'lockstep from (s)':<34} {lockstep.get('lockstep_from')}")
    print(f"{'simulated time per wall time':<34} {factor if factor is None else f'{factor:.2f}x'}")
    if factor is None or factor < 1.0:
        problems.append("lockstep slower than real time")
    if second.get("error"):
        problems.append(f"the flight ended early: {second['error']}")
    for name in problems:
        print(f"FAIL: {name}", file=sys.stderr)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
