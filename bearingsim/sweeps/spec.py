"""What a sweep is: a base scenario, overrides, axes and extra cases, resolved into cases.

A sweep is read either from the command line (``SCENARIO --param KEY=V1,V2 --set KEY=VALUE``; the
axes form a product) or from a sweep file::

    scenario = "../paper_3000rpm.toml"     # base scenario, relative to this file
    mode = "product"                        # or "zip": every axis has the same length

    [set]                                   # overrides applied to every case (like --set)
    "numerics.rotations" = 1

    [axes]                                  # one list of values per key
    "operating.inner_ring_speed_rpm" = [500, 1000, 2000]
    "bearing.pocket_clearance_mm" = { start = 0.1, stop = 0.4, num = 4 }   # evenly spaced, ends included

    [[cases]]                               # explicit extra cases (any keys)
    "operating.inner_ring_speed_rpm" = 6000
    "lubrication.drag_coefficient" = 0.05

Keys may be quoted dotted keys (as above) or nested tables (``[axes.operating]``). Every case is
resolved and validated before anything runs: a key given twice, an unknown key or a bad value stops
the sweep with a one-line :class:`~bearingsim.errors.UserError` naming it.

A case is identified by the content hash of its resolved scenario (:func:`case_hash`), which names
its archive ``cases/<hash>.h5``.
"""
from __future__ import annotations

import hashlib
import itertools
import math
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from bearingsim.errors import UserError
from bearingsim.scenario import (_with_override, check_run_request, is_integer_key, load_scenario,
                                 parse_override, read_toml_file)

SWEEP_FILE_KEYS = ("scenario", "mode", "set", "axes", "cases")
# Most cases in one sweep: ten times the 100 x 100 map of scenarios/sweeps/. Each case is resolved and
# held as a row before the first runs (100000 cases: ~1 GB of resolved scenarios in memory) and, with
# --archives all, writes an archive (~93 kB for the reduced model: ~9 GB on disk); more is a run to
# split into sweeps.
MAX_SWEEP_CASES = 100_000


@dataclass(frozen=True)
class Case:
    """One resolved case of a sweep.

    Attributes
    ----------
    hash : str
        First 16 hex digits of the SHA-256 of ``toml`` (names the archive).
    values : dict
        The swept keys and their values for this case (keys as given, dotted).
    toml : str
        The resolved scenario as TOML text (what the archive stores as ``/scenario``).
    model : str
        ``"reduced"`` or ``"multibody"`` (cheap reduced cases run in batches).
    scenario : optional
        The validated scenario model ``toml`` was written from (:func:`resolve_cases` keeps it, so a
        local pool's worker need not parse and validate the text again); None if not known.
    ran_at : dict
        The sweep's other swept keys, those this case does not set (an extra case's axes, a grid case's
        keys of the extra cases), with the value its resolved scenario has: what the case ran at, shown
        in the index beside ``values`` (:func:`resolve_cases`; empty where a key has no value).
    """

    hash: str
    values: dict[str, Any]
    toml: str
    model: str
    scenario: Any = field(default=None, compare=False, repr=False)
    ran_at: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def label(self) -> str:
        """``key=value, ...`` of the swept values, for messages: a number to 12 significant digits, so that a range's
        round-off (0.09000000000000001 of ``0.01:0.1:10``) does not show; the case's scenario holds the value itself."""
        return _label(self.values)


def _shown(value) -> str:
    """A swept value in a message: a float to 12 significant digits, anything else as it is."""
    return f"{value:.12g}" if isinstance(value, float) else str(value)


@dataclass
class SweepSpec:
    """A sweep before resolution: base scenario, overrides, axes and extra cases."""

    scenario: Path
    sets: list[str] = field(default_factory=list)
    axes: list[tuple[str, list]] = field(default_factory=list)
    mode: str = "product"
    extra: list[dict[str, Any]] = field(default_factory=list)
    origin: str = "--param"

    @property
    def size(self) -> int:
        """How many cases the sweep describes: the grid's rows (product or zip of the axes) and the extra
        cases (two of them that are the same scenario are refused when resolved)."""
        sizes = [len(v) for _, v in self.axes]
        grid = (math.prod(sizes) if self.mode != "zip" else max(sizes)) if sizes else 0
        return grid + len(self.extra)

    @property
    def keys(self) -> list[str]:
        """Every swept key: the axes' keys, then keys only set by extra cases, in order of appearance."""
        out = [k for k, _ in self.axes]
        for case in self.extra:
            out += [k for k in case if k not in out]
        return out


