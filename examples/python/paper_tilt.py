#!/usr/bin/env python3
"""The paper's simulation through the Python bindings: run it and draw its state figure.

Runs the built-in scenario ``paper-tilt`` (A4-Inc team, ascent to 1.5 m, roll reference towards
the infeasible pi/3 between 4 s and 10 s, descent; docs/method.md#scenario-paper-tilt) with
``tvmd.sim.run`` and draws, against time:

* the position ``x, y, z`` against the reference ``x_r``;
* the roll: actual ``phi``, reference ``phi_r`` and planned ``phi_d`` (the attitude planner
  saturates it at ``atan(c_y(1, s))``, drawn dashed);
* the allocation error ``e_f`` (N) and the Lyapunov candidate ``V_x`` (log scales).

Usage (after installing the wheel, see crates/tvmd-py/README.md)::

    python examples/python/paper_tilt.py --out paper_tilt.png [--relaxation 0.5] [--mcap run.mcap]

matplotlib is optional for the bindings but needed here (``pip install matplotlib``); without
``--show`` the figure is written with the Agg backend, so no display is needed.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

import tvmd
import tvmd.sim


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--relaxation", "--s", dest="relaxation", type=float, default=0.5,
                   help="planner relaxation s in (0, 1] (0.5)")  # fmt: skip
    p.add_argument("--scenario", default="paper-tilt",
                   help="built-in scenario or TOML file (paper-tilt)")  # fmt: skip
    p.add_argument("--out", default="paper_tilt.png", help="figure file (paper_tilt.png)")
    p.add_argument("--mcap", default=None, help="also write the run's MCAP log there")
    p.add_argument("--show", action="store_true", help="open a window instead of only saving")
    return p.parse_args(argv)


def load_pyplot(show):
    try:
        import matplotlib
    except ImportError:
        sys.exit(
            "error: this example draws with matplotlib, which is not installed.\n"
            "       pip install matplotlib   (the tvmd bindings themselves do not need it)"
        )
    if not show:
        matplotlib.use("Agg")  # no display needed
    import matplotlib.pyplot as plt

    return plt


def print_summary(r):
    s = r.summary
    m = r.paper_metrics
    rows = [
        ("scenario", f"{r.scenario_name} (s = {r.relaxation}, {r.allocator})"),
        ("simulated / wall time", f"{s['time']:.2f} s / {s['wall_time']:.3f} s"),
        ("max planned roll", f"{s['max_planned_roll']:.4f} rad"),
        ("atan(c_y(1, s))", f"{r.hover_roll_limit:.4f} rad"),
        ("max e_f / (m_C g)", f"{s['max_e_f_over_weight']:.2e}"),
        ("horizontal error 4 s / 12 s",
         f"{s['horizontal_error_at_4s']:.3f} m / {s['horizontal_error_at_12s']:.3f} m"),
        ("stage-B attitude settling", f"{m['stage_b_attitude_settling']} s"),
        ("final V_x", f"{s['final_v_x']:.2e}"),
    ]  # fmt: skip
    for k, v in rows:
        print(f"{k:<28} {v}")
    if r.mcap_path:
        print(f"{'MCAP log':<28} {r.mcap_path}")


def draw(plt, r):
    t = r.t
    fig, axes = plt.subplots(4, 1, figsize=(9, 11), sharex=True, constrained_layout=True)
    fig.suptitle(f"{r.scenario_name}: state profile (s = {r.relaxation})")

    ax = axes[0]
    for i, (name, color) in enumerate(zip("xyz", ("C0", "C1", "C2"))):
        ax.plot(t, r.position[:, i], color=color, label=name)
        ax.plot(t, r.reference_position[:, i], color=color, ls="--", lw=1, label=f"{name}_r")
    ax.set_ylabel("position (m)")
    ax.legend(ncol=3, fontsize="small")

    ax = axes[1]
    ax.plot(t, r.attitude_rpy[:, 0], label="roll φ")
    ax.plot(t, r.reference_roll, ls="--", label="reference φ_r")
    ax.plot(t, r.planned_roll, ls="-.", label="planned φ_d")
    if r.hover_roll_limit is not None:
        ax.axhline(r.hover_roll_limit, color="grey", ls=":", lw=1,
                   label=f"atan(c_y(1, s)) = {r.hover_roll_limit:.3f}")  # fmt: skip
    ax.set_ylabel("roll (rad)")
    ax.legend(fontsize="small")

    floor = 1e-18  # e_f is at round-off for s <= 0.75: show it on a log scale above this
    ax = axes[2]
    ax.semilogy(t, np.maximum(r.e_f, floor), label="e_f (0 drawn at 1e-18)")
    ax.axhline(1e-6 * r.mass * r.gravity, color="grey", ls=":", lw=1, label="1e-6 m_C g")
    ax.set_ylabel("e_f (N)")
    ax.legend(fontsize="small")

    ax = axes[3]
    ax.semilogy(t, r.V_x, label="V_x")
    ax.set_ylabel("V_x")
    ax.set_xlabel("t (s)")
    ax.legend(fontsize="small")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        for edge in (4.0, 10.0):  # stage B
            ax.axvline(edge, color="k", lw=0.5, alpha=0.3)
    return fig


def main(argv=None):
    args = parse_args(argv)
    plt = load_pyplot(args.show)
    try:
        r = tvmd.sim.run(args.scenario, relaxation=args.relaxation, mcap=args.mcap)
    except (ValueError, OSError, RuntimeError) as e:
        sys.exit(f"error: {e}")
    print_summary(r)
    fig = draw(plt, r)
    fig.savefig(args.out, dpi=110)
    print(f"{'figure':<28} {args.out}")
    if args.show:
        plt.show()


if __name__ == "__main__":
    main()
