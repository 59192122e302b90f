"""Issue 43: every output path follows one rule (checked before any work, written whole through
a temporary file renamed into place, errors naming the path), every long call honours Ctrl-C
and keeps what finished, and a refused failure mask is reported.

Each test fails on the code before the fix (the item is named).
"""

import os
import signal
import subprocess
import sys
import threading
import time

import pytest
from mcap.reader import make_reader

import tvmd
from tvmd import sim

SHORT = "duration = 0.3\n"
# Hours of flying: a check made after the work would never be reached by these tests.
LONG = "duration = 100000.0\n"


def test_the_scenario_file_is_never_overwritten_by_the_log(tmp_path):
    """Item 1: `run('s.toml', mcap='s.toml')` used to write the MCAP over the scenario."""
    s = tmp_path / "s.toml"
    s.write_text("duration = 0.5\n")
    calls = [
        lambda: sim.run(str(s), mcap=str(s)),
        lambda: sim.run(s, mcap=tmp_path / "." / "s.toml"),
        lambda: sim.run_many([{"scenario": str(s), "mcap": str(s)}]),
        # One run's log over another run's scenario file.
        lambda: sim.run_many([str(s), {"toml": SHORT, "mcap": s}]),
    ]
    for call in calls:
        with pytest.raises(ValueError, match="scenario file"):
            call()
        assert s.read_text() == "duration = 0.5\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_monte_carlo_out_over_a_file_fails_before_flying(tmp_path):
    """Item 2: the study flew every flight, then failed with a bare "File exists"."""
    f = tmp_path / "f"
    f.write_text("keep")
    with pytest.raises(OSError, match="is a file") as e:
        sim.monte_carlo(toml=LONG, runs=1000, out=f)
    assert str(f) in str(e.value)
    assert f.read_text() == "keep"


def test_outputs_are_checked_before_the_work(tmp_path):
    """Item 11: an unwritable log or figure directory fails before any flight or computation."""
    if sys.platform.startswith("linux"):
        with pytest.raises(OSError, match="/proc/x.mcap"):
            sim.run(toml=LONG, max_samples=0, mcap="/proc/x.mcap")
    f = tmp_path / "file"
    f.write_text("keep")
    with pytest.raises(OSError, match="is a file"):
        tvmd.afs_atlas("a8-inc", directions=3600, certify_heights=200, plots=f)
    with pytest.raises(OSError, match="is a file"):
        sim.relaxation_sweep([0.5], toml=LONG, max_samples=0, mcap_dir=f)
    assert f.read_text() == "keep"


def test_concurrent_runs_on_one_log_leave_a_whole_file(tmp_path):
    """Item 7: two runs writing one MCAP path both succeeded and left a corrupt file."""
    log = tmp_path / "race.mcap"
    errors = []

    def fly():
        try:
            sim.run(toml="duration = 1.0\n", mcap=log)
        except Exception as e:  # noqa: BLE001 - collected and asserted below
            errors.append(e)

    threads = [threading.Thread(target=fly) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    with open(log, "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics.message_count > 0
    # The last rename wins; no temporary file is left behind.
    assert [p.name for p in tmp_path.iterdir()] == ["race.mcap"]


def test_a_refused_failure_mask_is_reported():
    """Item 4: A3-Con cannot lose an agent; the refusal was only a note inside the MCAP."""
    r = sim.run("agent-failure", team="a3-con", max_samples=0)
    c = r.summary["hover_classifications"]
    assert len(c) == 1 and c[0]["capable"] is False, c
    assert "refused" in c[0]["refused"], c


CTRL_C = """
import sys
import tvmd
import tvmd.sim as sim
print("ready", flush=True)
try:
    {call}
except KeyboardInterrupt as e:
    p = getattr(e, "partial", None)
    print("interrupted", None if p is None else (p["interrupted"], p["flights_asked"], len(p["flights"])), flush=True)
    sys.exit(130)
print("finished", flush=True)
"""

# Each call would take many minutes; Ctrl-C must end it within the poll and one tick or ray.
LONG_CALLS = {
    "run": f"sim.run(toml={LONG!r}, max_samples=0)",
    "run_many": f"sim.run_many([{{'toml': {LONG!r}, 'max_samples': 0}}] * 2)",
    "relaxation_sweep": f"sim.relaxation_sweep([0.5, 1.0], toml={LONG!r}, max_samples=0)",
    "monte_carlo": "sim.monte_carlo(toml='duration = 2.0\\n', runs=100000, jobs=1)",
    "afs_atlas": "tvmd.afs_atlas('a8-inc', directions=3600, certify_heights=200)",
    # One executor task of a study.
    "monte_carlo_flight": f"sim.monte_carlo_flight(sim.monte_carlo_specs(toml={LONG!r}, runs=1)[0])",
}


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a child process")
@pytest.mark.parametrize("name", sorted(LONG_CALLS))
def test_ctrl_c_ends_every_long_call(name, tmp_path):
    """Item 3: `monte_carlo` (threads) and `afs_atlas` ignored Ctrl-C until all work was done."""
    child = subprocess.Popen(
        [sys.executable, "-c", CTRL_C.format(call=LONG_CALLS[name])],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert child.stdout.readline().strip() == "ready"
    time.sleep(1.5)  # inside the call
    child.send_signal(signal.SIGINT)
    try:
        out, err = child.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        child.kill()
        pytest.fail(f"{name} still running 60 s after Ctrl-C")
    assert child.returncode == 130, (out, err)
    assert out.startswith("interrupted"), (out, err)
    if name == "monte_carlo":
        # The finished flights travel with the exception, marked partial.
        assert out.strip().startswith("interrupted (True, 100000,"), out


def test_a_log_path_that_names_no_file_is_refused_before_the_flight(tmp_path, monkeypatch):
    """Found by the hostile suite: `mcap=""` or `"a/"` failed only at the rename, after the flight."""
    monkeypatch.chdir(tmp_path)
    for bad in ["", "a/", "x/.."]:
        with pytest.raises(ValueError, match="names no file"):
            sim.run(toml=SHORT, mcap=bad)
    assert list(tmp_path.iterdir()) == []
