"""Scenario files: declarative TOML (``schema_version = 1``) validated into frozen typed objects.

Resolution order for every key: package defaults < the named preset (``[bearing] preset``) < the
scenario file < ``--set KEY=VALUE`` overrides. Keys carry their units (``_mm``, ``_rpm``, ``_N``…);
:meth:`bearingsim.parameters.Parameters.from_scenario` gives the SI view the models take.

Every problem is reported as a :class:`bearingsim.errors.UserError` whose one-line message names the
offending key (dotted, e.g. ``bearing.pocket_clearance_mm``) and the file it came from.
"""
from __future__ import annotations

import copy
import os
import re
import stat
import math
import tomllib
import types
import unicodedata
from importlib import resources
from pathlib import Path
from typing import Any, Literal, Union, get_args, get_origin

import tomli_w
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from bearingsim.errors import UserError
from bearingsim.wording import KEY_TOPICS, counted, given_by, listed, rounded3

SCHEMA_VERSION = 1

# Package defaults: everything a preset or a scenario does not set. Literature defaults cite their
# source beside them; bearing geometry has no default (it comes from a preset or the scenario).
DEFAULTS: dict[str, dict[str, Any]] = {
    # cage guidance: "rollers" (the paper's rolling-element-guided cage, Sec. 1), or a ring land
    # ("outer_land", "inner_land"): the land clearance and the cage diameters come from the preset.
    # Only the multibody model's full scene has a free cage; the reduced model and the
    # reduced-equivalent scene (cage turning uniformly about the axis) do not use these keys
    "bearing": {"cage_guidance": "rollers"},
    "operating": {"direction": "forward", "gravity": True},
    # land_friction: reconstructed, not from a source: Coulomb friction of a lubricated brass rim on a
    # steel land in boundary/mixed lubrication, taken equal to the roller-cage friction (brass on steel)
    "contact": {"cage_friction": 0.1, "land_friction": 0.1},
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
        # pocket faces: arcs of the pocket circle about its centre. "auto": each face spans what the
        # cage wall allows, from the cage's inner to its outer diameter (bearing.cage_inner_diameter_mm,
        # cage_outer_diameter_mm): the material of the cage exists nowhere else. A number A [deg]: the
        # faces span +-A about the circumferential direction instead (refused if wider than the wall).
        "pocket_face_half_angle_deg": "auto",
        # 0: the arc faces are exact (contact with the true circle of the pocket); N >= 1: each arc face
        # is a circumscribed polyline of N straight segments (only to measure that approximation's
        # error: bearingsim bench, docs/geometry.md)
        "pocket_face_segments": 0,
        # pocket shape: "arc" (the cage's own pockets wrap the roller) or "flat" (two plane faces D + s
        # apart, as the paper's instrumented pocket, machined flat for its load cells, Sec. 2.1);
        # flat_pockets lists pockets that are flat whatever pocket_shape says (the rig's pocket 0)
        "pocket_shape": "arc",
        "flat_pockets": [],
        # raceway contacts: "hertz" (Palmgren springs, the rollers' radial motion integrated: dt ~4 us)
        # or "rigid" (rollers held on the outer race by a unilateral constraint, the inner-race loads
        # from the quasi-static distribution: dt set by the roller-cage impacts; docs/fast_scene.md)
        "raceway_contact": "hertz",
    },
    # Archard's k of brass on steel under boundary lubrication (a grease-lubricated cage pocket): 5e-6,
    # the middle on a log scale of 3e-7..1e-4, Rabinowicz's adhesive wear coefficients of unlike metals
    # between "average" and "poor" lubrication (Rabinowicz 1981, J. Lubr. Technol. 103:188; the range and
    # what of it was read: the preset's [source.wear.wear_coefficient]). Dry, 60/40 brass on tool steel
    # gives 6e-4 (Archard & Hirst 1956, Proc. R. Soc. A 236:397). High-strength brass hardness ~HV 150
    # -> 1.5e9 Pa (a handbook value; the preset's [source.wear.hardness_Pa]).
    "wear": {"wear_coefficient": 5.0e-6, "hardness_Pa": 1.5e9},
    # motion of every body for animations (multibody model; docs/archive.md, docs/animation.md): the last
    # 2 recorded cage rotations (an animation shows 2 rotations by default), 240 poses per cage rotation
    # (one pose per frame of a 30 fps video at 4 s per rotation, with 2x to spare: 1.5 deg of cage
    # travel between poses, ~22 poses per roller pass of the 16-roller NU214); 0 rotations: no motion
    "output": {"motion_rotations": 2.0, "motion_start_rotation": "last", "motion_samples_per_rotation": 240},
}

PRESET_DIR = "params"

# --- limits on what a scenario may ask for. Each says why. ------------------------------
# Scenario files are about 1 kB and presets about 5 kB; reading is bounded so that `run /dev/zero` or a
# wrong multi-GB file stops at once instead of filling memory.
MAX_SCENARIO_BYTES = 1 << 20
# Sections nest two deep (section.key); a value is a scalar. Deeper nesting is never a scenario, and
# very deep nesting would overflow the parser's recursion.
MAX_NESTING_DEPTH = 8
# The scenario name is the default archive file name (outputs/<name>.h5): a plain file name only, and
# short enough that the longest name a run derives from it (".<name>.h5.tmp-<pid>", name + 16 bytes)
# fits the 255-byte file-name limit of ext4, XFS, btrfs and APFS.
MAX_NAME_BYTES = 200
# Unicode's bidirectional controls (embeddings, overrides, isolates, marks): in a name they make a
# terminal or a file listing show the characters in another order than they are (U+202E "RLO")
_BIDI_CONTROLS = frozenset("\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")
# Per-rotation arrays, the impact table and the run time grow with the number of rotations: the
# multibody model takes ~0.2 s per cage rotation (docs/bench.md), so 1e5 rotations is ~6 h; the reduced
# model's impact table is ~1e2 rows per rotation, so 1e5 rotations is ~1e7 rows (~0.6 GB in memory).
MAX_ROTATIONS = 100_000
# dm*n: the fastest rolling bearings in service (jet-lubricated aircraft-engine mainshaft bearings)
# reach about 3e6 mm*rpm (Harris & Kotzalas, Advanced Concepts of Bearing Technology, 5th ed., 2007,
# ch. 2 on high-speed operation); 4e6 leaves a margin. Beyond it the rollers' centrifugal loads and
# the lubricant model of Eq. (2) are outside anything measured.
MAX_DM_N_MM_RPM = 4.0e6
# Implied roller density m / (pi/4 d^2 l): between light engineering polymers (~0.9e3 kg/m^3,
# polyethylene) and tungsten carbide (~15.6e3 kg/m^3), with a margin; bearing steel is 7.8e3.
ROLLER_DENSITY_RANGE_KG_M3 = (500.0, 20_000.0)
# Motion samples (poses of every body, [output] motion_*): at most 1e5 per run, ~70 MB before
# compression for the 16-roller NU214 (85 numbers of 8 bytes per sample): an hour of video at 30 fps,
# far more than anyone animates, and bounded so a typo (1e9 samples per rotation) cannot fill a disk.
MAX_MOTION_SAMPLES = 100_000
# Vickers hardness of cage materials: from soft polymers (PTFE ~ 3e7 Pa) to hard ceramics (~2e10 Pa);
# 1e7..1.2e11 Pa (diamond ~1e11 Pa) bounds every solid (Archard's H in Eq. 16).
HARDNESS_RANGE_PA = (1.0e7, 1.2e11)
# Oil-film rolling resistance F_o = c N^0.246 V^0.648 (Eq. 2) is a small fraction of the contact load
# (measured EHL rolling-resistance coefficients are 1e-3..1e-2); F_o > N at the operating point would
# be a drag larger than the load that causes it.
MAX_DRAG_TO_LOAD = 1.0
# Basic static load rating of a radial roller bearing, ISO 76:2006 Eq. (8): C0r = 44 (1 - D cos a / Dpw)
# i Z Lwe D cos a [N, mm], the load giving 4000 MPa at the most loaded contact. Beyond it the raceways
# deform permanently (> 1e-4 D) and the elastic Palmgren contact law of both models does not hold.
ISO76_C0_FACTOR = 44.0
# Archard's wear coefficient k (Eq. 16) is dimensionless: the probability that an asperity contact
# makes a wear particle, so below 1. The largest measured values, unlubricated mild steel on mild
# steel, are ~1e-2 (Archard 1953, J. Appl. Phys. 24:981, Table 1: 7e-3); lubricated contacts are
# 1e-6..1e-9. 0.1 leaves an order of magnitude above any measurement.
MAX_WEAR_COEFFICIENT = 0.1
# Bins of psi of a worn-depth profile (wear.worn_depth_*_um): the step loop interpolates it per contact;
# the recorded wear profile has 32 (~1.8 deg each), and 1000 (~0.06 deg, 7 um of the reference pocket's
# arc) is finer than any profilometer trace of a cage pocket.
MAX_WORN_BINS = 1000
# Radial (diametral, operating) clearance: the largest standard group of a cylindrical roller bearing,
# ISO 5753-1 C5, is a few tenths of a per cent of the bore, 1..2 % of the roller diameter (0.1..0.2 mm
# for the NU214's 13 mm rollers). 5 % of the roller diameter leaves room for a worn or special bearing;
# beyond it the rings no longer hold the rollers (the load zone shrinks to one roller) and the models'
# contact laws and steps are not made for it.
MAX_RADIAL_CLEARANCE_TO_ROLLER = 0.05
# Fewest rollers: an inner ring under a radial load, and a cage, are held in the plane by at least
# three rollers (two leave a free direction); no rolling bearing has fewer, and both models describe
# a whole bearing's load zone and cage (the reduced model's load-zone rule and cage speed included).
MIN_ROLLER_COUNT = 3
# Narrowest cage bar between two adjacent pockets, as a fraction of the roller diameter. Both models
# take the cage as rigid; the bar carries the roller impacts. The narrowest gap between two circular
# pockets of diameter D + s whose centres lie 2 r_p sin(pi/Z) apart on the pitch circle is that chord
# minus D + s. The NU214 cage's bars are 5.8 mm there (45 % of its 13 mm rollers), those of the
# 30-roller case of scenarios/hard 2.0 mm (25 %); a bar below a tenth of the roller it separates
# (1.3 mm for 13 mm rollers) is a foil, not a rigid cage bar, and no cage is made that thin (a
# judgement: bearing catalogues give no minimum).
MIN_CAGE_BAR_TO_ROLLER = 0.1


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)

    def __setattr__(self, item, value):
        raise AttributeError(self._frozen(item))  # not pydantic's multi-line ValidationError

    def __delattr__(self, item):
        raise AttributeError(self._frozen(item))

    def _frozen(self, item: str) -> str:
        """``sc.operating.radial_load_N = 1.0``'s refusal, as :meth:`Scenario.__setattr__`'s: the dotted key and
        :meth:`Scenario.replace`, which gives a validated copy (a plausible range's entry: frozen only)."""
        sections = {f.annotation: name for name, f in ScenarioModel.model_fields.items()}
        if type(self) is not ScenarioModel and type(self) not in sections:
            return f"Scenario is frozen: {type(self).__name__}.{item} cannot be assigned"
        key = f"{sections[type(self)]}.{item}" if type(self) in sections else item
        return (f"Scenario is frozen: {key} cannot be assigned; use scenario.replace(**{{{key!r}: value}}) "
                f"(validated) for a changed copy")