def case_hash(toml_text: str) -> str:
    """Content hash of a resolved scenario: the first 16 hex digits of SHA-256 of its TOML text."""
    return hashlib.sha256(toml_text.encode("utf-8")).hexdigest()[:16]


def toml_value(value: Any) -> str:
    """``value`` written as a TOML value (so ``KEY=<this>`` reads back the same value)."""
    import tomli_w

    return tomli_w.dumps({"v": value})[4:].strip()


PARAM_HELP = ("KEY=V1,V2,... (values as TOML; commas inside [ ], { } or quotes do not split) or "
              "KEY=START:STOP:NUM (NUM evenly spaced numbers, both ends included)")


def _split_top_level(text: str) -> list[str]:
    """``text`` split at the commas outside brackets, braces and quoted strings."""
    parts, depth, quote, cur = [], 0, "", []
    for ch in text:
        if quote:
            if ch == quote:
                quote = ""
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append("".join(cur))
            cur = []
            continue
        cur.append(ch)
    parts.append("".join(cur))
    return parts


def _range_values(item: str, key: str, text: str) -> list[float] | list[int] | None:
    """``START:STOP:NUM`` as :class:`_Range` values of ``key``; None if ``text`` is not of that form."""
    parts = text.split(":")
    if len(parts) < 2 or any(c in text for c in "[]{}\"'"):
        return None
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        return None
    if len(parts) != 3:  # numbers between colons: a range with a part missing or too many
        raise UserError(f"--param {item!r}: expected START:STOP:NUM (NUM evenly spaced numbers, both ends "
                        f"included), e.g. {key}={parts[0]}:{parts[1]}:3")
    try:
        num = int(parts[2])
    except ValueError:
        raise UserError(f"--param {item!r}: START:STOP:NUM needs an integer NUM >= 1") from None
    return _Range({"start": start, "stop": stop, "num": num}).values(f"--param {item!r}", key, text)


def parse_param(item: str) -> tuple[str, list]:
    """``KEY=V1,V2,...`` into (key, values), each value read as a TOML value (a bare word is a string;
    commas inside brackets, braces or quotes do not split), or ``KEY=START:STOP:NUM`` into ``NUM``
    evenly spaced values from START to STOP, both included."""
    if "=" not in item:
        raise UserError(f"--param {item!r}: expected {PARAM_HELP}")
    key, text = item.split("=", 1)
    key = key.strip()
    if not key or any(not part for part in key.split(".")):
        raise UserError(f"--param {item!r}: empty key; expected {PARAM_HELP}")
    values = _range_values(item, key, text.strip())
    if values is None:
        try:
            values = [parse_override(f"{key}={v}")[1] for v in _split_top_level(text) if v.strip()]
        except UserError as exc:  # a value refused as --set would be: named as the --param it is
            raise UserError(str(exc).replace("--set", "--param", 1)) from None
    if not key or not values:
        raise UserError(f"--param {item!r}: expected {PARAM_HELP}, with at least one value")
    return key, values


def _flatten(table: dict, where: str, prefix: str = "") -> dict[str, Any]:
    """Nested or dotted-key tables into one ``{dotted.key: value}``; a key reached twice is an error."""
    out: dict[str, Any] = {}
    for k, v in table.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict) and not _is_range(v):
            sub = _flatten(v, where, key + ".")
        else:
            sub = {key: v}
        for kk, vv in sub.items():
            if kk in out:
                raise UserError(f"{where}: {kk}: given twice")
            out[kk] = vv
    return out


_RANGE_KEYS = ("start", "stop", "num")


def _is_range(v) -> bool:
    return isinstance(v, dict) and set(v) == set(_RANGE_KEYS)


