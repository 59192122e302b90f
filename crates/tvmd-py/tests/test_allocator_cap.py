"""The exact-boundary redistribution's round cap (`max_rounds`) from Python: it bounds the walk,
returns admissible forces with their true error, and reaches the controller's allocator."""

import numpy as np

import tvmd


def test_a_round_cap_bounds_the_exact_boundary_walk():
    # Beyond the team's total thrust: the walk runs to its own cap unless a smaller one is given.
    team = tvmd.Team.a4_inc()
    wrench = np.array([0.5, 0.3, 0.0, 5.0, 0.0, 70.0])
    full = tvmd.allocate(team, wrench)
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
