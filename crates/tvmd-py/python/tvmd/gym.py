"""tvmd.gym: Gymnasium environments of the tvmd simulator (needs ``gymnasium``).

Importing the module registers four environments, each :class:`TeamEnv` on a scenario: follow
the scenario's reference from a perturbed initial pose.

* ``"tvmd/Hover-v0"``: the built-in ``"hover"`` (A4-Inc holds 1.5 m for 12 s);
* ``"tvmd/Tracking-v0"``: ``"figure-eight"`` (a figure eight at 1.5 m, 21 s);
* ``"tvmd/Wind-v0"``: ``"wind"`` (hover in a 1 m/s wind with a 3 m/s gust at 4-6 s: disturbance
  rejection);
* ``"tvmd/AgentFailure-v0"``: A6-Inc hovering at 1.5 m loses agent 0's thrust at 3 s (the
  wrench allocation is told and idles it), 12 s.

:class:`TeamVectorEnv` is the same task for many teams stepped together inside Rust
(``gymnasium.make_vec(id, num_envs, vectorization_mode="vector_entry_point")``).
``HoverEnv`` and ``HoverVectorEnv`` are their names with the default scenario. The plant is
:class:`tvmd.sim.Simulation` (the scenario's actuators, failures, disturbances and noise apply);
one environment step is one controller period (0.01 s by default). Everything is in SI units,
z up.

Observation (``Box`` of 18 float32): the position error ``x - x_r`` (3, m, world frame), the
velocity error ``x_dot - x_dot_r`` (3, m/s, world frame), the attitude ``R`` (9, body to world,
row-major) and the body rates ``Omega`` (3, rad/s), of the fed-back (noisy, delayed) state. With
``observe_reference=True`` (a setting; default off, the 18 values above) 12 more follow, what the
reward's attitude term compares against: the reference attitude ``R_r`` (9, row-major) and the
reference body rates ``Omega_r`` (3, rad/s) of the same tick (30 float32 in all).

Actions, two modes (``action=``):

* ``"wrench"`` (default): the body wrench ``[u_tau; u_f]`` (6, N m and N; body frame, about the
  centre of mass) that tvmd's allocation (the scenario controller's allocation stage) turns
  into admissible gimbal angles and thrusts. Bounds: ``|u_f_i| <= n sigma_Tf`` and
  ``|u_tau_i| <= n sigma_Tf max_i |p_i|``; actions outside are clipped.
* ``"commands"``: per-agent commands ``(n, 3)``: ``eta_x`` in ``[-sigma_x, sigma_x]``, ``eta_y``
  in ``[-sigma_y, sigma_y]`` (rad), thrust in ``[0, sigma_Tf]`` (N); clipped likewise.

Reward per step: ``alive - (w_position |e_x|^2 + w_velocity |e_v|^2 + w_attitude psi +
w_rate |Omega|^2 + w_action |a / a_max|^2)``, ``psi = (3 - trace(R_r^T R)) / 2`` in [0, 2]; the
weights are the ``weights`` argument over :data:`DEFAULT_WEIGHTS`, and ``info["reward_terms"]``
holds each term (before weighting). ``terminated``: the position error exceeds
``max_position_error``, the tilt ``acos(R_33)`` exceeds ``max_tilt``, or the simulation diverged;
``truncated``: the scenario's duration is reached. ``reset(seed=...)`` seeds the initial pose's
draw (uniform within ``initial_offset`` m per axis, upwards only for a scenario that starts on
the ground, and ``initial_tilt`` rad in roll and pitch) and the state noise.
"""

from __future__ import annotations

import math
from typing import Any, Optional

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import sim as _sim

#: The reward weights a ``weights`` argument updates.
DEFAULT_WEIGHTS = {
    "alive": 1.0,
    "position": 1.0,
    "velocity": 0.1,
    "attitude": 0.5,
    "rate": 0.01,
    "action": 0.0,
}

HOVER_ID = "tvmd/Hover-v0"

