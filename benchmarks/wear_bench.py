"""Wear-profile cost and the life study's time (docs/wear.md).

``python -m benchmarks.wear_bench cost``: solver time per run with the wear profile recorded and with it
switched off (psi_hi = psi_lo: the kernel skips it), repeats interleaved. ``python -m benchmarks.wear_bench
life``: ``bearingsim life`` of the wear-test scene, fast scene, 10 stages, at the default mapping, wall time.
``cost`` is the default; it runs each of its three rows 7 times (minutes); ``life`` takes about 10 s
(docs/wear.md). Both print their numbers and write nothing (the life study goes to a temporary folder).
"""
from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np


def _solver_s(sc, profile: bool) -> float:
    from bearingsim import multibody
    from bearingsim.multibody import core
    from bearingsim.parameters import Parameters

    real = core.rk.RecorderConfig

    def off(**kw):
        kw["psi_hi"] = kw["psi_lo"]
        return real(**kw)

    core.rk.RecorderConfig = real if profile else off
    try:
        raw = multibody.simulate(Parameters.from_scenario(sc)).raw  # (with its restarts at a shorter step)
    finally:
        core.rk.RecorderConfig = real
    return raw.loop_s  # the step loop of the last (kept) run


def cost(repeats: int = 3) -> None:
    from bearingsim.scenario import load_scenario

    rows = [("hertz 6000 rpm, 5 rot", ["numerics.rotations=5"]),
            ("rigid 6000 rpm, 40 rot", ["numerics.rotations=40", "multibody.raceway_contact=rigid"]),
            ("hertz 1000 rpm, 3 rot", ["numerics.rotations=3", "operating.inner_ring_speed_rpm=1000"])]
    print("| run | loop s, profile off (median) | profile on (median) | on / off |")
    print("|---|---|---|---|")
    for name, sets in rows:
        sc = load_scenario("scenarios/wear_test_6000rpm.toml", sets)
        _solver_s(sc, True)  # compile
        on, off = [], []
        for _ in range(repeats):
            off.append(_solver_s(sc, False))
            on.append(_solver_s(sc, True))
        a, b = float(np.median(off)), float(np.median(on))
        print(f"| {name} | {a:.3f} | {b:.3f} | {b / a:.3f} |")


def life(stages: int = 10, rotations: int = 10) -> None:
    from bearingsim.scenario import load_scenario
    from bearingsim.studies.life import parse_limit, read_life, run_life

    sc = load_scenario("scenarios/wear_test_6000rpm.toml", ["multibody.raceway_contact=rigid"])
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        cols = run_life(sc, d, parse_limit("depth=0.1mm"), stages=stages, rotations=rotations)  # default mapping
        wall = time.perf_counter() - t0
        mapping = read_life(f"{d}/life.h5")[1]["mapping"]
    print(f"life, fast scene 6000 rpm, mapping {mapping} (the default), {stages} stages x (1 warm-up + {rotations} "
          f"rotations): {wall:.1f} s wall; {cols['hours_end'][-1]:.4g} h to depth 0.1 mm")


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.wear_bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", nargs="?", choices=("cost", "life"), default="cost", help="(default: %(default)s)")
    return ap


def main(argv=None) -> None:
    {"cost": cost, "life": life}[parser().parse_args(argv).what]()


if __name__ == "__main__":
    main()
