"""Type stubs of the extension module ``tvmd._tvmd`` (PyO3 bindings of ``tvmd-core``).

Array arguments accept any real array-like (read as float64); returned arrays are fresh
float64 (or bool / int64) NumPy arrays. Shapes are given in the docstrings. Checked against the
built module by ``mypy.stubtest`` (``tests/test_stubs.py``).

Conventions: ``f64`` throughout, at most ``CAPACITY`` = 64 agents. Array inputs may be NumPy
arrays of any real dtype, nested lists or Python numbers (integers are converted; booleans,
complex numbers, strings and objects raise ``TypeError``). Wrong shapes raise ``ValueError``
naming the argument and the expected shape; NaN/inf inputs raise ``ValueError``; an integer
argument (any ``int`` or NumPy integer) outside its valid range raises ``ValueError`` naming the
argument and the range (never ``OverflowError``); the core's
configuration and input errors become ``ConfigError`` / ``InputError`` (both ``ValueError``s)
with the core's message. No code path panics.
"""

from typing import Any, ClassVar, Dict, Iterable, Literal, Mapping, Optional, Sequence, Tuple, Union, final, overload

import os
import numpy as np
from numpy.typing import ArrayLike, NDArray

# The submodule `_tvmd.sim` (the simulator), re-exported as `tvmd.sim`; stubs in `sim.pyi`.
from . import sim as sim

__version__: str
CAPACITY: int
GRAVITY: float
HAS_CLARABEL: bool
ALLOCATORS: Tuple[AllocatorName, ...]

_F64 = NDArray[np.float64]
_Bool = NDArray[np.bool_]
_Failed = Optional[Iterable[int]]
_StateLike = Union["State", Mapping[str, ArrayLike]]
_ReferenceLike = Union["Reference", Mapping[str, ArrayLike]]
# A control law: a name, or a dict with the keys of a scenario's TOML ``[law]`` table.
_LawArg = Union[Literal["paper", "offset-free"], Mapping[str, Any]]
_LawName = Literal["paper", "offset-free", "custom"]

AllocatorName = Literal[
    "exact-boundary-redistribution",
    "redistributed-pseudo-inverse",
    "pseudo-inverse",
    "weighted-pseudo-inverse",
    "capped-redistribution",
    "clarabel",
    "clarabel-sequential",
]
"""The allocators (``"clarabel"`` and ``"clarabel-sequential"`` only with the cargo feature, see
``ALLOCATORS``)."""
PlannerStatus = Literal["already-feasible", "planned", "zero-force", "unreachable"]
"""How the attitude planner reached its output."""
Arrangement = Literal["Con", "Inc"]
"""Consistent (every gimbal axis aligned with the team's) or inconsistent team."""

class ConfigError(ValueError):
    """A team, limit, gain, setting or failure mask that cannot be used (``tvmd_core::ConfigError``).

    ``field``: the offending field (e.g. ``'gains.k_x'``), or None.
    """

    field: Optional[str]

class InputError(ValueError):
    """A control-cycle input that cannot be used: not finite, not a rotation, beyond the cycle's
    bound for its float type, or a non-zero force request answered only by zero thrust."""

class CycleError(InputError):
    """``Controller.step`` rejected its input.

    ``commands``: (n, 4) float64, the previous period's commands to hold (columns ``eta_x, eta_y,
    thrust, omega``; idle before the first period). ``field``: the offending input (e.g.
    ``'state.position'``).
    """

    commands: _F64
    field: str

