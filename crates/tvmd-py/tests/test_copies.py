"""Pickle and ``copy.deepcopy`` of what an environment holds (issue 57, item 4): ``Team`` and
``Gains`` round-trip bit for bit; a ``Controller`` deep copy is the controller mid-flight, its
pickle the controller as constructed with its failures and landed flag; a ``Simulation`` copy
(deep copy or pickle) replays its flight, so both go on exactly as the original would; records
such as ``StepOutput`` are immutable and deep-copy to themselves, and a ``StepOutput`` pickles to
the same output, bit for bit. Gymnasium's tools then work on an environment made with a
``tvmd.Team``.
"""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import tvmd
import tvmd.sim as ts


def _same_team(a, b):
    for name in tvmd.Team.FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and np.array_equal(x, y), name
        else:
            assert x == y, name


def _teams():
    ring = tvmd.Team.ring(8, 1.0, True)
    rotor = tvmd.Team.from_rotor(
        ring.positions, ring.quarter_turns, 0.7, 0.5, 0.7, rho=1.225, d=0.2, c_l=0.11, sigma_omega=650.0
    )
    inertias = np.tile(np.diag([1e-3, 2e-3, 3e-3]), (4, 1, 1))
    a4 = tvmd.Team.a4_inc()
    heavy = tvmd.Team(
        a4.positions, a4.quarter_turns, a4.masses, 0.5, 0.7, 13.0, min_thrust=0.5,
        navigator_mass=0.3, navigator_inertia=np.diag([0.01, 0.02, 0.03]), agent_inertias=inertias,
    )
    return [ring, rotor, a4, heavy]


@pytest.mark.parametrize("index", range(4))
def test_a_team_pickles_and_deep_copies_bit_for_bit(index):
    team = _teams()[index]
    for copied in (pickle.loads(pickle.dumps(team)), copy.deepcopy(team), copy.copy(team)):
        _same_team(team, copied)
        assert repr(copied) == repr(team)


def test_gains_pickle_to_the_same_matrices():
    gains = tvmd.Gains(np.diag([1.0, 2.0, 3.0]), [4.0, 4.5, 5.0], np.diag([5.0, 6.0, 7.0, 8.0, 9.0, 10.0]))
    back = pickle.loads(pickle.dumps(gains))
    for name in tvmd.Gains.FIELDS:
        assert np.array_equal(getattr(back, name), getattr(gains, name)), name


def _hover_inputs(k):
    state = {"position": [0.01 * k, -0.02, 1.0 + 0.01 * k], "velocity": [0.1, 0.0, -0.05]}
    return state, {"position": [0.0, 0.0, 1.0]}


def test_a_controller_deep_copy_goes_on_exactly_as_the_original():
    c = tvmd.Controller(tvmd.Team.a4_inc(), rate_limits=(3.0, 3.0))
    for k in range(5):
        c.step(*_hover_inputs(k))
    d = copy.deepcopy(c)
    e = copy.copy(c)
    for k in range(5, 10):
        expected = c.step(*_hover_inputs(k)).commands
        assert np.array_equal(d.step(*_hover_inputs(k)).commands, expected)
        assert np.array_equal(e.step(*_hover_inputs(k)).commands, expected)


def test_a_controller_pickles_as_constructed_with_its_failures_and_landed_flag():
    team = tvmd.Team.preset("a6-inc") if "a6-inc" in tvmd.Team.preset_names() else tvmd.Team.ring(6, 0.5, True)
    kwargs = dict(relaxation=0.4, period=0.02, rate_limits=(2.0, 2.5), law="paper", planner_max_iterations=40)
    c = tvmd.Controller(team, **kwargs)
    c.step(*_hover_inputs(0))
    c.set_failures([1])
    c.set_landed(True)
    back = pickle.loads(pickle.dumps(c))
    assert repr(back) == repr(c)
    assert back.failed == [1] and back.landed
    assert (back.period, back.relaxation, back.rate_limits) == (0.02, 0.4, (2.0, 2.5))
    assert back.planner_max_iterations == 40 and back.law == "paper"
    # The flight state starts afresh: as a new controller with the same failures and flag.
    fresh = tvmd.Controller(team, **kwargs)
    fresh.set_failures([1])
    fresh.set_landed(True)
    for k in range(3):
        assert np.array_equal(back.step(*_hover_inputs(k)).commands, fresh.step(*_hover_inputs(k)).commands)


def test_step_outputs_and_observations_deep_copy_to_themselves():
    out = tvmd.Controller(tvmd.Team.a4_inc()).step(*_hover_inputs(0))
    assert copy.deepcopy(out) is out and copy.copy(out) is out
    obs = ts.Simulation("hover").reset()
    assert copy.deepcopy(obs) is obs


