"""Team-steps per second of the stepped simulator from Python (issue 48).

Three ways to step A4-Inc's hover at 100 Hz control (each step: one controller period, ten
1 kHz physics steps, the wrench allocated by tvmd's allocation stage):

* ``Simulation.step_wrench`` in a Python loop, one team;
* ``SimulationBatch.step_wrench``: ``B`` teams per call, stepped inside Rust on every core;
* ``tvmd.gym.HoverVectorEnv`` (the batch plus the observation, reward and autoreset in NumPy).

Run after building the wheel: ``.venv/bin/python benches/vector_env.py [B] [steps]``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

import tvmd.sim as sim


def rate(label: str, team_steps: int, seconds: float) -> None:
    print(f"{label:<44} {team_steps / seconds:>10,.0f} team-steps/s ({team_steps} in {seconds:.2f} s)")


def main() -> None:
    teams = int(sys.argv[1]) if len(sys.argv) > 1 else 64
    steps = int(sys.argv[2]) if len(sys.argv) > 2 else 200
    one = sim.Simulation("hover")
    hover = np.array([0, 0, 0, 0, 0, one.mass * 9.81])
    one.reset()
    start = time.perf_counter()
    for _ in range(steps * 4):
        one.step_wrench(hover)
    rate("Simulation.step_wrench (one team, Python loop)", steps * 4, time.perf_counter() - start)

    batch = sim.SimulationBatch("hover", count=teams)
    wrenches = np.tile(hover, (teams, 1))
    batch.reset()
    start = time.perf_counter()
    for _ in range(steps):
        batch.step_wrench(wrenches)
    rate(f"SimulationBatch.step_wrench (B = {teams})", steps * teams, time.perf_counter() - start)

    try:
        import tvmd.gym as tgym
    except ImportError:
        print("tvmd.gym: gymnasium is not installed")
        return
    env = tgym.HoverVectorEnv(teams)
    env.reset(seed=0)
    actions = np.tile(hover, (teams, 1)).astype(np.float32)
    start = time.perf_counter()
    for _ in range(steps):
        env.step(actions)
    rate(f"HoverVectorEnv.step (B = {teams})", steps * teams, time.perf_counter() - start)


if __name__ == "__main__":
    main()