class _Range:
    """``{ start, stop, num }``: ``num`` evenly spaced values from start to stop, both included."""

    def __init__(self, table: dict):
        self.table = table

    def values(self, where: str, key: str = "", given: str = "") -> list[float] | list[int]:
        """The values, ints for a key the schema types as an integer (:func:`_whole`); ``given``: the
        command line's ``START:STOP:NUM`` (a sweep file's range otherwise), as a refusal quotes it."""
        import numpy as np

        start, stop, num = self.table["start"], self.table["stop"], self.table["num"]
        num_ok = isinstance(num, int) and not isinstance(num, bool) and num >= 1
        ends_ok = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (start, stop))
        if not (num_ok and ends_ok):  # in the form given: START:STOP:NUM on the command line
            form = "START:STOP:NUM needs an integer NUM >= 1" if given else ("{ start, stop, num } needs numbers "
                                                                            "and an integer num >= 1")
            raise UserError(f"{where}: {form}")
        if num > MAX_SWEEP_CASES:
            raise UserError(f"{where}: num = {num} is more than the {MAX_SWEEP_CASES} cases a sweep may have; "
                            "split it into several sweeps")
        if num == 1 and float(start) != float(stop):  # one value cannot include both ends
            raise UserError(f"{where}: num = 1 is one value, and start {start:g} and stop {stop:g} differ: both ends "
                            "are included from num = 2 (one value: start = stop, or a list)")
        # to 15 significant digits, as the ends are written: 0.05:0.5:10 gives 0.15, not 0.15000000000000002
        # (a value a reader of the map selects by, xarray's .sel(0.15), and that names the case)
        values = [float(f"{x:.15g}") for x in np.linspace(float(start), float(stop), num)]
        return _whole(values, key, where, given) if key and is_integer_key(key) else values


def _whole(values: list[float], key: str, where: str, given: str) -> list[int]:
    """Evenly spaced ``values`` of integer ``key`` as ints (10:20:3 -> 10, 15, 20: a strict integer key
    refuses 15.0); values that are not whole (10:20:4 -> 13.33) are refused, saying what to give instead."""
    bad = [v for v in values if not v.is_integer()]
    if not bad:
        return [int(v) for v in values]
    start, stop, num = values[0], values[-1], len(values)
    axis = given or f"{{ start = {start:g}, stop = {stop:g}, num = {num} }}"
    nums = _whole_nums(start, stop, num)
    rounded = list(dict.fromkeys(math.floor(v + 0.5) for v in values))
    if given:
        instead = f"a list ({key}={','.join(map(str, rounded))})" if num <= 10 else "a list of integers"
        instead += f" or a NUM that lands on whole numbers ({nums})" if nums else ", or a whole START and STOP"
    else:
        instead = f"a list ({rounded})" if num <= 10 else "a list of integers"
        instead += f" or a num that lands on whole numbers ({nums})" if nums else ", or a whole start and stop"
    shown = ", ".join(f"{v:.4g}" for v in bad[:3]) + (", ..." if len(bad) > 3 else "")
    what = f"{key} is an integer" if given else "an integer"  # a sweep file's ``where`` ends with the key
    raise UserError(f"{where}: {what}, and {axis} gives {shown}, not whole numbers; give {instead}")


def _whole_nums(start: float, stop: float, num: int) -> str:
    """The counts nearest ``num`` (one below, one above) whose evenly spaced values from whole ``start``
    to ``stop`` are whole numbers: a divisor of the span, plus one ("3 or 6" for 10 to 20, num 4); "" when
    an end is not whole."""
    if not (start.is_integer() and stop.is_integer()):
        return ""
    span = abs(int(stop) - int(start))
    below = next((c for c in range(num - 1, 1, -1) if span % (c - 1) == 0), None)
    above = next((c for c in range(num + 1, min(span + 1, MAX_SWEEP_CASES) + 1) if span % (c - 1) == 0), None)
    return " or ".join(str(c) for c in (below, above) if c is not None)


def _check_unique(keys: list[str], where: str) -> None:
    seen = set()
    for k in keys:
        if k in seen:
            raise UserError(f"{where}: {k}: given twice")
        seen.add(k)


def is_sweep_file(path: str | Path) -> bool:
    """A sweep file names its base ``scenario``; a scenario file has ``schema_version`` instead."""
    raw = read_toml_file(path)
    return "schema_version" not in raw and "scenario" in raw


