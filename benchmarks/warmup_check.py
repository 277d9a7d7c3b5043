"""What the start-transient check sees (docs/statistics.md, *One warm-up rotation leaves a transient*).

    python -m benchmarks.warmup_check                           # the published table (~5 min on one core)
    python -m benchmarks.warmup_check --contacts rigid --warmups 3 --rotations 5 7 --runs 20

Runs the reference bearing at 3000 rpm (scenarios/multibody_3000rpm.toml) with the given raceway contact,
warm-up and recorded rotations, run k with the radial load 970 + 0.01 k N, and counts the runs whose first
recorded rotation :func:`bearingsim.plausibility.transient_flagged` flags (whatever the rotation count: the
check's own minimum is not applied), with the mean offset of the first rotation and the median sd of the later
ones, relative to their mean.
"""
from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

import bearingsim
from bearingsim.plausibility import transient_flagged, transient_offset

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "multibody_3000rpm.toml"


def flagged(contact: str, warmup: int, rotations: int, runs: int) -> tuple[int, float, float]:
    """(runs flagged, mean relative offset of the first rotation, median relative sd of the later ones)."""
    hits, rels, sds = 0, [], []
    for k in range(runs):
        sc = bearingsim.load_scenario(SCENARIO, set={
            "multibody.raceway_contact": contact, "numerics.warmup_rotations": warmup,
            "numerics.rotations": rotations, "operating.radial_load_N": 970.0 + 0.01 * k})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the run's own notes
            r = bearingsim.run(sc)
        x = np.asarray(r.per_rotation["I_dec"], float).mean(axis=1)
        off = transient_offset(x)
        hits += transient_flagged(off)
        rels.append(off[0])
        sds.append(float(x[1:].std(ddof=1) / x[1:].mean()))
    return hits, float(np.mean(rels)), float(np.median(sds))


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--contacts", nargs="+", default=["hertz", "rigid"], help="raceway contacts")
    ap.add_argument("--warmups", nargs="+", type=int, default=[1], help="warm-up rotations")
    ap.add_argument("--rotations", nargs="+", type=int, default=[4, 5, 6, 7], help="recorded rotations")
    ap.add_argument("--runs", type=int, default=20, help="runs per row")
    return ap


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    print("| raceways | warm-up rotations | rotations | flagged | first rotation (mean) | later sd (median) |")
    print("|---|---|---|---|---|---|")
    for contact in args.contacts:
        for warmup in args.warmups:
            for rotations in args.rotations:
                hits, rel, sd = flagged(contact, warmup, rotations, args.runs)
                print(f"| {contact} | {warmup} | {rotations} | {hits} of {args.runs} | {rel:+.1%} | {sd:.2%} |",
                      flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
