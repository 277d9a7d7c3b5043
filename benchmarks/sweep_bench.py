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

From the checkout's root:

    python -m benchmarks.sweep_bench                                # the scaling bench (minutes)
    python -m benchmarks.sweep_bench map [--archives none|all] OUTDIR  # one run of the 100 x 100 map

The scaling bench runs the sweep four times in temporary folders (removed after) and writes
``outputs/bench/sweep_scaling.csv``; ``map`` runs the map (seconds to a minute on 2 workers) into ``OUTDIR``
with no figures, with one archive per case unless ``--archives none``, and prints one line.
"""
from __future__ import annotations

import argparse
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


def _size(paths) -> tuple[int, int]:
    """(number of files, bytes) of ``paths`` that exist."""
    sizes = [p.stat().st_size for p in paths if p.is_file()]
    return len(sizes), sum(sizes)


def map_cost(outdir: str | Path, archives: str = "all", jobs: int = 2, figures: bool = False,
             quiet: bool = False, resume: bool = True) -> dict:
    """Run the 100 x 100 map ``scenarios/sweeps/map_speed_clearance.toml`` into ``outdir`` (a fresh
    folder: every case runs) with the archive policy ``archives`` (``all``: one archive per case;
    ``auto``, the default of ``bearingsim sweep``: none for these reduced-model cases) and return what
    it cost: ``wall_s`` (from reading the sweep file to the end, index, ``map.h5`` and, with
    ``figures``, the heat map included), ``done``, ``case_ms`` (the mean of the cases' own times in the
    workers), ``cpu_sweep_s`` (CPU time of the sweep process itself: resolving, dispatch, index, map),
    ``map_write_s`` (writing ``map.h5`` once), the files and bytes of the case archives, the index
    (``sweep.h5`` + ``sweep.csv``) and ``map.h5``, and with ``resume`` ``resume_s``: the same sweep run
    again, every case cached (from its archive, or from its index row).
    ``python -m benchmarks.sweep_bench map [--archives none|all] OUTDIR``.
    """
    import resource

    import bearingsim.sweeps.grid as grid
    from bearingsim.sweeps.engines import LocalEngine
    from bearingsim.sweeps.run import run_sweep
    from bearingsim.sweeps.spec import load_sweep_file

    outdir = Path(outdir)
    map_s = []
    real = grid.write_map

    def timed(*a, **kw):
        t = time.perf_counter()
        try:
            return real(*a, **kw)
        finally:
            map_s.append(time.perf_counter() - t)

    grid.write_map = timed
    try:
        cpu0 = resource.getrusage(resource.RUSAGE_SELF)
        t0 = time.perf_counter()
        spec = load_sweep_file(_scenario_path().parent / "sweeps" / "map_speed_clearance.toml")
        out = run_sweep(spec, outdir, engine=LocalEngine(jobs), figures=figures, progress=False, archives=archives)
        wall = time.perf_counter() - t0
        cpu1 = resource.getrusage(resource.RUSAGE_SELF)
    finally:
        grid.write_map = real
    walls = [r["wall_s"] for r in out.rows if r["status"] == "done"]
    n_cases, case_bytes = _size((outdir / "cases").glob("*.h5"))
    row = {"archives": archives, "workers": jobs, "cases": len(out.rows), "done": out.count("done"),
           "cached": out.count("cached"), "wall_s": wall,
           "case_ms": 1e3 * sum(walls) / max(1, len(walls)),
           "cpu_sweep_s": (cpu1.ru_utime + cpu1.ru_stime) - (cpu0.ru_utime + cpu0.ru_stime),
           "map_write_s": map_s[-1] if map_s else float("nan"),
           "archive_files": n_cases, "archive_bytes": case_bytes,
           "index_bytes": _size([outdir / "sweep.h5", outdir / "sweep.csv"])[1],
           "map_bytes": _size([outdir / "map.h5"])[1], "resume_s": float("nan")}
    if resume:
        t0 = time.perf_counter()
        again = run_sweep(load_sweep_file(_scenario_path().parent / "sweeps" / "map_speed_clearance.toml"), outdir,
                          engine=LocalEngine(jobs), figures=False, progress=False, archives=archives)
        row["resume_s"] = time.perf_counter() - t0
        if again.count("cached") != len(again.rows):
            raise RuntimeError(f"bench --map: resume ran {again.count('done')} cases again")
    if not quiet:
        print(f"100 x 100 map, archives={archives}, {jobs} workers: {row['done']} done in {wall:.1f} s, "
              f"resumed in {row['resume_s']:.1f} s")
    return row


def run_map_bench(outdir: str | Path = "outputs/bench", jobs: int = 2) -> list[dict]:
    """``bearingsim bench --map``: the 100 x 100 reduced-model map as ``bearingsim sweep
    scenarios/sweeps/map_speed_clearance.toml -j 2`` runs it (index, ``map.h5``, heat map; no case
    archives), then with ``--archives all`` (one archive per case), each resumed once; print the
    table, write ``map_cost.csv`` in ``outdir``; return the rows."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    load_before = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory(prefix="bearingsim-bench-map-") as tmp:
        rows.append(map_cost(Path(tmp) / "map", archives="auto", jobs=jobs, figures=True, quiet=True))
        rows.append(map_cost(Path(tmp) / "all", archives="all", jobs=jobs, figures=True, quiet=True))
    path = write_csv(outdir / "map_cost.csv", list(rows[0]), [list(r.values()) for r in rows])
    print(f"100 x 100 map of the reduced model (scenarios/sweeps/map_speed_clearance.toml), {jobs} workers; "
          f"{os.cpu_count()} cores; 1-min load average {load_before:.2f} before, {os.getloadavg()[0]:.2f} after "
          f"(other users' work on the cores slows every row)")
    print(f"{'run':28s} {'wall [s]':>8s} {'case [ms]':>9s} {'sweep CPU [s]':>13s} {'map.h5 write [s]':>16s} "
          f"{'resume [s]':>10s} {'archives':>18s} {'index':>8s} {'map.h5':>8s}")
    names = {"auto": "map only (default)", "all": "--archives all"}
    for r in rows:
        arch = f"{r['archive_files']} / {r['archive_bytes'] / 1e6:.0f} MB" if r["archive_files"] else "none"
        print(f"{names[r['archives']]:28s} {r['wall_s']:8.1f} {r['case_ms']:9.2f} {r['cpu_sweep_s']:13.1f} "
              f"{r['map_write_s']:16.3f} {r['resume_s']:10.1f} {arch:>18s} {r['index_bytes'] / 1e6:6.1f}MB "
              f"{r['map_bytes'] / 1e6:6.1f}MB")
    print(f"wrote {path}")
    return rows


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.sweep_bench", description=__doc__,
                                 usage="%(prog)s [-h] [map [--archives {none,all}] OUTDIR]",
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", metavar="map", help="run the map once instead of the scaling bench")
    one = sub.add_parser("map", help="the 100 x 100 map into OUTDIR (see map_cost)",
                         description="Run the 100 x 100 reduced-model map into OUTDIR and print what it cost.")
    one.add_argument("--archives", choices=("none", "all"), default="all", help="(default: %(default)s)")
    one.add_argument("outdir", metavar="OUTDIR")
    return ap


def main(argv=None) -> None:
    a = parser().parse_args(argv)
    if a.command == "map":
        map_cost(a.outdir, archives=a.archives)
    else:
        run_sweep_bench()


if __name__ == "__main__":  # pragma: no cover
    main()
