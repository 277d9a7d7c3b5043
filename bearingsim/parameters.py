"""The parameters layer: a resolved scenario turned once into frozen SI objects. SI throughout.

Both models take a :class:`Parameters` and nothing else: no model reads a scenario's text keys or
converts a unit. The groups follow their lifetime (ROSS-style frozen dataclasses):

* :class:`Bearing`: geometry and masses of the bearing and its cage (fixed for a bearing design);
* :class:`OperatingPoint`: speeds, direction, load and gravity (what a test rig changes);
* :class:`ContactLubrication`: roller-cage impact and friction, oil-film drag, EHL traction;
* :class:`Numerics`: time step, run length, output rate;
* :class:`ReducedOptions` / :class:`MultibodyOptions`: the model options of each model;
* :class:`Wear`: Archard's coefficient and the cage hardness.

A new physical parameter is added in three places: the schema (:mod:`bearingsim.scenario`, with its
unit in the key name and a default or a preset value), its SI field in one group here (converted in
:meth:`Parameters.from_scenario`), and the model code that uses it (``docs/architecture.md``).
"""
from __future__ import annotations

import math
import dataclasses
from dataclasses import dataclass

import numpy as np

from bearingsim import laws


@dataclass(frozen=True)
class Bearing:
    """Bearing geometry and masses [SI]. Raceway radii follow from the pitch circle and the roller."""

    roller_count: int
    roller_radius: float  # r_r [m]
    roller_length: float  # l [m]
    roller_mass: float  # m [kg]
    pitch_radius: float  # r_p [m]
    pocket_clearance: float  # s [m]: pocket diameter minus roller diameter
    radial_clearance: float  # P_d [m], diametral, operating
    cage_mass: float  # [kg]
    cage_inertia: float  # polar moment [kg m^2]
    cage_guidance: str = "rollers"  # "rollers", "outer_land" or "inner_land"
    cage_land_clearance: float | None = None  # c_L [m], diametral, cage rim to ring land (land guidance)
    cage_outer_radius: float | None = None  # [m], the outer land contact radius
    cage_inner_radius: float | None = None  # [m], the inner land contact radius

    @property
    def cage_land_radius(self) -> float | None:
        """Radius of the cage rim that runs on the guiding land [m] (None: roller-guided cage)."""
        if self.cage_guidance == "outer_land":
            return self.cage_outer_radius
        if self.cage_guidance == "inner_land":
            return self.cage_inner_radius
        return None

    @property
    def outer_race_radius(self) -> float:
        """r_o = r_p + r_r (paper, Eq. 4) [m]."""
        return self.pitch_radius + self.roller_radius

    @property
    def inner_race_radius(self) -> float:
        """r_i = r_p - r_r [m]."""
        return self.pitch_radius - self.roller_radius

    @property
    def roller_inertia(self) -> float:
        """Solid cylinder about its axis, m r_r^2 / 2 [kg m^2]."""
        return 0.5 * self.roller_mass * self.roller_radius**2

    @property
    def palmgren_stiffness(self) -> float:
        """K of the roller's line contacts, Q = K delta^(10/9) [N / m^(10/9)]."""
        return laws.palmgren_stiffness(self.roller_length)


@dataclass(frozen=True)
class OperatingPoint:
    """Speeds (magnitudes), direction, load and gravity [SI]. ``sign`` is +1 forward, -1 reverse."""

    inner_ring_speed_rpm: float  # n_i [rpm], kept for labels and reports
    omega_i: float  # |inner ring| [rad/s], Eq. (10)
    omega_c: float  # epicyclic cage speed [rad/s], Eq. (11)
    omega_r: float  # roller spin [rad/s], Eq. (12)
    rolling_velocity: float  # V [m/s], Eq. (4)
    sign: int
    radial_load: float  # W [N], the rotor's weight: it points down (-y)
    gravity: float  # g [m/s^2], 0 when switched off


@dataclass(frozen=True)
class ContactLubrication:
    """Roller-cage contact and lubrication [SI]."""

    restitution: float  # e of a roller-cage impact, Eq. (6) [-]
    cage_friction: float  # roller-cage Coulomb friction coefficient [-]
    drag_coefficient: float  # c of Eq. (2), SI
    traction_mu_max: float  # EHL traction mu_max of mu = mu_max tanh(slip / slip_ref) [-]
    traction_slip_ref: float  # slip_ref of the traction curve [-]
    land_friction: float = 0.0  # Coulomb friction of the cage rim on its guiding land [-]


