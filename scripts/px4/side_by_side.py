#!/usr/bin/env python3
"""The side-by-side table of docs/px4-module.md: each stack's hover (the flight files' window
`hover`, 28-35 s, the target 1.5 m above home) on the nominal vehicle, under a steady wind and
off its model, from tvmd-sim px4's reports (the truth) and the ulogs.

    side_by_side.py DIR

DIR holds `tvmd-{nominal,wind,model-error}.px4.json` and `.ulg` (tvmd_control, airframe 4090)
and `authors-{nominal,wind,model-error}.px4.json` (the authors' modules, airframe 4007, in
their position mode: scripts/px4/authors/flight-hold.toml). With DIR/perf/perf.json (from
`scripts/px4-module.sh --perf`: PX4's perf counters in real time, nominal vehicles only), the
nominal rows also give each stack's time per rate-loop period in its hovers (the range over
them). Prints a Markdown table; exits 1 if a report is missing or has no window `hover`.
"""
import json
import sys
from pathlib import Path

FLIGHTS = ("nominal", "wind", "model-error")
STACKS = (("tvmd", "tvmd_control"), ("authors", "the authors' modules"))


def hover(path):
    report = json.load(open(path))
    for w in report.get("windows", []):
        if w["name"] == "hover":
            return w
    raise SystemExit(f"error: {path} has no window `hover`")


def per_period(perf, stack):
    """The range of a stack's time per rate-loop period over its hovers in perf.json."""
    values = [w["per_period_us"] for r in perf if r["stack"] == stack for w in r["readings"]
              if w["window"] == "hover" and w.get("per_period_us") is not None]
    if not values:
        return "-"
    lo, hi = min(values), max(values)
    return f"{lo:.1f} us" if hi - lo < 0.05 else f"{lo:.1f}-{hi:.1f} us"


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    d = Path(sys.argv[1])
    perf_file = d / "perf" / "perf.json"
    perf = json.load(open(perf_file)) if perf_file.exists() else None
    head = "| flight | stack | hover hold: rms / largest (truth) | EKF2 position error, largest | height, largest |"
    rule = "|---|---|---:|---:|---:|"
    if perf is not None:
        head += " time per rate-loop period (perf, real time) |"
        rule += "---:|"
    print(head)
    print(rule)
    for flight in FLIGHTS:
        for key, name in STACKS:
            w = hover(d / f"{key}-{flight}.px4.json")
            row = (f"| {flight} | {name} | {w['hold_rms']:.3f} / {w['hold_max']:.3f} m | "
                   f"{w['ekf_position_max']:.3f} m | {w['height_max']:.2f} m |")
            if perf is not None:
                row += f" {per_period(perf, key) if flight == 'nominal' else '-'} |"
            print(row)
    return 0


if __name__ == "__main__":
    sys.exit(main())
