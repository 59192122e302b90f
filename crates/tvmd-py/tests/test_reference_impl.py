"""Tests of the pure-NumPy reference implementation (``reference_impl.py``).

The reference is checked against every case of the reference vectors
(``crates/tvmd-core/tests/data/core_vectors.json``, computed with the paper authors' MATLAB code;
provenance in the README beside it), against closed-form consequences of the paper (hover
saturation law, hover equilibrium, the reduced control law of ``docs/method.md``) and, finally,
in a short closed-loop run of the paper's scenario.

The vectors are loaded by ``vectors.py``: the repository's file, or the file named by
``$TVMD_REFERENCE_VECTORS`` when that variable is set.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import reference_impl as ri  # noqa: E402
from vectors import ATOL, PLANNER_TOL, RTOL, VECTORS  # noqa: E402,F401
from vectors import cases as _cases  # noqa: E402
from vectors import needs_vectors  # noqa: E402


def _close(actual, expected, rtol=RTOL, atol=ATOL):
    np.testing.assert_allclose(
        np.asarray(actual, dtype=float), np.asarray(expected, dtype=float), rtol=rtol, atol=atol
    )


# ---------------------------------------------------------------------------
# Shared test vectors
# ---------------------------------------------------------------------------


@needs_vectors
def test_vector_families_present():
    for key in ("gimbal", "effectiveness", "afs_semi_axes", "force_projection", "attitude_planner"):
        assert len(VECTORS[key]) > 0, key


@pytest.mark.parametrize("case", _cases("gimbal"))
def test_gimbal_vectors(case):
    _close(ri.gimbal_force(case["eta_x"], case["eta_y"], case["thrust"]), case["force"])
    _close(ri.thrust_direction(case["eta_x"], case["eta_y"]) * case["thrust"], case["force"])
    thrust, eta_x, eta_y = ri.gimbal_inverse(case["force"])
    _close(thrust, case["inv_thrust"])
    _close(eta_x, case["inv_eta_x"])
    _close(eta_y, case["inv_eta_y"])


@pytest.mark.parametrize("case", _cases("effectiveness"))
def test_effectiveness_vectors(case):
    M = ri.effectiveness(case["positions"], case["psi_quarter_turns"])
    assert M.shape == (6, 3 * len(case["positions"]))
    _close(M, case["M"])
    _close(M @ np.asarray(case["f"]), case["wrench"])


@pytest.mark.parametrize("case", _cases("afs_semi_axes"))
def test_afs_semi_axes_vectors(case):
    c_x, c_y = ri.afs_semi_axes(
        case["n"], case["n_x"], case["sigma_x"], case["sigma_y"], case["s"], case["z"], case["max_thrust"]
    )
    _close(c_x, case["c_x"])
    _close(c_y, case["c_y"])


@pytest.mark.parametrize("case", _cases("force_projection"))
def test_force_projection_vectors(case):
    n_x = ri.count_n_x(case["psi_quarter_turns"])
    u_proj, t_tf, t_eta = ri.force_projection(
        case["u"], case["n"], n_x, case["sigma_x"], case["sigma_y"], case["max_thrust"]
    )
    _close(u_proj, case["u_projected"])
    assert 0.0 <= t_tf <= 1.0 and 0.0 <= t_eta <= 1.0
    # The projected force is in the full (s = 1) AFS whenever it points upward.
    if u_proj[2] > 0.0:
        q = ri.afs_quadratic_form(
            u_proj, case["n"], n_x, case["sigma_x"], case["sigma_y"], 1.0, case["max_thrust"]
        )
        assert q <= 1.0 + 1e-9


@pytest.mark.parametrize("case", _cases("attitude_planner"))
def test_attitude_planner_vectors(case):
    n, n_x = case["n"], ri.count_n_x(case["psi_quarter_turns"])
    args = (n, n_x, case["sigma_x"], case["sigma_y"], case["max_thrust"], case["s"])
    R_r = np.asarray(case["R_r"])
    f_r = np.asarray(case["f_r"])
    R_d, theta, feasible_already = ri.attitude_planner(R_r, f_r, *args)

    np.testing.assert_allclose(theta, case["theta"], rtol=0.0, atol=PLANNER_TOL)
    np.testing.assert_allclose(R_d, np.asarray(case["R_d"]), rtol=0.0, atol=PLANNER_TOL)
    assert feasible_already == (case["theta"] == 0.0)
    # R_d is a rotation and the planned force is attainable (the planner returns the feasible end).
    np.testing.assert_allclose(R_d.T @ R_d, np.eye(3), atol=1e-12)
    assert np.linalg.det(R_d) == pytest.approx(1.0, abs=1e-12)
    sx, sy, s, T = case["sigma_x"], case["sigma_y"], case["s"], case["max_thrust"]
    assert ri.afs_contains(R_d.T @ f_r, n, n_x, sx, sy, s, T)
    if feasible_already:
        np.testing.assert_array_equal(R_d, R_r)


# ---------------------------------------------------------------------------
# Planner saturation in hover (docs/method.md#reproduction-targets)
# ---------------------------------------------------------------------------


def _hover_plan(team, phi_r, s):
    f_r = np.array([0.0, 0.0, team["m_C"] * ri.GRAVITY])
    return ri.attitude_planner(
        ri.rot_x(phi_r), f_r, team["n"], team["n_x"], team["sigma_x"], team["sigma_y"], team["max_thrust"], s
    )


@pytest.mark.parametrize("s", [0.25, 0.5, 0.75, 1.0])
@pytest.mark.parametrize("sigma_y", [math.pi / 4, math.pi / 6])
@pytest.mark.parametrize("excess", [1e-3, 0.05, 0.5])
def test_hover_saturation_law(s, sigma_y, excess):
    """In hover the planned roll stops at phi_max = atan(c_y(1, s))."""
    team = ri.paper_a4_inc()
    team["sigma_y"] = sigma_y
    c_x, c_y = ri.afs_semi_axes(team["n"], team["n_x"], team["sigma_x"], sigma_y, s, 1.0, team["max_thrust"])
    # A4-Inc: n_x = n_y = 2, so c_y(1, s) = (2/4)(tan(s sigma_x) + tan(s sigma_y)) = c_x(1, s).
    assert c_y == pytest.approx(0.5 * (math.tan(s * team["sigma_x"]) + math.tan(s * sigma_y)), rel=1e-12)
    assert c_x == pytest.approx(c_y, rel=1e-12)
    phi_max = math.atan(c_y)

    R_d, theta, feasible_already = _hover_plan(team, phi_max + excess, s)
    assert not feasible_already
    phi_d = math.atan2(R_d[2, 1], R_d[2, 2])
    assert phi_d == pytest.approx(phi_max, abs=1e-6)
    assert theta == pytest.approx(excess, abs=1e-6)
    # Heading is kept: the planned attitude is a pure roll.
    np.testing.assert_allclose(R_d, ri.rot_x(phi_d), atol=1e-9)


def test_hover_saturation_paper_values():
    team = ri.paper_a4_inc()
    R_d, _, _ = _hover_plan(team, 0.4, 0.5)
    assert math.atan2(R_d[2, 1], R_d[2, 2]) == pytest.approx(0.3287, abs=5e-5)
    team["sigma_y"] = math.pi / 6
    R_d, _, _ = _hover_plan(team, 0.4, 0.5)
    assert math.atan2(R_d[2, 1], R_d[2, 2]) == pytest.approx(math.pi / 12, abs=1e-6)


def test_hover_below_limit_is_kept():
    team = ri.paper_a4_inc()
    R_r = ri.rot_x(0.3)
    R_d, theta, feasible_already = _hover_plan(team, 0.3, 0.5)
    assert feasible_already and theta == 0.0
    np.testing.assert_array_equal(R_d, R_r)


# ---------------------------------------------------------------------------
# Model helpers and edge cases
# ---------------------------------------------------------------------------


def test_rot_z_quarter_exact():
    for m in range(-5, 9):
        Rz = ri.rot_z_quarter(m)
        psi = m * math.pi / 2
        c, s = math.cos(psi), math.sin(psi)
        expected = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        np.testing.assert_allclose(Rz, expected, atol=1e-15)
        assert set(np.unique(Rz)).issubset({-1.0, 0.0, 1.0})
        np.testing.assert_array_equal(Rz.T @ Rz, np.eye(3))


def test_gimbal_round_trip_and_zero_thrust():
    rng = np.random.default_rng(7)
    for _ in range(200):
        eta_x, eta_y = rng.uniform(-1.5, 1.5, size=2)
        thrust = rng.uniform(0.1, 20.0)
        T, ex, ey = ri.gimbal_inverse(ri.gimbal_force(eta_x, eta_y, thrust))
        assert (T, ex, ey) == pytest.approx((thrust, eta_x, eta_y), rel=1e-9, abs=1e-12)
    assert ri.gimbal_inverse([0.0, 0.0, 0.0]) == (0.0, 0.0, 0.0)
    # Singular eta_x = -pi/2 (thrust along +y): finite angles, no division by zero.
    T, ex, ey = ri.gimbal_inverse([0.0, 2.0, 0.0])
    assert T == 2.0 and ex == pytest.approx(-math.pi / 2) and ey == 0.0


def test_paper_team_mass_inertia():
    for team in (ri.paper_a4_inc(), ri.paper_a4_con()):
        assert team["m_C"] == pytest.approx(2.8)
        # -sum m [p]x[p]x = sum m (|p|^2 I - p p^T); |p|^2 = 0.25, p_x^2 = p_y^2 = 0.125.
        np.testing.assert_allclose(team["J_C"], np.diag([0.35, 0.35, 0.7]), atol=1e-15)
        assert team["max_thrust"] == pytest.approx(2 * 0.7 * 9.81)
    assert ri.paper_a4_inc()["n_x"] == 2 and ri.paper_a4_con()["n_x"] == 4
    m, J = ri.team_mass_inertia([[1.0, 0.0, 0.0]], [2.0], 1.0, np.eye(3), agent_inertias=[0.1 * np.eye(3)])
    assert m == 3.0
    np.testing.assert_allclose(J, np.diag([1.1, 3.1, 3.1]))


def test_afs_contains_edge_cases():
    args = (4, 2, math.pi / 6, math.pi / 4, 1.0, 10.0)
    assert ri.afs_contains([0.0, 0.0, 5.0], *args)
    # z = 0 in the tan branch: only the apex (all thrusts zero) is attainable.
    assert ri.afs_contains([0.0, 0.0, 0.0], *args)
    assert not ri.afs_contains([0.1, 0.0, 0.0], *args)
    assert not ri.afs_contains([0.0, 0.0, -1e-300], *args)
    assert not ri.afs_contains([0.0, 0.0, -5.0], *args)  # below the x-y plane
    assert not ri.afs_contains([0.0, 0.0, 41.0], *args)  # ||u|| > n sigma_Tf = 40
    assert ri.afs_contains([0.0, 0.0, 40.0], *args)  # boundary is attainable
    # A sigma >= pi/2 branch admits z = 0 (agents can thrust sideways), never z < 0.
    wide = (1, 1, 0.3, math.pi / 2, 1.0, 10.0)
    assert ri.afs_semi_axes(1, 1, 0.3, math.pi / 2, 1.0, 0.0, 10.0) == (10.0, 0.0)
    assert ri.afs_contains([5.0, 0.0, 0.0], *wide)
    assert not ri.afs_contains([5.0, 0.1, 0.0], *wide)  # zero semi-axis, non-zero component
    assert not ri.afs_contains([0.0, 0.0, -1.0], *wide)
    # Kronecker delta: no agents of a kind, no contribution.
    c_x, c_y = ri.afs_semi_axes(3, 3, 0.5, 0.7, 1.0, 2.0, 5.0)
    assert (c_x, c_y) == pytest.approx((2.0 * math.tan(0.7), 2.0 * math.tan(0.5)))


def test_force_projection_edge_cases():
    args = (4, 2, math.pi / 6, math.pi / 4, 10.0)
    u, t_tf, t_eta = ri.force_projection([0.0, 0.0, 0.0], *args)
    assert (t_tf, t_eta) == (1.0, 1.0) and not np.any(u)
    u, t_tf, t_eta = ri.force_projection([3.0, 0.0, 0.0], *args)  # horizontal: c_x(0) = 0
    assert (t_tf, t_eta) == (1.0, 0.0) and not np.any(u)
    u, t_tf, t_eta = ri.force_projection([0.0, 0.0, 80.0], *args)
    assert t_tf == 0.5 and t_eta == 1.0
    _close(u, [0.0, 0.0, 40.0])


def test_planner_degenerate_inputs():
    team = ri.paper_a4_inc()
    args = (team["n"], team["n_x"], team["sigma_x"], team["sigma_y"], team["max_thrust"], 0.5)
    R_r = ri.rot_x(0.2)
    R_d, theta, feasible_already = ri.attitude_planner(R_r, np.zeros(3), *args)
    assert theta == 0.0 and feasible_already
    np.testing.assert_array_equal(R_d, R_r)
    # f_r antiparallel to b_zr: rotate about b_xr by (almost) pi, no NaN.
    f_r = -20.0 * R_r[:, 2]
    R_d, theta, feasible_already = ri.attitude_planner(R_r, f_r, *args)
    assert np.all(np.isfinite(R_d)) and not feasible_already
    sx, sy, T = team["sigma_x"], team["sigma_y"], team["max_thrust"]
    assert ri.afs_contains(R_d.T @ f_r, team["n"], team["n_x"], sx, sy, 0.5, T)
    np.testing.assert_allclose(R_d[:, 0], R_r[:, 0], atol=1e-12)  # a pure roll about b_xr


def test_pseudo_inverse_allocation():
    team = ri.paper_a4_inc()
    M = team["M"]
    u_d = np.array([0.1, -0.2, 0.05, 0.3, -0.4, 27.0])
    f = ri.pseudo_inverse_allocation(M, u_d)
    _close(M @ f, u_d, rtol=1e-12, atol=1e-12)
    _close(f, np.linalg.pinv(M) @ u_d, rtol=1e-10, atol=1e-12)
    w = np.linspace(1.0, 3.0, M.shape[1])
    fw = ri.pseudo_inverse_allocation(M, u_d, w)
    _close(M @ fw, u_d, rtol=1e-12, atol=1e-12)
    assert fw @ (w * fw) <= f @ (w * f) + 1e-12  # the weighted solution minimises f^T W f
    cmd = ri.agent_commands(f)
    assert cmd.shape == (4, 3)


# ---------------------------------------------------------------------------
# Control law
# ---------------------------------------------------------------------------


def _law(team, state, ref, s=0.5):
    return ri.control_law(
        state["x"], state["R"], state["Omega"], state["v"],
        ref["x_r"], ref["x_r_dot"], ref["x_r_ddot"], ref["R_r"], ref["Omega_d"], ref["Omega_d_dot"],
        team["K_x"], team["K_R"], team["K_xi"], team["m_C"], team["J_C"],
        team["n"], team["n_x"], team["sigma_x"], team["sigma_y"], team["max_thrust"], s,
    )  # fmt: skip


def test_control_law_hover_equilibrium():
    team = ri.paper_a4_inc()
    ref = ri.paper_reference(3.0)
    state = {"x": ref["x_r"].copy(), "R": np.eye(3), "Omega": np.zeros(3), "v": np.zeros(3)}
    out = _law(team, state, ref)
    _close(out["u_d"], [0, 0, 0, 0, 0, team["m_C"] * ri.GRAVITY], atol=1e-12)
    assert out["V_x"] == 0.0 and out["V_R"] == pytest.approx(0.0, abs=1e-15)
    assert out["t_Tf"] == 1.0 and out["t_eta"] == 1.0 and out["feasible_already"]


def test_control_law_matches_spec_reduction():
    """With Omega_d = 0, the reduced forms of docs/method.md#control-law hold for any state."""
    team = ri.paper_a4_inc()
    rng = np.random.default_rng(3)
    K_Om, K_v = team["K_xi"][:3, :3], team["K_xi"][3:, 3:]
    m, e3 = team["m_C"], np.array([0.0, 0.0, 1.0])
    for t in np.linspace(0.0, 14.0, 15):
        ref = ri.paper_reference(float(t))
        R = ri.rot_x(rng.uniform(-0.6, 0.6)) @ _expm_so3(0.3 * rng.normal(size=3))
        state = {"x": rng.normal(size=3), "R": R, "Omega": rng.normal(size=3), "v": rng.normal(size=3)}
        out = _law(team, state, ref)
        e_x = state["x"] - ref["x_r"]
        e_v = state["v"] - R.T @ ref["x_r_dot"]
        u_fr = m * R.T @ ref["x_r_ddot"] - K_v @ e_v - R.T @ team["K_x"] @ e_x + m * ri.GRAVITY * R.T @ e3
        _close(out["u_fr"], u_fr, rtol=1e-12, atol=1e-12)
        _close(out["u_r"][:3], -K_Om @ state["Omega"] - team["K_R"] @ out["e_R"], rtol=1e-12, atol=1e-12)
        K_f = np.diag([out["t_eta"] * out["t_Tf"]] * 2 + [out["t_Tf"]])
        _close(out["u_d"], np.concatenate([out["u_r"][:3], K_f @ u_fr]), rtol=1e-12, atol=1e-12)
        _close(out["f_r"], out["t_Tf"] * R @ u_fr, rtol=1e-12, atol=1e-12)
        # e_R and Psi of the planned attitude.
        R_d = out["R_d"]
        _close(out["e_R"], 0.5 * ri.vee(R_d.T @ R - R.T @ R_d), rtol=1e-12, atol=1e-12)
        assert out["Psi"] == pytest.approx(0.5 * np.trace(team["K_R"] @ (np.eye(3) - R_d.T @ R)), abs=1e-12)
        assert out["V_x"] == pytest.approx(0.5 * e_x @ team["K_x"] @ e_x + 0.5 * e_v @ K_v @ e_v, rel=1e-12)