@dataclass(frozen=True)
class Numerics:
    """Time step and run length."""

    dt: float | None  # [s]; None: the model chooses
    rotations: int  # recorded cage rotations
    warmup_rotations: int  # cage rotations run before recording
    output_rate: float  # time-series samples per second [Hz]
    #: motion of every body (multibody model, ``[output] motion_*``): the window's start and length in
    #: recorded cage rotations (length 0: no motion) and the poses per cage rotation
    motion_start: float = 0.0
    motion_rotations: float = 0.0
    motion_samples_per_rotation: int = 0


@dataclass(frozen=True)
class ReducedOptions:
    """Options of the reduced single-pocket model (and of the reduced-equivalent multibody scene)."""

    method: str  # "event" or "euler"
    load_zone_half_angle: float  # phi [rad]: the scenario's value or the quasi-static one
    load_zone_rule: str  # how phi was obtained: "given" or "quasi-static"
    resting_contact: bool  # count the resting-contact impulse of Eq. (9)


@dataclass(frozen=True)
class MultibodyOptions:
    """Options of the multi-pocket model."""

    scene: str  # "full", "reduced_equivalent", "kinematic_cage" or "centred_cage" (docs/crosscheck.md)
    inner_ring: str  # "auto", "quasi_static" or "dynamic"
    inner_ring_mass: float | None  # [kg]; None: the rotor's mass W / g
    #: angular extent (psi_in, psi_out) of each arc pocket face from the pocket's circumferential centre
    #: line, inward negative [rad] (:func:`bearingsim.laws.pocket_face_extent`)
    pocket_face_extent: tuple[float, float]
    pocket_face_rule: str  # how the extent was obtained: "cage wall" or "given"
    pocket_face_segments: int  # 0: exact arc faces; N: each arc face a circumscribed polyline of N segments
    flat_pockets: tuple[int, ...]  # pockets with two plane faces D + s apart (the rig's instrumented pocket)
    raceway_contact: str = "hertz"  # "hertz" (Palmgren springs) or "rigid" (rollers held on the outer race)


@dataclass(frozen=True)
class Wear:
    """Archard wear of the cage: V = k W L / H; and the depth the pocket faces have worn already."""

    wear_coefficient: float  # k [-]
    hardness: float  # H [Pa]
    #: worn depth of each pocket's (front, rear) face per bin of psi, equal bins over the faces' extent
    #: ``[pocket][face][bin]`` [m]; None: unworn faces (docs/wear.md, "Worn faces")
    worn_depth: tuple[tuple[tuple[float, ...], ...], ...] | None = None


def _motion_window(out, rotations: int) -> dict:
    """The motion window of ``[output]`` in recorded rotations: "last" ends it with the run, and a
    window longer than the run is the whole run."""
    length = min(float(out.motion_rotations), float(rotations))
    start = rotations - length if out.motion_start_rotation == "last" else float(out.motion_start_rotation)
    return dict(motion_start=start, motion_rotations=length,
                motion_samples_per_rotation=int(out.motion_samples_per_rotation))


def _speeds(bearing: "Bearing", rpm: float) -> dict:
    """The speeds of an :class:`OperatingPoint` at the inner-ring speed ``rpm`` [rpm]: the ring's, the cage's
    epicyclic speed (Eq. 11), the roller's spin and its rolling velocity."""
    omega_i = laws.inner_ring_angular_speed(rpm)
    omega_c = laws.cage_angular_speed(omega_i, bearing.roller_radius, bearing.pitch_radius)
    omega_r = laws.roller_spin_speed(omega_i, bearing.roller_radius, bearing.pitch_radius)
    return dict(inner_ring_speed_rpm=float(rpm), omega_i=omega_i, omega_c=omega_c, omega_r=omega_r,
                rolling_velocity=laws.rolling_speed(omega_r, omega_c, bearing.roller_radius, bearing.outer_race_radius))