def _same_record(a, b):
    """Every field of two records equal, arrays bit for bit (NaN where NaN), nested records too."""
    assert type(a) is type(b)
    for name in type(a).FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        if hasattr(x, "FIELDS"):
            _same_record(x, y)
        elif isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape, name
            assert np.array_equal(x.view(np.uint8), y.view(np.uint8)), name
        elif isinstance(x, float):
            assert np.float64(x).tobytes() == np.float64(y).tobytes(), name
        else:
            assert x == y, name


@pytest.mark.parametrize("method", ["redistributed-pseudo-inverse", "exact-boundary-redistribution"])
def test_a_step_output_pickles_to_the_same_output(method):
    c = tvmd.Controller(tvmd.Team.preset("a6-inc"), allocator=method)
    c.set_failures([2])
    state, reference = _hover_inputs(0)
    a = 1.2  # a roll no A6 holds: the planner searches, the allocation saturates
    reference["attitude"] = [[1.0, 0.0, 0.0], [0.0, np.cos(a), -np.sin(a)], [0.0, np.sin(a), np.cos(a)]]
    out = c.step(state, reference)
    assert out.planner.status == "planned" and out.allocation.method == method
    back = pickle.loads(pickle.dumps(out))
    assert back is not out
    _same_record(out, back)
    assert back.commands.shape == (6, 4)


def test_a_malformed_step_output_state_is_refused():
    out = tvmd.Controller(tvmd.Team.a4_inc()).step(*_hover_inputs(0))
    restore, (values, n, method, report) = out.__reduce__()
    for bad in [
        (values[:-1], n, method, report),
        (values + [0.0], n, method, report),
        (values, 0, method, report),
        (values, n, "no-such-allocator", report),
        ([0.5] * len(values), n, method, report),
    ]:
        with pytest.raises(ValueError, match="StepOutput"):
            restore(*bad)


def _fly(sim, steps, start=0):
    # Commands, wrenches and a scenario controller's outputs in turn; the observations seen.
    n = sim.n_agents
    hover = sim.mass * 9.81 / n
    controller = ts.ScenarioController(toml=sim.scenario_toml)
    seen = []
    for k in range(start, start + steps):
        if k % 3 == 0:
            obs = sim.step(np.tile([0.01 * (k % 5), -0.01, hover * 1.01], (n, 1)))
        elif k % 3 == 1:
            obs = sim.step_wrench([0.0, 0.001, 0.0, 0.0, 0.0, sim.mass * 9.81])
        else:
            obs = sim.step(controller.step(sim.observe()))
        seen.append((obs.t, obs.state.position, obs.true_state.attitude, obs.state.angular_velocity))
    return seen


def _same_flight(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x[0] == y[0]
        for u, v in zip(x[1:], y[1:]):
            assert np.array_equal(u, v)


def test_a_simulation_copy_and_pickle_go_on_exactly_as_the_original():
    sim = ts.Simulation("wind")
    sim.reset(7, position=[0.05, -0.02, 1.55], attitude_rpy=[0.02, -0.01, 0.0])
    _fly(sim, 20)
    with pytest.raises(ValueError):
        sim.step(np.full((sim.n_agents, 3), np.nan))  # refused, and refused again in the copies
    deep, plain, pickled = copy.deepcopy(sim), copy.copy(sim), pickle.loads(pickle.dumps(sim))
    assert pickled.time == deep.time == plain.time == sim.time
    assert pickled.scenario_toml == sim.scenario_toml
    expected = _fly(sim, 15, start=20)
    for other in (deep, plain, pickled):
        _same_flight(_fly(other, 15, start=20), expected)
        assert np.array_equal(other.result().position, sim.result().position)


def test_a_simulation_of_a_tvmd_team_pickles():
    sim = ts.Simulation("hover", team=tvmd.Team.ring(8, 1.0, True), max_samples=50)
    sim.reset(3)
    _fly(sim, 4)
    back = pickle.loads(pickle.dumps(sim))
    assert back.n_agents == 8
    _same_flight(_fly(back, 4, start=4), _fly(sim, 4, start=4))
    assert len(back.result()) == len(sim.result())


def test_a_gymnasium_environment_made_with_a_team_passes_check_env_and_copies():
    gym = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    import tvmd.gym  # noqa: F401  (registers the environments)

    env = gym.make("tvmd/Hover-v0", team=tvmd.Team.ring(8, 1.0, True))
    assert env.spec is not None and env.unwrapped.spec is not None
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(env.unwrapped, skip_render_check=True)
    env.reset(seed=5)
    action = np.zeros(env.action_space.shape, dtype=np.float32)
    action[5] = 8 * 0.7 * 9.81
    env.step(action)
    copies = (copy.deepcopy(env), pickle.loads(pickle.dumps(env)))
    for _ in range(3):
        a = env.step(action)
        for other in copies:
            b = other.step(action)
            assert np.array_equal(a[0], b[0]) and a[1:4] == b[1:4]