#: A6-Inc hovering at 1.5 m loses agent 0's thrust at 3 s (``"tvmd/AgentFailure-v0"``).
AGENT_FAILURE_TOML = """name = "hover-agent-failure"
description = "A6-Inc hovers at 1.5 m and loses agent 0's thrust at 3 s (controller told)"
duration = 12.0
initial_position = [0.0, 0.0, 1.5]
[team]
preset = "a6-inc"
[reference]
kind = "hover"
position = [0.0, 0.0, 1.5]
[[failures]]
agent = 0
time = 3.0
kind = "no-thrust"
"""

#: The registered environments: id -> keyword arguments of :class:`TeamEnv`.
ENVIRONMENTS = {
    HOVER_ID: {},
    "tvmd/Tracking-v0": {"scenario": "figure-eight"},
    "tvmd/Wind-v0": {"scenario": "wind"},
    "tvmd/AgentFailure-v0": {"toml": AGENT_FAILURE_TOML},
}



def _observation_space(observe_reference: Any) -> spaces.Box:
    # The observation box: 18 values, 30 with the reference attitude and rates.
    if not isinstance(observe_reference, (bool, np.bool_)):
        raise ValueError(f"`observe_reference` must be a bool, got {observe_reference!r}")
    return spaces.Box(-np.inf, np.inf, shape=(30 if observe_reference else 18,), dtype=np.float32)


def _action_bounds(simulation: Any, action: str) -> tuple[np.ndarray, np.ndarray]:
    # The action box of a team (a ``Simulation``): a wrench or per-agent commands, SI units.
    n, thrust = simulation.n_agents, simulation.max_thrust
    if action == "wrench":
        arm = float(np.linalg.norm(simulation.agent_positions, axis=1).max())
        high = np.array([n * thrust * arm] * 3 + [n * thrust] * 3)
        return -high, high
    sx, sy = simulation.gimbal_limits
    return np.tile([-sx, -sy, 0.0], (n, 1)), np.tile([sx, sy, thrust], (n, 1))


def _check(action: str, weights: Optional[dict[str, float]]) -> dict[str, float]:
    # The checked action mode; the weights over the defaults, each a finite number.
    if action not in ("wrench", "commands"):
        raise ValueError(f'`action` must be "wrench" or "commands", got {action!r}')
    unknown = set(weights or {}) - set(DEFAULT_WEIGHTS)
    if unknown:
        raise ValueError(f"unknown reward weights {sorted(unknown)} (known: {sorted(DEFAULT_WEIGHTS)})")
    for name, w in (weights or {}).items():
        if isinstance(w, bool) or not isinstance(w, (int, float, np.integer, np.floating)) or not math.isfinite(w):
            raise ValueError(f"`weights[{name!r}]` must be a finite number, got {w!r}")
    return {**DEFAULT_WEIGHTS, **{k: float(v) for k, v in (weights or {}).items()}}


def _bounded(name: str, value: Any, low: float, high: float = math.inf, *, open_low: bool = False) -> float:
    # `value` as a float in [low, high] (or (low, high] with `open_low`), else ValueError naming it.
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a number, got {value!r}") from None
    inside = math.isfinite(x) and (x > low if open_low else x >= low) and x <= high
    if not inside:
        span = f"{'(' if open_low else '['}{low:g}, {high:g}]"
        raise ValueError(f"`{name}` must be finite and in {span}, got {value!r}")
    return x


def _check_task(
    simulation: Any, home: np.ndarray, initial_offset: Any, initial_tilt: Any, max_position_error: Any, max_tilt: Any
) -> tuple[float, float, float, float]:
    # The episode's bounds, checked; the farthest initial poses they allow must be poses the
    # scenario accepts (not under the ground, not beyond its ranges), found here and not at a
    # later reset. Probing moves `simulation`'s initial pose; every reset sets its own.
    offset = _bounded("initial_offset", initial_offset, 0.0)
    tilt = _bounded("initial_tilt", initial_tilt, 0.0, math.pi)
    error = _bounded("max_position_error", max_position_error, 0.0, open_low=True)
    max_tilt_ = _bounded("max_tilt", max_tilt, 0.0, math.pi, open_low=True)
    z_low = 0.0 if home[2] < offset else -offset
    for corner in ([offset, offset, offset], [-offset, -offset, z_low]):
        for rpy in ([tilt, tilt, 0.0], [-tilt, -tilt, 0.0]):
            try:
                simulation.reset(0, position=home + np.array(corner), attitude_rpy=rpy)
            except ValueError as e:
                raise ValueError(
                    f"`initial_offset` = {offset:g} m with `initial_tilt` = {tilt:g} rad allow an "
                    f"initial pose the scenario refuses: {e}"
                ) from None
    return offset, tilt, error, max_tilt_


