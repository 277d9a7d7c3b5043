"""Wording of printed messages shared by the commands."""
from __future__ import annotations


#: how the command line prints a run's note (:func:`bearingsim.plausibility.check`); the stored note keeps it
NOTE_PREFIX = "bearingsim: note: "


def run_notes(notes) -> list[str]:
    """A run's notes (``result.notes``) as tables, indexes, reports and ``inspect`` show them: one line each,
    without the command line's ``bearingsim: note:`` prefix."""
    return [str(n).removeprefix(NOTE_PREFIX) for n in notes or ()]


def counted(n, noun: str, plural: str | None = None, fmt: str = "") -> str:
    """``n`` and ``noun``, in the plural unless ``n`` is one: ``counted(1, "case")`` is "1 case",
    ``counted(3, "case")`` "3 cases", ``counted(2, "speed", fmt="g")`` "2 speeds". ``plural``: the
    plural when it is not ``noun + "s"``; ``fmt``: the number's format spec."""
    return f"{n:{fmt}} {noun if n == 1 else plural or noun + 's'}"
