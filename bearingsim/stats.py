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

import functools
import math

import numpy as np

#: contiguous batches of rotations whose means estimate the standard error
BATCHES = 5


#: a difference is significant when it lies outside the central SIGNIFICANCE_LEVEL of its Student t
#: distribution: |x - x0| > t(1 - (1 - SIGNIFICANCE_LEVEL) / 2, nu) sqrt(se^2 + se0^2), nu the
#: Welch-Satterthwaite degrees of freedom of the two standard errors (each from its batches - 1). Two
#: standard errors (the rule before) marked 8 % of pairs of runs of equal true means and 12 % against an
#: exact reference (SE 0), each SE being a batch-means error from 5 batches (4 degrees of freedom).
SIGNIFICANCE_LEVEL = 0.95
ROUND_OFF_REL = 1e-9


def significant(x: float, se: float, x0: float, se0: float, batches: int = BATCHES,
                batches0: int = BATCHES) -> bool | None:
    """True/False: whether ``x - x0`` lies outside the central :data:`SIGNIFICANCE_LEVEL` of its error
    (:func:`critical_ses`: Student's t of the Welch-Satterthwaite degrees of freedom of ``se`` and ``se0``,
    each from ``batches`` / ``batches0`` batch means, :func:`sem_batches`) and exceeds :data:`ROUND_OFF_REL`
    of the larger magnitude (round-off is no difference); None when it cannot be judged (a number or a
    standard error missing: None or NaN; a non-zero standard error of a single batch mean)."""
    vals = (x, se, x0, se0)
    if any(v is None or not math.isfinite(v) for v in vals):
        return None
    floor = ROUND_OFF_REL * max(abs(x), abs(x0))
    t = critical_ses(se, se0, batches, batches0)
    if math.isnan(t):  # a standard error of one batch mean: no degrees of freedom, no t
        return None
    return abs(x - x0) > max(t * math.hypot(se, se0), floor)


def critical_ses(se: float, se0: float, batches: int = BATCHES, batches0: int = BATCHES) -> float:
    """How many standard errors of the difference, sqrt(se^2 + se0^2), a difference must exceed to be
    significant at :data:`SIGNIFICANCE_LEVEL` (two-sided): Student's t quantile of the Welch-Satterthwaite
    degrees of freedom (se^2 + se0^2)^2 / (se^4 / (batches - 1) + se0^4 / (batches0 - 1)); a standard error
    of exactly 0 (the reduced model) contributes none. 1.96 (normal) when neither has any (both 0)."""
    parts = [(e * e, b - 1) for e, b in ((se, batches), (se0, batches0)) if e > 0.0]
    if not parts:
        return t_quantile(0.5 + SIGNIFICANCE_LEVEL / 2, math.inf)
    if any(d < 1 for _, d in parts):
        return math.nan
    dof = sum(v for v, _ in parts) ** 2 / sum(v * v / d for v, d in parts)
    return t_quantile(0.5 + SIGNIFICANCE_LEVEL / 2, dof)


def sem_batches(rotations: int, batches: int = BATCHES) -> int:
    """The number of batch means :func:`batch_sem` takes for a series of ``rotations`` values (its standard
    error has that many less one degrees of freedom)."""
    return min(int(batches), int(rotations))


def t_sf(t: float, dof: float) -> float:
    """P(T > t) of Student's t with ``dof`` (> 0, not necessarily whole) degrees of freedom: half the
    regularised incomplete beta function I_{dof / (dof + t^2)}(dof / 2, 1 / 2) for t >= 0 (numpy-free,
    no scipy: this leaf module stays light). ``dof`` inf: the normal tail."""
    if math.isinf(dof):
        return 0.5 * math.erfc(t / math.sqrt(2.0))
    tail = 0.5 * _betainc(dof / 2.0, 0.5, dof / (dof + t * t))
    return tail if t >= 0.0 else 1.0 - tail


