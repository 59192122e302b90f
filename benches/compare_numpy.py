"""One control cycle three ways on identical inputs, and the ratios from one run.

1. pure NumPy: the test suite's independent reference implementation
   (``crates/tvmd-py/tests/reference_impl.py``): law + planner + projection, pseudo-inverse
   allocation, gimbal inversion;
2. tvmd through Python: ``tvmd.Controller(..., allocator="pseudo-inverse").step``;
3. native Rust: ``cargo run --release --example cycle_timing`` (same cycle, same inputs).

Inputs: the paper's A4-Inc team 0.2 m off a hover reference at 1.5 m rolled to pi/3, so the
planner runs its bisection. Usage (with the wheel installed, e.g. in .venv after
``bash scripts/test.sh``): ``.venv/bin/python benches/compare_numpy.py``.
"""

from __future__ import annotations

import math
import subprocess
import sys
import timeit
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "crates" / "tvmd-py" / "tests"))

import reference_impl as ri  # noqa: E402
import tvmd  # noqa: E402


def numpy_cycle(team, x, R, x_r, R_r):
    zero = np.zeros(3)
    out = ri.control_law(
        x, R, zero, zero, x_r, zero, zero, R_r, zero, zero,
        team["K_x"], team["K_R"], team["K_xi"], team["m_C"], team["J_C"],
        team["n"], team["n_x"], team["sigma_x"], team["sigma_y"], team["max_thrust"], team["s"],
    )  # fmt: skip
    forces = ri.pseudo_inverse_allocation(team["M"], out["u_d"])
    return ri.agent_commands(forces)


def best_per_call(fn, number):
    return min(timeit.repeat(fn, number=number, repeat=7)) / number


def main() -> None:
    team = ri.paper_a4_inc()
    x, R = np.array([0.2, 0.0, 1.5]), np.eye(3)
    x_r, R_r = np.array([0.0, 0.0, 1.5]), ri.rot_x(math.pi / 3)

    controller = tvmd.Controller(tvmd.Team.a4_inc(), allocator="pseudo-inverse")
    state = tvmd.State(position=x, attitude=R)
    reference = tvmd.Reference(position=x_r, attitude=R_r)

    # Same inputs, same answer (commands as [eta_x, eta_y, thrust]).
    ours = controller.step(state, reference).commands[:, :3]
    ref = numpy_cycle(team, x, R, x_r, R_r)
    ref = np.column_stack([ref[:, 1], ref[:, 2], ref[:, 0]])
    agreement = float(np.max(np.abs(ours - ref)))

    t_numpy = best_per_call(lambda: numpy_cycle(team, x, R, x_r, R_r), 200)
    t_python = best_per_call(lambda: controller.step(state, reference), 20000)
    native = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "--example", "cycle_timing"],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout  # fmt: skip
    t_native = float(native.split()[-1]) * 1e-9

    print(f"max |commands tvmd - NumPy| = {agreement:.2e}")
    print(f"{'implementation':<28} {'time per cycle':>16} {'vs native':>10}")
    for name, t in [("pure NumPy", t_numpy), ("tvmd via Python", t_python), ("native Rust (f64)", t_native)]:
        print(f"{name:<28} {t * 1e6:>13.2f} us {t / t_native:>9.1f}x")
    print(f"NumPy / native = {t_numpy / t_native:.0f}x, NumPy / tvmd-Python = {t_numpy / t_python:.0f}x")


if __name__ == "__main__":
    main()
