"""Every scenario key with its unit, bounds, default and source (``bearingsim keys``).

Read from the scenario schema itself (:class:`bearingsim.scenario.ScenarioModel`: the types and bounds
that validation enforces), the package defaults (:data:`bearingsim.scenario.DEFAULTS`) and a preset's
values with their ``[source.<section>.<key>]`` entries, so the list cannot drift from what a scenario
accepts.
"""
from __future__ import annotations

import typing
from dataclasses import dataclass

from pydantic import BaseModel

from bearingsim.sweeps.index import DRAG_COEFFICIENT_UNIT, unit_of
from bearingsim.wording import KEY_TOPICS

#: the sources of the package defaults that have one (bearingsim/scenario.py DEFAULTS, beside each value)
DEFAULT_SOURCES = {
    "multibody.traction_mu_max": "EHL traction of mineral oils (Johnson & Tevaarwerk 1977)",
    "multibody.traction_slip_ref": "EHL traction of mineral oils (Johnson & Tevaarwerk 1977)",
    "wear.wear_coefficient": "Rabinowicz 1981: unlike metals, boundary lubrication (log-middle)",
    "wear.hardness_Pa": "high-strength brass, ~HV 150",
    "contact.land_friction": "reconstructed: equal to the roller-cage friction (brass on steel)",
    "bearing.cage_guidance": "the paper's roller-guided cage",
    "output.motion_rotations": "what an animation shows by default (2 cage rotations; docs/animation.md)",
    "output.motion_start_rotation": "the end of the run, when the cage has settled",
    "output.motion_samples_per_rotation": "2 poses per frame of a 30 fps video at 4 s per cage rotation",
    "reduced.resting_contact": "the paper's model: Eq. (9)'s resting-contact impulse counted",
}
#: what a package default the preset does not document means (``keys KEY --why`` prints it below the row)
DEFAULT_REASONS = {
    "reduced.resting_contact": (
        "true: while the roller rests on a face that the net force presses it onto, the face's impulse "
        "integral of m|a| dt is counted in I_dec / I_acc (Eq. (9), third case); false: impacts only (a bounce "
        "sequence closed at once is credited m u (1+e)/(1-e)), as the paper's previous model, which also has no "
        "gravity (docs/physics.md; docs/validation.md, Fig. 9). At e = 0 an impact ends in resting contact: "
        "I_dec 5.44 mN s with it, 1.10 without (bearingsim run scenarios/paper_3000rpm.toml --set "
        "contact.restitution=0 [--set reduced.resting_contact=false])"),
}
#: the units of the keys whose names carry none (:func:`bearingsim.sweeps.index.unit_of` reads a name's suffix):
#: Eq. (2)'s c, with F_o and N in N and V in m/s (docs/physics.md)
KEY_UNITS = {"lubrication.drag_coefficient": DRAG_COEFFICIENT_UNIT}
#: what a key counts, in the table's source column: these count the cage's rotations, not the inner ring's
#: (which turns inner-ring speed / cage speed times as often)
KEY_MEANINGS = {
    "numerics.rotations": "counts recorded cage rotations (not inner-ring rotations)",
    "numerics.warmup_rotations": "counts cage rotations run before the recorded ones (not inner-ring rotations)",
    "output.motion_rotations": "counts cage rotations (not inner-ring rotations)",
    "output.motion_start_rotation": "the recorded cage rotation the motion starts at",
    "output.motion_samples_per_rotation": "poses per cage rotation",
    "wear.wear_coefficient": ("Archard's dimensionless k = k' H (k': specific wear rate [m^3/(N m)]; "
                              "H: wear.hardness_Pa)"),
}
#: what the ``--why`` line of a key says first, beside the preset's reasoning
KEY_WHY = {
    "wear.wear_coefficient": (
        "k is Archard's dimensionless wear coefficient, V = k W / H (W: sliding work, H: wear.hardness_Pa). A data "
        "sheet's specific wear rate k' in m^3/(N m) is k / H, so give k = k' H: k' = 1e-15 m^3/(N m) at H = 1.5e9 Pa "
        "is k = 1.5e-6; k' given as k reads the wear about 1e9 times low."),
}
#: longest preset reference shown in the table (the whole of it with --why)
WHERE_CHARS = 60

