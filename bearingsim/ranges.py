"""Plausible ranges of uncertain scenario keys.

A preset gives a range beside a value's source::

    [source.bearing.pocket_clearance_mm]
    kind = "reconstructed"
    reason = "..."
    range = [0.16, 0.24]
    range_reason = "why these ends"

and a scenario file (a user's own bearing) can give or replace one::

    [ranges.bearing.pocket_clearance_mm]
    range = [0.15, 0.30]
    reason = "why these ends"

The resolved scenario holds them all in its ``ranges`` table (``[ranges.<section>.<key>]`` with
``range`` and ``reason``), so an archive stores them with the scenario and ``bearingsim show`` prints
them. :func:`check_ranges` refuses, in one line naming the key, a range of a key that is not a
continuous number, a range whose ends are not increasing, and a range that leaves the key's own bounds
(the ends are validated as values of the key). The sensitivity and uncertainty studies
(:mod:`bearingsim.studies.sensitivity`, :mod:`bearingsim.studies.uncertainty`) read them with
:func:`ranged_keys`.
"""
from __future__ import annotations

import math
from typing import Any

from bearingsim.errors import UserError


def preset_ranges(preset: dict[str, Any]) -> dict[str, Any]:
    """``{"ranges": {section: {key: {"range": [lo, hi], "reason": ...}}}}`` from a preset's
    ``[source.<section>.<key>]`` entries that carry ``range`` (``range_reason`` the reason); empty if
    none do. Malformed entries are passed on as they are, for the scenario's validation to name."""
    out: dict[str, dict[str, Any]] = {}
    sources = preset.get("source")
    if not isinstance(sources, dict):
        return {}
    for section, keys in sources.items():
        if not isinstance(keys, dict):
            continue
        for key, src in keys.items():
            if isinstance(src, dict) and "range" in src:
                out.setdefault(section, {})[key] = {"range": src["range"], "reason": src.get("range_reason", "")}
    return {"ranges": out} if out else {}


def _field_kind(section_model, key: str) -> str | None:
    """"float" for a key whose values are real numbers (possibly also a word such as "auto" or unset),
    "list" for a list (of numbers: ``wear.worn_depth_front_um``, possibly unset), "other" for any other key
    of the section (a count or a choice), None for no such key."""
    import types
    import typing

    field = type(section_model).model_fields.get(key)
    if field is None:
        return None
    annotation = field.annotation
    kinds = (typing.get_args(annotation) if typing.get_origin(annotation) in (typing.Union, types.UnionType)
             else (annotation,))
    if float in kinds:
        return "float"
    if any(typing.get_origin(k) is list for k in kinds):
        return "list"
    return "other"


def is_continuous(scenario, dotted: str) -> bool:
    """Whether ``section.key`` of a resolved scenario takes real numbers (what a range, a relative step and
    a sensitivity need), not a count, a choice or a list."""
    return key_kind(scenario, dotted) == "float"


def key_kind(scenario, dotted: str) -> str | None:
    """What ``section.key`` of a resolved scenario takes: "float" (a real number), "list" (a list of numbers),
    "other" (a count or a choice); None for no such key (a top-level one, ``name``, is no section's key)."""
    if "." not in dotted:
        return None
    section, key = dotted.split(".", 1)
    sec = getattr(scenario.model_, section, None)
    return _field_kind(sec, key) if sec is not None and hasattr(type(sec), "model_fields") else None


_BOUND_ERRORS: dict[tuple, str | None] = {}


def _bound_error(section, key: str, value: float) -> str | None:
    """The section's own message for ``key = value`` (its bounds and field validators), None if valid.
    The sections have no validator that reads two keys, so the answer depends on the section's class,
    the key and the value alone (cached: a sweep resolves thousands of cases with one preset)."""
    from pydantic import ValidationError

    memo = (type(section), key, value)
    if memo in _BOUND_ERRORS:
        return _BOUND_ERRORS[memo]
    msg = None
    try:
        type(section).model_validate({**section.model_dump(), key: value})
    except ValidationError as exc:
        err = next((e for e in exc.errors() if e["loc"][:1] == (key,)), exc.errors()[0])
        msg = err["msg"].replace("Input should be", "must be").replace("Value error, ", "")
    if len(_BOUND_ERRORS) > 4096:
        _BOUND_ERRORS.clear()
    _BOUND_ERRORS[memo] = msg
    return msg


#: ranges found valid: (section, key, low, high). Validity depends on the schema only (the key's type and
#: bounds), not on the scenario's values, so the thousands of cases of a sweep check each range once.
_VALID: set[tuple[str, str, float, float]] = set()


def check_ranges(model, source: str) -> None:
    """Refuse a wrong ``ranges`` table of a validated scenario model in one line naming the key."""
    for section, keys in (model.ranges or {}).items():
        sec = getattr(model, section, None) if section in type(model).model_fields else None
        for key, entry in keys.items():
            seen = (section, key, float(entry.range[0]), float(entry.range[1]))
            if seen in _VALID:
                continue
            where = f"{source}: ranges.{section}.{key}"
            if sec is None or not hasattr(type(sec), "model_fields") or _field_kind(sec, key) is None:
                raise UserError(f"{where}: no key {section}.{key} in the scenario to give a range to")
            if _field_kind(sec, key) != "float":
                raise UserError(f"{where}: {section}.{key} is not a continuous number; only such keys take a range")
            lo, hi = entry.range
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise UserError(f"{where}: range = [{lo:g}, {hi:g}]: give [low, high] with low < high")
            for end in (lo, hi):
                msg = _bound_error(sec, key, float(end))
                if msg is not None:
                    raise UserError(f"{where}: range = [{lo:g}, {hi:g}] leaves the key's bounds: "
                                    f"{section}.{key} = {end:g} {msg}")
            _VALID.add(seen)


def ranged_keys(scenario) -> dict[str, tuple[float, float, str]]:
    """Every ranged key of a resolved scenario: ``{"section.key": (low, high, reason)}`` in the order
    of the ``ranges`` table."""
    out = {}
    for section, keys in (scenario.model_.ranges or {}).items():
        for key, entry in keys.items():
            out[f"{section}.{key}"] = (float(entry.range[0]), float(entry.range[1]), entry.reason)
    return out


def value_of(scenario, dotted: str):
    """The value of ``section.key`` in a resolved scenario (None when unset)."""
    section, key = dotted.split(".", 1)
    return getattr(getattr(scenario.model_, section), key)
