"""Tests of the Python bindings ``tvmd`` (PyO3 extension of tvmd-core).

The bindings are compared with the independent pure-NumPy reference ``reference_impl.py`` on
seeded random inputs and on the reference vectors (tests/data/core_vectors.json of tvmd-core); every error path is checked to raise
``ValueError`` / ``TypeError`` (never a ``PanicException``). The largest differences are
recorded with the ``agreement`` fixture (conftest.py) and printed in the terminal summary.
"""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest

import reference_impl as ri
import tvmd
from vectors import ATOL, PLANNER_TOL, RTOL, cases

HALF_PI = 0.5 * math.pi


def _close(actual, expected, rtol=RTOL, atol=ATOL):
    np.testing.assert_allclose(
        np.asarray(actual, dtype=float), np.asarray(expected, dtype=float), rtol=rtol, atol=atol
    )


def _rotation(rng, scale=math.pi):
    """A random rotation exp([w]x) with |w| <= scale."""
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angle = rng.uniform(0.0, scale)
    K = ri.skew(axis)
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def _random_sigma(rng):
    # Mostly inside (0, pi/2), sometimes exactly pi/2 (the n_k sigma_Tf branch of eq. 8).
    return HALF_PI if rng.random() < 0.1 else rng.uniform(0.05, HALF_PI - 1e-3)


def _ring_team(rng, n=None):
    n = int(rng.integers(3, 11)) if n is None else n
    radius = rng.uniform(0.2, 1.0)
    phase = 2.0 * math.pi * np.arange(n) / n + rng.uniform(0, 0.3, n)
    positions = np.column_stack([radius * np.cos(phase), radius * np.sin(phase), rng.uniform(-0.05, 0.05, n)])
    turns = rng.integers(-3, 5, n)
    masses = rng.uniform(0.4, 1.0, n)
    sigma_x, sigma_y = rng.uniform(0.3, 1.2, 2)
    max_thrust = 2.0 * float(np.max(masses)) * ri.GRAVITY
    nav_inertia = np.diag(rng.uniform(0.0, 0.05, 3))
    team = tvmd.Team(positions, turns, masses, sigma_x, sigma_y, max_thrust,
                     navigator_mass=0.3, navigator_inertia=nav_inertia)  # fmt: skip
    return team


def _ref_team(team):
    """The reference's view of a tvmd.Team."""
    m_c, J_c = ri.team_mass_inertia(team.positions, team.masses, team.navigator_mass, team.navigator_inertia)
    return {
        "n": team.n,
        "n_x": ri.count_n_x(team.quarter_turns),
        "m_C": m_c,
        "J_C": J_c,
        "M": ri.effectiveness(team.positions, team.quarter_turns),
        "sigma_x": team.sigma_x,
        "sigma_y": team.sigma_y,
        "max_thrust": team.max_thrust,
    }


def _spd(rng, lo, hi):
    """A random symmetric positive-definite 3x3 gain with eigenvalues in [lo, hi]."""
    Q = _rotation(rng)
    return Q @ np.diag(rng.uniform(lo, hi, 3)) @ Q.T


# ---------------------------------------------------------------------------
# Team model
# ---------------------------------------------------------------------------


def test_team_presets_match_reference():
    for team, ref in ((tvmd.Team.a4_inc(), ri.paper_a4_inc()), (tvmd.Team.a4_con(), ri.paper_a4_con())):
        assert team.n == 4 and team.n_x == ref["n_x"] and team.n_y == 4 - ref["n_x"]
        assert team.mass == pytest.approx(ref["m_C"], rel=1e-15)
        _close(team.inertia, ref["J_C"], rtol=1e-14, atol=1e-15)
        _close(team.positions, ref["positions"], rtol=0, atol=0)
        np.testing.assert_array_equal(team.quarter_turns, ref["quarter_turns"])
        _close(team.effectiveness(), ref["M"], rtol=0, atol=1e-15)
        assert team.sigma_x == ref["sigma_x"] and team.sigma_y == ref["sigma_y"]
        assert team.max_thrust == pytest.approx(ref["max_thrust"], rel=1e-15)
    assert tvmd.Team.a4_inc().arrangement == "Inc" and tvmd.Team.a4_con().arrangement == "Con"


def test_team_random_mass_inertia_effectiveness(agreement):
    rng = np.random.default_rng(101)
    for _ in range(50):
        team = _ring_team(rng)
        inertias = np.array([np.diag(rng.uniform(0.0, 0.01, 3)) for _ in range(team.n)])
        team2 = tvmd.Team(team.positions, team.quarter_turns, team.masses, team.sigma_x, team.sigma_y,
                          team.max_thrust, navigator_mass=team.navigator_mass,
                          navigator_inertia=team.navigator_inertia, agent_inertias=inertias)  # fmt: skip
        m, J = ri.team_mass_inertia(team2.positions, team2.masses, team2.navigator_mass, team2.navigator_inertia,
                                    agent_inertias=inertias)  # fmt: skip
        agreement.record("team.inertia", team2.inertia, J)
        assert team2.mass == pytest.approx(m, rel=1e-14)
        _close(team2.inertia, J, rtol=1e-12, atol=1e-15)
        M = ri.effectiveness(team.positions, team.quarter_turns)
        agreement.record("team.effectiveness", team.effectiveness(), M)
        _close(team.effectiveness(), M, rtol=1e-15, atol=1e-15)
        f = rng.normal(size=(team.n, 3))
        agreement.record("team.wrench", team.wrench(f), M @ f.reshape(-1))
        _close(team.wrench(f), M @ f.reshape(-1), rtol=1e-12, atol=1e-12)
        # A failed agent leaves M: zero columns, its force ignored.
        Mf = team.effectiveness(failed=[0])
        assert not np.any(Mf[:, 0:3])
        _close(Mf[:, 3:], M[:, 3:], rtol=0, atol=0)
        _close(team.wrench(f, failed=[0]), M[:, 3:] @ f[1:].reshape(-1), rtol=1e-12, atol=1e-12)


def test_team_ring_and_from_rotor():
    team = tvmd.Team.ring(6, 0.5, True)
    assert team.n == 6 and team.n_x == 3 and team.arrangement == "Inc"
    assert team.sigma_x == pytest.approx(math.pi / 6) and team.max_thrust == pytest.approx(2 * 0.7 * 9.81)
    _close(np.linalg.norm(team.positions[:, :2], axis=1), np.full(6, 0.5), rtol=1e-15)
    con = tvmd.Team.ring(5, 0.4, False, sigma_x=0.3, sigma_y=0.4, max_thrust=10.0)
    assert con.arrangement == "Con" and con.n_x == 5 and con.max_thrust == 10.0
    rho, d, c_l, w = 1.2, 0.25, 0.1, 800.0
    rotor = tvmd.Team.from_rotor(team.positions, team.quarter_turns, 0.7, 0.5, 0.6, rho, d, c_l, w)
    k = rho * d**4 * c_l
    assert rotor.thrust_coefficient == pytest.approx(k) and rotor.max_thrust == pytest.approx(k * w * w)
    np.testing.assert_array_equal(rotor.masses, np.full(6, 0.7))


# ---------------------------------------------------------------------------
# Gimbal (eq. 1) and its inverse
# ---------------------------------------------------------------------------