def _expm_so3(w):
    """Rotation exp([w]x) (Rodrigues), for random test attitudes."""
    th = float(np.linalg.norm(w))
    if th == 0.0:
        return np.eye(3)
    K = ri.skew(w / th)
    return np.eye(3) + math.sin(th) * K + (1.0 - math.cos(th)) * (K @ K)


def test_control_law_desired_rate_feedforward():
    """xi_d_dot is the time derivative of xi_d along the motion (R_d_dot = R_d [Omega_d]x)."""
    team = ri.paper_a4_inc()
    rng = np.random.default_rng(11)
    R, Om, v = _expm_so3(rng.normal(size=3) * 0.2), rng.normal(size=3), rng.normal(size=3)
    R_d0 = _expm_so3(rng.normal(size=3) * 0.1)
    Om_d, Om_d_dot = rng.normal(size=3), rng.normal(size=3)
    x_r_dot, x_r_ddot = rng.normal(size=3), rng.normal(size=3)

    def xi_d(h):
        R_h = R @ _expm_so3(Om * h)
        R_dh = R_d0 @ _expm_so3(Om_d * h + 0.5 * Om_d_dot * h * h)
        return np.concatenate([R_h.T @ R_dh @ (Om_d + Om_d_dot * h), R_h.T @ (x_r_dot + x_r_ddot * h)])

    h = 1e-6
    fd = (xi_d(h) - xi_d(-h)) / (2 * h)
    # Mild reference (s = 1) so that the planner keeps R_d = R_r and xi_d is the one above.
    ref = {"x_r": np.zeros(3), "x_r_dot": x_r_dot, "x_r_ddot": x_r_ddot, "R_r": R_d0,
           "Omega_d": Om_d, "Omega_d_dot": Om_d_dot}  # fmt: skip
    state = {"x": np.zeros(3), "R": R, "Omega": Om, "v": v}
    out = _law(team, state, ref, s=1.0)
    assert out["feasible_already"]
    _close(out["xi_d"], xi_d(0.0), rtol=1e-12, atol=1e-12)
    _close(out["xi_d_dot"], fd, rtol=1e-6, atol=1e-6)


