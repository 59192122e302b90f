"""tvmd.sim: the simulator ``tvmd-sim`` with the tvmd controller in the loop.

The team is one rapier3d rigid body (agents as point masses), stepped at ``physics.dt``; the
controller (``tvmd_core::Controller``) runs every ``controller_period`` with a zero-order hold.
Scenarios are TOML (every field defaults to the paper's simulation, ``"paper-tilt"``: A4-Inc,
ascent to 1.5 m, roll tilt towards the infeasible ``pi/3``, descent; ``s = 0.5``).

* :func:`builtin_scenarios`, :func:`scenario_toml` -- the built-in scenarios.
* :func:`run` -- one run (GIL released) -> :class:`SimResult` (NumPy time series and the
  summary dicts), optionally writing an MCAP log.
* :func:`run_many`, :func:`relaxation_sweep` -- many runs in parallel threads.

Errors: ``ValueError`` (unknown scenario, bad TOML or field, bad override; the message names the
field), ``TypeError``, ``OSError`` (scenario file, log), ``RuntimeError`` (the run failed).
"""

from ._tvmd import sim as _sim

SimResult = _sim.SimResult
builtin_scenarios = _sim.builtin_scenarios
relaxation_sweep = _sim.relaxation_sweep
run = _sim.run
run_many = _sim.run_many
scenario_toml = _sim.scenario_toml

__all__ = [
    "SimResult",
    "builtin_scenarios",
    "relaxation_sweep",
    "run",
    "run_many",
    "scenario_toml",
]