PosFloat = Field(gt=0.0, allow_inf_nan=False)


class BearingSection(_Section):
    preset: str | None = None
    roller_count: int  # at least MIN_ROLLER_COUNT: _check_geometry says why
    roller_diameter_mm: float = Field(gt=0.0)
    roller_length_mm: float = Field(gt=0.0)
    roller_mass_kg: float = Field(gt=0.0)
    pitch_diameter_mm: float = Field(gt=0.0)
    pocket_clearance_mm: float = Field(gt=0.0)
    radial_clearance_mm: float = Field(ge=0.0)
    cage_mass_kg: float = Field(gt=0.0)
    cage_inertia_kgm2: float = Field(gt=0.0)
    cage_guidance: Literal["rollers", "outer_land", "inner_land"]
    cage_land_clearance_mm: float | None = None  # diametral; needed with a land-guided cage
    cage_outer_diameter_mm: float | None = Field(default=None, gt=0.0)
    cage_inner_diameter_mm: float | None = Field(default=None, gt=0.0)

    @field_validator("cage_land_clearance_mm")
    @classmethod
    def _land_clearance(cls, v):
        if v is not None and not v > 0.0:
            raise ValueError("must be > 0 mm (diametral clearance between the cage rim and the ring land; "
                             "with none the cage would be jammed on the land)")
        return v


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
    land_friction: float = Field(ge=0.0)


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
    scene: Literal["full", "reduced_equivalent", "kinematic_cage", "centred_cage"]
    traction_mu_max: float = Field(ge=0.0)
    traction_slip_ref: float = Field(gt=0.0)
    inner_ring: Literal["auto", "quasi_static", "dynamic"]
    inner_ring_mass_kg: float | Literal["auto"]
    pocket_face_half_angle_deg: float | Literal["auto"]
    pocket_face_segments: int = Field(ge=0, le=1000)
    pocket_shape: Literal["arc", "flat"]
    flat_pockets: list[int]
    raceway_contact: Literal["hertz", "rigid"]

    @field_validator("inner_ring_mass_kg")
    @classmethod
    def _ring_mass(cls, v):
        if v != "auto" and not v > 0.0:
            raise ValueError("must be 'auto' or a positive mass in kg")
        return v

    @field_validator("pocket_face_half_angle_deg")
    @classmethod
    def _face_half_angle(cls, v):
        if v != "auto" and not 0.0 < v < 90.0:
            raise ValueError("must be 'auto' (the cage wall's extent) or an angle in deg between 0 and 90")
        return v


class WearSection(_Section):
    wear_coefficient: float = Field(ge=0.0)
    hardness_Pa: float = Field(gt=0.0)
    # the depth each pocket face has worn already (multibody model, exact arc faces): one row of equal
    # bins of psi over the face's extent per pocket; unset: unworn (docs/wear.md, "Worn faces")
    worn_depth_front_um: list[list[float]] | None = None
    worn_depth_rear_um: list[list[float]] | None = None


class OutputSection(_Section):
    """What a run stores beyond its results: the bodies' motion for animations (multibody model)."""

    motion_rotations: float = Field(ge=0.0)  # cage rotations of motion stored; 0: none
    motion_start_rotation: float | Literal["last"]  # recorded rotation the window starts at; "last": ends with the run
    motion_samples_per_rotation: int = Field(ge=8, le=MAX_MOTION_SAMPLES)

    @field_validator("motion_start_rotation")
    @classmethod
    def _start(cls, v):
        if v != "last" and not v >= 0.0:
            raise ValueError("must be 'last' (the window ends with the run) or a recorded rotation >= 0")
        return v


class RangeEntry(_Section):
    """A plausible range of one numeric key (``[ranges.<section>.<key>]``): ``range = [low, high]`` in the
    key's unit and the ``reason`` for it (:mod:`bearingsim.ranges`)."""

    range: list[float] = Field(min_length=2, max_length=2)
    reason: str = Field(min_length=1)


class ScenarioModel(_Section):
    schema_version: int
    name: str = Field(min_length=1)

    @field_validator("name")
    @classmethod
    def _plain_file_name(cls, v):
        bad = [c for c in v if c in "/\\" or c in _BIDI_CONTROLS or unicodedata.category(c) in ("Cc", "Cs", "Zl", "Zp")]
        if bad or v in (".", "..") or v.startswith(".") or len(v.encode("utf-8", "surrogatepass")) > MAX_NAME_BYTES:
            raise ValueError(
                f"must be a plain file name (it names the archive outputs/<name>.h5): no '/', '\\', "
                f"control characters (C0, C1), bidirectional overrides or line separators, no leading '.', "
                f"at most {MAX_NAME_BYTES} bytes")
        return v
    model: Literal["reduced", "multibody"]
    bearing: BearingSection
    operating: OperatingSection
    lubrication: LubricationSection
    contact: ContactSection
    reduced: ReducedSection
    numerics: NumericsSection
    multibody: MultibodySection
    wear: WearSection
    output: OutputSection
    # plausible ranges of uncertain keys, by section and key (bearingsim.ranges; the preset's are merged in)
    ranges: dict[str, dict[str, RangeEntry]] | None = None


class Scenario:
    """A validated, fully resolved scenario. ``raw`` is the merged dictionary (the archive's copy).

    Parameters
    ----------
    model : ScenarioModel
        The validated scenario (frozen).
    source : str
        Where it came from, for messages.
    toml : str, optional
        ``model``'s TOML text if the caller has it already (:meth:`to_toml` of a scenario with the same
        model, e.g. a sweep case's text): then it is not formatted again.
    overrides : the overrides applied to ``source``'s values (:attr:`overrides`).
    """

    def __init__(self, model: ScenarioModel, source: str, toml: str | None = None, overrides=()):
        self.model_ = model
        self.source = source
        self._toml = toml
        self._parameters = None
        self._overrides = tuple(overrides)

    _OWN = frozenset({"model_", "source", "_toml", "_parameters", "_overrides"})

    #: at most this many overrides are named in the repr (then "and N more")
    REPR_OVERRIDES = 3

    def __setattr__(self, item, value):
        """Only the constructor sets attributes: a scenario is validated once and frozen (``sc.name =
        "../x"`` would bypass that validation, and an archive would store what no check saw)."""
        if item not in self._OWN or "model_" in self.__dict__ and item == "model_":
            raise AttributeError(f"Scenario is frozen: {item} cannot be assigned; use "
                                 f"scenario.replace(**{{{item!r}: value}}) (validated) for a changed copy")
        object.__setattr__(self, item, value)

    def __getattr__(self, item):
        # the model's sections and values only: no special names (copy.deepcopy would find the model's
        # __deepcopy__ and return a ScenarioModel), and an instance not yet filled (unpickling asks for
        # __setstate__ before __dict__ is set) has no model_ to look into (no endless recursion)
        model = self.__dict__.get("model_")
        if model is None or item.startswith("__"):
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {item!r}")
        return getattr(model, item)

    def __repr__(self) -> str:
        """``<Scenario 'paper_3000rpm': reduced model, from 'scenarios/paper_3000rpm.toml' with
        numerics.rotations=1>``: its name, model, where it came from and the overrides applied to it
        (:meth:`overrides_text`)."""
        model = self.__dict__.get("model_")
        if model is None:  # not filled in yet (unpickling)
            return f"<{type(self).__name__} (empty)>"
        return (f"<{type(self).__name__} {model.name!r}: {model.model} model, from {self.source!r}"
                f"{self.overrides_text()}>")

    @property
    def overrides(self) -> tuple[str, ...]:
        """The overrides applied to the values of :attr:`source`, as ``KEY=VALUE`` texts in the order applied:
        :func:`load_scenario`'s ``overrides`` (as written) and ``values`` (``repr`` of each value), then
        :meth:`replace`'s keys. Empty for a scenario as its source holds it (an archive's: its resolved values)."""
        return self.__dict__.get("_overrides", ())

    def overrides_text(self) -> str:
        """`` with A=1, B=2, C=3 and 2 more``: the first :data:`REPR_OVERRIDES` :attr:`overrides` on one line
        ("" without any), for reprs."""
        given = [" ".join(o.split()) for o in self.overrides]
        n = self.REPR_OVERRIDES
        if not given:
            return ""
        return f" with {', '.join(given[:n])}" + (f" and {len(given) - n} more" if len(given) > n else "")

    def __eq__(self, other) -> bool:
        """Two scenarios are equal when they resolve to the same values (wherever they came from)."""
        if not isinstance(other, Scenario):
            return NotImplemented
        return self.model_ == other.model_

    def __hash__(self) -> int:
        return hash(self.to_toml())  # equal models give the same text

    @property
    def raw(self) -> dict[str, Any]:
        """The resolved scenario as nested plain tables, unset keys left out (a new dictionary per call:
        the caller may change it)."""
        return self.model_.model_dump(exclude_none=True)

    @property
    def parameters(self):
        """The SI :class:`bearingsim.parameters.Parameters` the models take, built once (the scenario is
        frozen, so they cannot change)."""
        if self._parameters is None:
            from bearingsim.parameters import Parameters

            self._parameters = Parameters.from_scenario(self)
        return self._parameters

    def to_toml(self) -> str:
        """The resolved scenario as TOML text (what an archive stores), formatted once: the model is
        frozen, so the text cannot change."""
        if self._toml is None:
            self._toml = _dumps(self.raw)
        return self._toml

    def replace(self, **dotted: Any) -> "Scenario":
        """A new scenario with dotted keys replaced, e.g. ``replace(**{"operating.direction": "reverse"})``."""
        raw = self.raw
        for key, value in dotted.items():
            _set_dotted(raw, key, value, origin="replace()")
        new = _validate(raw, self.source)
        new._overrides = self.overrides + tuple(f"{k}={v!r}" for k, v in dotted.items())
        return new


