#!/usr/bin/env python3
"""A random policy and a PD baseline on ``tvmd/Hover-v0`` through the wrench action (issue 48).

Trains nothing: it flies a few seeded episodes of each policy through Gymnasium's interface
(``tvmd.gym``: a body wrench ``[u_tau; u_f]`` per step, which tvmd's allocation turns into
admissible gimbal angles and thrusts) and reports, and optionally plots, the returns. The PD
baseline holds the hover for the whole episode; the random policy soon leaves the bounds.

Usage (after installing the wheel with gymnasium)::

    python examples/python/gym_baselines.py [--episodes 5] [--env tvmd/Wind-v0] [--out returns.png]

matplotlib is needed for ``--out`` only.
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np

import tvmd.gym  # noqa: F401 - registers the environments

G = 9.81


def pd_policy(mass: float):
    """A PD law on the observation: a world force from the position and velocity errors, turned
    into the body frame, and a torque towards level with damping."""

    def act(obs: np.ndarray) -> np.ndarray:
        e_x, e_v, rot, omega = obs[:3], obs[3:6], obs[6:15].reshape(3, 3), obs[15:]
        force = mass * (np.array([0.0, 0.0, G]) - 4.0 * e_x - 4.0 * e_v)
        e_r = 0.5 * np.array([rot[2, 1] - rot[1, 2], rot[0, 2] - rot[2, 0], rot[1, 0] - rot[0, 1]])
        return np.concatenate([-2.0 * e_r - 0.5 * omega, rot.T @ force]).astype(np.float32)

    return act


def episode(env: gym.Env, policy, seed: int) -> tuple[float, int]:
    obs, _ = env.reset(seed=seed)
    total, steps = 0.0, 0
    while True:
        obs, reward, terminated, truncated, _ = env.step(policy(obs))
        total += float(reward)
        steps += 1
        if terminated or truncated:
            return total, steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="tvmd/Hover-v0")
    parser.add_argument("--episodes", type=int, default=5)
    parser.add_argument("--out", help="write a figure of the returns there (needs matplotlib)")
    args = parser.parse_args()
    env = gym.make(args.env)
    env.action_space.seed(0)
    policies = {"random": lambda obs: env.action_space.sample(), "PD": pd_policy(env.unwrapped.sim.mass)}
    returns = {}
    for name, policy in policies.items():
        runs = [episode(env, policy, seed) for seed in range(args.episodes)]
        returns[name] = [r for r, _ in runs]
        steps = [s for _, s in runs]
        print(f"{name:>6}: return {np.mean(returns[name]):9.1f} +- {np.std(returns[name]):7.1f}, steps {np.mean(steps):7.1f}")
    if args.out:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 3.5))
        for name, values in returns.items():
            ax.plot(range(len(values)), values, "o-", label=name)
        ax.set_xlabel("episode (seed)")
        ax.set_ylabel("return")
        ax.set_title(args.env)
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.out, dpi=120)
        print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
