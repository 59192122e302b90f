"""Errors that say precisely what is wrong and name the argument (issue 57, item 9): a control
period out of range says so (1e300 is finite), a bad ``Controller`` argument is named as the
argument (not as a scenario field), and gains from natural frequencies that overflow name the
natural-frequency input, not the gain ``gains.k_x``.
"""

from __future__ import annotations

import pytest

import tvmd
import tvmd.sim as ts

A4 = tvmd.Team.a4_inc()


@pytest.mark.parametrize("period", [1e300, 2.0, 1e-9, float("inf"), float("nan"), 0.0, -0.01])
def test_a_period_out_of_range_says_so_with_the_range(period):
    with pytest.raises(tvmd.ConfigError, match=r"`period` = .* s is out of range: .* in \[1e-6, 1\.0\] s") as e:
        tvmd.Controller(A4, period=period)
    assert "positive and finite" not in str(e.value)
    assert e.value.field == "period"


@pytest.mark.parametrize(
    "kwargs, argument, key",
    [
        ({"fault_detection": {"threshold": -1.0}}, "fault_detection", "threshold"),
        ({"fault_detection": {"persistence": 0}}, "fault_detection", "persistence"),
        ({"null_space": "inward-tilt=2"}, "null_space", "tilt"),
    ],
)
def test_a_bad_controller_argument_is_named_as_the_argument(kwargs, argument, key):
    with pytest.raises(ValueError) as e:
        tvmd.Controller(A4, **kwargs)
    message = str(e.value)
    assert "scenario field" not in message
    assert f"invalid `{argument}` argument, key `{key}`" in message


NATURAL = {"gains": {"natural": {"position_frequency": [1e160] * 3}}}


def test_an_overflowing_natural_frequency_is_named_by_the_controller():
    with pytest.raises(tvmd.ConfigError) as e:
        tvmd.Controller(A4, law=NATURAL)
    assert e.value.field == "gains.natural_frequency"
    assert "natural_frequency" in str(e.value) and "K_x" in str(e.value)
    assert "`gains.k_x`" not in str(e.value)


def test_an_overflowing_natural_frequency_is_named_by_the_simulator():
    with pytest.raises(ValueError, match=r"law\.gains\.natural.*natural_frequency") as e:
        ts.run("hover", law=NATURAL)
    assert "`gains.k_x`" not in str(e.value)
