"""Does one run's standard error cover the scatter between runs? (docs/statistics.md)

``python -m benchmarks.replica_scatter [--replicas R] [--rotations N] [--jobs J] [--perturb step]
[--case RACEWAYS:RPM ...] [--others]`` runs the reference
bearing (as ``bearingsim bench --fast-scene``: 970 N, roller-guided cage, exact faces, 1 warm-up + N
recorded rotations) R times per case, replica k with the radial load ``970 N (1 + k 1e-9)`` and
everything else the same, the time step automatic. The whole bearing is chaotic: a change of the load by
parts per billion changes the trajectory at first in the last digits, and the difference grows until
the replicas are as different as independent runs (the column ``corr``: the correlation of two
replicas' per-rotation I_dec over the second half of the rotations, averaged over every pair, ~0 when
they have separated; its scatter between independent pairs is about 1 / sqrt(pairs x rotations / 2)). Its systematic effect on the mean is of the order of 1e-9 relative (I_dec changes by less
than its load's relative change), far below anything here. ``restarts``: replicas whose automatic step
was shortened after an overlap above the bound (they count as replicas all the same).

``--perturb step``: replica k runs at the case's automatic step times ``1 + k 1e-6``, given as the step
(``simulate(dt=...)``), which does not restart: a replica that meets an overlap above the bound stops,
and the column ``stopped`` counts those (their impulses are left out).

Per case it prints the mean of the replicas' mean I_dec, the standard deviation of those means (the
run-to-run scatter, ``sd``), the median of the replicas' own batch-means standard errors (``se``, what a
single run reports, :func:`bearingsim.stats.batch_sem`), their ratio ``sd / se``, and the interval in
which that ratio falls 95 % of the time when ``se`` is the true scatter and the means are normal
(the chi-square interval of a standard deviation from R values; ``se`` taken as exact, so the
interval is a little narrow). Beside them, a scatter that one odd replica does not set: ``robust sd``,
1.4826 x the median absolute deviation of the means from their median (the sd for normal values), and
``worst``: the largest deviation of a replica's mean from the median of the means, in units of that
replica's own ``se``. And the start's transient that one warm-up rotation leaves in the recorded ones:
``rotation 1`` and ``rotations 1-5``, the mean I_dec of the first recorded rotation and of the first
five against that of rotations 9 to N, relative, averaged over the replicas (± its standard error over
them); 5 is the default ``numerics.rotations``. With N below 9 these two columns are ``-``. ``--others`` adds a
table of the first impact speed, the cage slip and the load zone's half angle: per case the standard deviation
of the replicas' values against the median of their own standard errors
(:func:`bearingsim.stats.summary_standard_errors`), and the same 95 % range.
"""
from __future__ import annotations

import argparse
import math
import statistics
from concurrent.futures import ProcessPoolExecutor

import numpy as np

CASES = (("rigid", 1000.0), ("rigid", 3000.0), ("rigid", 6000.0), ("hertz", 3000.0))
#: the other summary numbers with a standard error (``--others``), each with the key of its error
OTHER_QUANTITIES = ("first_impact_speed_m_s", "cage_slip", "load_zone_half_angle_deg")
SEM_KEYS = {"first_impact_speed_m_s": "first_impact_speed_sem_m_s", "cage_slip": "cage_slip_sem",
            "load_zone_half_angle_deg": "load_zone_half_angle_sem_deg"}
LOAD_N = 970.0
LOAD_SCALE = 1e-9
STEP_SCALE = 1e-6


def _replica(job):
    """(I_dec mean, its batch-means standard error, per-rotation pocket-mean I_dec [N s], restarted) of one
    replica; None for a replica at a given step that stopped on the overlap bound."""
    from benchmarks.multibody_bench import reference_scenario
    from bearingsim.errors import SimulationUnstable
    from bearingsim.multibody import simulate
    from bearingsim.parameters import Parameters
    from bearingsim.stats import batch_sem, pocket_means

    raceway, rpm, rotations, load, dt = job
    try:
        res = simulate(Parameters.from_scenario(reference_scenario(rpm, rotations, 1, raceway_contact=raceway,
                                                                   load=load)), dt=dt)
    except SimulationUnstable:
        if dt is None:
            raise
        return None
    from bearingsim.stats import result_standard_errors

    series = pocket_means(np.asarray(res.get("per_rotation/I_dec")))
    restarted = "restarted" in str(res.provenance.get("dt_choice", ""))
    se = result_standard_errors(res)
    others = {k: (float(res.summary[k]), se.get(SEM_KEYS[k], math.nan)) for k in OTHER_QUANTITIES}
    return float(res.summary["I_dec_mean_Ns"]), batch_sem(series), series, restarted, others


