"""tvmd: full-pose tracking control for over-actuated thrust-vectoring modular team UAVs.

Python bindings of the Rust crate ``tvmd-core`` (after Chu, Fang and Lian, *Attainable Force
Approximation and Full-Pose Tracking Control of an Over-Actuated Thrust-Vectoring Modular Team
UAV*). Equation numbers refer to the paper.

* :class:`Team` -- the configuration ``Xi`` (positions, quarter turns ``m_i``, masses, limits),
  presets ``Team.a4_inc()``, ``Team.a4_con()``, ``Team.ring(...)``, the authors' catalogue
  ``Team.preset(name)``; ``M(Xi)`` (eq. 4).
* :class:`AttainableForceSpace` -- the AFS approximation (eqs. 7-8) and the projection ``K_f``
  (eqs. 12-13); :func:`gimbal_force` / :func:`gimbal_inverse` (eq. 1).
* :class:`AttitudePlanner` -- the bisection planner (eqs. 9-11).
* :class:`Gains`, :class:`State`, :class:`Reference`, :class:`Plant`, :func:`force_request`,
  :func:`control_wrench` -- the control law (eq. 12).
* :func:`afs_atlas` -- the exact attainable force set against the cone, and the certified
  relaxation ``s*`` (docs/afs-atlas.md).
* :func:`allocate` -- the allocators (exact-boundary redistribution, the default; redistributed,
  pseudo-inverse, weighted, Clarabel).
* :class:`Controller` -- one ``step`` per control period, returning a :class:`StepOutput`
  (``out.planner``, ``out.projection``, ``out.law``, ``out.allocation``, ``out.commands``);
  by default with the offset-free law (``law="offset-free"``: natural gains, a disturbance
  observer, the planned attitude's rates), ``law="paper"`` for the paper's eq. (12).
* :mod:`tvmd.sim` -- the simulator ``tvmd-sim`` (the paper's simulation, relaxation study).
* :mod:`tvmd.gym` -- Gymnasium environments of the simulator (``import tvmd.gym``; needs
  ``gymnasium``): ``"tvmd/Hover-v0"``, a body wrench or per-agent commands as the action.

Arrays are float64 NumPy arrays, SI units, z up, twist ``xi = [Omega; v]`` in the body frame,
wrenches ``[torque; force]``. Errors: ``ValueError`` (wrong shapes, NaN/inf; the subclasses
:class:`ConfigError`, :class:`InputError`, :class:`CycleError` carry the core's messages) and
``TypeError`` (wrong types).
"""

from ._tvmd import (
    ALLOCATORS,
    CAPACITY,
    GRAVITY,
    HAS_CLARABEL,
    Allocation,
    AllocationStage,
    AttainableForceSpace,
    AttitudePlanner,
    ConfigError,
    Controller,
    CycleError,
    ForceProjection,
    Gains,
    HoverCapability,
    InputError,
    LawOutput,
    LawStage,
    NullSpaceReport,
    PlannerResult,
    Plant,
    Reference,
    State,
    StepOutput,
    Team,
    __version__,
    afs_atlas,
    allocate,
    control_wrench,
    force_request,
    gimbal_force,
    gimbal_inverse,
    thrust_direction,
)
from . import sim  # the submodule tvmd.sim (not in __all__)

__all__ = [
    "ALLOCATORS",
    "CAPACITY",
    "GRAVITY",
    "HAS_CLARABEL",
    "Allocation",
    "AllocationStage",
    "AttainableForceSpace",
    "AttitudePlanner",
    "ConfigError",
    "Controller",
    "CycleError",
    "ForceProjection",
    "Gains",
    "HoverCapability",
    "InputError",
    "LawOutput",
    "LawStage",
    "NullSpaceReport",
    "PlannerResult",
    "Plant",
    "Reference",
    "State",
    "StepOutput",
    "Team",
    "__version__",
    "afs_atlas",
    "allocate",
    "control_wrench",
    "force_request",
    "gimbal_force",
    "gimbal_inverse",
    "thrust_direction",
]