@final
class Team:
    """The team configuration ``Xi = {(p_i, psi_i)}`` with agent limits, masses and navigator
    (paper, "Modeling"; eqs. 3-6), validated. Up to 64 agents. Immutable: ``copy.deepcopy``
    returns it, ``pickle`` rebuilds the same team bit for bit (as ``Gains`` and the records).

    Args:
        positions: (n, 3) agent positions ``p_i`` in the team CoM frame {C} (m).
        quarter_turns: (n,) integers ``m_i``, the agent yaws ``psi_i = m_i pi/2``.
        masses: (n,) agent masses ``m_i`` (kg), or one mass for every agent.
        sigma_x: gimbal limit ``sigma_x`` of ``|eta_x|`` (rad), in (0, pi/2] (eq. 6).
        sigma_y: gimbal limit ``sigma_y`` of ``|eta_y|`` (rad), in (0, pi/2] (eq. 6).
        max_thrust: ``sigma_Tf``, the maximum thrust of one agent (N). Rotor speeds are then
            normalized (``omega = 1`` at maximum thrust); see ``Team.from_rotor`` for eq. (5).
        min_thrust: idle thrust (N) in [0, max_thrust), the smallest thrust allocated.
        navigator_mass: ``m_0`` (kg), >= 0.
        navigator_inertia: ``J_0`` (3, 3), symmetric positive semi-definite; default 0.
        agent_inertias: optional (n, 3, 3) inertias of the agents about their own CoM, in {C}
            axes (extension of the paper's point-mass model), each symmetric positive
            semi-definite.

    Finite values whose team mass, weight ``m_C g`` at standard gravity, ``J_C``, ``M M^T`` or
    ``n sigma_Tf`` would not be finite are rejected (``ConfigError`` naming the field).

    Team mass ``m_C = m_0 + sum m_i``, inertia ``J_C = J_0 + sum (J_i - m_i [p_i]x [p_i]x)``.

    Raises:
        ConfigError (a ValueError): the core's validation failed (no agents, more than 64,
            non-finite values, gimbal limits outside (0, pi/2], non-positive masses or thrust,
            a bad navigator inertia, or ``M(Xi)`` not of rank 6).
        ValueError / TypeError: wrong shapes or dtypes.
    """

    FIELDS: ClassVar[Tuple[str, ...]]

    def __new__(
        cls,
        positions: ArrayLike,
        quarter_turns: ArrayLike,
        masses: ArrayLike,
        sigma_x: float,
        sigma_y: float,
        max_thrust: float,
        min_thrust: float = 0.0,
        navigator_mass: float = 0.0,
        navigator_inertia: Optional[ArrayLike] = None,
        agent_inertias: Optional[ArrayLike] = None,
    ) -> "Team": ...
    @staticmethod
    def from_rotor(
        positions: ArrayLike,
        quarter_turns: ArrayLike,
        masses: ArrayLike,
        sigma_x: float,
        sigma_y: float,
        rho: float,
        d: float,
        c_l: float,
        sigma_omega: float,
        min_thrust: float = 0.0,
        navigator_mass: float = 0.0,
        navigator_inertia: Optional[ArrayLike] = None,
        agent_inertias: Optional[ArrayLike] = None,
    ) -> "Team":
        """A team whose maximum thrust follows from the rotor constants of eq. (5):
        ``T = rho d^4 c_l omega^2``, ``sigma_Tf = T(sigma_omega)``. Rotor speeds ``omega`` of the
        commands are then in rad/s.

        Args:
            positions, quarter_turns, masses, sigma_x, sigma_y: as for ``Team(...)``.
            rho: air density (kg/m^3). d: rotor diameter (m). c_l: lift coefficient.
            sigma_omega: maximum rotor speed (rad/s).
            min_thrust, navigator_mass, navigator_inertia, agent_inertias: as for ``Team(...)``.
        """
    @staticmethod
    def a4_inc() -> "Team":
        """The paper's simulated team "A4 inc, 1 navigator": four agents at ``(+-a, +-a, 0)``,
        ``a = 0.5 sqrt(2)/2`` m, in the order (+a,+a), (+a,-a), (-a,-a), (-a,+a) with
        ``psi = [pi/2, pi/2, 0, 0]``; ``m_i = 0.7`` kg, navigator mass 0, ``sigma_x = pi/6``,
        ``sigma_y = pi/4``, ``sigma_Tf = 2 m_i g``.
        """
    @staticmethod
    def a4_con() -> "Team":
        """As ``a4_inc()`` with every agent aligned: the consistent A4 team."""
    @staticmethod
    def preset(name: str) -> "Team":
        """A team of the authors' catalogue (TVMD-Simulations ``team_conf``) with the paper's
        agents (0.7 kg, ``sigma_x = pi/6``, ``sigma_y = pi/4``, ``sigma_Tf = 2 m_i g``): ``"a3-con"``
        to ``"a10-inc"``, ``"t10-con"``, ``"t10-inc"``, the authors' diamond ``"a4-diamond-inc"``
        and the paper's square ``"a4-inc"`` (``_`` may stand for ``-``). Layouts:
        ``docs/afs-atlas.md``. Raises ``ValueError`` for an unknown name."""
    @staticmethod
    def preset_names() -> list[str]:
        """Every name ``Team.preset`` accepts, Con before Inc, by size."""
    @staticmethod
    def ring(
        n: int,
        radius: float,
        inconsistent: bool,
        sigma_x: float = 0.5235987755982989,
        sigma_y: float = 0.7853981633974483,
        max_thrust: float = 13.734,
    ) -> "Team":
        """``n`` agents of the paper's mass (0.7 kg) on a circle of ``radius`` (m) in the x-y plane,
        agent ``i`` at phase ``2 pi i / n``; every second agent turned a quarter turn when
        ``inconsistent`` (A3..A10-like layouts).
        """
    @property
    def n(self) -> int:
        """The number of agents."""
    @property
    def n_x(self) -> int:
        """Agents with even ``m_i``."""
    @property
    def n_y(self) -> int:
        """Agents with odd ``m_i``."""
    @property
    def mass(self) -> float:
        """``m_C`` (kg)."""
    @property
    def inertia(self) -> _F64:
        """``J_C`` (3, 3) (kg m^2)."""
    @property
    def positions(self) -> _F64:
        """(n, 3) agent positions ``p_i`` (m)."""
    @property
    def quarter_turns(self) -> NDArray[np.int64]:
        """(n,) quarter turns ``m_i``."""
    @property
    def masses(self) -> _F64:
        """(n,) agent masses (kg)."""
    @property
    def arrangement(self) -> Arrangement:
        """"Con" if every ``m_i`` is even, else "Inc"."""
    @property
    def sigma_x(self) -> float:
        """``sigma_x`` (rad)."""
    @property
    def sigma_y(self) -> float:
        """``sigma_y`` (rad)."""
    @property
    def max_thrust(self) -> float:
        """``sigma_Tf`` (N)."""
    @property
    def min_thrust(self) -> float:
        """The idle thrust (N)."""
    @property
    def thrust_coefficient(self) -> float:
        """``rho d^4 c_l`` of eq. (5)."""
    @property
    def navigator_mass(self) -> float:
        """``m_0`` (kg)."""
    @property
    def navigator_inertia(self) -> _F64:
        """``J_0`` (3, 3) (kg m^2)."""
    def effectiveness(self, failed: _Failed = None) -> _F64:
        """``M(Xi)``, the (6, 3n) effectiveness matrix of eq. (4), rows ``[torque; force]``: block ``i``
        is ``[[p_i]x R_z(psi_i); R_z(psi_i)]``, so the wrench is ``u = M f`` for the stacked
        agent-frame forces ``f = [f_1; ...; f_n]``. Columns of failed agents are zero.

        Args:
            failed: None or an iterable of failed agent indices.
        """
    def wrench(self, forces: ArrayLike, failed: _Failed = None) -> _F64:
        """``u = M(Xi) f`` (eq. 4): the (6,) wrench ``[u_tau; u_f]`` of the (n, 3) agent-frame forces
        ``f_i``. Forces of failed agents are ignored.

        Raises:
            ValueError: wrong shape, or NaN/inf forces.
        """
    def afs(self, failed: _Failed = None) -> "AttainableForceSpace":
        """The attainable-force-space approximation (eqs. 7-8) of the working agents.

        Raises:
            ConfigError: every agent failed, or a failure index the team does not have.
        """
    def plant(self, gravity: float = 9.81) -> "Plant":
        """The rigid-body parameters of the control law."""
    def hover_capability(self, failed: _Failed = None, gravity: float = 9.81) -> "HoverCapability":
        """Whether the working agents can hold hover at ``gravity`` with a margin (see
        ``HoverCapability``). A mask that leaves ``M`` rank-deficient is classified not capable.

        Raises:
            ConfigError: every agent failed, a failure index the team does not have, or a
                gravity that is not positive and finite (or whose weight overflows).
        """
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

@final
class AttainableForceSpace:
    """The elliptic-cone approximation of the attainable force space (AFS) of ``n`` working agents,
    ``n_x`` of them with even quarter turns (eqs. 7-8):

    ``u_f in AFS  <=>  u_f^T C(u_fz) u_f <= 1  and  ||u_f|| <= n sigma_Tf``,
    ``C = diag(1/c_x^2, 1/c_y^2, 0)``,
    ``c_x(z, s) = g(n_x, s sigma_y, z) + g(n_y, s sigma_x, z)``,
    ``c_y(z, s) = g(n_x, s sigma_x, z) + g(n_y, s sigma_y, z)``,
    ``g(n_k, sigma, z) = n_k sigma_Tf`` if ``sigma >= pi/2``, else ``(n_k/n)(1 - delta(n_k)) |z| tan(sigma)``.

    A force with ``z <= 0`` is outside unless a semi-axis comes from the ``sigma >= pi/2`` branch;
    the thrust bound is closed (``<=``). ``s`` in (0, 1] is the relaxation of the planner.

    Also available from a team: ``team.afs(failed=None)``.

    Raises:
        ConfigError: ``n = 0``, ``n_x > n``, or invalid limits.
    """

    FIELDS: ClassVar[Tuple[str, ...]]

    def __new__(
        cls, n: int, n_x: int, sigma_x: float, sigma_y: float, max_thrust: float
    ) -> "AttainableForceSpace": ...
    @property
    def n(self) -> int:
        """Working agents."""
    @property
    def n_x(self) -> int:
        """Working agents with even quarter turns."""
    @property
    def n_y(self) -> int:
        """``n - n_x``."""
    @property
    def sigma_x(self) -> float:
        """``sigma_x`` (rad)."""
    @property
    def sigma_y(self) -> float:
        """``sigma_y`` (rad)."""
    @property
    def max_thrust(self) -> float:
        """``sigma_Tf`` (N)."""
    @property
    def max_force(self) -> float:
        """``n sigma_Tf`` (N)."""
    @overload
    def semi_axes(
        self, z: float, relaxation: Optional[float] = None, *, s: Optional[float] = None
    ) -> Tuple[float, float]:
        """The semi-axes ``(c_x(z, s), c_y(z, s))`` of eq. (8) at height ``z``.

        Args:
            z: a float or an array of heights (N).
            relaxation: ``s`` in (0, 1], default 1 (``s=`` is an alias).

        Returns:
            ``(c_x, c_y)``: floats for a scalar ``z``, else arrays of ``z``'s shape.
        """
    @overload
    def semi_axes(
        self, z: ArrayLike, relaxation: Optional[float] = None, *, s: Optional[float] = None
    ) -> Tuple[Any, Any]:
        """The semi-axes for an array of heights (arrays of ``z``'s shape)."""
    def quadratic_form(
        self, u: ArrayLike, relaxation: Optional[float] = None, *, s: Optional[float] = None
    ) -> Any:
        """``u^T C(u_z) u = (u_x/c_x)^2 + (u_y/c_y)^2`` (eq. 7); a zero semi-axis gives 0 for a zero
        component and ``inf`` otherwise.

        Args:
            u: (3,) force or (N, 3) forces in the team frame (N).
            relaxation: ``s`` in (0, 1], default 1 (``s=`` is an alias).

        Returns:
            a float for (3,) input, else an (N,) array.
        """
    def contains(
        self, u: ArrayLike, relaxation: Optional[float] = None, *, s: Optional[float] = None
    ) -> Any:
        """Membership in the approximated AFS (eq. 7) with relaxation ``s``.

        Args:
            u: (3,) force or (N, 3) forces in the team frame (N).
            relaxation: ``s`` in (0, 1], default 1 (``s=`` is an alias).

        Returns:
            a bool for (3,) input, else an (N,) bool array.

        Raises:
            ValueError: NaN/inf in ``u``, or ``s`` outside (0, 1].
        """
    def project(self, u: ArrayLike) -> Tuple[_F64, Any, Any]:
        """The force projection ``K_f`` of eqs. (12)-(13) (with ``s = 1``):
        ``t_Tf = min(1, n sigma_Tf / ||u||)``, ``u' = t_Tf u``,
        ``t_eta = min(1, sqrt(1 / (u'^T C(u'_z) u')))``, ``K_f = diag(t_eta t_Tf, t_eta t_Tf, t_Tf)``.

        Args:
            u: (3,) requested force ``u_fr`` or (N, 3) forces in the team frame (N).

        Returns:
            ``(K_f u, t_Tf, t_eta)``: a (3,) array and two floats for (3,) input, else (N, 3),
            (N,) and (N,) arrays.
        """
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