def test_gimbal_random_vectorized(agreement):
    rng = np.random.default_rng(202)
    eta_x = rng.uniform(-1.5, 1.5, 500)
    eta_y = rng.uniform(-1.5, 1.5, 500)
    thrust = rng.uniform(0.0, 20.0, 500)
    forces = tvmd.gimbal_force(eta_x, eta_y, thrust)
    assert forces.shape == (500, 3) and forces.dtype == np.float64
    ref = np.array([ri.gimbal_force(a, b, t) for a, b, t in zip(eta_x, eta_y, thrust)])
    agreement.record("gimbal_force", forces, ref)
    _close(forces, ref, rtol=1e-15, atol=1e-14)
    dirs = tvmd.thrust_direction(eta_x, eta_y)
    _close(dirs, np.array([ri.thrust_direction(a, b) for a, b in zip(eta_x, eta_y)]), rtol=1e-15, atol=1e-15)
    ex, ey, T = tvmd.gimbal_inverse(ref)
    inv = np.array([ri.gimbal_inverse(f) for f in ref])
    agreement.record("gimbal_inverse", np.column_stack([T, ex, ey]), inv)
    _close(np.column_stack([T, ex, ey]), inv, rtol=1e-14, atol=1e-14)
    # Scalars in, (3,) out; broadcasting; round trip.
    f = tvmd.gimbal_force(0.1, -0.2, 3.0)
    assert f.shape == (3,)
    assert tvmd.gimbal_inverse(f) == pytest.approx((0.1, -0.2, 3.0), rel=1e-14)
    assert tvmd.gimbal_force(eta_x[:5], 0.2, 1.0).shape == (5, 3)
    assert tvmd.gimbal_force(np.zeros((2, 1)), np.zeros(4), 1.0).shape == (2, 4, 3)
    assert tvmd.gimbal_inverse([0.0, 0.0, 0.0]) == (0.0, 0.0, 0.0)


@pytest.mark.parametrize("case", cases("gimbal"))
def test_gimbal_vectors(case):
    _close(tvmd.gimbal_force(case["eta_x"], case["eta_y"], case["thrust"]), case["force"])
    eta_x, eta_y, thrust = tvmd.gimbal_inverse(case["force"])
    _close(thrust, case["inv_thrust"])
    _close(eta_x, case["inv_eta_x"])
    _close(eta_y, case["inv_eta_y"])


@pytest.mark.parametrize("case", cases("effectiveness"))
def test_effectiveness_vectors(case):
    M_ref = np.asarray(case["M"])
    n = len(case["positions"])
    args = (case["positions"], case["psi_quarter_turns"], 0.7, 0.5, 0.7, 10.0)
    if np.linalg.matrix_rank(M_ref) < 6:
        # The core only builds teams that can produce every wrench (eq. 4 of rank 6).
        with pytest.raises(tvmd.ConfigError, match="rank 6"):
            tvmd.Team(*args)
        return
    team = tvmd.Team(*args)
    M = team.effectiveness()
    assert M.shape == (6, 3 * n)
    _close(M, M_ref)
    _close(team.wrench(np.asarray(case["f"]).reshape(n, 3)), case["wrench"])


# ---------------------------------------------------------------------------
# Attainable force space (eqs. 7-8) and projection (eqs. 12-13)
# ---------------------------------------------------------------------------


def _random_afs(rng):
    n = int(rng.integers(1, 12))
    n_x = int(rng.integers(0, n + 1))
    sx, sy = _random_sigma(rng), _random_sigma(rng)
    T = rng.uniform(1.0, 20.0)
    return (n, n_x, sx, sy, T), tvmd.AttainableForceSpace(n, n_x, sx, sy, T)


def test_afs_semi_axes_random(agreement):
    rng = np.random.default_rng(303)
    for _ in range(300):
        (n, n_x, sx, sy, T), afs = _random_afs(rng)
        s = rng.uniform(0.05, 1.0)
        z = rng.uniform(-3 * n * T, 3 * n * T, 12)
        c_x, c_y = afs.semi_axes(z, s)
        ref = np.array([ri.afs_semi_axes(n, n_x, sx, sy, s, zi, T) for zi in z])
        agreement.record("afs.semi_axes", np.column_stack([c_x, c_y]), ref)
        _close(np.column_stack([c_x, c_y]), ref, rtol=1e-13, atol=1e-13)
        one = afs.semi_axes(float(z[0]), s)
        assert isinstance(one[0], float) and one == pytest.approx(tuple(ref[0]), rel=1e-13)
        assert afs.n == n and afs.n_x == n_x and afs.n_y == n - n_x
        assert afs.max_force == pytest.approx(n * T, rel=1e-15)


def test_afs_contains_and_quadratic_form_random(agreement):
    rng = np.random.default_rng(404)
    decided = 0
    for _ in range(300):
        (n, n_x, sx, sy, T), afs = _random_afs(rng)
        s = rng.uniform(0.05, 1.0)
        u = rng.normal(size=(40, 3)) * rng.uniform(0.1, 1.5) * n * T / 2.0
        u[:, 2] = np.abs(u[:, 2]) * np.where(rng.random(40) < 0.9, 1.0, -1.0)
        inside = afs.contains(u, s)
        q = afs.quadratic_form(u, s)
        assert inside.shape == (40,) and inside.dtype == np.bool_ and q.shape == (40,)
        q_ref = np.array([ri.afs_quadratic_form(ui, n, n_x, sx, sy, s, T) for ui in u])
        finite = np.isfinite(q_ref)
        np.testing.assert_array_equal(np.isfinite(q), finite)
        agreement.record("afs.quadratic_form", q[finite], q_ref[finite])
        _close(q[finite], q_ref[finite], rtol=1e-12, atol=1e-14)
        ref = np.array([ri.afs_contains(ui, n, n_x, sx, sy, s, T) for ui in u])
        # Exclude points within round-off of the boundary (q = 1 or ||u|| = n sigma_Tf).
        clear = (np.abs(q_ref - 1.0) > 1e-9) & (np.abs(np.linalg.norm(u, axis=1) - n * T) > 1e-9 * n * T)
        np.testing.assert_array_equal(inside[clear], ref[clear])
        decided += int(np.sum(clear))
        assert afs.contains(u[0], s) is bool(inside[0])
    assert decided > 10000


def test_afs_project_random(agreement):
    rng = np.random.default_rng(505)
    for _ in range(300):
        (n, n_x, sx, sy, T), afs = _random_afs(rng)
        u = rng.normal(size=(20, 3)) * rng.uniform(0.1, 2.0) * n * T
        u[:3, :2] = 0.0  # purely vertical
        u[3, 2] = 0.0  # horizontal
        forces, t_tf, t_eta = afs.project(u)
        ref = [ri.force_projection(ui, n, n_x, sx, sy, T) for ui in u]
        agreement.record("afs.project.force", forces, np.array([r[0] for r in ref]))
        agreement.record("afs.project.t_Tf", t_tf, np.array([r[1] for r in ref]))
        agreement.record("afs.project.t_eta", t_eta, np.array([r[2] for r in ref]))
        _close(forces, np.array([r[0] for r in ref]), rtol=1e-12, atol=1e-12)
        _close(t_tf, np.array([r[1] for r in ref]), rtol=1e-14, atol=1e-15)
        _close(t_eta, np.array([r[2] for r in ref]), rtol=1e-12, atol=1e-14)
        f0, t0, e0 = afs.project(u[0])
        assert f0.shape == (3,) and isinstance(t0, float) and isinstance(e0, float)


