"""Issue 13 from Python: finite but unusable configurations raise ``ConfigError`` (a
``ValueError``) naming the field, and ``set_failures`` / ``Team.hover_capability`` classify a
degraded team (A4-Inc minus any one agent: not hover-capable; A6-Inc minus one: capable)."""

from __future__ import annotations

import numpy as np
import pytest
import tvmd

A4 = tvmd.Team.a4_inc()
A6 = tvmd.Team.ring(6, 0.5, True)
SQUARE = np.array([[1, 1, 0], [1, -1, 0], [-1, -1, 0], [-1, 1, 0]]) * 0.3535533905932738
PAPER = dict(sigma_x=np.pi / 6, sigma_y=np.pi / 4, max_thrust=13.734)


def square(**kw):
    args = dict(positions=SQUARE, quarter_turns=[1, 1, 0, 0], masses=0.7, **PAPER)
    args.update(kw)
    return tvmd.Team(**args)


def raises_config(fn, field, text):
    with pytest.raises(tvmd.ConfigError, match=text) as e:
        fn()
    assert isinstance(e.value, ValueError)
    assert e.value.field == field
    return e.value


def test_huge_masses_and_positions_are_rejected_not_summed_to_inf():
    raises_config(lambda: square(masses=1e308), "agent.mass", "team mass m_C")
    raises_config(lambda: square(masses=1e307), "agent.mass", "weight m_C g")
    raises_config(lambda: square(positions=SQUARE * 1e200), "agent.position", "team inertia J_C")
    big = square(masses=1e300)
    assert np.isfinite(big.mass) and big.mass > 1e300


def test_huge_thrust_and_rotor_constants_overflow():
    raises_config(
        lambda: square(max_thrust=1.7e308), "limits.max_thrust", "total thrust n sigma_Tf"
    )
    raises_config(
        lambda: tvmd.Team.from_rotor(
            SQUARE, [1, 1, 0, 0], 0.7, np.pi / 6, np.pi / 4, 1.2, 0.2, 0.1, 1e200
        ),
        "limits.sigma_omega",
        "not finite in this float type",
    )


@pytest.mark.parametrize(
    "inertia",
    [
        np.array([[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]) * 1e-3,  # not symmetric
        -np.eye(3) * 1e-3,  # negative definite
        np.array([[1, 2, 0], [2, 1, 0], [0, 0, 1]]) * 1e-3,  # positive diagonal, indefinite
    ],
)
def test_agent_inertia_must_be_symmetric_psd(inertia):
    inertias = np.zeros((4, 3, 3))
    inertias[2] = inertia
    e = raises_config(lambda: square(agent_inertias=inertias), "agent.inertia", "agent 2")
    assert "symmetric positive semi-definite" in str(e)
    rod = np.zeros((4, 3, 3))
    rod[1] = np.diag([1e-3, 1e-3, 0.0])
    assert square(agent_inertias=rod).n == 4


def test_controller_gravity_must_keep_the_weight_finite():
    raises_config(lambda: tvmd.Controller(A4, gravity=1e308), "gravity", "weight m_C g")
    for g in [0.0, -9.81]:
        raises_config(lambda g=g: tvmd.Controller(A4, gravity=g), "gravity", "gravity")
    assert tvmd.Controller(A4, gravity=1e300).gravity == 1e300


@pytest.mark.parametrize(
    ("mass", "inertia", "gravity", "field", "text"),
    [
        (0.0, np.eye(3), 9.81, "plant.mass", "must be positive"),
        (-2.8, np.eye(3), 9.81, "plant.mass", "must be positive"),
        (2.8, np.eye(3), 0.0, "gravity", "must be positive"),
        (2.8, np.eye(3), -9.81, "gravity", "must be positive"),
        (2.8, np.diag([1.0, 0.0, 1.0]), 9.81, "plant.inertia", "symmetric positive definite"),
        (2.8, [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]], 9.81, "plant.inertia", "symmetric positive definite"),
        (1e300, np.eye(3), 1e10, "gravity", "weight m_C g"),
    ],
)
def test_plant_is_validated(mass, inertia, gravity, field, text):
    raises_config(lambda: tvmd.Plant(mass, inertia, gravity), field, text)


