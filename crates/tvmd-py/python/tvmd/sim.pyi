"""Type stubs of ``tvmd.sim`` (the submodule ``tvmd._tvmd.sim``: PyO3 bindings of ``tvmd-sim``).

Time series are fresh NumPy arrays with ``K`` samples (one per controller tick) and ``n``
agents; SI units, z up, angles in rad. Values the controller did not report are NaN.
"""

import os
from typing import Any, ClassVar, Iterable, Mapping, Optional, Tuple, Union, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._tvmd import AllocatorName

_F64 = NDArray[np.float64]
_ScenarioArg = Union[str, "os.PathLike[str]"]
_PathArg = Union[str, "os.PathLike[str]"]
_RunItem = Union[str, "os.PathLike[str]", Mapping[str, Any]]

@final
class SimResult:
    """One simulated run: time series (NumPy) and the summary dicts."""

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def scenario_name(self) -> str:
        """Name of the scenario that ran."""
    @property
    def relaxation(self) -> float:
        """Planner relaxation ``s`` of the run."""
    @property
    def allocator(self) -> AllocatorName:
        """Allocator of the run."""
    @property
    def mcap_path(self) -> Optional[str]:
        """Path of the MCAP log written, or None."""
    @property
    def n_agents(self) -> int:
        """Number of agents ``n``."""
    @property
    def mass(self) -> Optional[float]:
        """Team mass ``m_C`` (kg)."""
    @property
    def gravity(self) -> float:
        """Gravity ``g`` (m/s^2)."""
    @property
    def hover_roll_limit(self) -> Optional[float]:
        """``atan(c_y(1, s))`` (rad), the planned roll at which the planner saturates in hover."""
    @property
    def t(self) -> _F64:
        """(K,) time (s)."""
    @property
    def position(self) -> _F64:
        """(K, 3) ``x`` (m)."""
    @property
    def velocity(self) -> _F64:
        """(K, 3) ``x_dot`` (m/s)."""
    @property
    def reference_position(self) -> _F64:
        """(K, 3) ``x_r`` (m)."""
    @property
    def attitude_rpy(self) -> _F64:
        """(K, 3) roll, pitch, yaw of ``R`` (rad, ZYX)."""
    @property
    def reference_rpy(self) -> _F64:
        """(K, 3) roll, pitch, yaw of ``R_r`` (rad)."""
    @property
    def reference_roll(self) -> _F64:
        """(K,) ``phi_r`` (rad)."""
    @property
    def planned_roll(self) -> _F64:
        """(K,) ``phi_d`` of the planned ``R_d`` (rad)."""
    @property
    def planned_rpy(self) -> _F64:
        """(K, 3) roll, pitch, yaw of ``R_d`` (rad)."""
    @property
    def attitude_error(self) -> _F64:
        """(K,) angle between ``R`` and ``R_d`` (rad)."""
    @property
    def theta(self) -> _F64:
        """(K,) planner angle ``theta*`` (rad)."""
    @property
    def e_f(self) -> _F64:
        """(K,) allocation error ``||u_fd - u_f||`` (N)."""
    @property
    def saturated_agents(self) -> NDArray[np.int64]:
        """(K,) agents the allocator saturated (-1: not reported)."""
    @property
    def V_x(self) -> _F64:
        """(K,) Lyapunov candidate ``V_x``."""
    @property
    def V_R(self) -> _F64:
        """(K,) Lyapunov candidate ``V_R``."""
    @property
    def cycle_error(self) -> NDArray[np.bool_]:
        """(K,) the controller skipped the cycle."""
    @property
    def commands(self) -> _F64:
        """(K, n, 3) commanded ``eta_x``, ``eta_y`` (rad), ``thrust`` (N)."""
    @property
    def actual(self) -> _F64:
        """(K, n, 3) actual actuator outputs, same columns."""
    @property
    def failed(self) -> NDArray[np.bool_]:
        """(K, n) true failure flags."""
    @property
    def summary(self) -> dict[str, Any]:
        """Every field of tvmd-sim's ``RunSummary``."""
    @property
    def paper_metrics(self) -> dict[str, Any]:
        """tvmd-sim's ``PaperMetrics``."""
    @property
    def scenario_toml(self) -> str:
        """The scenario that ran, as TOML."""
    def to_dict(self) -> dict[str, Any]:
        """Every field as a dict."""
    def __len__(self) -> int:
        """The number of samples ``K``."""

def builtin_scenarios() -> list[str]:
    """The names of the built-in scenarios."""

def scenario_toml(name: str) -> str:
    """A built-in scenario as TOML text (every field)."""

def run(
    scenario: Optional[_ScenarioArg] = None,
    *,
    toml: Optional[str] = None,
    mcap: Optional[_PathArg] = None,
    relaxation: Optional[float] = None,
    allocator: Optional[AllocatorName] = None,
) -> SimResult:
    """Runs one scenario with the tvmd controller in the loop (GIL released)."""

def run_many(runs: Iterable[_RunItem], *, jobs: Optional[int] = None) -> list[SimResult]:
    """Runs many scenarios on parallel threads; results in input order."""

def relaxation_sweep(
    relaxations: Optional[ArrayLike] = None,
    scenario: Optional[_ScenarioArg] = None,
    *,
    toml: Optional[str] = None,
    allocator: Optional[AllocatorName] = None,
    mcap_dir: Optional[_PathArg] = None,
    jobs: Optional[int] = None,
) -> list[SimResult]:
    """The relaxation study: one scenario flown once per ``s``; results in input order."""


__all__ = [
    "SimResult",
    "builtin_scenarios",
    "relaxation_sweep",
    "run",
    "run_many",
    "scenario_toml",
]