@pytest.mark.parametrize("case", cases("afs_semi_axes"))
def test_afs_semi_axes_vectors(case):
    afs = tvmd.AttainableForceSpace(case["n"], case["n_x"], case["sigma_x"], case["sigma_y"], case["max_thrust"])
    c_x, c_y = afs.semi_axes(case["z"], case["s"])
    _close(c_x, case["c_x"])
    _close(c_y, case["c_y"])


@pytest.mark.parametrize("case", cases("force_projection"))
def test_force_projection_vectors(case):
    n_x = ri.count_n_x(case["psi_quarter_turns"])
    afs = tvmd.AttainableForceSpace(case["n"], n_x, case["sigma_x"], case["sigma_y"], case["max_thrust"])
    u_proj, t_tf, t_eta = afs.project(case["u"])
    _close(u_proj, case["u_projected"])
    assert 0.0 <= t_tf <= 1.0 and 0.0 <= t_eta <= 1.0


# ---------------------------------------------------------------------------
# Attitude planner (eqs. 9-11)
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("case", cases("attitude_planner"))
def test_attitude_planner_vectors(case, agreement):
    n, n_x = case["n"], ri.count_n_x(case["psi_quarter_turns"])
    afs = tvmd.AttainableForceSpace(n, n_x, case["sigma_x"], case["sigma_y"], case["max_thrust"])
    out = tvmd.AttitudePlanner(case["s"]).plan(afs, case["R_r"], case["f_r"])
    agreement.record("vectors.planner.theta (default tolerance)", out.theta, case["theta"])
    agreement.record("vectors.planner.R_d (default tolerance)", out.R_d, case["R_d"])
    np.testing.assert_allclose(out.theta, case["theta"], rtol=0.0, atol=PLANNER_TOL)
    np.testing.assert_allclose(out.R_d, np.asarray(case["R_d"]), rtol=0.0, atol=PLANNER_TOL)
    assert (out.status == "already-feasible") == (case["theta"] == 0.0)
    assert afs.contains(out.R_d.T @ np.asarray(case["f_r"]), case["s"])


def test_planner_random(agreement):
    rng = np.random.default_rng(606)
    statuses = set()
    for _ in range(300):
        (n, n_x, sx, sy, T), afs = _random_afs(rng)
        s = rng.uniform(0.1, 1.0)
        R_r = _rotation(rng, scale=1.2)
        direction = _rotation(rng, scale=1.0)[:, 2]
        f_r = direction * rng.uniform(0.05, 1.0) * n * T
        out = tvmd.AttitudePlanner(s, tolerance=1e-12).plan(afs, R_r, f_r)
        R_d, theta, feasible = ri.attitude_planner(R_r, f_r, n, n_x, sx, sy, T, s, tol=1e-12)
        statuses.add(out.status)
        assert (out.status == "already-feasible") == feasible
        agreement.record("planner.theta", out.theta, theta)
        agreement.record("planner.R_d", out.R_d, R_d)
        np.testing.assert_allclose(out.theta, theta, rtol=0.0, atol=1e-6)
        np.testing.assert_allclose(out.R_d, R_d, rtol=0.0, atol=1e-6)
        np.testing.assert_allclose(out.R_d.T @ out.R_d, np.eye(3), atol=1e-12)
    assert {"already-feasible", "planned"} <= statuses


def test_planner_hover_saturation_law():
    """In hover the planned roll stops at phi_max = atan(c_y(1, s)) (docs/method.md, reproduction targets)."""
    team = tvmd.Team.a4_inc()
    afs = team.afs()
    for s in (0.25, 0.5, 0.75, 1.0):
        _, c_y = afs.semi_axes(1.0, s)
        phi_max = math.atan(c_y)
        out = tvmd.AttitudePlanner(s).plan(afs, ri.rot_x(phi_max + 0.05), [0.0, 0.0, team.mass * 9.81])
        assert out.status == "planned" and out.iterations > 0
        assert math.atan2(out.R_d[2, 1], out.R_d[2, 2]) == pytest.approx(phi_max, abs=1e-6)
    out = tvmd.AttitudePlanner(0.5).plan(afs, ri.rot_x(0.4), [0.0, 0.0, team.mass * 9.81])
    assert math.atan2(out.R_d[2, 1], out.R_d[2, 2]) == pytest.approx(0.3287, abs=5e-5)
    zero = tvmd.AttitudePlanner(0.5).plan(afs, ri.rot_x(0.2), [0.0, 0.0, 0.0])
    assert zero.status == "zero-force" and zero.theta == 0.0
    assert set(zero.to_dict()) == {"R_d", "theta", "iterations", "status"}
    # `relaxation` is the keyword everywhere; `s` stays as an alias.
    assert tvmd.AttitudePlanner(relaxation=0.25).relaxation == tvmd.AttitudePlanner(s=0.25).relaxation == 0.25
    assert afs.semi_axes(1.0, relaxation=0.25) == afs.semi_axes(1.0, s=0.25) == afs.semi_axes(1.0, 0.25)
    assert tvmd.Controller(team, s=0.25).relaxation == tvmd.Controller(team, relaxation=0.25).relaxation == 0.25
    assert repr(zero).startswith("PlannerResult(R_d=array(")


# ---------------------------------------------------------------------------
# Control law (eq. 12)
# ---------------------------------------------------------------------------


def _random_state_reference(rng, scale=1.0):
    state = {
        "position": rng.normal(size=3) * scale,
        "attitude": _rotation(rng, scale=0.6 * scale),
        "angular_velocity": rng.normal(size=3) * scale,
        "velocity": rng.normal(size=3) * scale,
    }
    reference = {
        "position": rng.normal(size=3) * scale,
        "velocity": rng.normal(size=3) * scale,
        "acceleration": rng.normal(size=3) * scale,
        "attitude": _rotation(rng, scale=0.8 * scale),
        "angular_velocity": rng.normal(size=3) * scale,
        "angular_acceleration": rng.normal(size=3) * scale,
    }
    return state, reference


def _ref_law(team_ref, gains, state, reference, s):
    K_xi = np.zeros((6, 6))
    K_xi[:3, :3], K_xi[3:, 3:] = gains.k_omega, gains.k_v
    return ri.control_law(
        state["position"], state["attitude"], state["angular_velocity"], state["velocity"],
        reference["position"], reference["velocity"], reference["acceleration"], reference["attitude"],
        reference["angular_velocity"], reference["angular_acceleration"],
        gains.k_x, gains.k_r, K_xi, team_ref["m_C"], team_ref["J_C"],
        team_ref["n"], team_ref["n_x"], team_ref["sigma_x"], team_ref["sigma_y"], team_ref["max_thrust"], s,
    )  # fmt: skip


def _random_gains(rng):
    if rng.random() < 0.5:
        return tvmd.Gains(rng.uniform(0.2, 2, 3), rng.uniform(1, 15, 3), rng.uniform(0.5, 10, 6))
    K_xi = np.zeros((6, 6))
    K_xi[:3, :3], K_xi[3:, 3:] = _spd(rng, 0.5, 10), _spd(rng, 0.5, 3)
    return tvmd.Gains(_spd(rng, 0.2, 2), _spd(rng, 1, 15), K_xi)


