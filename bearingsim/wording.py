"""Wording of printed messages shared by the commands."""
from __future__ import annotations

import math
import numbers
import re


#: the keys a lubricant enters through: the oil-film drag's c and the raceways' traction curve
_LUBRICANT_KEYS = ("lubrication.drag_coefficient", "multibody.traction_mu_max", "multibody.traction_slip_ref")
#: words an engineer looks for that no key's name holds: the keys through which they enter, and how
#: (``bearingsim keys WORD`` answers with those keys and this line, and an unknown key holding the word,
#: :func:`bearingsim.scenario.did_you_mean`, names them)
KEY_TOPICS = {
    "viscosity": (("lubrication.drag_coefficient",), "a lubricant's viscosity enters through Eq. (2)'s c, as "
                  "c' = c (eta'/eta)^0.648 (docs/whatif.md, Lubricant)"),
    "oil": (_LUBRICANT_KEYS,
            "an oil enters through the oil-film drag's c and the raceways' traction curve (docs/whatif.md, "
            "Lubricant)"),
    "lubricant": (_LUBRICANT_KEYS,
                  "a lubricant enters through the oil-film drag's c and the raceways' traction curve "
                  "(docs/whatif.md, Lubricant)"),
    "grease": (_LUBRICANT_KEYS,
               "a grease enters through the oil-film drag's c (the paper's c = 0.02 is its fit to a lithium-complex "
               "grease) and the raceways' traction curve (docs/whatif.md, Lubricant)"),
    "material": (("bearing.cage_mass_kg", "bearing.cage_inertia_kgm2", "contact.restitution", "contact.cage_friction",
                  "contact.land_friction", "wear.wear_coefficient", "wear.hardness_Pa"),
                 "a cage material enters through the cage's mass and inertia (its density), the roller-cage "
                 "restitution and friction, and Archard's coefficient and hardness (docs/whatif.md, Cage material)"),
    "density": (("bearing.cage_mass_kg", "bearing.cage_inertia_kgm2"),
                "the cage's density enters through its mass and inertia, both in proportion (docs/whatif.md, "
                "Cage material)"),
}


#: how the command line prints a run's note (:func:`bearingsim.plausibility.check`); the stored note keeps it
NOTE_PREFIX = "bearingsim: note: "


def run_notes(notes) -> list[str]:
    """A run's notes (``result.notes``) as tables, indexes, reports and ``inspect`` show them: one line each,
    without the command line's ``bearingsim: note:`` prefix."""
    return [str(n).removeprefix(NOTE_PREFIX) for n in notes or ()]


#: a number in a note's text (a sign, digits, a decimal part, an exponent): what two runs' notes of one kind differ in
_NOTE_NUMBER_RE = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def note_kind(text: str) -> str:
    """``text``, a note, with its numbers masked: two notes of one kind (the warm-up note, which gives each run's
    own rotations) differ in their numbers only, and tables give such a kind once."""
    return _NOTE_NUMBER_RE.sub("#", text)


def by_kind(notes) -> dict[str, tuple[int, int, bool]]:
    """``notes`` (texts, in order) grouped by kind (:func:`note_kind`), in the order the kinds first come: for each,
    ``(the position of its first note, how many notes, whether they differ in their numbers)``."""
    kinds: dict[str, list] = {}
    for i, text in enumerate(notes):
        kind = kinds.setdefault(note_kind(text), [i, 0, set()])
        kind[1] += 1
        kind[2].add(text)
    return {k: (first, n, len(texts) > 1) for k, (first, n, texts) in kinds.items()}


def listed(items, last: str = "or") -> str:
    """``a``, ``a or b``, ``a, b or c`` (``last``: the word before the last item)."""
    items = list(items)
    return items[0] if len(items) == 1 else f"{', '.join(items[:-1])} {last} {items[-1]}"


def rounded3(x: float, *, up: bool) -> float:
    """``x`` > 0 rounded up (``up``) or down to 3 significant digits: a bound a message names, which a user types
    back and is not refused."""
    q = 10.0 ** (math.floor(math.log10(x)) - 2)
    if up:
        return math.ceil(x / q * (1.0 - 1e-12)) * q * (1.0 + 1e-12)
    return math.floor(x / q * (1.0 + 1e-12)) * q * (1.0 - 1e-12)


def counted(n, noun: str, plural: str | None = None, fmt: str = "") -> str:
    """``n`` and ``noun``, in the plural unless ``n`` is one: ``counted(1, "case")`` is "1 case",
    ``counted(3, "case")`` "3 cases", ``counted(2, "speed", fmt="g")`` "2 speeds". ``plural``: the
    plural when it is not ``noun + "s"``; ``fmt``: the number's format spec."""
    return f"{n:{fmt}} {noun if n == 1 else plural or noun + 's'}"


def given_step(dt: float, auto: float, argument: bool) -> str:
    """Advice for a run whose given step ``dt`` [s], longer than the automatic ``auto`` [s], did not give a
    result; ``argument``: the step came from the ``dt`` argument of :func:`bearingsim.run` (stored as
    ``numerics.dt_s``), else from the key ``numerics.dt_s``."""
    if argument:
        return (f"the given step dt = {dt:.3g} s (run()'s dt argument) is {dt / auto:.3g} times the "
                f"automatic {auto:.3g} s: give a smaller dt, or none")
    return (f"the given step numerics.dt_s = {dt:.3g} s is {dt / auto:.3g} times the automatic "
            f"{auto:.3g} s: remove numerics.dt_s or set a smaller one")


def given_by(origin: str, what: str) -> str:
    """``what`` (a key or an override) as a refusal names it with the option or argument ``origin`` that gave
    it: "--set KEY" of a command-line option, "overrides: KEY" of a Python argument."""
    return f"{origin} {what}" if origin.startswith("--") else f"{origin}: {what}"


def distinct_texts(values) -> list[str]:
    """A column of values (a swept key's, one per case) as tables and figures write them: numbers as ``%g``
    writes them, or with the fewest more significant digits (up to 16; beyond, Python's shortest repr) that keep
    distinct values distinct (970.000001 and 970.000002, both "970" by ``%g``: "970.000001",
    "970.000002"); text, switches and whole numbers as they are; NaN, a case that does not set the key (validate's
    rig cases have no drag coefficient of their own), as "-", as tables write a missing number."""
    def is_float(v):  # a Python or numpy float (numpy registers its floats as numbers.Real)
        return isinstance(v, numbers.Real) and not isinstance(v, numbers.Integral)

    finite = {float(v) for v in values if is_float(v) and math.isfinite(v)}
    digits = next((d for d in range(6, 17) if len({f"{v:.{d}g}" for v in finite}) == len(finite)), None)
    return [("-" if v != v else repr(float(v)) if digits is None else f"{float(v):.{digits}g}") if is_float(v)
            else str(v) for v in values]


#: display scale and unit of units that read better scaled
SCALED = {"N s": (1e3, "mN s"), "m^3/h": (1e9, "mm^3/h")}
#: display scale and unit of keys stored as a fraction (unit 1) that read better in per cent
SCALED_KEYS = {"cage_slip": (100.0, "%"), "cage_slip_sem": (100.0, "%")}


def shown_as(key: str, unit: str) -> tuple[float, str]:
    """(scale, unit) in which the tables show summary key ``key`` of SI unit ``unit``: cage slip in per cent,
    impulses in mN s, the rest as stored (``bearingsim run``, ``bearingsim table``, the study tables and the
    report's tables show them so)."""
    return SCALED_KEYS.get(key, SCALED.get(unit, (1.0, unit)))