@final
class ForceProjection:
    """The force projection of eqs. (12)-(13): ``K_f = diag(t_eta t_Tf, t_eta t_Tf, t_Tf)``.

    Attributes:
        force: (3,) ``K_f u_fr``.
        t_Tf: ``min(1, n sigma_Tf / ||u_fr||)``.
        t_eta: ``min(1, sqrt(1 / (u'^T C(u'_z) u')))``, ``u' = t_Tf u_fr``.
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def force(self) -> _F64:
        """(3,) ``K_f u_fr``."""
    @property
    def t_Tf(self) -> float:
        """``t_Tf``."""
    @property
    def t_eta(self) -> float:
        """``t_eta``."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

def gimbal_force(eta_x: ArrayLike, eta_y: ArrayLike, thrust: ArrayLike) -> _F64:
    """``f = T a_hat(eta_x, eta_y)``, ``a_hat = [cos eta_x sin eta_y, -sin eta_x, cos eta_x cos eta_y]``
    (eqs. 1 and 5): the agent-frame force of a gimbal command.

    Args:
        eta_x: inner gimbal angle(s) (rad).
        eta_y: outer gimbal angle(s) (rad).
        thrust: thrust(s) ``T`` (N).

    The arguments broadcast like NumPy's.

    Returns:
        an array of shape ``broadcast_shape + (3,)``: (3,) for scalars.
    """

def thrust_direction(eta_x: ArrayLike, eta_y: ArrayLike) -> _F64:
    """``a_hat(eta_x, eta_y)`` of eq. (1), the unit thrust direction in the agent frame.

    Returns:
        an array of shape ``broadcast_shape + (3,)``.
    """

def gimbal_inverse(force: ArrayLike) -> Tuple[Any, Any, Any]:
    """The allocation inverse of an agent force (paper, "Control Allocation"):
    ``T = ||f||``, ``eta_x = asin(-f_y / T)``,
    ``eta_y = atan2(f_x / sgn(cos eta_x), f_z / sgn(cos eta_x))`` (a zero force gives zeros).

    Args:
        force: (3,) or (N, 3) agent-frame force(s) (N).

    Returns:
        ``(eta_x, eta_y, thrust)``, floats for (3,) input, else (N,) arrays, so that
        ``gimbal_force(*gimbal_inverse(f))`` reproduces ``f``.
    """

@final
class AttitudePlanner:
    """The bisection attitude planner of eqs. (9)-(11): the smallest tilt ``theta`` of the reference
    attitude ``R_r`` toward the force request ``f_r`` that makes ``R_d^T f_r`` attainable (in the AFS
    with relaxation ``s``). ``b_zd = rot(b_zr, k, theta)``, ``k = (b_zr x f_r)/||.||``,
    ``b_yd = (b_zd x b_xr)/||.||``, ``b_xd = b_yd x b_zd``.

    Returns the last *feasible* bisection point, stops on ``tolerance`` or ``max_iterations``,
    and rolls about ``b_xr`` when ``f_r`` is (anti)parallel to ``b_zr``.

    Args:
        relaxation: AFS relaxation ``s`` in (0, 1] (``s=`` is an alias).
        tolerance: bisection tolerance on ``theta`` (rad); default ``max(1e-10, 8 eps)``.
        max_iterations: bisection iteration cap (>= 1); default 64.

    Raises:
        ConfigError: ``s`` outside (0, 1], a non-positive tolerance or a zero iteration cap.
    """

    def __new__(
        cls,
        relaxation: Optional[float] = None,
        tolerance: Optional[float] = None,
        max_iterations: Optional[int] = None,
        *,
        s: Optional[float] = None,
    ) -> "AttitudePlanner": ...
    @property
    def relaxation(self) -> float:
        """The relaxation ``s``."""
    @property
    def tolerance(self) -> float:
        """The bisection tolerance (rad)."""
    @property
    def max_iterations(self) -> int:
        """The bisection iteration cap."""
    def plan(self, afs: AttainableForceSpace, R_r: ArrayLike, f_r: ArrayLike) -> "PlannerResult":
        """Plans ``R_d`` for the reference attitude ``R_r`` and the inertial force request
        ``f_r = t_Tf R u_fr`` (eq. 9).

        Args:
            afs: the team's ``AttainableForceSpace``.
            R_r: (3, 3) reference attitude (body to inertial).
            f_r: (3,) inertial force request (N).

        Returns:
            PlannerResult(R_d, theta, iterations, status).

        Raises:
            ValueError: wrong shapes, or NaN/inf inputs.
        """

@final
class PlannerResult:
    """The planner's output (eqs. 9-11).

    Attributes:
        R_d: (3, 3) planned attitude ``[b_xd b_yd b_zd]``.
        theta: the tilt ``theta*`` from ``b_zr`` toward ``f_r`` (rad).
        iterations: bisection iterations used (0 unless status is "planned").
        status: "already-feasible" (``R_d = R_r``), "planned" (bisection), "zero-force"
            (``f_r = 0``, ``R_d = R_r``) or "unreachable" (``||f_r|| > n sigma_Tf``: ``b_zd`` along
            ``f_r``).
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def R_d(self) -> _F64:
        """(3, 3) planned attitude."""
    @property
    def theta(self) -> float:
        """``theta*`` (rad)."""
    @property
    def iterations(self) -> int:
        """Bisection iterations used."""
    @property
    def status(self) -> PlannerStatus:
        """How the output was reached."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

