"""``tvmd.sim.load``: a run read back from its MCAP log equals the ``SimResult`` the run returned.

The log stores every value as a protobuf ``double`` (float64), so the comparison is exact
(NaN where the result has NaN; ``-0.0 == 0.0``, as protobuf does not keep the sign of a zero
scalar): every array field, the summary, the paper metrics and the
scalars. A corrupt or foreign file is a ``ValueError`` naming the path; a missing file a
``FileNotFoundError`` (as in ``run``); a FIFO or device is refused before it is opened
(``OSError``), each case in a child process under a timeout; a truncated log loads the ticks
before the damage with a warning.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest

import tvmd.sim as sim


def same(a, b, where="result"):
    """Recursive equality of summary values, NaN equal to NaN."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), where
        for k in a:
            same(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, (list, tuple)):
        assert isinstance(b, (list, tuple)) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{where}[{i}]")
    elif isinstance(a, float) and math.isnan(a):
        assert isinstance(b, float) and math.isnan(b), where
    else:
        assert a == b, (where, a, b)


def arrays(result):
    return {name: getattr(result, name) for name in result.FIELDS if isinstance(getattr(result, name), np.ndarray)}


@pytest.fixture(scope="module", params=["agent-failure", "paper-tilt"])
def logged(request, tmp_path_factory):
    # agent-failure: a failure mid-flight (hover classification, failed flags, held commands);
    # paper-tilt: the planner saturates (theta, e_f, e_tau non-zero).
    path = tmp_path_factory.mktemp("logs") / f"{request.param}.mcap"
    return sim.run(request.param, mcap=path), path


def test_a_loaded_log_equals_the_run_that_wrote_it(logged):
    flown, path = logged
    loaded = sim.load(path)
    assert isinstance(loaded, sim.SimResult)
    assert len(loaded) == len(flown) > 100
    assert loaded.sample_stride == 1
    flown_arrays, loaded_arrays = arrays(flown), arrays(loaded)
    assert flown_arrays.keys() == loaded_arrays.keys()
    assert {"t", "position", "rotation", "commands", "actual", "failed", "theta", "e_tau", "V_x"} <= flown_arrays.keys()
    for name, value in flown_arrays.items():
        assert loaded_arrays[name].dtype == value.dtype, name
        np.testing.assert_array_equal(loaded_arrays[name], value, err_msg=name)
    same(flown.summary, loaded.summary, "summary")
    same(flown.paper_metrics, loaded.paper_metrics, "paper_metrics")
    for name in ("scenario_name", "law", "relaxation", "allocator", "precision", "n_agents", "mass", "scenario_toml"):
        assert getattr(loaded, name) == getattr(flown, name), name
    assert loaded.mcap_path == flown.mcap_path == str(path)


def test_the_loaded_flight_is_not_trivially_equal(logged):
    # The comparison above means something: the flight moves, and (agent-failure) an agent fails.
    flown, _ = logged
    loaded = sim.load(flown.mcap_path)
    assert np.ptp(loaded.position[:, 2]) > 0.5
    assert np.isfinite(loaded.commands).all()
    if flown.scenario_name == "agent-failure":
        assert loaded.failed[-1].any() and not loaded.failed[0].any()
        assert loaded.summary["hover_classifications"]


def test_a_thinned_log_has_nan_on_the_ticks_it_left_out(tmp_path):
    path = tmp_path / "thinned.mcap"
    flown = sim.run(toml='name = "thin"\nduration = 1.0\n[log]\ndecimation = 4\n', mcap=path)
    loaded = sim.load(path)
    assert len(loaded) == len(flown)
    kept = np.arange(len(flown)) % 4 == 0
    np.testing.assert_array_equal(loaded.position, flown.position)
    np.testing.assert_array_equal(loaded.commands[kept], flown.commands[kept])
    assert np.isnan(loaded.commands[~kept]).all() and np.isnan(loaded.e_f[~kept]).all()
    same(flown.summary, loaded.summary, "summary")


def test_a_missing_file_is_a_file_not_found_error_naming_it(tmp_path):
    path = tmp_path / "nowhere" / "run.mcap"
    with pytest.raises(FileNotFoundError, match="nowhere"):
        sim.load(path)


def load_in_child(path, timeout=60):
    """`load(path)` in a child process: (exception type name, message); a hang is a timeout."""
    code = (
        "import sys, tvmd.sim as s\n"
        "try:\n    s.load(sys.argv[1]); print('LOADED')\n"
        "except BaseException as e:\n    print(type(e).__name__, e)\n"
    )
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, timeout=timeout)
    return done.stdout.strip()


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_is_refused_before_it_is_opened(tmp_path):
    fifo = tmp_path / "p.mcap"
    os.mkfifo(fifo)
    out = load_in_child(fifo)
    assert out.startswith("OSError") and "not a regular file" in out and "p.mcap" in out, out


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_a_device_is_refused_before_it_is_read():
    out = load_in_child("/dev/zero")
    assert out.startswith("OSError") and "not a regular file" in out, out


def test_a_large_file_that_is_not_mcap_is_refused_after_its_first_bytes(tmp_path):
    path = tmp_path / "sparse.mcap"
    with open(path, "wb") as f:
        f.write(b"not mcap")
        f.truncate(2**31)  # sparse: 2 GB that reading whole would hold in memory
    out = load_in_child(path)
    assert out.startswith("ValueError") and "magic" in out and "sparse.mcap" in out, out


def test_a_file_that_is_not_mcap_is_a_value_error_naming_it(tmp_path):
    path = tmp_path / "garbage.mcap"
    path.write_bytes(b"\x89MCAP0\r\n" + b"\x00garbage" * 100)
    with pytest.raises(ValueError, match="garbage.mcap"):
        sim.load(path)
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    with pytest.raises(ValueError, match="empty.mcap"):
        sim.load(empty)


def test_a_truncated_log_loads_what_it_holds_with_a_warning(tmp_path):
    path = tmp_path / "whole.mcap"
    flown = sim.run(toml='name = "long"\nduration = 8.0\n', mcap=path)
    data = path.read_bytes()
    partial = 0
    for keep in (len(data) - 100, 3 * len(data) // 4, len(data) // 2, 2 * len(data) // 5):
        damaged = tmp_path / f"cut-{keep}.mcap"
        damaged.write_bytes(data[:keep])
        try:
            with pytest.warns(UserWarning, match=f"cut-{keep}.mcap.*damaged"):
                loaded = sim.load(damaged)
        except ValueError as e:
            # Cut inside the first chunk: nothing whole before the damage.
            assert keep < len(data) - 100 and "cut-" in str(e), e
            continue
        k = len(loaded)
        assert 0 < k <= len(flown)
        if keep == len(data) - 100:
            assert k == len(flown), "only the summary section is lost"
            same(flown.summary, loaded.summary, "summary")
        partial += k < len(flown)
        np.testing.assert_array_equal(loaded.position, flown.position[:k])
        np.testing.assert_array_equal(loaded.commands, flown.commands[:k])
        assert loaded.scenario_toml == flown.scenario_toml
    assert partial > 0, "some cut loads the ticks before it"
