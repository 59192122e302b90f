"""The exact-boundary redistribution's round cap (`max_rounds`) from Python: it bounds the walk,
returns admissible forces with their true error, and reaches the controller's allocator; the
default is capped at 2 rounds and "uncapped" is one word away (issue 59)."""

import numpy as np
import pytest

import tvmd


def test_a_round_cap_bounds_the_exact_boundary_walk():
    # Beyond the team's total thrust: uncapped, the walk runs to its own limit.
    team = tvmd.Team.a4_inc()
    wrench = np.array([0.5, 0.3, 0.0, 5.0, 0.0, 70.0])
    full = tvmd.allocate(team, wrench, max_rounds="uncapped")
    for k in (0, 1, 2):
        capped = tvmd.allocate(team, wrench, max_rounds=k)
        # The start's redistribution (at most n rounds) plus at most k walk rounds.
        assert capped.rounds <= team.n + k < full.rounds
        assert np.all(np.isfinite(capped.forces))
        # Never better than the whole walk, and the true error of the forces returned.
        assert capped.e_f >= full.e_f - 1e-9
        made = team.wrench(capped.forces)
        assert np.isclose(capped.e_f, np.linalg.norm(made[3:] - wrench[3:]), rtol=1e-9)
    controller = tvmd.Controller(team, max_rounds=2)
    out = controller.step({"position": [0.0, 0.0, 1.0]}, {"position": [0.0, 0.0, 1.0]})
    assert np.all(np.isfinite(out.commands))


def test_the_default_is_two_rounds_and_uncapped_is_a_choice():
    team = tvmd.Team.a4_inc()
    wrench = np.array([0.5, 0.3, 0.0, 5.0, 0.0, 70.0])
    default = tvmd.allocate(team, wrench)
    two = tvmd.allocate(team, wrench, max_rounds=2)
    assert default.rounds == two.rounds <= team.n + 2
    np.testing.assert_array_equal(default.forces, two.forces)
    assert tvmd.allocate(team, wrench, max_rounds="uncapped").rounds > default.rounds
    # The controller's default allocator is capped too: the same commands as max_rounds=2.
    state = {"position": [0.0, 0.0, 1.0]}
    c, s = np.cos(1.0), np.sin(1.0)
    tilted = [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
    reference = {"position": [0.3, -0.2, 1.5], "attitude": tilted}
    a = tvmd.Controller(team).step(state, reference)
    b = tvmd.Controller(team, max_rounds=2).step(state, reference)
    np.testing.assert_array_equal(a.commands, b.commands)


@pytest.mark.parametrize("bad", ["none", "Uncapped", ""])
def test_another_word_is_a_value_error_naming_max_rounds(bad):
    team = tvmd.Team.a4_inc()
    for call in (
        lambda: tvmd.allocate(team, np.zeros(6), max_rounds=bad),
        lambda: tvmd.Controller(team, max_rounds=bad),
    ):
        with pytest.raises(ValueError, match=r"`max_rounds` must be an int >= 0 or \"uncapped\""):
            call()
    with pytest.raises(TypeError):
        tvmd.allocate(team, np.zeros(6), max_rounds=2.0)


def test_the_capped_redistribution_takes_its_rounds_from_max_rounds():
    assert "capped-redistribution" in tvmd.ALLOCATORS
    team = tvmd.Team.a4_inc()
    wrench = np.array([0.5, 0.3, 0.0, 5.0, 0.0, 70.0])
    paper = tvmd.allocate(team, wrench, method="redistributed-pseudo-inverse")
    assert paper.rounds > 1
    for k, most in ((1, 1), (None, 2), ("uncapped", team.n)):
        out = tvmd.allocate(team, wrench, method="capped-redistribution", max_rounds=k)
        assert 1 <= out.rounds <= most and out.method == "capped-redistribution"
        assert np.all(np.isfinite(out.forces))
        # The miss is reported: the true error of the forces returned.
        made = team.wrench(out.forces)
        assert np.isclose(out.e_f, np.linalg.norm(made[3:] - wrench[3:]), rtol=1e-9)
    with pytest.raises(ValueError, match="max_rounds|round"):
        tvmd.allocate(team, wrench, method="capped-redistribution", max_rounds=0)
    controller = tvmd.Controller(team, allocator="capped-redistribution", max_rounds=1)
    out = controller.step({"position": [0.0, 0.0, 1.0]}, {"position": [0.0, 0.0, 1.0]})
    assert np.all(np.isfinite(out.commands))
