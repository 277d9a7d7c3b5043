"""Driver of the multi-pocket model: scene, time step, run set-up, errors, results. SI throughout.

See the package docstring of :mod:`bearingsim.multibody` for the definitions of the recorded
quantities. Per time step ``h`` (:mod:`bearingsim.multibody.loop`) the body states are read in one
batch, the raceway forces computed by one numba kernel (:func:`bearingsim.multibody.forces.raceway_forces`)
at the predicted positions and handed to pymunk in one batch, pymunk's step solves the roller-cage
contacts, and :func:`bearingsim.multibody.recorder.record_step` attributes the arbiter impulses to
pockets, faces and rotations. The loop over steps is compiled (:mod:`bearingsim.multibody.chipmunk`)
or, where pymunk's private C interface is not as expected, plain Python over pymunk's public API;
Python sees the compiled loop only every 2048 output samples, to write them and move the progress bar.

:func:`run` assembles the kernels' named inputs: :class:`~bearingsim.multibody.forces.RacewayParams`,
:class:`~bearingsim.multibody.recorder.RecorderConfig` and the accumulators of
:func:`~bearingsim.multibody.recorder.accumulators`, :class:`~bearingsim.multibody.loop.LoopLimits`,
:class:`~bearingsim.multibody.loop.HoldRule`, :class:`~bearingsim.multibody.loop.StepInputs`,
:class:`~bearingsim.multibody.loop.StepWork` and a :data:`~bearingsim.multibody.loop.LOOP_STATE` record.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from bearingsim import laws
from bearingsim.errors import SimulationUnstable, UserError
from bearingsim.multibody import forces as fk
from bearingsim.multibody import chipmunk
from bearingsim.multibody import loop as lp
from bearingsim.multibody import recorder as rk
from bearingsim.multibody.scene import build_scene

# --- fixed model choices (documented, not tuned) ------------------------------------------------
# exact arc faces: a roller further than this fraction of the play R - r from its pocket centre has its faces
# placed for the step (closer, it cannot reach them: chipmunk's overlap correction moves it by far less)
ARC_NEAR_FRACTION = 0.5
CONTACT_DAMPING_S = 2.5e-6  # c = c_r k_lin [s]; lower end of the range 0.25e-5..2.5e-5 s of Kraemer (1993) / Sopanen & Mikkola (2003): the normal force is explicit
DAMPING_FADE_M = 5.0e-9  # fade-in depth of the contact damping (continuity of Q at delta = 0)
MIN_ENTRAINMENT_M_S = 0.1  # floor of the entrainment speed in the traction slip ratio
DRAG_DIRECTION_EPS_M_S = 1.0e-3  # regularisation speed of the sign of the drag force
NEWTON_MAX_STEP_M = 2.0e-6  # step limit of the ring-centre Newton iteration
IMPACT_SPEED_THRESHOLD_M_S = 0.01  # approach speed above which a contact step is an impact
THETA_BINS = 360
IMPACT_CAPACITY = 200_000
# automatic dt: fraction of the explicit Hertz stability limit 2/omega_n (the kernel is implicitly
# linearised, so this is an accuracy choice: ~12 steps per contact period)
DT_FRACTION = 0.5
DT_MAX_FACTOR = 2.0  # dt above this multiple of 2/omega_n is refused (UserError); between 1x and 2x a run may still blow up (SimulationUnstable)
IMPACT_OVERLAP_FRACTION = 0.005  # auto dt: one step's approach at the impact speed <= 0.5 % of s
DT_CAP_S = 2.0e-5  # never above this (impact resolution: s / v_rel >> dt for v_rel ~ 1 m/s)

PENETRATION_LIMIT = 0.01  # largest roller-cage overlap accepted, as a fraction of the pocket clearance
RESTART_MARGIN = 0.8  # a restarted run's step keeps the approach that stopped it at this fraction of the bound
# land-guided cage: the land contact is a linear penalty whose stiffness keeps the overlap below
# LAND_OVERLAP_FRACTION of c_L/2 under land_reference_force(); a run whose cage goes further than
# LAND_ORBIT_MARGIN x c_L/2 beyond the land (ten times that bound) is stopped as a lost cage
LAND_OVERLAP_FRACTION = 0.01
LAND_ORBIT_MARGIN = 0.1

# rigid raceways (multibody.raceway_contact = "rigid", docs/fast_scene.md): the rollers ride on the
# outer race held by a unilateral joint, so no raceway spring limits the step
# auto dt: one step's approach at the estimated impact speed <= 0.8 % of s, RESTART_MARGIN x the 1 % bound (a
# restart's own margin). The free-flight estimate misses the faster approaches of the load zone and its exit
# (front faces, up to 1.16 x the estimate at 6000 rpm); at the bound itself they restarted the reference
# bearing's runs at 1000, 3000 and 6000 rpm, late in the run (docs/fast_scene.md, *Time step*)
RIGID_IMPACT_OVERLAP_FRACTION = RESTART_MARGIN * PENETRATION_LIMIT
RIGID_DT_CAP_S = 1.0e-4  # never above this
RIGID_START_OVERLAP_FRACTION = 0.005  # the start phase's step: the cage's fall within 0.5 % of s per step
# the roller must press on the outer race with its centrifugal load: m r omega_c^2 >= this multiple of
# its weight, so the rollers at the top stay on the race against gravity and the cage's pushes
RIGID_MIN_CENTRIFUGAL_RATIO = 1.5


def land_reference_force(p) -> float:
    """Largest radial force [N] expected on a land-guided cage: the radial load, the centrifugal loads
    of all rollers and the cage's weight, ``W + Z m r_p omega_c^2 + m_cage g``. The cage is pushed
    radially only by its weight and by the rollers, and the rollers' forces on it come from what the
    raceways give them, which sums to about W and the centrifugal loads."""
    g, op = p.bearing, p.operating
    return (op.radial_load + g.roller_count * g.roller_mass * g.pitch_radius * op.omega_c**2
            + g.cage_mass * op.gravity)


def land_params(p, active: bool) -> fk.LandParams:
    """:class:`~bearingsim.multibody.forces.LandParams` of the cage's guiding land (inactive: rollers).

    Stiffness ``k = F_ref / (LAND_OVERLAP_FRACTION c_L/2)`` with ``F_ref`` from
    :func:`land_reference_force`; damping ``c = c_r k`` with the raceway contacts' ``c_r``
    (``CONTACT_DAMPING_S``). For the reference cage (c_L = 0.30 mm, 970 N, 3000 rpm) k ~ 8e8 N/m, of
    the order of the linearised Palmgren stiffness of a few-mm-wide steel line contact at ~100 N
    (~2e8 N/m for l = 5 mm), and 2/omega_n = 2 sqrt(m_cage / k) ~ 3e-5 s, ten times the time step.
    """
    g, op = p.bearing, p.operating
    if not active:
        return fk.LandParams(active=False, side=1.0, rim_radius=0.0, half_clearance=0.0, stiffness=0.0, damping=0.0,
                             damping_fade=DAMPING_FADE_M, friction=0.0, inner=False, omega_ring=0.0,
                             slide_eps=DRAG_DIRECTION_EPS_M_S)
    half = 0.5 * g.cage_land_clearance
    k = land_reference_force(p) / (LAND_OVERLAP_FRACTION * half)
    inner = g.cage_guidance == "inner_land"
    return fk.LandParams(active=True, side=-1.0 if inner else 1.0, rim_radius=float(g.cage_land_radius),
                         half_clearance=float(half), stiffness=float(k), damping=float(CONTACT_DAMPING_S * k),
                         damping_fade=DAMPING_FADE_M, friction=float(p.contact.land_friction), inner=inner,
                         omega_ring=float(op.sign * op.omega_i) if inner else 0.0, slide_eps=DRAG_DIRECTION_EPS_M_S)


# scenes whose cage is a pymunk KINEMATIC body turning at the epicyclic speed about the bearing axis
KINEMATIC_CAGE_SCENES = ("reduced_equivalent", "kinematic_cage")


def paper_assumptions(scene: str) -> bool:
    """True for the scene that makes the reduced model's assumptions in the plane (no inner ring, no
    traction, roller spin fixed, rollers held at the front of their pockets through the load zone):
    ``reduced_equivalent``. Every other scene has the inner ring, traction and free spin."""
    return scene == "reduced_equivalent"


class PenetrationExceeded(Exception):
    """A roller overlapped a cage face by more than ``PENETRATION_LIMIT`` of s: the step is too long
    for the approach speeds of this scene (the run is stopped, not written)."""

    def __init__(self, pen, limit, dt, t, approach, how=""):
        self.pen, self.limit, self.dt, self.t, self.approach = pen, limit, dt, t, approach
        self.how = how  # how the stopped run's step was chosen (its dt_choice)
        super().__init__(f"roller-cage overlap {pen:.3g} m > {limit:.3g} m at t = {t:.4g} s with dt = {dt:.3g} s "
                         f"(approach speed {approach:.3g} m/s)")

    def suggested_dt(self) -> float:
        """A step that keeps the same approach under ``RESTART_MARGIN`` (80 %) of the limit (the overlap is ~ v dt)."""
        return RESTART_MARGIN * self.dt * self.limit / self.pen


def inner_ring_model(p):
    """(mass [kg], description) of the inner ring: mass 0 is quasi-static (massless).

    ``multibody.inner_ring = "auto"`` keeps the quasi-static ring while the load is always shared by at
    least two rollers (:func:`bearingsim.kinematics.loaded_rollers_with_one_at_centre` >= 2) or there
    is no load, and otherwise makes it dynamic: a ring resting on a single roller has no stable
    sideways equilibrium, so the rotor's inertia decides where it goes. The dynamic ring's mass is
    ``multibody.inner_ring_mass_kg``; "auto" takes the radial load as the weight of the rotor the
    bearing carries (the paper's rig), ``M = W / g_n``.
    """
    mb = p.multibody
    if paper_assumptions(mb.scene):
        return 0.0, "none (reduced-equivalent scene)"
    geo = p.bearing
    load = p.operating.radial_load
    mode = mb.inner_ring
    why = ""
    if mode == "auto":
        if load <= 0.0:
            mode, why = "quasi_static", "auto: no radial load"
        else:
            k = laws.loaded_rollers_with_one_at_centre(load, geo.roller_count, geo.roller_length,
                                                      geo.radial_clearance)
            mode = "quasi_static" if k >= 2 else "dynamic"
            why = (f"auto: {k} roller(s) loaded with one at the load-zone centre "
                   f"({'>= 2: quasi-static' if k >= 2 else 'the ring would rest on one roller: dynamic'})")
    if mode == "quasi_static":
        return 0.0, "quasi-static (massless)" + (f"; {why}" if why else "")
    if mb.inner_ring_mass is None:
        if load <= 0.0:
            raise UserError("multibody.inner_ring_mass_kg: a dynamic inner ring without radial load needs its "
                            "mass (there is no rotor weight to take it from); set it in kg")
        mass = load / laws.STANDARD_GRAVITY
        src = f"W / g_n = {mass:.4g} kg"
    else:
        mass = mb.inner_ring_mass
        src = f"multibody.inner_ring_mass_kg = {mass:.4g} kg"
    return mass, f"dynamic, mass {src}" + (f"; {why}" if why else "")


def rigid(p) -> bool:
    """True when the raceway contacts are rigid (``multibody.raceway_contact = "rigid"``)."""
    return p.multibody.raceway_contact == "rigid"


def rigid_radius(p) -> float:
    """Radius [m] of a roller centre on the outer race, r_c = r_o + P_d/4 - r_r (the rigid raceways'
    joint; P_d = 0 in the reduced-equivalent scene, which keeps the paper's roller path)."""
    g = p.bearing
    pd = 0.0 if paper_assumptions(p.multibody.scene) else g.radial_clearance
    return g.outer_race_radius + 0.25 * pd - g.roller_radius


def rigid_speed_floor(p) -> float:
    """Lowest inner-ring speed [rpm] the rigid raceways accept (:data:`RIGID_MIN_CENTRIFUGAL_RATIO`)."""
    op = p.operating
    r = rigid_radius(p)
    omega_c = math.sqrt(RIGID_MIN_CENTRIFUGAL_RATIO * max(op.gravity, 0.0) / r)
    return omega_c / max(op.omega_c / op.omega_i, 1e-300) * 30.0 / math.pi


def max_roller_load(p) -> float:
    """Estimate of the largest raceway load [N]: Stribeck 5 W / Z plus the centrifugal load."""
    g = p.bearing
    op = p.operating
    return 5.0 * op.radial_load / g.roller_count + g.roller_mass * g.pitch_radius * op.omega_c**2 + 1.0


RACEWAY_APPROACH_FACTOR = 3.0  # blow-up: approach > 3x that of one roller carrying the whole load alone


def raceway_approach_limit(p) -> float:
    """Largest outer-raceway approach [m] a sound run reaches, with margin: ``RACEWAY_APPROACH_FACTOR``
    times the Palmgren approach of one roller carrying the whole radial load and its centrifugal load
    alone (no roller ever carries more), and never below ``loop.DELTA_LIMIT_M`` (50 um). Beyond it the
    run has blown up. (A fixed 50 um refused a legitimate 100 kN load: the most loaded roller's
    approach is ~50 um per race there.)"""
    g, op = p.bearing, p.operating
    q = op.radial_load + g.roller_mass * g.pitch_radius * op.omega_c**2
    return max(lp.DELTA_LIMIT_M, RACEWAY_APPROACH_FACTOR * (q / laws.palmgren_stiffness(g.roller_length)) ** 0.9)


def stability_limit(p) -> float:
    """Explicit stability limit 2/omega_n [s] of a roller between two linearised Palmgren contacts."""
    g = p.bearing
    K = laws.palmgren_stiffness(g.roller_length)
    q = max_roller_load(p)
    delta = (q / K) ** 0.9
    k_lin = 10.0 / 9.0 * q / delta
    omega_n = math.sqrt(2.0 * k_lin / g.roller_mass)
    return 2.0 / omega_n


def impact_dt(p) -> float:
    """Impact resolution [s]: a rear impact may overlap the face by at most 0.5 % of s in one step.

    Approach speed estimate: free flight across the clearance under the no-load-zone deceleration
    (F_o at the centrifugal load, plus g), ``v = sqrt(2 a s)``, as in the reduced model.
    """
    g = p.bearing
    op = p.operating
    n_c = g.roller_mass * g.pitch_radius * op.omega_c**2
    f_o = laws.oil_film_drag(p.contact.drag_coefficient, n_c, op.rolling_velocity)
    a = float(f_o) / g.roller_mass + op.gravity + 1e-3
    v = math.sqrt(2.0 * a * g.pocket_clearance)
    return IMPACT_OVERLAP_FRACTION * g.pocket_clearance / v


def land_stability_limit(p) -> float:
    """Explicit stability limit 2/omega_n [s] of the cage on its land's penalty contact (inf: roller-guided)."""
    land = land_params(p, active=p.multibody.scene == "full" and p.bearing.cage_guidance != "rollers")
    return 2.0 * math.sqrt(p.bearing.cage_mass / land.stiffness) if land.active else math.inf


def choose_dt(p, dt=None):
    """(dt [s], how it was chosen, explicit limit [s]). Raises UserError for a dt far above stable."""
    if rigid(p):
        return _choose_dt_rigid(p, dt)
    lim = stability_limit(p)
    largest = DT_MAX_FACTOR * lim
    if dt is None and p.numerics.dt is not None:
        dt = p.numerics.dt
        how = "numerics.dt_s"
    elif dt is not None:
        how = "simulate(dt=...)"
    else:
        dti = impact_dt(p)
        dt = min(DT_FRACTION * lim, dti, DT_CAP_S)
        how = (f"auto: min of {DT_FRACTION} x 2/omega_n of the stiffest raceway contact "
               f"(Palmgren, Q_max = {max_roller_load(p):.0f} N; 2/omega_n = {lim:.3e} s), "
               f"impact resolution {IMPACT_OVERLAP_FRACTION} s / v_impact = {dti:.3e} s, and {DT_CAP_S:.0e} s")
    if dt > largest:
        raise UserError(
            f"numerics.dt_s = {dt:.3g} s is far above the stable time step of this bearing "
            f"(Hertz limit 2/omega_n = {lim:.3g} s): use at most {largest:.3g} s, or remove numerics.dt_s "
            f"for the automatic {min(DT_FRACTION * lim, DT_CAP_S):.3g} s")
    return float(dt), how, lim


def _choose_dt_rigid(p, dt):
    """Rigid raceways: no raceway spring; the step resolves the roller-cage impacts (and the land's
    penalty contact of a land-guided cage). Returns (dt, how, explicit limit [s] (the land's or inf))."""
    lim = land_stability_limit(p)
    largest = DT_MAX_FACTOR * lim
    if dt is None and p.numerics.dt is not None:
        dt, how = p.numerics.dt, "numerics.dt_s"
    elif dt is not None:
        how = "simulate(dt=...)"
    else:
        s = p.bearing.pocket_clearance
        dti = RIGID_IMPACT_OVERLAP_FRACTION / IMPACT_OVERLAP_FRACTION * impact_dt(p)
        dt = min(dti, DT_FRACTION * lim, RIGID_DT_CAP_S)
        how = (f"auto (rigid raceways): min of impact resolution {RIGID_IMPACT_OVERLAP_FRACTION:g} s / v_impact = "
               f"{dti:.3e} s (s = {s * 1e3:.3g} mm)"
               + (f", {DT_FRACTION} x 2/omega_n of the cage on its land = {DT_FRACTION * lim:.3e} s"
                  if math.isfinite(lim) else "")
               + f" and {RIGID_DT_CAP_S:.0e} s")
    if dt > largest:
        raise UserError(
            f"numerics.dt_s = {dt:.3g} s is far above the stable time step of the cage on its land "
            f"(2/omega_n = {lim:.3g} s): use at most {largest:.3g} s, or remove numerics.dt_s")
    return float(dt), how, lim


def rigid_start(p, dt):
    """Rigid raceways with the automatic step: the start phase, (its duration [s], its step [s]).

    The cage starts centred and settles onto its rollers (or its land) under gravity: a fall across
    the pocket clearance s, ``v_fall = sqrt(2 g s)``, bouncing with the roller-cage restitution e for
    ``t_fall (1 + e) / (1 - e)`` (a bouncing ball; 58 ms on the reference bearing), at most one cage
    rotation. Those first contacts come faster than the steady impacts the automatic step is set for
    (measured on the reference bearing with the start phase off: 0.11 m/s at 500 rpm and 0.10 m/s at
    3000 rpm within the first 10 ms, against the automatic step's estimates of 0.07 and 0.09 m/s), and
    at the 1 % bound they would restart the whole run with a shorter step. The start phase runs at the step
    that keeps ``v_fall`` within 0.5 % of s (the Hertz scene's margin), if that is shorter.
    Returns (0, dt) when there is no fall (no gravity)."""
    g, op = p.bearing, p.operating
    s = g.pocket_clearance
    e = p.contact.restitution
    if op.gravity <= 0.0:
        return 0.0, dt
    t_fall = math.sqrt(2.0 * s / op.gravity)
    t_settle = t_fall * (1.0 + e) / (1.0 - e) if e < 1.0 else math.inf
    t_start = min(t_settle, 2.0 * math.pi / op.omega_c)
    dt_start = RIGID_START_OVERLAP_FRACTION * s / math.sqrt(2.0 * op.gravity * s)
    return t_start, min(dt, dt_start)


def check_rigid(p):
    """Refuse (UserError) what the rigid raceways cannot represent: rollers that would leave the outer race."""
    g, op = p.bearing, p.operating
    fc = g.roller_mass * rigid_radius(p) * op.omega_c**2
    w = g.roller_mass * op.gravity
    if fc < RIGID_MIN_CENTRIFUGAL_RATIO * w:
        raise UserError(
            f"multibody.raceway_contact = 'rigid': at {op.inner_ring_speed_rpm:g} rpm a roller's centrifugal load "
            f"({fc:.3g} N) is less than {RIGID_MIN_CENTRIFUGAL_RATIO:g} x its weight ({w:.3g} N), so the rollers at "
            f"the top leave the outer race, which rigid raceways do not model; use raceway_contact = 'hertz' "
            f"below {rigid_speed_floor(p):.0f} rpm")


def face_geometry(sc, rr, margin):
    """:class:`bearingsim.multibody.loop.FaceMasks` of the scene's pocket faces for a roller of radius
    ``rr`` [m] and a margin [m]; None when the segments share one category bit (too many for a bit each)."""
    if sc.face_bits is None:
        return None
    fs = sc.face_segments
    ends = fs[..., 2:4] - fs[..., 0:2]
    e2 = np.sum(ends * ends, axis=-1)
    inv = np.divide(1.0, e2, out=np.zeros_like(e2), where=e2 > 0.0)  # unused rows: bit 0, never tested
    reach = rr + margin
    clear = sc.pocket_radius - rr - margin
    arc = np.array([pair[0] is not None for pair in sc.arc_shapes], dtype=np.bool_) if sc.arc_shapes is not None \
        else np.zeros(len(fs), dtype=np.bool_)
    return lp.FaceMasks(True, np.concatenate([fs[..., 0:2], ends, inv[..., None]], axis=-1), sc.face_bits,
                        np.ascontiguousarray(sc.pocket_centres, dtype=np.float64),
                        clear * clear if clear > 0.0 else -1.0, reach * reach, arc)


def arc_faces(sc, rr, sign) -> "lp.ArcFaces":
    """:class:`bearingsim.multibody.loop.ArcFaces` of a scene with exact arc faces (roller radius ``rr`` [m],
    ``sign`` of the rotation)."""
    n = len(sc.arc_shapes)
    a = np.asarray(sc.pocket_body_angle, dtype=np.float64)
    sign = 1.0 if sign > 0 else -1.0
    e_r = np.stack([np.cos(a), np.sin(a)], axis=1)
    e_t = sign * np.stack([-np.sin(a), np.cos(a)], axis=1)
    play = sc.pocket_radius - rr
    near = ARC_NEAR_FRACTION * play
    from bearingsim.multibody.scene import TANGENT_HALF_LENGTH

    return lp.ArcFaces(True, np.array([pair[0] is not None for pair in sc.arc_shapes], dtype=np.bool_),
                       np.ascontiguousarray(sc.pocket_centres, dtype=np.float64), np.ascontiguousarray(e_t),
                       np.ascontiguousarray(e_r), float(sc.pocket_radius), float(sc.extent[0]), float(sc.extent[1]),
                       float(TANGENT_HALF_LENGTH * sc.pocket_radius), float(near * near))


def face_radial_reach(p) -> float:
    """How far [m] the cage centre can move off the axis while the rollers still hold it: the radial reach
    of the arc faces from the pocket centre, ``R sin(min(-psi_in, psi_out))``."""
    lo, hi = p.multibody.pocket_face_extent
    return (p.bearing.roller_radius + 0.5 * p.bearing.pocket_clearance) * math.sin(min(-lo, hi))


def run(p, sink=None, progress=False, dt=None, penetration_limit=PENETRATION_LIMIT,
        step_loop=None):
    """Run the parameters ``p``; return a dict of raw accumulators (see :class:`MultibodyResult`).

    Time series go to ``sink`` (``timeseries(...)`` appenders; see :class:`bearingsim.results.MemorySink`).

    ``step_loop``: "compiled", "plain" or None (see :mod:`bearingsim.multibody.chipmunk`); which one ran is
    ``raw["step_loop"]``.
    """
    t_wall0 = time.perf_counter()
    geo = p.bearing
    op = p.operating
    scene_kind = p.multibody.scene
    # two separate choices of the scene (docs/crosscheck.md): the paper's assumptions (no inner ring,
    # no traction, fixed spin, rollers held at the front of their pockets in the load zone, roller path
    # on the pitch circle) and a kinematic cage turning at the epicyclic speed
    reduced_eq = paper_assumptions(scene_kind)
    kinematic = scene_kind in KINEMATIC_CAGE_SCENES
    n = geo.roller_count
    if n < 3:
        raise UserError(f"bearing.roller_count = {n}: the multibody model needs at least 3 rollers")
    is_rigid = rigid(p)
    if is_rigid:
        check_rigid(p)
    h, dt_how, dt_lim = choose_dt(p, dt)
    # rigid raceways, automatic step: the cage's settling at the start at a step of its own
    t_start, h_start = rigid_start(p, h) if is_rigid and dt is None and p.numerics.dt is None else (0.0, h)
    if h_start < h:
        dt_how += f"; the first {t_start:.3g} s (the cage settling onto its rollers) at {h_start:.3e} s"
    else:
        t_start = 0.0
    sign = op.sign
    e = p.contact.restitution
    mu_c = p.contact.cage_friction
    warm = p.numerics.warmup_rotations
    nrot = p.numerics.rotations
    s = geo.pocket_clearance
    rr = geo.roller_radius
    rp = geo.pitch_radius
    K = laws.palmgren_stiffness(geo.roller_length)
    # the reduced-equivalent scene keeps the paper's roller path on the pitch circle (no clearance)
    pd = 0.0 if reduced_eq else geo.radial_clearance
    ro_race = geo.outer_race_radius + 0.25 * pd
    ri_race = geo.inner_race_radius - 0.25 * pd
    # rigid raceways: roller centres on the outer race, at most r_c from the axis (a unilateral joint);
    # the inner-race contact carries both contacts' compliance in series, Q = K 2^(-10/9) delta^(10/9)
    r_c = rigid_radius(p)
    K_race = K * 2.0 ** (-10.0 / 9.0) if is_rigid else K

    n_seg = p.multibody.pocket_face_segments
    sc = build_scene(geo, op, e, mu_c, extent=p.multibody.pocket_face_extent,
                     n_seg=n_seg, kinematic_cage=kinematic, spin_free=not reduced_eq,
                     flat_pockets=p.multibody.flat_pockets, centred_cage=scene_kind == "centred_cage",
                     rigid_radius=r_c if is_rigid else None)
    space = sc.space
    nb = n + 1
    # rollers start on the outer race (centrifugal), moving with the cage
    n_centrifugal = geo.roller_mass * rp * op.omega_c**2 + 1e-3
    r0 = r_c if is_rigid else ro_race - rr - (n_centrifugal / K) ** 0.9
    omega_cage = sign * op.omega_c
    for i, b in enumerate(sc.rollers):
        a = sc.pocket_body_angle[i]
        b.position = (r0 * math.cos(a), r0 * math.sin(a))
        b.velocity = (-omega_cage * r0 * math.sin(a), omega_cage * r0 * math.cos(a))

    ring_mass, ring_how = inner_ring_model(p)
    prm = fk.RacewayParams(
        roller_radius=float(rr), roller_mass=float(geo.roller_mass), roller_inertia=float(geo.roller_inertia),
        outer_race_radius=float(ro_race), inner_race_radius=float(ri_race),
        outer_race_geom_radius=float(geo.outer_race_radius), inner_race_geom_radius=float(geo.inner_race_radius),
        palmgren_stiffness=float(K_race), damping_time=0.0 if is_rigid else CONTACT_DAMPING_S,
        damping_fade=DAMPING_FADE_M,
        traction_mu_max=float(p.contact.traction_mu_max),
        traction_slip_ref=float(p.contact.traction_slip_ref), min_entrainment=MIN_ENTRAINMENT_M_S,
        drag_coefficient=float(p.contact.drag_coefficient), drag_direction_eps=DRAG_DIRECTION_EPS_M_S,
        omega_ring=float(sign * op.omega_i), radial_load=float(op.radial_load), gravity=float(op.gravity),
        inner_ring=not reduced_eq, traction=not reduced_eq, spin_free=not reduced_eq,
        newton_max_step=NEWTON_MAX_STEP_M, ring_mass=float(ring_mass), rigid=is_rigid, rigid_radius=float(r_c))
    cfg = rk.RecorderConfig(sign=float(sign), roller_count=int(n), warmup_rotations=float(warm), rotations=nrot,
                            theta_bins=THETA_BINS, impact_speed_threshold=IMPACT_SPEED_THRESHOLD_M_S,
                            pocket_centre_radius=float(geo.pitch_radius),
                            psi_lo=float(p.multibody.pocket_face_extent[0]),
                            psi_hi=float(p.multibody.pocket_face_extent[1]))
    acc = rk.accumulators(nrot, n, THETA_BINS, IMPACT_CAPACITY)
    # pocket angles from the load-zone centre at t = 0, in [0, 2 pi)
    theta0 = np.mod(-2.0 * math.pi * np.arange(n) / n, 2.0 * math.pi)
    # start at the continuous quasi-static displacement (close to equilibrium: small start transient)
    _, delta_qs = laws.quasi_static_load_zone(op.radial_load, n, geo.roller_length, pd) if not reduced_eq else (0, 0)
    # (the same start for rigid raceways: the continuous distribution's displacement is that of two
    # contacts in series already)
    ids = sc.body_ids
    order = np.argsort(ids)

    # reduced-equivalent: held rollers sit at the front of their pockets on the outer race
    phi = p.reduced.load_zone_half_angle if reduced_eq else 0.0
    if reduced_eq or is_rigid:  # held rollers (reduced-equivalent), rollers on the race (rigid): states set too
        set_fields = lp.BODY_SET_ALL
        set_arr = np.zeros(nb * 7)
    else:
        set_fields = lp.BODY_SET_FORCE
        set_arr = np.zeros(nb * 3)
    ORBIT_KEEP = 4096
    wk = lp.StepWork(
        ring_c=np.array([0.0, -max(0.5 * pd, delta_qs)]), ring_c_prev=np.zeros(2), ring_v=np.zeros(2),
        hold=np.zeros(n, dtype=np.bool_),
        # full scene: the kernel writes the (fx, fy, torque) rows straight into the set buffer
        out_f=np.zeros(nb * 3) if (reduced_eq or is_rigid) else set_arr, set_arr=set_arr,
        diag=np.zeros(n, dtype=fk.DIAG), smp=np.zeros(2048, dtype=lp.SAMPLE),
        orbit=np.full((ORBIT_KEEP, 3), np.nan), land_out=np.zeros(4), land_win=np.zeros((nrot, 3)),
        n_out=np.full(n, n_centrifugal),  # rigid: the first step's outer-race loads, before a joint has acted
        n_held=np.zeros(n),
        e_set=np.full(n, float(e)), e_want=np.full(n, float(e)), touched=np.zeros(n, dtype=np.bool_),
        n_extra=np.zeros(n),
        arc_ends=sc.face_segments[:, :2, :].copy() if sc.arc_shapes is not None else np.zeros((n, 2, 4)),
        arc_todo=np.zeros((n, 2), dtype=np.bool_))
    # room for every roller against every face segment of every pocket: pymunk never grows the arrays
    arb_cap = max(4096, 2 * max(n_seg, 1) * n * n + 64)
    masks = face_geometry(sc, rr, lp.MASK_MARGIN_M)
    arc = arc_faces(sc, rr, sign) if sc.arc_shapes is not None else lp.ARC_FACES_OFF
    io, loop_why = chipmunk.open_step_loop(space, nb, set_fields, set_arr, arb_cap, step_loop, sc.joints,
                                           [next(iter(b.shapes)) for b in sc.rollers], [*sc.rollers, sc.cage], masks,
                                           sc.arc_shapes)

    total_rot = warm + nrot
    travel_end = 2.0 * math.pi * total_rot
    omega_nom = op.omega_c
    steps_est = int(math.ceil(travel_end / omega_nom / h + t_start / h_start))
    def sample_every(step):  # steps between samples (and health checks) at numerics.output_rate
        return max(1, int(round(1.0 / (p.numerics.output_rate * step))))

    out_every = sample_every(h)
    series = None
    if sink is not None:
        series = [
            (sink.timeseries("cage_angular_speed", (), "rad/s", "cage angular speed in the direction of rotation"),
             ("cage_speed",)),
            (sink.timeseries("cage_slip", (), "1", "1 - cage speed / epicyclic speed (Eq. 11)"), ("cage_slip",)),
            (sink.timeseries("cage_centre", (2,), "m", "cage centre (x, y); y up, radial load along -y"),
             ("cage_x", "cage_y")),
        ]
        if not reduced_eq:
            series.append((sink.timeseries("inner_ring_centre", (2,), "m", "quasi-static inner-ring centre (x, y)"),
                           ("ring_x", "ring_y")))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total_rot, unit="rot", desc="cage rotations", file=sys.stderr)
    bar_done = 0
    io.read_states()
    # the rollers hold the cage only while its centre stays within the radial reach of the face arcs
    face_reach = face_radial_reach(p)
    # a land-guided cage is held by its land (the full scene's free cage only)
    land = land_params(p, active=scene_kind == "full" and geo.cage_guidance != "rollers")
    orbit_limit = face_reach
    if land.active:  # the inner land moves with the inner ring, at most P_d/2 plus its raceway approach
        orbit_limit = land.half_clearance * (1.0 + LAND_ORBIT_MARGIN) + (
            0.5 * pd + raceway_approach_limit(p) if land.inner else 0.0)
    lim = lp.LoopLimits(
        travel_end=travel_end, travel_record=2.0 * math.pi * warm,
        penetration=penetration_limit * s,  # (the stability scan passes 0.5 to look for blow-up alone)
        omega=3.0 * op.omega_i + 10.0, omega_nominal=float(omega_nom), orbit=float(orbit_limit),
        raceway_approach=raceway_approach_limit(p), out_every=out_every,
        max_steps=int(3 * steps_est + 1000))
    inp = lp.StepInputs(
        h=float(h), prm=prm, cfg=cfg, lim=lim,
        hold_rule=lp.HoldRule(active=reduced_eq, phi=float(phi),
                              radius=r_c if is_rigid else rp - (n_centrifugal / K) ** 0.9,
                              front_offset=0.5 * s, omega_cage=float(omega_cage)),
        land=land,
        pocket_a=np.ascontiguousarray(sc.pocket_body_angle, dtype=np.float64), theta0=theta0,
        ids_sorted=ids[order].astype(np.uint64), ids_index=order.astype(np.int64),
        onset_restitution=is_rigid, restitution=float(e), arc=arc)
    inp_main = inp
    if t_start > 0.0:  # the start phase: its own step (and samples at the same rate)
        inp = inp._replace(h=float(h_start), lim=lim._replace(
            t_phase_end=float(t_start), out_every=sample_every(h_start)))
    ls = np.zeros(1, dtype=lp.LOOP_STATE)
    st = ls[0]
    t_loop0 = time.perf_counter()
    while True:
        code = io.advance(inp, wk, acc, ls)
        k = int(st["n_samples"])
        if series is not None and k:
            smp = wk.smp[:k]
            for ts, cols in series:
                ts.append(smp["step"].copy(), smp["t"].copy(),
                          smp[cols[0]].copy() if len(cols) == 1 else np.stack([smp[c] for c in cols], axis=1))
        st["n_samples"] = 0
        t = float(st["t"])
        step = int(st["step"])
        state = io.states[int(st["cur"])]
        if bar is not None:
            done = min(total_rot, int(sign * state[n, 2] / (2.0 * math.pi)))
            if done > bar_done:
                bar.update(done - bar_done)
                bar_done = done
        if code == lp.CODE_BLOCK_FULL:
            continue
        if code == lp.CODE_PHASE_END:
            # the overlap is checked every out_every steps: the phase's last ones are checked here
            if acc.glob[0]["maxpen_all"] <= lim.penetration:
                inp = inp_main
                continue
            code = lp.CODE_PENETRATION  # stopped with the start phase's step
        if code == lp.CODE_DONE:
            break
        if bar is not None:
            bar.close()
        if code == lp.CODE_NONFINITE:
            raise SimulationUnstable(f"non-finite state at t = {t:.6g} s (step {step}); "
                                     f"try a smaller numerics.dt_s than {h:.3g} s")
        if code == lp.CODE_PENETRATION:
            g = acc.glob[0]
            raise PenetrationExceeded(g["maxpen_all"], lim.penetration, inp.h, g["maxpen_time"],
                                          g["maxpen_approach"], dt_how)
        if code == lp.CODE_BLOWUP:
            raise SimulationUnstable(
                f"raceway approach {max(wk.diag['delta_out'].max(), wk.diag['delta_in'].max() if is_rigid else 0.0):.3g} m (limit {lim.raceway_approach:.3g} m, 3x the "
                f"Palmgren approach under the whole operating.radial_load_N) or cage speed {state[n, 5]:.3g} rad/s "
                f"(limit {lim.omega:.3g}) out of bounds at t = {t:.6g} s (energy blow-up); try a smaller "
                f"numerics.dt_s than {h:.3g} s")
        if code == lp.CODE_STALLED:
            raise SimulationUnstable(
                f"cage did not complete {total_rot} rotations in {step} steps "
                f"(cage speed {state[n, 5]:.3g} rad/s): the cage stalled")
        if code == lp.CODE_CAGE_LOST and land.active:
            raise SimulationUnstable(
                f"the cage centre moved {math.hypot(state[n, 0], state[n, 1]) * 1e3:.4g} mm off the bearing axis at "
                f"t = {t:.6g} s, more than {LAND_ORBIT_MARGIN:.0%} of half the land clearance "
                f"(bearing.cage_land_clearance_mm) beyond its {geo.cage_guidance.replace('_', ' ')}: the land "
                f"contact did not hold it; try a smaller numerics.dt_s than {h:.3g} s")
        if code == lp.CODE_CAGE_LOST:
            raise SimulationUnstable(
                f"the cage centre moved {math.hypot(state[n, 0], state[n, 1]) * 1e3:.4g} mm off the bearing axis at "
                f"t = {t:.6g} s, beyond the radial reach of its pocket faces ({face_reach * 1e3:.4g} mm): the rollers no "
                f"longer hold it; widen the faces (multibody.pocket_face_half_angle_deg, at most what the cage wall "
                f"allows) or guide the cage on a ring land (bearing.cage_guidance)")
        raise RuntimeError(f"multibody step loop: pymunk grew a batch buffer at step {step} (code {code})")
    if bar is not None:
        bar.update(total_rot - bar_done)
        bar.close()
    loop_s = time.perf_counter() - t_loop0
    n_imp = int(st["n_imp"])
    # impacts in one step come in pymunk's arbiter order, which follows shape addresses: sort them by
    # (time, pocket, face) so that the table is the same in every run (front before rear, as before the
    # face codes of the two models were made the same)
    imp = acc.impacts[:n_imp]
    imp = imp[np.lexsort((imp["face"] != rk.FACE_FRONT, imp["pocket"], imp["time"]))]
    wall = time.perf_counter() - t_wall0
    prev = io.states[int(st["cur"])]
    rec_started = st["recording"] == 1
    t_rec = t - st["t_rec0"] if rec_started else 0.0
    ring_n = st["ring_n"]
    n_orbit = int(st["n_orbit"])
    pymunk_s = st["pymunk_ns"] * 1e-9 if io.timed else float("nan")
    return dict(
        parameters=p, scene=scene_kind, inner_ring=ring_how, dt=h, dt_choice=dt_how, dt_explicit_limit=dt_lim, steps=step,
        t_start=t_start, dt_start=h_start if t_start > 0.0 else h,  # rigid: the start phase (0: none)
        wall_s=wall, loop_s=loop_s, pymunk_step_s=pymunk_s, step_loop=io.name, step_loop_reason=loop_why, t_end=t,
        t_record=t_rec, win=acc.win, first_imp=acc.first_imp, f_bin=acc.f_bin, t_bin=acc.t_bin, q_bin=acc.q_bin,
        tq_bin=acc.tq_bin, glob=acc.glob.copy()[0], impacts=imp, prof=acc.prof,
        impacts_dropped=n_imp >= IMPACT_CAPACITY, cage_w_start=st["cage_w_start"] if rec_started else None,
        cage_w_end=prev[n, 5],
        cage_inertia=geo.cage_inertia, newton_failures=int(st["newton_failures"]), orbit_max=st["orbit_max"],
        phi=phi,
        final_state=prev.copy(), orbit=np.roll(wk.orbit, -(n_orbit % ORBIT_KEEP), axis=0),
        ring_centre_mean=(np.array([st["ring_sum_x"], st["ring_sum_y"]]) / ring_n if ring_n and not reduced_eq
                          else np.full(2, np.nan)),
        radial_clearance=geo.radial_clearance, raceway_contact=p.multibody.raceway_contact,
        lift_max=float(st["lift_max"]) if is_rigid else None,
        beyond_max=float(st["beyond_max"]) if is_rigid else None, beyond_vr=float(st["beyond_vr"]) if is_rigid else None,
        beyond_before=float(st["beyond_before"]) if is_rigid else None,
        rigid_radius=float(r_c),
        land=(dict(win=wk.land_win.copy(), tau=float(st["land_tau"]), overlap_max=float(st["land_overlap_max"]),
                   stiffness=land.stiffness, half_clearance=land.half_clearance) if land.active else None),
    )
