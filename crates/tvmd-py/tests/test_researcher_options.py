"""What researchers asked of the Python surfaces (issue 57, item 11): a ``SimResult`` of your own
controller does not claim the scenario's law and relaxation flew; the environments can observe
the reference attitude and rates their reward compares against; ``run`` and ``Simulation``
turn on fault detection and the allocator's round cap.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import tvmd.sim as ts

ROOT = Path(__file__).resolve().parents[3]


def _hover_commands(sim):
    return np.tile([0.0, 0.0, sim.mass * 9.81 / sim.n_agents], (sim.n_agents, 1))


def test_your_own_controllers_result_names_no_law_or_relaxation():
    sim = ts.Simulation("hover")
    sim.reset(1)
    for _ in range(3):
        sim.step(_hover_commands(sim))
    own = sim.result()
    assert own.law is None and own.relaxation is None
    assert "law=None" in repr(own) and "relaxation=None" in repr(own)
    sim.reset(1)
    sim.step_wrench([0, 0, 0, 0, 0, sim.mass * 9.81])
    assert sim.result().law is None
    # The scenario's controller flying every step is the scenario's law and relaxation.
    sim.reset(1)
    controller = ts.ScenarioController("hover")
    obs = sim.observe()
    for _ in range(3):
        obs = sim.step(controller.step(obs))
    flown = sim.result()
    reference = ts.run("hover", max_samples=10)
    assert flown.law == reference.law and flown.relaxation == reference.relaxation
    assert flown.law is not None


def test_the_environments_observe_the_reference_attitude_and_rates_on_request():
    gym = pytest.importorskip("gymnasium")
    import warnings

    from gymnasium.utils.env_checker import check_env

    import tvmd.gym  # noqa: F401  (registers the environments)

    plain = gym.make("tvmd/Tracking-v0")
    extended = gym.make("tvmd/Tracking-v0", observe_reference=True)
    assert plain.observation_space.shape == (18,) and extended.observation_space.shape == (30,)
    a, _ = plain.reset(seed=4)
    b, _ = extended.reset(seed=4)
    assert np.array_equal(a, b[:18])
    action = np.zeros(extended.action_space.shape, dtype=np.float32)
    action[5] = extended.unwrapped.sim.mass * 9.81
    for _ in range(30):
        a = plain.step(action)[0]
        b = extended.step(action)[0]
    assert np.array_equal(a, b[:18])
    r = extended.unwrapped.sim.observe().reference
    assert np.array_equal(b[18:27], r.attitude.reshape(9).astype(np.float32))
    assert np.array_equal(b[27:], r.angular_velocity.astype(np.float32))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(gym.make("tvmd/Hover-v0", observe_reference=True).unwrapped, skip_render_check=True)
    with pytest.raises(ValueError, match="observe_reference"):
        gym.make("tvmd/Hover-v0", observe_reference="yes")
    vec = gym.make_vec("tvmd/Tracking-v0", num_envs=3, vectorization_mode="vector_entry_point", observe_reference=True)
    obs, _ = vec.reset(seed=2)
    assert obs.shape == (3, 30)
    obs = vec.step(np.tile(action, (3, 1)))[0]
    batch_like = ts.Simulation("figure-eight")
    assert np.allclose(obs[:, 18:27].reshape(3, 3, 3), batch_like.observe().reference.attitude, atol=0.1)


def test_the_batch_reports_the_reference_rates_as_a_simulation_does():
    batch = ts.SimulationBatch("figure-eight", count=2)
    d = batch.reset(seeds=[1, 2])
    sim = ts.Simulation("figure-eight")
    first = sim.reset(1)
    assert d["reference_angular_velocity"].shape == (2, 3)
    assert np.array_equal(d["reference_angular_velocity"][0], first.reference.angular_velocity)


LOSS = (ROOT / "scenarios/faults/loss-hover.toml").read_text().replace('[fault_detection]\nresponse = "mask"\n', "")


def test_run_turns_on_fault_detection():
    assert "[fault_detection]" not in LOSS
    off = ts.run(toml=LOSS)
    assert off.summary.get("fault") is None
    on = ts.run(toml=LOSS, fault_detection="mask")
    assert on.summary["fault"]["masked"]["agent"] == 0
    assert "[fault_detection]" in on.scenario_toml
    with pytest.raises(ValueError, match="fault_detection"):
        ts.run("hover", fault_detection={"threshold": -1.0})


def test_run_and_simulation_cap_the_allocators_rounds():
    assert "allocator_max_rounds = 2" in ts.run("hover", max_rounds=2, max_samples=5).scenario_toml
    sim = ts.Simulation("hover", max_rounds=1, fault_detection="report")
    assert "allocator_max_rounds = 1" in sim.scenario_toml and "[fault_detection]" in sim.scenario_toml
    sim.reset()
    sim.step_wrench([0, 0, 0, 0, 0, sim.mass * 9.81])
    with pytest.raises(ValueError, match="allocator_max_rounds"):
        ts.run("hover", allocator="pseudo-inverse", max_rounds=2)
    with pytest.raises(ValueError, match="max_rounds"):
        ts.Simulation("hover", max_rounds=-1)