_TOML_TABLES: dict[tuple[str, str], str] = {}  # (table name, repr of its content) -> its TOML text


def _dumps(raw: dict[str, Any]) -> str:
    """``tomli_w.dumps(raw)``, each top-level table formatted once per process for a given content.

    tomli_w writes the top-level values, then each table, separated by a blank line; a table's text
    depends only on its name and its content, so thousands of sweep cases that differ in one or two
    keys share the text of their other tables. The key is the table's ``repr``, which tells 1, 1.0 and
    True apart: ``raw`` is a scenario model's dump, whose top-level values are plain scalars and whose
    tables hold only str, int, float, bool and lists and tables of them, each of which its ``repr``
    spells out whole (no array of tables, which tomli_w would write after the tables).
    """
    top = {k: v for k, v in raw.items() if not isinstance(v, dict)}
    parts = [tomli_w.dumps(top)] if top else []
    for k, v in raw.items():
        if isinstance(v, dict):
            key = (k, repr(v))
            text = _TOML_TABLES.get(key)
            if text is None:
                if len(_TOML_TABLES) >= 4096:
                    _TOML_TABLES.clear()
                text = _TOML_TABLES[key] = tomli_w.dumps({k: v})
            parts.append(text)
    return "\n".join(parts)


def available_presets() -> list[str]:
    folder = resources.files("bearingsim") / PRESET_DIR
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_preset(name: str) -> dict[str, Any]:
    """The preset's data (sections of values, ``name``, ``citation`` and per-key ``source``)."""
    return _copy(_preset(name))


_PRESETS: dict[str, tuple[tuple, dict]] = {}


def _preset(name: str) -> dict[str, Any]:
    """The parsed preset, shared: callers must not change it. Parsed again when the file changes
    (a sweep's worker resolves thousands of cases with one preset)."""
    if isinstance(name, str) and name and "/" not in name and "\\" not in name and not name.startswith("."):
        path = Path(str(resources.files("bearingsim") / PRESET_DIR / f"{name}.toml"))
        try:
            st = path.stat()
        except OSError:
            st = None
        if st is not None:
            stamp = (st.st_mtime_ns, st.st_size, st.st_ino)
            hit = _PRESETS.get(name)
            if hit is not None and hit[0] == stamp:
                return hit[1]
    if not isinstance(name, str) or name not in available_presets():
        raise UserError(
            f"bearing.preset: unknown preset {name!r} (available: {', '.join(available_presets())})"
        )
    path = resources.files("bearingsim") / PRESET_DIR / f"{name}.toml"
    data = tomllib.loads(path.read_text())
    try:
        st = Path(str(path)).stat()
        _PRESETS[name] = ((st.st_mtime_ns, st.st_size, st.st_ino), data)
    except OSError:  # not a plain file (a zipped package): parsed every time
        pass
    return data


def parse_override(item: str, origin: str = "--set") -> tuple[str, Any]:
    """``KEY=VALUE`` with VALUE read as a TOML value; a bare word is a string. ``origin``: what gave it, as its
    refusals name it (:func:`bearingsim.wording.given_by`: the command line's ``--set``, the API's ``overrides``)."""
    if not isinstance(item, str):  # bytes, a number: not text to split
        raise UserError(f"{given_by(origin, repr(item))}: expected a KEY=VALUE string (got {type(item).__name__})")
    if "=" not in item:
        raise UserError(f"{given_by(origin, repr(item))}: expected KEY=VALUE")
    key, text = item.split("=", 1)
    key = key.strip()
    if not key or any(not part for part in key.split(".")):
        raise UserError(f"{given_by(origin, repr(item))}: empty key")
    if len(item) > MAX_SCENARIO_BYTES:
        raise UserError(f"{given_by(origin, key)}: value longer than {MAX_SCENARIO_BYTES} bytes")
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        value = text.strip()
    except RecursionError:
        raise UserError(f"{given_by(origin, key)}: value nested too deeply") from None
    _check_depth(value, given_by(origin, key), depth=len(key.split(".")))
    return key, value


def _check_depth(node: Any, where: str, depth: int = 0) -> None:
    """Refuse data nested deeper than :data:`MAX_NESTING_DEPTH` (iteratively: no recursion limit)."""
    stack = [(node, depth)]
    while stack:
        item, d = stack.pop()
        if d > MAX_NESTING_DEPTH:
            raise UserError(f"{where}: nested more than {MAX_NESTING_DEPTH} levels deep (a scenario has "
                            "sections of keys)")
        if isinstance(item, dict):
            stack.extend((v, d + 1) for v in item.values())
        elif isinstance(item, list):
            stack.extend((v, d + 1) for v in item)


def _plain(value: Any) -> Any:
    """``value`` with numpy scalars as the Python numbers they hold (``np.int64(2)`` -> ``2``,
    ``np.float64`` -> float, ``np.bool_`` -> bool), inside dicts and lists too: a value computed with
    numpy is the number it holds, validated as such (an integer key still refuses ``np.float64(2.0)``,
    as it refuses ``2.0``). Anything else is returned as it is."""
    import numpy as np

    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        if isinstance(value, np.bool_):
            return bool(value)
        if isinstance(value, np.integer):
            return int(value)
        if isinstance(value, np.floating):
            return float(value)
    return value


def _set_dotted(raw: dict, key: str, value: Any, origin: str) -> None:
    """Set dotted ``key`` of ``raw`` to ``value``; a table given for a section (``operating={...}``) sets the
    keys it holds and keeps the section's others, as its keys given one by one would."""
    value = _plain(value)
    parts = key.split(".")
    node = raw
    for p in parts[:-1]:
        child = node.setdefault(p, {})
        if not isinstance(child, dict):
            raise UserError(f"{origin}: {key}: {p!r} is a value, not a section")
        node = child
    old = node.get(parts[-1])
    node[parts[-1]] = _merge(old, value) if isinstance(old, dict) and isinstance(value, dict) else value


def _merge(base: dict, top: dict) -> dict:
    """``base`` updated by ``top``, sections merged key by key; neither is changed (values copied).
    Keys in ``base``'s order, then those only in ``top``."""
    out = {}
    for k, v in base.items():
        if k in top:
            t = top[k]
            out[k] = _merge(v, t) if isinstance(t, dict) and isinstance(v, dict) else _copy(t)
        else:
            out[k] = _copy(v)
    for k, t in top.items():
        if k not in base:
            out[k] = _copy(t)
    return out


_IMMUTABLE = (str, int, float, bool, type(None))


def _copy(v):
    """A deep copy of TOML-like data (dicts, lists, immutable scalars); anything else: copy.deepcopy."""
    if isinstance(v, _IMMUTABLE):
        return v
    if type(v) is dict:
        return {k: _copy(x) for k, x in v.items()}
    if type(v) is list:
        return [_copy(x) for x in v]
    return copy.deepcopy(v)


def read_toml_file(path: str | Path) -> dict[str, Any]:
    p = Path(path)
    if not str(path):  # Path("") is "." (the current folder): "is a directory" would name no path given
        raise UserError("scenario path is empty: give the path of a scenario file (.toml)")
    try:
        if "\x00" in str(path):
            raise UserError(f"{str(path)!r}: file name contains a NUL byte")
        # opened without blocking and refused unless a regular file: a FIFO would wait for a writer
        # forever, a device (/dev/zero) is not a scenario; the read is bounded (a huge file stops at once)
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK)
        with open(fd, "rb") as fh:
            mode = os.fstat(fd).st_mode
            if stat.S_ISDIR(mode):
                raise IsADirectoryError
            if not stat.S_ISREG(mode):
                raise UserError(f"{p}: not a regular file (a FIFO, socket or device), not a scenario file")
            data = fh.read(MAX_SCENARIO_BYTES + 1)
        if data.startswith(b"\x89HDF"):  # an HDF5 file, a bearingsim archive most likely
            raise UserError(f"{p}: is an HDF5 file, not a scenario file; 'bearingsim inspect {p}' says what it is, "
                            f"'bearingsim rerun {p}' runs a run's archive again, 'bearingsim show {p}' prints the "
                            f"scenario an archive or a study's table stores")
        if len(data) > MAX_SCENARIO_BYTES:
            raise UserError(f"{p}: larger than {MAX_SCENARIO_BYTES} bytes, not a scenario file")
        text = data.decode("utf-8")
    except FileNotFoundError:
        raise UserError(f"{p}: scenario file not found") from None
    except IsADirectoryError:
        raise UserError(f"{p}: is a directory, not a scenario file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(f"{p}: cannot read scenario file ({exc.__class__.__name__})") from None
    return parse_toml_text(text, str(p))


def parse_toml_text(text: str, where: str) -> dict[str, Any]:
    """The scenario dictionary of TOML ``text`` (a file's, or an archive's ``/scenario``), read with the
    limits of a scenario file: one-line :class:`UserError` naming ``where`` for text that is longer than
    :data:`MAX_SCENARIO_BYTES`, not TOML, or nested deeper than :data:`MAX_NESTING_DEPTH`."""
    if len(text) > MAX_SCENARIO_BYTES:
        raise UserError(f"{where}: larger than {MAX_SCENARIO_BYTES} bytes, not a scenario")
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"{where}: not valid TOML ({exc})") from None
    except RecursionError:
        raise UserError(f"{where}: nested too deeply to be a scenario") from None
    _check_depth(raw, where)
    return raw


