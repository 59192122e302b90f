"""Arguments at the binding layer (issue 43): integer ranges, the defaults that ``inspect`` and
``help()`` show, and errors that name the argument (or the batch item) they are about.

* Every integer argument of every public callable, out of its range (negative, beyond 64 bits,
  beyond 128 bits), raises ``ValueError`` naming the argument and its valid range, never
  ``OverflowError`` with a message of the binding's internals.
* No public callable shows ``Ellipsis`` as a default; the defaults shown are the ones used
  (passing them back gives the same result).
* ``run_many`` / ``relaxation_sweep`` on an executor name the failing item as the threads do.
"""

from __future__ import annotations

import inspect
import math
import os
import re
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import tvmd
import tvmd.sim as sim

A4 = tvmd.Team.a4_inc()
SHORT = "duration = 1.0\n"
BIG = 2**200  # beyond every Rust integer type

# ---------------------------------------------------------------------------
# Integer arguments (issue 43, item 8)
# ---------------------------------------------------------------------------

U64 = r">= 0 and <= 2\*\*64 - 1"
U32_ITER = r">= 1 and <= 2\*\*32 - 1"
U32_ROUNDS = r">= 0 and <= 2\*\*32 - 1"
JOBS = r">= 1 and <= 2\*\*64 - 1"

# (call taking the bad value, the argument's name as the message gives it, its range)
INTEGER_ARGUMENTS = [
    (lambda v: sim.monte_carlo("hover", runs=2, seed=v), "seed", U64),
    (lambda v: sim.monte_carlo_specs("hover", runs=v), "runs", JOBS),
    (lambda v: sim.monte_carlo(toml=SHORT, runs=1, jobs=v), "jobs", JOBS),
    (lambda v: sim.monte_carlo_fly([], jobs=v), "jobs", JOBS),
    (lambda v: sim.run("hover", max_samples=v), "max_samples", U64),
    (lambda v: sim.run_many(["hover"], jobs=v), "jobs", JOBS),
    (lambda v: sim.run_many([{"scenario": "hover", "max_samples": v}]), r"runs\[0\]\['max_samples'\]", U64),
    (lambda v: sim.relaxation_sweep([0.5], "hover", jobs=v), "jobs", JOBS),
    (lambda v: sim.relaxation_sweep([0.5], "hover", max_samples=v), "max_samples", U64),
    (lambda v: tvmd.Controller(A4, planner_max_iterations=v), "planner_max_iterations", U32_ITER),
    (lambda v: tvmd.Controller(A4, max_rounds=v), "max_rounds", U32_ROUNDS),
    (lambda v: tvmd.allocate(A4, np.zeros(6), max_rounds=v), "max_rounds", U32_ROUNDS),
    (lambda v: tvmd.AttitudePlanner(0.5, max_iterations=v), "max_iterations", U32_ITER),
    (lambda v: tvmd.AttainableForceSpace(v, 0, 0.5, 0.5, 10.0), "n", U64),
    (lambda v: tvmd.AttainableForceSpace(4, v, 0.5, 0.5, 10.0), "n_x", U64),
    (lambda v: tvmd.Team.ring(v, 1.0, True), "n", U64),
    (lambda v: tvmd.afs_atlas("a4-inc", directions=v), "directions", ">= 4 and <= 3600"),
    (lambda v: tvmd.afs_atlas("a4-inc", certify_heights=v), "certify_heights", ">= 2 and <= 200"),
    (lambda v: tvmd.afs_atlas("a4-inc", failed=[v]), "failed", U64),
]  # fmt: skip
IDS = [f"{k}-{name}" for k, (_, name, _) in enumerate(INTEGER_ARGUMENTS)]


@pytest.mark.parametrize("value", [-1, 2**70, -(2**70), 10**20, BIG, -BIG])
@pytest.mark.parametrize("call, name, valid", INTEGER_ARGUMENTS, ids=IDS)
def test_out_of_range_integers_raise_value_error_naming_argument_and_range(call, name, valid, value):
    with pytest.raises(ValueError) as info:
        call(value)
    assert not isinstance(info.value, OverflowError)
    message = str(info.value)
    assert re.search(rf"`{name}` must be {valid}, got {value}$", message), message


@pytest.mark.parametrize(
    "call",
    [
        lambda: sim.monte_carlo("hover", runs=2, seed=-1),
        lambda: sim.run("hover", max_samples=2**70),
        lambda: tvmd.Controller(A4, planner_max_iterations=10**20),
    ],
    ids=["seed", "max_samples", "planner_max_iterations"],
)
def test_issue_examples_are_value_errors(call):
    with pytest.raises(ValueError, match="must be >="):
        call()


def test_failure_indices_beyond_64_bits_are_config_errors():
    with pytest.raises(tvmd.ConfigError, match=f"agent {2**70},"):
        A4.effectiveness(failed=[2**70])
    with pytest.raises(tvmd.ConfigError, match=f"agent {-BIG},"):
        tvmd.Controller(A4, failed=[-BIG])


def test_integer_arguments_take_numpy_integers_and_refuse_floats():
    assert tvmd.Team.ring(np.int64(5), 0.5, True).n == 5
    assert tvmd.AttitudePlanner(0.5, max_iterations=np.uint32(7)).max_iterations == 7
    with pytest.raises(TypeError):
        tvmd.Team.ring(5.0, 0.5, True)
    with pytest.raises(TypeError):
        sim.monte_carlo_specs("hover", runs=2, seed=1.5)
    with pytest.raises(TypeError):
        tvmd.afs_atlas("a4-inc", directions="36")
    # The largest seed is valid.
    assert len(sim.monte_carlo_specs(toml=SHORT, runs=1, seed=2**64 - 1)) == 1
    # 0 is left to the core, whose ConfigError names its field.
    with pytest.raises(tvmd.ConfigError, match="planner.max_iterations"):
        tvmd.Controller(A4, planner_max_iterations=0)


