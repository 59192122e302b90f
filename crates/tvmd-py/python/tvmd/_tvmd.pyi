"""Type stubs of the extension module ``tvmd._tvmd`` (PyO3 bindings of ``tvmd-core``).

Array arguments accept any real array-like (read as float64); returned arrays are fresh
float64 (or bool / int64) NumPy arrays. Shapes are given in the docstrings. Checked against the
built module by ``mypy.stubtest`` (``tests/test_stubs.py``).
"""

from typing import Any, ClassVar, Iterable, Literal, Mapping, Optional, Tuple, Union, final, overload

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

AllocatorName = Literal[
    "pseudo-inverse", "weighted-pseudo-inverse", "redistributed-pseudo-inverse", "clarabel"
]
"""The allocators (``"clarabel"`` only with the cargo feature, see ``ALLOCATORS``)."""
PlannerStatus = Literal["already-feasible", "planned", "zero-force", "unreachable"]
"""How the attitude planner reached its output."""
Arrangement = Literal["Con", "Inc"]
"""Consistent (every gimbal axis aligned with the team's) or inconsistent team."""

class ConfigError(ValueError):
    """A team, limit, gain, setting or failure mask that cannot be used."""

    field: Optional[str]

class InputError(ValueError):
    """A control-cycle input that cannot be used: not finite, or not a rotation."""

class CycleError(InputError):
    """``Controller.step`` rejected its input; ``commands`` (n, 4) are the commands to hold."""

    commands: _F64
    field: str

@final
class Team:
    """The team configuration ``Xi`` (eqs. 3-6), up to 64 agents."""

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
        """A team whose maximum thrust follows from the rotor constants of eq. (5)."""
    @staticmethod
    def a4_inc() -> "Team":
        """The paper's simulated team "A4 inc, 1 navigator"."""
    @staticmethod
    def a4_con() -> "Team":
        """As ``a4_inc()`` with every agent aligned: the consistent A4 team."""
    @staticmethod
    def ring(
        n: int,
        radius: float,
        inconsistent: bool,
        sigma_x: float = ...,
        sigma_y: float = ...,
        max_thrust: float = ...,
    ) -> "Team":
        """``n`` agents of 0.7 kg on a circle of ``radius`` (m)."""
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
        """``M(Xi)`` (6, 3n) of eq. (4); columns of failed agents are zero."""
    def wrench(self, forces: ArrayLike, failed: _Failed = None) -> _F64:
        """``u = M(Xi) f`` (6,) of the (n, 3) agent-frame forces."""
    def afs(self, failed: _Failed = None) -> "AttainableForceSpace":
        """The AFS approximation (eqs. 7-8) of the working agents."""
    def plant(self, gravity: float = ...) -> "Plant":
        """The rigid-body parameters of the control law."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

@final
class AttainableForceSpace:
    """The elliptic-cone AFS approximation (eqs. 7-8)."""

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
        """The semi-axes ``(c_x, c_y)`` of eq. (8) at height ``z`` (relaxation default 1)."""
    @overload
    def semi_axes(
        self, z: ArrayLike, relaxation: Optional[float] = None, *, s: Optional[float] = None
    ) -> Tuple[Any, Any]:
        """The semi-axes for an array of heights."""
    def quadratic_form(
        self, u: ArrayLike, relaxation: Optional[float] = None, *, s: Optional[float] = None
    ) -> Any:
        """``u^T C(u_z) u`` (eq. 7): a float for (3,), an (N,) array for (N, 3)."""
    def contains(
        self, u: ArrayLike, relaxation: Optional[float] = None, *, s: Optional[float] = None
    ) -> Any:
        """Membership in the AFS (eq. 7): a bool for (3,), an (N,) bool array for (N, 3)."""
    def project(self, u: ArrayLike) -> Tuple[_F64, Any, Any]:
        """``(K_f u, t_Tf, t_eta)`` of eqs. (12)-(13)."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

@final
class ForceProjection:
    """The force projection ``K_f`` of eqs. (12)-(13)."""

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
    """``f = T a_hat(eta_x, eta_y)`` (eqs. 1 and 5), broadcast like NumPy."""