def load_scenario(path: str | Path, overrides: list[str] | None = None,
                  values: dict[str, Any] | None = None, origin: str = "--set") -> Scenario:
    """Read, merge with preset and defaults, apply overrides, and validate.

    ``overrides`` are ``KEY=VALUE`` strings (VALUE read as TOML, as ``--set`` on the command line), each key
    at most once (a key given twice is refused, naming both); ``values`` maps dotted keys to Python values,
    applied after them; both name keys as ``section.key``. ``origin``: what gave ``overrides``, as their
    refusals name it (``--set`` of the command line, ``overrides`` of :func:`bearingsim.load_scenario`).
    """
    from collections.abc import Mapping

    if not isinstance(path, (str, os.PathLike)):
        raise UserError(f"path: expected the path of a scenario file, a str or a pathlib.Path "
                        f"(got {type(path).__name__})")
    if values is not None and not isinstance(values, Mapping):
        raise UserError(f"set: expected a dict of dotted keys and values such as {{'numerics.rotations': 10}} "
                        f"(got {type(values).__name__})")
    if overrides is not None and (isinstance(overrides, (str, bytes)) or not isinstance(overrides, (list, tuple))):
        raise UserError(f"overrides: expected a list of 'KEY=VALUE' strings (got {type(overrides).__name__})")
    raw = read_toml_file(path)
    if "schema_version" not in raw and "scenario" in raw:  # a sweep file's mark (sweeps.spec.is_sweep_file)
        raise UserError(f"{path}: is a sweep file (its base scenario and axes), not a scenario file; "
                        f"'bearingsim sweep {path}' runs it (docs/sweeps.md)")
    if not isinstance(raw.get("name", ""), str):
        raise UserError(f"{path}: name: must be a string")
    given = {}  # key -> the override that set it, as the user wrote it
    leaves = {}  # every dotted key an override sets (a section's table sets each key it holds) -> that override
    for item in overrides or []:
        key, value = parse_override(item, origin)
        set_keys = list(flatten({key: value})) or [key]  # a table (operating={...}) sets each key it holds
        twice = [k for k in set_keys if k in leaves]
        if twice:  # which one was meant is not ours to guess (a sweep refuses it the same way)
            raise UserError(f"{given_by(origin, twice[0])}: given twice ({leaves[twice[0]]} and {item.strip()}); "
                            f"give it once")
        _set_dotted(raw, key, value, origin=origin)
        given[key] = item.strip()
        leaves.update(dict.fromkeys(set_keys, item.strip()))
    for key, value in (values or {}).items():
        if not isinstance(key, str) or not key or any(not part for part in key.split(".")):
            raise UserError(f"set: {key!r}: expected a dotted key such as operating.inner_ring_speed_rpm")
        _set_dotted(raw, key, value, origin="set")
        given[key] = f"{key}={value!r}"
    raw.setdefault("name", Path(path).stem)
    try:
        scenario = resolve(raw, str(path))
    except UserError as exc:
        raise _with_override(exc, str(path), given) from None
    scenario._overrides = tuple(given.values())
    return scenario


#: a dotted scenario key as a message names it (``bearing.pocket_clearance_mm``)
_KEY_IN_TEXT = re.compile(r"\b[a-z][a-z0-9_]*(?:\.[a-z0-9_]+)+\b")


def _with_override(exc: UserError, source: str, given: dict[str, str]) -> UserError:
    """``exc`` of the scenario file ``source`` ("FILE: KEY: why"), saying the overrides that gave the values
    it is about when some did ("FILE with KEY=VALUE: KEY: why"; several: "with A=1 and B=2"), the file does
    not hold those values: every override of KEY, of a key the message names, or of a key the violated
    check reads (``exc.involves``, :func:`_involving`); an override of a table or of a key in it counts
    for both (an unknown section ``operatin`` is the override ``operatin.inner_ring_speed_rpm``)."""
    text = str(exc)
    head = f"{source}: "
    if not text.startswith(head):
        return exc
    body = text[len(head):]
    named = {body.split(":", 1)[0], *_KEY_IN_TEXT.findall(body), *getattr(exc, "involves", ())}

    def about(key: str) -> bool:
        return any(key == k or k.startswith(f"{key}.") or key.startswith(f"{k}.") for k in named)

    which = [given[k] for k in given if about(k)]
    if not which:
        return exc
    return type(exc)(f"{source} with {' and '.join(which)}: {body}")


def with_overrides(exc: UserError, path, overrides=()) -> UserError:
    """``exc``, a refusal of the run that the scenario file ``path`` with the ``KEY=VALUE`` ``overrides``
    asks for (:func:`bearingsim.simulation.check_run`), naming the overrides it is about as a refusal of
    :func:`load_scenario` does (:func:`_with_override`)."""
    given = {}
    for item in overrides or ():
        given[parse_override(item)[0]] = item.strip()
    return _with_override(exc, str(path), given)


def _involving(exc: UserError, *keys: str) -> UserError:
    """``exc``, a check's refusal, marked with the other keys the check reads (``exc.involves``): an override
    of any of them is named in the message too (:func:`_with_override`)."""
    exc.involves = keys
    return exc


#: the keys that place the raceways (the pitch circle and the rollers on it), read by the checks of the cage
_RACEWAY_KEYS = ("bearing.pitch_diameter_mm", "bearing.roller_diameter_mm")
#: and the pockets' width, D + s
_POCKET_KEYS = (*_RACEWAY_KEYS, "bearing.pocket_clearance_mm")
_CAGE_DIAMETER_KEYS = ("bearing.cage_inner_diameter_mm", "bearing.cage_outer_diameter_mm")


def resolve(raw: dict[str, Any], source: str = "<dict>") -> Scenario:
    """Merge a scenario dictionary with its preset and the package defaults, then validate."""
    raw = _plain(raw) if isinstance(raw, dict) else raw
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
            preset = _preset(preset_name)  # shared: _merge copies what it keeps
        except UserError as exc:
            raise UserError(f"{source}: {exc}") from None
        for section, values in preset.items():
            if section in ScenarioModel.model_fields and isinstance(values, dict):
                merged = _merge(merged, {section: values})
        from bearingsim.ranges import preset_ranges

        merged = _merge(merged, preset_ranges(preset))
    merged = _merge(merged, raw)
    return _validate(merged, source)


# keys a figure title shows already (speed, direction, load) or that set only how long and how often
# a run records, and keys a model does not use: not named as differences from the preset
_TITLE_SKIP = ("schema_version", "name", "model", "bearing.preset", "operating.inner_ring_speed_rpm",
               "operating.direction", "operating.radial_load_N", "numerics.", "multibody.scene", "output.")
_TITLE_SKIP_MODEL = {
    "reduced": ("multibody.", "bearing.cage_guidance", "bearing.cage_land_clearance_mm",
                "bearing.cage_outer_diameter_mm", "bearing.cage_inner_diameter_mm", "contact.land_friction"),
    "multibody": ("reduced.",),
}
# keys a model reads nothing of (set in a scenario of that model they change nothing): the reduced model
# has no multibody scene, no cage body (its cage turns at the kinematic speed: no mass, inertia, rim or
# roller-cage friction) and no lands, and solves one pass per rotation (no warm-up, no time series).
# (The multibody model reads reduced.* in its reduced-equivalent scene, so nothing is listed for it.)
# The sensitivity and uncertainty studies refuse these keys in --keys (bearingsim.studies.sensitivity).
UNUSED_BY_MODEL = {
    "reduced": ("multibody.", "bearing.cage_guidance", "bearing.cage_mass_kg", "bearing.cage_inertia_kgm2",
                "bearing.cage_land_clearance_mm", "bearing.cage_outer_diameter_mm", "bearing.cage_inner_diameter_mm",
                "contact.cage_friction", "contact.land_friction", "numerics.warmup_rotations",
                "numerics.output_rate_hz", "output."),
    # the multibody model reads of [reduced] only the load zone, and only in its reduced-equivalent scene
    "multibody": ("reduced.method", "reduced.resting_contact"),
}
# keys the reduced model's method reads nothing of: the event method is event-driven (no time step)
UNUSED_BY_METHOD = {"event": ("numerics.dt_s",)}


def _matching(keys, prefixes) -> list[str]:
    out = []
    for k in keys:
        if k not in out and any(k == p or (p.endswith(".") and k.startswith(p)) for p in prefixes):
            out.append(k)
    return out


def unused_keys(model: str, keys, method: str | None = None) -> list[str]:
    """The keys among ``keys`` (dotted) that ``model`` does not use (with the reduced model's
    ``method``, if given), in order, each once."""
    out = _matching(keys, UNUSED_BY_MODEL.get(model, ()))
    if model == "reduced":
        out += [k for k in _matching(keys, UNUSED_BY_METHOD.get(method, ())) if k not in out]
    return out


def unused_note(model: str, keys, method: str | None = None) -> str | None:
    """One line saying which of ``keys`` have no effect in ``model`` (and the reduced model's
    ``method``, if given); None if all are used."""
    by_model = _matching(keys, UNUSED_BY_MODEL.get(model, ()))
    by_method = [k for k in unused_keys(model, keys, method) if k not in by_model]
    parts = []
    if by_model:
        parts.append(f"{', '.join(by_model)}: not used by the {model} model (no effect on the run)")
    if by_method:
        parts.append(f"{', '.join(by_method)}: not used by reduced.method = {method!r} (event-driven, no time step; "
                     f"no effect on the run)")
    return "; ".join(parts) or None


#: the keys only a land-guided cage reads (the cage's rim running on a ring land)
LAND_KEYS = ("bearing.cage_land_clearance_mm", "contact.land_friction")
#: the keys the reduced model reads only to find its load zone (``reduced.load_zone_half_angle_deg = "auto"``,
#: the quasi-static load distribution): with the half angle given its single pocket's pass reads none of them
LOAD_ZONE_KEYS = ("operating.radial_load_N", "bearing.roller_count", "bearing.roller_length_mm",
                  "bearing.radial_clearance_mm")


#: the keys whose values decide whether a dynamic ring's mass is read (:func:`bearingsim.parameters.inner_ring_mode`)
RING_MODE_KEYS = ("multibody.inner_ring", "multibody.scene", *LOAD_ZONE_KEYS)


def _unread_by_setting(scenario, key: str, varied=()) -> str | None:
    """Why a key the model uses is not read with this scenario's settings, or None. A rule whose deciding
    setting is among ``varied`` (the keys a sweep varies: some of its cases may read the key) says nothing."""
    varied = set(varied)
    if (key in LAND_KEYS and scenario.model == "multibody" and scenario.bearing.cage_guidance == "rollers"
            and "bearing.cage_guidance" not in varied):
        return "not used with bearing.cage_guidance = 'rollers' (no land to run on)"
    if (key in LOAD_ZONE_KEYS and scenario.model == "reduced" and scenario.reduced.load_zone_half_angle_deg != "auto"
            and "reduced.load_zone_half_angle_deg" not in varied):
        return ("not used by the reduced model when reduced.load_zone_half_angle_deg is given (it sets the "
                "load zone only when 'auto')")
    if (key == "reduced.load_zone_half_angle_deg" and scenario.model == "multibody"
            and scenario.multibody.scene != "reduced_equivalent" and "multibody.scene" not in varied):
        return (f"not used by the multibody model's {scenario.multibody.scene!r} scene (its load zone comes out of "
                f"the raceway contacts; only multibody.scene = 'reduced_equivalent' reads it)")
    if key == "multibody.inner_ring_mass_kg" and scenario.model == "multibody" and not varied & set(RING_MODE_KEYS):
        from bearingsim.parameters import inner_ring_mode

        mode, why = inner_ring_mode(scenario.parameters)
        if mode == "none":
            return "not used by the multibody model's 'reduced_equivalent' scene (it has no inner ring)"
        if mode == "quasi_static":
            return (f"not used with a quasi-static (massless) inner ring ({why or 'multibody.inner_ring'}; only "
                    f"multibody.inner_ring = 'dynamic' gives it a mass)")
    return None