@dataclass(frozen=True)
class Parameters:
    """Everything a model run depends on, in SI, grouped by lifetime.

    ``name`` and ``model`` identify the run (labels); :meth:`from_scenario` is the only place where
    scenario keys are read and units converted.
    """

    name: str
    model: str
    bearing: Bearing
    operating: OperatingPoint
    contact: ContactLubrication
    numerics: Numerics
    reduced: ReducedOptions
    multibody: MultibodyOptions
    wear: Wear

    def at_speed(self, rpm: float) -> "Parameters":
        """These parameters at the inner-ring speed ``rpm`` [rpm], the speeds derived as :meth:`from_scenario`
        derives them and everything else as it is."""
        return dataclasses.replace(self, operating=dataclasses.replace(self.operating, **_speeds(self.bearing, rpm)))

    @classmethod
    def from_scenario(cls, scenario) -> "Parameters":
        """Build the SI parameters of a resolved :class:`bearingsim.scenario.Scenario`."""
        bearing = _bearing(scenario.bearing)
        o = scenario.operating
        operating = OperatingPoint(
            **_speeds(bearing, o.inner_ring_speed_rpm),
            sign=1 if o.direction == "forward" else -1,
            radial_load=float(o.radial_load_N),
            gravity=laws.STANDARD_GRAVITY if o.gravity else 0.0,
        )
        mb = scenario.multibody
        contact = ContactLubrication(
            restitution=float(scenario.contact.restitution),
            cage_friction=float(scenario.contact.cage_friction),
            drag_coefficient=float(scenario.lubrication.drag_coefficient),
            traction_mu_max=float(mb.traction_mu_max),
            traction_slip_ref=float(mb.traction_slip_ref),
            land_friction=float(scenario.contact.land_friction),
        )
        nu = scenario.numerics
        numerics = Numerics(
            dt=None if nu.dt_s is None else float(nu.dt_s),
            rotations=int(nu.rotations),
            warmup_rotations=int(nu.warmup_rotations),
            output_rate=float(nu.output_rate_hz),
            **_motion_window(scenario.output, int(nu.rotations)),
        )
        r = scenario.reduced
        given = None if r.load_zone_half_angle_deg == "auto" else float(r.load_zone_half_angle_deg)
        reduced = ReducedOptions(
            method=r.method,
            load_zone_half_angle=laws.load_zone_half_angle(given, operating.radial_load, bearing.roller_count,
                                                           bearing.roller_length, bearing.radial_clearance),
            load_zone_rule="quasi-static" if given is None else "given",
            resting_contact=bool(r.resting_contact),
        )
        face_extent = _face_extent(mb.pocket_face_half_angle_deg, bearing)
        multibody = MultibodyOptions(
            scene=mb.scene,
            inner_ring=mb.inner_ring,
            inner_ring_mass=None if mb.inner_ring_mass_kg == "auto" else float(mb.inner_ring_mass_kg),
            pocket_face_extent=face_extent,
            pocket_face_rule="given" if mb.pocket_face_half_angle_deg != "auto" else "cage wall",
            pocket_face_segments=int(mb.pocket_face_segments),
            flat_pockets=(tuple(range(bearing.roller_count)) if mb.pocket_shape == "flat"
                          else tuple(sorted(mb.flat_pockets))),
            raceway_contact=mb.raceway_contact,
        )
        wear = Wear(wear_coefficient=float(scenario.wear.wear_coefficient),
                    hardness=float(scenario.wear.hardness_Pa), worn_depth=_worn_depth(scenario.wear))
        return cls(name=scenario.name, model=scenario.model, bearing=bearing, operating=operating,
                   contact=contact, numerics=numerics, reduced=reduced, multibody=multibody, wear=wear)


def _bearing(b) -> Bearing:
    """The SI :class:`Bearing` of a scenario's ``[bearing]`` section."""
    return Bearing(
        roller_count=b.roller_count,
        roller_radius=b.roller_diameter_mm * 0.5e-3,
        roller_length=b.roller_length_mm * 1e-3,
        roller_mass=b.roller_mass_kg,
        pitch_radius=b.pitch_diameter_mm * 0.5e-3,
        pocket_clearance=b.pocket_clearance_mm * 1e-3,
        radial_clearance=b.radial_clearance_mm * 1e-3,
        cage_mass=b.cage_mass_kg,
        cage_inertia=b.cage_inertia_kgm2,
        cage_guidance=b.cage_guidance,
        cage_land_clearance=None if b.cage_land_clearance_mm is None else b.cage_land_clearance_mm * 1e-3,
        cage_outer_radius=None if b.cage_outer_diameter_mm is None else b.cage_outer_diameter_mm * 0.5e-3,
        cage_inner_radius=None if b.cage_inner_diameter_mm is None else b.cage_inner_diameter_mm * 0.5e-3,
    )