# ---------------------------------------------------------------------------
# Defaults shown by inspect / help() (issue 43, item 9)
# ---------------------------------------------------------------------------


def _public_callables():
    for module in (tvmd, sim):
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.isclass(obj):
                yield f"{module.__name__}.{name}", obj
                for attr, member in vars(obj).items():
                    if callable(member) and not attr.startswith("_"):
                        yield f"{module.__name__}.{name}.{attr}", getattr(obj, attr)
            elif callable(obj):
                yield f"{module.__name__}.{name}", obj


def test_no_default_is_ellipsis():
    shown = []
    for qualname, obj in _public_callables():
        try:
            signature = inspect.signature(obj)
        except ValueError:
            continue  # no text signature (a record class without a constructor)
        for p in signature.parameters.values():
            if p.default is Ellipsis:
                shown.append(f"{qualname}({p.name})")
    assert not shown, shown


def _default(obj, name):
    return inspect.signature(obj).parameters[name].default


@pytest.mark.parametrize(
    "obj",
    [tvmd.Controller, tvmd.Plant, tvmd.Team.plant, tvmd.Team.hover_capability],
    ids=["Controller", "Plant", "Team.plant", "Team.hover_capability"],
)
def test_gravity_defaults_are_standard_gravity(obj):
    assert _default(obj, "gravity") == tvmd.GRAVITY == 9.81
    assert "gravity=9.81" in (obj.__text_signature__ or "")


def test_shown_defaults_are_the_defaults_used():
    ring = inspect.signature(tvmd.Team.ring).parameters
    shown = {name: ring[name].default for name in ("sigma_x", "sigma_y", "max_thrust")}
    # The paper's agents: pi/6, pi/4 and 2 m_i g.
    ring6 = tvmd.Team.ring(6, 0.5, True)
    assert shown == {"sigma_x": ring6.sigma_x, "sigma_y": ring6.sigma_y, "max_thrust": ring6.max_thrust}
    assert shown["sigma_x"] == pytest.approx(math.pi / 6, rel=1e-15)
    assert shown["sigma_y"] == math.pi / 4 and shown["max_thrust"] == 2 * 0.7 * tvmd.GRAVITY
    assert repr(tvmd.Team.ring(6, 0.5, True, **shown)) == repr(ring6)
    g = _default(tvmd.Team.plant, "gravity")
    assert repr(A4.plant(gravity=g)) == repr(A4.plant())
    assert A4.hover_capability(gravity=g).to_dict() == A4.hover_capability().to_dict()
    assert repr(tvmd.Plant(2.0, np.eye(3), gravity=g)) == repr(tvmd.Plant(2.0, np.eye(3)))
    kw = {name: _default(tvmd.Controller, name) for name in ("gravity", "period", "allocator")}
    assert repr(tvmd.Controller(A4, **kw)) == repr(tvmd.Controller(A4))
    assert tvmd.Controller(A4, **kw).gravity == tvmd.Controller(A4).gravity
    atlas = inspect.signature(tvmd.afs_atlas).parameters
    assert (atlas["directions"].default, atlas["certify_heights"].default) == (36, 9)
    specs = inspect.signature(sim.monte_carlo_specs).parameters
    assert (specs["runs"].default, specs["seed"].default) == (100, 0)


# ---------------------------------------------------------------------------
# afs_atlas names `certify_heights` (issue 43, item 10)
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("value", [1, 0, 201])
def test_afs_atlas_certify_heights_is_named_with_its_range(value):
    with pytest.raises(ValueError) as info:
        tvmd.afs_atlas("a4-inc", certify_heights=value)
    message = str(info.value)
    assert message == f"`certify_heights` must be >= 2 and <= 200, got {value}"
    assert "range" not in message and "HeightRange" not in message


def test_afs_atlas_certify_heights_bounds_are_valid():
    for value in (2, 200):
        row = tvmd.afs_atlas("a4-inc", heights=[1.0], directions=4, certify_heights=value)
        assert row["team"] == "a4-inc"


# ---------------------------------------------------------------------------
# run_many on an executor names the failing item (issue 43, item 5)
# ---------------------------------------------------------------------------


def _message(call):
    with pytest.raises(OSError) as info:
        call()
    return str(info.value)


def test_run_many_on_an_executor_names_the_failing_item(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    runs = [{"toml": SHORT}, {"toml": SHORT}, {"toml": SHORT, "mcap": blocker / "x.mcap"}]
    threads = _message(lambda: sim.run_many(runs))
    with ThreadPoolExecutor(2) as pool:
        there = _message(lambda: sim.run_many(runs, executor=pool))
    assert "runs[2] (paper-tilt): cannot write the MCAP log" in threads
    assert there == threads


def test_relaxation_sweep_on_an_executor_names_the_failing_run(tmp_path):
    kw = dict(toml=SHORT, mcap_dir=tmp_path, max_samples=0)
    first = sim.relaxation_sweep([0.5, 1.0], **kw)
    for r in first:
        os.remove(r.mcap_path)
    # The second run's log cannot be written: a directory stands where it goes (checked, and
    # named, before any run flies).
    os.mkdir(first[1].mcap_path)
    threads = _message(lambda: sim.relaxation_sweep([0.5, 1.0], **kw))
    with ThreadPoolExecutor(2) as pool:
        there = _message(lambda: sim.relaxation_sweep([0.5, 1.0], **kw, executor=pool))
    assert "s = 1 (paper-tilt-s1): cannot write the MCAP log" in threads
    assert there == threads
