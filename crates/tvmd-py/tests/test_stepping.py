"""``tvmd.sim.Simulation``: the simulator stepped from Python with one's own controller.

A user-written PD law holds the hover through ``step_wrench`` (a body wrench through tvmd's
allocation) and through ``step`` (per-agent thrusts from one's own allocation); the tvmd
controller (``ScenarioController``) flown through the same steps reproduces ``tvmd.sim.run``'s
flight exactly (every array equal, not close); bad actions raise ``ValueError`` and change
nothing; ``reset`` replays or reseeds the noise.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import tvmd
import tvmd.sim as sim

G = 9.81
E3 = np.array([0.0, 0.0, 1.0])
# The run's fields that are not the flight: the wall clock, and where the controller ran.
NOT_FLIGHT = {"wall_time", "real_time_factor", "controller_target"}


def vee(m):
    return np.array([m[2, 1], m[0, 2], m[1, 0]])


def pd_wrench(obs, mass, kp=4.0, kd=4.0, kr=2.0, kw=0.5):
    """A PD law on the position (world force) and attitude (body torque): the body wrench."""
    s, r = obs.state, obs.reference
    f = mass * (G * E3 - kp * (s.position - r.position) - kd * (obs.velocity_world - r.velocity))
    rot, rot_r = s.attitude, r.attitude
    e_r = 0.5 * vee(rot_r.T @ rot - rot.T @ rot_r)
    tau = -kr * e_r - kw * s.angular_velocity
    return np.concatenate([tau, rot.T @ f])


def fly(simulation, law):
    obs = simulation.reset()
    errors = []
    while not obs.done:
        obs = law(obs)
        errors.append(np.linalg.norm(obs.true_state.position - obs.reference.position))
    return np.array(errors)


def test_a_pd_law_holds_hover_through_the_wrench():
    s = sim.Simulation("hover")
    assert (s.n_agents, s.controller_period, s.duration) == (4, 0.01, 12.0)
    errors = fly(s, lambda obs: s.step_wrench(pd_wrench(obs, s.mass)))
    assert len(errors) == 1200 and s.done and s.time == pytest.approx(12.0)
    assert errors.max() < 0.01, errors.max()
    r = s.result()
    assert len(r) == 1200
    # The commands the allocation chose hold the team's weight.
    assert r.commands[-1, :, 2].sum() == pytest.approx(s.mass * G, rel=0.02)
    assert np.isnan(r.e_f).all(), "a wrench step reports no controller diagnostics"


def test_a_pd_law_holds_hover_through_commands():
    # One's own allocation: vertical thrusts only (gimbals at zero), total thrust and the roll
    # and pitch torques split by a pseudo-inverse over the agents' positions.
    s = sim.Simulation("hover")
    p = tvmd.Team.preset("a4-inc").positions
    split = np.linalg.pinv(np.vstack([np.ones(4), p[:, 1], -p[:, 0]]))

    def law(obs):
        u = pd_wrench(obs, s.mass)
        thrust = u[3:] @ (obs.state.attitude.T @ E3)
        t_i = np.clip(split @ np.array([thrust, u[0], u[1]]), 0.0, s.max_thrust)
        return s.step(np.column_stack([np.zeros(4), np.zeros(4), t_i]))

    errors = fly(s, law)
    assert errors.max() < 0.02, errors.max()
    # The same as normalized rotor speeds: T = max_thrust omega^2.
    s.reset()
    hover = np.sqrt(s.mass * G / 4 / s.max_thrust)
    obs = s.step(np.column_stack([np.zeros(4), np.zeros(4), np.full(4, hover)]), rotor_speeds=True)
    assert s.result().commands[0, :, 2] == pytest.approx(np.full(4, s.mass * G / 4))
    assert abs(obs.true_state.velocity[2]) < 1e-3


@pytest.mark.parametrize("scenario", ["agent-failure", "paper-experiment", "wind"])
def test_the_scenario_controller_reproduces_run_exactly(scenario):
    # agent-failure: a failure the controller is told of; paper-experiment: state noise,
    # feedback latency, actuator lag, model error; wind: gusts.
    ran = sim.run(scenario)
    s = sim.Simulation(scenario)
    controller = sim.ScenarioController(scenario)
    obs = s.reset()
    while not obs.done:
        obs = s.step(controller.step(obs))
    stepped = s.result()
    assert len(stepped) == len(ran) > 100
    for field in ran.FIELDS:
        a, b = getattr(stepped, field), getattr(ran, field)
        if field == "summary":
            a = {k: v for k, v in a.items() if k not in NOT_FLIGHT}
            b = {k: v for k, v in b.items() if k not in NOT_FLIGHT}
            assert a == b
        elif field not in NOT_FLIGHT:
            np.testing.assert_array_equal(a, b, err_msg=field)


def test_commands_alone_fly_the_same_trajectory():
    ran = sim.run("agent-failure")
    s = sim.Simulation("agent-failure")
    controller = sim.ScenarioController("agent-failure")
    obs = s.reset()
    while not obs.done:
        out = controller.step(obs)
        assert out.commands.shape == (4, 3)
        obs = s.step(out.commands)
    r = s.result()
    for field in ("t", "position", "velocity", "attitude_rpy", "commands", "actual", "failed"):
        np.testing.assert_array_equal(getattr(r, field), getattr(ran, field), err_msg=field)


def test_bad_actions_raise_and_change_nothing():
    s = sim.Simulation("hover")
    s.step(np.zeros((4, 3)))
    t, position = s.time, s.state.position
    bad = [np.zeros((3, 3)), np.zeros((4, 2)), np.zeros(12), np.full((4, 3), np.nan), [[0, 0, np.inf]] * 4]
    for commands in bad:
        with pytest.raises(ValueError, match="commands"):
            s.step(commands)
    with pytest.raises(ValueError, match="negative rotor speed"):
        s.step(np.full((4, 3), -0.1), rotor_speeds=True)
    for wrench in (np.zeros(5), np.array([0, 0, 0, 0, 0, np.nan]), "abc"):
        with pytest.raises((ValueError, TypeError)):
            s.step_wrench(wrench)
    assert s.time == t and np.array_equal(s.state.position, position)
    assert len(s.result()) == 1
    short = sim.Simulation(toml='name = "short"\nduration = 0.02\n')
    short.step(np.zeros((4, 3)))
    assert short.step(np.zeros((4, 3))).done
    with pytest.raises(ValueError, match="reset"):
        short.step(np.zeros((4, 3)))
    with pytest.raises(ValueError):
        sim.Simulation("no-such-scenario")
    with pytest.raises(ValueError, match="seed"):
        s.reset(seed=-1)


def test_reset_replays_or_reseeds_the_noise():
    # paper-experiment feeds the controller a noisy state.
    s = sim.Simulation("paper-experiment")

    def fed(seed):
        obs = s.reset(seed)
        out = [obs.state.position]
        for _ in range(20):
            obs = s.step_wrench(pd_wrench(obs, s.mass))
            out.append(obs.state.position)
        return np.array(out)

    first = fed(None)
    assert s.time == pytest.approx(0.2)
    np.testing.assert_array_equal(fed(None), first)
    other = fed(3)
    assert not np.array_equal(other, first)
    np.testing.assert_array_equal(fed(3), other)
    # The observation of a tick is drawn once.
    a, b = s.observe(), s.observe()
    np.testing.assert_array_equal(a.state.position, b.state.position)


def test_a_team_flies_the_hover():
    s = sim.Simulation(team="a6-inc")
    assert s.n_agents == 6
    errors = fly(s, lambda obs: s.step_wrench(pd_wrench(obs, s.mass)))
    assert errors.max() < 0.01
    obs = s.observe()
    assert obs.done and set(obs.to_dict()) == set(sim.Observation.FIELDS)


def test_a_tvmd_team_flies_in_run_and_in_the_simulation():
    # A Team built in Python (a ring of six, not a preset of the scenarios) flies everywhere.
    ring = tvmd.Team.ring(6, 0.4, True, math.pi / 6, math.pi / 4, 2 * 0.7 * G)
    s = sim.Simulation(team=ring)
    assert s.n_agents == 6 and s.mass == pytest.approx(ring.mass)
    np.testing.assert_allclose(s.agent_positions, ring.positions, atol=1e-12)
    assert s.max_thrust == ring.max_thrust and s.gimbal_limits == (ring.sigma_x, ring.sigma_y)
    errors = fly(s, lambda obs: s.step_wrench(pd_wrench(obs, s.mass)))
    assert errors.max() < 0.01
    r = sim.run("hover", team=ring)
    assert r.n_agents == 6 and abs(r.position[-1] - r.reference_position[-1]).max() < 0.01
    # The catalogue's A6-Inc as a tvmd.Team flies as the name does, to round-off.
    by_name = sim.run("hover", team="a6-inc")
    by_team = sim.run("hover", team=tvmd.Team.preset("a6-inc"))
    np.testing.assert_allclose(by_team.position, by_name.position, atol=1e-9)
    with pytest.raises(TypeError, match="team"):
        sim.Simulation(team=6)


def test_a_nan_in_one_teams_action_fails_only_that_team():
    """As the Rust batch: a non-finite action is its team's error; the others step, and the
    failed team's simulation is unchanged (its next finite step starts where it stood)."""
    batch = sim.SimulationBatch("hover", count=3, jobs=2)
    start = batch.reset(seeds=[1, 2, 3])
    hover = np.zeros((3, 6))
    hover[:, 5] = batch.mass * G
    wrenches = hover.copy()
    wrenches[1, 2] = np.nan
    out = batch.step_wrench(wrenches)
    assert out["errors"][0] is None and out["errors"][2] is None
    assert "non-finite wrench component 2" in out["errors"][1]
    assert np.isnan(out["position"][1]).all()
    assert np.isfinite(out["position"][[0, 2]]).all()
    assert (out["t"][[0, 2]] > start["t"][[0, 2]]).all()
    again = batch.step_wrench(hover, active=[False, True, False])
    assert again["errors"] == [None, None, None]
    assert again["t"][1] == out["t"][0]
    commands = np.zeros((3, batch.n_agents, 3))
    commands[:, :, 2] = batch.mass * G / batch.n_agents
    commands[2, 0, 0] = np.inf
    out = batch.step(commands)
    assert out["errors"][0] is None and out["errors"][1] is None
    assert out["errors"][2] is not None and "non-finite" in out["errors"][2]
    assert np.isfinite(out["position"][[0, 1]]).all()