def test_control_law_random(agreement):
    rng = np.random.default_rng(707)
    for i in range(200):
        team = tvmd.Team.a4_inc() if i % 3 == 0 else _ring_team(rng)
        team_ref = _ref_team(team)
        gains = _random_gains(rng)
        s = rng.uniform(0.1, 1.0)
        state, reference = _random_state_reference(rng)
        ref = _ref_law(team_ref, gains, state, reference, s)
        plant = team.plant()
        u_fr = tvmd.force_request(plant, gains, state, reference)
        agreement.record("law.force_request", u_fr, ref["u_fr"])
        _close(u_fr, ref["u_fr"], rtol=1e-9, atol=1e-9)
        law = tvmd.control_wrench(plant, gains, state, reference, ref["R_d"], ref["u_fr"], ref["K_f"])
        for name, key in (("e_x", "e_x"), ("e_R", "e_R"), ("e_xi", "e_xi"), ("u_r", "u_r"), ("u_d", "u_d"),
                          ("V_R", "V_R"), ("V_x", "V_x")):  # fmt: skip
            agreement.record(f"law.control_wrench.{name}", getattr(law, name), ref[key])
            _close(getattr(law, name), ref[key], rtol=1e-9, atol=1e-9)
        # The diagonal form of K_f is accepted too, and State/Reference objects like dicts.
        law2 = tvmd.control_wrench(plant, gains, tvmd.State(**state), tvmd.Reference(**reference), ref["R_d"],
                                   u_fr, np.diag(ref["K_f"]))  # fmt: skip
        _close(law2.u_d, law.u_d, rtol=1e-12, atol=1e-12)
        # The same pipeline through the bindings' projection and planner.
        afs = team.afs()
        _, t_tf, t_eta = afs.project(u_fr)
        assert t_tf == pytest.approx(ref["t_Tf"], rel=1e-12) and t_eta == pytest.approx(ref["t_eta"], rel=1e-9)
        f_r = t_tf * (state["attitude"] @ u_fr)
        plan = tvmd.AttitudePlanner(s, tolerance=1e-12).plan(afs, reference["attitude"], f_r)
        agreement.record("law.pipeline.R_d", plan.R_d, ref["R_d"])
        np.testing.assert_allclose(plan.R_d, ref["R_d"], rtol=0, atol=1e-6)


def test_law_output_record():
    team = tvmd.Team.a4_inc()
    state = tvmd.State([0.0, 0.0, 1.0])
    reference = tvmd.Reference.hover([0.0, 0.0, 1.0])
    u_fr = tvmd.force_request(team.plant(), tvmd.Gains.paper(), state, reference)
    _close(u_fr, [0, 0, team.mass * 9.81], rtol=1e-15, atol=0)
    law = tvmd.control_wrench(team.plant(), tvmd.Gains.paper(), state, reference, np.eye(3), u_fr, np.eye(3))
    assert list(law.to_dict()) == ["e_x", "e_R", "e_xi", "u_r", "u_d", "V_R", "V_x"]
    assert repr(law).startswith("LawOutput(e_x=array(")
    assert law.V_x == 0.0 and law.V_R == 0.0


def test_gains_forms():
    paper = tvmd.Gains.paper()
    _close(np.diag(paper.k_x), [0.4, 0.4, 1.0], rtol=0, atol=0)
    _close(np.diag(paper.k_r), [12, 12, 1], rtol=0, atol=0)
    _close(np.diag(paper.k_xi), [8, 8, 1.5, 0.8, 0.8, 2], rtol=0, atol=0)
    same = tvmd.Gains([0.4, 0.4, 1.0], np.diag([12.0, 12, 1]), np.diag([8, 8, 1.5, 0.8, 0.8, 2]))
    for k in ("k_x", "k_r", "k_omega", "k_v", "k_xi"):
        np.testing.assert_array_equal(getattr(same, k), getattr(paper, k))
    assert "k_x=[0.4, 0.4, 1]" in repr(paper)


# ---------------------------------------------------------------------------
# Allocation
# ---------------------------------------------------------------------------


def _hover_wrench(rng, team, spread=0.05):
    mg = team.mass * 9.81
    return np.concatenate([rng.normal(size=3) * spread, rng.normal(size=2) * spread * mg, [mg * rng.uniform(0.8, 1.2)]])


def test_pseudo_inverse_allocation_random(agreement):
    rng = np.random.default_rng(808)
    admissible = 0
    for i in range(200):
        team = tvmd.Team.a4_inc() if i % 4 == 0 else _ring_team(rng)
        M = ri.effectiveness(team.positions, team.quarter_turns)
        u_d = _hover_wrench(rng, team)
        ref = ri.pseudo_inverse_allocation(M, u_d).reshape(-1, 3)
        out = tvmd.allocate(team, u_d, method="pseudo-inverse")
        assert out.forces.shape == (team.n, 3) and out.saturated.shape == (team.n,)
        assert out.method == "pseudo-inverse" and out.rounds == 1 and out.report is None
        if not out.saturated.any():
            admissible += 1
            agreement.record("allocate.pseudo-inverse.forces", out.forces, ref)
            _close(out.forces, ref, rtol=1e-9, atol=1e-9 * np.max(np.abs(ref)))
            assert out.e_f < 1e-9 and out.wrench_error < 1e-9
            _close(out.wrench, u_d, rtol=1e-9, atol=1e-9)
            # Redistribution changes nothing when nothing saturates.
            red = tvmd.allocate(team, u_d, method="redistributed-pseudo-inverse")
            _close(red.forces, out.forces, rtol=1e-12, atol=1e-12)
            # Nor does the exact-boundary walk (the default), which returns that start then.
            red = tvmd.allocate(team, u_d)
            _close(red.forces, out.forces, rtol=1e-12, atol=1e-12)
        # Weighted pseudo-inverse: per-agent weights w_i -> W = diag(repeat(w, 3)).
        w = rng.uniform(0.5, 2.0, team.n)
        weighted = tvmd.allocate(team, u_d, method="weighted-pseudo-inverse", weights=w)
        if not weighted.saturated.any():
            ref_w = ri.pseudo_inverse_allocation(M, u_d, np.repeat(w, 3)).reshape(-1, 3)
            agreement.record("allocate.weighted-pseudo-inverse.forces", weighted.forces, ref_w)
            _close(weighted.forces, ref_w, rtol=1e-9, atol=1e-9 * np.max(np.abs(ref_w)))
    assert admissible > 100


def test_allocation_saturation_rate_limits_and_failures():
    team = tvmd.Team.a4_inc()
    mg = team.mass * 9.81
    # Far outside the gimbal range: the pseudo-inverse clamps, the redistribution does better.
    u_d = np.array([0.0, 0.0, 0.0, 0.9 * mg, 0.0, mg])
    pi = tvmd.allocate(team, u_d, method="pseudo-inverse")
    red = tvmd.allocate(team, u_d, method="redistributed-pseudo-inverse")
    assert pi.saturated.any() and red.saturated.any()
    assert red.wrench_error <= pi.wrench_error + 1e-12
    for out in (pi, red):
        ex, ey, T = tvmd.gimbal_inverse(out.forces)
        assert np.all(np.abs(ex) <= team.sigma_x + 1e-9) and np.all(np.abs(ey) <= team.sigma_y + 1e-9)
        assert np.all(T <= team.max_thrust * (1 + 1e-12))
    # Rate limits around the previous command.
    previous = np.zeros((4, 4))
    limited = tvmd.allocate(team, [0, 0, 0, 0.3 * mg, 0, mg], rate_limits=(1.0, 1.0), dt=0.01, previous=previous)
    ex, ey, _ = tvmd.gimbal_inverse(limited.forces)
    assert np.all(np.abs(ex) <= 0.01 + 1e-9) and np.all(np.abs(ey) <= 0.01 + 1e-9)
    # A failed agent gets zero force on a team that keeps rank 6.
    ring = tvmd.Team.ring(6, 0.5, True)
    out = tvmd.allocate(ring, [0, 0, 0, 0, 0, ring.mass * 9.81], failed=[2])
    assert not np.any(out.forces[2]) and out.wrench_error < 1e-9
    assert set(out.to_dict()) == {"forces", "wrench", "e_f", "wrench_error", "rounds", "saturated", "fallback",
                                  "method", "report"}  # fmt: skip


