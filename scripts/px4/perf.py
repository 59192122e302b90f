#!/usr/bin/env python3
"""Each stack's time per cycle as PX4's `perf` counters report it, on real time: tvmd_control
(airframe 4090) against the authors' pfa_att_control + control_allocator (+ pfa_pos_control,
airframe 4007), flown on tvmd-sim with a PX4 build without lockstep (px4_sitl_nolockstep, whose
clock is the wall clock) and the bridge in real time (`tvmd-sim px4 --real-time`). The
authors' modules need their PX4 fork (airframe 4007, as scripts/px4-module.sh --side-by-side).

    perf.py --sim TVMD_SIM --px4-dir PX4_DIR [--build px4_sitl_nolockstep] [--instance N]
        [--conditions nominal,wind,model-error] --out DIR

In lockstep SITL, hrt is the simulated clock, which does not advance inside a cycle: every perf
elapsed counter reads 0 there. Here each flight is started by tvmd-sim; once PX4 reports the
simulator connected (its console), the script runs PX4's own `perf reset` at the start of each
measured window and `perf` at its end (the daemon client `build/BUILD/bin/px4-perf --instance
N`, as the `perf` command of PX4's shell), so the counters cover that window alone. The flights
and windows (simulated s, which the real-time bridge keeps on the wall clock):
  tvmd        tvmd_control/flight.toml  hover 22.5-29.5 (before its parameter test), tilt 38.5-45.5
  authors     authors/flight-hold.toml  hover 28-35 (their position mode)
  authors-rc  authors/flight.toml       hover 18.5-21.5, tilt 24.5-27.5 (their manual mode)
(in scripts/px4/), on the nominal vehicles (scenario.toml); with --conditions (default all
three) `tvmd` and `authors` again under a steady wind (`-wind`, scenario-wind.toml) and off
their models (`-model-error`, scenario-model-error.toml). The windows' edges are found on the wall clock from PX4's console line,
within a tenth of a second. Also reads the ulogs' `perf_counter_postflight` (PX4's logger writes
every counter at disarm: from the last `perf reset` here, the last window's start, to the
disarm, the landing included) where a flight disarmed. Writes DIR/perf.json (side_by_side.py
reads the hovers' time per period from it) and prints a Markdown table: per counter, the
events, mean and largest time in the window, and per stack the time per rate-loop period (its
rate-loop modules' mean plus the position loop's mean times its share of periods). The
machine's load average is printed with each reading: the numbers are wall-clock times on a
shared machine. Exits 1 when a flight or a reading fails, or a flight fell behind real time
(more than 1% of its ticks late).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
COUNTER = re.compile(r"^(?P<name>[^:]+: [^:]+): (?P<events>\d+) events, (?P<elapsed>\d+)us elapsed, "
                     r"(?P<avg>[\d.]+)us avg, min (?P<min>\d+)us max (?P<max>\d+)us")
MODULES = ("tvmd_control", "pfa_att_control", "control_allocator", "pfa_pos_control")
# Per stack: the counters that run every rate-loop period, and the position loop's.
STACKS = {
    "tvmd": (("tvmd_control: attitude+allocation",), ("tvmd_control: law",)),
    "authors": (("pfa_att_control: cycle", "control_allocator: cycle"), ("pfa_pos_control: cycle",)),
}


def flights(conditions):
    """(name, stack, scenario, flight file, airframe, params, windows, condition) per flight: each
    stack's under each condition (nominal, wind, model-error: the scenarios of the side-by-side
    table), and the authors' manual flight on the nominal vehicle."""
    t, a = REPO / "scripts/px4/tvmd_control", REPO / "scripts/px4/authors"
    out = []
    for c in conditions:
        scenario = "scenario.toml" if c == "nominal" else f"scenario-{c}.toml"
        suffix = "" if c == "nominal" else f"-{c}"
        out.append((f"tvmd{suffix}", "tvmd", t / scenario, t / "flight.toml", 4090, t / "params",
                    [("hover", 22.5, 29.5), ("tilt", 38.5, 45.5)], c))
        out.append((f"authors{suffix}", "authors", a / scenario, a / "flight-hold.toml", 4007, a / "params",
                    [("hover", 28.0, 35.0)], c))
        if c == "nominal":
            out.append(("authors-rc", "authors", a / scenario, a / "flight.toml", 4007, a / "params",
                        [("hover", 18.5, 21.5), ("tilt", 24.5, 27.5)], c))
    return out


def parse(lines):
    counters = {}
    for line in lines:
        m = COUNTER.match(line.strip())
        if m and m["name"].split(":")[0] in MODULES:
            counters[m["name"]] = {"events": int(m["events"]), "elapsed_us": int(m["elapsed"]),
                                   "mean_us": float(m["avg"]), "max_us": int(m["max"])}
    return counters


def client(a, rootfs, *args):
    binary = Path(a.px4_dir) / "build" / a.build / "bin" / "px4-perf"
    r = subprocess.run([str(binary), "--instance", str(a.instance), *args], cwd=rootfs,
                       capture_output=True, text=True, timeout=20)
    if r.returncode != 0:
        raise RuntimeError(f"px4-perf {' '.join(args)} failed: {r.stderr.strip()}")
    return r.stdout.splitlines()


