"""The plant saturates as the hardware does (issue 57, item 1).

Whatever a step is given, the plant holds each agent's command clamped to the gimbal limits and
to thrusts in ``[0, sigma_Tf]`` (a rotor never pushes down its axis), the same in
``Simulation`` and ``SimulationBatch``, and reports by how much it clamped each agent's command
(``Observation.saturation``, the batch's ``"saturation"``). Non-finite commands are refused.
"""

from __future__ import annotations

import numpy as np
import pytest

import tvmd.sim as sim


def held(simulation, commands, **kw):
    """Steps twice with `commands`: the second tick's sample records what the plant held."""
    simulation.step(commands, **kw)
    obs = simulation.step(commands, **kw)
    r = simulation.result()
    return obs, r.actual[-1], r.forces[-1]


def test_downward_thrust_is_never_applied():
    s = sim.Simulation("hover")
    s.reset()
    obs, actual, forces = held(s, np.array([[0.0, 0.0, -5.0]] * 4))
    assert (actual[:, 2] == 0.0).all()
    assert (forces[:, 2] == 0.0).all(), forces
    np.testing.assert_array_equal(obs.saturation, [[0.0, 0.0, -5.0]] * 4)


def test_angles_and_thrust_beyond_the_hardware_are_clamped_and_reported():
    s = sim.Simulation("hover")
    s.reset()
    sx, sy = s.gimbal_limits
    top = s.max_thrust
    command = np.array([[2.0, -2.0, 30.0]] * 4)
    obs, actual, _ = held(s, command)
    np.testing.assert_allclose(actual, [[sx, -sy, top]] * 4, rtol=1e-7)
    np.testing.assert_allclose(obs.saturation, command - actual, rtol=1e-12)
    # A rotor speed of 2 (four times the largest thrust) spins at its largest speed.
    obs, actual, _ = held(s, np.array([[0.0, 0.0, 0.0, 2.0]] * 4), rotor_speeds=True)
    np.testing.assert_allclose(actual[:, 2], top, rtol=1e-7)
    np.testing.assert_allclose(obs.saturation[:, 2], 3.0 * top, rtol=1e-7)


def test_commands_inside_the_range_are_flown_as_given():
    s = sim.Simulation("hover")
    first = s.reset()
    np.testing.assert_array_equal(first.saturation, np.zeros((4, 3)))
    command = np.array([[0.1, -0.2, 4.0], [0.0, 0.0, 0.0], [-0.3, 0.5, 9.0], [0.2, 0.1, 1.0]])
    obs, actual, _ = held(s, command)
    np.testing.assert_array_equal(actual, command)
    np.testing.assert_array_equal(obs.saturation, np.zeros((4, 3)))


def test_the_batch_saturates_each_team_alike():
    b = sim.SimulationBatch("hover", count=2, jobs=1)
    d = b.reset()
    assert d["saturation"].shape == (2, 4, 3) and (d["saturation"] == 0.0).all()
    commands = np.array([[[0.0, 0.0, -5.0]] * 4, [[0.1, 0.0, 4.0]] * 4])
    d = b.step(commands)
    np.testing.assert_array_equal(d["saturation"][0], [[0.0, 0.0, -5.0]] * 4)
    np.testing.assert_array_equal(d["saturation"][1], np.zeros((4, 3)))
    one = sim.Simulation("hover")
    one.reset()
    obs = one.step(commands[0])
    np.testing.assert_array_equal(d["position"][0], obs.state.position)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_commands_are_refused(bad):
    s = sim.Simulation("hover")
    s.reset()
    with pytest.raises(ValueError):
        s.step(np.array([[0.0, 0.0, bad]] * 4))
    # In a batch the non-finite command is its team's failure, as in the Rust batch (issue 58).
    b = sim.SimulationBatch("hover", count=1, jobs=1)
    b.reset()
    out = b.step(np.array([[[bad, 0.0, 1.0]] * 4]))
    assert out["errors"][0] is not None and "non-finite" in out["errors"][0]


@pytest.mark.parametrize(
    ("scenario", "kw"),
    [
        ("paper-tilt", {}),
        ("paper-tilt", {"precision": "f32"}),
        ("agent-failure", {}),
        ("a6-agent-failure", {}),
        ("wind", {}),
        ("figure-eight", {"precision": "f32"}),
    ],
)
def test_the_tvmd_controller_is_never_clamped(scenario, kw):
    # Its commands lie inside the hardware's range: the plant flies them as given, so its
    # flights (and run's, which steps the same way) are those of before the saturation.
    s = sim.Simulation(scenario, **kw)
    ctrl = sim.ScenarioController(scenario, **kw)
    obs = s.reset()
    while not obs.done:
        obs = s.step(ctrl.step(obs))
        assert (obs.saturation == 0.0).all(), (obs.t, obs.saturation)