@pytest.mark.skipif(not tvmd.HAS_CLARABEL, reason="built without the cargo feature `clarabel`")
def test_clarabel_allocation():
    team = tvmd.Team.a4_inc()
    u_d = np.array([0.0, 0.0, 0.0, 0.0, 0.0, team.mass * 9.81])
    out = tvmd.allocate(team, u_d, method="clarabel")
    assert out.method == "clarabel" and out.report is not None
    assert out.wrench_error < 1e-5
    ctrl = tvmd.Controller(team, allocator="clarabel")
    step = ctrl.step({"position": [0, 0, 1]}, {"position": [0, 0, 1]})
    assert step.allocation.report is not None and step.allocation.method == "clarabel"


@pytest.mark.skipif(not tvmd.HAS_CLARABEL, reason="built without the cargo feature `clarabel`")
def test_clarabel_sequential_allocation():
    team = tvmd.Team.a4_inc()
    # A saturating request: never worse than the redistributed pseudo-inverse.
    mg = team.mass * 9.81
    u_d = np.array([0.5, -0.4, 0.1, 12.0, -9.0, mg])
    rpi = tvmd.allocate(team, u_d, method="redistributed-pseudo-inverse")
    out = tvmd.allocate(team, u_d, method="clarabel-sequential")
    assert out.method == "clarabel-sequential" and out.report is not None and "convex steps" in out.report
    assert out.wrench_error <= rpi.wrench_error * (1 + 1e-12) + 1e-12
    assert "clarabel-sequential" in tvmd.ALLOCATORS
    ctrl = tvmd.Controller(team, allocator="clarabel-sequential")
    step = ctrl.step({"position": [0, 0, 1]}, {"position": [0, 0, 1]})
    assert step.allocation.report is not None and step.allocation.method == "clarabel-sequential"
    assert step.allocation.e_f < 1e-9


# ---------------------------------------------------------------------------
# Controller
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("team", [tvmd.Team.a4_inc(), tvmd.Team.a4_con(), tvmd.Team.ring(7, 0.6, True)],
                         ids=["a4_inc", "a4_con", "ring7"])  # fmt: skip
@pytest.mark.parametrize("allocator", ["pseudo-inverse", "redistributed-pseudo-inverse"])
@pytest.mark.parametrize("law", ["paper", "offset-free"])
def test_controller_hover_equilibrium(team, allocator, law, agreement):
    # Both laws hold an exact hover from rest (the offset-free state starts at zero).
    ctrl = tvmd.Controller(team, allocator=allocator, law=law)
    assert ctrl.law == law
    x = np.array([0.3, -0.2, 1.5])
    out = ctrl.step(tvmd.State(x), tvmd.Reference.hover(x))
    mg = team.mass * 9.81
    agreement.record("controller.hover.sum_thrust", np.sum(out.commands[:, 2]), mg)
    assert np.sum(out.commands[:, 2]) == pytest.approx(mg, rel=1e-12)
    _close(out.law.u_d, [0, 0, 0, 0, 0, mg], rtol=1e-12, atol=1e-12)
    _close(out.allocation.wrench, out.law.u_d, rtol=1e-12, atol=1e-12)
    assert np.all(np.abs(out.commands[:, :2]) < 1e-12)
    assert out.allocation.e_f < 1e-12 and out.law.V_x == 0.0 and out.planner.status == "already-feasible"
    assert out.projection.t_Tf == 1.0 and out.projection.t_eta == 1.0 and not out.allocation.saturated.any()
    # omega normalized to 1 at maximum thrust (eq. 5 without rotor constants).
    _close(out.commands[:, 3], np.sqrt(out.commands[:, 2] / team.max_thrust), rtol=1e-12, atol=0)
    _close(ctrl.previous_commands, out.commands, rtol=0, atol=0)


def test_controller_step_matches_reference(agreement):
    rng = np.random.default_rng(909)
    compared = 0
    for i in range(150):
        team = tvmd.Team.a4_inc() if i % 3 == 0 else _ring_team(rng)
        team_ref = _ref_team(team)
        gains = _random_gains(rng)
        s = rng.uniform(0.1, 1.0)
        # The paper's law: the reference is the paper's eq. (12) with `gains` as given.
        ctrl = tvmd.Controller(team, gains=gains, relaxation=s, allocator="pseudo-inverse", planner_tolerance=1e-12,
                               law="paper")  # fmt: skip
        state, reference = _random_state_reference(rng, scale=0.3)
        out = ctrl.step(state, reference)
        ref = _ref_law(team_ref, gains, state, reference, s)
        for part, name, key, tol in (
            ("projection", "t_Tf", "t_Tf", 1e-12), ("projection", "t_eta", "t_eta", 1e-9), (None, "f_r", "f_r", 1e-9),
            ("planner", "theta", "theta", 1e-6), ("planner", "R_d", "R_d", 1e-6), ("law", "e_x", "e_x", 1e-9),
            ("law", "e_R", "e_R", 1e-6), ("law", "e_xi", "e_xi", 1e-6), ("law", "u_r", "u_r", 1e-5),
            ("law", "u_d", "u_d", 1e-5), ("law", "V_R", "V_R", 1e-6), ("law", "V_x", "V_x", 1e-9),
        ):  # fmt: skip
            value = getattr(out if part is None else getattr(out, part), name)
            agreement.record(f"controller.step.{name}", value, ref[key])
            _close(value, ref[key], rtol=tol, atol=tol)
        assert (out.planner.status == "already-feasible") == ref["feasible_already"]
        if not out.allocation.saturated.any():
            compared += 1
            f_ref = ri.pseudo_inverse_allocation(team_ref["M"], ref["u_d"]).reshape(-1, 3)
            agreement.record("controller.step.forces", out.allocation.forces, f_ref)
            _close(out.allocation.forces, f_ref, rtol=1e-6, atol=1e-6 * np.max(np.abs(f_ref)))
            cmd_ref = ri.agent_commands(f_ref.reshape(-1))  # columns thrust, eta_x, eta_y
            agreement.record("controller.step.commands", out.commands[:, :3], cmd_ref[:, [1, 2, 0]])
            _close(out.commands[:, :3], cmd_ref[:, [1, 2, 0]], rtol=1e-6, atol=1e-6)
    assert compared > 50


