"""Comparing two results: scenario keys, summary numbers, the results' other stored numbers (attribute groups:
the reduced model's wear rates, pass and operating point) and every array the run computed (each dataset under
``/results`` and each time series under ``/observables``), bit for bit: same dtype, same shape, same bytes (a NaN
equals a NaN of the same bits, -0.0 differs from 0.0). The provenance is not compared (its package versions are
listed beside a difference).

Used by ``bearingsim compare A.h5 B.h5`` and ``bearingsim rerun ARCHIVE``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bearingsim.scenario import differing_keys, same_value


@dataclass
class Comparison:
    """What differs between two results (empty lists: identical)."""

    scenario_keys: list[tuple[str, object, object]] = field(default_factory=list)
    summary: list[tuple[str, float, float]] = field(default_factory=list)  # every key of either (NaN where absent)
    absent: dict[str, str] = field(default_factory=dict)  # a summary key only one result has: "A" or "B", the other
    summary_differs: list[str] = field(default_factory=list)
    arrays_differ: list[str] = field(default_factory=list)
    how: dict[str, str] = field(default_factory=dict)  # how each of arrays_differ differs, by its name
    arrays_compared: int = 0  # the arrays and other numbers compared (of either result)
    unrecorded: dict[str, str] = field(default_factory=dict)  # an added array one archive predates: "A" or "B"
    #: the motion series not compared (the runs stored different motion: :func:`_stored_motion_differs`), and why
    unstored: list[str] = field(default_factory=list)
    unstored_why: str = ""
    versions: list[tuple[str, object, object]] = field(default_factory=list)

    @property
    def identical(self) -> bool:
        """True when every summary number, other stored number and compared array is bit-identical."""
        return not self.summary_differs and not self.arrays_differ

    def summary_table(self) -> str:
        """The summary numbers side by side with their absolute and relative difference."""
        rows = [f"{'summary':34s} {'A':>14s} {'B':>14s} {'B - A':>11s} {'(B - A)/|A|':>11s}"]
        for k, a, b in self.summary:
            mark = "" if k not in self.summary_differs else "  *"
            if k in self.absent:  # a number of one model only (the multibody model's cage slip, say)
                cells = [f"{'(none)':>14s}" if self.absent[k] == side else f"{v:14.7g}" for side, v in (("A", a), ("B", b))]
                rows.append(f"{k:34s} {cells[0]} {cells[1]} {'':>11s} {'':>11s}{mark}")
                continue
            rows.append(f"{k:34s} {a:14.7g} {b:14.7g} {b - a:11.3g} {relative_change(a, b):>11s}{mark}")
        if self.summary_differs:
            rows.append(f"* : not bit-identical, however small the difference; {SIGNIFICANCE_HINT}")
        return "\n".join(rows)

    def difference_lines(self, shown: int = 8) -> list[str]:
        """The arrays and other numbers that differ, the first ``shown`` with how (their largest difference),
        then how many more, then how many were compared."""
        lines = [f"  differs: {k} ({self.how.get(k, 'differs')})" for k in self.arrays_differ[:shown]]
        if len(self.arrays_differ) > shown:
            lines.append(f"  ... and {len(self.arrays_differ) - shown} more")
        if self.arrays_differ:
            lines.append(f"  {len(self.arrays_differ)} of {self.arrays_compared} arrays and other numbers differ "
                         "(bit for bit)")
        return lines + self.unrecorded_lines()

    def version_lines(self, a: str = "A", b: str = "B") -> list[str]:
        """One line for each version that differs between the two results' provenance (the model's, a
        package's), ``a`` and ``b`` naming them: where numbers differ, a likely cause (another numpy can round
        a transcendental function's last digit otherwise: the same scenario gives bit-identical numbers on one
        installation)."""
        lines = []
        for k, va, vb in self.versions:
            if k == "model_version":
                lines.append(f"  model version: {a} {va}, {b} {vb} (bumped when a change moves the model's numbers: "
                             "CHANGELOG.md says which)")
            else:
                lines.append(f"  package version {k.removeprefix('version_')}: {a} {va}, {b} {vb}")
        return lines

    def unrecorded_lines(self) -> list[str]:
        """One line for each array that one archive holds and the other, written by an earlier version, predates
        (:attr:`bearingsim.results.Result.ADDED_ARRAYS`): not compared, and no difference of the run."""
        lines = [f"  not in {side}: {k} (recorded by later versions than the one that wrote {side}; not compared)"
                 for k, side in self.unrecorded.items()]
        if self.unstored:
            lines.append(f"  not compared: {len(self.unstored)} motion series (what a run stores for animations "
                         f"beyond its results; {self.unstored_why})")
        return lines


def relative_change(a: float, b: float) -> str:
    """The ``(B - A)/|A|`` cell: ``0`` for equal numbers (0 and 0 too), ``from 0`` where A is 0 and B is not
    (a change from zero has no relative size: the ``B - A`` cell says how large it is), else the ratio
    (``nan`` where a number is NaN)."""
    if a == b:
        return "0"
    if a == 0.0:
        return "from 0"
    return f"{(b - a) / abs(a):.3g}"


#: where a difference is judged against the runs' scatter (the marks of this module are bit-for-bit)
SIGNIFICANCE_HINT = "'bearingsim table A B' marks the differences beyond the runs' standard errors"


def compare_results(a, b) -> Comparison:
    """Compare results ``a`` and ``b`` (:class:`bearingsim.results.Result`)."""
    c = Comparison()
    c.scenario_keys = differing_keys(a.scenario.raw, b.scenario.raw)
    sa, sb = a.summary, b.summary
    for k in list(sa) + [k for k in sb if k not in sa]:
        va, vb = sa.get(k, float("nan")), sb.get(k, float("nan"))
        c.summary.append((k, va, vb))
        if k not in sa or k not in sb:
            c.absent[k] = "A" if k not in sa else "B"
        if k not in sa or k not in sb or not same_bits(va, vb):
            c.summary_differs.append(k)
    models = getattr(a, "model", None), getattr(b, "model", None)
    # an array a later version of the model added, which an archive of an earlier one predates; between two models'
    # results an array of one only is that model's, and differs as any other
    added = (getattr(type(a), "ADDED_ARRAYS", frozenset()) | getattr(type(b), "ADDED_ARRAYS", frozenset())
             if models[0] == models[1] else frozenset())
    c.unstored_why = _stored_motion_differs(a, b)
    for pa, pb in ((compared_arrays(a), compared_arrays(b)), (other_numbers(a), other_numbers(b))):
        for k in list(pa) + [k for k in pb if k not in pa]:
            if (k not in pa or k not in pb) and f"results/{k}" in added:
                c.unrecorded[k] = "A" if k not in pa else "B"
                continue
            if c.unstored_why and k.startswith(MOTION_SERIES):
                c.unstored.append(k)
                continue
            c.arrays_compared += 1
            how = "only in B" if k not in pa else "only in A" if k not in pb else how_differs(pa[k], pb[k])
            if how is not None:
                c.arrays_differ.append(k)
                c.how[k] = how
    named = ("bearingsim_version", "model_version")  # and every version_<package>
    va = {k: v for k, v in a.provenance.items() if k.startswith("version_") or k in named}
    vb = {k: v for k, v in b.provenance.items() if k.startswith("version_") or k in named}
    for k in sorted(set(va) | set(vb)):
        if va.get(k) != vb.get(k):
            c.versions.append((k, va.get(k, "?"), vb.get(k, "?")))
    if models[0] != models[1]:  # two models' versions are not versions of one model: each named with its model
        c.versions = [(k, f"{x} ({models[0]} model)", f"{y} ({models[1]} model)") if k == "model_version" else (k, x, y)
                      for k, x, y in c.versions]
    return c


#: the names (:func:`compared_arrays`) of the motion a multibody run stores for animations: the bodies' states
#: over the window its ``[output]`` keys set, on which no number of the run depends (docs/archive.md)
MOTION_SERIES = "observables/motion_"


def _stored_motion_differs(a, b) -> str:
    """Why the two results' motion series are not compared: their ``[output]`` keys differ (one stores no motion,
    or another window of it), said as those keys; "" when they are the same (the series are then compared bit
    for bit, as every other)."""
    out_a, out_b = (r.scenario.raw.get("output") or {} for r in (a, b))
    keys = differing_keys(out_a, out_b)
    return ("the runs store different motion: " + ", ".join(f"output.{k} {va!r} -> {vb!r}" for k, va, vb in keys)
            if keys else "")


def compared_arrays(result) -> dict[str, np.ndarray]:
    """The arrays compared bit for bit: every dataset under ``results/`` (by its name there) and the
    ``step``, ``time`` and ``value`` of every time series (``observables/<name>/<field>``), the series
    with the dtypes their archive stores (:class:`bearingsim.archive.TimeSeries`), so that a result in
    memory compares as its archive would."""
    arrays = {k.removeprefix("results/"): np.asarray(v.data) for k, v in result.data.items()
              if k.startswith("results/")}
    for name, s in getattr(result, "series", {}).items():  # a result-like object may hold no series
        for what, dtype in (("step", np.int64), ("time", np.float64), ("value", np.float64)):
            arrays[f"observables/{name}/{what}"] = np.asarray(getattr(s, what), dtype=dtype)
    return arrays


def same_bits(a, b) -> bool:
    """Two stored numbers are the same bit for bit: floats of one type with the same bits (-0.0 is not 0.0,
    NaN is NaN of the same bits), anything else :func:`bearingsim.scenario.same_value`."""
    if isinstance(a, (float, np.floating)) or isinstance(b, (float, np.floating)):
        return type(a) is type(b) and np.asarray(a).tobytes() == np.asarray(b).tobytes()
    return same_value(a, b)


def how_differs(x, y) -> str | None:
    """None when ``x`` and ``y`` are the same bit for bit (arrays: dtype, shape and bytes; text arrays: their
    text, which an archive stores as bytes), else a few words of how: dtype or shape, or the largest
    difference of numbers and where it is."""
    if not isinstance(x, np.ndarray) or not isinstance(y, np.ndarray):
        return None if same_bits(x, y) else f"{x!r} -> {y!r}"
    if x.dtype.kind in "US" or y.dtype.kind in "US":
        if x.dtype.kind == y.dtype.kind and x.shape == y.shape and x.tolist() == y.tolist():
            return None
        return f"shape {x.shape} -> {y.shape}" if x.shape != y.shape else f"{int(np.sum(x != y))} of {x.size} texts differ"
    if x.dtype != y.dtype:
        return f"dtype {x.dtype} -> {y.dtype}"
    if x.shape != y.shape:
        return f"shape {x.shape} -> {y.shape}"
    if x.tobytes() == y.tobytes():
        return None
    xf, yf = (np.ascontiguousarray(v).reshape(-1) for v in (x, y))
    differ = np.flatnonzero((xf.view(np.uint8).reshape(xf.size, -1) != yf.view(np.uint8).reshape(yf.size, -1)).any(1))
    with np.errstate(invalid="ignore", over="ignore"):
        d = np.abs(yf[differ].astype(np.float64) - xf[differ].astype(np.float64))
    d = np.where(np.isnan(d), -1.0, d)  # a NaN on one side: shown where no larger number differs
    i = differ[int(np.argmax(d))]
    at = np.unravel_index(i, x.shape)
    value = f"{d.max():.3g}" if d.max() > 0 else "0: the sign of a zero or a NaN's bits" if d.max() == 0 else "NaN"
    where = f" at [{', '.join(map(str, at))}]" if x.ndim else ""
    n = len(differ)
    return f"{n} of {x.size} values, largest |B - A| {value}{where}: {x[at].item()!r} -> {y[at].item()!r}"


def other_numbers(result) -> dict[str, object]:
    """Every stored value of the result's attribute groups but the summary's numbers (compared on their own),
    by ``group/name`` under ``results/``: the reduced model's wear rates, its pass and operating point, and
    the summary's text (a multibody run's ``scene``)."""
    from bearingsim.results import SUMMARY

    return {f"{g.removeprefix('results/')}/{k}": v for g, group in result.groups.items()
            for k, v in group.attrs.items() if g != SUMMARY or k not in result.summary}
