"""Hostile use of tvmd.sim and tvmd.Controller: path clashes, Ctrl-C, extreme scenarios, threads.

Each case ends in a clear error (ValueError naming the field or path, OSError with the path,
KeyboardInterrupt) or a correct result, never a corrupt log or a run that cannot be stopped.
"""

import _thread
import pathlib
import threading
import time

import numpy as np
import pytest
from mcap.reader import make_reader

import tvmd
from tvmd import sim

SHORT = "duration = 0.3\n"


def test_duplicate_log_paths_in_a_batch_are_refused(tmp_path):
    with pytest.raises(ValueError, match="output path clash"):
        sim.relaxation_sweep([0.5, 0.5], toml=SHORT, mcap_dir=tmp_path)
    log = tmp_path / "same.mcap"
    with pytest.raises(ValueError, match="both"):
        sim.run_many([{"toml": SHORT, "mcap": log}, {"toml": SHORT, "mcap": tmp_path / "." / "same.mcap"}])
    assert not log.exists()
    # Distinct relaxations: distinct logs, both complete.
    runs = sim.relaxation_sweep([0.5, 1.0], toml=SHORT, mcap_dir=tmp_path)
    assert len({r.mcap_path for r in runs}) == 2


def test_ctrl_c_stops_a_run_promptly_and_its_log_is_complete(tmp_path):
    log = tmp_path / "long.mcap"
    duration = 400.0

    def interrupt_once_flying():
        # The log is written under a temporary name beside it while the run flies.
        while not any(p.name.startswith(".tmp-") for p in tmp_path.iterdir()):
            time.sleep(0.005)
        time.sleep(0.2)
        _thread.interrupt_main()

    threading.Thread(target=interrupt_once_flying, daemon=True).start()
    with pytest.raises(KeyboardInterrupt):
        sim.run(toml=f"duration = {duration}\n", mcap=log)
    with open(log, "rb") as f:
        summary = make_reader(f).get_summary()
    # The strict reader finds the footer and summary; the flight stopped early.
    assert summary is not None and summary.statistics.message_count > 0
    assert summary.statistics.message_end_time < 0.9 * duration * 1e9


def test_errors_name_the_path_and_the_field(tmp_path):
    blocker = tmp_path / "blocker"
    blocker.write_text("")
    with pytest.raises(OSError, match="is a file, not a directory"):
        sim.run(toml=SHORT, mcap=blocker / "x" / "run.mcap")
    with pytest.raises(OSError, match="missing.toml"):
        sim.run(str(tmp_path / "missing.toml"))
    for toml, field in [
        ("duration = 1e308\n", "duration"),
        ("duration = 1e-9\n", "duration"),
        ("[physics]\ndt = 10.0\n", "physics.dt"),
        ("[physics]\nsolver_iterations = 0\n", "physics.solver_iterations"),
        ("[physics]\ngravity = 1e300\n", "physics.gravity"),
        ("[team]\nagent_mass = 1e-300\n", "team.agent_mass"),
        ("initial_position = [0.0, 0.0, -0.5]\n", "initial_position"),
        ("[reference]\nkind = \"paper-tilt\"\ntilt = [4.0, 4.0]\n", "reference.tilt"),
    ]:
        with pytest.raises(ValueError, match=field.replace(".", r"\.")):
            sim.run(toml=toml)
    # Every [reference] field has a default, kind included.
    assert sim.run(toml="duration = 0.3\n[reference]\nascent_height = 1.0\n").summary["time"] > 0


def test_scenario_names_cannot_leave_the_log_directory(tmp_path):
    runs = sim.relaxation_sweep([0.5], toml='name = "../../evil"\nduration = 0.1\n', mcap_dir=tmp_path)
    assert tmp_path in pathlib.Path(runs[0].mcap_path).parents


def test_a_controller_shared_by_threads_with_slow_array_likes():
    ctl = tvmd.Controller(tvmd.Team.a4_inc())

    class SlowArray:
        """An array-like whose conversion runs Python code, letting other threads in."""

        def __init__(self, values):
            self.values = np.asarray(values, dtype=float)

        def __array__(self, dtype=None, copy=None):
            time.sleep(0.001)
            return self.values if dtype is None else self.values.astype(dtype)

    errors = []

    def fly():
        for _ in range(50):
            try:
                ctl.step({"position": SlowArray([0.1, 0.0, 1.5])}, {"position": SlowArray([0.0, 0.0, 1.5])})
            except Exception as e:  # noqa: BLE001 - collected and asserted below
                errors.append(e)

    threads = [threading.Thread(target=fly) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []


def test_messages_blame_the_right_thing():
    # An empty team: a ValueError about the team, not a dtype TypeError.
    with pytest.raises(ValueError, match=r"no \(working\) agent"):
        tvmd.Team(np.zeros((0, 3)), [], 0.7, 0.5, 0.7, 14.0)
    # A non-symmetric gain matrix is called that.
    skew = [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    with pytest.raises(ValueError, match="symmetric"):
        tvmd.Gains(skew, [12.0, 12.0, 1.0], [8.0, 8.0, 1.5, 0.8, 0.8, 2.0])
    # A servo too fast for the physics step names the servo, not a non-finite force.
    toml = "duration = 0.3\n[actuators.servo]\nnatural_frequency = 1e308\ndamping_ratio = 0.7\nrate_limit = 5.0\n"
    with pytest.raises(ValueError, match=r"actuators\.servo\.natural_frequency"):
        sim.run(toml=toml)
