"""The control law of ``tvmd.Controller`` and ``tvmd.sim.run`` (keyword ``law``).

The default is the offset-free law (natural gains, disturbance observer, planned attitude
rates); ``law="paper"`` is the paper's eq. (12). A crude translational loop (attitude held level,
the allocation's force integrated with a constant force the controller does not model) shows
what the default is for: its compensation converges to the negative of the unmodelled force
and the position error vanishes, while the paper's law keeps the steady error ``F / k_x``.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import tvmd
import tvmd.sim as sim

A4 = tvmd.Team.a4_inc()
HOVER = {"position": [0.0, 0.0, 1.5]}
# An unmodelled constant force (N, inertial frame), well inside what A4-Inc produces level.
UNMODELLED = np.array([0.3, -0.2, 0.5])
PAPER_TABLE = {"gains": "paper", "offset_free": "off", "attitude_rate": "off"}


def fly(ctrl, steps, force=UNMODELLED, landed=None):
    """``steps`` periods of a point mass under the allocation's force plus ``force``, attitude
    level (so body and inertial frames agree); ``landed(k)`` sets the landed flag per period.
    Returns the final position error, velocity and the compensation force of every period."""
    m, g, dt = A4.mass, ctrl.gravity, ctrl.period
    x, v = np.array(HOVER["position"]), np.zeros(3)
    compensation = []
    for k in range(steps):
        if landed is not None:
            ctrl.set_landed(landed(k))
        out = ctrl.step({"position": x, "velocity": v}, HOVER)
        # The allocation's wrench is [torque; force] in the body frame.
        acceleration = (out.allocation.wrench[3:] + force) / m - np.array([0.0, 0.0, g])
        v = v + dt * acceleration
        x = x + dt * v
        compensation.append(ctrl.offset_free_compensation[0])
    return x - HOVER["position"], v, np.array(compensation)


def test_default_law_is_offset_free_and_differs_from_the_paper():
    default, paper = tvmd.Controller(A4), tvmd.Controller(A4, law="paper")
    assert default.law == "offset-free" and paper.law == "paper"
    assert tvmd.Controller(A4, law="offset-free").law == "offset-free"
    assert "law='offset-free'" in repr(default) and "law='paper'" in repr(paper)
    # Natural gains (scaled by the team) against the paper's as given.
    np.testing.assert_array_equal(paper.gains.k_x, tvmd.Gains.paper().k_x)
    assert not np.array_equal(default.gains.k_x, paper.gains.k_x)
    # With natural gains `gains` is not used.
    custom = tvmd.Gains([1, 1, 1], [2, 2, 2], np.full(6, 3.0))
    np.testing.assert_array_equal(tvmd.Controller(A4, gains=custom).gains.k_x, default.gains.k_x)
    np.testing.assert_array_equal(tvmd.Controller(A4, gains=custom, law="paper").gains.k_x, custom.k_x)
    # The planned-rate filter only in the offset-free law.
    assert paper.planned_rates is None and default.planned_rates is not None
    # The same step away from the setpoint: different requests.
    state = {"position": [0.2, -0.1, 1.4]}
    assert not np.allclose(default.step(state, HOVER).law.u_d, paper.step(state, HOVER).law.u_d)


def test_shown_default_is_the_default_used():
    shown = inspect.signature(tvmd.Controller).parameters["law"]
    assert shown.default == "offset-free" and shown.kind is inspect.Parameter.KEYWORD_ONLY
    ctrl = tvmd.Controller(A4, law=shown.default)
    assert ctrl.law == tvmd.Controller(A4).law == tvmd.Controller(A4, law=None).law
    np.testing.assert_array_equal(ctrl.gains.k_x, tvmd.Controller(A4).gains.k_x)


def test_offset_free_compensation_converges_to_the_unmodelled_force():
    ctrl = tvmd.Controller(A4)
    force, torque = ctrl.offset_free_compensation
    assert force.shape == torque.shape == (3,) and not force.any() and not torque.any()
    error, velocity, compensation = fly(ctrl, 1000)  # 10 s
    np.testing.assert_allclose(compensation[-1], -UNMODELLED, atol=1e-6)
    assert np.abs(error).max() < 1e-5 and np.abs(velocity).max() < 1e-5
    # It was built up by the observer, not there from the start.
    assert np.abs(compensation[10] + UNMODELLED).max() > 0.05
    # No torque is unmodelled here: the torque part stays zero.
    np.testing.assert_allclose(ctrl.offset_free_compensation[1], 0.0, atol=1e-9)
    # reset() clears the offset-free state.
    ctrl.reset()
    assert not np.any(ctrl.offset_free_compensation[0])


def test_paper_law_keeps_the_steady_error():
    ctrl = tvmd.Controller(A4, law="paper")
    error, velocity, compensation = fly(ctrl, 6000)  # 60 s: the paper's gains are slow
    assert not compensation.any()
    # The equilibrium of eq. (12) without offset-free action: K_x e_x = F.
    np.testing.assert_allclose(error, UNMODELLED / np.diag(tvmd.Gains.paper().k_x), rtol=1e-3)
    assert np.abs(velocity).max() < 1e-3


def test_landed_holds_the_compensation_at_zero():
    ctrl = tvmd.Controller(A4)
    assert ctrl.landed is False
    _, _, compensation = fly(ctrl, 300, landed=lambda k: k < 200)
    assert ctrl.landed is False
    assert not compensation[:200].any()
    # After take-off it starts from zero and builds up again.
    assert np.abs(compensation[-1] + UNMODELLED).max() < 0.5 * np.abs(UNMODELLED).max()
    ctrl.set_landed(True)
    assert ctrl.landed is True and not ctrl.offset_free_compensation[0].any()
    # reset() keeps the flag (the caller's input).
    ctrl.reset()
    assert ctrl.landed is True


# Controller(A4) before the keyword `law` existed (the paper's law), third step from STATE to
# REFERENCE: u_d (6,) and the commands (4, 4).
STATE = tvmd.State([0.3, -0.2, 1.2], velocity=[0.1, 0.0, -0.2], angular_velocity=[0.05, -0.02, 0.01])
REFERENCE = tvmd.Reference([0.0, 0.0, 1.5])
OLD_U_D = [-0.4, 0.16, -0.015, -0.2, 0.08000000000000002, 28.168]
OLD_COMMANDS = [
    [-0.006725215187217141, 0.002211349760798886, 6.646186750339641, 0.6956451292105428],
    [-0.007668380388301276, 0.0020378922206600774, 7.211932647047326, 0.7246483531312881],
    [-0.003401797874192738, -0.007435121267679351, 7.438228430184824, 0.7359295374734452],
    [-0.003681834624186395, -0.0065038059344773615, 6.8724863036933685, 0.7073891918465576],
]


def third_step(law):
    ctrl = tvmd.Controller(A4, law=law)
    for _ in range(3):
        out = ctrl.step(STATE, REFERENCE)
    return out


@pytest.mark.parametrize("law", ["paper", PAPER_TABLE], ids=["name", "table"])
def test_paper_law_reproduces_the_old_numbers(law):
    out = third_step(law)
    np.testing.assert_allclose(out.law.u_d, OLD_U_D, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(out.commands, OLD_COMMANDS, rtol=1e-14, atol=1e-15)
    # The force part of u_r is the paper's force request (eq. 12) with its gains.
    u_fr = tvmd.force_request(A4.plant(), tvmd.Gains.paper(), STATE, REFERENCE)
    np.testing.assert_allclose(out.law.u_r[3:], u_fr, rtol=0, atol=1e-13)
    assert tvmd.Controller(A4, law=law).law == "paper"


def test_default_law_is_not_the_old_numbers():
    out = third_step("offset-free")
    assert not np.allclose(out.law.u_d, OLD_U_D, rtol=1e-3)
    u_fr = tvmd.force_request(A4.plant(), tvmd.Gains.paper(), STATE, REFERENCE)
    assert not np.allclose(out.law.u_r[3:], u_fr, rtol=1e-3)


def test_law_tables():
    observer = {"kind": "observer", "force_bandwidth": 5.0, "torque_bandwidth": 8, "max_torque": 2.0}
    ctrl = tvmd.Controller(A4, law={"gains": "team-scaled", "offset_free": observer, "attitude_rate": "off"})
    assert ctrl.law == "custom" and ctrl.planned_rates is None
    np.testing.assert_allclose(ctrl.gains.k_x, np.diag(tvmd.Gains.paper().k_x) * A4.mass * np.eye(3), rtol=1e-12)
    natural = {"natural": {"position_frequency": np.array([1.0, 1.0, 2.0])}}
    assert tvmd.Controller(A4, law={"gains": natural}).law == "custom"
    # A table's missing keys take the offset-free law's values.
    assert tvmd.Controller(A4, law={}).law == "offset-free"
    integral = {"kind": "integral", "k_x": [1, 1, 1], "k_r": (0.5, 0.5, 0.5)}
    _, _, compensation = fly(tvmd.Controller(A4, law={"offset_free": integral}), 50)
    assert np.abs(compensation[-1]).max() > 0


@pytest.mark.parametrize(
    "law, exc, match",
    [
        ("nope", ValueError, r"invalid `law`: unknown law `nope`"),
        ({"gainz": "paper"}, ValueError, r"`law.gainz`: unknown field"),
        ({"offset_free": {"kind": "magic"}}, ValueError, r"`law.offset_free`: unknown offset-free kind `magic`"),
        ({"offset_free": {"kind": "observer", "force_bandwidth": -1.0}}, ValueError,
         r"`law.offset_free.force_bandwidth`: must be finite and > 0"),  # fmt: skip
        ({"offset_free": {"kind": "observer", "k_x": [1, 1, 1]}}, ValueError, r"`law.offset_free`: `k_x` is not"),
        ({"offset_free": {"kind": "integral", "k_x": [1, 1, 1]}}, ValueError, r"`law.offset_free`: .*needs `k_r`"),
        ({"attitude_rate": {"bandwidth": 0.0}}, ValueError, r"`law.attitude_rate.bandwidth`: must be finite and > 0"),
        ({"attitude_rate": "on"}, ValueError, r"`law.attitude_rate`: unknown attitude-rate setting"),
        ({"gains": {"natural": {"attitude_damping": [1.0, float("nan"), 1.0]}}}, ValueError,
         r"`law.gains.natural.attitude_damping\[1\]`: must be finite"),  # fmt: skip
        ({"gains": {"natural": {"position_frequency": [1.0, 1.0]}}}, ValueError,
         r"`law.gains.natural.position_frequency`: invalid length 2"),  # fmt: skip
        (5, TypeError, r"`law` must be \"paper\", \"offset-free\" or a dict"),
        ({"gains": 5}, TypeError, r"`law.gains`: invalid type"),
        ({"offset_free": {"kind": "observer", "max_torque": "5"}}, TypeError,
         r"`law.offset_free.max_torque`: invalid type"),  # fmt: skip
        ({1: "paper"}, TypeError, r"`law` keys must be strings"),
        ({"gains": object()}, TypeError, r"`law.gains` must be a str, a number"),
    ],
)
def test_bad_laws_name_the_field(law, exc, match):
    with pytest.raises(exc, match=match):
        tvmd.Controller(A4, law=law)


# ---------------------------------------------------------------------------
# tvmd.sim
# ---------------------------------------------------------------------------

SHORT = "duration = 2.0\n"


def test_sim_run_with_either_law():
    """The scenario's law is overridden through ``RunRequest.law``; ``SimResult.law`` names it."""
    paper = sim.run("hover", law="paper", max_samples=0)
    free = sim.run("hover", law="offset-free", max_samples=0)
    assert (paper.law, free.law) == ("paper", "offset-free")
    assert sim.run("hover", max_samples=0).law == "offset-free"  # the family's own law
    # The scenario that flew carries the law.
    assert 'offset_free = "off"' in paper.scenario_toml and "[law.offset_free]" in free.scenario_toml
    assert "law='paper'" in repr(paper) and "law='offset-free'" in repr(free)
    # Under wind (an unmodelled force) only the offset-free law holds the setpoint.
    wind = {law: sim.run("wind", law=law, max_samples=0).summary for law in ("paper", "offset-free")}
    assert wind["offset-free"]["final_position_error"] < 1e-3 < 0.1 < wind["paper"]["final_position_error"]
    assert wind["offset-free"]["verdict"]["success"] and not wind["paper"]["verdict"]["success"]
    # The built-in paper scenario flies the paper's law; TOML that names none the default law.
    assert sim.run("paper-tilt", max_samples=0).law == "paper"
    assert sim.run(toml=SHORT, max_samples=0).law == "offset-free"
    assert sim.run(toml=SHORT, law={"offset_free": "off"}, max_samples=0).law == "custom"


def test_sim_law_errors_and_batches():
    with pytest.raises(ValueError, match=r"invalid `law.attitude_rate.max_rate`"):
        sim.run(toml=SHORT, law={"attitude_rate": {"max_rate": -1.0}})
    with pytest.raises(TypeError, match=r"`law` must be"):
        sim.run(toml=SHORT, law=1.5)
    with pytest.raises(ValueError, match=r"invalid `runs\[1\]\['law'\]`: unknown law"):
        sim.run_many([{"toml": SHORT}, {"toml": SHORT, "law": "fast"}])
    with pytest.raises(ValueError, match=r"invalid `runs\[0\]\['law'\].offset_free.max_torque`"):
        sim.run_many([{"toml": SHORT, "law": {"offset_free": {"kind": "observer", "max_torque": 0}}}])
    laws = ["paper", None, {"offset_free": "off"}]
    runs = [{"toml": SHORT, "law": law, "max_samples": 0} for law in laws]
    assert [r.law for r in sim.run_many(runs)] == ["paper", "offset-free", "custom"]
