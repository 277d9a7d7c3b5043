"""``bearingsim bench --sweep``: how a multibody sweep scales over workers and engines;
``bearingsim bench --map``: what the 100 x 100 reduced-model map costs (:func:`run_map_bench`).

The same sweep (``CASES`` copies of ``scenarios/multibody_6000rpm.toml`` with ``numerics.rotations =
ROTATIONS``, differing only in ``name``, so every case does the same work) runs on a local pool and on
a dask ``LocalCluster`` (127.0.0.1 only), each with 1 and 2 workers, into a fresh folder each time.
Every worker has its compiled kernels loaded before the clock starts (the local pool forks a process
that has run a short case; the cluster's workers each run one), so the first case of a worker does not
carry numba's cache load.

Reported per run: ``wall_s`` (``run_sweep`` from call to return: validation, dispatch, archives,
index), ``case_s`` (the cases' own time, summed, measured around ``run_scenario`` in the worker),
``efficiency`` = wall(1 worker) / (2 wall(2 workers)) of the same engine, and the engine's
``overhead_per_case`` = (workers x wall - sum of case times) / cases, also as a share of the mean case
time. Idle workers at the end of an uneven split count as overhead.
"""
from __future__ import annotations

import os
import tempfile
import time
import warnings
from pathlib import Path

from bearingsim.outputs import write_csv

CASES = 8
ROTATIONS = 10
SCENARIO = "multibody_6000rpm.toml"


def _scenario_path() -> Path:
    return Path(__file__).resolve().parents[1] / "scenarios" / SCENARIO


def _warm() -> bool:
    """Run one short multibody case here (loads the compiled step loop into this process)."""
    from bearingsim.scenario import load_scenario
    from bearingsim.simulation import run_scenario

    sc = load_scenario(_scenario_path(), ["numerics.rotations=1", "numerics.warmup_rotations=1"])
    with tempfile.TemporaryDirectory() as tmp:
        run_scenario(sc, Path(tmp) / "warm.h5", figures=False)
    return True


def _spec():
    from bearingsim.sweeps.spec import SweepSpec

    return SweepSpec(scenario=_scenario_path(), sets=[f"numerics.rotations={ROTATIONS}"],
                     extra=[{"name": f"bench_{i}"} for i in range(CASES)], origin="bench --sweep")


def _measure(engine_name: str, workers: int, engine, root: Path) -> dict:
    from bearingsim.sweeps.run import run_sweep

    out = run_sweep(_spec(), root / f"{engine_name}_{workers}", engine=engine, figures=False, progress=False)
    if out.count("done") != CASES:
        errors = "; ".join(r["error"] for r in out.rows if r["error"])
        raise RuntimeError(f"bench sweep on {engine_name} x {workers}: not every case ran ({errors})")
    case_s = sum(r["wall_s"] for r in out.rows)
    over = (workers * out.wall_s - case_s) / CASES
    return {"engine": engine_name, "workers": workers, "cases": CASES, "wall_s": out.wall_s, "case_s": case_s,
            "mean_case_s": case_s / CASES, "overhead_per_case_s": over,
            "overhead_share": over / (case_s / CASES)}


def run_sweep_bench(outdir: str | Path = "outputs/bench") -> list[dict]:
    """Run the scaling bench, print its table, write ``sweep_scaling.csv`` in ``outdir``; return the rows."""
    from bearingsim.sweeps.engines import DaskEngine, LocalEngine

    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    load_before = os.getloadavg()[0]
    _warm()  # forked pool workers inherit the loaded kernels
    rows = []
    with tempfile.TemporaryDirectory(prefix="bearingsim-bench-sweep-") as tmp:
        root = Path(tmp)
        for n in (1, 2):
            eng = LocalEngine(n)
            eng.start()
            rows.append(_measure("local pool", n, eng, root))
        from distributed import LocalCluster

        for n in (1, 2):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # dask's start-up notices (ports in use, ...)
                with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                  host="127.0.0.1") as cluster:
                    eng = DaskEngine(cluster=cluster)
                    eng.start()
                    eng.client.run(_warm)  # every worker loads the kernels before the clock starts
                    rows.append(_measure("dask LocalCluster", n, eng, root))
    for kind in ("local pool", "dask LocalCluster"):
        one = next(r for r in rows if r["engine"] == kind and r["workers"] == 1)
        for r in rows:
            if r["engine"] == kind:
                r["efficiency"] = one["wall_s"] / (r["workers"] * r["wall_s"])
    path = write_csv(outdir / "sweep_scaling.csv", list(rows[0]), [list(r.values()) for r in rows])
    print(f"{CASES} cases of {SCENARIO} with numerics.rotations={ROTATIONS}; {os.cpu_count()} cores; "
          f"1-min load average {load_before:.2f} before, {os.getloadavg()[0]:.2f} after (other users' work "
          f"on the cores lowers the efficiency)")
    print(f"{'engine':18s} {'workers':>7s} {'wall [s]':>9s} {'mean case [s]':>13s} {'efficiency':>10s} "
          f"{'overhead/case [s]':>17s} {'share of case':>13s}")
    for r in rows:
        print(f"{r['engine']:18s} {r['workers']:7d} {r['wall_s']:9.2f} {r['mean_case_s']:13.2f} "
              f"{r['efficiency']:10.2f} {r['overhead_per_case_s']:17.3f} {100 * r['overhead_share']:12.1f}%")
    print(f"wrote {path}")
    return rows