@final
class Gains:
    """Gains of the control law (eq. 12): ``K_x``, ``K_R`` and ``K_xi = blockdiag(K_Omega, K_v)``
    (twist order ``[Omega; v]``). Not scaled by mass or inertia.

    Args:
        k_x: ``K_x``, (3,) diagonal or (3, 3) symmetric with a positive diagonal.
        k_r: ``K_R``, (3,) diagonal or (3, 3).
        k_xi: ``K_xi``, (6,) diagonal or a block-diagonal (6, 6) matrix ``blockdiag(K_Omega, K_v)``.

    Raises:
        ConfigError: a gain is not finite, not symmetric or has a non-positive diagonal entry.
        ValueError: wrong shapes, or a (6, 6) ``k_xi`` with non-zero off-diagonal blocks.
    """

    FIELDS: ClassVar[Tuple[str, ...]]

    def __new__(cls, k_x: ArrayLike, k_r: ArrayLike, k_xi: ArrayLike) -> "Gains": ...
    @staticmethod
    def paper() -> "Gains":
        """The paper's gains: ``K_x = diag(0.4, 0.4, 1)``, ``K_R = diag(12, 12, 1)``,
        ``K_xi = diag(8, 8, 1.5, 0.8, 0.8, 2)``.
        """
    @property
    def k_x(self) -> _F64:
        """``K_x`` (3, 3)."""
    @property
    def k_r(self) -> _F64:
        """``K_R`` (3, 3)."""
    @property
    def k_omega(self) -> _F64:
        """``K_Omega`` (3, 3)."""
    @property
    def k_v(self) -> _F64:
        """``K_v`` (3, 3)."""
    @property
    def k_xi(self) -> _F64:
        """``K_xi`` (6, 6)."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

@final
class State:
    """The measured state: pose and body-frame twist ``xi = [Omega; v]``.

    Args:
        position: ``x`` (3,), CoM position in the inertial frame (m), z up.
        attitude: ``R`` (3, 3), body-to-inertial rotation; default identity.
        angular_velocity: ``Omega`` (3,), body frame (rad/s); default 0.
        velocity: ``v`` (3,), body frame, ``x_dot = R v`` (m/s); default 0.

    Wherever a state is expected a dict with these keys is accepted too. Values are not
    validated here: ``Controller.step`` reports NaN/inf or a non-rotation attitude as a
    ``CycleError``, the law functions as an ``InputError``.
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    def __new__(
        cls,
        position: ArrayLike,
        attitude: Optional[ArrayLike] = None,
        angular_velocity: Optional[ArrayLike] = None,
        velocity: Optional[ArrayLike] = None,
    ) -> "State": ...
    @property
    def position(self) -> _F64:
        """``x`` (3,) (m)."""
    @property
    def attitude(self) -> _F64:
        """``R`` (3, 3)."""
    @property
    def angular_velocity(self) -> _F64:
        """``Omega`` (3,), body frame (rad/s)."""
    @property
    def velocity(self) -> _F64:
        """``v`` (3,), body frame (m/s)."""
    def to_dict(self) -> dict[str, _F64]:
        """The fields as a dict (accepted wherever a state is)."""

@final
class Reference:
    """The reference pose and its derivatives (feed-forward); unknown derivatives are zero.

    Args:
        position: ``x_r`` (3,) (m).
        velocity: ``x_r_dot`` (3,), inertial (m/s); default 0.
        acceleration: ``x_r_ddot`` (3,), inertial (m/s^2); default 0.
        attitude: ``R_r`` (3, 3), the reference attitude; default identity.
        angular_velocity: ``Omega_d`` (3,), body frame of the reference (rad/s); default 0.
        angular_acceleration: ``Omega_d_dot`` (3,) (rad/s^2); default 0.

    Wherever a reference is expected a dict with these keys is accepted too.
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    def __new__(
        cls,
        position: ArrayLike,
        velocity: Optional[ArrayLike] = None,
        acceleration: Optional[ArrayLike] = None,
        attitude: Optional[ArrayLike] = None,
        angular_velocity: Optional[ArrayLike] = None,
        angular_acceleration: Optional[ArrayLike] = None,
    ) -> "Reference": ...
    @staticmethod
    def hover(position: ArrayLike) -> "Reference":
        """Hover, level, at ``position`` with zero feed-forward."""
    @property
    def position(self) -> _F64:
        """``x_r`` (3,)."""
    @property
    def velocity(self) -> _F64:
        """``x_r_dot`` (3,)."""
    @property
    def acceleration(self) -> _F64:
        """``x_r_ddot`` (3,)."""
    @property
    def attitude(self) -> _F64:
        """``R_r`` (3, 3)."""
    @property
    def angular_velocity(self) -> _F64:
        """``Omega_d`` (3,)."""
    @property
    def angular_acceleration(self) -> _F64:
        """``Omega_d_dot`` (3,)."""
    def to_dict(self) -> dict[str, _F64]:
        """The fields as a dict (accepted wherever a reference is)."""

@final
class Plant:
    """Rigid-body parameters of the law: ``G = blockdiag(J_C, m_C I)`` and gravity ``g`` along ``-e_3``
    (eqs. 2-3). ``team.plant(gravity=9.81)`` builds it from a team.

    Args:
        mass: ``m_C`` (kg), > 0.
        inertia: ``J_C`` (3, 3) (kg m^2), symmetric positive definite.
        gravity: ``g`` (m/s^2), > 0.

    Raises:
        ValueError: NaN/inf values or a wrong shape.
        ConfigError (a ValueError): a mass or gravity that is not positive, an inertia that is
            not symmetric positive definite, or a weight ``m_C g`` that overflows.
    """

    FIELDS: ClassVar[Tuple[str, ...]]

    def __new__(cls, mass: float, inertia: ArrayLike, gravity: float = 9.81) -> "Plant": ...
    @property
    def mass(self) -> float:
        """``m_C`` (kg)."""
    @property
    def inertia(self) -> _F64:
        """``J_C`` (3, 3) (kg m^2)."""
    @property
    def gravity(self) -> float:
        """``g`` (m/s^2)."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

@final
class LawOutput:
    """Everything the control law computes in one period (eq. 12).

    Attributes:
        e_x: (3,) ``x - x_r``.
        e_R: (3,) ``1/2 (R_d^T R - R^T R_d)^vee``.
        e_xi: (6,) ``xi - xi_d = [e_Omega; e_v]``.
        u_r: (6,) ``[u_tau_r; u_fr]``.
        u_d: (6,) ``blockdiag(I, K_f) u_r``.
        V_R: ``Psi + ||e_Omega||_{K_Omega}``.
        V_x: ``||e_x||_{K_x} + ||e_v||_{K_v}``.
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def e_x(self) -> _F64:
        """(3,) ``e_x``."""
    @property
    def e_R(self) -> _F64:
        """(3,) ``e_R``."""
    @property
    def e_xi(self) -> _F64:
        """(6,) ``[e_Omega; e_v]``."""
    @property
    def u_r(self) -> _F64:
        """(6,) ``[u_tau_r; u_fr]``."""
    @property
    def u_d(self) -> _F64:
        """(6,) ``blockdiag(I, K_f) u_r``."""
    @property
    def V_R(self) -> float:
        """``V_R``."""
    @property
    def V_x(self) -> float:
        """``V_x``."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

def force_request(
    plant: Plant, gains: Gains, state: _StateLike, reference: _ReferenceLike
) -> _F64:
    """``u_fr``, the force part of ``u_r`` in the team frame, which does not depend on ``R_d``
    (eq. 12 with ``g_C = [0; -m g R^T e_3]``):
    ``u_fr = m R^T x_r_ddot - K_v e_v - R^T K_x e_x + m g R^T e_3``, ``e_x = x - x_r``,
    ``e_v = v - R^T x_r_dot``.

    Args:
        plant: ``Plant`` (or ``team.plant()``).
        gains: ``Gains``.
        state: ``State`` or dict.
        reference: ``Reference`` or dict.

    Returns:
        (3,) array.

    Raises:
        InputError (a ValueError): NaN/inf input or a non-rotation attitude.
    """