def test_controller_outputs_and_state():
    team = tvmd.Team.a4_inc()
    ctrl = tvmd.Controller(team, rate_limits=(2.0, 2.0))
    assert ctrl.allocator == "exact-boundary-redistribution" and ctrl.relaxation == 0.5 and ctrl.period == 0.01
    assert tvmd.ALLOCATORS[0] == ctrl.allocator  # the default first, as the core's table
    assert ctrl.rate_limits == (2.0, 2.0) and ctrl.failed == [] and ctrl.gravity == 9.81
    assert ctrl.team.n == 4 and ctrl.afs.n == 4 and ctrl.planner_max_iterations == 64
    out = ctrl.step({"position": [0.5, -0.5, 0.0]}, {"position": [0.0, 0.0, 1.5], "attitude": ri.rot_x(1.0)})
    d = out.to_dict()
    assert tuple(d) == tvmd.StepOutput.FIELDS
    assert tvmd.StepOutput.FIELDS == ("planner", "projection", "f_r", "law", "allocation", "commands", "command_clamp", "null_space")
    assert tuple(d["planner"]) == tvmd.PlannerResult.FIELDS and tuple(d["law"]) == tvmd.LawOutput.FIELDS
    assert tuple(d["allocation"]) == tvmd.Allocation.FIELDS
    assert tuple(d["projection"]) == tvmd.ForceProjection.FIELDS == ("force", "t_Tf", "t_eta")
    shapes = {("planner", "R_d"): (3, 3), (None, "f_r"): (3,), ("law", "u_r"): (6,), ("law", "u_d"): (6,),
              ("allocation", "wrench"): (6,), ("law", "e_x"): (3,), ("law", "e_R"): (3,), ("law", "e_xi"): (6,),
              ("allocation", "forces"): (4, 3), (None, "commands"): (4, 4), ("allocation", "saturated"): (4,),
              ("projection", "force"): (3,)}  # fmt: skip
    for (part, key), shape in shapes.items():
        value = d[key] if part is None else d[part][key]
        assert value.shape == shape, key
        assert value.dtype == (np.bool_ if key == "saturated" else np.float64), key
        np.testing.assert_array_equal(value, getattr(out if part is None else getattr(out, part), key))
    assert out.planner.status == "planned" and out.planner.theta > 0.0
    assert out.allocation.method == "exact-boundary-redistribution" and out.allocation.report is None
    assert repr(out).startswith("StepOutput(planner=PlannerResult(R_d=array(") and "command_clamp=" in repr(out)
    # Every access returns fresh arrays.
    out.planner.R_d[:] = 0.0
    assert out.planner.R_d[2, 2] != 0.0
    # Rate limits: the gimbals move at most rate * dt from the centred start.
    assert np.all(np.abs(out.commands[:, :2]) <= 0.02 + 1e-12)
    ctrl.set_failures([1])
    assert ctrl.failed == [1] and ctrl.afs.n == 3
    ctrl.set_failures(None)
    ctrl.reset()
    assert not np.any(ctrl.previous_commands)


def test_controller_cycle_error_holds_commands():
    ctrl = tvmd.Controller(tvmd.Team.a4_inc())
    good = ctrl.step({"position": [0, 0, 1]}, {"position": [0, 0, 1]})
    for state, reference, field in (
        ({"position": [np.nan, 0, 1]}, {"position": [0, 0, 1]}, "state.position"),
        ({"position": [0, 0, 1], "velocity": [0, np.inf, 0]}, {"position": [0, 0, 1]}, "state.velocity"),
        ({"position": [0, 0, 1], "attitude": 2 * np.eye(3)}, {"position": [0, 0, 1]}, "state.attitude"),
        ({"position": [0, 0, 1]}, {"position": [0, 0, 1], "acceleration": [np.nan] * 3}, "reference.acceleration"),
    ):
        with pytest.raises(tvmd.CycleError) as info:
            ctrl.step(state, reference)
        assert isinstance(info.value, ValueError) and isinstance(info.value, tvmd.InputError)
        assert field in str(info.value) and info.value.field == field
        np.testing.assert_array_equal(info.value.commands, good.commands)
    ctrl.reset()
    with pytest.raises(tvmd.CycleError) as info:
        ctrl.step({"position": [np.nan, 0, 1]}, {"position": [0, 0, 1]})
    assert not np.any(info.value.commands) and info.value.commands.shape == (4, 4)


# ---------------------------------------------------------------------------
# Error paths: ValueError / TypeError, never a PanicException
# ---------------------------------------------------------------------------

A4 = tvmd.Team.a4_inc()
AFS = A4.afs()
GOOD = dict(positions=A4.positions, quarter_turns=[1, 1, 0, 0], masses=0.7, sigma_x=0.5, sigma_y=0.7, max_thrust=14.0)


def _team(**changes):
    return tvmd.Team(**{**GOOD, **changes})