def _face_extent(half_angle_deg, bearing: Bearing) -> tuple[float, float]:
    """The arc faces' extent (psi_in, psi_out) [rad]: ``multibody.pocket_face_half_angle_deg`` when given,
    else what the cage wall allows (:func:`bearingsim.laws.pocket_face_extent`); NaN for a reduced-model
    scenario whose preset has no cage ring (the faces are not used)."""
    if half_angle_deg != "auto":
        half = math.radians(float(half_angle_deg))
        return (-half, half)
    if bearing.cage_inner_radius is not None and bearing.cage_outer_radius is not None:
        return laws.pocket_face_extent(bearing.pitch_radius, bearing.roller_radius + 0.5 * bearing.pocket_clearance,
                                       bearing.cage_inner_radius, bearing.cage_outer_radius)
    return (math.nan, math.nan)


def _worn_depth(w) -> tuple | None:
    """``[pocket][face (front, rear)][bin]`` worn depth [m] of a scenario's ``[wear]`` section (a face not
    given is unworn); None when neither face is given or every depth is 0 (the unworn faces' code path)."""
    rows = [v for v in (w.worn_depth_front_um, w.worn_depth_rear_um) if v is not None]
    if not rows or not any(x > 0.0 for v in rows for row in v for x in row):
        return None
    zero = [[0.0] * len(row) for row in rows[0]]
    front = w.worn_depth_front_um if w.worn_depth_front_um is not None else zero
    rear = w.worn_depth_rear_um if w.worn_depth_rear_um is not None else zero
    return tuple((tuple(x * 1e-6 for x in f), tuple(x * 1e-6 for x in r)) for f, r in zip(front, rear))


def paper_assumptions(scene: str) -> bool:
    """True for the scene that makes the reduced model's assumptions in the plane (no inner ring, no
    traction, roller spin fixed, rollers held at the front of their pockets through the load zone):
    ``reduced_equivalent``. Every other scene has the inner ring, traction and free spin."""
    return scene == "reduced_equivalent"


def inner_ring_mode(p) -> tuple[str, str]:
    """What the multibody model makes of its inner ring: ``("none", why)`` in the scene of the paper's
    assumptions (:func:`paper_assumptions`), else ``("quasi_static" | "dynamic", why)``.

    ``multibody.inner_ring = "auto"`` keeps the quasi-static ring while the load is always shared by at
    least two rollers (:func:`bearingsim.laws.loaded_rollers_with_one_at_centre` >= 2) or there is no
    load, and otherwise makes it dynamic: a ring resting on a single roller has no stable sideways
    equilibrium, so the rotor's inertia decides where it goes. ``why`` says how "auto" chose ("" when
    the mode is given)."""
    mb = p.multibody
    if paper_assumptions(mb.scene):
        return "none", "reduced-equivalent scene"
    if mb.inner_ring != "auto":
        return mb.inner_ring, ""
    load = p.operating.radial_load
    if load <= 0.0:
        return "quasi_static", "auto: no radial load"
    geo = p.bearing
    k = laws.loaded_rollers_with_one_at_centre(load, geo.roller_count, geo.roller_length, geo.radial_clearance)
    return ("quasi_static" if k >= 2 else "dynamic",
            f"auto: {k} roller(s) loaded with one at the load-zone centre "
            f"({'>= 2: quasi-static' if k >= 2 else 'the ring would rest on one roller: dynamic'})")


def pocket_angles(roller_count: int, sign: int) -> np.ndarray:
    """Cage-frame angles [rad] of the pocket centres at cage angle 0.

    Pocket 0 sits at the bottom (load-zone centre); pocket ``i`` trails pocket 0 by ``i`` pitches,
    so its angle from the load-zone centre, measured in the direction of cage rotation, starts at
    ``-2 pi i / n``.
    """
    i = np.arange(roller_count)
    return -0.5 * math.pi - sign * 2.0 * math.pi * i / roller_count