def _draw_offsets(rng: np.random.Generator, home: np.ndarray, bound: float, m: int) -> np.ndarray:
    # Initial position offsets within `bound` per axis; never below the ground (z = 0) for a
    # scenario that starts on it.
    offsets = rng.uniform(-bound, bound, (m, 3))
    if home[2] < bound:
        offsets[:, 2] = np.abs(offsets[:, 2])
    return offsets


class TeamEnv(gym.Env):
    """Follow a scenario's reference from a perturbed initial pose (see the module's
    documentation).

    Args:
        scenario: a scenario for ``tvmd.sim.Simulation`` (default ``"hover"``: A4-Inc at 1.5 m,
            12 s, so 1200 steps).
        action: ``"wrench"`` or ``"commands"``.
        weights: reward weights over ``DEFAULT_WEIGHTS`` (unknown keys and values that are not
            finite numbers raise ``ValueError``).
        initial_offset: largest initial position offset per axis (m, finite, at least 0).
        initial_tilt: largest initial roll and pitch (rad, in [0, pi]).
        max_position_error: the episode terminates beyond it (m, finite, positive).
        max_tilt: the episode terminates beyond it (rad, in (0, pi]).
        observe_reference: append the reference attitude ``R_r`` (9) and rates ``Omega_r`` (3)
            to the observation (30 values; default False: the 18 of before).

    A bad argument raises ``ValueError`` naming it, here rather than at a later reset; so do an
    ``initial_offset`` and ``initial_tilt`` whose farthest pose the scenario refuses (an agent
    under the ground).
        **simulation: further ``tvmd.sim.Simulation`` keywords (``team``, ``toml``, ``allocator``,
            ...).
    """

    metadata = {"render_modes": []}

    def __init__(
        self,
        scenario: Optional[str] = None,
        *,
        action: str = "wrench",
        weights: Optional[dict[str, float]] = None,
        initial_offset: float = 0.2,
        initial_tilt: float = 0.1,
        max_position_error: float = 2.0,
        max_tilt: float = 1.2,
        observe_reference: bool = False,
        render_mode: Optional[str] = None,
        **simulation: Any,
    ) -> None:
        self.weights = _check(action, weights)
        self.observation_space = _observation_space(observe_reference)
        self.observe_reference = bool(observe_reference)
        if render_mode is not None:
            raise ValueError("TeamEnv does not render")
        self.render_mode = render_mode
        self.sim = _sim.Simulation(scenario, **simulation)
        self.action_mode = action
        first = self.sim.observe()
        self._home = first.true_state.position.copy()
        checked = _check_task(self.sim, self._home, initial_offset, initial_tilt, max_position_error, max_tilt)
        self.initial_offset, self.initial_tilt, self.max_position_error, self.max_tilt = checked
        self._low, self._high = _action_bounds(self.sim, action)
        self._scale = np.maximum(np.abs(self._low), np.abs(self._high))
        self.action_space = spaces.Box(self._low.astype(np.float32), self._high.astype(np.float32), dtype=np.float32)
        self._last = self._vector(first)

    def _vector(self, obs: Any) -> np.ndarray:
        s, r = obs.state, obs.reference
        parts = [s.position - r.position, obs.velocity_world - r.velocity, s.attitude.reshape(9), s.angular_velocity]
        if self.observe_reference:
            parts += [r.attitude.reshape(9), r.angular_velocity]
        return np.concatenate(parts).astype(np.float32)

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None) -> tuple[np.ndarray, dict[str, Any]]:
        """Starts an episode from a perturbed pose (drawn with the environment's generator)."""
        super().reset(seed=seed)
        rng = self.np_random
        offset = _draw_offsets(rng, self._home, self.initial_offset, 1)[0]
        tilt = rng.uniform(-self.initial_tilt, self.initial_tilt, 2)
        noise_seed = int(rng.integers(0, 2**63))
        obs = self.sim.reset(noise_seed, position=self._home + offset, attitude_rpy=[tilt[0], tilt[1], 0.0])
        self._last = self._vector(obs)
        return self._last.copy(), {"time": obs.t}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """One controller period with ``action`` held."""
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(self._low.shape), self._low, self._high)
        try:
            obs = self.sim.step_wrench(a) if self.action_mode == "wrench" else self.sim.step(a)
        except RuntimeError as e:
            # The state diverged: the episode ends where it was.
            obs = None
            diverged = str(e)
        if obs is None:
            return self._last.copy(), -100.0, True, False, {"diverged": diverged}
        s, r = obs.state, obs.reference
        e_x = s.position - r.position
        e_v = obs.velocity_world - r.velocity
        psi = 0.5 * (3.0 - float(np.trace(r.attitude.T @ s.attitude)))
        terms = {
            "position": float(e_x @ e_x),
            "velocity": float(e_v @ e_v),
            "attitude": psi,
            "rate": float(s.angular_velocity @ s.angular_velocity),
            "action": float(np.sum((a / self._scale) ** 2)),
        }
        w = self.weights
        reward = w["alive"] - sum(w[k] * v for k, v in terms.items())
        tilt = math.acos(max(-1.0, min(1.0, float(obs.true_state.attitude[2, 2]))))
        error = float(np.linalg.norm(obs.true_state.position - r.position))
        terminated = error > self.max_position_error or tilt > self.max_tilt
        truncated = bool(obs.done) and not terminated
        info = {"time": obs.t, "reward_terms": terms, "position_error": error, "tilt": tilt}
        self._last = self._vector(obs)
        return self._last.copy(), float(reward), bool(terminated), truncated, info