def control_wrench(
    plant: Plant,
    gains: Gains,
    state: _StateLike,
    reference: _ReferenceLike,
    R_d: ArrayLike,
    u_fr: ArrayLike,
    K_f: ArrayLike,
) -> LawOutput:
    """The torque part of eq. (12) with the planned ``R_d``, and the full ``u_r``, ``u_d``:
    ``e_R = 1/2 (R_d^T R - R^T R_d)^vee``, ``e_xi = xi - [R^T R_d Omega_d; R^T x_r_dot]``,
    ``u_tau_r = J xi_dot_dOmega - [J Omega]x Omega_d' - K_Omega e_Omega - K_R e_R``,
    ``u_r = [u_tau_r; u_fr]``, ``u_d = blockdiag(I, K_f) u_r``, and the Lyapunov values
    ``V_R = Psi + ||e_Omega||_{K_Omega}``, ``Psi = 1/2 tr(K_R (I - R_d^T R))``,
    ``V_x = ||e_x||_{K_x} + ||e_v||_{K_v}`` with ``||a||_K = 1/2 a^T K a``.

    Args:
        plant, gains, state, reference: as for ``force_request``.
        R_d: (3, 3) planned attitude (from ``AttitudePlanner.plan``).
        u_fr: (3,) force request (from ``force_request``).
        K_f: (3, 3) force projection ``diag(t_eta t_Tf, t_eta t_Tf, t_Tf)``, or its (3,) diagonal.

    Returns:
        LawOutput(e_x, e_R, e_xi, u_r, u_d, V_R, V_x).

    Raises:
        InputError / ValueError: NaN/inf input, a non-rotation attitude or wrong shapes.
    """

