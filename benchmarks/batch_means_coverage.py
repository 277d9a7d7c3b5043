"""How well the batch-means standard error (bearingsim.stats.batch_sem) and the plain sd/sqrt(n) estimate the
error of a mean of correlated rotations, and how often +- 2 of the batch-means error covers the true mean
(docs/statistics.md, *The estimator*).

    python -m benchmarks.batch_means_coverage            # ~2 min on one core

AR(1) series y_t = phi y_(t-1) + e_t (e standard normal, 200 values of burn-in dropped), 20000 series of
n = 5, 10, 40 values for phi = -0.3, +0.3, +0.5 (seed 0). Prints, per phi and n, the rms batch-means error
over the true scatter of the means, the same for sd/sqrt(n), and the share of series whose mean lies within
+- 2 batch-means errors of 0.
"""
from __future__ import annotations

import argparse

import numpy as np

from bearingsim.stats import batch_sem


def parser() -> argparse.ArgumentParser:
    return argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)


def ar1(rng, phi: float, n: int, m: int) -> np.ndarray:
    e = rng.normal(size=(m, n + 200))
    y = np.zeros_like(e)
    for t in range(1, e.shape[1]):
        y[:, t] = phi * y[:, t - 1] + e[:, t]
    return y[:, 200:]


def main(argv=None) -> int:
    parser().parse_args(argv)
    rng = np.random.default_rng(0)
    print("| phi | n | batch means / true | plain / true | P(|mean| <= 2 SE) |")
    print("|---|---|---|---|---|")
    for phi in (-0.3, +0.3, +0.5):
        for n in (5, 10, 40):
            y = ar1(rng, phi, n, 20000)
            true = y.mean(1).std()
            sems = np.array([batch_sem(r) for r in y])
            bm = np.sqrt(np.mean(sems ** 2))
            plain = np.sqrt(np.mean(y.var(1, ddof=1) / n))
            cover = np.mean(np.abs(y.mean(1)) <= 2 * sems)
            print(f"| {phi:+.1f} | {n} | {bm / true:.2f} | {plain / true:.2f} | {cover:.3f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