@pytest.mark.parametrize(
    "call, exc, match",
    [
        # Team: shapes and dtypes.
        (lambda: _team(positions=np.zeros((4, 2))), ValueError, r"`positions` must have shape \(n, 3\), got \(4, 2\)"),
        (lambda: _team(quarter_turns=[1.0, 1.0, 0.0, 0.0]), TypeError, "`quarter_turns` must contain integers"),
        (lambda: _team(quarter_turns=[1, 1, 0]), ValueError, r"`quarter_turns` must have shape \(4,\), got \(3,\)"),
        (lambda: _team(masses=[0.7, 0.7]), ValueError, "`masses` must have shape"),
        (lambda: _team(positions="abc"), TypeError, "`positions` must contain real numbers"),
        (lambda: _team(positions=[[0, 0], [1, 1, 1]]), ValueError, "`positions` is not a rectangular array"),
        (lambda: _team(navigator_inertia=np.eye(2)), ValueError, "`navigator_inertia` must have shape"),
        (lambda: _team(agent_inertias=np.zeros((3, 3, 3))), ValueError, "`agent_inertias` must have shape"),
        # Team: the core's validation (ConfigError).
        (lambda: _team(positions=np.full((4, 3), np.nan)), tvmd.ConfigError, "agent.position"),
        (lambda: _team(sigma_x=2.0), tvmd.ConfigError, r"sigma_x = 2 rad is outside \(0, pi/2\]"),
        (lambda: _team(sigma_y=float("nan")), tvmd.ConfigError, "not finite"),
        (lambda: _team(masses=-1.0), tvmd.ConfigError, "agent 0 has mass -1 kg"),
        (lambda: _team(max_thrust=0.0), tvmd.ConfigError, "maximum thrust"),
        (lambda: _team(min_thrust=20.0), tvmd.ConfigError, "idle thrust"),
        (lambda: _team(navigator_mass=-1.0), tvmd.ConfigError, "navigator"),
        (lambda: _team(navigator_inertia=-np.eye(3)), tvmd.ConfigError, "positive semi-definite"),
        (lambda: _team(positions=np.zeros((0, 3)), quarter_turns=np.zeros(0, int)), tvmd.ConfigError, "no"),
        (lambda: _team(positions=[[0, 0, 0]], quarter_turns=[0]), tvmd.ConfigError, "not rank 6"),
        (lambda: tvmd.Team.ring(65, 1.0, True), tvmd.ConfigError, "exceed the capacity of 64"),
        (lambda: tvmd.Team.ring(-1, 1.0, True), ValueError, "`n` must be >= 0"),
        (lambda: A4.effectiveness(failed=[4]), tvmd.ConfigError, "agent 4"),
        (lambda: A4.effectiveness(failed=[-1]), tvmd.ConfigError, "agent -1"),
        (lambda: A4.effectiveness(failed=[True]), TypeError, "agent indices"),
        (lambda: A4.effectiveness(failed=3), TypeError, "iterable of agent indices"),
        (lambda: A4.afs(failed=[0, 1, 2, 3]), tvmd.ConfigError, "no"),
        (lambda: A4.wrench(np.zeros((3, 3))), ValueError, r"`forces` must have shape \(4, 3\), got \(3, 3\)"),
        (lambda: A4.wrench(np.full((4, 3), np.inf)), ValueError, "`forces` contains NaN or infinite"),
        # AFS and gimbal.
        (lambda: tvmd.AttainableForceSpace(4, 5, 0.5, 0.5, 10.0), tvmd.ConfigError, "n_x = 5 exceeds n = 4"),
        (lambda: tvmd.AttainableForceSpace(0, 0, 0.5, 0.5, 10.0), tvmd.ConfigError, "no"),
        (lambda: tvmd.AttainableForceSpace(-2, 0, 0.5, 0.5, 10.0), ValueError, "`n` must be >= 0"),
        (lambda: AFS.semi_axes(1.0, 0.0), tvmd.ConfigError, r"relaxation s = 0 is outside \(0, 1\]"),
        (lambda: AFS.semi_axes(1.0, 1.5), tvmd.ConfigError, "relaxation"),
        (lambda: AFS.semi_axes(float("nan")), ValueError, "`z` contains NaN"),
        (lambda: AFS.contains([0, 0, np.nan]), ValueError, "`u` contains NaN"),
        (lambda: AFS.contains([0, 0]), ValueError, r"`u` must have shape \(3,\) or \(N, 3\), got \(2,\)"),
        (lambda: AFS.contains(np.zeros((5, 2))), ValueError, "`u` must have shape"),
        (lambda: AFS.contains([1j, 0, 1]), TypeError, "`u` must contain real numbers"),
        (lambda: AFS.project(np.zeros((2, 4))), ValueError, "`u` must have shape"),
        (lambda: AFS.quadratic_form([0, 0, 1], s=-1.0), tvmd.ConfigError, "relaxation"),
        (lambda: tvmd.gimbal_force(np.zeros(2), np.zeros(3), 1.0), ValueError, "do not broadcast"),
        (lambda: tvmd.gimbal_force(0.0, np.nan, 1.0), ValueError, "`eta_y` contains NaN"),
        (lambda: tvmd.gimbal_inverse([[1.0, 2.0]]), ValueError, "`force` must have shape"),
        # Planner.
        (lambda: tvmd.AttitudePlanner(0.0), tvmd.ConfigError, "relaxation"),
        (lambda: tvmd.AttitudePlanner(0.5, tolerance=-1.0), tvmd.ConfigError, "planner.tolerance"),
        (lambda: tvmd.AttitudePlanner(0.5, max_iterations=0), tvmd.ConfigError, "planner.max_iterations"),
        (lambda: tvmd.AttitudePlanner(0.5, max_iterations=-3), ValueError, "max_iterations"),
        (lambda: tvmd.AttitudePlanner(0.5).plan(AFS, np.eye(2), [0, 0, 1]), ValueError, "`R_r` must have shape"),
        (lambda: tvmd.AttitudePlanner(0.5).plan(AFS, np.eye(3), [0, 0, np.nan]), ValueError, "`f_r` contains NaN"),
        (lambda: tvmd.AttitudePlanner(0.5).plan(A4, np.eye(3), [0, 0, 1]), TypeError,
         "`afs` must be a tvmd.AttainableForceSpace, got Team"),  # fmt: skip
        # Law.
        (lambda: tvmd.Gains([1, 1], [1, 1, 1], np.ones(6)), ValueError, r"`k_x` must have shape \(3,\)"),
        (lambda: tvmd.Gains([1, 1, 1], [1, 1, 1], np.ones((6, 6))), ValueError, "`k_xi` must be block diagonal"),
        (lambda: tvmd.Gains([1, 1, 1], [1, 1, 1], np.ones(5)), ValueError, "`k_xi` must have shape"),
        (lambda: tvmd.Gains([1, -1, 1], [1, 1, 1], np.ones(6)), tvmd.ConfigError, "gains.k_x"),
        (lambda: tvmd.Gains([1, 1, 1], [[1, 2, 0], [0, 1, 0], [0, 0, 1]], np.ones(6)), tvmd.ConfigError, "gains.k_r"),
        (lambda: tvmd.Plant(float("nan"), np.eye(3)), ValueError, "`mass` contains NaN"),
        (lambda: tvmd.State([0, 0]), ValueError, r"`state.position` must have shape \(3,\), got \(2,\)"),
        (lambda: tvmd.State([0, 0, 0], attitude=np.eye(3)[:2]), ValueError, "`state.attitude` must have shape"),
        (lambda: tvmd.Reference([0, 0, 0], velocity=[0, 0]), ValueError, "`reference.velocity` must have shape"),
        (lambda: tvmd.force_request(A4.plant(), tvmd.Gains.paper(), {"pos": [0, 0, 0]}, {"position": [0, 0, 0]}),
         ValueError, "unknown key 'pos' in `state`"),  # fmt: skip
        (lambda: tvmd.force_request(A4.plant(), tvmd.Gains.paper(), {}, {"position": [0, 0, 0]}),
         ValueError, "`state` needs a 'position'"),  # fmt: skip
        (lambda: tvmd.force_request(A4.plant(), tvmd.Gains.paper(), [0, 0, 0], {"position": [0, 0, 0]}),
         TypeError, "`state` must be a tvmd.State or a dict"),  # fmt: skip
        (lambda: tvmd.force_request(A4.plant(), tvmd.Gains.paper(), {"position": [np.nan, 0, 0]},
                                    {"position": [0, 0, 0]}), tvmd.InputError, "state.position"),  # fmt: skip
        (lambda: tvmd.force_request(A4.plant(), tvmd.Gains.paper(), {"position": [0, 0, 0]},
                                    {"position": [0, 0, 0], "attitude": np.ones((3, 3))}),
         tvmd.InputError, "reference.attitude` is not a rotation"),  # fmt: skip
        (lambda: tvmd.control_wrench(A4.plant(), tvmd.Gains.paper(), {"position": [0, 0, 0]}, {"position": [0, 0, 0]},
                                     np.eye(3), [0, 0, 1], np.eye(2)), ValueError, "`K_f` must have shape"),  # fmt: skip
        # Allocation.
        (lambda: tvmd.allocate(A4, np.zeros(6), method="magic"), ValueError, "unknown allocator 'magic'"),
        (lambda: tvmd.allocate(AFS, np.zeros(6)), TypeError, "`team` must be a tvmd.Team, got AttainableForceSpace"),
        (lambda: tvmd.allocate(A4, np.zeros(5)), ValueError, r"`wrench` must have shape \(6,\), got \(5,\)"),
        (lambda: tvmd.allocate(A4, [0, 0, 0, 0, 0, np.nan]), ValueError, "`wrench` contains NaN"),
        (lambda: tvmd.allocate(A4, np.zeros(6), method="weighted-pseudo-inverse"), ValueError, "needs `weights`"),
        (lambda: tvmd.allocate(A4, np.zeros(6), method="weighted-pseudo-inverse", weights=np.ones(3)), ValueError,
         r"`weights` must have shape \(4,\)"),  # fmt: skip
        (lambda: tvmd.allocate(A4, np.zeros(6), method="weighted-pseudo-inverse", weights=-np.ones(4)),
         tvmd.ConfigError, "allocation.weights"),  # fmt: skip
        (lambda: tvmd.allocate(A4, np.zeros(6), method="pseudo-inverse", weights=np.ones(4)), ValueError,
         "takes no `weights`"),  # fmt: skip
        (lambda: tvmd.allocate(A4, np.zeros(6), method="pseudo-inverse", max_rounds=2), ValueError,
         "takes no `max_rounds`"),  # fmt: skip
        (lambda: tvmd.Controller(A4, allocator="redistributed-pseudo-inverse", max_rounds=1), ValueError,
         "takes no `max_rounds`"),  # fmt: skip
        (lambda: tvmd.allocate(A4, np.zeros(6), previous=np.zeros((4, 4))), ValueError, "only apply with `rate_limits`"),
        (lambda: tvmd.allocate(A4, np.zeros(6), rate_limits=(1.0, 1.0)), ValueError, "`rate_limits` needs `dt`"),
        (lambda: tvmd.allocate(A4, np.zeros(6), rate_limits=(1.0, 0.0), dt=0.01), tvmd.ConfigError, "rate_limits"),
        (lambda: tvmd.allocate(A4, np.zeros(6), rate_limits=(1.0, 1.0), dt=-0.01), tvmd.ConfigError, "`dt`"),
        (lambda: tvmd.allocate(A4, np.zeros(6), rate_limits=(1.0, 1.0), dt=0.01, previous=np.zeros((4, 5))),
         ValueError, "`previous` must have shape"),  # fmt: skip
        (lambda: tvmd.allocate(A4, np.zeros(6), failed=[0, 2]), tvmd.ConfigError, "not rank 6"),
        # Controller.
        (lambda: tvmd.Controller(A4, relaxation=0.0), tvmd.ConfigError, "relaxation"),
        (lambda: tvmd.Controller(A4, s=1.01), tvmd.ConfigError, "relaxation"),
        (lambda: tvmd.Controller(A4, relaxation=0.5, s=0.5), TypeError, "not both"),
        (lambda: tvmd.AttitudePlanner(), TypeError, "missing required argument `relaxation`"),
        (lambda: AFS.contains([0, 0, 1], relaxation=0.5, s=0.5), TypeError, "not both"),
        (lambda: tvmd.Controller(A4, gravity=-9.81), tvmd.ConfigError, "`gravity`"),
        (lambda: tvmd.Controller(A4, period=0.0), tvmd.ConfigError, "`period`"),
        (lambda: tvmd.Controller(A4, allocator="nope"), ValueError, "unknown allocator 'nope'"),
        (lambda: tvmd.Controller(None), TypeError, "`team` must be a tvmd.Team, got NoneType"),
        (lambda: tvmd.force_request(A4, tvmd.Gains.paper(), {"position": [0, 0, 0]}, {"position": [0, 0, 0]}),
         TypeError, "`plant` must be a tvmd.Plant, got Team"),  # fmt: skip
        (lambda: tvmd.Controller(A4, gains="paper"), TypeError, "`gains` must be a tvmd.Gains, got str"),
        (lambda: tvmd.Controller(A4, failed=[0, 2]), tvmd.ConfigError, "not rank 6"),
        (lambda: tvmd.Controller(A4, failed=[9]), tvmd.ConfigError, "agent 9"),
        (lambda: tvmd.Controller(A4, rate_limits=(1.0,)), ValueError, "`rate_limits` must have shape"),
        (lambda: tvmd.Controller(A4, planner_tolerance=0.0), tvmd.ConfigError, "planner.tolerance"),
        (lambda: tvmd.Controller(A4).step({"position": [0, 0, 0], "attitude": np.eye(4)}, {"position": [0, 0, 0]}),
         ValueError, "`state.attitude` must have shape"),  # fmt: skip
        (lambda: tvmd.Controller(A4).step({"position": [0, 0, 0]}, {"position": [0, 0]}), ValueError,
         "`reference.position` must have shape"),  # fmt: skip
        (lambda: tvmd.Controller(A4).step({"position": [0, 0, 0]}, None), TypeError,
         "`reference` must be a tvmd.Reference or a dict"),  # fmt: skip
    ],
)
def test_error_paths(call, exc, match):
    with pytest.raises(exc, match=match) as info:
        call()
    # ConfigError/InputError/CycleError are ValueErrors; nothing is a PanicException.
    assert isinstance(info.value, (ValueError, TypeError))