_OPS = (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<="))


@dataclass(frozen=True)
class KeyInfo:
    """One scenario key: ``key`` (dotted), ``unit``, ``kind`` (type and bounds as text), ``default`` (the
    value a scenario gets when it does not set the key, as TOML text, or ``"(required)"``), ``source``
    (where that value comes from), ``why`` (the preset's reference or reasoning, also for a package default
    that the preset's ``[source.<section>.<key>]`` documents; may be empty),
    ``unused_by`` (models that read nothing of the key), ``plausible`` (the preset's plausible range of
    an uncertain value, ``"lo..hi"``, or empty: :mod:`bearingsim.ranges`)."""

    key: str
    unit: str
    kind: str
    default: str
    source: str
    why: str
    unused_by: tuple[str, ...]
    plausible: str = ""


def _type_name(arg) -> str:
    """``int``, ``list of int``, ``list of list of float``."""
    if typing.get_origin(arg) is list:
        return "list of " + _type_name(typing.get_args(arg)[0])
    return getattr(arg, "__name__", str(arg))


def _kind(field) -> str:
    """Type and bounds of a pydantic field: ``int >= 1``, ``"full" | "rigid"``, ``float > 0 | "auto"``."""
    parts = []
    for arg in _flat_args(field.annotation):
        if typing.get_origin(arg) is typing.Literal:
            parts.extend(f'"{v}"' for v in typing.get_args(arg))
        elif arg is type(None):
            continue  # optional: said by the default "(unset)"
        else:
            parts.append(_type_name(arg))
    bounds = [f"{op} {getattr(m, name):g}" for m in field.metadata for name, op in _OPS
              if getattr(m, name, None) is not None]
    if bounds:
        num = next((i for i, p in enumerate(parts) if p in ("int", "float")), None)
        if num is not None:
            parts[num] += " " + ", ".join(bounds)
    return " | ".join(parts) or "?"


def _flat_args(annotation):
    if typing.get_origin(annotation) in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        out = []
        for a in typing.get_args(annotation):
            out.extend(_flat_args(a))
        return out
    return [annotation]


def _toml_value(v) -> str:
    import tomli_w

    return tomli_w.dumps({"v": v}).split("=", 1)[1].strip()


def _bounds_note(section: str, name: str) -> str:
    """Bounds that validators (not field metadata) enforce, from the validator's own wording."""
    return {
        ("bearing", "cage_land_clearance_mm"): "> 0, needed with a land-guided cage",
        ("reduced", "load_zone_half_angle_deg"): "in [0, 180)",
        ("multibody", "inner_ring_mass_kg"): "> 0",
        ("multibody", "pocket_face_half_angle_deg"): "in (0, 90)",
        ("output", "motion_start_rotation"): ">= 0, + motion_rotations <= numerics.rotations",
    }.get((section, name), "")


def _validated_kind(section: str, name: str) -> str:
    """Type and bounds of a key whose validator raises the field's own bound (the field keeps its looser
    bound, so that the validator's message, which says why, is the one a user sees)."""
    from bearingsim.scenario import HARDNESS_RANGE_PA, MAX_WEAR_COEFFICIENT, MIN_ROLLER_COUNT

    return {
        ("bearing", "roller_count"): f"int >= {MIN_ROLLER_COUNT}",
        ("numerics", "warmup_rotations"): "int >= 0, >= 1 to run the multibody model",  # check_run_request
        ("wear", "wear_coefficient"): f"float >= 0, <= {MAX_WEAR_COEFFICIENT:g}",
        ("wear", "hardness_Pa"): f"float >= {HARDNESS_RANGE_PA[0]:g}, <= {HARDNESS_RANGE_PA[1]:g}",
    }.get((section, name), "")


def _checked_bounds(section: str, name: str) -> str:
    """Bounds that a scenario's checks enforce with other keys (:func:`bearingsim.scenario._check_limits`,
    from its constants), added to the field's own."""
    from bearingsim import scenario as sc

    lo, hi = sc.ROLLER_DENSITY_RANGE_KG_M3
    return {
        ("numerics", "rotations"): f"<= {sc.MAX_ROTATIONS}, multibody: + numerics.warmup_rotations <= {sc.MAX_ROTATIONS}",
        ("numerics", "warmup_rotations"): f"multibody: + numerics.rotations <= {sc.MAX_ROTATIONS}",
        ("operating", "inner_ring_speed_rpm"): f"x bearing.pitch_diameter_mm (dm*n) <= {sc.MAX_DM_N_MM_RPM:g} mm rpm",
        ("bearing", "roller_mass_kg"): f"density m / (pi/4 d^2 l) in [{lo:g}, {hi:g}] kg/m^3",
        ("bearing", "radial_clearance_mm"): f"<= {sc.MAX_RADIAL_CLEARANCE_TO_ROLLER:g} x bearing.roller_diameter_mm",
        ("bearing", "cage_inertia_kgm2"): "in [m r_in^2, m r_out^2] of the cage ring (m: bearing.cage_mass_kg)",
        ("lubrication", "drag_coefficient"): f"oil-film drag (Eq. 2) <= {sc.MAX_DRAG_TO_LOAD:g} x the least roller load",
        ("operating", "radial_load_N"): f"<= C0r = {sc.ISO76_C0_FACTOR:g} (1 - D/d_p) Z l D [N, mm] (ISO 76)",
        ("numerics", "output_rate_hz"): "multibody: >= 2 x bearing.roller_count samples per cage rotation",
    }.get((section, name), "")


def _with_bound(kind: str, bound: str) -> str:
    """``kind`` with ``bound`` added to its number's bounds: ``int >= 1`` and ``+ x <= 9``: ``int >= 1, + x <= 9``."""
    parts = kind.split(" | ")
    num = next((i for i, p in enumerate(parts) if p.split(" ")[0] in ("int", "float")), None)
    if num is None:
        return kind
    parts[num] += (", " if " " in parts[num] else " ") + bound
    return " | ".join(parts)


def list_keys(preset: str = "NU214-Suzuki2023") -> list[KeyInfo]:
    """Every key a scenario accepts, in schema order, with the defaults of the package and ``preset``."""
    from bearingsim.scenario import DEFAULTS, UNUSED_BY_MODEL, ScenarioModel, load_preset

    values = load_preset(preset) if preset else {}
    sources = values.get("source", {}) if isinstance(values.get("source"), dict) else {}
    out = []
    for section, field in ScenarioModel.model_fields.items():
        ann = field.annotation
        if isinstance(ann, type) and issubclass(ann, BaseModel):
            for name, sub in ann.model_fields.items():
                out.append(_info(f"{section}.{name}", sub, section, name, DEFAULTS, values, sources, preset,
                                 UNUSED_BY_MODEL))
        else:
            out.append(_info(section, field, None, section, DEFAULTS, values, sources, preset, UNUSED_BY_MODEL))
    return out


def _plausible(src: dict) -> str:
    """The plausible range of a preset's ``[source.<section>.<key>]`` entry, ``"lo..hi"``, or empty."""
    rng = src.get("range")
    if isinstance(rng, list) and len(rng) == 2:
        return f"{rng[0]:g}..{rng[1]:g}"
    return ""


def _info(key, field, section, name, defaults, preset_values, sources, preset, unused) -> KeyInfo:
    kind = (_validated_kind(section, name) if section else "") or _kind(field)
    extra = _bounds_note(section, name) if section else ""
    if extra:
        kind = kind.replace("float", f"float {extra}", 1)
    checked = _checked_bounds(section, name) if section else ""
    if checked:
        kind = _with_bound(kind, checked)
    src = sources.get(section, {}).get(name, {}) if section and isinstance(sources.get(section), dict) else {}
    src = src if isinstance(src, dict) else {}
    why = ""
    plausible = _plausible(src)
    if section and name in preset_values.get(section, {}):
        default = _toml_value(preset_values[section][name])
        where = src.get("where") or ""
        short = where if len(where) <= WHERE_CHARS else where[:WHERE_CHARS - 1].rstrip() + "..."
        source = f"preset {preset}: {src.get('kind', 'no source entry')}" + (f" ({short})" if short else "")
        why = src.get("reason", "") or (where if short != where else "")
    elif section and name in defaults.get(section, {}):
        default = _toml_value(defaults[section][name])
        source = "package default" + (f": {DEFAULT_SOURCES[key]}" if key in DEFAULT_SOURCES else "")
        # the preset's word on the package's value, else the package's
        why = src.get("reason", "") or src.get("range_reason", "") or DEFAULT_REASONS.get(key, "")
    elif key == "schema_version":
        default, source = "1", "the only schema this bearingsim reads (required)"
    elif key == "name":
        default, source = "the file's name", "scenario file"
    elif not field.is_required():
        default, source = "(unset)", "optional"
    else:
        default, source = "(required)", "the scenario or its preset"
    if section == "bearing" and name == "preset":
        default, source = "(none)", "a file in bearingsim/params"
    models = tuple(m for m, prefixes in unused.items()
                   if any(key == p or (p.endswith(".") and key.startswith(p)) for p in prefixes))
    if key == "ranges":
        default, source = "the preset's", "plausible ranges of uncertain keys: [ranges.<section>.<key>] range, reason"
    unit = KEY_UNITS.get(key) or (unit_of(key) if section else "1")
    return KeyInfo(key, unit, kind, default, source, why, models, plausible)


def _is_number(kind: str) -> bool:
    """Whether a key of type and bounds ``kind`` (``int >= 1``, ``float > 0 | "auto"``) takes a number: such a key
    without a unit shows ``1``, as archives write it; a text or a switch shows none."""
    return any(part.split(" ")[0] in ("int", "float") for part in kind.split(" | "))


def format_keys(keys: list[KeyInfo], pattern: str | None = None, why: bool = False) -> str:
    """The keys as an aligned table (``pattern``: only keys containing it, or, when none does, whose names hold
    its words: ``roller count``, ``rollers``); with ``why``, the preset's
    reasoning for each of its values and each package default it documents on the line below it, after what
    :data:`KEY_WHY` says of the key."""
    rows = [k for k in keys if not pattern or pattern.lower() in k.key.lower()]
    if pattern and not rows:  # the words of a name, as an engineer types them: "roller count", "rollers"
        from bearingsim.scenario import key_words

        words = key_words(pattern.strip().replace(" ", "_").replace(".", "_"))
        rows = [k for k in keys if words and words <= key_words(k.key.replace(".", "_"))]
    topic = KEY_TOPICS.get(pattern.strip().lower()) if pattern and not rows else None
    if topic:  # a word no key's name holds: the keys it enters through, and how
        rows = [k for k in keys if k.key in topic[0]]
        return f"{pattern!r} is in no key's name: {topic[1]}:\n" + format_keys(rows, why=why)
    if not rows:
        return ""
    head = ("key", "unit", "type and bounds", "default", "source")
    cells = [(k.key, k.unit if k.unit != "1" or _is_number(k.kind) else "", k.kind, k.default,
              k.source + (f"; {KEY_MEANINGS[k.key]}" if k.key in KEY_MEANINGS else "")
              + (f"; plausible {k.plausible}" if k.plausible else "")
              + (f"; not used by the {', '.join(k.unused_by)} model" if k.unused_by else ""))
             for k in rows]
    widths = [max([len(h)] + [len(c[j]) for c in cells]) for j, h in enumerate(head[:-1])]
    lines = ["  ".join(h.ljust(w) for h, w in zip(head[:-1], widths)) + "  " + head[-1]]
    for k, c in zip(rows, cells):
        lines.append("  ".join(v.ljust(w) for v, w in zip(c[:-1], widths)) + "  " + c[-1])
        said = " ".join(w for w in (KEY_WHY.get(k.key, ""), k.why) if w)
        if why and said:
            lines.append(" " * 4 + said)
    return "\n".join(lines)
