"""Scaling of an uncertainty study on a dask cluster: the same study on a LocalCluster of 1 and of 2
worker processes (127.0.0.1 only), each into a fresh folder, every worker's compiled kernels loaded
before the clock starts.

    python -m benchmarks.uncertainty_scaling [--samples N] [--rpm RPM]

The study: ``scenarios/multibody_<rpm>rpm.toml`` on the fast scene (rigid raceways), 1 warm-up + 10
rotations, every ranged key, N base samples (N (k + 2) runs), seed 0. Printed: wall time per worker
count and the efficiency wall(1) / (2 wall(2)); the 1-minute load average before and after.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
import warnings
from pathlib import Path

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


def _scenario(rpm: int):
    from bearingsim.scenario import load_scenario

    return load_scenario(SCENARIOS / f"multibody_{rpm}rpm.toml",
                         ["multibody.raceway_contact=rigid", "numerics.rotations=10", "numerics.warmup_rotations=1"])


def _warm() -> bool:
    import bearingsim

    bearingsim.run(_scenario(6000).replace(**{"numerics.rotations": 1}))
    return True


def main(argv=None) -> None:
    from distributed import LocalCluster

    from bearingsim.studies.uncertainty import run_uncertainty
    from bearingsim.sweeps.engines import DaskEngine

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=8)
    ap.add_argument("--rpm", type=int, default=3000)
    a = ap.parse_args(argv)
    sc = _scenario(a.rpm)
    load_before = os.getloadavg()[0]
    walls, runs = {}, None
    with tempfile.TemporaryDirectory(prefix="bearingsim-bench-unc-") as tmp:
        for n in (1, 2):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # dask's start-up notices
                with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                  host="127.0.0.1") as cluster:
                    eng = DaskEngine(cluster=cluster)
                    eng.start()
                    eng.client.run(_warm)
                    t0 = time.perf_counter()
                    res = run_uncertainty(sc, Path(tmp) / f"w{n}", samples=a.samples, seed=0, engine=eng)
                    walls[n] = time.perf_counter() - t0
                    runs = res.outcome.count("done") + res.outcome.count("cached")
    print(f"uncertainty of multibody_{a.rpm}rpm (rigid raceways, 1 + 10 rotations), N = {a.samples}, "
          f"{runs} runs; {os.cpu_count()} cores; load average {load_before:.2f} before, "
          f"{os.getloadavg()[0]:.2f} after")
    print("| workers | wall [s] | wall per run [s] | efficiency |")
    print("|---|---|---|---|")
    for n, w in walls.items():
        print(f"| {n} | {w:.1f} | {w / runs:.3f} | {walls[1] / (n * w):.2f} |")


if __name__ == "__main__":
    main()
