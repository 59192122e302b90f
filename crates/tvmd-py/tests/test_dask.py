"""A Monte Carlo batch on a two-worker dask.distributed LocalCluster equals the in-process batch
for the same seed (each flight is one task: its spec and row are JSON text)."""

# A hard import, not importorskip: a broken install fails the test command instead of skipping.
import distributed

from tvmd import sim

SHORT = """
name = "mc-dask"
duration = 2.0
initial_position = [0.0, 0.0, 1.5]
[reference]
kind = "hover"
position = [0.0, 0.0, 1.5]
[success]
steady_state_window = 0.5
"""


def test_a_batch_on_a_local_cluster_equals_the_in_process_batch():
    kw = dict(toml=SHORT, runs=4, seed=42, teams=["a4-inc", "a6-inc"], model_errors=[0.5])
    here = sim.monte_carlo(**kw)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        there = sim.monte_carlo(**kw, executor=client.get_executor())
        # Two worker processes, not this one, flew the tasks.
        assert len(client.scheduler_info()["workers"]) == 2
    assert len(there["flights"]) == 8
    assert there["flights"] == here["flights"]
    assert there["groups"] == here["groups"]
    assert there["success_rate"] == here["success_rate"]
