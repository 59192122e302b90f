"""1,000 flights of paper-tilt on a dask.distributed LocalCluster: the success rate against the
model-error level (docs/method.md "Monte Carlo").

    pip install "dask[distributed]" target/wheels/tvmd-*.whl
    python examples/python/monte_carlo_dask.py [--out out/montecarlo-dask] [--scheduler ADDRESS]

With ``--scheduler tcp://host:8786`` it uses a running cluster instead (every worker needs the
same tvmd wheel installed). Writes flights.csv, groups.csv, the box plots and success_rate.png.
"""

import argparse
import time

import distributed

from tvmd import sim

LEVELS = [0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 0.75, 1.0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="paper-tilt")
    ap.add_argument("--runs", type=int, default=100, help="flights per model-error level")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="out/montecarlo-dask")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler")
    ap.add_argument("--workers", type=int, default=None, help="LocalCluster workers")
    a = ap.parse_args()

    if a.scheduler:
        client = distributed.Client(a.scheduler)
    else:
        cluster = distributed.LocalCluster(
            n_workers=a.workers, threads_per_worker=1, dashboard_address=None
        )
        client = distributed.Client(cluster)
    with client:
        workers = len(client.scheduler_info()["workers"])
        t0 = time.perf_counter()
        report = sim.monte_carlo(
            a.scenario,
            runs=a.runs,
            seed=a.seed,
            model_errors=LEVELS,
            out=a.out,
            executor=client.get_executor(),
        )
        wall = time.perf_counter() - t0
    n = len(report["flights"])
    print(f"{n} flights on {workers} Dask workers in {wall:.1f} s ({n / wall:.1f} flights/s)")
    print(f"{'model error':>12} {'success':>8} {'median steady (m)':>18}")
    for g in report["groups"]:
        steady = g["median_position_steady_state"]
        print(f"{g['model_error']:>12} {100 * g['success_rate']:>7.1f}% {steady:>18.4f}")
    print("success rate against model error:", next(p for p in report["files"]["plots"] if p.endswith("success_rate.png")))


if __name__ == "__main__":
    main()