class TeamVectorEnv(gym.vector.VectorEnv):
    """``num_envs`` teams of one task stepped together inside Rust (``tvmd.sim.SimulationBatch``: one
    call per batch step on ``jobs`` threads, no Python loop per team). Spaces, reward, initial
    poses and episode ends are :class:`TeamEnv`'s, batched; episodes reset automatically on the
    step after they end (Gymnasium's next-step autoreset: that step's action is ignored, its
    reward 0). A team whose simulation fails (diverges) is terminated with reward -100.

    Args: ``num_envs``, then as :class:`TeamEnv`, plus ``jobs`` (worker threads).
    """

    metadata = {"autoreset_mode": gym.vector.AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        num_envs: int,
        scenario: Optional[str] = None,
        *,
        action: str = "wrench",
        weights: Optional[dict[str, float]] = None,
        initial_offset: float = 0.2,
        initial_tilt: float = 0.1,
        max_position_error: float = 2.0,
        max_tilt: float = 1.2,
        observe_reference: bool = False,
        jobs: Optional[int] = None,
        **simulation: Any,
    ) -> None:
        self.weights = _check(action, weights)
        self.single_observation_space = _observation_space(observe_reference)
        self.observe_reference = bool(observe_reference)
        self.num_envs = int(num_envs)
        self.batch = _sim.SimulationBatch(scenario, count=self.num_envs, jobs=jobs, **simulation)
        one = _sim.Simulation(scenario, **simulation)
        self._home = one.observe().true_state.position.copy()
        self.action_mode = action
        self._low, self._high = _action_bounds(one, action)
        self._scale = np.maximum(np.abs(self._low), np.abs(self._high))
        self.single_action_space = spaces.Box(self._low.astype(np.float32), self._high.astype(np.float32), dtype=np.float32)
        self.action_space = gym.vector.utils.batch_space(self.single_action_space, self.num_envs)
        self.observation_space = gym.vector.utils.batch_space(self.single_observation_space, self.num_envs)
        checked = _check_task(one, self._home, initial_offset, initial_tilt, max_position_error, max_tilt)
        self.initial_offset, self.initial_tilt, self.max_position_error, self.max_tilt = checked
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._last = np.zeros((self.num_envs, self.single_observation_space.shape[0]), dtype=np.float32)

    def _reset_teams(self, indices: np.ndarray) -> dict[str, Any]:
        m = len(indices)
        rng = self.np_random
        offsets = _draw_offsets(rng, self._home, self.initial_offset, m)
        tilts = rng.uniform(-self.initial_tilt, self.initial_tilt, (m, 2))
        seeds = [int(x) for x in rng.integers(0, 2**63, m)]
        attitudes = np.column_stack([tilts, np.zeros(m)])
        return self.batch.reset([int(k) for k in indices], seeds=seeds, positions=self._home + offsets, attitudes_rpy=attitudes)

    def _vectors(self, d: dict[str, Any]) -> np.ndarray:
        b = len(d["t"])
        parts = [
            d["position"] - d["reference_position"],
            d["velocity_world"] - d["reference_velocity"],
            d["rotation"].reshape(b, 9),
            d["angular_velocity"],
        ]
        if self.observe_reference:
            parts += [d["reference_rotation"].reshape(b, 9), d["reference_angular_velocity"]]
        return np.concatenate(parts, axis=1).astype(np.float32)

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None) -> tuple[np.ndarray, dict[str, Any]]:
        """Resets every team (initial poses drawn with the environment's generator)."""
        super().reset(seed=seed)
        d = self._reset_teams(np.arange(self.num_envs))
        self._autoreset[:] = False
        self._last = self._vectors(d)
        return self._last.copy(), {}

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One controller period for every team (teams that ended last step are reset instead)."""
        shape = (self.num_envs, *self._low.shape)
        a = np.clip(np.asarray(actions, dtype=np.float64).reshape(shape), self._low, self._high)
        resetting = self._autoreset.copy()
        if resetting.any():
            self._reset_teams(np.flatnonzero(resetting))
        active = [bool(x) for x in ~resetting]
        d = self.batch.step_wrench(a, active=active) if self.action_mode == "wrench" else self.batch.step(a, active=active)
        obs = self._vectors(d)
        failed = np.array([e is not None for e in d["errors"]])
        obs[failed] = self._last[failed]
        e_x = d["position"] - d["reference_position"]
        e_v = d["velocity_world"] - d["reference_velocity"]
        trace = np.einsum("kji,kji->k", d["reference_rotation"], d["rotation"])
        omega = d["angular_velocity"]
        w = self.weights
        reward = w["alive"] - (
            w["position"] * np.einsum("ki,ki->k", e_x, e_x)
            + w["velocity"] * np.einsum("ki,ki->k", e_v, e_v)
            + w["attitude"] * 0.5 * (3.0 - trace)
            + w["rate"] * np.einsum("ki,ki->k", omega, omega)
            + w["action"] * np.sum((a / self._scale) ** 2, axis=tuple(range(1, a.ndim)))
        )
        error = np.linalg.norm(d["true_position"] - d["reference_position"], axis=1)
        tilt = np.arccos(np.clip(d["rotation"][:, 2, 2], -1.0, 1.0))
        terminated = (error > self.max_position_error) | (tilt > self.max_tilt) | failed
        truncated = d["done"] & ~terminated
        reward = np.where(failed, -100.0, reward)
        reward[resetting] = 0.0
        terminated[resetting] = False
        truncated[resetting] = False
        self._autoreset = terminated | truncated
        self._last = obs
        return obs.copy(), reward.astype(np.float64), terminated, truncated, {}


#: :class:`TeamEnv` under its first name (its default scenario is the hover).
HoverEnv = TeamEnv
#: :class:`TeamVectorEnv` under its first name.
HoverVectorEnv = TeamVectorEnv

for _id, _kwargs in ENVIRONMENTS.items():
    if _id not in gym.registry:
        gym.register(id=_id, entry_point="tvmd.gym:TeamEnv", vector_entry_point="tvmd.gym:TeamVectorEnv", kwargs=_kwargs)

__all__ = [
    "AGENT_FAILURE_TOML",
    "DEFAULT_WEIGHTS",
    "ENVIRONMENTS",
    "HOVER_ID",
    "HoverEnv",
    "HoverVectorEnv",
    "TeamEnv",
    "TeamVectorEnv",
]
