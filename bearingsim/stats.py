"""The one standard error of bearingsim: batch means over rotations.

Every command and study that reports the standard error of a mean impulse (``bearingsim sweep``'s
index, ``bearingsim crosscheck``, ``bearingsim validate``'s rig table, ``bearingsim table``) computes it
here, so that one archive gets one standard error wherever it is read (``docs/statistics.md``).

Why batch means: successive cage rotations of the multi-pocket model are correlated (the cage's whirl
and the rollers' phases carry over from one rotation to the next), so the sample standard deviation
of the per-rotation values over sqrt(rotations) underestimates the error of their mean. The means of
:data:`BATCHES` contiguous batches of rotations are much closer to independent; their scatter over
sqrt(batches) estimates the error of the overall mean. With fewer rotations than batches each batch is
one rotation (the plain estimate); with fewer than 2 rotations there is none (NaN). The reduced model
repeats one pass every rotation: its standard error is 0 by construction.

The one rule that calls a difference of two means significant is here too (:func:`significant`: the
marks of ``bearingsim table``, ``compare``, a sweep's table and a report, and the cross-check's verdicts).

A leaf module (numpy only): every layer may use it.
"""
from __future__ import annotations

import math

import numpy as np

#: contiguous batches of rotations whose means estimate the standard error
BATCHES = 5


#: a difference is significant when it exceeds this many standard errors of the difference
SIGNIFICANCE_SE = 2.0
#: ... and this fraction of the larger of the two numbers, below which it is round-off. The reduced model's
#: standard error is 0 (it is deterministic), so without a floor any difference was marked, also one in the
#: last bits: a clearance changes the flight by round-off, and I_dec read 0.007832783677204172, ...178,
#: ...176 (1000 rpm, 0.16/0.20/0.24 mm). Measured: the reduced model with an input moved by 1e-16 to 3e-15
#: of itself (pocket_clearance_mm, 0.1/0.2/0.4 mm at 500-6000 rpm) moves I_dec and I_acc by at most 1.6e-12
#: of themselves with the event method (the event times' root finding amplifies the last bit, 1.6e-12 is
#: ~7000 machine epsilons) and 2e-15 with the Euler step (1000, 3000 rpm). 1e-9 lies 600 times above the
#: largest and 1e5 times below the 4 significant digits a table shows, so a difference a table resolves is
#: still marked (1000 against 6000 rpm differ by 20 %); a multibody run's two standard errors (a few 1e-3
#: of its mean) lie far above it, so its marks are unchanged.
ROUND_OFF_REL = 1e-9


def significant(x: float, se: float, x0: float, se0: float) -> bool | None:
    """True/False: whether ``x - x0`` exceeds :data:`SIGNIFICANCE_SE` standard errors of the difference
    and :data:`ROUND_OFF_REL` of the larger magnitude (round-off is no difference); None when it cannot
    be judged (a number or a standard error missing: None or NaN)."""
    vals = (x, se, x0, se0)
    if any(v is None or not math.isfinite(v) for v in vals):
        return None
    floor = ROUND_OFF_REL * max(abs(x), abs(x0))
    return abs(x - x0) > max(SIGNIFICANCE_SE * math.hypot(se, se0), floor)


def batch_sem(x, batches: int = BATCHES) -> float:
    """Standard error of the mean of a series of rotations from ``batches`` batch means [unit of x].

    ``np.array_split`` makes the batches (sizes differ by at most one rotation); NaN with fewer than
    2 values."""
    x = np.asarray(x, float).ravel()
    b = min(batches, len(x))
    if b < 2:
        return float("nan")
    means = np.array([c.mean() for c in np.array_split(x, b)])
    return float(means.std(ddof=1) / math.sqrt(b))


def pocket_means(per_rotation) -> np.ndarray:
    """The per-rotation series of a ``[rotations, pockets]`` array: each rotation averaged over the
    pockets (pockets of one rotation share the cage's motion: they are not independent samples)."""
    a = np.asarray(per_rotation, dtype=float)
    if a.ndim == 0 or a.size == 0:
        return np.array([])
    return a.reshape(a.shape[0], -1).mean(axis=1)


def impulse_standard_errors(per_rotation_I_dec, per_rotation_I_acc, model: str | None = None) -> dict[str, float]:
    """``{"I_dec_sem_Ns": ..., "I_acc_sem_Ns": ...}``: the standard errors of ``I_dec_mean_Ns`` and
    ``I_acc_mean_Ns`` from a result's ``per_rotation`` arrays ``[rotations, pockets]`` [N s]: the
    batch-means error (:func:`batch_sem`) of the pocket-mean series over rotations; 0 for the reduced
    model (``model == "reduced"``: every rotation repeats one pass, even a single one)."""
    if model == "reduced":
        return {"I_dec_sem_Ns": 0.0, "I_acc_sem_Ns": 0.0}
    return {"I_dec_sem_Ns": batch_sem(pocket_means(per_rotation_I_dec)),
            "I_acc_sem_Ns": batch_sem(pocket_means(per_rotation_I_acc))}


def result_standard_errors(result) -> dict[str, float]:
    """:func:`impulse_standard_errors` of a :class:`bearingsim.results.Result` (its model from its
    scenario, its arrays from ``per_rotation``)."""
    return impulse_standard_errors(result.per_rotation["I_dec"], result.per_rotation["I_acc"],
                                   getattr(result.scenario, "model", None))
