"""Scenario files: declarative TOML (``schema_version = 1``) validated into frozen typed objects.

Resolution order for every key: package defaults < the named preset (``[bearing] preset``) < the
scenario file < ``--set KEY=VALUE`` overrides. Keys carry their units (``_mm``, ``_rpm``, ``_N``…);
:meth:`bearingsim.parameters.Parameters.from_scenario` gives the SI view the models take.

Every problem is reported as a :class:`bearingsim.errors.UserError` whose one-line message names the
offending key (dotted, e.g. ``bearing.pocket_clearance_mm``) and the file it came from.
"""
from __future__ import annotations

import copy
import math
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import tomli_w
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from bearingsim.errors import UserError

SCHEMA_VERSION = 1

# Package defaults: everything a preset or a scenario does not set. Literature defaults cite their
# source beside them; bearing geometry has no default (it comes from a preset or the scenario).
DEFAULTS: dict[str, dict[str, Any]] = {
    "operating": {"direction": "forward", "gravity": True},
    "contact": {"cage_friction": 0.1},
    "reduced": {"method": "event", "load_zone_half_angle_deg": "auto", "resting_contact": True},
    "numerics": {"rotations": 5, "warmup_rotations": 1, "output_rate_hz": 20000.0},
    "multibody": {
        "scene": "full",
        # EHL traction curve mu(slip) = mu_max tanh(slip / slip_ref): the shape of the measured
        # traction curves of mineral oils at moderate slide-roll ratio (Johnson & Tevaarwerk 1977,
        # Proc. R. Soc. A 356:215; Harris & Kotzalas, Rolling Bearing Analysis, Fig. 4.11).
        "traction_mu_max": 0.06,
        "traction_slip_ref": 0.02,
        # inner ring: quasi-static (massless) while the load is always shared by >= 2 rollers, else
        # dynamic with the rotor's mass (docs/stability.md); the radial load is the rotor's weight
        "inner_ring": "auto",
        "inner_ring_mass_kg": "auto",
        # pocket faces: arcs about the pocket centre within +-45 deg of the circumferential direction
        # (the paper gives no pocket drawing; a cylindrical-roller cage pocket wraps the roller enough
        # to guide it radially). Narrower arcs guide the cage less (README: the cage whirls more).
        "pocket_face_half_angle_deg": 45.0,
        # pocket shape: "arc" (the cage's own pockets wrap the roller) or "flat" (two plane faces D + s
        # apart, as the paper's instrumented pocket, machined flat for its load cells, Sec. 2.1);
        # flat_pockets lists pockets that are flat whatever pocket_shape says (the rig's pocket 0)
        "pocket_shape": "arc",
        "flat_pockets": [],
    },
    # Archard & Hirst (1956), Proc. R. Soc. A 236:397, Table 1: 60/40 brass on tool steel,
    # k = 6e-4; high-strength brass hardness ~HV 150 -> 1.5e9 Pa.
    "wear": {"wear_coefficient": 6.0e-4, "hardness_Pa": 1.5e9},
}

PRESET_DIR = "params"


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


PosFloat = Field(gt=0.0, allow_inf_nan=False)


class BearingSection(_Section):
    preset: str | None = None
    roller_count: int = Field(ge=1)
    roller_diameter_mm: float = Field(gt=0.0)
    roller_length_mm: float = Field(gt=0.0)
    roller_mass_kg: float = Field(gt=0.0)
    pitch_diameter_mm: float = Field(gt=0.0)
    pocket_clearance_mm: float = Field(gt=0.0)
    radial_clearance_mm: float = Field(ge=0.0)
    cage_mass_kg: float = Field(gt=0.0)
    cage_inertia_kgm2: float = Field(gt=0.0)


class OperatingSection(_Section):
    inner_ring_speed_rpm: float = Field(gt=0.0)
    direction: Literal["forward", "reverse"]
    radial_load_N: float = Field(ge=0.0)
    gravity: bool


class LubricationSection(_Section):
    drag_coefficient: float = Field(ge=0.0)


class ContactSection(_Section):
    restitution: float = Field(ge=0.0, le=1.0)
    cage_friction: float = Field(ge=0.0)


class ReducedSection(_Section):
    method: Literal["event", "euler"]
    load_zone_half_angle_deg: float | Literal["auto"]
    resting_contact: bool

    @field_validator("load_zone_half_angle_deg")
    @classmethod
    def _angle(cls, v):
        if v != "auto" and not (0.0 <= v < 180.0):
            raise ValueError("must be 'auto' or in [0, 180) deg")
        return v


class NumericsSection(_Section):
    dt_s: float | None = Field(default=None, gt=0.0)
    rotations: int = Field(ge=1)
    warmup_rotations: int = Field(ge=0)
    output_rate_hz: float = Field(gt=0.0)


