"""Comparing two results: scenario keys, summary numbers, the results' other stored numbers (attribute groups:
the reduced model's wear rates, pass and operating point) and their per-rotation and wear arrays, bit for bit.

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
        if k not in sa or k not in sb or not same_value(va, vb):
            c.summary_differs.append(k)
    pa, pb = compared_arrays(a), compared_arrays(b)
    for k in list(pa) + [k for k in pb if k not in pa]:
        x, y = pa.get(k), pb.get(k)
        if x is None or y is None or x.shape != y.shape or not np.array_equal(x, y, equal_nan=x.dtype.kind == "f"):
            c.arrays_differ.append(k)
    ga, gb = other_numbers(a), other_numbers(b)
    for k in list(ga) + [k for k in gb if k not in ga]:
        if k not in ga or k not in gb or not same_value(ga[k], gb[k]):
            c.arrays_differ.append(k)
    va = {k: v for k, v in a.provenance.items() if k.startswith("version_") or k == "bearingsim_version"}
    vb = {k: v for k, v in b.provenance.items() if k.startswith("version_") or k == "bearingsim_version"}
    for k in sorted(set(va) | set(vb)):
        if va.get(k) != vb.get(k):
            c.versions.append((k, va.get(k, "?"), vb.get(k, "?")))
    return c


def compared_arrays(result) -> dict[str, np.ndarray]:
    """The arrays compared bit for bit (:data:`bearingsim.simulation.COMPARED`: per rotation and wear), by
    their name under ``results/``."""
    from bearingsim.simulation import COMPARED

    under = tuple(f"{p}/" for p in COMPARED)
    return {k.removeprefix("results/"): np.asarray(v.data) for k, v in result.data.items() if k.startswith(under)}


def other_numbers(result) -> dict[str, object]:
    """Every stored number of the result's attribute groups but the summary (compared on its own), by
    ``group/name`` under ``results/``: the reduced model's wear rates, its pass and operating point."""
    from bearingsim.results import SUMMARY

    return {f"{g.removeprefix('results/')}/{k}": v for g, group in result.groups.items() if g != SUMMARY
            for k, v in group.attrs.items()}