def t_quantile(p: float, dof: float) -> float:
    """The ``p`` quantile (0.5 <= p < 1) of Student's t with ``dof`` degrees of freedom: Newton's method on
    :func:`t_sf`, kept inside a bracket by bisection (within 1e-9 of scipy's for 1 to 1e6 degrees
    of freedom and p up to 0.99999)."""
    if p <= 0.5:
        return 0.0
    lo, hi = 0.0, 1.0
    while t_sf(hi, dof) > 1.0 - p:
        lo, hi = hi, 2.0 * hi
    t = 0.5 * (lo + hi)
    for _ in range(200):
        excess = t_sf(t, dof) - (1.0 - p)  # > 0: t below the quantile
        lo, hi = (t, hi) if excess > 0.0 else (lo, t)
        step = excess / _t_pdf(t, dof)
        new = t + step if lo < t + step < hi else 0.5 * (lo + hi)
        if abs(new - t) <= 1e-13 * new or hi - lo <= 1e-13 * hi:
            return new
        t = new
    return t


def _t_pdf(t: float, dof: float) -> float:
    """The density of Student's t with ``dof`` degrees of freedom (inf: the normal's) at ``t``."""
    if math.isinf(dof):
        return math.exp(-0.5 * t * t) / math.sqrt(2.0 * math.pi)
    return math.exp(math.lgamma((dof + 1.0) / 2.0) - math.lgamma(dof / 2.0) - 0.5 * math.log(dof * math.pi)
                    - (dof + 1.0) / 2.0 * math.log1p(t * t / dof))


def _betainc(a: float, b: float, x: float) -> float:
    """The regularised incomplete beta function I_x(a, b) (continued fraction, modified Lentz; Numerical
    Recipes 6.4), to machine precision."""
    if x <= 0.0 or x >= 1.0:
        return 0.0 if x <= 0.0 else 1.0
    if x > (a + 1.0) / (a + b + 2.0):
        return 1.0 - _betainc(b, a, 1.0 - x)
    front = math.exp(math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x)) / a
    tiny = 1e-300
    c, d = 1.0, 1.0 - (a + b) * x / (a + 1.0)
    d = 1.0 / (d if abs(d) > tiny else tiny)
    f = d
    for m in range(1, 500):
        for num in (m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m)),
                    -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1))):
            d = 1.0 + num * d
            d = 1.0 / (d if abs(d) > tiny else tiny)
            c = 1.0 + num / c
            c = c if abs(c) > tiny else tiny
            f *= c * d
        if abs(c * d - 1.0) < 1e-15:
            break
    return front * f


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


def pocket_cov(means) -> float:
    """Coefficient of variation (standard deviation, ÷ n, over the mean) of the pockets' means ``(pockets,)``
    [-]; NaN for a mean <= 0. ``bearingsim wear`` prints it per face, and a run's note of uneven pockets judges
    it (:func:`pocket_spread_critical`)."""
    v = np.asarray(means, dtype=float).ravel()
    return float(v.std() / v.mean()) if v.size and v.mean() > 0 else float("nan")


def pocket_sampling_cov(per_rotation) -> float:
    """The coefficient of variation over pockets that identical pockets would show from the rotations' scatter
    alone, of a ``[rotations, pockets]`` array [-]: the pockets' mean standard error of their mean (the
    batch-means error over the rotations, :func:`batch_sem`) over the overall mean; NaN with fewer than 2
    rotations or a mean <= 0. :func:`pocket_cov` near it is that scatter, not a difference of the pockets:
    both fall as 1/sqrt(rotations)."""
    v = np.asarray(per_rotation, dtype=float)
    if v.ndim != 2 or v.shape[0] < 2 or not v.mean() > 0.0:
        return float("nan")
    return float(np.mean([batch_sem(v[:, i]) for i in range(v.shape[1])]) / v.mean())


def pocket_spread_critical(pockets: int, rotations: int, false_alarm: float) -> float:
    """The ratio :func:`pocket_cov` / :func:`pocket_sampling_cov` that identical pockets exceed in a share
    ``false_alarm`` of runs: with P pocket means scattering independently and normally about one mean, P cov² /
    s² is chi-square of P - 1 degrees of freedom (s the standard error, relative), and s estimated from B batch
    means per pocket (:func:`sem_batches`) makes (P / (P - 1)) (c4 cov / s)² Fisher's F of P - 1 and P (B - 1);
    c4 (:func:`c4`) corrects the mean of the pockets' standard errors, which reads sigma c4 on average, not
    sigma. So the ratio is sqrt((P - 1) / P F(1 - false_alarm)) / c4 (16 pockets, 5 batches, 5e-4: 1.86).
    NaN with fewer than 2 pockets or rotations."""
    b = sem_batches(rotations)
    if pockets < 2 or b < 2:
        return float("nan")
    f = f_quantile(1.0 - false_alarm, pockets - 1, pockets * (b - 1))
    return math.sqrt((pockets - 1) / pockets * f) / c4(b)