def spec_from_args(target: str | Path, params: list[str], sets: list[str]) -> SweepSpec:
    """The sweep the command line describes: a sweep file (``--param``/``--set`` add to it) or a
    scenario with ``--param`` axes."""
    target = Path(target)
    if is_sweep_file(target):
        spec = load_sweep_file(target)
    else:
        spec = SweepSpec(scenario=target)
        if not params:
            raise UserError(f"{target}: a scenario needs at least one --param KEY=V1,V2,... to sweep "
                            "(or give a sweep file)")
    extra_axes = [parse_param(p) for p in params]
    if extra_axes and spec.mode == "zip":
        raise UserError(f"{target}: mode: --param adds a product axis; not allowed with mode = \"zip\"")
    spec.axes = spec.axes + extra_axes
    given = {parse_override(o)[0] for o in sets}  # the command line's --set overrides the file's [set], as
    spec.sets = [o for o in spec.sets if parse_override(o)[0] not in given] + list(sets)  # run's the scenario's
    return spec


def load_sweep_file(path: str | Path) -> SweepSpec:
    """Read a sweep file (see the module docstring) into a :class:`SweepSpec`."""
    path = Path(path)
    raw = read_toml_file(path)
    for k in raw:
        if k not in SWEEP_FILE_KEYS:
            raise UserError(f"{path}: {k}: unknown key in a sweep file (expected {', '.join(SWEEP_FILE_KEYS)})")
    base = raw.get("scenario")
    if not isinstance(base, str) or not base:
        raise UserError(f"{path}: scenario: must name the base scenario file")
    mode = raw.get("mode", "product")
    if mode not in ("product", "zip"):
        raise UserError(f"{path}: mode: must be \"product\" or \"zip\" (got {mode!r})")
    sets_tab = raw.get("set", {})
    axes_tab = raw.get("axes", {})
    cases = raw.get("cases", [])
    if not isinstance(sets_tab, dict):
        raise UserError(f"{path}: set: must be a table of KEY = VALUE")
    if not isinstance(axes_tab, dict):
        raise UserError(f"{path}: axes: must be a table of KEY = [values]")
    if not isinstance(cases, list) or not all(isinstance(c, dict) for c in cases):
        raise UserError(f"{path}: cases: must be an array of tables ([[cases]])")
    sets = _flatten(sets_tab, f"{path}: set")
    axes = _flatten(axes_tab, f"{path}: axes")
    for k in axes:
        parent, _, last = k.rpartition(".")
        if last in _RANGE_KEYS and parent:  # a range with a key missing or misspelt was read as a nested table
            got = ", ".join(kk.rpartition(".")[2] for kk in axes if kk.rpartition(".")[0] == parent)
            raise UserError(f"{path}: axes: {parent}: {{ start, stop, num }} needs exactly these three keys (got {got})")
    for k, v in axes.items():
        if _is_range(v):
            axes[k] = _Range(v).values(f"{path}: axes: {k}", k)
        elif not isinstance(v, list) or not v:
            raise UserError(f"{path}: axes: {k}: must be a non-empty list of values or {{ start, stop, num }}")
    extra = [_flatten(c, f"{path}: cases[{i}]") for i, c in enumerate(cases)]
    # its folder joined to the file's own reference, "../paper_3000rpm.toml" resolved: the path the index shows
    return SweepSpec(scenario=Path(os.path.normpath(path.parent / base)), sets=[f"{k}={toml_value(v)}" for k, v in sets.items()],
                     axes=list(axes.items()), mode=mode, extra=extra, origin=str(path))