def map_cost(outdir: str | Path, archives: bool = True, jobs: int = 2, figures: bool = False,
             quiet: bool = False) -> dict:
    """Run the 100 x 100 map ``scenarios/sweeps/map_speed_clearance.toml`` into ``outdir`` (a fresh
    folder: every case runs) and return what it cost: ``wall_s`` (from reading the sweep file to the
    end, index and, with ``figures``, the heat map included), ``done``, ``cached``, ``case_ms`` (the
    mean of the cases' own times in the workers) and ``cpu_sweep_s`` (CPU time of the sweep process
    itself: resolving, dispatch, index).

    With ``archives=False`` the workers (forked, so they inherit the change) solve each case without
    building or writing its archive: what the engine, the solver and the index cost without
    ``archive.py``. ``python -m benchmarks.sweep_bench map [--no-archives] OUTDIR``.
    """
    import resource

    import bearingsim.archive as archive
    import bearingsim.sweeps.worker as worker
    from bearingsim.sweeps.engines import LocalEngine
    from bearingsim.sweeps.run import run_sweep
    from bearingsim.sweeps.spec import load_sweep_file

    real = archive.to_bytes, worker._write_file
    if not archives:  # a reduced case's archive is built by to_bytes and written by _write_file
        archive.to_bytes = lambda result: b""
        worker._write_file = lambda target, data: None
    try:
        cpu0 = resource.getrusage(resource.RUSAGE_SELF)
        t0 = time.perf_counter()
        spec = load_sweep_file(_scenario_path().parent / "sweeps" / "map_speed_clearance.toml")
        out = run_sweep(spec, Path(outdir), engine=LocalEngine(jobs), figures=figures, progress=False)
        wall = time.perf_counter() - t0
        cpu1 = resource.getrusage(resource.RUSAGE_SELF)
    finally:
        archive.to_bytes, worker._write_file = real
    walls = [r["wall_s"] for r in out.rows if r["status"] == "done"]
    row = {"archives": archives, "workers": jobs, "cases": len(out.rows), "done": out.count("done"),
           "cached": out.count("cached"), "wall_s": wall,
           "case_ms": 1e3 * sum(walls) / max(1, len(walls)),
           "cpu_sweep_s": (cpu1.ru_utime + cpu1.ru_stime) - (cpu0.ru_utime + cpu0.ru_stime)}
    if not quiet:
        print(f"100 x 100 map, {'with' if archives else 'without'} archives, {jobs} workers: "
              f"{row['done']} done, {row['cached']} cached in {wall:.1f} s")
    return row


def run_map_bench(outdir: str | Path = "outputs/bench", jobs: int = 2) -> list[dict]:
    """``bearingsim bench --map``: the 100 x 100 reduced-model map with its archives, index and heat map
    (what ``bearingsim sweep scenarios/sweeps/map_speed_clearance.toml -j 2`` does), then again
    without archives; print the table, write ``map_cost.csv`` in ``outdir``; return the rows."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    load_before = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory(prefix="bearingsim-bench-map-") as tmp:
        rows.append(map_cost(Path(tmp) / "with", archives=True, jobs=jobs, figures=True, quiet=True))
        rows.append(map_cost(Path(tmp) / "without", archives=False, jobs=jobs, figures=False, quiet=True))
    path = write_csv(outdir / "map_cost.csv", list(rows[0]), [list(r.values()) for r in rows])
    print(f"100 x 100 map of the reduced model (scenarios/sweeps/map_speed_clearance.toml), {jobs} workers; "
          f"{os.cpu_count()} cores; 1-min load average {load_before:.2f} before, {os.getloadavg()[0]:.2f} after "
          f"(other users' work on the cores slows every row)")
    print(f"{'run':34s} {'cases':>6s} {'wall [s]':>9s} {'case in worker [ms]':>19s} {'sweep process CPU [s]':>21s}")
    names = {True: "archives, index, heat map", False: "no archives (solve, index)"}
    for r in rows:
        print(f"{names[r['archives']]:34s} {r['done']:6d} {r['wall_s']:9.1f} {r['case_ms']:19.2f} "
              f"{r['cpu_sweep_s']:21.1f}")
    print(f"wrote {path}")
    return rows


if __name__ == "__main__":  # pragma: no cover
    import sys

    if sys.argv[1:2] == ["map"]:
        map_cost(sys.argv[-1], archives="--no-archives" not in sys.argv)
    else:
        run_sweep_bench()