def c4(n: int) -> float:
    """The mean of the sample standard deviation (ddof 1) of ``n`` (>= 2) normal values over their sigma:
    sqrt(2 / (n - 1)) Gamma(n / 2) / Gamma((n - 1) / 2) (0.798 for 2, 0.940 for 5)."""
    return math.sqrt(2.0 / (n - 1)) * math.exp(math.lgamma(n / 2.0) - math.lgamma((n - 1) / 2.0))


@functools.lru_cache(maxsize=None)
def expected_normal_max(n: int) -> float:
    """E[max of ``n`` independent standard normal values]: the integral of x n phi(x) Phi(x)^(n - 1) over x
    (trapezoids of 1e-3 over -12..12; 1.766 for 16, 0 for 1)."""
    x = np.linspace(-12.0, 12.0, 24001)
    phi = np.exp(-0.5 * x * x) / math.sqrt(2.0 * math.pi)
    cdf = 0.5 * (1.0 + np.array([math.erf(v / math.sqrt(2.0)) for v in x]))
    y = x * n * phi * cdf ** (n - 1)
    return float(np.sum(0.5 * (y[1:] + y[:-1])) * (x[1] - x[0]))


def scatter_lead(per_rotation) -> float:
    """The lead over the pockets' mean [-, relative] that the worst of P identical pockets reads on average from
    the rotations' scatter alone, of a ``[rotations, pockets]`` array: :func:`expected_normal_max` (P) times the
    pockets' standard error of their mean relative to the mean, :func:`pocket_sampling_cov` / :func:`c4` (the
    mean of batch-means errors reads sigma c4 on average); NaN where :func:`pocket_sampling_cov` is."""
    v = np.asarray(per_rotation, dtype=float)
    sampling = pocket_sampling_cov(v)
    if not math.isfinite(sampling):
        return math.nan
    return expected_normal_max(v.shape[1]) * sampling / c4(sem_batches(v.shape[0]))


def f_sf(x: float, d1: float, d2: float) -> float:
    """P(F > x) of Fisher's F with ``d1`` and ``d2`` degrees of freedom: I_{d2 / (d2 + d1 x)}(d2 / 2, d1 / 2)."""
    if x <= 0.0:
        return 1.0
    return _betainc(d2 / 2.0, d1 / 2.0, d2 / (d2 + d1 * x))


def f_quantile(p: float, d1: float, d2: float) -> float:
    """The ``p`` quantile (0 < p < 1) of Fisher's F with ``d1`` and ``d2`` degrees of freedom: bisection on
    :func:`f_sf` (to 1e-12 relative)."""
    lo, hi = 0.0, 1.0
    while f_sf(hi, d1, d2) > 1.0 - p:
        lo, hi = hi, 2.0 * hi
    while hi - lo > 1e-12 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f_sf(mid, d1, d2) > 1.0 - p else (lo, mid)
    return 0.5 * (lo + hi)


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


#: the summary means :func:`summary_standard_errors` gives a standard error of (the key of the error), and its unit
SUMMARY_SEM_OF = {"I_dec_mean_Ns": "I_dec_sem_Ns", "I_acc_mean_Ns": "I_acc_sem_Ns",
                  "first_impact_speed_m_s": "first_impact_speed_sem_m_s", "cage_slip": "cage_slip_sem",
                  "load_zone_half_angle_deg": "load_zone_half_angle_sem_deg"}
SEM_UNITS = {"I_dec_sem_Ns": "N s", "I_acc_sem_Ns": "N s", "first_impact_speed_sem_m_s": "m/s", "cage_slip_sem": "1",
             "load_zone_half_angle_sem_deg": "deg"}


