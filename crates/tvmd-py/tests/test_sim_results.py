"""What a ``SimResult`` keeps for a researcher: body rates, rotation matrices, frame-named
velocities (``velocity`` kept as the world-frame alias), the agents' forces and rotor speeds,
flat columns for pandas; and ``run_many(errors="keep")``, which keeps every successful run and
reports each failure by its index.
"""

from __future__ import annotations

import numpy as np
import pytest

import tvmd.sim as sim

SHORT_HOVER = {"toml": 'name = "short"\nduration = 1.0\n'}
# A push no team can hold: the speed passes the simulator's 300 m/s bound, the run fails in flight.
DIVERGING = 'name = "pushed"\nduration = 2.0\n[disturbances.external_wrench]\nforce = [0.0, 0.0, 10000.0]\n'


@pytest.fixture(scope="module")
def tilt():
    # The paper's flight: attitude and rates change, every agent works.
    return sim.run("paper-tilt")


def rpy_matrix(rpy):
    r, p, y = rpy
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    return rz @ ry @ rx


def test_pose_rates_and_frame_named_velocities(tilt):
    k = len(tilt)
    rot = tilt.rotation
    assert rot.shape == (k, 3, 3) and tilt.angular_velocity.shape == (k, 3)
    np.testing.assert_allclose(np.einsum("kji,kjl->kil", rot, rot), np.broadcast_to(np.eye(3), (k, 3, 3)), atol=1e-12)
    for i in (0, k // 3, 2 * k // 3, k - 1):
        np.testing.assert_allclose(rot[i], rpy_matrix(tilt.attitude_rpy[i]), atol=1e-9)
    np.testing.assert_array_equal(tilt.velocity_world, tilt.velocity)
    np.testing.assert_allclose(tilt.velocity_body, np.einsum("kji,kj->ki", rot, tilt.velocity_world), atol=1e-12)
    assert np.abs(tilt.angular_velocity[:, 0]).max() > 0.1, "the roll tilt turns the team"
    # The body rates integrate to the attitude: R_{k+1} ~ R_k exp(Omega_k dt), to first order.
    dt = tilt.t[1] - tilt.t[0]
    d_rot = np.einsum("kji,kjl->kil", rot[:-1], rot[1:]) - np.eye(3)
    omega = np.stack([d_rot[:, 2, 1], d_rot[:, 0, 2], d_rot[:, 1, 0]], axis=1) / dt
    assert np.abs(omega - tilt.angular_velocity[:-1]).max() < 0.05 * np.abs(tilt.angular_velocity).max() + 0.02


def test_agent_forces_and_rotor_speeds(tilt):
    forces, actual = tilt.forces, tilt.actual
    assert forces.shape == actual.shape == (len(tilt), tilt.n_agents, 3)
    # Nominal actuation: each force has the actual thrust as its magnitude.
    np.testing.assert_allclose(np.linalg.norm(forces, axis=2), actual[:, :, 2], rtol=1e-12, atol=1e-12)
    # In hover the forces hold the weight.
    hover = sim.run("hover")
    assert hover.forces[-1, :, 2].sum() == pytest.approx(hover.mass * hover.gravity, rel=0.01)
    max_thrust = sim.Simulation("paper-tilt").max_thrust
    np.testing.assert_allclose(tilt.rotor_speeds**2 * max_thrust, tilt.commands[:, :, 2], rtol=1e-12, atol=1e-12)
    assert 0.0 < tilt.rotor_speeds.max() <= 1.0


def test_flat_columns_and_pandas(tilt):
    columns = tilt.to_columns()
    k = len(tilt)
    assert all(c.shape == (k,) for c in columns.values())
    for name in ("t", "position_x", "velocity_world_z", "velocity_body_x", "angular_velocity_y", "rotation_21",
                 "attitude_rpy_roll", "commands_0_thrust", "actual_3_eta_y", "forces_2_z", "rotor_speeds_1",
                 "failed_0", "e_f", "V_x"):  # fmt: skip
        assert name in columns, name
    assert "velocity_x" not in columns, "the alias is one column"
    np.testing.assert_array_equal(columns["rotation_21"], tilt.rotation[:, 2, 1])
    np.testing.assert_array_equal(columns["commands_0_thrust"], tilt.commands[:, 0, 2])
    pandas = pytest.importorskip("pandas")
    frame = tilt.to_pandas()
    assert isinstance(frame, pandas.DataFrame) and frame.shape == (k, len(columns))
    assert list(frame.columns) == list(columns)
    assert frame["position_z"].max() == pytest.approx(tilt.position[:, 2].max())
    # The nested form is unchanged: to_dict holds every field.
    assert set(tilt.to_dict()) == set(sim.SimResult.FIELDS)


def test_a_batch_keeps_its_successes_and_reports_each_failure_by_index():
    runs = [SHORT_HOVER, "no-such-scenario", {"toml": DIVERGING}, {"scenario": "hover", "relaxation": 5.0}, SHORT_HOVER]
    with pytest.raises(RuntimeError, match=r"runs\[0\] \(pushed\): simulation diverged"):
        sim.run_many(runs[2:3])
    with pytest.raises(ValueError, match="no-such-scenario"):
        sim.run_many(runs)
    out = sim.run_many(runs, errors="keep", jobs=2)
    assert len(out) == 5
    assert isinstance(out[0], sim.SimResult) and isinstance(out[4], sim.SimResult)
    assert len(out[0]) == 100
    np.testing.assert_array_equal(out[0].position, out[4].position)
    # Each failure is the exception "raise" would raise, in the failed run's place.
    assert isinstance(out[1], ValueError) and "no-such-scenario" in str(out[1])
    assert isinstance(out[2], RuntimeError) and "runs[2]" in str(out[2]) and "exceeds" in str(out[2])
    assert isinstance(out[3], ValueError) and "relaxation" in str(out[3])
    failures = [k for k, r in enumerate(out) if isinstance(r, Exception)]
    assert failures == [1, 2, 3]
    with pytest.raises(ValueError, match="errors"):
        sim.run_many(runs, errors="ignore")


def test_a_batch_on_an_executor_keeps_failures_too():
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(2) as pool:
        out = sim.run_many([SHORT_HOVER, {"toml": DIVERGING}], executor=pool, errors="keep")
    assert isinstance(out[0], sim.SimResult)
    assert isinstance(out[1], RuntimeError) and "runs[1]" in str(out[1])


def test_run_many_dicts_fly_a_tvmd_team_as_run_does():
    import tvmd

    team = tvmd.Team.preset("a6-inc")
    alone = sim.run(**SHORT_HOVER, team=team)
    (batched, by_name) = sim.run_many([{**SHORT_HOVER, "team": team}, {**SHORT_HOVER, "team": "a6-inc"}])
    assert alone.n_agents == batched.n_agents == 6
    np.testing.assert_array_equal(batched.position, alone.position)
    np.testing.assert_array_equal(batched.commands, alone.commands)
    assert batched.scenario_toml == alone.scenario_toml
    assert by_name.n_agents == 6
    with pytest.raises(TypeError, match=r"runs\[1\]\['team'\]"):
        sim.run_many([SHORT_HOVER, {**SHORT_HOVER, "team": 3}])