def _automatic_dt(raceway: str, rpm: float) -> float:
    from benchmarks.multibody_bench import reference_scenario
    from bearingsim.multibody.core import choose_dt
    from bearingsim.parameters import Parameters

    return float(choose_dt(Parameters.from_scenario(reference_scenario(rpm, 1, 1, raceway_contact=raceway)))[0])


def chi_interval(replicas: int) -> tuple[float, float]:
    """95 % interval of s / sigma for the sample standard deviation s of ``replicas`` normal values."""
    from scipy.stats import chi2

    dof = replicas - 1
    return math.sqrt(chi2.ppf(0.025, dof) / dof), math.sqrt(chi2.ppf(0.975, dof) / dof)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--replicas", type=int, default=12)
    ap.add_argument("--rotations", type=int, default=40)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--perturb", choices=("load", "step"), default="load")
    ap.add_argument("--case", action="append", help="RACEWAYS:RPM, e.g. rigid:1000 (default: the four cases)")
    ap.add_argument("--others", action="store_true",
                    help="also a table of the first impact speed, cage slip and load zone: sd between runs / se")
    args = ap.parse_args(argv)
    cases = [(c.split(":")[0], float(c.split(":")[1])) for c in args.case] if args.case else CASES
    lo, hi = chi_interval(args.replicas)  # (with stopped replicas the interval is a little wider)
    how = (f"load {LOAD_N:g} N x (1 + k {LOAD_SCALE:g}), automatic step" if args.perturb == "load"
           else f"the automatic step x (1 + k {STEP_SCALE:g}), given")
    print(f"{args.replicas} replicas, 1 warm-up + {args.rotations} rotations; {how}")
    print("| raceways | rpm | mean I_dec [mN s] | sd between runs [mN s] | median se of one run [mN s] "
          f"| sd / se | 95 % range if se is right | robust sd [mN s] | worst [se] | rotation 1 [%] | rotations 1-5 [%] "
          "| corr | restarts | stopped |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    others = []  # (case, quantity, means, ses) for --others
    with ProcessPoolExecutor(args.jobs) as pool:
        for raceway, rpm in cases:
            if args.perturb == "load":
                jobs = [(raceway, rpm, args.rotations, LOAD_N * (1.0 + k * LOAD_SCALE), None)
                        for k in range(args.replicas)]
            else:
                dt = _automatic_dt(raceway, rpm)
                jobs = [(raceway, rpm, args.rotations, LOAD_N, dt * (1.0 + k * STEP_SCALE)) for k in range(args.replicas)]
            done = list(pool.map(_replica, jobs))
            out = [o for o in done if o is not None]
            stopped = len(done) - len(out)
            if len(out) < 2:
                print(f"| {raceway} | {rpm:g} | - | - | - | - | - | - | - | - | - | - | - | {stopped} |", flush=True)
                continue
            means = [o[0] for o in out]
            ses = [o[1] for o in out]
            sd = statistics.stdev(means)
            se = statistics.median(ses)
            med = statistics.median(means)
            robust = 1.4826 * statistics.median(abs(m - med) for m in means)
            worst = max(abs(m - med) / e for m, e in zip(means, ses))
            def start(k):  # the first k recorded rotations against rotations 9..N, % (mean, its standard error)
                if args.rotations < 9:  # no rotation 9..N to compare with
                    return "-"
                d = [100.0 * (o[2][:k].mean() / o[2][8:].mean() - 1.0) for o in out]
                return f"{statistics.fmean(d):+.2f} ± {statistics.stdev(d) / math.sqrt(len(d)):.2f}"

            half = args.rotations // 2
            c = np.corrcoef(np.array([o[2][half:] for o in out]))
            corr = float(c[np.triu_indices(len(out), 1)].mean())
            print(f"| {raceway} | {rpm:g} | {statistics.fmean(means) * 1e3:.3f} | {sd * 1e3:.3f} | "
                  f"{se * 1e3:.3f} | {sd / se:.2f} | {lo:.2f}-{hi:.2f} | {robust * 1e3:.4f} | {worst:.1f} | {start(1)} | {start(5)} | {corr:+.2f} | {sum(o[3] for o in out)} | {stopped} |",
                  flush=True)
            if args.others:
                others += [((raceway, rpm), q, [o[4][q][0] for o in out], [o[4][q][1] for o in out])
                           for q in OTHER_QUANTITIES]
    if args.others:
        print()
        print("| raceways | rpm | quantity | mean | sd between runs | median se of one run | sd / se "
              "| 95 % range if se is right |")
        print("|---|---|---|---|---|---|---|---|")
        for (raceway, rpm), q, means, ses in others:
            sd, se = statistics.stdev(means), statistics.median(ses)
            print(f"| {raceway} | {rpm:g} | {q} | {statistics.fmean(means):.6g} | {sd:.2g} | {se:.2g} | "
                  f"{sd / se:.2f} | {lo:.2f}-{hi:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