def thrust_direction(eta_x: ArrayLike, eta_y: ArrayLike) -> _F64:
    """``a_hat(eta_x, eta_y)`` of eq. (1)."""

def gimbal_inverse(force: ArrayLike) -> Tuple[Any, Any, Any]:
    """``(eta_x, eta_y, thrust)`` of agent-frame force(s)."""

@final
class AttitudePlanner:
    """The bisection attitude planner (eqs. 9-11)."""

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
        """Plans ``R_d`` for ``R_r`` and the inertial force request ``f_r`` (eq. 9)."""

@final
class PlannerResult:
    """The planner's output."""

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
    """Gains ``K_x``, ``K_R``, ``K_xi = blockdiag(K_Omega, K_v)`` of eq. (12)."""

    FIELDS: ClassVar[Tuple[str, ...]]

    def __new__(cls, k_x: ArrayLike, k_r: ArrayLike, k_xi: ArrayLike) -> "Gains": ...
    @staticmethod
    def paper() -> "Gains":
        """The paper's gains."""
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
    """The measured state (pose and body-frame twist)."""

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
    """The reference pose and its derivatives."""

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
    """Rigid-body parameters ``m_C``, ``J_C`` and gravity ``g``."""

    FIELDS: ClassVar[Tuple[str, ...]]

    def __new__(cls, mass: float, inertia: ArrayLike, gravity: float = ...) -> "Plant": ...
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
    """Everything the control law computes in one period."""

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
    """``u_fr`` (3,), the force part of ``u_r`` (eq. 12)."""

def control_wrench(
    plant: Plant,
    gains: Gains,
    state: _StateLike,
    reference: _ReferenceLike,
    R_d: ArrayLike,
    u_fr: ArrayLike,
    K_f: ArrayLike,
) -> LawOutput:
    """The torque part of eq. (12) with the planned ``R_d``, and ``u_r``, ``u_d``."""

@final
class Allocation:
    """The result of one allocation."""

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
        """Clarabel's solve report, None otherwise."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""

def allocate(
    team: Team,
    wrench: ArrayLike,
    method: AllocatorName = "redistributed-pseudo-inverse",
    weights: Optional[ArrayLike] = None,
    failed: _Failed = None,
    previous: Optional[ArrayLike] = None,
    rate_limits: Optional[ArrayLike] = None,
    dt: Optional[float] = None,
    regularization: Optional[float] = None,
) -> Allocation:
    """Allocates a desired wrench ``u_d`` over the working agents (eqs. 4 and 6)."""

@final
class Controller:
    """The full-pose controller: one ``step`` per control period."""

    def __new__(
        cls,
        team: Team,
        gains: Optional[Gains] = None,
        relaxation: Optional[float] = None,
        gravity: float = ...,
        period: float = 0.01,
        allocator: AllocatorName = "redistributed-pseudo-inverse",
        rate_limits: Optional[ArrayLike] = None,
        failed: _Failed = None,
        weights: Optional[ArrayLike] = None,
        regularization: Optional[float] = None,
        planner_tolerance: Optional[float] = None,
        planner_max_iterations: Optional[int] = None,
        *,
        s: Optional[float] = None,
    ) -> "Controller": ...
    def set_failures(self, failed: _Failed = None) -> None:
        """Marks agents failed (None or [] for none)."""
    def reset(self) -> None:
        """Forgets the previous command."""
    def step(self, state: _StateLike, reference: _ReferenceLike) -> "StepOutput":
        """One control period."""
    @property
    def team(self) -> Team:
        """The team."""
    @property
    def gains(self) -> Gains:
        """The gains."""
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
    def failed(self) -> list[int]:
        """Indices of the failed agents."""
    @property
    def afs(self) -> AttainableForceSpace:
        """The AFS of the working agents."""
    @property
    def previous_commands(self) -> _F64:
        """(n, 4) previous period's commands."""

@final
class StepOutput:
    """Everything one ``Controller.step`` computed, nested like the core's ``ControlOutput``."""

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
        """Largest clamp of the command inversion (normalized)."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict (nested records as dicts)."""