# ---------------------------------------------------------------------------
# Closed loop of the paper scenario (s = 0.5)
# ---------------------------------------------------------------------------


def test_closed_loop_paper_scenario():
    """RK4 at 1 kHz, controller at 100 Hz, plain PI allocation, no ground, 16 s (~3 s runtime)."""
    team = ri.paper_a4_inc()
    s = 0.5
    log = ri.simulate_paper_scenario(team, s=s, t_end=16.0, dt=1e-3)
    sx, sy, T = team["sigma_x"], team["sigma_y"], team["max_thrust"]
    _, c_y = ri.afs_semi_axes(team["n"], team["n_x"], sx, sy, s, 1.0, T)
    phi_max = math.atan(c_y)

    assert np.all(np.isfinite(log["x"]))
    # The planned roll saturates at the hover law (NumPy calibration: 0.331 rad vs 0.3287).
    assert abs(np.max(log["phi_d"]) - phi_max) < 0.01
    assert np.max(log["phi_d"]) <= phi_max + 0.01
    # The vehicle stays within 1 m of the reference (the start is 0.71 m off).
    err = np.linalg.norm(log["x"] - log["x_r"], axis=1)
    assert np.max(err) < 1.0
    # ... and the position error shrinks: small by the end of the hover and at touch-down.
    t = log["t"]
    assert err[np.argmin(np.abs(t - 12.0))] < 0.2
    assert err[-1] < 0.1
    # V_x converges.
    assert log["V_x"][-1] < 0.01 * log["V_x"][0]
    # At s = 0.5 the plain pseudo-inverse stays inside the gimbal and thrust limits.
    assert np.max(log["max_eta_x"]) <= team["sigma_x"]
    assert np.max(log["max_eta_y"]) <= team["sigma_y"]
    assert np.max(log["max_thrust"]) <= team["max_thrust"]
