"""Stability scan of the multi-pocket model: the largest time step per scene, speed and load.

``python -m benchmarks.stability [--quick]`` bisects, for each scene, inner-ring speed and
radial load, the largest dt at which one cage rotation (after none of warm-up, from the start state)

* **runs**: finishes without a blow-up (non-finite state, raceway approach > 50 um, cage faster than
  3 omega_i, or a roller more than s/2 into a cage face: the checks of :func:`core.run`);
* **is accurate**: in addition, no roller overlaps a cage face by more than 1 % of the pocket
  clearance (the bound the automatic dt restarts on).

It prints a markdown table beside the explicit Hertz limit 2/omega_n of the stiffest raceway contact
and the automatic dt, for ``docs/stability.md``. Bisection on a log scale to 5 % between 1 us and
40 us; one rotation is a short test, so a dt reported stable can still fail later in a long run: the
automatic dt keeps a factor 2 below the Hertz limit.
"""
from __future__ import annotations

import argparse
import math
import time

from bearingsim.errors import SimulationUnstable, UserError
from bearingsim.multibody.core import PenetrationExceeded, choose_dt, run
from benchmarks.multibody_bench import reference_scenario
from bearingsim.parameters import Parameters


def _ok(sc, dt, limit):
    try:
        run(sc, dt=dt, penetration_limit=limit)
        return True
    except (SimulationUnstable, PenetrationExceeded, UserError):  # UserError: above the refusal threshold
        return False


def largest_dt(sc, limit, lo=1e-6, hi=4e-5, tol=1.05):
    """Bisect (log scale) between ``lo`` and ``hi``; ``lo`` is probed last, only if nothing above ran
    (small steps are the expensive probes). NaN if even ``lo`` fails."""
    if _ok(sc, hi, limit):
        return hi
    lo0 = lo
    while hi / lo > tol:
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if _ok(sc, mid, limit) else (lo, mid)
    if lo == lo0 and not _ok(sc, lo, limit):
        return float("nan")
    return lo


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="fewer speeds and loads")
    a = ap.parse_args(argv)
    speeds = (1000, 6000) if a.quick else (1000, 3000, 6000, 12000)
    loads = (970.0,) if a.quick else (300.0, 970.0, 5000.0, 20000.0)
    print("| scene | rpm | load N | inner ring | 2/omega_n [us] | auto dt [us] | largest dt that runs [us] "
          "| largest dt with overlap <= 1 % s [us] | scan s |")
    print("|---|---|---|---|---|---|---|---|---|")
    from bearingsim.multibody.core import inner_ring_model

    for scene in ("full", "reduced_equivalent"):
        for rpm in speeds:
            for load in (loads if scene == "full" else (970.0,)):
                sc = Parameters.from_scenario(reference_scenario(rpm, 1, 0, scene=scene, load=load, source="<stability>"))
                t0 = time.perf_counter()
                auto, _, lim = choose_dt(sc)
                run_dt = largest_dt(sc, 0.5)
                acc_dt = largest_dt(sc, 0.01)
                ring = inner_ring_model(sc)[1].split(",")[0].split(";")[0]
                print(f"| {scene} | {rpm} | {load:g} | {ring} | {lim * 1e6:.2f} | {auto * 1e6:.2f} | "
                      f"{run_dt * 1e6:.2f} | {acc_dt * 1e6:.2f} | {time.perf_counter() - t0:.0f} |", flush=True)


if __name__ == "__main__":
    main()
