"""Type stubs of ``tvmd.sim`` (the submodule ``tvmd._tvmd.sim``: PyO3 bindings of ``tvmd-sim``).

Time series are fresh NumPy arrays with ``K`` samples (one per controller tick) and ``n``
agents; SI units, z up, angles in rad. Values the controller did not report are NaN.
"""

import os
from typing import Any, Iterable, Mapping, Optional, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

F64 = NDArray[np.float64]
ScenarioArg = Union[str, "os.PathLike[str]"]
PathArg = Union[str, "os.PathLike[str]"]
RunItem = Union[str, "os.PathLike[str]", Mapping[str, Any]]

class SimResult:
    """One simulated run: time series (NumPy) and the summary dicts."""

    FIELDS: Tuple[str, ...]
    @property
    def scenario_name(self) -> str: ...
    @property
    def relaxation(self) -> float: ...
    @property
    def allocator(self) -> str: ...
    @property
    def mcap_path(self) -> Optional[str]: ...
    @property
    def n_agents(self) -> int: ...
    @property
    def mass(self) -> Optional[float]: ...
    @property
    def gravity(self) -> float: ...
    @property
    def hover_roll_limit(self) -> Optional[float]: ...
    @property
    def t(self) -> F64:
        """(K,) time (s)."""
    @property
    def position(self) -> F64:
        """(K, 3) ``x`` (m)."""
    @property
    def velocity(self) -> F64:
        """(K, 3) ``x_dot`` (m/s)."""
    @property
    def reference_position(self) -> F64:
        """(K, 3) ``x_r`` (m)."""
    @property
    def attitude_rpy(self) -> F64:
        """(K, 3) roll, pitch, yaw of ``R`` (rad, ZYX)."""
    @property
    def reference_rpy(self) -> F64:
        """(K, 3) roll, pitch, yaw of ``R_r`` (rad)."""
    @property
    def reference_roll(self) -> F64:
        """(K,) ``phi_r`` (rad)."""
    @property
    def planned_roll(self) -> F64:
        """(K,) ``phi_d`` of the planned ``R_d`` (rad)."""
    @property
    def planned_rpy(self) -> F64:
        """(K, 3) roll, pitch, yaw of ``R_d`` (rad)."""
    @property
    def attitude_error(self) -> F64:
        """(K,) angle between ``R`` and ``R_d`` (rad)."""
    @property
    def theta(self) -> F64:
        """(K,) planner angle ``theta*`` (rad)."""
    @property
    def e_f(self) -> F64:
        """(K,) allocation error ``||u_fd - u_f||`` (N)."""
    @property
    def saturated_agents(self) -> NDArray[np.int64]:
        """(K,) agents the allocator saturated (-1: not reported)."""
    @property
    def V_x(self) -> F64:
        """(K,) Lyapunov candidate ``V_x``."""
    @property
    def V_R(self) -> F64:
        """(K,) Lyapunov candidate ``V_R``."""
    @property
    def cycle_error(self) -> NDArray[np.bool_]:
        """(K,) the controller skipped the cycle."""
    @property
    def commands(self) -> F64:
        """(K, n, 3) commanded ``eta_x``, ``eta_y`` (rad), ``thrust`` (N)."""
    @property
    def actual(self) -> F64:
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
    def to_dict(self) -> dict[str, Any]: ...
    def __len__(self) -> int: ...

def builtin_scenarios() -> list[str]: ...
def scenario_toml(name: str) -> str: ...
def run(
    scenario: Optional[ScenarioArg] = None,
    *,
    toml: Optional[str] = None,
    mcap: Optional[PathArg] = None,
    relaxation: Optional[float] = None,
    allocator: Optional[str] = None,
) -> SimResult: ...
def run_many(runs: Iterable[RunItem], *, jobs: Optional[int] = None) -> list[SimResult]: ...
def relaxation_sweep(
    relaxations: Optional[ArrayLike] = None,
    scenario: Optional[ScenarioArg] = None,
    *,
    toml: Optional[str] = None,
    allocator: Optional[str] = None,
    mcap_dir: Optional[PathArg] = None,
    jobs: Optional[int] = None,
) -> list[SimResult]: ...

__all__ = [
    "SimResult",
    "builtin_scenarios",
    "relaxation_sweep",
    "run",
    "run_many",
    "scenario_toml",
]