def resolve_cases(spec: SweepSpec) -> list[Case]:
    """Every case of ``spec``, resolved and validated, in a fixed order (axes first, then extras).

    Raises
    ------
    UserError
        A key given twice (within the axes, or both in the overrides and swept), an unknown key,
        a bad value, unequal zipped axes, or two cases that resolve to the same scenario.
    """
    where = spec.origin
    axis_keys = [k for k, _ in spec.axes]
    _check_unique(axis_keys, where)
    set_keys = [parse_override(s)[0] for s in spec.sets]
    _check_unique(set_keys, f"{where} (--set / [set])")
    for k in set_keys:
        if k in axis_keys:
            raise UserError(f"{where}: {k}: given both as an override and as a swept axis")
    for i, case in enumerate(spec.extra):
        for k in case:
            if k in set_keys:
                raise UserError(f"{where}: cases[{i}]: {k}: given both as an override and in an extra case")
    if not spec.axes and not spec.extra:
        raise UserError(f"{where}: nothing to sweep (no axes and no cases)")
    sizes = [len(v) for _, v in spec.axes]
    total = spec.size
    if total > MAX_SWEEP_CASES:  # counted before any case is built
        shape = (" x " if spec.mode != "zip" else ", ").join(f"{k} ({n})" for (k, _), n in zip(spec.axes, sizes))
        raise UserError(f"{where}: {total} cases ({shape or 'extra cases'}) are more than the {MAX_SWEEP_CASES} a "
                        "sweep may have; split it into several sweeps")
    points: list[dict[str, Any]] = []
    if spec.axes:
        if spec.mode == "zip":
            lengths = {len(v) for _, v in spec.axes}
            if len(lengths) != 1:
                raise UserError(f"{where}: mode = \"zip\" needs axes of equal length (got "
                                + ", ".join(f"{k}: {len(v)}" for k, v in spec.axes) + ")")
            combos = zip(*[v for _, v in spec.axes])
        else:
            combos = itertools.product(*[v for _, v in spec.axes])
        points += [dict(zip(axis_keys, c)) for c in combos]
    points += [dict(c) for c in spec.extra]
    base = load_scenario(spec.scenario, spec.sets)  # the base alone first: its own errors name it
    given = {parse_override(s)[0]: s.strip() for s in spec.sets}  # the values the scenario file does not hold
    keys = spec.keys
    cases: list[Case] = []
    seen: dict[str, int] = {}
    for i, values in enumerate(points):
        try:
            sc = base.replace(**values)
            _check_case(sc)  # refused here as `bearingsim run` refuses it, before any case runs
        except UserError as exc:  # "FILE with KEY=VALUE: ..." for the overrides and the case's values it is about
            exc = _with_override(exc, base.source, {**given, **{k: f"{k}={v}" for k, v in values.items()}})
            raise UserError(f"{exc} (sweep case {_label(values)})") from None
        text = sc.to_toml()
        h = case_hash(text)
        if h in seen:
            raise UserError(f"{where}: cases {_label(points[seen[h]])} and {_label(values)} are the same scenario")
        seen[h] = i
        ran_at = {k: v for k in keys if k not in values and (v := resolved_value(sc, k)) is not None}
        cases.append(Case(hash=h, values=values, toml=text, model=sc.model, scenario=sc.model_, ran_at=ran_at))
    return cases


def _check_case(sc) -> None:
    """What ``bearingsim run`` of case ``sc`` would refuse before its first step: the run request, and where
    a model checks its start (the multibody model's step and raceway contact, the reduced euler method's step)
    that too (:func:`bearingsim.simulation.check_run`); the reduced event method checks nothing more, so its
    many cheap cases are not given the parameters they would build for nothing."""
    if sc.model == "multibody" or sc.reduced.method == "euler":
        from bearingsim.simulation import check_run

        check_run(sc)
    else:
        check_run_request(sc)


def resolved_value(scenario, key: str) -> Any:
    """The value of dotted ``key`` in a resolved scenario (``operating.direction`` -> ``"forward"``);
    None where it has none (a key left unset, such as ``numerics.dt_s`` for the automatic step) or
    where the key names a table rather than a value."""
    from pydantic import BaseModel

    node = scenario.model_
    for part in key.split("."):
        node = node.get(part) if isinstance(node, dict) else getattr(node, part, None)
        if node is None:
            return None
    return None if isinstance(node, (BaseModel, dict)) else node


def _label(values: dict) -> str:
    """``key=value, ...`` of a case's swept values (:meth:`Case.label`)."""
    return ", ".join(f"{k}={_shown(v)}" for k, v in values.items()) or "(base scenario)"


def scenario_from_toml(text: str, source: str = "<sweep case>"):
    """Rebuild the resolved scenario of a case from its TOML text (inside a worker)."""
    from bearingsim.scenario import resolve

    return resolve(tomllib.loads(text), source)
