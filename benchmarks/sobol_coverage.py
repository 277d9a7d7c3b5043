"""How often the uncertainty study's 95 % bootstrap intervals of the Sobol indices cover the true index, at the
sample counts the studies use (docs/sensitivity.md, *Limits of these numbers*).

    python -m benchmarks.sobol_coverage                 # N = 16 and 64, 200 seeds each: ~1 min on one core

The study's own design and estimators (``bearingsim.studies.uncertainty.design`` and ``sobol_indices``) on the
Ishigami function f = sin x1 + 7 sin^2 x2 + 0.1 x3^4 sin x1, x uniform on [-pi, pi]^3, whose indices are
known in closed form (Ishigami & Homma 1990; Saltelli et al., Global Sensitivity Analysis: The Primer, 2008):
S1 = 0.3139, 0.4424, 0 and ST = 0.5576, 0.4424, 0.2437. Prints, per N, the share of seeds whose interval holds
the true S1 and ST of each input (the bootstrap's own seed is the design's).
"""
from __future__ import annotations

import argparse
import math

import numpy as np

from bearingsim.studies.uncertainty import design, sobol_indices

S1_TRUE = np.array([0.3139, 0.4424, 0.0])
ST_TRUE = np.array([0.5576, 0.4424, 0.2437])


def ishigami(x: np.ndarray) -> np.ndarray:
    return np.sin(x[..., 0]) + 7.0 * np.sin(x[..., 1]) ** 2 + 0.1 * x[..., 2] ** 4 * np.sin(x[..., 0])


def coverage(n: int, seeds: int) -> tuple[np.ndarray, np.ndarray]:
    """The shares of ``seeds`` designs of ``n`` points whose 95 % intervals hold each true S1 and ST."""
    bounds = np.array([[-math.pi, math.pi]] * 3)
    c1, ct = np.zeros(3), np.zeros(3)
    for seed in range(seeds):
        a, b, ab = design(bounds, n, seed)
        s = sobol_indices(ishigami(a), ishigami(b), ishigami(ab), seed)
        c1 += (s["S1_low"] <= S1_TRUE) & (S1_TRUE <= s["S1_high"])
        ct += (s["ST_low"] <= ST_TRUE) & (ST_TRUE <= s["ST_high"])
    return c1 / seeds, ct / seeds


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.sobol_coverage", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", default="16,64", help="sample counts N, comma-separated (default 16,64)")
    ap.add_argument("--seeds", type=int, default=200, help="designs per N (default 200)")
    return ap


def main(argv=None) -> None:
    args = parser().parse_args(argv)
    print("| N | seeds | S1 covered (x1, x2, x3) | ST covered (x1, x2, x3) |")
    print("|---|---|---|---|")
    for n in (int(v) for v in args.samples.split(",")):
        c1, ct = coverage(n, args.seeds)
        print(f"| {n} | {args.seeds} | {', '.join(f'{v:.3f}' for v in c1)} | {', '.join(f'{v:.3f}' for v in ct)} |",
              flush=True)


if __name__ == "__main__":
    main()
