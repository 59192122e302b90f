#!/usr/bin/env python3
"""The side-by-side tables of docs/px4-side-by-side.md: tvmd_control and the authors' modules on
the same flights, measured the same way (stack_measures.py: the truth from tvmd-sim px4's reports,
the plans, the unallocated force and the saturation from the ulogs).

    side_by_side.py DIR

DIR holds, each as `.px4.json` (the bridge's report) and `.ulg`:
  - `tvmd-{nominal,wind,model-error}`: tvmd_control's flight (airframe 4090,
    scripts/px4/tvmd_control/flight.toml): the hover (window `hover`, 28-35 s) and the tilt
    (`tilt`, 38-46 s, the roll stick full: a reference of pi/3);
  - `authors-{nominal,wind,model-error}`: the authors' hover in their position mode
    (scripts/px4/authors/flight-hold.toml, 28-35 s);
  - `authors-tilt-{nominal,wind,model-error}`: their manual flight with the tilt (flight.toml;
    under the model error flight-trimmed.toml, the throttle trimmed; the tilt window 24-28 s of
    the roll stick's 22-28 s);
  - `tvmd-agent-failure`, `authors-agent-failure`: agent 0 lost at 30 s in the hover (told to
    tvmd_control, untold to theirs).
With DIR/perf/perf.json (from `scripts/px4-module.sh --perf`: PX4's perf counters in real time),
the hover table also gives each stack's time per rate-loop period (the range over its hovers)
under each condition perf.json has (`condition`: nominal, wind, model-error). Prints Markdown
tables; exits 1 if a report or ulog is missing.
"""
import json
import sys
from pathlib import Path

import stack_measures

FLIGHTS = ("nominal", "wind", "model-error")
STACKS = (("tvmd", "tvmd_control"), ("authors", "the authors' modules"))
FAILURE_AT = 30.0


def per_period(perf, stack, flight):
    """The range of a stack's time per rate-loop period over its hovers in perf.json."""
    values = [w["per_period_us"] for r in perf
              if r["stack"] == stack and r.get("condition", "nominal") == flight
              for w in r["readings"] if w["window"] == "hover" and w.get("per_period_us") is not None]
    if not values:
        return "-"
    lo, hi = min(values), max(values)
    return f"{lo:.1f} us" if hi - lo < 0.05 else f"{lo:.1f}-{hi:.1f} us"


def load(d, name, stack, failure=None):
    ulog, report = d / f"{name}.ulg", d / f"{name}.px4.json"
    for path in (ulog, report):
        if not path.exists():
            raise SystemExit(f"error: {path} is missing")
    return stack_measures.measure(stack, str(ulog), str(report), failure)


def saturated(w):
    n, of = w.get("saturated_periods"), w.get("periods")
    lost = f" ({w['unlogged']:.1f} s not logged)" if w.get("unlogged", 0.0) > 0.05 else ""
    return "-" if n is None else f"{n} of {of}{lost}"


def num(v, fmt):
    return "-" if v is None else format(v, fmt)


def hover_table(d, perf):
    head = ("| flight | stack | hover hold: rms / largest (truth) | EKF2 position error, largest | height, largest "
            "| saturated periods |")
    rule = "|---|---|---:|---:|---:|---:|"
    if perf is not None:
        head += " time per rate-loop period (perf, real time) |"
        rule += "---:|"
    print(head)
    print(rule)
    for flight in FLIGHTS:
        for key, name in STACKS:
            w = load(d, f"{key}-{flight}", key)["hover"]
            row = (f"| {flight} | {name} | {w['hold_rms']:.3f} / {w['hold_max']:.3f} m | "
                   f"{w['ekf_position_max']:.3f} m | {w['height_max']:.2f} m | {saturated(w)} |")
            if perf is not None:
                row += f" {per_period(perf, key, flight)} |"
            print(row)


def tilt_table(d):
    print("| flight | stack | planned roll, largest | roll flown: largest; held (last 4 s): mean / std "
          "| unallocated force, largest "
          "| position error (truth): rms / largest | height (truth) | EKF2 position error, largest "
          "| saturated periods |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for flight in FLIGHTS:
        for key, name in STACKS:
            w = load(d, f"{key}-{flight}" if key == "tvmd" else f"authors-tilt-{flight}", key)["tilt"]
            print(f"| {flight} | {name} | {num(w.get('planned_roll_max'), '.4f')} rad | "
                  f"{w['roll_max']:.3f}; {w['roll_held_mean']:.3f} / {w['roll_held_std']:.3f} rad | "
                  f"{num(w.get('unallocated_force_max'), '.2f')} N | "
                  f"{num(w['hold_rms'], '.3f')} / {num(w['hold_max'], '.3f')} m | "
                  f"{num(w['height_min'], '.2f')}-{num(w['height_max'], '.2f')} m | "
                  f"{w['ekf_position_max']:.3f} m | {saturated(w)} |")


def failure_table(d):
    print("| stack | told | tilt, largest: 10 s after / to the end | horizontal distance from the hover point, "
          "largest: 10 s after / to the end | upside down after | on the ground after (distance) "
          "| at the end: height, tilt, disarmed |")
    print("|---|---|---:|---:|---:|---:|---|")
    for key, name in STACKS:
        f = load(d, f"{key}-agent-failure", key, FAILURE_AT)["failure"]
        told = "yes (TVMD_FAIL_MASK)" if key == "tvmd" else "no (no way to)"
        after = "never" if f["upside_down_after"] is None else f"{f['upside_down_after']:.2f} s"
        ground = ("never" if f["ground_after"] is None
                  else f"{f['ground_after']:.2f} s ({f['ground_distance']:.2f} m)")
        print(f"| {name} | {told} | {f['tilt_max_10s']:.3f} / {f['tilt_max']:.3f} rad | "
              f"{f['horizontal_error_max_10s']:.2f} / {f['horizontal_error_max']:.2f} m | {after} | {ground} | "
              f"{f['end_height']:.2f} m, {f['end_tilt']:.2f} rad, {'yes' if f['disarmed_at_end'] else 'no'} |")


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    d = Path(sys.argv[1])
    perf_file = d / "perf" / "perf.json"
    perf = json.load(open(perf_file)) if perf_file.exists() else None
    print("Hover (28-35 s):\n")
    hover_table(d, perf)
    print("\nThe tilt (a roll reference of pi/3 from the sticks):\n")
    tilt_table(d)
    print(f"\nAn agent failure (agent 0 of the plant loses its thrust at {FAILURE_AT:.0f} s in the hover):\n")
    failure_table(d)
    return 0


if __name__ == "__main__":
    sys.exit(main())