class MultibodySection(_Section):
    scene: Literal["full", "reduced_equivalent"]
    traction_mu_max: float = Field(ge=0.0)
    traction_slip_ref: float = Field(gt=0.0)
    inner_ring: Literal["auto", "quasi_static", "dynamic"]
    inner_ring_mass_kg: float | Literal["auto"]
    pocket_face_half_angle_deg: float = Field(gt=0.0, lt=90.0)
    pocket_shape: Literal["arc", "flat"]
    flat_pockets: list[int]

    @field_validator("inner_ring_mass_kg")
    @classmethod
    def _ring_mass(cls, v):
        if v != "auto" and not v > 0.0:
            raise ValueError("must be 'auto' or a positive mass in kg")
        return v


class WearSection(_Section):
    wear_coefficient: float = Field(ge=0.0)
    hardness_Pa: float = Field(gt=0.0)


class ScenarioModel(_Section):
    schema_version: int
    name: str = Field(min_length=1)
    model: Literal["reduced", "multibody"]
    bearing: BearingSection
    operating: OperatingSection
    lubrication: LubricationSection
    contact: ContactSection
    reduced: ReducedSection
    numerics: NumericsSection
    multibody: MultibodySection
    wear: WearSection


class Scenario:
    """A validated, fully resolved scenario. ``raw`` is the merged dictionary (the archive's copy)."""

    def __init__(self, model: ScenarioModel, source: str):
        self.model_ = model
        self.source = source

    def __getattr__(self, item):
        return getattr(self.model_, item)

    @property
    def raw(self) -> dict[str, Any]:
        return _drop_none(self.model_.model_dump())

    def to_toml(self) -> str:
        return tomli_w.dumps(self.raw)

    def replace(self, **dotted: Any) -> "Scenario":
        """A new scenario with dotted keys replaced, e.g. ``replace(**{"operating.direction": "reverse"})``."""
        raw = self.raw
        for key, value in dotted.items():
            _set_dotted(raw, key, value, origin="replace()")
        return _validate(raw, self.source)


def _drop_none(d):
    if isinstance(d, dict):
        return {k: _drop_none(v) for k, v in d.items() if v is not None}
    return d


def available_presets() -> list[str]:
    folder = resources.files("bearingsim") / PRESET_DIR
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_preset(name: str) -> dict[str, Any]:
    """The preset's data (sections of values, ``name``, ``citation`` and per-key ``source``)."""
    if not isinstance(name, str) or name not in available_presets():
        raise UserError(
            f"bearing.preset: unknown preset {name!r} (available: {', '.join(available_presets())})"
        )
    text = (resources.files("bearingsim") / PRESET_DIR / f"{name}.toml").read_text()
    return tomllib.loads(text)


def parse_override(item: str) -> tuple[str, Any]:
    """``KEY=VALUE`` with VALUE read as a TOML value; a bare word is a string."""
    if "=" not in item:
        raise UserError(f"--set {item!r}: expected KEY=VALUE")
    key, text = item.split("=", 1)
    key = key.strip()
    if not key or any(not part for part in key.split(".")):
        raise UserError(f"--set {item!r}: empty key")
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        value = text.strip()
    return key, value


def _set_dotted(raw: dict, key: str, value: Any, origin: str) -> None:
    parts = key.split(".")
    node = raw
    for p in parts[:-1]:
        child = node.setdefault(p, {})
        if not isinstance(child, dict):
            raise UserError(f"{origin}: {key}: {p!r} is a value, not a section")
        node = child
    node[parts[-1]] = value