def first_impact_sem(per_rotation_first_impact, model: str | None = None) -> float:
    """The standard error of ``first_impact_speed_m_s`` (the mean of every recorded first rear-face impact,
    pockets and rotations pooled) from a result's ``per_rotation`` array ``first_impact_speed``
    ``[rotations, pockets]`` (NaN: no impact in that pass) [m/s]: the batches of :func:`batch_sem`, each with the
    sum S_b of its n_b impacts, and the pooled mean's ratio-estimator error
    ``sqrt(sum_b (S_b - m n_b)^2 / (B (B - 1))) / mean_b(n_b)``, m the pooled mean (with the same count in every
    batch: the batch means' error; with counts that differ it weighs a batch by its impacts, as the mean does).
    NaN with fewer than 2 rotations or no impact; 0 for the reduced model (``model == "reduced"``: one exact
    pass)."""
    if model == "reduced":
        return 0.0
    a = np.asarray(per_rotation_first_impact, dtype=float)
    if a.ndim == 0 or a.size == 0:
        return float("nan")
    rows = a.reshape(a.shape[0], -1)
    b = sem_batches(len(rows))
    if b < 2:
        return float("nan")
    parts = np.array_split(rows, b)
    sums = np.array([np.nansum(c) for c in parts])
    counts = np.array([np.isfinite(c).sum() for c in parts], dtype=float)
    if counts.sum() == 0:
        return float("nan")
    m = sums.sum() / counts.sum()
    return float(math.sqrt(np.sum((sums - m * counts) ** 2) / (b * (b - 1))) / counts.mean())


def summary_standard_errors(per_rotation, model: str | None = None) -> dict[str, float]:
    """The standard errors of a result's summary numbers (:data:`SUMMARY_SEM_OF`) from its ``per_rotation``
    arrays, a mapping holding ``I_dec`` and ``I_acc`` and, where the model records them, ``first_impact_speed``,
    ``cage_slip`` and ``load_zone_half_angle``: ``I_dec_sem_Ns`` and ``I_acc_sem_Ns``
    (:func:`impulse_standard_errors`), ``first_impact_speed_sem_m_s`` (:func:`first_impact_sem`),
    ``cage_slip_sem`` and ``load_zone_half_angle_sem_deg`` (:func:`batch_sem` of the per-rotation series; the
    summary's numbers are those of the whole recording, which its rotations' values average to within their
    differences in length). The reduced model's, every rotation one exact pass: 0 for its impulses, first impact
    speed and load zone (it has no cage slip)."""
    se = impulse_standard_errors(per_rotation["I_dec"], per_rotation["I_acc"], model)
    if model == "reduced" or "first_impact_speed" in per_rotation:
        se["first_impact_speed_sem_m_s"] = first_impact_sem(per_rotation.get("first_impact_speed"), model)
    if model != "reduced" and "cage_slip" in per_rotation:
        se["cage_slip_sem"] = batch_sem(per_rotation["cage_slip"])
    if model == "reduced":
        se["load_zone_half_angle_sem_deg"] = 0.0
    elif "load_zone_half_angle" in per_rotation:
        se["load_zone_half_angle_sem_deg"] = batch_sem(per_rotation["load_zone_half_angle"])
    return se


def result_standard_errors(result) -> dict[str, float]:
    """:func:`summary_standard_errors` of a :class:`bearingsim.results.Result` (its model from its
    scenario, its arrays from ``per_rotation``)."""
    return summary_standard_errors(result.per_rotation, getattr(result.scenario, "model", None))


def with_error(v: float, e: float) -> str:
    """``v ± e`` as the tables show it: the error to 2 significant digits and the value to the same decimal place,
    trailing zeros kept (``18.30 ± 0.17``, ``14.4070 ± 0.0095``, ``1230 ± 170``), so the text says how many digits
    mean something; an error of 0 (an exact model's) or none (``n/a``) leaves the value at 4 significant digits,
    and so does one beyond 10 decimals or at or above 1e4 of the unit (a damaged archive's), then with the error
    to 2 significant digits."""
    if not math.isfinite(e):
        return f"{v:.4g} ± n/a"
    if e == 0.0:
        return f"{v:.4g} ± 0"
    e2 = float(f"{abs(e):.2g}")
    places = 1 - math.floor(math.log10(e2))
    if places > 10 or e >= 1e4:
        return f"{v:.4g} ± {e:.2g}"
    if places < 0:  # an error of 100 or more: both to its second digit, no decimals
        return f"{round(v, places):.0f} ± {e2:.0f}"
    return f"{v:.{places}f} ± {e:.{places}f}"
