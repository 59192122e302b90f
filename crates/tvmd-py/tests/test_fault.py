"""Agent fault detection from Python (issue 47): `Controller(fault_detection=...)` and
`Controller.fault_report()`, and a loss the controller is not told of, found by the simulator's
controller (`scenarios/faults/loss-hover.toml`)."""

import pathlib

import pytest

import tvmd

ROOT = pathlib.Path(__file__).resolve().parents[3]


def team():
    return tvmd.Team.preset("a4-inc")


def hover(controller, periods=10):
    for _ in range(periods):
        controller.step({"position": [0.0, 0.0, 1.5]}, {"position": [0.0, 0.0, 1.5]})


def test_off_by_default_no_report():
    c = tvmd.Controller(team())
    hover(c, 2)
    assert c.fault_report() is None


@pytest.mark.parametrize("response", ["report", "mask"])
def test_a_steady_hover_is_nominal(response):
    c = tvmd.Controller(team(), fault_detection=response)
    assert c.fault_report() is None  # nothing stepped yet
    hover(c)
    r = c.fault_report()
    assert r["verdict"] == "nominal"
    assert 0.0 <= r["statistic"] < r["threshold"] == 5.0
    assert r["agent"] is None and r["kind"] is None and r["masked"] is None


def test_a_dict_sets_the_numbers():
    c = tvmd.Controller(team(), fault_detection={"threshold": 7.5, "persistence": 3})
    hover(c, 2)
    assert c.fault_report()["threshold"] == 7.5


def test_it_needs_the_observer():
    with pytest.raises(ValueError, match="observer"):
        tvmd.Controller(team(), law="paper", fault_detection="report")


@pytest.mark.parametrize(
    "bad, error, words",
    [
        ("bogus", ValueError, "fault_detection"),
        ({"nope": 1}, ValueError, "fault_detection.nope"),
        ({"threshold": -1.0}, ValueError, "threshold"),
        ({"persistence": 0}, ValueError, "persistence"),
        (3, TypeError, "fault_detection"),
    ],
)
def test_bad_settings_name_their_field(bad, error, words):
    with pytest.raises(error, match=words):
        tvmd.Controller(team(), fault_detection=bad)


@pytest.mark.parametrize(
    "key, value",
    [
        ("thrust_tolerance", 0.0),
        ("angle_tolerance", float("nan")),
        ("servo_rate", -1.0),
        ("servo_lag", float("inf")),
        ("command_delay", -0.01),
        ("link_timeout", 0.0),
        ("persistence", 0),
        ("persistence", 256),
        ("thrust_forget", 0.0),
        ("angle_forget", -2.0),
        ("lag", 1.0),
    ],
)
def test_bad_report_check_settings_name_their_key(key, value):
    with pytest.raises(ValueError, match=f"report_check.{key}"):
        tvmd.Controller(team(), fault_detection={"report_check": {key: value}})


def test_the_report_checks_persistence_is_a_setting():
    """Agent 1's rotor reported stopped (after ten agreeing reports): the recommended check
    confirms it after two reports,
    one set to four reports waits for four; a long link timeout keeps old reports a check."""
    for persistence in (2, 4):
        c = tvmd.Controller(
            team(),
            fault_detection={
                "response": "report",
                "report_check": {"persistence": persistence, "link_timeout": 0.5},
            },
        )
        state = {"position": [0.0, 0.0, 1.5]}
        out = c.step(state, state)
        for _ in range(10):  # agreeing reports while the check's rotor model spins up
            c.set_reports(reports_of(out))
            out = c.step(state, state)
        verdicts = []
        for _ in range(4):
            c.set_reports(reports_of(out, dead=(1,)))
            out = c.step(state, state)
            r = c.fault_report()
            verdicts.append((r["verdict"], r["agent"], r["source"]))
        first = next(i for i, v in enumerate(verdicts) if v == ("confirmed", 1, "reports"))
        assert first == persistence - 1, verdicts
    # A report 0.3 s old: a lost link with the recommended 0.1 s, not with 0.5 s.
    for timeout, kind in ((None, "link-loss"), (0.5, None)):
        check = {} if timeout is None else {"link_timeout": timeout}
        c = tvmd.Controller(team(), fault_detection={"report_check": check})
        out = c.step(state, state)
        for _ in range(3):
            c.set_reports([row[:3] + [0.3] for row in reports_of(out)])
            out = c.step(state, state)
        assert c.fault_report()["kind"] == kind


