"""The cycle's stages from Python: ``law_stage`` then ``allocate`` is ``step`` bit for bit,
``plan`` plans what the step planned, and bad input raises the documented errors."""

import numpy as np
import pytest

import tvmd


def _roll(phi: float) -> np.ndarray:
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


@pytest.mark.parametrize("law", ["paper", "offset-free"])
def test_law_stage_then_allocate_is_the_step(law: str) -> None:
    team = tvmd.Team.a4_inc()
    whole = tvmd.Controller(team, law=law)
    staged = tvmd.Controller(team, law=law)
    for k in range(25):
        state = {"position": [0.2 - 0.01 * k, 0.0, 1.5]}
        reference = {"position": [0.0, 0.0, 1.5], "attitude": _roll(0.05 * k)}
        out = whole.step(state, reference)
        stage = staged.law_stage(state, reference)
        alloc = staged.allocate(stage.wrench)
        np.testing.assert_array_equal(stage.wrench, out.law.u_d)
        np.testing.assert_array_equal(stage.planner.R_d, out.planner.R_d)
        np.testing.assert_array_equal(alloc.commands, out.commands)
        assert alloc.allocation.e_f == out.allocation.e_f
        assert alloc.torque_error >= 0.0
    plan = staged.plan(_roll(1.0), out.f_r)
    assert plan.theta >= 0.0


def test_stages_refuse_bad_input() -> None:
    c = tvmd.Controller(tvmd.Team.a4_inc(), law="paper")
    weight = c.team.mass * 9.81
    good = c.allocate([0, 0, 0, 0, 0, weight])
    assert np.all(good.commands[:, 2] > 0)
    with pytest.raises(ValueError, match="wrench"):
        c.allocate([0, 0, 0, 0, float("nan"), weight])
    with pytest.raises(ValueError, match="wrench"):
        c.allocate([0, 0, weight])
    with pytest.raises(ValueError):
        c.plan(np.eye(3) * 2.0, [0.0, 0.0, weight])
    with pytest.raises(tvmd.CycleError) as e:
        c.law_stage({"position": [np.inf, 0, 1]}, {"position": [0, 0, 1]})
    np.testing.assert_array_equal(e.value.commands, good.commands)
