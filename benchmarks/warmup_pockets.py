"""Where the first recorded rotation's excess comes from (docs/statistics.md, *One warm-up rotation leaves a
transient*).

    python -m benchmarks.warmup_pockets                 # rigid and Hertz raceways, 8 replicas each
    python -m benchmarks.warmup_pockets --contacts rigid --replicas 4

Pocket i's recorded rotation k is the cage travel [360 (W + k) - theta_i0, ...) with theta_i0 its start
angle in [0, 360) from the load-zone centre in the direction of rotation (docs/archive.md): pocket 0's first
window starts after W whole rotations, pocket i's (i >= 1) after 360 (W - 1) + 360 i / Z deg. This runs the
reference bearing at 3000 rpm (scenarios/multibody_3000rpm.toml, 20 recorded rotations) with W = 1 and
W = 2, replica k with the radial load 970 + k N (as the statistics study's replicas), and prints the
first recorded rotation's I_dec against the mean of rotations 9-20 (index 8 on), for the pockets whose
first window starts within the first cage rotation after the start (1-8 at W = 1: at most 180 deg in) and
the others, mean over the replicas +- its standard error.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import bearingsim

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "multibody_3000rpm.toml"


def excess(contact: str, warmup: int, replicas: int) -> dict[str, np.ndarray]:
    """First recorded rotation's I_dec / mean of rotations 9-20 - 1, per replica, for pockets 1-8, the
    others (9-15 and 0), and all."""
    out = {"1-8": [], "9-15, 0": [], "all": []}
    for k in range(replicas):
        sc = bearingsim.load_scenario(SCENARIO, set={
            "multibody.raceway_contact": contact, "numerics.rotations": 20, "numerics.warmup_rotations": warmup,
            "operating.radial_load_N": 970.0 + k})
        d = bearingsim.run(sc).per_rotation["I_dec"]  # [rotation, pocket]
        ex = d[0] / d[8:].mean(axis=0) - 1.0
        n = d.shape[1]
        out["1-8"].append(ex[1:n // 2 + 1].mean())
        out["9-15, 0"].append(np.r_[ex[n // 2 + 1:], ex[:1]].mean())
        out["all"].append(d[0].mean() / d[8:].mean() - 1.0)
    return {g: np.asarray(v) for g, v in out.items()}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--contacts", default="rigid,hertz", help="raceway contacts to run (default rigid,hertz)")
    ap.add_argument("--replicas", type=int, default=8)
    args = ap.parse_args(argv)
    print("| raceways | warm-up rotations | pockets 1-8 | pockets 9-15 and 0 | all pockets |")
    print("|---|---|---|---|---|")
    for contact in args.contacts.split(","):
        for warmup in (1, 2):
            ex = excess(contact, warmup, args.replicas)
            cells = [f"{v.mean() * 100:+.1f} ± {v.std(ddof=1) / np.sqrt(len(v)) * 100:.1f} %" for v in ex.values()]
            print(f"| {contact} | {warmup} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