def test_plant_accepts_valid_values():
    p = tvmd.Plant(2.8, np.eye(3) * 0.1, 9.81)
    assert (p.mass, p.gravity) == (2.8, 9.81)
    assert A4.plant().mass == pytest.approx(2.8)


def test_gains_must_be_symmetric_positive_definite():
    # Symmetric with a positive diagonal, yet indefinite.
    e = raises_config(
        lambda: tvmd.Gains([1, 1, 1], [[1, 2, 0], [2, 1, 0], [0, 0, 1]], np.ones(6)),
        "gains.k_r",
        "symmetric positive definite",
    )
    assert "positive and finite" not in str(e)
    # Not symmetric: named as such, not as "positive and finite".
    e = raises_config(
        lambda: tvmd.Gains([[1, 0.5, 0], [0, 1, 0], [0, 0, 1]], [1, 1, 1], np.ones(6)),
        "gains.k_x",
        "symmetric positive definite",
    )
    assert "positive and finite" not in str(e)


@pytest.mark.parametrize("lost", range(4))
def test_a4_inc_minus_any_one_is_not_hover_capable(lost):
    ctrl = tvmd.Controller(A4)
    assert ctrl.hover_capability.capable
    hover = ctrl.set_failures([lost])
    assert isinstance(hover, tvmd.HoverCapability)
    # The mask is accepted (M keeps rank 6) but hover is not held with a margin.
    assert ctrl.failed == [lost]
    assert not hover.capable
    assert abs(hover.margin) < 1e-9
    assert hover.limit in ("max_thrust", "min_thrust")
    assert hover.limiting_agent != lost
    assert hover.weight == pytest.approx(2.8 * 9.81)
    assert ctrl.hover_capability.to_dict() == hover.to_dict()
    assert A4.hover_capability(failed=[lost]).to_dict() == hover.to_dict()


@pytest.mark.parametrize("lost", range(6))
def test_a6_inc_minus_one_is_hover_capable(lost):
    hover = tvmd.Controller(A6).set_failures([lost])
    assert hover.capable
    assert hover.margin == pytest.approx(0.4, abs=1e-6)
    assert set(hover.FIELDS) == {"capable", "margin", "limiting_agent", "limit", "weight"}
    assert "HoverCapability(" in repr(hover)


def test_team_hover_capability_gravity_and_errors():
    full = A4.hover_capability()
    assert full.capable and full.margin == pytest.approx(1.0)
    # Lighter gravity: A6 minus two opposite-side agents gains a margin it lacks at 9.81.
    assert not A6.hover_capability(failed=[0, 2]).capable
    assert A6.hover_capability(failed=[0, 2], gravity=3.0).capable
    # Rank-deficient masks are classified, not refused.
    assert not A4.hover_capability(failed=[0, 1]).capable
    raises_config(lambda: A4.hover_capability(gravity=0.0), "gravity", "gravity")
    with pytest.raises(tvmd.ConfigError):
        A4.hover_capability(failed=[0, 1, 2, 3])
    with pytest.raises(tvmd.ConfigError):
        A4.hover_capability(failed=[7])


def test_simulator_reports_the_classification_of_a_failure():
    lost = tvmd.sim.run("agent-failure").summary["hover_classifications"]
    assert len(lost) == 1 and lost[0]["time"] == pytest.approx(5.0)
    assert not lost[0]["capable"] and abs(lost[0]["margin"]) < 1e-9 and not lost[0]["landing"]
    kept = tvmd.sim.run("a6-agent-failure").summary["hover_classifications"]
    assert len(kept) == 1 and kept[0]["capable"]
    assert kept[0]["margin"] == pytest.approx(0.4, abs=1e-6)
