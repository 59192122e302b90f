"""tvmd.sim: the simulator ``tvmd-sim`` with the tvmd controller in the loop.

The team is one rapier3d rigid body (agents as point masses), stepped at ``physics.dt``; the
controller (``tvmd_core::Controller``) runs every ``controller_period`` with a zero-order hold.
Scenarios are TOML (every field defaults to the paper's simulation, ``"paper-tilt"``: A4-Inc,
ascent to 1.5 m, roll tilt towards the infeasible ``pi/3``, descent; ``s = 0.5``).

* :func:`builtin_scenarios`, :func:`scenario_toml` -- the built-in scenarios.
* :class:`Simulation` -- the simulator stepped one controller period at a time with your own
  controller: ``reset``, ``step`` (per-agent commands), ``step_wrench`` (a body wrench through
  tvmd's allocation), each returning the next :class:`Observation`; :class:`ScenarioController`
  is the tvmd controller as :func:`run` flies it, for the same steps.
* :func:`run` -- one run (GIL released) -> :class:`SimResult` (NumPy time series and the
  summary dicts), optionally writing an MCAP log.
* :func:`load` -- a run read back from its MCAP log, as the :class:`SimResult` it returned.
* :func:`run_many`, :func:`relaxation_sweep` -- many runs in parallel threads, or one task per
  run on any ``concurrent.futures.Executor`` (``executor=``; results pickle back).
* :func:`monte_carlo` -- a Monte Carlo study (model errors and initial conditions drawn per
  flight) on threads or on any ``concurrent.futures.Executor`` (a process pool, a Dask
  cluster's ``client.get_executor()``); the results equal for the same seed wherever they fly.

Errors: ``ValueError`` (unknown scenario, bad TOML or field, bad override; the message names the
field), ``TypeError``, ``OSError`` (scenario file, log), ``RuntimeError`` (the run failed).
"""

from ._tvmd import sim as _sim

monte_carlo_specs = _sim.monte_carlo_specs
monte_carlo_flight = _sim.monte_carlo_flight
monte_carlo_fly = _sim.monte_carlo_fly
monte_carlo_report = _sim.monte_carlo_report


def _fly(spec):
    # Module-level, so executors pickle it by reference (``tvmd.sim._fly``) to their workers.
    return _sim.monte_carlo_flight(spec)


def monte_carlo(
    scenario=None,
    *,
    toml=None,
    runs=100,
    seed=0,
    teams=None,
    allocators=None,
    model_errors=None,
    distributions=None,
    law=None,
    out=None,
    jobs=None,
    executor=None,
):
    """A Monte Carlo study of ``runs`` flights (the full docstring is the stub's, below)."""
    specs = _sim.monte_carlo_specs(
        scenario,
        toml=toml,
        runs=runs,
        seed=seed,
        teams=teams,
        allocators=allocators,
        model_errors=model_errors,
        distributions=distributions,
        law=law,
    )
    if out is not None:
        # Checked before any flight: a bad `out` must not cost the study.
        _sim._check_report_dir(out)
    if executor is None:
        try:
            rows = _sim.monte_carlo_fly(specs, jobs=jobs)
        except KeyboardInterrupt as e:
            # Ctrl-C: the finished flights' report travels with the exception, marked partial.
            finished = getattr(e, "partial", None)
            if finished is not None:
                report = _sim.monte_carlo_report(finished)
                report["interrupted"] = True
                report["flights_asked"] = len(specs)
                e.partial = report
            raise
    else:
        if jobs is not None:
            raise ValueError("give `jobs` (threads here) or `executor`, not both")
        _check_executor(executor)
        rows = list(executor.map(_fly, specs))
    return _sim.monte_carlo_report(rows, out=out)


SimResult = _sim.SimResult
Simulation = _sim.Simulation
SimulationBatch = _sim.SimulationBatch
Observation = _sim.Observation
ScenarioController = _sim.ScenarioController
ControllerOutput = _sim.ControllerOutput
builtin_scenarios = _sim.builtin_scenarios
run = _sim.run
load = _sim.load
scenario_toml = _sim.scenario_toml
# `SimResult.__reduce__` names it here: an executor's worker sends its result back pickled.
_sim_result_from_state = _sim._sim_result_from_state


# The flat columns of ``SimResult.to_columns``: the suffixes of the fields whose last axis is not
# x, y, z, and the fields with one entry (or one row) per agent.
_XYZ = ("x", "y", "z")
_RPY = ("roll", "pitch", "yaw")
_ACTUATOR = ("eta_x", "eta_y", "thrust")
_SUFFIXES = {"attitude_rpy": _RPY, "reference_rpy": _RPY, "planned_rpy": _RPY, "commands": _ACTUATOR, "actual": _ACTUATOR}
_PER_AGENT = {"failed", "rotor_speeds", "commands", "actual", "forces"}
# ``velocity`` is ``velocity_world`` under its old name: one column.
_ALIASES = {"velocity"}


