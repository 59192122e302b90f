"""Options that were accepted and ignored, and errors of the wrong type (issue 57, items 9 and 10).

An observation of one team handed to another team's ``ScenarioController``, or its output to
another team's ``Simulation``, is a ``ValueError`` naming what disagrees; ``SimulationBatch.reset``
refuses a team named twice (it reset it twice and dropped a seed); a failure that tells the
controller late but never tells it (``informed_after`` with ``controller_informed = false``) is
refused naming the field.
"""

from __future__ import annotations

import numpy as np
import pytest

import tvmd.sim as sim


def test_an_observation_of_another_team_is_a_value_error():
    a4 = sim.Simulation("hover")
    obs = a4.reset()
    with pytest.raises(ValueError, match="observation.*4 agents.*6"):
        sim.ScenarioController("hover", team="a6-inc").step(obs)
    a6 = sim.Simulation("hover", team="a6-inc")
    with pytest.raises(ValueError, match="observation.*6 agents.*4"):
        sim.ScenarioController("hover").step(a6.reset())


def test_another_teams_output_is_a_value_error_that_changes_nothing():
    a6 = sim.Simulation("hover", team="a6-inc")
    obs6 = a6.reset()
    a4 = sim.Simulation("hover")
    out4 = sim.ScenarioController("hover").step(a4.reset())
    with pytest.raises(ValueError, match="4 commands for 6 agents"):
        a6.step(out4)
    assert a6.time == obs6.t == 0.0


def test_a_batch_reset_names_each_team_once():
    b = sim.SimulationBatch("hover", count=2, jobs=1)
    with pytest.raises(ValueError, match="indices.*team 0 twice"):
        b.reset([0, 0], seeds=[1, 2])
    d = b.reset([1, 0], seeds=[1, 2])
    assert np.isfinite(d["position"]).all()


def test_informed_after_without_informing_is_refused():
    toml = (
        'name = "late"\nduration = 0.1\n[[failures]]\nagent = 0\ntime = 0.05\nkind = "no-thrust"\n'
        "controller_informed = false\ninformed_after = 0.02\n"
    )
    with pytest.raises(ValueError, match=r"failures\[0\]\.informed_after"):
        sim.run(toml=toml)
    sim.run(toml=toml.replace("informed_after = 0.02\n", ""))


def test_set_landed_takes_the_flag_as_flight_code_passes_it():
    import tvmd

    c = tvmd.Controller(tvmd.Team.a4_inc())
    c.set_landed(1)
    assert c.landed
    c.set_landed(0)
    assert not c.landed
    c.set_landed(np.True_)
    assert c.landed
    for bad in (2, -1, "yes", None, 0.5):
        with pytest.raises(TypeError, match="landed"):
            c.set_landed(bad)
    assert c.landed