def _merge(base: dict, top: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in top.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def read_toml_file(path: str | Path) -> dict[str, Any]:
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UserError(f"{p}: scenario file not found") from None
    except IsADirectoryError:
        raise UserError(f"{p}: is a directory, not a scenario file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(f"{p}: cannot read scenario file ({exc.__class__.__name__})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"{p}: not valid TOML ({exc})") from None


def load_scenario(path: str | Path, overrides: list[str] | None = None,
                  values: dict[str, Any] | None = None) -> Scenario:
    """Read, merge with preset and defaults, apply overrides, and validate.

    ``overrides`` are ``KEY=VALUE`` strings (VALUE read as TOML, as ``--set`` on the command line);
    ``values`` maps dotted keys to Python values; both name keys as ``section.key``.
    """
    raw = read_toml_file(path)
    for item in overrides or []:
        key, value = parse_override(item)
        _set_dotted(raw, key, value, origin="--set")
    for key, value in (values or {}).items():
        if not isinstance(key, str) or not key or any(not part for part in key.split(".")):
            raise UserError(f"set: {key!r}: expected a dotted key such as operating.inner_ring_speed_rpm")
        _set_dotted(raw, key, value, origin="set")
    raw.setdefault("name", Path(path).stem)
    return resolve(raw, str(path))


def resolve(raw: dict[str, Any], source: str = "<dict>") -> Scenario:
    """Merge a scenario dictionary with its preset and the package defaults, then validate."""
    version = raw.get("schema_version")
    if version is None:
        raise UserError(f"{source}: schema_version: missing (this bearingsim reads schema_version = 1)")
    if version != SCHEMA_VERSION or isinstance(version, bool):
        raise UserError(f"{source}: schema_version: {version!r} is not supported (expected 1)")
    merged = copy.deepcopy(DEFAULTS)
    bearing = raw.get("bearing", {})
    preset_name = bearing.get("preset") if isinstance(bearing, dict) else None
    if preset_name is not None:
        try:
            preset = load_preset(preset_name)
        except UserError as exc:
            raise UserError(f"{source}: {exc}") from None
        for section, values in preset.items():
            if section in ScenarioModel.model_fields and isinstance(values, dict):
                merged = _merge(merged, {section: values})
    merged = _merge(merged, raw)
    return _validate(merged, source)


def _loc(err) -> str:
    return ".".join(str(p) for p in err["loc"] if not str(p).startswith(("function-", "literal[")))


def _validate(merged: dict[str, Any], source: str) -> Scenario:
    try:
        model = ScenarioModel.model_validate(merged)
    except ValidationError as exc:
        err = exc.errors()[0]
        key = _loc(err)
        if err["type"] == "missing":
            msg = "missing (set it in the scenario or name a [bearing] preset)"
        elif err["type"] == "extra_forbidden":
            msg = "unknown key"
        else:
            msg = err["msg"].replace("Input should be", "must be").replace("Value error, ", "")
            if "input" in err and not isinstance(err["input"], dict):
                msg += f" (got {err['input']!r})"
        raise UserError(f"{source}: {key}: {msg}") from None
    _check_geometry(model, source)
    return Scenario(model, source)


def _check_geometry(m: ScenarioModel, source: str) -> None:
    b = m.bearing
    if b.roller_diameter_mm >= b.pitch_diameter_mm:
        raise UserError(
            f"{source}: bearing.roller_diameter_mm: {b.roller_diameter_mm} mm must be smaller than "
            f"the pitch diameter {b.pitch_diameter_mm} mm"
        )
    pocket = b.roller_diameter_mm + b.pocket_clearance_mm
    if b.roller_count >= 2:
        chord = b.pitch_diameter_mm * math.sin(math.pi / b.roller_count)
        if pocket >= chord:
            most = max(int(math.pi / math.asin(min(1.0, pocket / b.pitch_diameter_mm))), 0)
            raise UserError(
                f"{source}: bearing.roller_count: {b.roller_count} pockets of {pocket:.4g} mm (bearing.roller_diameter_mm "
                f"+ bearing.pocket_clearance_mm) do not fit "
                f"on a {b.pitch_diameter_mm} mm pitch circle (adjacent pockets {chord:.4g} mm apart; "
                f"at most {most} fit)"
            )
    if b.pocket_clearance_mm >= b.roller_diameter_mm:
        raise UserError(
            f"{source}: bearing.pocket_clearance_mm: {b.pocket_clearance_mm} mm is not smaller than the "
            f"roller diameter {b.roller_diameter_mm} mm"
        )
    if m.model == "multibody" and b.roller_count < 3:
        raise UserError(
            f"{source}: bearing.roller_count: the multibody model needs at least 3 rollers to hold the cage"
        )
    flat = m.multibody.flat_pockets
    bad = [i for i in flat if not 0 <= i < b.roller_count]
    if bad:
        raise UserError(f"{source}: multibody.flat_pockets: pocket {bad[0]} does not exist "
                        f"(pockets 0..{b.roller_count - 1}, bearing.roller_count = {b.roller_count})")
    if len(set(flat)) != len(flat):
        raise UserError(f"{source}: multibody.flat_pockets: a pocket is listed twice ({flat})")
    if m.model == "multibody" and (m.multibody.pocket_shape == "flat" or len(set(flat)) == b.roller_count):
        raise UserError(
            f"{source}: multibody.pocket_shape: with every pocket flat nothing guides the roller-guided cage "
            f"radially (flat faces push only along the direction of rotation): the cage would drift off the "
            f"axis; keep arc pockets and list the flat ones in multibody.flat_pockets")
    if m.reduced.load_zone_half_angle_deg != "auto" and m.model == "reduced":
        if m.reduced.load_zone_half_angle_deg >= 180.0:
            raise UserError(f"{source}: reduced.load_zone_half_angle_deg: must be below 180 deg")
