"""The Python calls of issue 13 ("safe on any input"): each raises a ValueError or returns
admissible, non-zero results."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tvmd

HOVER = {"position": [0, 0, 1.5]}


def _admissible(team, forces):
    """Every agent force is inside E_f of the paper's limits (thrust and gimbal angles)."""
    eta_x, eta_y, thrust = (np.asarray(a) for a in tvmd.gimbal_inverse(np.asarray(forces)))
    tol = 1e-9
    assert np.all(np.isfinite(thrust)) and np.all(thrust <= 13.734 * (1 + tol))
    assert np.all(np.abs(eta_x) <= math.pi / 6 + tol)
    assert np.all(np.abs(eta_y) <= math.pi / 4 + tol)


def test_step_with_huge_angular_velocity_raises():
    c = tvmd.Controller(tvmd.Team.a4_inc())
    with pytest.raises(ValueError, match="angular_velocity") as e:
        c.step(
            {"position": [0, 0, 1.5], "angular_velocity": [1e154, 0, 0]},
            {"position": [0, 0, 1.5], "angular_velocity": [0, 1, 0]},
        )
    assert isinstance(e.value, tvmd.CycleError)
    assert e.value.field == "state.angular_velocity"
    assert np.all(np.isfinite(e.value.commands))


def test_step_with_huge_position_raises():
    c = tvmd.Controller(tvmd.Team.a4_inc())
    with pytest.raises(tvmd.CycleError, match="beyond") as e:
        c.step({"position": [1e200, 0, 1.5]}, HOVER)
    assert e.value.field == "state.position"


def test_step_far_above_the_reference_is_unattainable():
    c = tvmd.Controller(tvmd.Team.a4_inc())
    held = c.step(HOVER, HOVER).commands
    with pytest.raises(tvmd.CycleError, match="zero thrust") as e:
        c.step({"position": [0, 0, 200.0]}, HOVER)
    assert e.value.field == "force_request"
    np.testing.assert_array_equal(e.value.commands, held)


def test_allocate_huge_request_saturates():
    team = tvmd.Team.a4_inc()
    out = tvmd.allocate(team, [0, 0, 0, 0, 0, 1e155])
    _admissible(team, out.forces)
    assert np.allclose(np.linalg.norm(out.forces, axis=1), 13.734, rtol=1e-9)
    assert math.isfinite(out.e_f) and out.e_f == pytest.approx(1e155, rel=1e-12)
    assert all(out.saturated)


def test_allocate_downward_request_leaves_at_most_the_request():
    team = tvmd.Team.a4_inc()
    out = tvmd.allocate(team, [0, 0, 0, 0, 0, -1])
    _admissible(team, out.forces)
    assert out.e_f <= 1.0 + 1e-12


@pytest.mark.parametrize("r_r", [np.zeros((3, 3)), 2 * np.eye(3)])
def test_plan_with_a_non_rotation_raises(r_r):
    afs = tvmd.Team.a4_inc().afs()
    with pytest.raises(ValueError, match="rotation"):
        tvmd.AttitudePlanner(0.5).plan(afs, r_r, [0, 0, 27])


@pytest.mark.parametrize("thrust", [1e155, 1e-160])
def test_gimbal_inverse_at_extreme_magnitudes(thrust):
    eta_x, eta_y, t = tvmd.gimbal_inverse(tvmd.gimbal_force(0.2, -0.3, thrust))
    assert t == pytest.approx(thrust, rel=1e-14)
    assert eta_x == pytest.approx(0.2, abs=1e-15)
    assert eta_y == pytest.approx(-0.3, abs=1e-15)


def test_project_huge_request_is_a_non_zero_member():
    afs = tvmd.Team.a4_inc().afs()
    v = np.array([0.3, -0.2, 1.0])
    force, t_tf, t_eta = afs.project(v * 1e155)
    assert np.all(np.isfinite(force)) and force[2] > 0
    assert afs.contains(force)
    expected, _, _ = afs.project(v * 100)
    np.testing.assert_allclose(force, expected, rtol=1e-9)


def test_contains_never_admits_a_downward_force():
    afs = tvmd.AttainableForceSpace(4, 2, math.pi / 6, math.pi / 2, 13.734)
    assert not afs.contains([0, 0, -1], s=1)
    assert afs.contains([1, 0, 0], s=1)