def fly(a, out, name, scenario, flight, autostart, params, windows):
    mcap = out / f"perf-{name}.mcap"
    cmd = [a.sim, "px4", str(scenario), "--flight", str(flight), "--px4-dir", a.px4_dir,
           "--px4-build", a.build, "--real-time", "--autostart", str(autostart), "--params",
           str(params), "--instance", str(a.instance), "--out", str(mcap)]
    log = open(out / f"perf-{name}.log", "w")
    proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
    console = out / f"perf-{name}.px4" / "px4-console.txt"
    start = time.monotonic()
    t0 = None
    while t0 is None:
        if proc.poll() is not None:
            raise RuntimeError(f"{name}: tvmd-sim ended before PX4 connected ({log.name})")
        if time.monotonic() - start > 120:
            proc.kill()
            raise RuntimeError(f"{name}: PX4 did not connect within 120 s")
        if console.exists() and "Simulator connected on TCP port" in console.read_text(errors="replace"):
            t0 = time.monotonic()
        time.sleep(0.05)
    rootfs = out / f"perf-{name}.px4" / "rootfs"
    readings = []
    for window, t_from, t_to in windows:
        time.sleep(max(0.0, t0 + t_from - time.monotonic()))
        client(a, rootfs, "reset")
        time.sleep(max(0.0, t0 + t_to - time.monotonic()))
        counters = parse(client(a, rootfs))
        readings.append({"window": window, "from": t_from, "to": t_to, "counters": counters,
                         "load_average": os.getloadavg()})
    if proc.wait(timeout=600) != 0:
        raise RuntimeError(f"{name}: the flight failed ({log.name})")
    report = json.load(open(mcap.with_suffix(".px4.json")))
    ticks = max(1, report["lockstep"]["lockstep_ticks"])
    late = report["lockstep"]["late_ticks"]
    print(f"    {report['sim_time']:.1f} s simulated in {report['wall_time']:.1f} s wall, "
          f"{late} ticks of {ticks} sent more than a period late", flush=True)
    if late > 0.01 * ticks:
        raise RuntimeError(f"{name}: {late} of {ticks} ticks late: the bridge did not keep real time")
    postflight = {}
    ulog = mcap.with_suffix(".ulg")
    if ulog.exists():
        from pyulog import ULog
        info = ULog(str(ulog), []).msg_info_multiple_dict.get("perf_counter_postflight", [])
        postflight = parse(info[-1]) if info else {}
    return {"flight": name, "readings": readings, "postflight_since_last_reset": postflight,
            "late_ticks": late, "ticks": ticks}


def per_period(stack, counters):
    """Mean time per rate-loop period: the rate loop's modules' means, plus the position loop's
    mean times its events per rate-loop event."""
    rate, position = STACKS[stack]
    present = [c for c in rate if c in counters]
    if not present:
        return None
    periods = counters[present[0]]["events"]
    total = sum(counters[c]["mean_us"] for c in present)
    for c in position:
        if c in counters and periods:
            total += counters[c]["mean_us"] * counters[c]["events"] / periods
    return total


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sim", required=True)
    p.add_argument("--px4-dir", required=True)
    p.add_argument("--build", default="px4_sitl_nolockstep")
    p.add_argument("--instance", type=int, default=7)
    p.add_argument("--out", required=True)
    p.add_argument("--conditions", default="nominal,wind,model-error",
                   help="comma-separated: nominal, wind, model-error (the scenarios' conditions)")
    a = p.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results = []
    conditions = [c for c in a.conditions.split(",") if c]
    unknown = set(conditions) - {"nominal", "wind", "model-error"}
    if unknown:
        raise SystemExit(f"error: unknown conditions {sorted(unknown)}")
    for name, stack, scenario, flight, autostart, params, windows, condition in flights(conditions):
        print(f"==> perf: {name} (airframe {autostart}, {flight.name}, real time)", flush=True)
        r = fly(a, out, name, scenario, flight, autostart, params, windows)
        r["stack"], r["condition"] = stack, condition
        for w in r["readings"]:
            w["per_period_us"] = per_period(stack, w["counters"])
        results.append(r)
    json.dump(results, open(out / "perf.json", "w"), indent=1)

    print("\n| flight | window | counter | events | mean | largest | load average (1 min) |")
    print("|---|---|---|---:|---:|---:|---:|")
    for r in results:
        for w in r["readings"]:
            for c, v in sorted(w["counters"].items()):
                print(f"| {r['flight']} | {w['window']} {w['from']}-{w['to']} s | `{c}` | {v['events']} | "
                      f"{v['mean_us']:.2f} us | {v['max_us']} us | {w['load_average'][0]:.2f} |")
    print("\n| flight | window | time per rate-loop period, mean |")
    print("|---|---|---:|")
    for r in results:
        for w in r["readings"]:
            total = w["per_period_us"]
            print(f"| {r['flight']} | {w['window']} | " + (f"{total:.2f} us |" if total is not None else "- |"))
    print("\nFrom the flight's last `perf reset` (its last window's start) to the disarm (the ulog's "
          "perf_counter_postflight; none for a flight that ends in the air):")
    for r in results:
        for c, v in sorted(r["postflight_since_last_reset"].items()):
            print(f"  {r['flight']:<11} {c:<36} {v['events']:>7} events, mean {v['mean_us']:.2f} us, "
                  f"largest {v['max_us']} us")
    missing = [f"{r['flight']} {w['window']}" for r in results for w in r["readings"]
               if w["per_period_us"] is None]
    if missing:
        print(f"error: no rate-loop counter read in {', '.join(missing)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (RuntimeError, subprocess.TimeoutExpired) as e:
        print(f"error: {e}", file=sys.stderr)
        sys.exit(1)