def unread_because(scenario, key: str) -> str | None:
    """Why the resolved scenario's run does not read ``key`` (a run with another value of it gives the same
    numbers), or None: a key its model does not use (:data:`UNUSED_BY_MODEL`), a land key with a
    roller-guided cage, the reduced model's load, roller count, roller length and radial clearance when its
    load zone is given (:data:`LOAD_ZONE_KEYS`), the load zone in a multibody scene that makes its own."""
    if unused_keys(scenario.model, [key]):
        return f"not used by the {scenario.model} model"
    return _unread_by_setting(scenario, key)


def unread_note(scenario, keys, method: str | None = "", varied=()) -> str | None:
    """One line saying which of ``keys`` the resolved scenario's run does not read: :func:`unused_note` of
    its model and method, and the keys its settings leave unread (:func:`unread_because`); None if it
    reads them all. ``method``: the reduced model's method to judge by (default: the scenario's; None: none,
    as for a sweep that varies it); ``varied``: the keys a sweep varies (a key left unread by a setting
    among them is not noted: some cases read it)."""
    method = scenario.reduced.method if method == "" else method
    note = unused_note(scenario.model, keys, method)
    unused = unused_keys(scenario.model, keys, method)
    by_setting: dict[str, list[str]] = {}
    for k in dict.fromkeys(keys):
        why = None if k in unused else _unread_by_setting(scenario, k, varied)
        if why is not None:
            by_setting.setdefault(why, []).append(k)
    parts = ([note] if note else []) + [f"{', '.join(ks)}: {why}; no effect on the run" for why, ks in by_setting.items()]
    return "; ".join(parts) or None


#: what a value far below its plausible range may be (:func:`out_of_range_note`): key -> (threshold, hint), the
#: hint given only below the threshold. A specific wear rate k' [m^3/(N m)] given as Archard's dimensionless
#: k = k' H reads the wear ~1e9 times low; data sheets give k' of about 1e-17 to 1e-12 m^3/(N m), while k itself
#: runs from about 1e-9 (polymers, lubricated) to 1e-2, so a k below 1e-11 looks like a k' and one above it is
#: a k (a polymer's converted k of 2e-7 gets the ordinary note)
BELOW_RANGE = {"wear.wear_coefficient": (1e-11, "; k is Archard's dimensionless coefficient, k = k' H: a specific "
                                                "wear rate k' in m^3/(N m) given as k reads the wear about 1e9 times low")}


def _below_range_hint(key: str, value: float) -> str:
    """The :data:`BELOW_RANGE` hint of ``key`` at ``value`` (below its plausible range), or ''."""
    threshold, hint = BELOW_RANGE.get(key, (None, ""))
    return hint if threshold is not None and value < threshold else ""


def out_of_range_note(scenario) -> str | None:
    """One line naming the keys of a resolved scenario that are set outside their plausible range (its
    ``[ranges]``, from the preset or the file: what the sensitivity and uncertainty studies sample),
    those its model uses; None if there are none. Such a run is valid, of a bearing unlike the one the
    ranges describe."""
    from bearingsim.ranges import ranged_keys, value_of

    ranged = ranged_keys(scenario)
    used = [k for k in ranged if k not in unused_keys(scenario.model, [k], scenario.reduced.method)
            and _unread_by_setting(scenario, k) is None]
    out = []
    for k in used:
        lo, hi, _ = ranged[k]
        v = value_of(scenario, k)
        if isinstance(v, (int, float)) and not isinstance(v, bool) and not lo <= v <= hi:
            out.append(f"{k} = {v:g} (plausible {lo:g} to {hi:g}" + (_below_range_hint(k, v) if v < lo else "") + ")")
    if not out:
        return None
    return (f"bearingsim: note: {'; '.join(out)}: outside the range the preset's sensitivity studies sample "
            f"('bearingsim keys KEY --why' says where it comes from); the run is valid, of a bearing unlike the preset's")


def given_keys(path, overrides=(), values=None) -> list[str]:
    """Every dotted key a scenario file, its ``KEY=VALUE`` overrides and its ``{KEY: value}`` values set (not
    its preset's or the defaults': those are the model's own), the keys whose effect a run notes. A file that
    gives the reduced model's load zone itself states the load it is of beside it (the paper scenarios: 970 N,
    23.5°), so its own :data:`LOAD_ZONE_KEYS` are left out; an override of them is kept."""
    in_file = flatten(read_toml_file(path))
    if in_file.get("reduced.load_zone_half_angle_deg", "auto") != "auto":
        in_file = {k: v for k, v in in_file.items() if k not in LOAD_ZONE_KEYS}
    given = []
    pairs = [parse_override(o) for o in overrides or ()] + list((values or {}).items())
    for key, value in pairs:  # a table for a section gives the keys it holds
        given += [f"{key}.{k}" for k in flatten(value)] if isinstance(value, dict) and value else [key]
    return list(in_file) + given


# compact wording of the differences most often made (others: ``key = value`` by the key's last part)
_TITLE_LABELS = {
    "multibody.raceway_contact": lambda v: f"raceway {v}",
    "bearing.cage_guidance": lambda v: "roller-guided cage" if v == "rollers" else f"{str(v).replace('_', '-')} cage",
    "bearing.pocket_clearance_mm": lambda v: f"s = {v:g} mm",
    "bearing.radial_clearance_mm": lambda v: f"radial clearance {v:g} mm",
    "bearing.cage_land_clearance_mm": lambda v: f"land clearance {v:g} mm",
    "bearing.roller_count": lambda v: f"{v} rollers",
    "multibody.inner_ring": lambda v: f"{str(v).replace('_', '-')} inner ring",
    "operating.gravity": lambda v: "gravity" if v else "no gravity",
    "reduced.load_zone_half_angle_deg": lambda v: f"load zone ±{v:g}°",
}