def test_a_batch_whose_every_team_failed_keeps_its_shapes():
    # Issues 57 and 58 together: every array keeps (B, n, ...) when no team stepped.
    batch = sim.SimulationBatch("hover", count=2, jobs=1)
    batch.reset()
    out = batch.step(np.full((2, batch.n_agents, 3), np.nan))
    assert all(e is not None for e in out["errors"])
    assert out["saturation"].shape == (2, batch.n_agents, 3)
    assert np.isnan(out["saturation"]).all() and out["position"].shape == (2, 3)


def test_observations_carry_the_agents_reports_and_links_apply():
    """Issue 60: with ``[reports]`` each observation has (n, 4) reports (NaN before the first),
    20 ms old by default; a ``[links]`` flight still holds its hover; without either, None."""
    base = sim.scenario_toml("hover").replace('duration = 12.0', 'duration = 1.0')
    s = sim.Simulation(toml=base + "\n[reports]\nlying = [1]\n\n[links]\nlatency = 0.02\nloss = 0.05\n")
    controller = sim.ScenarioController(toml=base)
    obs = s.reset()
    assert obs.reports.shape == (4, 4) and np.isnan(obs.reports).all()
    while not obs.done:
        obs = s.step(controller.step(obs))
    ages = obs.reports[:, 3]
    assert np.all((ages >= 0.02 - 1e-9) & (ages <= 0.03 + 1e-9)), ages
    assert abs(obs.reports[:, 0].sum() - 4 * obs.reports[0, 0]) < 1.0  # four agents share the weight
    assert np.linalg.norm(obs.true_state.position - np.array([0.0, 0.0, 1.5])) < 0.05
    assert sim.Simulation("hover").reset().reports is None
    with pytest.raises(ValueError, match="reports.lying"):
        sim.Simulation(toml=base + "\n[reports]\nlying = [9]\n")