def test_config_error_field():
    with pytest.raises(tvmd.ConfigError) as info:
        tvmd.Gains([1, -1, 1], [1, 1, 1], np.ones(6))
    assert info.value.field == "gains.k_x"
    with pytest.raises(tvmd.ConfigError) as info:
        tvmd.AttitudePlanner(relaxation=2.0)
    assert info.value.field == "relaxation"


def test_set_failures_keeps_previous_mask_on_error():
    ctrl = tvmd.Controller(tvmd.Team.ring(6, 0.5, True))
    ctrl.set_failures([1])
    with pytest.raises(tvmd.ConfigError):
        ctrl.set_failures([0, 1, 2, 3, 4])
    assert ctrl.failed == [1]
    with pytest.raises(tvmd.ConfigError, match="agent 6"):
        ctrl.set_failures([6])
    assert ctrl.failed == [1]


@pytest.mark.skipif(tvmd.HAS_CLARABEL, reason="built with the cargo feature `clarabel`")
def test_clarabel_not_built():
    assert "clarabel" not in tvmd.ALLOCATORS
    with pytest.raises(ValueError, match="without the cargo feature `clarabel`"):
        tvmd.allocate(A4, np.zeros(6), method="clarabel")
    with pytest.raises(ValueError, match="cargo feature `clarabel`"):
        tvmd.Controller(A4, allocator="clarabel")
    with pytest.raises(ValueError, match="'clarabel-sequential' is not available"):
        tvmd.allocate(A4, np.zeros(6), method="clarabel-sequential")


# ---------------------------------------------------------------------------
# Documentation and stubs
# ---------------------------------------------------------------------------

def test_docstrings_present():
    for name in tvmd.__all__:
        obj = getattr(tvmd, name)
        if inspect.isclass(obj) or callable(obj):
            assert obj.__doc__ and obj.__doc__.strip(), name
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for attr, value in vars(obj).items():
                if not attr.startswith("_") and attr != "FIELDS":
                    assert getattr(value, "__doc__", None), f"{name}.{attr}"


def test_controller_null_space_stage():
    team = tvmd.Team.a4_inc()
    c, s = math.cos(0.6), math.sin(0.6)
    roll = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    state = {"position": [0.3, -0.2, 1.5]}
    reference = {"position": [0.0, 0.0, 1.5], "attitude": roll}
    plain = tvmd.Controller(team).step(state, reference)
    assert not plain.null_space.ran and plain.null_space.iterations == 0
    ctrl = tvmd.Controller(team, null_space="margin")
    assert ctrl.null_space == "margin"
    out = ctrl.step(state, reference)
    r = out.null_space
    assert r.ran and r.margin_after >= r.margin_before
    assert r.objective_after >= r.objective_before
    # The wrench is the allocator's to round-off.
    np.testing.assert_allclose(out.allocation.wrench, plain.allocation.wrench, atol=1e-9)
    assert set(r.to_dict()) == set(tvmd.NullSpaceReport.FIELDS)
    assert tvmd.Controller(team, null_space="inward-tilt=0.1").null_space == "inward-tilt=0.1"
    for bad in ["sideways", "inward-tilt", "inward-tilt=nan", "inward-tilt=1.6"]:
        with pytest.raises(ValueError, match="null_space"):
            tvmd.Controller(team, null_space=bad)