def flatten(d: dict, prefix: str = "") -> dict:
    """A nested table as ``{"section.key": value}`` (dotted keys, as ``--set`` names them)."""
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(flatten(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def same_value(a, b) -> bool:
    """Two scenario or summary values are the same: equal and of one type (1 is not 1.0), NaN equal to NaN."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b and type(a) is type(b)


def differing_keys(*tables: dict) -> list[tuple]:
    """The dotted keys whose values differ (:func:`same_value`) between the scenario tables, sorted, each
    as ``(key, value in the first table, in the second, ...)`` (``"(unset)"`` where a table lacks it)."""
    flat = [flatten(t) for t in tables]
    rows = ((k, *(f.get(k, "(unset)") for f in flat)) for k in sorted(set().union(*flat)))
    return [row for row in rows if not all(same_value(row[1], v) for v in row[2:])]


def _title_value(key: str, v) -> str:
    label = _TITLE_LABELS.get(key)
    if label is not None:
        try:
            return label(v)
        except (TypeError, ValueError):
            pass
    text = f"{v:g}" if isinstance(v, float) else ("[" + ", ".join(map(str, v)) + "]" if isinstance(v, list) else str(v))
    return f"{key.rsplit('.', 1)[-1]} = {text}"


def differences_from_preset(scenario: "Scenario") -> list[str]:
    """What a scenario sets differently from its preset and the package defaults, in a few words each
    (``["raceway rigid", "outer-land cage", "s = 0.3 mm"]``), for figure titles: two runs that differ
    show it. Speed, direction and load (in every title), run length and keys the scenario's model does
    not use are left out."""
    raw = scenario.raw
    ref = copy.deepcopy(DEFAULTS)
    preset = raw.get("bearing", {}).get("preset")
    if preset is not None:
        try:
            for section, values in _preset(preset).items():
                if section in ScenarioModel.model_fields and isinstance(values, dict):
                    ref = _merge(ref, {section: values})
        except UserError:
            pass
    ref = _merge(ref, {k: raw[k] for k in ("schema_version", "name", "model", "operating", "numerics") if k in raw})
    try:
        ref = ScenarioModel.model_validate(ref).model_dump(exclude_none=True)
    except ValidationError:  # no preset: compare with what the defaults set
        pass
    have, base = flatten(raw), flatten(ref)
    skip = _TITLE_SKIP + _TITLE_SKIP_MODEL.get(raw.get("model"), ())
    out = []
    for key, v in have.items():
        if key.startswith(skip) or key not in base:
            continue
        b = base[key]
        same = v == b if not (isinstance(v, bool) or isinstance(b, bool)) else v is b
        if not same:
            out.append(_title_value(key, v))
    return out


def sweep_context(scenario: "Scenario", swept) -> str:
    """What a sweep's cases share, for its figures' titles: ``multibody_6000rpm: multibody, full scene,
    6000 rpm forward, 970 N, 1 warm-up + 3 rotations; raceway rigid``. The speed, direction, load and the
    (warm-up) rotation counts are named unless ``swept`` (the varied keys) holds them; the base's differences
    from its preset (:func:`differences_from_preset`) leave the swept keys out."""
    op, swept = scenario.operating, set(swept)
    what = (f"multibody, {scenario.multibody.scene} scene" if scenario.model == "multibody"
            else f"reduced model ({scenario.reduced.method})")
    point = " ".join(x for k, x in (("operating.inner_ring_speed_rpm", f"{op.inner_ring_speed_rpm:g} rpm"),
                                    ("operating.direction", op.direction)) if k not in swept)
    parts = [what] + ([point] if point else []) + (
        [f"{op.radial_load_N:g} N"] if "operating.radial_load_N" not in swept else [])
    n = scenario.numerics
    if scenario.model == "multibody":  # a swept count is no case's: left out
        from bearingsim.wording import counted

        rec = "numerics.rotations" not in swept
        counts = [(f"{n.warmup_rotations} warm-up" if rec else counted(n.warmup_rotations, "warm-up rotation"))
                  ] if "numerics.warmup_rotations" not in swept else []
        counts += [counted(n.rotations, "rotation")] if rec else []
        parts += [" + ".join(counts)] if counts else []
    flat = flatten(scenario.raw)
    skip = {_title_value(k, flat[k]) for k in swept if k in flat}
    diffs = [d for d in differences_from_preset(scenario) if d not in skip]
    return f"{scenario.name}: {', '.join(parts)}" + (f"; {', '.join(diffs)}" if diffs else "")


# The tags pydantic appends to an error's location for the branch of a union it tried (``float |
# Literal["auto"]`` reports ('reduced', 'load_zone_half_angle_deg', 'float') and (..., "literal['auto']")):
# not keys of the scenario.
_BRANCH_TAGS = ("float", "int", "str", "bool")


def _loc(err) -> str:
    return ".".join(str(p) for p in err["loc"]
                    if not str(p).startswith(("function-", "literal[")) and str(p) not in _BRANCH_TAGS)


def _union_message(errors, err) -> str | None:
    """What a value refused by both branches of a ``float | Literal[...]`` key must be, e.g. "must be a
    number or 'auto'" (pydantic gives one error per branch, each naming only its own), or None."""
    loc = err["loc"]
    if err["type"] not in ("float_type", "float_parsing") or not loc or loc[-1] != "float":
        return None
    words = [e["msg"].replace("Input should be ", "") for e in errors
             if e["type"] == "literal_error" and e["loc"][:-1] == loc[:-1]]
    return f"must be a number or {' or '.join(words)}" if words else None


def known_keys() -> list[str]:
    """Every dotted key a scenario accepts, and its section names (the schema's own list)."""
    out = []
    for name, field in ScenarioModel.model_fields.items():
        sub = field.annotation
        if isinstance(sub, type) and issubclass(sub, BaseModel):
            out.append(name)
            out.extend(f"{name}.{k}" for k in sub.model_fields)
        else:
            out.append(name)
    return out


def is_integer_key(key: str) -> bool:
    """Whether the schema types dotted ``key`` as an integer, with no float it may also be
    (``bearing.roller_count``, ``numerics.rotations``; not ``bearing.cage_land_clearance_mm``, nor an unknown key):
    a strict ``int`` field refuses ``10.0``, so a sweep's evenly spaced values of it must be ints."""
    section, _, name = key.partition(".")
    field = ScenarioModel.model_fields.get(section)
    if field is not None and name:
        sub = field.annotation
        fields = sub.model_fields if isinstance(sub, type) and issubclass(sub, BaseModel) else {}
        field = fields.get(name)
    if field is None:
        return False
    ann = field.annotation  # int, or a union such as int | None (not list[int]: a list is no number)
    kinds = get_args(ann) if get_origin(ann) in (Union, types.UnionType) else (ann,)
    return int in kinds and float not in kinds


#: the parts of a key's name that are its unit (``_mm``, ``_kg``), which name no quantity
_UNIT_WORDS = frozenset({"mm", "um", "kg", "kgm2", "n", "s", "pa", "deg", "hz"})


def key_words(name: str) -> frozenset:
    """The words of a key's name that name its quantity, singular (``pocket_clearance_mm``: pocket, clearance;
    ``rollers``: roller)."""
    words = (w for w in name.lower().split("_") if w and w not in _UNIT_WORDS)
    return frozenset(w[:-1] if len(w) > 3 and w.endswith("s") and not w.endswith(("ss", "us")) else w for w in words)


def did_you_mean(key: str) -> str:
    """`` (did you mean X?)`` for the accepted key closest to an unknown ``key`` (difflib), or ``""``; a ``key``
    that is the last part of exactly one accepted key (``rotations``: ``numerics.rotations``) names that key. A
    ``key`` that is no misspelling of a key beside it but names words of keys' names (``bearing.clearance``,
    ``contact.friction``) names every key that holds them (``did you mean X, Y or Z?``), of its section or, when
    none there does, of any; a word no key's name holds that ``bearingsim keys`` answers (:data:`bearingsim.wording.KEY_TOPICS`:
    ``bearing.cage_material``) names the keys it enters through."""
    import difflib

    known = known_keys()
    ending = [k for k in known if k.rpartition(".")[2] == key and k != key]
    if len(ending) == 1:
        return f" (did you mean {ending[0]}?)"
    section, _, leaf = key.rpartition(".")
    same = [k for k in known if k.rpartition(".")[0] == section]  # the keys beside it (or the top level)
    near = difflib.get_close_matches(leaf, [k.rpartition(".")[2] for k in same], n=1, cutoff=0.8)
    if near:  # a misspelling of one key beside it
        return f" (did you mean {section + '.' if section else ''}{near[0]}?)"
    words = key_words(leaf)
    if words:  # a key named by its words (clearance, friction, load): every key of the section that holds them
        holding = [k for k in same if words <= key_words(k.rpartition(".")[2])]
        if not holding:  # the right words in the wrong section, or at the top level without their section
            holding = [k for k in known if "." in k and words <= key_words(k.rpartition(".")[2])]
        if holding:
            return f" (did you mean {listed(holding)}?)"
        topic = next((w for w in sorted(words) if w in KEY_TOPICS), None)
        if topic:  # a word no key's name holds (material, viscosity): the keys it enters through
            keys, how = KEY_TOPICS[topic]
            return f" ({topic!r} is in no key's name: {how}: {listed(keys, 'and')})"
    close = [f"{section}.{m}" if section else m for m in difflib.get_close_matches(
        leaf, [k.rpartition(".")[2] for k in same], n=1, cutoff=0.6)]
    if not close:  # the right name in the wrong section
        by_leaf = {k.rpartition(".")[2]: k for k in known if "." in k}
        hit = difflib.get_close_matches(leaf, list(by_leaf), n=1, cutoff=0.8)
        close = [by_leaf[hit[0]]] if hit else []
    return f" (did you mean {close[0]}?)" if close else ""


def _validate(merged: dict[str, Any], source: str) -> Scenario:
    try:
        model = ScenarioModel.model_validate(merged)
    except ValidationError as exc:
        errors = exc.errors()  # an unknown key first: a misspelt section or key is why another one is missing
        err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
        key = _loc(err)
        if err["type"] == "missing":
            # a preset gives the bearing's keys only
            msg = "missing (set it in the scenario" + (" or name a [bearing] preset)" if key.startswith("bearing.") else ")")
        elif err["type"] == "extra_forbidden":
            msg = "unknown key" + did_you_mean(key)
        elif err["type"] == "model_type":  # a section given as one value: pydantic would name its class
            msg = f"must be a table of keys ([{key}] in a file, {key}.KEY=VALUE with --set) (got {err['input']!r})"
        else:
            msg = _union_message(errors, err) or \
                err["msg"].replace("Input should be", "must be").replace("Value error, ", "")
            if "input" in err and not isinstance(err["input"], dict):
                msg += f" (got {err['input']!r})"
        raise UserError(f"{source}: {key}: {msg}") from None
    _check_geometry(model, source)
    scenario = Scenario(model, source)
    _check_limits(model, source, scenario)
    _check_motion(model, source)
    if model.ranges:
        from bearingsim.ranges import check_ranges

        check_ranges(model, source)
    return scenario


def check_scenario_argument(scenario, what: str) -> None:
    """Refuse, in one line naming the function ``what`` (``"run()"``), a ``scenario`` argument that is not a
    :class:`Scenario` (a dictionary, a path: what :func:`load_scenario` and :func:`resolve` turn into one)."""
    if not isinstance(scenario, Scenario):
        raise UserError(f"{what}: scenario: expected a Scenario from bearingsim.load_scenario (got "
                        f"{type(scenario).__name__}; a dictionary: bearingsim.scenario.resolve(d))")


def check_run_request(scenario: "Scenario") -> None:
    """Checks for a run asked for results (``bearingsim.run``, and so ``bearingsim run``, ``rerun``,
    every case of a ``sweep`` and of a study), beyond what the schema allows.

    ``numerics.warmup_rotations = 0`` with the multibody model: every pocket's first window then
    starts from the assembled state, and the means over rotations are biased (measured: the
    mean I_dec of the reduced-equivalent scene 21 % low). A stability scan (``benchmarks.stability`` of a
    source checkout) and the kernel tests, which want exactly one rotation from the start state, call
    the model's own ``simulate(parameters)``, below this check.
    """
    if scenario.model == "multibody" and scenario.numerics.warmup_rotations < 1:
        raise UserError(f"{scenario.source}: numerics.warmup_rotations: 0 with the multibody model averages "
                        "windows that start from the assembled state (biased means); use at least 1 warm-up rotation")


def _check_limits(m: ScenarioModel, source: str, scenario: "Scenario") -> None:
    """Sizes, run length and physically absurd values, each refused with the limit and its reason
    (the constants above); ``scenario``: ``m`` as a scenario, whose SI parameters the last checks use."""
    b, o, n = m.bearing, m.operating, m.numerics
    warmup = n.warmup_rotations if m.model == "multibody" else 0  # the reduced model runs no warm-up
    total = n.rotations + warmup
    if total > MAX_ROTATIONS:
        key = "numerics.rotations" if n.rotations > warmup else "numerics.warmup_rotations"
        exc = UserError(f"{source}: {key}: {total} rotations in all exceed {MAX_ROTATIONS} (memory and run "
                        "time grow with rotations); run fewer")
        raise _involving(exc, "numerics.rotations", *(("numerics.warmup_rotations",) if warmup else ()))
    dmn = o.inner_ring_speed_rpm * b.pitch_diameter_mm
    if dmn > MAX_DM_N_MM_RPM:
        exc = UserError(f"{source}: operating.inner_ring_speed_rpm: {o.inner_ring_speed_rpm:g} rpm gives "
                        f"dm*n = {dmn:.3g} mm rpm, beyond any rolling bearing (limit {MAX_DM_N_MM_RPM:.0e})")
        raise _involving(exc, "bearing.pitch_diameter_mm")
    rho = b.roller_mass_kg / (math.pi / 4 * (b.roller_diameter_mm * 1e-3) ** 2 * b.roller_length_mm * 1e-3)
    lo, hi = ROLLER_DENSITY_RANGE_KG_M3
    if not lo <= rho <= hi:
        exc = UserError(f"{source}: bearing.roller_mass_kg: {b.roller_mass_kg:g} kg gives a roller density of "
                        f"{rho:.3g} kg/m^3, outside any roller material ({lo:g}..{hi:g} kg/m^3)")
        raise _involving(exc, "bearing.roller_diameter_mm", "bearing.roller_length_mm")
    if m.wear.wear_coefficient > MAX_WEAR_COEFFICIENT:
        raise UserError(f"{source}: wear.wear_coefficient: {m.wear.wear_coefficient:g} is not an Archard wear "
                        f"coefficient (dimensionless, a probability per asperity contact; measured values are "
                        f"1e-9..1e-2, at most {MAX_WEAR_COEFFICIENT:g} accepted)")
    limit = MAX_RADIAL_CLEARANCE_TO_ROLLER * b.roller_diameter_mm
    if b.radial_clearance_mm > limit:
        exc = UserError(f"{source}: bearing.radial_clearance_mm: {b.radial_clearance_mm:g} mm is more than "
                        f"{MAX_RADIAL_CLEARANCE_TO_ROLLER:.0%} of the roller diameter ({limit:.3g} mm); the largest "
                        f"standard clearance (ISO 5753-1 C5) is 1..2 % of it")
        raise _involving(exc, "bearing.roller_diameter_mm")
    _check_cage_inertia(b, source)
    lo, hi = HARDNESS_RANGE_PA
    if not lo <= m.wear.hardness_Pa <= hi:
        raise UserError(f"{source}: wear.hardness_Pa: {m.wear.hardness_Pa:g} Pa is outside the hardness of "
                        f"solids ({lo:g}..{hi:g} Pa)")
    from bearingsim import laws

    view = scenario.parameters
    g_r, op = view.bearing, view.operating
    n_free = g_r.roller_mass * (g_r.pitch_radius * op.omega_c**2 + op.gravity)  # Eq. (3), least N
    if n_free > 0:
        drag = float(laws.oil_film_drag(m.lubrication.drag_coefficient, n_free, op.rolling_velocity))
        if drag > MAX_DRAG_TO_LOAD * n_free:
            # the drag is c times that of c = 1: the largest c the bound accepts, rounded down to 3 digits
            largest = rounded3(MAX_DRAG_TO_LOAD * n_free / float(laws.oil_film_drag(1.0, n_free, op.rolling_velocity)),
                                up=False)
            exc = UserError(f"{source}: lubrication.drag_coefficient: {m.lubrication.drag_coefficient:g} gives an "
                            f"oil-film drag of {drag:.3g} N against a roller load of {n_free:.3g} N (Eq. 2); "
                            f"rolling resistance is a small fraction of the load: use at most {largest:.3g} here "
                            f"(drag = {MAX_DRAG_TO_LOAD:g} x load)")
            raise _involving(exc, "bearing.roller_mass_kg", *_RACEWAY_KEYS, "operating.inner_ring_speed_rpm",
                             "operating.gravity")
    c0 = ISO76_C0_FACTOR * (1 - b.roller_diameter_mm / b.pitch_diameter_mm) * b.roller_count * \
        b.roller_length_mm * b.roller_diameter_mm
    if o.radial_load_N > c0:
        exc = UserError(f"{source}: operating.radial_load_N: {o.radial_load_N:g} N exceeds the static load rating "
                        f"C0r = {c0:.4g} N of this bearing (ISO 76); the raceways would yield")
        raise _involving(exc, "bearing.roller_count", "bearing.roller_length_mm", *_RACEWAY_KEYS)
    if m.model == "multibody":
        period = 2 * math.pi / op.omega_c
        per_rotation = n.output_rate_hz * period
        need = 2 * b.roller_count  # Nyquist for the roller-pass frequency in the cage orbit
        if per_rotation < need:
            exc = UserError(f"{source}: numerics.output_rate_hz: {n.output_rate_hz:g} Hz gives {per_rotation:.3g} "
                            f"samples per cage rotation; at least {need} (2 per roller pass) are needed, use "
                            f">= {need / period:.3g} Hz")
            raise _involving(exc, "operating.inner_ring_speed_rpm", *_RACEWAY_KEYS, "bearing.roller_count")


def _check_motion(m: ScenarioModel, source: str) -> None:
    """The motion window of a multibody run lies in the recorded rotations (a given start) and holds at most
    :data:`MAX_MOTION_SAMPLES` poses. With start "last" a window longer than the run is the whole run. The
    reduced model stores no motion: it does not read ``[output]`` (:func:`unread_note` says so)."""
    if m.model != "multibody":
        return
    out, rotations = m.output, m.numerics.rotations
    start, length = out.motion_start_rotation, out.motion_rotations
    if start != "last" and start + length > rotations:
        ways = []  # what moves the window into the run: an earlier start only where the window fits in it
        if length <= rotations:
            ways.append(f"start it at {rotations - length:g} or earlier")
        if start < rotations:
            ways.append(f"shorten output.motion_rotations to {rotations - start:g} or less")
        ways.append(f"set numerics.rotations to {math.ceil(start + length):g} or more")
        exc = UserError(f"{source}: output.motion_start_rotation: the window {start:g} .. {start + length:g} ends "
                        f"after the {rotations} recorded rotations (numerics.rotations); {', '.join(ways)}, or set "
                        f"output.motion_start_rotation = 'last' (the last recorded rotations)")
        raise _involving(exc, "output.motion_rotations", "numerics.rotations")
    length = min(out.motion_rotations, rotations)
    if length * out.motion_samples_per_rotation > MAX_MOTION_SAMPLES:
        exc = UserError(f"{source}: output.motion_rotations: {length:g} rotations x {out.motion_samples_per_rotation} "
                        f"samples per rotation is more than {MAX_MOTION_SAMPLES} motion samples; store a shorter "
                        f"window or fewer output.motion_samples_per_rotation")
        raise _involving(exc, "numerics.rotations")


def given_key_notes(scenario, keys) -> list[str]:
    """The notes on the keys a user gave (``keys``, :func:`given_keys`) that ``bearingsim run`` prints before it
    starts and the public ``load_scenario`` warns: those the run does not read (:func:`unread_note`) and a
    motion window longer than the run (:func:`motion_window_note`)."""
    return [n for n in (unread_note(scenario, keys), motion_window_note(scenario, keys)) if n]


def motion_window_note(scenario, keys) -> str | None:
    """One line when ``output.motion_rotations``, among the keys given (:func:`given_keys`), asks a multibody
    run for a window longer than its recorded rotations: with ``motion_start_rotation = "last"`` such a window
    is the whole run, which the archive stores instead (a given start is refused: :func:`_check_motion`);
    None otherwise."""
    out, rotations = scenario.output, scenario.numerics.rotations
    if (scenario.model != "multibody" or "output.motion_rotations" not in keys or out.motion_start_rotation != "last"
            or out.motion_rotations <= rotations):
        return None
    return (f"output.motion_rotations = {out.motion_rotations:g} is longer than the run's {rotations} recorded "
            f"rotations (numerics.rotations): the archive stores the motion of those {rotations}, the whole "
            f"recorded run (docs/archive.md, Motion)")


def _check_cage_inertia(b: "BearingSection", source: str) -> None:
    """The cage is a ring between the raceways (or between its given diameters): the moment of inertia of
    a ring of mass m between radii r_in and r_out lies between m r_in^2 and m r_out^2."""
    r_out = 0.5e-3 * (b.cage_outer_diameter_mm or b.pitch_diameter_mm + b.roller_diameter_mm)
    r_in = 0.5e-3 * (b.cage_inner_diameter_mm or b.pitch_diameter_mm - b.roller_diameter_mm)
    lo, hi = b.cage_mass_kg * r_in**2, b.cage_mass_kg * r_out**2
    if not lo <= b.cage_inertia_kgm2 <= hi:
        exc = UserError(f"{source}: bearing.cage_inertia_kgm2: {b.cage_inertia_kgm2:g} kg m^2 is impossible for a "
                        f"{b.cage_mass_kg:g} kg cage ring between radii {r_in * 1e3:.4g} and {r_out * 1e3:.4g} mm "
                        f"(m r_in^2 = {lo:.3g} .. m r_out^2 = {hi:.3g} kg m^2); the cage's mass and inertia go "
                        f"together: a uniform ring of this mass has m (r_in^2 + r_out^2) / 2 = "
                        f"{0.5 * (lo + hi):.4g} kg m^2")
        raise _involving(exc, "bearing.cage_mass_kg", *_CAGE_DIAMETER_KEYS, *_RACEWAY_KEYS)


def _check_geometry(m: ScenarioModel, source: str) -> None:
    b = m.bearing
    if b.roller_diameter_mm >= b.pitch_diameter_mm:
        exc = UserError(
            f"{source}: bearing.roller_diameter_mm: {b.roller_diameter_mm} mm must be smaller than "
            f"the pitch diameter {b.pitch_diameter_mm} mm"
        )
        raise _involving(exc, "bearing.pitch_diameter_mm")
    if b.roller_count < MIN_ROLLER_COUNT:
        raise UserError(
            f"{source}: bearing.roller_count: {b.roller_count} is too few; a bearing needs at least "
            f"{MIN_ROLLER_COUNT} rollers to hold its inner ring and its cage (both models describe a whole bearing)"
        )
    if b.pocket_clearance_mm >= b.roller_diameter_mm:
        exc = UserError(
            f"{source}: bearing.pocket_clearance_mm: {b.pocket_clearance_mm} mm is not smaller than the "
            f"roller diameter {b.roller_diameter_mm} mm"
        )
        raise _involving(exc, "bearing.roller_diameter_mm")
    _check_cage_bars(b, source)
    flat = m.multibody.flat_pockets
    bad = [i for i in flat if not 0 <= i < b.roller_count]
    if bad:
        raise UserError(f"{source}: multibody.flat_pockets: pocket {bad[0]} does not exist "
                        f"(pockets 0..{b.roller_count - 1}, bearing.roller_count = {b.roller_count})")
    if len(set(flat)) != len(flat):
        raise UserError(f"{source}: multibody.flat_pockets: a pocket is listed twice ({flat})")
    _check_cage_wall(m, source)
    land = b.cage_guidance != "rollers"
    if land:
        _check_land(m, source)
    if m.model == "multibody":
        _check_pocket_faces(m, source)
    _check_worn(m, source)
    if m.model == "multibody" and not land and (m.multibody.pocket_shape == "flat" or len(set(flat)) == b.roller_count):
        raise UserError(
            f"{source}: multibody.pocket_shape: with every pocket flat nothing guides the roller-guided cage "
            f"radially (flat faces push only along the direction of rotation): the cage would drift off the "
            f"axis; keep arc pockets and list the flat ones in multibody.flat_pockets, or guide the cage on a "
            f"ring land (bearing.cage_guidance)")
    if m.reduced.load_zone_half_angle_deg != "auto" and m.model == "reduced":
        if m.reduced.load_zone_half_angle_deg >= 180.0:
            raise UserError(f"{source}: reduced.load_zone_half_angle_deg: must be below 180 deg")


def _check_worn(m: ScenarioModel, source: str) -> None:
    """A worn-depth profile (``wear.worn_depth_front_um``, ``_rear_um``): the multibody model with exact arc
    faces, one row per pocket, rows of equal length (the bins of psi), depths >= 0, and a cage bar that
    is not worn through (the depths of the two faces on each bar, one pocket's front face and its neighbour's
    rear face, in each bin of psi, below the bar's width: :func:`bearingsim.laws.worn_bar_depth`)."""
    w = m.wear
    given = [(k, v) for k, v in (("worn_depth_front_um", w.worn_depth_front_um),
                                 ("worn_depth_rear_um", w.worn_depth_rear_um)) if v is not None]
    if not given:
        return
    key = f"wear.{given[0][0]}"
    if m.model != "multibody":
        exc = UserError(f"{source}: {key}: worn pocket faces need the whole bearing (model = \"multibody\"); the "
                        f"reduced model has no shape of the pocket faces")
        raise _involving(exc, "model")
    if m.multibody.pocket_face_segments != 0:
        raise UserError(f"{source}: {key}: worn faces need the exact arc faces (multibody.pocket_face_segments = 0)")
    b = m.bearing
    bins = {len(row) for _, v in given for row in v}
    for k, v in given:
        if len(v) != b.roller_count:
            raise UserError(f"{source}: wear.{k}: {counted(len(v), 'row')}; give one per pocket ({b.roller_count}, "
                            f"bearing.roller_count)")
    if len(bins) != 1 or not 1 <= min(bins) <= MAX_WORN_BINS:
        raise UserError(f"{source}: {key}: every row (both faces) must have the same number of bins of psi, "
                        f"1 to {MAX_WORN_BINS} (got {sorted(bins)[:4]})")
    for k, v in given:
        if min(min(row) for row in v) < 0.0:
            raise UserError(f"{source}: wear.{k}: a worn depth is negative; wear only removes material")
    import numpy as np

    from bearingsim.laws import cage_bar_width, worn_bar_depth

    faces = {k: np.array(v, dtype=np.float64).T for k, v in given}  # (bins, pockets) [um]
    zero = np.zeros_like(next(iter(faces.values())))
    on_bar = worn_bar_depth(faces.get("worn_depth_front_um", zero), faces.get("worn_depth_rear_um", zero)) * 1e-3
    bar = cage_bar_width(b.pitch_diameter_mm, b.roller_diameter_mm, b.pocket_clearance_mm, b.roller_count)
    if on_bar.max() >= bar:
        i = int(np.unravel_index(np.argmax(on_bar), on_bar.shape)[1])
        exc = UserError(f"{source}: {key}: pocket {i}'s front face and pocket {(i - 1) % b.roller_count}'s rear face, "
                        f"either side of the cage bar between them, are worn {on_bar.max():.4g} mm deep together in a "
                        f"bin of psi, the bar's width ({bar:.4g} mm) or more: the bar would be worn through")
        raise _involving(exc, *_POCKET_KEYS, "bearing.roller_count")


def _most_pockets(width_mm: float, pitch_mm: float) -> int:
    """Most pockets whose centres are at least ``width_mm`` apart (chord) on a ``pitch_mm`` circle."""
    return max(int(math.pi / math.asin(min(1.0, width_mm / pitch_mm))), 0)


def _check_cage_bars(b: "BearingSection", source: str) -> None:
    """The pockets fit on the pitch circle with a cage bar between each two of at least
    :data:`MIN_CAGE_BAR_TO_ROLLER` of the roller diameter (adjacent pocket centres are the chord
    2 r_p sin(pi/Z) apart; the bar is that chord minus the pocket width D + s)."""
    pocket = b.roller_diameter_mm + b.pocket_clearance_mm
    chord = b.pitch_diameter_mm * math.sin(math.pi / b.roller_count)
    keys = "bearing.roller_diameter_mm + bearing.pocket_clearance_mm"
    least = MIN_CAGE_BAR_TO_ROLLER * b.roller_diameter_mm
    most = _most_pockets(pocket + least, b.pitch_diameter_mm)  # the most either check accepts
    advice = (f"at most {most} rollers" if most >= MIN_ROLLER_COUNT else
              f"not even {MIN_ROLLER_COUNT} rollers leave such bars: the pockets are too wide for this pitch circle")
    if pocket >= chord:
        exc = UserError(
            f"{source}: bearing.roller_count: {b.roller_count} pockets of {pocket:.4g} mm ({keys}) do not fit "
            f"on a {b.pitch_diameter_mm} mm pitch circle (adjacent pockets {chord:.4g} mm apart); with cage bars "
            f"of at least {MIN_CAGE_BAR_TO_ROLLER:.0%} of the roller diameter, {advice}")
        raise _involving(exc, *_POCKET_KEYS)
    if chord - pocket < least:
        exc = UserError(
            f"{source}: bearing.roller_count: {b.roller_count} pockets of {pocket:.4g} mm ({keys}) on a "
            f"{b.pitch_diameter_mm} mm pitch circle leave cage bars of {chord - pocket:.3g} mm between them, less "
            f"than {MIN_CAGE_BAR_TO_ROLLER:.0%} of the roller diameter ({least:.3g} mm): not a rigid cage; {advice}")
        raise _involving(exc, *_POCKET_KEYS)


def _check_cage_wall(m: ScenarioModel, source: str) -> None:
    """The cage's given diameters: its bore smaller than its outside diameter (every model: the cage
    inertia check reads them); where the cage wall is used (the multibody model, a land-guided cage)
    the wall straddles the pitch circle and clears both raceways (diameters D_pw - D and D_pw + D)."""
    b = m.bearing
    bore, rim = b.cage_inner_diameter_mm, b.cage_outer_diameter_mm
    if bore is not None and rim is not None and not bore < rim:
        raise UserError(f"{source}: bearing.cage_inner_diameter_mm: the cage bore {bore:g} mm must be smaller than "
                        f"its outside diameter bearing.cage_outer_diameter_mm = {rim:g} mm")
    if m.model != "multibody" and b.cage_guidance == "rollers":
        return  # the reduced model has no cage wall (UNUSED_BY_MODEL)
    pitch, d = b.pitch_diameter_mm, b.roller_diameter_mm
    wall = "(the cage wall holds the pockets around the pitch circle, between the raceways)"
    if bore is not None and not pitch - d < bore < pitch:
        exc = UserError(f"{source}: bearing.cage_inner_diameter_mm: the cage bore {bore:g} mm must lie between the inner raceway "
                        f"diameter {pitch - d:g} mm and the pitch diameter {pitch:g} mm {wall}")
        raise _involving(exc, *_RACEWAY_KEYS)
    if rim is not None and not pitch < rim < pitch + d:
        exc = UserError(f"{source}: bearing.cage_outer_diameter_mm: the cage's outside diameter {rim:g} mm must lie between the pitch diameter "
                        f"{pitch:g} mm and the outer raceway diameter {pitch + d:g} mm {wall}")
        raise _involving(exc, *_RACEWAY_KEYS)


def _check_pocket_faces(m: ScenarioModel, source: str) -> None:
    """The arc pocket faces fit the cage wall: "auto" needs the cage's diameters and a wall that holds
    the pocket centre; a given half angle may not reach past the wall (bearingsim.laws.pocket_face_extent)."""
    from bearingsim import laws

    b = m.bearing
    mb = m.multibody
    wall = (b.cage_inner_diameter_mm, b.cage_outer_diameter_mm)
    if None in wall:
        if mb.pocket_face_half_angle_deg == "auto":
            key = "cage_inner_diameter_mm" if wall[0] is None else "cage_outer_diameter_mm"
            raise UserError(f"{source}: bearing.{key}: missing; the pocket faces span the cage wall "
                            f"(multibody.pocket_face_half_angle_deg = 'auto'): give the cage's diameters or a "
                            f"half angle")
        return
    lo, hi = laws.pocket_face_extent(0.5e-3 * b.pitch_diameter_mm, 0.5e-3 * (b.roller_diameter_mm + b.pocket_clearance_mm),
                                     0.5e-3 * wall[0], 0.5e-3 * wall[1])
    a = mb.pocket_face_half_angle_deg
    if a != "auto" and a > min(-lo, hi) * 180.0 / math.pi * (1.0 + 1e-12):
        exc = UserError(f"{source}: multibody.pocket_face_half_angle_deg: {a:g} deg is wider than the cage wall "
                        f"allows ({lo * 180.0 / math.pi:.1f} to +{hi * 180.0 / math.pi:.1f} deg from the pocket's "
                        f"centre line between bearing.cage_inner_diameter_mm and cage_outer_diameter_mm); use "
                        f"'auto' or at most {min(-lo, hi) * 180.0 / math.pi:.1f}")
        raise _involving(exc, *_POCKET_KEYS, *_CAGE_DIAMETER_KEYS)


def _check_land(m: ScenarioModel, source: str) -> None:
    """A land-guided cage: the land clearance and the cage diameters are given, and the land lies
    between the raceways (outer land: the outer ring's land bore, cage OD + c_L, inside the outer
    raceway; inner land: the inner ring's land, cage ID - c_L, outside the inner raceway)."""
    b = m.bearing
    for key in ("cage_land_clearance_mm", "cage_outer_diameter_mm", "cage_inner_diameter_mm"):
        if getattr(b, key) is None:
            raise UserError(f"{source}: bearing.{key}: missing; bearing.cage_guidance = {b.cage_guidance!r} needs it "
                            f"(set it in the scenario or name a [bearing] preset that has it)")
    od, idia, c = b.cage_outer_diameter_mm, b.cage_inner_diameter_mm, b.cage_land_clearance_mm
    if b.cage_guidance == "outer_land" and od + c >= b.pitch_diameter_mm + b.roller_diameter_mm:
        exc = UserError(f"{source}: bearing.cage_land_clearance_mm: the outer land bore, cage OD + c_L = "
                        f"{od + c:g} mm, must be smaller than the outer raceway diameter "
                        f"{b.pitch_diameter_mm + b.roller_diameter_mm:g} mm")
        raise _involving(exc, "bearing.cage_outer_diameter_mm", "bearing.cage_guidance", *_RACEWAY_KEYS)
    if b.cage_guidance == "inner_land" and idia - c <= b.pitch_diameter_mm - b.roller_diameter_mm:
        exc = UserError(f"{source}: bearing.cage_land_clearance_mm: the inner land, cage ID - c_L = "
                        f"{idia - c:g} mm, must be larger than the inner raceway diameter "
                        f"{b.pitch_diameter_mm - b.roller_diameter_mm:g} mm")
        raise _involving(exc, "bearing.cage_inner_diameter_mm", "bearing.cage_guidance", *_RACEWAY_KEYS)