def test_link_stats_count_each_agents_commands_and_restart_on_reset():
    """Issue 60: ``Simulation.link_stats()`` is per agent the commands sent, lost, stale and
    the failsafes, as int arrays; None without ``[links]``."""
    base = sim.scenario_toml("hover").replace('duration = 12.0', 'duration = 1.0')
    s = sim.Simulation(toml=base + "\n[links]\nlatency = 0.005\njitter = 0.02\nloss = 0.3\n")
    controller = sim.ScenarioController(toml=base)
    obs = s.reset()
    ticks = 0
    while not obs.done:
        obs = s.step(controller.step(obs))
        ticks += 1
    stats = s.link_stats()
    assert set(stats) == {"sent", "lost", "stale", "failsafes"}
    for counts in stats.values():
        assert counts.shape == (4,) and counts.dtype == np.int64 and (counts >= 0).all()
    # Every tick sends each agent one command; 30% loss drops some of the 100, not all.
    assert (stats["sent"] == ticks).all() and ticks == 100
    assert ((stats["lost"] > 5) & (stats["lost"] < 60)).all(), stats["lost"]
    # A jitter four times the latency lets newer commands overtake older ones.
    assert stats["stale"].sum() > 0
    assert (stats["lost"] + stats["stale"] <= stats["sent"]).all()
    s.reset()
    assert (s.link_stats()["sent"] == 0).all()
    assert sim.Simulation("hover").link_stats() is None
