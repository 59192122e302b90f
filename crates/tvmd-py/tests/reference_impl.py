"""Independent pure-NumPy reference implementation of the TVMD paper.

This module re-implements, from ``docs/method.md`` and the paper's equations, the pure
functions of the TVMD core (gimbal model, effectiveness matrix, approximated
attainable force space, force projection, attitude planner, control law and
pseudo-inverse allocation). It deliberately shares no code with the Rust crates:
the Python test suite compares the bindings against it, and the benchmark script
uses it as the NumPy baseline.

Equation numbers count the numbered equations of the paper in order:

    (1) gimbal reduced attitude      (2) kinematics x_dot = R v, R_dot = R [Omega]x
    (3) G xi_dot = C(xi) xi + u + g  (4) wrench u = M(Xi) f
    (5) thrust T = rho d^4 c_l w^2   (6) gimbal / speed limits
    (7) approximated AFS (cone)      (8) semi-axes c_x, c_y (two lines: 7-8 in docs/method.md)
    (9) attitude planner R_d         (10) t_Tf scaling
    (11) planner optimisation (bisection on theta)
    (12) control law u_d = blockdiag(I, K_f) u_r     (13) t_eta projection

Conventions (as in docs/method.md):

* SI units, angles in radians, z axis up, gravity g = 9.81 m/s^2 by default.
* The twist is xi = [Omega; v], both expressed in the body (team) frame {C}; x_dot = R v.
* Wrenches are ordered [torque; force]; M is 6 x 3n.
* Agent yaw psi_i = m_i * pi/2 is always carried as the integer number of quarter turns m_i.
* sigma_Tf ("max_thrust") is the maximum thrust of ONE agent.
* The gravity wrench is g_C = [0; -m_C g R^T e3] (docs/method.md: the paper prints it without the minus
  sign, which is wrong for a z-up frame); the control law's "- g_C" therefore adds +m_C g R^T e3.

Only NumPy is used.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "GRAVITY",
    "skew",
    "vee",
    "rot_x",
    "thrust_direction",
    "gimbal_force",
    "gimbal_inverse",
    "rot_z_quarter",
    "effectiveness",
    "team_mass_inertia",
    "count_n_x",
    "afs_semi_axes",
    "afs_quadratic_form",
    "afs_contains",
    "force_projection",
    "attitude_planner",
    "control_law",
    "pseudo_inverse_allocation",
    "agent_commands",
    "paper_a4_inc",
    "paper_a4_con",
    "paper_reference",
    "rigid_body_derivative",
    "simulate_paper_scenario",
]

GRAVITY = 9.81

_HALF_PI = 0.5 * math.pi


# ---------------------------------------------------------------------------
# Small SO(3) helpers
# ---------------------------------------------------------------------------


def skew(w):
    """Skew-symmetric matrix [w]x such that [w]x a = w x a."""
    w = np.asarray(w, dtype=float)
    return np.array(
        [
            [0.0, -w[2], w[1]],
            [w[2], 0.0, -w[0]],
            [-w[1], w[0], 0.0],
        ]
    )


def vee(S):
    """Inverse of :func:`skew` (reads the lower-left entries of a 3x3 matrix)."""
    S = np.asarray(S, dtype=float)
    return np.array([S[2, 1], S[0, 2], S[1, 0]])


def rot_x(phi):
    """Basic rotation about the x axis (used for the paper's roll reference)."""
    c, s = math.cos(phi), math.sin(phi)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _cross(a, b):
    """Cross product of two 3-vectors (much cheaper than np.cross for single vectors)."""
    return np.array(
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    )


def _unit(a):
    return a / np.linalg.norm(a)


def _rodrigues(v, k, theta):
    """Rotate vector ``v`` about the unit axis ``k`` by ``theta`` (Rodrigues' formula)."""
    c, s = math.cos(theta), math.sin(theta)
    return v * c + _cross(k, v) * s + k * float(np.dot(k, v)) * (1.0 - c)


# ---------------------------------------------------------------------------
# Agent model: eqs. (1), (5), (6) and the allocation inverse
# ---------------------------------------------------------------------------


def thrust_direction(eta_x, eta_y):
    """Thrust direction a_hat in the agent frame {B_i}, eq. (1).

    a_hat = [cos(eta_x) sin(eta_y), -sin(eta_x), cos(eta_x) cos(eta_y)].
    """
    cx, sx = math.cos(eta_x), math.sin(eta_x)
    return np.array([cx * math.sin(eta_y), -sx, cx * math.cos(eta_y)])


def gimbal_force(eta_x, eta_y, thrust):
    """Agent force f_i = T_f a_hat(eta_x, eta_y) in {B_i}, eqs. (1) and (5)."""
    return float(thrust) * thrust_direction(eta_x, eta_y)


def gimbal_inverse(force):
    """Allocation inverse of one agent force (paper, section "Control Allocation").

    T = ||f||, eta_x = asin(-f_y / T),
    eta_y = atan2(f_x / sgn(cos eta_x), f_z / sgn(cos eta_x)).

    Returns ``(thrust, eta_x, eta_y)``. Readings:

    * thrust = 0 returns both angles 0 (the direction is undefined);
    * the asin argument is clipped to [-1, 1] against round-off;
    * since asin returns eta_x in [-pi/2, pi/2], cos(eta_x) >= 0; the only case
      sgn(cos eta_x) = 0 is the singular |eta_x| = pi/2 (f_x = f_z = 0), where we
      take the sign as +1 so that eta_y = atan2(f_x, f_z) (never a division by 0).
    """
    f = np.asarray(force, dtype=float)
    thrust = float(np.linalg.norm(f))
    if thrust == 0.0:
        return 0.0, 0.0, 0.0
    eta_x = math.asin(min(1.0, max(-1.0, -f[1] / thrust)))
    sgn = 1.0 if math.cos(eta_x) >= 0.0 else -1.0
    eta_y = math.atan2(f[0] / sgn, f[2] / sgn)
    return thrust, eta_x, eta_y


# ---------------------------------------------------------------------------
# Team model: eqs. (3), (4)
# ---------------------------------------------------------------------------


def rot_z_quarter(m):
    """R_z(m pi/2), exact for an integer number of quarter turns ``m`` (any sign)."""
    m = int(m) % 4
    c = (1.0, 0.0, -1.0, 0.0)[m]
    s = (0.0, 1.0, 0.0, -1.0)[m]
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def effectiveness(positions, quarter_turns):
    """Effectiveness matrix M(Xi) in R^{6 x 3n}, eq. (4), rows [torque; force].

    Block i is [[p_i]x R_z(psi_i); R_z(psi_i)] with psi_i = m_i pi/2, so that
    u = M f with f = [f_1; ...; f_n] the agent forces in their own frames {B_i}.
    """
    P = np.asarray(positions, dtype=float).reshape(-1, 3)
    q = np.asarray(quarter_turns).reshape(-1)
    if len(q) != len(P):
        raise ValueError("positions and quarter_turns must have the same length")
    M = np.zeros((6, 3 * len(P)))
    for i, (p, m) in enumerate(zip(P, q)):
        Rz = rot_z_quarter(m)
        M[0:3, 3 * i : 3 * i + 3] = skew(p) @ Rz
        M[3:6, 3 * i : 3 * i + 3] = Rz
    return M


def team_mass_inertia(positions, masses, navigator_mass=0.0, navigator_inertia=None, agent_inertias=None):
    """Team mass and inertia (text below eq. (3)).

    m_C = m_0 + sum m_i,  J_C = J_0 - sum m_i [p_i]x [p_i]x (point-mass agents).

    ``navigator_inertia`` (J_0, 3x3) defaults to zero. ``agent_inertias`` is the optional
    extension of docs/method.md: a sequence of per-agent 3x3 inertias about each agent's own CoM,
    expressed in {C}, added to J_C. Positions are taken relative to the team CoM.
    Returns ``(m_C, J_C)``.
    """
    P = np.asarray(positions, dtype=float).reshape(-1, 3)
    masses = np.broadcast_to(np.asarray(masses, dtype=float), (len(P),))
    m_c = float(navigator_mass) + float(np.sum(masses))
    J = np.zeros((3, 3)) if navigator_inertia is None else np.array(navigator_inertia, dtype=float)
    for p, m in zip(P, masses):
        S = skew(p)
        J = J - m * (S @ S)
    if agent_inertias is not None:
        for Ji in agent_inertias:
            J = J + np.asarray(Ji, dtype=float)
    return m_c, J


def count_n_x(quarter_turns):
    """n_x = number of agents whose psi_i = m_i pi/2 has m_i even (aligned with {C})."""
    return int(sum(1 for m in np.asarray(quarter_turns).reshape(-1) if int(m) % 2 == 0))


# ---------------------------------------------------------------------------
# Approximated attainable force space (AFS), eqs. (7)-(8)
# ---------------------------------------------------------------------------


def _g_term(n_k, n, sigma, z, max_thrust):
    """g(n_k, sigma, z) of eq. (8); returns ``(value, wide)``.

    g = n_k sigma_Tf                              if sigma >= pi/2 ("wide" branch)
      = (n_k/n)(1 - delta(n_k)) |z| tan(sigma)    otherwise,
    where delta is the Kronecker delta (1 iff n_k = 0), so the term vanishes without agents.
    ``wide`` tells whether the sigma >= pi/2 branch was taken with at least one agent; such
    an axis does not shrink to 0 at z = 0, so the z > 0 requirement is lifted (docs/method.md).
    """
    if sigma >= _HALF_PI:
        return n_k * max_thrust, n_k > 0
    if n_k == 0:
        return 0.0, False
    return (n_k / n) * abs(z) * math.tan(sigma), False


def _semi_axes_and_wide(n, n_x, sigma_x, sigma_y, s, z, max_thrust):
    n_y = n - n_x
    gx1, w1 = _g_term(n_x, n, s * sigma_y, z, max_thrust)
    gx2, w2 = _g_term(n_y, n, s * sigma_x, z, max_thrust)
    gy1, w3 = _g_term(n_x, n, s * sigma_x, z, max_thrust)
    gy2, w4 = _g_term(n_y, n, s * sigma_y, z, max_thrust)
    return gx1 + gx2, gy1 + gy2, (w1 or w2 or w3 or w4)


def afs_semi_axes(n, n_x, sigma_x, sigma_y, s, z, max_thrust):
    """Semi-axes (c_x, c_y) of the approximated AFS at height z, eq. (8).

    c_x(z, s) = g(n_x, s sigma_y, z) + g(n_y, s sigma_x, z)
    c_y(z, s) = g(n_x, s sigma_x, z) + g(n_y, s sigma_y, z),  n_y = n - n_x.

    Agents aligned with {C} (m_i even) tilt their thrust along x through eta_y, so they
    contribute sigma_y to c_x; rotated agents swap the roles.
    """
    c_x, c_y, _ = _semi_axes_and_wide(n, n_x, sigma_x, sigma_y, s, z, max_thrust)
    return c_x, c_y


def _ellipse_term(component, semi_axis):
    """component^2 / semi_axis^2 with the limits 0/0 -> 0 and a/0 -> inf."""
    if semi_axis == 0.0:
        return 0.0 if component == 0.0 else math.inf
    return (component / semi_axis) ** 2


def afs_quadratic_form(u, n, n_x, sigma_x, sigma_y, s, max_thrust):
    """q = u^T C(u_z) u with C = diag(1/c_x^2, 1/c_y^2, 0), eq. (7) (may be inf)."""
    u = np.asarray(u, dtype=float)
    c_x, c_y = afs_semi_axes(n, n_x, sigma_x, sigma_y, s, u[2], max_thrust)
    return _ellipse_term(u[0], c_x) + _ellipse_term(u[1], c_y)


def afs_contains(u, n, n_x, sigma_x, sigma_y, s, max_thrust):
    """Membership of a body-frame force ``u`` in the approximated AFS, eq. (7).

    u is inside iff
      * ||u|| <= n sigma_Tf (the paper writes a strict "<"; we accept the boundary so that a
        force scaled by t_Tf to exactly n sigma_Tf is attainable),
      * u^T C(u_z) u <= 1, and
      * u_z >= 0: no agent pushes down (z = T cos(eta_x) cos(eta_y) >= 0), whatever the branch
        of g (docs/method.md reading). At u_z = 0 the tan branch gives zero semi-axes, so only
        the apex u = 0 passes there unless some semi-axis comes from the sigma >= pi/2 branch.
    """
    u = np.asarray(u, dtype=float)
    if float(np.linalg.norm(u)) > n * max_thrust:
        return False
    c_x, c_y, _ = _semi_axes_and_wide(n, n_x, sigma_x, sigma_y, s, u[2], max_thrust)
    if u[2] < 0.0:
        return False
    q = _ellipse_term(u[0], c_x) + _ellipse_term(u[1], c_y)
    return q <= 1.0


# ---------------------------------------------------------------------------
# Force projection K_f, eqs. (10), (12)-(13)
# ---------------------------------------------------------------------------


def force_projection(u, n, n_x, sigma_x, sigma_y, max_thrust):
    """Force projection K_f (eqs. (10), (12)-(13)); returns ``(u_projected, t_Tf, t_eta)``.

    t_Tf  = min(1, n sigma_Tf / ||u||)              (t_Tf = 1 when ||u|| = 0)
    u'    = t_Tf u
    t_eta = min(1, sqrt(1 / u'^T C(u'_z) u'))       with s = 1 (the full AFS);
            t_eta = 1 when the quadratic form is 0, 0 when it is inf
    u_projected = K_f u = diag(t_eta t_Tf, t_eta t_Tf, t_Tf) u.
    A request with u_z < 0 is not brought into the AFS by any K_f of this structure: it
    projects to the apex, zero force, with t_Tf = t_eta = 0 (docs/method.md).
    """
    u = np.asarray(u, dtype=float)
    if u[2] < 0.0:
        return np.zeros(3), 0.0, 0.0
    norm = float(np.linalg.norm(u))
    t_tf = 1.0 if norm == 0.0 else min(1.0, n * max_thrust / norm)
    u1 = t_tf * u
    q = afs_quadratic_form(u1, n, n_x, sigma_x, sigma_y, 1.0, max_thrust)
    if q == 0.0:
        t_eta = 1.0
    elif math.isinf(q):
        t_eta = 0.0
    else:
        t_eta = min(1.0, math.sqrt(1.0 / q))
    u_proj = np.array([t_eta * u1[0], t_eta * u1[1], u1[2]])
    return u_proj, t_tf, t_eta


# ---------------------------------------------------------------------------
# Attitude planner, eqs. (9), (11)
# ---------------------------------------------------------------------------


def _frame_from_bz(b_zd, R_r):
    """Complete b_zd into a rotation matrix keeping the heading of R_r (eq. (9) text).

    b_yd = (b_zd x b_xr)/||.||, b_xd = b_yd x b_zd. If b_zd is (anti)parallel to b_xr the
    heading is taken from b_yr instead: b_xd = (b_yr x b_zd)/||.||, b_yd = b_zd x b_xd.
    """
    b_xr, b_yr = R_r[:, 0], R_r[:, 1]
    y = _cross(b_zd, b_xr)
    ny = float(np.linalg.norm(y))
    if ny > 1e-9:
        b_yd = y / ny
        b_xd = _cross(b_yd, b_zd)
    else:
        b_xd = _unit(_cross(b_yr, b_zd))
        b_yd = _cross(b_zd, b_xd)
    return np.column_stack([b_xd, b_yd, b_zd])


def attitude_planner(R_r, f_r, n, n_x, sigma_x, sigma_y, max_thrust, s, tol=1e-12, max_iter=64):
    """Attitude planner, eqs. (9) and (11); returns ``(R_d, theta, feasible_already)``.

    ``f_r`` is the (t_Tf-scaled) required force in the inertial frame, eq. (9)-(10).

    * If R_r^T f_r is inside the AFS with relaxation ``s``: R_d = R_r, theta = 0,
      feasible_already = True.
    * Otherwise b_zr is rotated toward f_r about k = (b_zr x f_r)/||.|| by theta in
      [0, theta_max], theta_max = arccos(b_zr . f_r / ||f_r||) (the paper's extension of
      Franchi et al.'s arcsin bound), and the smallest feasible theta is found by bisection.
      Each trial attitude is completed by :func:`_frame_from_bz` and checked as
      R_d^T f_r in the AFS.
    * Improvements prescribed by docs/method.md: the bisection keeps the invariant "hi is feasible" and
      returns hi (the last *feasible* point, never the infeasible side); it stops when
      hi - lo <= tol or after max_iter halvings; if f_r is (anti)parallel to b_zr
      (||b_zr x f_r|| <= 1e-9 ||f_r||) the rotation axis is k = b_xr (i.e. the vehicle rolls,
      the paper's footnote leaves this choice to the designer).
    * f_r = 0 (nothing to attain): R_d = R_r, theta = 0, feasible_already = True.
    * If even theta_max is infeasible (only possible when ||f_r|| > n sigma_Tf, i.e. f_r was
      not scaled by t_Tf) the planner points b_z along f_r (theta = theta_max). No NaN is
      ever returned.
    """
    R_r = np.asarray(R_r, dtype=float)
    f_r = np.asarray(f_r, dtype=float)
    norm_f = float(np.linalg.norm(f_r))
    if norm_f == 0.0:
        return R_r.copy(), 0.0, True

    def feasible(R):
        return afs_contains(R.T @ f_r, n, n_x, sigma_x, sigma_y, s, max_thrust)

    if feasible(R_r):
        return R_r.copy(), 0.0, True

    b_zr = R_r[:, 2]
    cross = _cross(b_zr, f_r)
    nc = float(np.linalg.norm(cross))
    k = cross / nc if nc > 1e-9 * norm_f else R_r[:, 0].copy()
    theta_max = math.acos(min(1.0, max(-1.0, float(np.dot(b_zr, f_r)) / norm_f)))

    def attitude(theta):
        return _frame_from_bz(_unit(_rodrigues(b_zr, k, theta)), R_r)

    lo, hi = 0.0, theta_max
    R_hi = attitude(hi)
    if feasible(R_hi):
        for _ in range(max_iter):
            if hi - lo <= tol:
                break
            mid = 0.5 * (lo + hi)
            R_mid = attitude(mid)
            if feasible(R_mid):
                hi, R_hi = mid, R_mid
            else:
                lo = mid
    return R_hi, hi, False


# ---------------------------------------------------------------------------
# Control law, eq. (12)
# ---------------------------------------------------------------------------


def _as_gain(K, dim):
    K = np.asarray(K, dtype=float)
    if K.ndim == 1:
        K = np.diag(K)
    if K.shape != (dim, dim):
        raise ValueError(f"gain must be {dim}x{dim} or a length-{dim} diagonal")
    return K


def control_law(
    x,
    R,
    Omega,
    v,
    x_r,
    x_r_dot,
    x_r_ddot,
    R_r,
    Omega_d,
    Omega_d_dot,
    K_x,
    K_R,
    K_xi,
    m_C,
    J_C,
    n,
    n_x,
    sigma_x,
    sigma_y,
    max_thrust,
    s,
    g=GRAVITY,
):
    """Full-pose tracking control law (eq. (12) with eqs. (9)-(11), (13)).

    State: position ``x`` (inertial), attitude ``R`` (body -> inertial), body rates
    ``Omega`` and body-frame velocity ``v`` (x_dot = R v). Reference: ``x_r`` and its first
    two derivatives, reference attitude ``R_r``, desired rate ``Omega_d`` and its derivative
    (both in the desired frame). Gains: ``K_x``, ``K_R`` (3x3) and ``K_xi`` (6x6, order
    [Omega; v]; a vector is read as a diagonal). ``K_xi`` must be block diagonal, because
    docs/method.md computes the force part before R_d (and hence e_Omega) is known.

    Model (eqs. (2)-(3)): G = blockdiag(J_C, m_C I),
    C(xi) = blockdiag([J_C Omega]x, -m_C [Omega]x)  (J Omega_dot = (J Omega) x Omega + tau,
    m v_dot = -m Omega x v + f), gravity wrench g_C = [0; -m_C g R^T e3] (z up).

    One cycle, in the order of docs/method.md:
      1. e_x = x - x_r, xi_d,v = R^T x_r_dot, e_v = v - xi_d,v,
         xi_d_dot,v = R^T x_r_ddot - Omega x R^T x_r_dot and
         u_fr = m (xi_d_dot,v + Omega x xi_d,v) - K_v e_v - R^T K_x e_x + m g R^T e3
              = m R^T x_r_ddot - K_v e_v - R^T K_x e_x + m g R^T e3  (does not need R_d);
      2. force projection on u_fr -> t_Tf, t_eta, K_f (eq. (13), s = 1);
      3. f_r = t_Tf R u_fr (inertial) and the planner -> R_d, theta (eqs. (9)-(11));
      4. e_R = 1/2 (R_d^T R - R^T R_d)^vee, xi_d,Omega = R^T R_d Omega_d, e_Omega,
         xi_d_dot,Omega = -Omega x xi_d,Omega + R^T R_d Omega_d_dot (nominal R_d_dot = R_d [Omega_d]x),
         u_tau_r = J xi_d_dot,Omega - [J Omega]x xi_d,Omega - K_Omega e_Omega - K_R e_R;
      5. u_d = blockdiag(I, K_f) u_r.

    Lyapunov monitors (figure captions; ||a||_K = 1/2 a^T K a):
      Psi = 1/2 tr(K_R (I - R_d^T R)),  V_R = Psi + ||e_Omega||_{K_Omega},
      V_x = ||e_x||_{K_x} + ||e_v||_{K_v},  with K_Omega, K_v the diagonal blocks of K_xi.

    Returns a dict with u_fr, t_Tf, t_eta, K_f, f_r, R_d, theta, feasible_already, e_x, e_R,
    e_xi, xi_d, xi_d_dot, u_r, u_d, Psi, V_R, V_x.
    """
    x = np.asarray(x, dtype=float)
    R = np.asarray(R, dtype=float)
    Omega = np.asarray(Omega, dtype=float)
    v = np.asarray(v, dtype=float)
    x_r = np.asarray(x_r, dtype=float)
    x_r_dot = np.asarray(x_r_dot, dtype=float)
    x_r_ddot = np.asarray(x_r_ddot, dtype=float)
    R_r = np.asarray(R_r, dtype=float)
    Omega_d = np.asarray(Omega_d, dtype=float)
    Omega_d_dot = np.asarray(Omega_d_dot, dtype=float)
    K_x = _as_gain(K_x, 3)
    K_R = _as_gain(K_R, 3)
    K_xi = _as_gain(K_xi, 6)
    if np.any(K_xi[0:3, 3:6] != 0.0) or np.any(K_xi[3:6, 0:3] != 0.0):
        raise ValueError("K_xi must be block diagonal (blockdiag(K_Omega, K_v))")
    K_Om, K_v = K_xi[0:3, 0:3], K_xi[3:6, 3:6]
    J_C = np.asarray(J_C, dtype=float)
    e3 = np.array([0.0, 0.0, 1.0])

    # 1. translational part (independent of R_d).
    e_x = x - x_r
    xi_d_v = R.T @ x_r_dot
    e_v = v - xi_d_v
    xi_d_dot_v = R.T @ x_r_ddot - _cross(Omega, xi_d_v)
    u_fr = (
        m_C * xi_d_dot_v  # G xi_d_dot (force rows)
        + m_C * _cross(Omega, xi_d_v)  # - C(xi) xi_d = + m [Omega]x v_d
        - K_v @ e_v
        - R.T @ (K_x @ e_x)  # grad Phi (force rows)
        + m_C * g * (R.T @ e3)  # - g_C
    )

    # 2. force projection K_f (s = 1).
    _, t_tf, t_eta = force_projection(u_fr, n, n_x, sigma_x, sigma_y, max_thrust)
    K_f = np.diag([t_eta * t_tf, t_eta * t_tf, t_tf])

    # 3. attitude planner on the inertial required force.
    f_r = t_tf * (R @ u_fr)
    R_d, theta, feasible_already = attitude_planner(R_r, f_r, n, n_x, sigma_x, sigma_y, max_thrust, s)

    # 4. rotational part with the planned R_d.
    e_R = 0.5 * vee(R_d.T @ R - R.T @ R_d)
    xi_d_om = R.T @ R_d @ Omega_d
    e_om = Omega - xi_d_om
    xi_d_dot_om = -_cross(Omega, xi_d_om) + R.T @ R_d @ Omega_d_dot
    u_tr = (
        J_C @ xi_d_dot_om  # G xi_d_dot (torque rows)
        - skew(J_C @ Omega) @ xi_d_om  # - C(xi) xi_d
        - K_Om @ e_om
        - K_R @ e_R  # grad Phi (torque rows)
    )

    u_r = np.concatenate([u_tr, u_fr])
    u_d = np.concatenate([u_tr, K_f @ u_fr])

    psi = 0.5 * float(np.trace(K_R @ (np.eye(3) - R_d.T @ R)))
    V_R = psi + 0.5 * float(e_om @ K_Om @ e_om)
    V_x = 0.5 * float(e_x @ K_x @ e_x) + 0.5 * float(e_v @ K_v @ e_v)

    return {
        "u_fr": u_fr,
        "t_Tf": t_tf,
        "t_eta": t_eta,
        "K_f": K_f,
        "f_r": f_r,
        "R_d": R_d,
        "theta": theta,
        "feasible_already": feasible_already,
        "e_x": e_x,
        "e_R": e_R,
        "e_xi": np.concatenate([e_om, e_v]),
        "xi_d": np.concatenate([xi_d_om, xi_d_v]),
        "xi_d_dot": np.concatenate([xi_d_dot_om, xi_d_dot_v]),
        "u_r": u_r,
        "u_d": u_d,
        "Psi": psi,
        "V_R": V_R,
        "V_x": V_x,
    }


# ---------------------------------------------------------------------------
# Allocation
# ---------------------------------------------------------------------------


def pseudo_inverse_allocation(M, u_d, weights=None):
    """(Weighted) pseudo-inverse allocation f = W^-1 M^T (M W^-1 M^T)^-1 u_d.

    Minimises f^T W f subject to M f = u_d (M full row rank). ``weights`` is the diagonal
    of W (length 3n, positive); None gives the plain pseudo-inverse M^T (M M^T)^-1 u_d.
    The redistributed variant (Jin 2005) is not part of this reference.
    """
    M = np.asarray(M, dtype=float)
    u_d = np.asarray(u_d, dtype=float)
    if weights is None:
        return M.T @ np.linalg.solve(M @ M.T, u_d)
    w_inv = 1.0 / np.asarray(weights, dtype=float)
    MW = M * w_inv[None, :]
    return MW.T @ np.linalg.solve(MW @ M.T, u_d)


def agent_commands(f):
    """Per-agent (thrust, eta_x, eta_y) of a stacked force vector f (3n,), shape (n, 3)."""
    F = np.asarray(f, dtype=float).reshape(-1, 3)
    return np.array([gimbal_inverse(fi) for fi in F])


# ---------------------------------------------------------------------------
# The paper's team and scenario (section "Simulations", docs/method.md, scenario "paper-tilt")
# ---------------------------------------------------------------------------

_A4_HALF = 0.5 * math.sqrt(2.0) / 2.0
# Agent order (our choice; the AFS only depends on the counts n, n_x):
#   1: (+a, +a), 2: (+a, -a), 3: (-a, -a), 4: (-a, +a)
_A4_POSITIONS = np.array(
    [
        [_A4_HALF, _A4_HALF, 0.0],
        [_A4_HALF, -_A4_HALF, 0.0],
        [-_A4_HALF, -_A4_HALF, 0.0],
        [-_A4_HALF, _A4_HALF, 0.0],
    ]
)


def _paper_team(quarter_turns):
    positions = _A4_POSITIONS.copy()
    quarter_turns = np.array(quarter_turns, dtype=int)
    agent_mass = 0.7
    masses = np.full(len(positions), agent_mass)
    navigator_mass = 0.0
    m_c, J_c = team_mass_inertia(positions, masses, navigator_mass, None)
    return {
        "positions": positions,
        "quarter_turns": quarter_turns,
        "masses": masses,
        "navigator_mass": navigator_mass,
        "n": len(positions),
        "n_x": count_n_x(quarter_turns),
        "m_C": m_c,
        "J_C": J_c,
        "M": effectiveness(positions, quarter_turns),
        "sigma_x": math.pi / 6.0,
        "sigma_y": math.pi / 4.0,
        "max_thrust": 2.0 * agent_mass * GRAVITY,
        "g": GRAVITY,
        "K_x": np.diag([0.4, 0.4, 1.0]),
        "K_R": np.diag([12.0, 12.0, 1.0]),
        "K_xi": np.diag([8.0, 8.0, 1.5, 0.8, 0.8, 2.0]),
        "s": 0.5,
        "control_period": 0.01,
        "x0": np.array([0.5, -0.5, 0.0]),
    }


def paper_a4_inc():
    """Team A4-Inc of the paper: agents 1 and 2 turned by pi/2 (quarter turns [1, 1, 0, 0]).

    4 agents at (+-a, +-a, 0), a = 0.5 sqrt(2)/2 m, in the order (+a,+a), (+a,-a), (-a,-a),
    (-a,+a); m_i = 0.7 kg, navigator mass 0; sigma_x = pi/6, sigma_y = pi/4,
    sigma_Tf = 2 m_i g; the gains of docs/method.md (not scaled by mass or inertia), s = 0.5, 100 Hz control.
    """
    return _paper_team([1, 1, 0, 0])


def paper_a4_con():
    """Team A4-Con: same as :func:`paper_a4_inc` with all agents aligned (quarter turns 0)."""
    return _paper_team([0, 0, 0, 0])


def paper_reference(t):
    """Reference of the paper's simulation (docs/method.md, scenario "paper-tilt") at time ``t``.

    A) 0-2 s: x_r = [0, 0, 0.75 (1 - cos(pi t / 2))], then hover at z = 1.5 m;
    B) 4-10 s: roll phi_r = (pi/6)(1 + cos((t - 7) pi / 3)) about the body x axis
       (R_r = R_x(phi_r), peak pi/3 at t = 7), Omega_d = 0;
    C) 12-14 s: the ascent mirrored back to z = 0, z = 0.75 (1 + cos(pi (t - 12) / 2)); hold.
    Returns a dict with x_r, x_r_dot, x_r_ddot, phi_r, R_r, Omega_d, Omega_d_dot.
    """
    w = 0.5 * math.pi
    z, zd, zdd = 0.0, 0.0, 0.0
    if t <= 0.0:
        z = 0.0
    elif t < 2.0:
        z = 0.75 * (1.0 - math.cos(w * t))
        zd = 0.75 * w * math.sin(w * t)
        zdd = 0.75 * w * w * math.cos(w * t)
    elif t < 12.0:
        z = 1.5
    elif t < 14.0:
        tau = t - 12.0
        z = 0.75 * (1.0 + math.cos(w * tau))
        zd = -0.75 * w * math.sin(w * tau)
        zdd = -0.75 * w * w * math.cos(w * tau)
    else:
        z = 0.0
    phi = (math.pi / 6.0) * (1.0 + math.cos((t - 7.0) * math.pi / 3.0)) if 4.0 <= t <= 10.0 else 0.0
    return {
        "x_r": np.array([0.0, 0.0, z]),
        "x_r_dot": np.array([0.0, 0.0, zd]),
        "x_r_ddot": np.array([0.0, 0.0, zdd]),
        "phi_r": phi,
        "R_r": rot_x(phi),
        "Omega_d": np.zeros(3),
        "Omega_d_dot": np.zeros(3),
    }


# ---------------------------------------------------------------------------
# A minimal closed-loop simulation (used by the sanity test and the benchmark)
# ---------------------------------------------------------------------------


def rigid_body_derivative(state, wrench, m_C, J_C, g=GRAVITY, J_inv=None):
    """Time derivative of the state [x, R (row-major 9), Omega, v] under eqs. (2)-(3).

    x_dot = R v, R_dot = R [Omega]x, J Omega_dot = (J Omega) x Omega + tau,
    m v_dot = -m Omega x v + f - m g R^T e3 (body-frame wrench [tau; f]).
    ``J_inv`` optionally passes a precomputed inverse of J_C.
    """
    J_inv = np.linalg.inv(J_C) if J_inv is None else J_inv
    R = state[3:12].reshape(3, 3)
    Om = state[12:15]
    v = state[15:18]
    tau, f = wrench[0:3], wrench[3:6]
    d = np.empty(18)
    d[0:3] = R @ v
    d[3:12] = (R @ skew(Om)).reshape(9)
    d[12:15] = J_inv @ (_cross(J_C @ Om, Om) + tau)
    d[15:18] = -_cross(Om, v) + (f - m_C * g * R[2, :]) / m_C
    return d


def _reorthonormalise(R):
    U, _, Vt = np.linalg.svd(R)
    Q = U @ Vt
    if np.linalg.det(Q) < 0.0:
        U[:, -1] = -U[:, -1]
        Q = U @ Vt
    return Q


def simulate_paper_scenario(team=None, s=None, t_end=16.0, dt=1e-3, control_period=None):
    """Closed loop of the paper scenario: ZOH controller, PI allocation, RK4 plant, no ground.

    The allocated wrench M f is applied unsaturated (ideal actuators), so the plant sees u_d;
    the per-agent gimbal angles and thrusts of the plain pseudo-inverse are recorded to check
    the limits. Returns a dict of arrays sampled at every control update: t, x, x_r, phi_r,
    phi (roll of R), theta, phi_d (roll of R_d), V_x, V_R, max_eta_x, max_eta_y, max_thrust.
    """
    team = paper_a4_inc() if team is None else team
    s = team["s"] if s is None else s
    Tc = team["control_period"] if control_period is None else control_period
    steps_per_ctrl = int(round(Tc / dt))
    n_ctrl = int(round(t_end / Tc))
    m_c, J_c, M = team["m_C"], team["J_C"], team["M"]
    J_inv = np.linalg.inv(J_c)
    g = team["g"]

    state = np.zeros(18)
    state[0:3] = team["x0"]
    state[3:12] = np.eye(3).reshape(9)

    log = {k: [] for k in ("t", "x", "x_r", "phi_r", "phi", "theta", "phi_d", "V_x", "V_R",
                           "max_eta_x", "max_eta_y", "max_thrust")}
    for k in range(n_ctrl):
        t = k * Tc
        ref = paper_reference(t)
        R = state[3:12].reshape(3, 3)
        out = control_law(
            state[0:3], R, state[12:15], state[15:18],
            ref["x_r"], ref["x_r_dot"], ref["x_r_ddot"], ref["R_r"], ref["Omega_d"], ref["Omega_d_dot"],
            team["K_x"], team["K_R"], team["K_xi"], m_c, J_c,
            team["n"], team["n_x"], team["sigma_x"], team["sigma_y"], team["max_thrust"], s,
            team["g"],
        )
        f = pseudo_inverse_allocation(M, out["u_d"])
        cmd = agent_commands(f)
        wrench = M @ f

        log["t"].append(t)
        log["x"].append(state[0:3].copy())
        log["x_r"].append(ref["x_r"])
        log["phi_r"].append(ref["phi_r"])
        log["phi"].append(math.atan2(R[2, 1], R[2, 2]))
        log["theta"].append(out["theta"])
        log["phi_d"].append(math.atan2(out["R_d"][2, 1], out["R_d"][2, 2]))
        log["V_x"].append(out["V_x"])
        log["V_R"].append(out["V_R"])
        log["max_eta_x"].append(float(np.max(np.abs(cmd[:, 1]))))
        log["max_eta_y"].append(float(np.max(np.abs(cmd[:, 2]))))
        log["max_thrust"].append(float(np.max(cmd[:, 0])))

        for _ in range(steps_per_ctrl):
            k1 = rigid_body_derivative(state, wrench, m_c, J_c, g, J_inv)
            k2 = rigid_body_derivative(state + 0.5 * dt * k1, wrench, m_c, J_c, g, J_inv)
            k3 = rigid_body_derivative(state + 0.5 * dt * k2, wrench, m_c, J_c, g, J_inv)
            k4 = rigid_body_derivative(state + dt * k3, wrench, m_c, J_c, g, J_inv)
            state = state + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            state[3:12] = _reorthonormalise(state[3:12].reshape(3, 3)).reshape(9)

    return {k: np.asarray(v) for k, v in log.items()}