def _columns(result):
    # ``SimResult.to_columns``: every (K, ...) array field as (K,) columns, in field order.
    import numpy as np

    columns = {}
    k = len(result)
    for name in result.FIELDS:
        if name in _ALIASES:
            continue
        value = getattr(result, name)
        if not isinstance(value, np.ndarray) or value.ndim == 0 or value.shape[0] != k:
            continue
        if value.ndim == 1:
            columns[name] = value
        elif name in _PER_AGENT:
            for i in range(value.shape[1]):
                if value.ndim == 2:
                    columns[f"{name}_{i}"] = value[:, i]
                else:
                    for j, suffix in enumerate(_SUFFIXES.get(name, _XYZ)):
                        columns[f"{name}_{i}_{suffix}"] = value[:, i, j]
        elif value.ndim == 2:
            for j, suffix in enumerate(_SUFFIXES.get(name, _XYZ)):
                columns[f"{name}_{suffix}"] = value[:, j]
        else:
            for r in range(value.shape[1]):
                for c in range(value.shape[2]):
                    columns[f"{name}_{r}{c}"] = value[:, r, c]
    return columns


def _to_pandas(result):
    # ``SimResult.to_pandas``: pandas is imported only here (an optional dependency).
    try:
        import pandas
    except ImportError as e:
        raise ImportError("SimResult.to_pandas needs pandas (pip install pandas); to_columns() does not") from e
    return pandas.DataFrame(_columns(result))


def _run_one(item, index):
    # Module-level, so executors pickle it by reference (``tvmd.sim._run_one``). A failure
    # names ``runs[index]``, as the threads do.
    return _sim._run_item(item, index)


def _run_swept(item, index):
    # As ``_run_one`` for a relaxation study's run: a failure names its ``s``, as the threads do.
    return _sim._run_item(item, index, sweep=True)


def _check_executor(executor):
    # A TypeError naming the argument, not an AttributeError from inside (hostile suite).
    if not callable(getattr(executor, "map", None)):
        raise TypeError(
            f"`executor` must be a concurrent.futures.Executor (with `map`), got {type(executor).__name__}"
        )


def _on_executor(items, jobs, executor, fly):
    if jobs is not None:
        raise ValueError("give `jobs` (threads here) or `executor`, not both")
    _check_executor(executor)
    return list(executor.map(fly, items, range(len(items))))


def _run_one_keeping(item, index):
    # ``_run_one`` for ``errors="keep"``: the exception comes back in the result's place.
    try:
        return _sim._run_item(item, index)
    except Exception as e:  # noqa: BLE001 - every failure of one run is kept, by its index
        return e


def run_many(runs, *, jobs=None, executor=None, errors="raise"):
    """Many runs in parallel, results in input order (the full docstring is the stub's, below)."""
    if errors not in ("raise", "keep"):
        raise ValueError(f'`errors` must be "raise" or "keep", got {errors!r}')
    if executor is None:
        return _sim.run_many(runs, jobs=jobs, errors=errors)
    items = runs if isinstance(runs, (str, dict)) else list(runs)
    if errors == "raise":
        _sim._check_runs(items)
        return _on_executor(items, jobs, executor, _run_one)
    return _on_executor(items, jobs, executor, _run_one_keeping)


def relaxation_sweep(
    relaxations=None,
    scenario=None,
    *,
    toml=None,
    allocator=None,
    precision=None,
    mcap_dir=None,
    jobs=None,
    pil=None,
    max_samples=None,
    executor=None,
):
    """The paper's relaxation study (the full docstring is the stub's, below)."""
    kw = dict(
        toml=toml,
        allocator=allocator,
        precision=precision,
        mcap_dir=mcap_dir,
        pil=pil,
        max_samples=max_samples,
    )
    if executor is None:
        return _sim.relaxation_sweep(relaxations, scenario, jobs=jobs, **kw)
    items = _sim._relaxation_sweep_runs(relaxations, scenario, **kw)
    return _on_executor(items, jobs, executor, _run_swept)

def _docs_from_stub(*functions):
    # One source: these Python functions show the docstrings of ``sim.pyi`` (shipped beside this
    # file) in ``help()``, as the Rust callables do (scripts/stub_docs.py). The longest
    # overload's docstring is the full one.
    import ast
    from pathlib import Path

    try:
        tree = ast.parse(Path(__file__).with_name("sim.pyi").read_text())
    except OSError:
        return
    docs = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            doc = ast.get_docstring(node) or ""
            if len(doc) > len(docs.get(node.name, "")):
                docs[node.name] = doc
    for f in functions:
        f.__doc__ = docs.get(f.__name__) or f.__doc__


_docs_from_stub(monte_carlo, run_many, relaxation_sweep)

__all__ = [
    "ControllerOutput",
    "Observation",
    "ScenarioController",
    "SimResult",
    "Simulation",
    "SimulationBatch",
    "builtin_scenarios",
    "load",
    "monte_carlo",
    "monte_carlo_flight",
    "monte_carlo_fly",
    "monte_carlo_report",
    "monte_carlo_specs",
    "relaxation_sweep",
    "run",
    "run_many",
    "scenario_toml",
]
