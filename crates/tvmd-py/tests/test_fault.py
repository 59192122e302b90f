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


def test_an_uninformed_loss_is_found_and_masked_in_the_simulator():
    result = tvmd.sim.run(str(ROOT / "scenarios/faults/loss-hover.toml"))
    fault = result.summary["fault"]
    # Agent 0 loses its thrust at t = 4 s; the controller is not told.
    assert fault["masked"]["agent"] == 0
    assert 4.0 < fault["masked"]["time"] < 4.5
    assert fault["first_loss"]["agent"] == 0
    assert fault["max_statistic"] > fault["threshold"]