def test_an_uninformed_loss_is_found_and_masked_in_the_simulator():
    result = tvmd.sim.run(str(ROOT / "scenarios/faults/loss-hover.toml"))
    fault = result.summary["fault"]
    # Agent 0 loses its thrust at t = 4 s; the controller is not told.
    assert fault["masked"]["agent"] == 0
    assert 4.0 < fault["masked"]["time"] < 4.5
    assert fault["first_loss"]["agent"] == 0
    assert fault["max_statistic"] > fault["threshold"]


def reports_of(output, dead=()):
    """Each agent's report of the commands of `output` (10 ms old); agents in `dead` report a
    stopped rotor."""
    rows = []
    for i, (eta_x, eta_y, thrust, _omega) in enumerate(output.commands):
        rows.append([0.0 if i in dead else thrust, eta_x, eta_y, 0.01])
    return rows


def test_agents_reports_name_a_stopped_rotor_and_agreeing_ones_change_nothing():
    c = tvmd.Controller(team(), fault_detection="mask")
    plain = tvmd.Controller(team(), fault_detection="mask")
    state = {"position": [0.0, 0.0, 1.5]}
    out = c.step(state, state)
    plain.step(state, state)
    for _ in range(10):
        c.set_reports(reports_of(out))
        out = c.step(state, state)
        assert (out.commands == plain.step(state, state).commands).all()
    assert c.fault_report()["source"] is None
    # Agent 1's rotor reported stopped: two reports confirm the loss and the mask follows.
    for _ in range(2):
        c.set_reports(reports_of(out, dead=(1,)))
        out = c.step(state, state)
    r = c.fault_report()
    assert (r["verdict"], r["agent"], r["kind"], r["source"]) == ("confirmed", 1, "loss", "reports")
    assert r["masked"] == 1 and out.commands[1][2] == 0.0


def test_reports_rows_of_nan_are_no_report_and_bad_ones_name_their_row():
    c = tvmd.Controller(team(), fault_detection="report")
    nan = float("nan")
    c.set_reports([[nan] * 4] * 4)
    with pytest.raises(ValueError, match="reports"):
        c.set_reports([[1.0, 0.0, 0.0, 0.0]] * 3)
    with pytest.raises(ValueError, match="row 2: .*age"):
        c.set_reports([[1.0, 0.0, 0.0, 0.0]] * 2 + [[1.0, 0.0, 0.0, -1.0], [nan] * 4])
    with pytest.raises(ValueError, match="row 0"):
        c.set_reports([[nan, 0.0, 0.0, 0.0]] + [[nan] * 4] * 3)
    with pytest.raises(ValueError, match="fault detection"):
        tvmd.Controller(team()).set_reports([[1.0, 0.0, 0.0, 0.0]] * 4)


def test_the_simulator_passes_its_agents_reports_to_the_controller():
    text = (ROOT / "scenarios/faults/loss-hover.toml").read_text()
    result = tvmd.sim.run(toml=text + '\n[reports]\ndead_esc = "zero"\n', team="a6-inc")
    masked = result.summary["fault"]["masked"]
    # 100 Hz reports, 20 ms late: named from the reports, two reports after the first zero.
    assert (masked["agent"], masked["kind"], masked["source"]) == (0, "loss", "reports")
    assert 4.0 < masked["time"] <= 4.05


def test_the_scenarios_report_check_reaches_the_simulators_controller():
    """``[fault_detection.report_check]`` in a scenario: six reports to confirm instead of two
    mask the dead agent four reports (40 ms at 100 Hz) later, still from its reports."""
    text = (ROOT / "scenarios/faults/loss-hover.toml").read_text() + '\n[reports]\ndead_esc = "zero"\n'
    times = []
    for extra in ("", "\n[fault_detection.report_check]\npersistence = 6\n"):
        masked = tvmd.sim.run(toml=text + extra, team="a6-inc").summary["fault"]["masked"]
        assert (masked["agent"], masked["source"]) == (0, "reports")
        times.append(masked["time"])
    assert 0.03 < times[1] - times[0] < 0.05, times