@final
class Allocation:
    """The result of one allocation.

    Attributes:
        forces: (n, 3) agent-frame forces ``f_i``, each inside its admissible set (zero for
            failed agents).
        wrench: (6,) ``u = M f``, the wrench they produce.
        e_f: ``||u_fd - u_f||``, the paper's allocation error (force part).
        wrench_error: ``||u_d - M f||`` over the whole wrench.
        rounds: solve rounds (pseudo-inverse 1, redistribution up to n, Clarabel iterations).
        saturated: (n,) bool, agents saturated onto the boundary of their admissible set.
        fallback: the allocator fell back to the redistributed pseudo-inverse (Clarabel).
        method: the allocator's name.
        report: the solve report (text) of "clarabel" and "clarabel-sequential", None for the
            other allocators.
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def forces(self) -> _F64:
        """(n, 3) agent-frame forces."""
    @property
    def wrench(self) -> _F64:
        """(6,) ``M f``."""
    @property
    def e_f(self) -> float:
        """``||u_fd - u_f||``."""
    @property
    def wrench_error(self) -> float:
        """``||u_d - M f||``."""
    @property
    def rounds(self) -> int:
        """Solve rounds."""
    @property
    def saturated(self) -> _Bool:
        """(n,) saturated agents."""
    @property
    def fallback(self) -> bool:
        """The allocator fell back to the redistributed pseudo-inverse."""
    @property
    def method(self) -> AllocatorName:
        """The allocator's name."""
    @property
    def report(self) -> Optional[str]:
        """The solve report of "clarabel" and "clarabel-sequential", None otherwise."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

def afs_atlas(
    team: str,
    *,
    failed: Optional[Sequence[int]] = None,
    heights: Optional[Sequence[float]] = None,
    directions: int = 36,
    relaxation: float = 1.0,
    certify_heights: int = 9,
    torque: Optional[Sequence[float]] = None,
    plots: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> dict[str, Any]:
    """The AFS atlas of one catalogue team (``Team.preset_names()``) with the agents ``failed``
    removed: the exact attainable lateral forces, bracketed, against the elliptic cone at
    relaxation ``relaxation``, and the certified relaxation ``s*`` (as ``tvmd-sim afs``;
    ``docs/afs-atlas.md``). Every number is an interval ``[lower, upper]``: ``lower`` attained by
    commands inside every agent's box, ``upper`` a weak-duality bound.

    Keys: ``team``, ``failed``, ``n``, ``weight`` (N), ``ceiling`` (the hover ceiling in
    ``m_C g``), ``can_hover``, ``heights`` (one dict per height in ``m_C g``: ``ratio`` (cone over
    attainable radius, smallest and largest over the directions), ``soundness``,
    ``conservatism``, ``worst_width``), ``certified`` (``s*`` as ``[lower, upper]``),
    ``certified_range`` (``m_C g``), ``limiting`` (height in ``m_C g`` and angle in degrees where
    ``s*`` is limited), ``certified_worst_width``, ``note``. With ``plots`` (a directory) the
    cross-sections are drawn as ``<team>.png``. ``torque`` (N m) is held meanwhile (zero by
    default). Raises ``ValueError`` for an unknown team, a bad mask or bad settings, ``OSError``
    (the path named) for a ``plots`` directory that cannot be one, before any work, and
    ``KeyboardInterrupt`` on Ctrl-C (the computation stops within one ray; nothing written).
    Releases the GIL; about 2 s for A4 with the defaults in a release build."""

def allocate(
    team: Team,
    wrench: ArrayLike,
    method: AllocatorName = "exact-boundary-redistribution",
    weights: Optional[ArrayLike] = None,
    failed: _Failed = None,
    previous: Optional[ArrayLike] = None,
    rate_limits: Optional[ArrayLike] = None,
    dt: Optional[float] = None,
    regularization: Optional[float] = None,
    max_rounds: Optional[Union[int, Literal["uncapped"]]] = None,
) -> Allocation:
    """Allocates a desired wrench ``u_d`` over the team's working agents: inverts ``u_d = M f``
    (eq. 4) into agent-frame forces inside each agent's admissible set ``E_f`` (eq. 6).

    Methods:
        "pseudo-inverse": ``f = M^T (M M^T)^-1 u_d``, then each agent outside ``E_f`` is clamped.
        "weighted-pseudo-inverse": minimizes ``sum_i w_i ||f_i||^2`` s.t. ``M f = u_d``, clamped;
            ``weights`` (n,) positive per-agent weights are required.
        "redistributed-pseudo-inverse": Jin 2005 redistribution (the paper's): the agent
            leaving ``E_f`` furthest is saturated and fixed, the rest of the wrench is
            redistributed.
        "exact-boundary-redistribution" (default): walks from the redistributed
            pseudo-inverse's forces toward ``u_d``, stopping each agent on the exact boundary of
            ``E_f`` (closed form) and moving it along that boundary afterwards; never clamps (a
            one-shot call has no previous period to start from; the controller's allocator
            keeps one).
        "capped-redistribution": the redistribution stopped after ``max_rounds`` rounds
            (default 2, at least 1), the agents still outside clamped and the miss in ``e_f``: a
            bounded period for large teams.
        "clarabel": ``min ||W (M f - u_d)||^2 + lambda ||f||^2`` over a convex inner bound of
            ``E_f`` (SOC-constrained QP); needs the cargo feature ``clarabel``. ``weights`` (6,) is the
            diagonal of ``W``, ``regularization`` is ``lambda`` (default 1e-6).
        "clarabel-sequential": the same objective over the exact ``E_f`` by sequential convex
            steps: from the redistributed pseudo-inverse's forces, each step a QP over ``E_f``
            linearized at the current forces (an inner bound that keeps the gimbal corners the
            "clarabel" pyramid drops), at most 5 steps, stopping when the wrench is exact
            (relative 1e-9) or the objective decreases by less than 1e-6 relatively; never worse
            than "redistributed-pseudo-inverse". Needs the cargo feature ``clarabel``;
            ``weights`` (6,) is ``W``, ``regularization`` is ``lambda`` (default 0).

    Args:
        team: the ``Team``.
        wrench: (6,) desired wrench ``u_d = [u_tau; u_f]`` in the team frame.
        method: the allocator name (see ``tvmd.ALLOCATORS``).
        weights: see the methods.
        failed: None or failed agent indices (they get zero force).
        previous: (n, 2..4) previous commands, columns ``eta_x, eta_y[, thrust, omega]``; only
            with ``rate_limits`` (default: centred gimbals).
        rate_limits: ``(eta_x_rate, eta_y_rate)`` (rad/s): narrows each gimbal range to
            ``|eta - eta_prev| <= rate dt``.
        dt: the control period (s), required with ``rate_limits``.
        regularization: ``lambda`` of "clarabel" and "clarabel-sequential".
        max_rounds: "exact-boundary-redistribution": caps its walk at this many rounds
            (an int >= 0; 0 is its start, the redistributed pseudo-inverse's forces or better),
            or "uncapped" for the walk's own ``2 n + 4`` rounds. A capped call returns the best
            forces found so far, inside ``E_f``, with their true ``e_f``. Default None: the
            library's default cap, 2 rounds (a bounded worst case). "capped-redistribution":
            its rounds (an int >= 1; default 2; "uncapped": one per agent). Refused by the others.

    Returns:
        Allocation(forces, wrench, e_f, wrench_error, rounds, saturated, fallback, method, report).

    Raises:
        ValueError: an unknown method, "clarabel" or "clarabel-sequential" without the feature, options that do not
            apply to the method, wrong shapes, NaN/inf input.
        ConfigError: a degraded team that cannot produce every wrench, bad weights or rates.
    """

@final
class Controller:
    """The full-pose controller of a team (``tvmd_core::Controller``): per control period, the force
    request ``u_fr``, the projection ``t_Tf``, the attitude planner (``R_d``, eqs. 9-11), ``K_f`` and the
    torque part of the law (eq. 12), the allocation and the inversion into gimbal angles and
    rotor speeds inside ``E_f`` (eq. 6).

    The law: by default the offset-free law (``law="offset-free"``, ``tvmd_core::ControllerSettings::
    offset_free_law``; docs/method.md "Beyond the paper"), the one that holds its setpoint under
    model error and unmodelled forces: natural gains (1.5 rad/s position with damping 1,
    6 rad/s attitude with damping 0.6, scaled by the team's mass and inertia), a disturbance observer (10 rad/s, torque
    bound 5 N m) and the planned attitude's rates. ``law="paper"`` is the paper's eq. (12) bit for
    bit (``gains`` as given, no offset-free action, the reference's ``Omega_d``); under any
    unmodelled force it leaves a steady error.

    Threads: a controller may be shared between threads. Its calls run one at a time (the GIL);
    arguments are converted before the controller is borrowed, so a conversion that runs
    Python code (an ``__array__`` method) never finds it busy. The order of two threads' steps is
    theirs to arrange: each ``step`` advances the one controller state.

    Copies: ``copy.copy`` and ``copy.deepcopy`` give an independent controller in the same state
    (previous commands, offset-free state, planned-rate filter, fault detector): both go on
    exactly as the original would. ``pickle`` rebuilds the controller from its constructor's
    arguments with its current failures (``set_failures``) and landed flag; its flight state
    starts afresh, as after ``reset()``.

    Args:
        team: the ``Team``.
        gains: ``Gains``; None for the paper's (``Gains.paper()``). Used as given with
            ``law="paper"`` (and a ``law`` dict whose ``gains`` is ``"paper"``; multiplied by the
            team's mass and inertia for ``"team-scaled"``); unused with natural gains, which the
            default ``law="offset-free"`` has (``Controller.gains`` shows the gains in use).
        relaxation: AFS relaxation ``s`` of the planner, in (0, 1]; default 0.5 (``s=`` is an
            alias).
        gravity: ``g`` (m/s^2).
        period: control period ``dt`` (s) (used by the rate limits, the offset-free state and the
            planned rates).
        allocator: allocator name (see ``tvmd.ALLOCATORS`` and ``tvmd.allocate``).
        rate_limits: optional ``(eta_x_rate, eta_y_rate)`` gimbal rate limits (rad/s).
        failed: None or failed agent indices.
        weights: allocator weights (see ``tvmd.allocate``).
        regularization: ``lambda`` of the "clarabel" and "clarabel-sequential" allocators.
        planner_tolerance: bisection tolerance (rad); default ``max(1e-10, 8 eps)``.
        planner_max_iterations: bisection iteration cap; default 64.
        null_space: a null-space stage after the allocator (docs/method.md "Null-space stage"):
            ``"margin"`` (keep every agent away from its limits) or ``"inward-tilt=<rad>"``
            (tilt each thrust toward the team's centre); moves the forces inside ``null(M)``, so
            the wrench is unchanged to round-off, and never outside ``E_f``. None (default): off.
            ``StepOutput.null_space`` reports what it changed.
        law: the control law (keyword only): ``"offset-free"`` (default), ``"paper"``, or a dict
            with the keys of a scenario's TOML ``[law]`` table, a key left out taking the
            offset-free law's value: ``gains`` (``"paper"``, ``"team-scaled"`` or
            ``{"natural": {"position_frequency": [wx, wy, wz], "position_damping": [..],
            "attitude_frequency": [..], "attitude_damping": [..]}}``, rad/s and ratios, each
            > 0), ``offset_free`` (``"off"``, ``{"kind": "observer", "force_bandwidth": 10.0,
            "torque_bandwidth": 10.0, "max_torque": 5.0}`` in rad/s and N m, or ``{"kind":
            "integral", "k_x": [..], "k_r": [..], "max_torque": 5.0}`` in N/(m s), N m/(rad s)),
            ``attitude_rate`` (``"off"`` or ``{"bandwidth": 20.0, "max_rate": 5.0}`` in rad/s).
            Lists may be NumPy arrays. ``Controller.law`` names it.
        fault_detection: agent fault detection (keyword only; default None, off): ``"report"``
            or ``"mask"`` (the recommended detector: relative model error 0.015, threshold 5,
            persistence 5 periods; with ``"mask"`` the controller masks an agent whose loss is
            confirmed, as ``set_failures`` would), or a dict with the keys of a scenario's TOML
            ``[fault_detection]`` table (``model_error``, ``threshold``, ``persistence``,
            ``response``, and ``report_check``: a dict of the check of the agents' reports,
            ``set_reports``, with the keys ``thrust_tolerance`` (share of the maximum thrust,
            0.1), ``angle_tolerance`` (rad, 0.05), ``servo_rate`` (rad/s, 6), ``servo_lag`` (s,
            0.05), ``command_delay`` (s, >= 0, 0.01), ``link_timeout`` (s, 0.1), ``persistence``
            (reports, 1 to 255, 2), ``thrust_forget`` (share of the maximum thrust per second,
            2.5), ``angle_forget`` (rad/s, 2.5); each optional, its recommended value given
            after its unit; every number but ``command_delay`` finite and > 0). It reads the
            disturbance observer's residual, so it needs the offset-free law's observer.
            ``fault_report()`` gives each period's verdict. A bad value raises ``ValueError``
            naming its key.
        max_rounds: the "exact-boundary-redistribution" allocator's round cap per period
            (keyword only; see ``tvmd.allocate``): bounds its worst-case cost, the flight option
            of docs/allocation-benchmark.md; "uncapped" for the walk's own ``2 n + 4``. Default
            None: the library's default cap, 2 rounds.

    Raises:
        ConfigError: invalid gains, ``s``, gravity, period, rates, or a degraded team that cannot
            produce every wrench.
        ValueError: unknown allocator, "clarabel" or "clarabel-sequential" without the cargo
            feature, wrong shapes, an unknown null-space objective or a tilt that is missing, not
            finite or not below ``pi/2``; an unknown ``law`` name or key, a missing or misplaced
            setting, or a value that is not finite and > 0 (the message names the field, e.g.
            ``law.offset_free.force_bandwidth``).
        TypeError: ``law`` neither a str nor a dict, or a value in it of the wrong type (a str
            for a number, a number for a table).
    """

    def __new__(
        cls,
        team: Team,
        gains: Optional[Gains] = None,
        relaxation: Optional[float] = None,
        gravity: float = 9.81,
        period: float = 0.01,
        allocator: AllocatorName = "exact-boundary-redistribution",
        rate_limits: Optional[ArrayLike] = None,
        failed: _Failed = None,
        weights: Optional[ArrayLike] = None,
        regularization: Optional[float] = None,
        planner_tolerance: Optional[float] = None,
        planner_max_iterations: Optional[int] = None,
        *,
        s: Optional[float] = None,
        null_space: Optional[str] = None,
        law: _LawArg = "offset-free",
        fault_detection: Union[str, Mapping[str, Any], None] = None,
        max_rounds: Optional[Union[int, Literal["uncapped"]]] = None,
    ) -> "Controller": ...
    def fault_report(self) -> Optional[Dict[str, Any]]:
        """The fault detector's report of the last period, or None (detection off, or no period
        stepped yet).

        Returns:
            dict: ``statistic`` (the residual in noise units) and the ``threshold`` it was
            compared with; ``verdict`` (``"nominal"``, ``"unexplained"``, ``"suspected"`` or
            ``"confirmed"``); ``agent`` (the isolated agent, or None), ``kind`` (``"loss"``,
            ``"partial-loss"``, ``"stuck-gimbal"``, ``"link-loss"`` or None) and ``efficiency``
            (the fraction delivered, for a partial loss); ``periods`` (consecutive periods of a
            suspicion); ``masked`` (the agent the controller masked itself, with
            ``fault_detection="mask"``, or None); ``source`` (``"residual"`` or ``"reports"``:
            the check that named ``agent``, ``set_reports``; None when no agent is named).
        """
    def set_reports(self, reports: ArrayLike) -> None:
        """Gives the fault detection each agent's newest own report (issue 60): what it measured of its
        rotor and gimbal, checked at the next ``step`` against the commands it answers. The
        controller ages each report by its period at every step until a newer one replaces it; the same
        report given again (its age grown) is not counted twice, and an agent whose report grows older
        than the link timeout (0.1 s) is named with ``kind="link-loss"``. ``fault_report()["source"]``
        says whether the reports or the residual named an agent.

        Args:
            reports: (n, 4) rows ``(thrust, eta_x, eta_y, age)``: the rotor speed as the thrust it
                makes (N), the gimbal angles (rad) and the report's age (s), as
                ``tvmd.sim.Observation.reports``; a row all NaN is an agent with no report (kept as
                before).

        Raises:
            ValueError: another shape, a row with a NaN or infinite value among finite ones, a negative
                thrust or age (the message names the row), or a controller without fault detection.
        """
    def set_failures(self, failed: _Failed = None) -> "HoverCapability":
        """Marks agents failed (None or [] for none). A failed agent leaves ``n``, ``n_x``/``n_y`` and ``M``
        and is commanded idle.

        Returns:
            HoverCapability: whether the working agents can hold hover with a margin, computed
            now (once per mask) and kept as ``hover_capability``, so a caller can decide to land.

        Raises:
            ConfigError: an index the team does not have, or a remaining team that cannot
                produce every wrench (the previous mask is kept).
        """
    @property
    def hover_capability(self) -> "HoverCapability":
        """The classification of the working agents when the failures were last set (the full
        team's after construction)."""
    def reset(self) -> None:
        """Forgets the previous command (rate limits restart from centred gimbals; a rejected
        cycle then holds idle commands), whatever the allocator kept, the offset-free state (the
        observer's estimate or the integral back to zero) and the planned-rate filter (at rest).
        The landed flag (``set_landed``) is kept.
        """
    def set_landed(self, landed: Union[bool, Literal[0, 1]]) -> None:
        """Tells the controller whether the team stands on the ground (the caller's contact or
        landing detector). While landed the offset-free state is cleared and held at zero (the
        ground's reaction is no disturbance to compensate); after ``set_landed(False)`` it starts
        again from zero. No effect on anything else, and none with ``law="paper"``. ``landed``
        is a bool or the integer 0 or 1 (anything else: ``TypeError``).
        """
    @property
    def landed(self) -> bool:
        """Whether the landed hold is on (``set_landed``); False after construction."""
    @property
    def offset_free_compensation(self) -> Tuple[_F64, _F64]:
        """``(force, torque)``: the wrench the offset-free state adds to the next period's request
        (before it measures that period): ``force`` (3,) in N in the inertial frame ``{I}``,
        ``torque`` (3,) in N m in the body frame ``{C}``. Zeros with ``law="paper"`` (no
        offset-free action) and while landed. The observer's estimate of the unmodelled
        disturbance is its negative: under a constant unmodelled force ``F`` the force converges to
        ``-F``.
        """
    @property
    def planned_rates(self) -> Optional[Tuple[_F64, _F64]]:
        """``(Omega_d, Omega_d_dot)``: the planned attitude's rates of the last period, (3,) each,
        body frame, rad/s and rad/s^2; None without the planned-rate filter (``law="paper"``)."""
    @property
    def law(self) -> _LawName:
        """The control law's name: ``"paper"``, ``"offset-free"`` (the default) or ``"custom"``
        (any other ``law`` dict)."""
    def step(self, state: _StateLike, reference: _ReferenceLike) -> "StepOutput":
        """One control period.

        Args:
            state: ``State`` or dict with keys position (3,), attitude (3, 3),
                angular_velocity (3,), velocity (3,) (only ``position`` required).
            reference: ``Reference`` or dict with keys position, velocity, acceleration,
                attitude, angular_velocity, angular_acceleration (only ``position`` required).

        Returns:
            StepOutput.

        Raises:
            CycleError (a ValueError): NaN/inf input, a non-rotation attitude, a component beyond
                the cycle's input bound (``tvmd_core::Controller::input_limit``, 4.3e151 for the
                paper's team in f64), or a non-zero force request that only zero thrust answers;
                the exception's ``commands`` (n, 4) are the previous period's commands to hold.
            ValueError / TypeError: wrong shapes or argument types.
        """
    def law_stage(self, state: _StateLike, reference: _ReferenceLike) -> "LawStage":
        """The law stage of one period (``Controller::law`` in Rust, ``tvmd_law`` in C): ``u_fr``
        (with the offset-free compensation), the projection, the planner and eq. 12, up to the
        body wrench ``u_d``; ``allocate(out.wrench)`` then gives what ``step`` gives, bit for
        bit. Run the two at their own rates (a flight stack's attitude and allocation loops);
        with an offset-free law the next ``allocate`` records the delivered wrench.

        Args:
            state, reference: as ``step``.

        Raises:
            CycleError: as ``step``'s input checks (``commands``: the held ones).
            ValueError / TypeError: wrong shapes or argument types.
        """
    def allocate(self, wrench: ArrayLike) -> "AllocationStage":
        """The allocation stage: a (6,) body wrench ``[u_tau; u_f]`` (N m, N; body frame) to
        per-agent commands inside ``E_f``, which become the held commands (the drop-in for a
        flight stack's control allocation).

        Raises:
            ValueError: a wrench that is not (6,) or not finite.
            CycleError: zero thrust on every agent for a non-zero force, or a non-finite result
                (``commands``: the held ones).
        """
    def plan(self, reference_attitude: ArrayLike, force: ArrayLike) -> "PlannerResult":
        """The planner alone: the attitude ``R_d`` closest to ``reference_attitude`` (3, 3) whose
        AFS holds ``force`` (3,) (N, inertial frame), at the controller's relaxation and
        failure mask. Changes nothing.

        Raises:
            ValueError: wrong shapes, non-finite values, or a ``reference_attitude`` that is not a
                rotation.
        """
    @property
    def team(self) -> Team:
        """The team."""
    @property
    def gains(self) -> Gains:
        """The gains the law uses: ``gains`` as given (``law="paper"``), scaled by the team
        (``"team-scaled"``) or made from the natural frequencies (the default law)."""
    @property
    def relaxation(self) -> float:
        """The planner relaxation ``s``."""
    @property
    def gravity(self) -> float:
        """``g`` (m/s^2)."""
    @property
    def period(self) -> float:
        """The control period (s)."""
    @property
    def rate_limits(self) -> Optional[Tuple[float, float]]:
        """The gimbal rate limits (rad/s), or None."""
    @property
    def allocator(self) -> AllocatorName:
        """The allocator's name."""
    @property
    def planner_max_iterations(self) -> int:
        """The planner's bisection iteration cap."""
    @property
    def null_space(self) -> Optional[str]:
        """The null-space stage ("margin", "inward-tilt=<rad>"), or None."""
    @property
    def failed(self) -> list[int]:
        """Indices of the failed agents."""
    @property
    def afs(self) -> AttainableForceSpace:
        """The AFS of the working agents."""
    @property
    def previous_commands(self) -> _F64:
        """(n, 4) previous period's commands."""

@final
class HoverCapability:
    """Whether the working agents of a team can hold hover with a margin: the hover wrench
    ``[0, 0, 0, 0, 0, m_C g]`` strictly inside their attainable wrench set (``tvmd_core::hover``,
    docs/method.md "Hover capability").

    The margin is certified by an allocation ``f`` with ``M f = w_hover`` inside every working
    agent's exact ``E_f`` (eq. 6): the smallest normalized slack of any agent (thrust to both
    ends of its range, each gimbal angle to its limit, each over the range's half-width; 1 means
    every agent at the centre). It is a lower bound of the best slack over all allocations, exact
    when the vertical forces are determined (e.g. three agents at ``z = 0``). A4-Inc minus any
    one agent: not capable, margin 0; A6-Inc minus one: capable, margin 0.4.

    Attributes:
        capable: rank-6 ``M``, the allocation produces the hover wrench, and ``margin`` exceeds
            ``sqrt(eps)``.
        margin: the certified margin (<= 0: a bound is touched or exceeded).
        limiting_agent: the agent whose slack is ``margin`` (None without working agents).
        limit: the bound it is closest to.
        weight: ``m_C g`` (N).
    """

    FIELDS: ClassVar[Tuple[str, ...]]

    @property
    def capable(self) -> bool:
        """The hover wrench is strictly inside the working agents' attainable set."""
    @property
    def margin(self) -> float:
        """Smallest normalized slack of any working agent in the certifying allocation."""
    @property
    def limiting_agent(self) -> Optional[int]:
        """The agent whose slack is ``margin``, or None."""
    @property
    def limit(self) -> Literal["max_thrust", "min_thrust", "gimbal_x", "gimbal_y"]:
        """The bound that agent is closest to."""
    @property
    def weight(self) -> float:
        """``m_C g`` (N)."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

@final
class LawStage:
    """The law stage of one period (``Controller.law_stage``; read-only).

    Attributes:
        planner: PlannerResult. projection: ForceProjection. f_r: (3,) inertial.
        law: LawOutput. wrench: (6,) ``u_d = [u_tau; u_f]`` (N m, N; body frame).
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def planner(self) -> PlannerResult:
        """The planner's result (eqs. 9-11)."""
    @property
    def projection(self) -> ForceProjection:
        """The force projection ``K_f`` (eqs. 12-13)."""
    @property
    def f_r(self) -> _F64:
        """(3,) ``t_Tf R u_fr`` (inertial)."""
    @property
    def law(self) -> LawOutput:
        """The control law's output (eq. 12)."""
    @property
    def wrench(self) -> _F64:
        """(6,) ``u_d = [u_tau; u_f]`` (N m, N; body frame): the wrench for ``allocate``."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict (nested records as dicts)."""

@final
class AllocationStage:
    """The allocation stage of one period (``Controller.allocate``; read-only).

    Attributes:
        allocation: Allocation (``e_f`` is the force error). torque_error: N m.
        commands: (n, 4). command_clamp: rad, or relative to the largest thrust. null_space: NullSpaceReport.
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def allocation(self) -> Allocation:
        """The allocation (eqs. 4 and 6)."""
    @property
    def torque_error(self) -> float:
        """``||u_tau_d - u_tau||`` (N m), the torque the team could not deliver."""
    @property
    def commands(self) -> _F64:
        """(n, 4) commands, columns ``eta_x, eta_y, thrust, omega``."""
    @property
    def command_clamp(self) -> float:
        """Largest clamp of the command inversion (rad, or relative to the largest thrust)."""
    @property
    def null_space(self) -> "NullSpaceReport":
        """What the null-space stage changed."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict (nested records as dicts)."""

@final
class StepOutput:
    """Everything one ``Controller.step`` computed, nested like the core's ``ControlOutput``
    (read-only; each access returns fresh arrays).

    Attributes:
        planner: PlannerResult (``R_d``, ``theta``, ``iterations``, ``status``).
        projection: ForceProjection (``force = K_f u_fr``, ``t_Tf``, ``t_eta``).
        f_r: (3,) ``t_Tf R u_fr``, the inertial force the planner aligns with.
        law: LawOutput (``e_x``, ``e_R``, ``e_xi``, ``u_r``, ``u_d``, ``V_R``, ``V_x``).
        allocation: Allocation (``forces``, ``wrench`` = ``M f``, ``e_f``, ``wrench_error``, ``rounds``,
            ``saturated``, ``fallback``, ``method``, ``report``).
        commands: (n, 4) columns ``eta_x, eta_y, thrust, omega`` (idle for failed agents).
        command_clamp: the largest clamp the command inversion applied (rad, or
            relative to the largest thrust).
        null_space: NullSpaceReport of the null-space stage (``ran`` False without one).
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def planner(self) -> PlannerResult:
        """The planner's result (eqs. 9-11)."""
    @property
    def projection(self) -> ForceProjection:
        """The force projection ``K_f`` (eqs. 12-13)."""
    @property
    def f_r(self) -> _F64:
        """(3,) ``t_Tf R u_fr`` (inertial)."""
    @property
    def law(self) -> LawOutput:
        """The control law's output (eq. 12)."""
    @property
    def allocation(self) -> Allocation:
        """The allocation (eqs. 4 and 6)."""
    @property
    def commands(self) -> _F64:
        """(n, 4) commands, columns ``eta_x, eta_y, thrust, omega``."""
    @property
    def command_clamp(self) -> float:
        """Largest clamp of the command inversion (rad, or relative to the largest thrust)."""
    @property
    def null_space(self) -> "NullSpaceReport":
        """What the null-space stage changed."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict (nested records as dicts)."""

@final
class NullSpaceReport:
    """What the null-space stage (``Controller(null_space=...)``, ``tvmd_core::NullSpaceStage``)
    changed in one period. Margins are the smallest normalized margin of any working agent to
    its admissible boundary (each gimbal and thrust limit as a fraction of its range: 0 on the
    boundary, 1 at the opposite end).

    Attributes:
        ran: the stage ran (configured, and the allocation was finite); False: all zero.
        iterations: accepted steps (0: the allocator's forces are unchanged).
        objective_before, objective_after: the objective (soft minimum of the margins for
            ``"margin"``, mean cos to the tilt target for ``"inward-tilt"``); never lower after.
        margin_before, margin_after: the smallest normalized margin before and after.
        largest_force_change: largest change of one agent's force (N).
        wrench_drift: ``||M f' - M f||``, the wrench the stage moved (round-off).
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def ran(self) -> bool:
        """The stage ran on this period's allocation."""
    @property
    def iterations(self) -> int:
        """Accepted steps (0: the allocator's forces unchanged)."""
    @property
    def objective_before(self) -> float:
        """The objective at the allocator's forces."""
    @property
    def objective_after(self) -> float:
        """The objective at the returned forces."""
    @property
    def margin_before(self) -> float:
        """Smallest normalized margin to the admissible boundary at the allocator's forces."""
    @property
    def margin_after(self) -> float:
        """The same at the returned forces."""
    @property
    def largest_force_change(self) -> float:
        """Largest change of one agent's force (N)."""
    @property
    def wrench_drift(self) -> float:
        """``||M f' - M f||``, the wrench the stage moved (round-off)."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""
