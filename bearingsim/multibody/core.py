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
from typing import NamedTuple

import numpy as np

from bearingsim import laws
from bearingsim.errors import SimulationUnstable, UserError
from bearingsim.multibody import forces as fk
from bearingsim.multibody import chipmunk
from bearingsim.multibody import loop as lp
from bearingsim.multibody import recorder as rk
from bearingsim.multibody.scene import build_scene
from bearingsim.parameters import inner_ring_mode
from bearingsim.parameters import paper_assumptions  # noqa: F401 - re-exported: the scene of the paper's assumptions
from bearingsim.wording import given_step, rounded3

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
# kinematic_cage scene (cross-check rung 3): the automatic step divided by this. A cage turned at a prescribed
# speed holds every roller at that speed through the load zone against the traction, whose velocity stiffness
# C (relaxation m / C ~ 50 us) the implicit update and pymunk's contact share at first order in h C / m: I_dec
# converges at first order there (+3.6 %, +1.9 % per halving from 4 us at 3000 rpm, 2 + 2 rotations; +0.14 %
# with slip_ref 10 x larger), where the free cage's is not resolved. Divided by 8, a halving
# changes it by less than 1 % at 1000, 3000 and 6000 rpm, the step error the full scene's step is shown to
# keep (docs/multibody.md, *Its time step*; docs/crosscheck.md)
KINEMATIC_DT_DIVISOR = 8

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
# A given step (numerics.dt_s) needing more steps per cage rotation than this is refused before the run:
# the automatic step takes ~6e3 per rotation at 6000 rpm and ~7e4 at 500 rpm, a step costs ~14 us on
# one core (the main job: 237 011 steps in 3.3 s), so 1e7 is ~2 min a rotation, a convergence study's
# finest step with room to spare, where a mistyped exponent (1e-9 for 1e-6 s) would run for hours.
MAX_STEPS_PER_ROTATION = 10_000_000
# Steps in which the quasi-static inner ring's force balance (forces.solve_ring_centre) did not converge: a
# few isolated steps are harmless (the next step starts again from the last iterate) and are noted
# (bearingsim.plausibility); in more than 1 % of the steps the ring equilibrium the model assumes is
# not met and the run is refused, as soon as the failures exceed 1 % of the most steps it may take
# (LoopLimits.max_steps), which no later step can bring back under.
MAX_NEWTON_FAILURE_FRACTION = 0.01
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
    """(mass [kg], description) of the inner ring: mass 0 is quasi-static (massless), as
    :func:`bearingsim.parameters.inner_ring_mode` decides. The dynamic ring's mass is
    ``multibody.inner_ring_mass_kg``; "auto" takes the radial load as the weight of the rotor the
    bearing carries (the paper's rig), ``M = W / g_n``.
    """
    mode, why = inner_ring_mode(p)
    if mode == "none":
        return 0.0, "none (reduced-equivalent scene)"
    if mode == "quasi_static":
        advice = one_roller_ring_advice(p)
        if advice is not None:
            raise UserError(f'multibody.inner_ring = "quasi_static": {advice}')
        return 0.0, "quasi-static (massless)" + (f"; {why}" if why else "")
    mb = p.multibody
    load = p.operating.radial_load
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


def traction_relaxation_time(p) -> float:
    """The relaxation time [s] of a roller that a pocket face holds against the raceway traction:
    ``tau = m / (2 C) = m slip_ref u / (2 mu_max Q)``, with ``C = mu_max Q / (slip_ref u)`` the traction's slope at
    zero slip on each raceway (both at :func:`max_roller_load` ``Q``, ``u`` :func:`rolling_speed`). The force
    kernel takes the traction implicitly and pymunk's contact solve follows it in the same step, so for a roller
    held at a face moving at constant speed the face's force comes out ``1 / (1 + h / tau)`` of the exact one at
    the discrete steady state (equal slopes: the translation and the spin do not couple in the implicit solve, so
    the roller's inertia about its axis drops out; with one raceway contact alone the force is exact). The cage
    re-balances, so a run's I_dec moves much less than that (docs/multibody.md, *Its time step*)."""
    mu = p.contact.traction_mu_max
    return (math.inf if mu <= 0.0 else
            p.bearing.roller_mass * p.contact.traction_slip_ref * rolling_speed(p) / (2.0 * mu * max_roller_load(p)))


def rolling_speed(p) -> float:
    """The rollers' rolling (entrainment) speed in pure rolling, ``omega_c r_o`` [m/s], at least
    :data:`MIN_ENTRAINMENT_M_S` (the traction's floor)."""
    return max(abs(p.operating.omega_c) * p.bearing.outer_race_radius, MIN_ENTRAINMENT_M_S)


RACEWAY_APPROACH_FACTOR = 3.0  # blow-up: approach > 3x that of one roller carrying the whole load alone


def raceway_approach_limit(p) -> float:
    """Largest outer-raceway approach [m] a sound run reaches, with margin: ``RACEWAY_APPROACH_FACTOR``
    times the Palmgren approach of one roller carrying the whole radial load and its centrifugal load
    alone (no roller ever carries more), and never below ``loop.DELTA_LIMIT_M`` (50 um). Beyond it the
    run has blown up. (A fixed 50 um refused a legitimate 100 kN load: the most loaded roller's
    approach is ~50 um per race there.)"""
    g, op = p.bearing, p.operating
    q = op.radial_load + g.roller_mass * g.pitch_radius * op.omega_c**2
    return max(lp.DELTA_LIMIT_M, RACEWAY_APPROACH_FACTOR * laws.palmgren_approach(q, g.roller_length))


def stability_limit(p) -> float:
    """Explicit stability limit 2/omega_n [s] of a roller between two linearised Palmgren contacts."""
    g = p.bearing
    q = max_roller_load(p)
    delta = laws.palmgren_approach(q, g.roller_length)
    k_lin = 10.0 / 9.0 * q / delta
    omega_n = math.sqrt(2.0 * k_lin / g.roller_mass)
    return 2.0 / omega_n


def worn_play(p) -> tuple[float, int | None]:
    """(the play [m] a roller crosses in its pocket, the pocket whose play it is (None: unworn)).

    Unworn: the pocket clearance s (``bearing.pocket_clearance_mm``), exactly. With worn faces
    (``[wear] worn_depth_*``): s plus the largest, over pockets and directions psi of the extent, of the
    front and the rear face's worn depth **as the contact meets the face** in the same direction psi (the
    worn boundary's polar radius less R, :func:`worn_radius`, at the bin centres and the two edges): a
    groove narrower than the roller and a deep end bin are bridged by the lines beside them, so the
    roller never crosses their depth (docs/wear.md, *Worn faces*). A roller crossing its pocket at a radial
    offset meets both faces at about the same psi. A flat face moves out by its mean worn depth (a
    uniform shift): its pocket's play is s plus its front and rear means."""
    s = p.bearing.pocket_clearance
    worn = worn_array(p)
    if worn is None:
        return s, None
    rr = p.bearing.roller_radius
    R = rr + 0.5 * s
    knots, h = worn_lines(p.multibody.pocket_face_extent, R, worn)
    r = worn_radius(knots, h, knots)  # (n, 2, K): the knots are the bin centres and the edges
    extra = (r[:, 0] - R + r[:, 1] - R).max(axis=1)
    for i in p.multibody.flat_pockets:
        extra[i] = float(np.mean(worn[i, 0])) + float(np.mean(worn[i, 1]))
    i = int(np.argmax(extra))
    return s + max(float(extra[i]), 0.0), i


def impact_dt(p, play=None) -> float:
    """Impact resolution [s]: a rear impact may overlap the face by at most 0.5 % of s in one step.

    Approach speed estimate: free flight across the play under the no-load-zone deceleration
    (F_o at the centrifugal load, plus g), ``v = sqrt(2 a L)``, as in the reduced model; L the play a
    roller crosses (:func:`worn_play`: s, or with worn faces s plus the deepest front and rear worn depth
    a roller meets in its pocket; ``play``: its result when the caller has it). The bound stays 0.5 % of s:
    the overlap limit is a fraction of s."""
    g = p.bearing
    op = p.operating
    n_c = g.roller_mass * g.pitch_radius * op.omega_c**2
    f_o = laws.oil_film_drag(p.contact.drag_coefficient, n_c, op.rolling_velocity)
    a = float(f_o) / g.roller_mass + op.gravity + 1e-3
    v = math.sqrt(2.0 * a * (play or worn_play(p))[0])
    return IMPACT_OVERLAP_FRACTION * g.pocket_clearance / v


def _play_text(p, play) -> str:
    """How :func:`worn_play` chose the play (``play``: its result), for ``dt_choice`` ("" unworn)."""
    play, i = play
    if i is None:
        return ""
    s = p.bearing.pocket_clearance
    return (f"; v_impact across the worn play {play * 1e3:.4g} mm = s + {(play - s) * 1e6:.4g} um (pocket {i}'s "
            f"deepest front + rear worn depth in one direction, as the contact meets the faces)")


def land_stability_limit(p) -> float:
    """Explicit stability limit 2/omega_n [s] of the cage on its land's penalty contact (inf: roller-guided)."""
    land = land_params(p, active=p.multibody.scene == "full" and p.bearing.cage_guidance != "rollers")
    return 2.0 * math.sqrt(p.bearing.cage_mass / land.stiffness) if land.active else math.inf


def choose_dt(p, dt=None, play=None):
    """(dt [s], how it was chosen, explicit limit [s]). Raises UserError for a dt far above stable.
    ``play``: :func:`worn_play` of ``p`` when the caller has it (else computed where needed)."""
    if rigid(p):
        return _choose_dt_rigid(p, dt, play)
    lim = stability_limit(p)
    largest = DT_MAX_FACTOR * lim
    if dt is None and p.numerics.dt is not None:
        dt = p.numerics.dt
        how = "numerics.dt_s"
    elif dt is not None:
        how = "simulate(dt=...)"
    else:
        dt, how = _automatic_dt(p, lim, play)
    check_step_count(p, dt, how)
    if dt > largest:
        raise UserError(_far_above(dt, f"this bearing (Hertz limit 2/omega_n = {lim:.3g} s)", largest,
                                   _automatic_dt(p, lim, play)[0]))
    return float(dt), how, lim


def _far_above(dt: float, what: str, largest: float, auto: float) -> str:
    """The refusal of a given step ``dt`` [s] above ``largest`` [s] (:data:`DT_MAX_FACTOR` times the explicit
    limit of ``what``), said as the key's ("run(): dt: ..." of the API's dt): steps up to ``largest`` are taken,
    but between the automatic step ``auto`` and it a run may still blow up."""
    return (f"numerics.dt_s: {dt:.3g} s is far above the stable time step of {what}: steps up to {largest:.3g} s "
            f"are accepted, but only the automatic {auto:.3g} s is shown stable (leave the step to the automatic "
            f"choice)")


def automatic_step(p, play=None) -> float:
    """The step [s] :func:`choose_dt` chooses for ``p`` when no step is given (``numerics.dt_s`` set aside).
    ``play``: :func:`worn_play` of ``p`` when the caller has it."""
    if rigid(p):
        return _automatic_dt_rigid(p, land_stability_limit(p), play)[0]
    return _automatic_dt(p, stability_limit(p), play)[0]


def unstable_advice(p, h: float, how: str) -> str | None:
    """What to change after a run at a given step ``h`` [s] (chosen ``how``, its ``dt_choice``) went unstable,
    when ``h`` is longer than the automatic step: that step (a bound from the stopped state's speeds would be one
    of a state that has already diverged). None for the automatic step or a given one not longer than it."""
    if how.startswith("auto"):
        return None
    auto = automatic_step(p)
    return given_step(h, auto, how.startswith("simulate(dt=")) if h > auto else None


def _automatic_dt(p, lim: float, play=None) -> tuple[float, str]:
    """The automatic step of Hertz raceways and how it was chosen: the smallest of a fraction of the stiffest
    contact's 2/omega_n (``lim``), the impact resolution and a cap; an eighth of it in the kinematic cage."""
    play = play or worn_play(p)
    dti = impact_dt(p, play)
    dt = min(DT_FRACTION * lim, dti, DT_CAP_S)
    how = (f"auto: min of {DT_FRACTION} x 2/omega_n of the stiffest raceway contact "
           f"(Palmgren, Q_max ≈ {max_roller_load(p):.0f} N, Stribeck's estimate 5W/Z + m omega_c^2 r_p, not the "
           f"run's roller loads; 2/omega_n = {lim:.3e} s), "
           f"impact resolution {IMPACT_OVERLAP_FRACTION} s / v_impact = {dti:.3e} s, and {DT_CAP_S:.0e} s"
           + _play_text(p, play))
    if p.multibody.scene == "kinematic_cage":
        dt /= KINEMATIC_DT_DIVISOR
        how += (f"; divided by {KINEMATIC_DT_DIVISOR} for the kinematic cage (its rollers pushed through the "
                f"load zone: I_dec converges at first order in the step)")
    return dt, how


def _choose_dt_rigid(p, dt, play=None):
    """Rigid raceways: no raceway spring; the step resolves the roller-cage impacts (and the land's
    penalty contact of a land-guided cage). Returns (dt, how, explicit limit [s] (the land's or inf))."""
    lim = land_stability_limit(p)
    largest = DT_MAX_FACTOR * lim
    if dt is None and p.numerics.dt is not None:
        dt, how = p.numerics.dt, "numerics.dt_s"
    elif dt is not None:
        how = "simulate(dt=...)"
    else:
        dt, how = _automatic_dt_rigid(p, lim, play)
    check_step_count(p, dt, how)
    if dt > largest:
        raise UserError(_far_above(dt, f"the cage on its land (2/omega_n = {lim:.3g} s)", largest,
                                   _automatic_dt_rigid(p, lim, play)[0]))
    return float(dt), how, lim


def _automatic_dt_rigid(p, lim: float, play=None) -> tuple[float, str]:
    """The automatic step of rigid raceways and how it was chosen: the smallest of the impact resolution, a
    fraction of the land's 2/omega_n (``lim``, inf for a roller-guided cage) and a cap."""
    s = p.bearing.pocket_clearance
    play = play or worn_play(p)
    dti = RIGID_IMPACT_OVERLAP_FRACTION / IMPACT_OVERLAP_FRACTION * impact_dt(p, play)
    dt = min(dti, DT_FRACTION * lim, RIGID_DT_CAP_S)
    how = (f"auto (rigid raceways): min of impact resolution {RIGID_IMPACT_OVERLAP_FRACTION:g} s / v_impact = "
           f"{dti:.3e} s (s = {s * 1e3:.3g} mm)"
           + (f", {DT_FRACTION} x 2/omega_n of the cage on its land = {DT_FRACTION * lim:.3e} s"
              if math.isfinite(lim) else "")
           + f" and {RIGID_DT_CAP_S:.0e} s" + _play_text(p, play))
    return dt, how


def check_step_count(p, dt: float, how: str) -> None:
    """Refuse a step that needs more than :data:`MAX_STEPS_PER_ROTATION` steps per nominal cage rotation (one
    line): a given one (``how`` not automatic) naming its key, the steps and the run time they stand for; the
    automatic one (a crawl: it is set by the stiffest contact and the impacts, about 4 us on the reference bearing
    at any speed) naming ``operating.inner_ring_speed_rpm``, the steps of the run's ``numerics.rotations`` and the
    least speed at which the automatic step is accepted."""
    per_rotation = 2.0 * math.pi / abs(p.operating.omega_c) / dt
    if per_rotation <= MAX_STEPS_PER_ROTATION:
        return
    if how.startswith("auto"):
        op, nu = p.operating, p.numerics
        total = nu.rotations + nu.warmup_rotations
        raise UserError(
            f"operating.inner_ring_speed_rpm: at {op.inner_ring_speed_rpm:g} rpm a cage rotation takes "
            f"{2.0 * math.pi / abs(op.omega_c):.3g} s, {per_rotation:.3g} steps of the automatic {dt:.3g} s (set by "
            f"the stiffest contact and the impacts, not by the speed), more than {MAX_STEPS_PER_ROTATION:.0e} (about "
            f"2 min each on one core): the {total} rotations (numerics.rotations + numerics.warmup_rotations) would "
            f"take {total * per_rotation:.3g} steps; run at {least_automatic_speed(p):.3g} rpm or more")
    # said as the key's refusal ("run(): dt: ..." of the API's dt)
    raise UserError(
        f"numerics.dt_s: {dt:.3g} s needs {per_rotation:.3g} steps per cage rotation, more than "
        f"{MAX_STEPS_PER_ROTATION:.0e} (about 2 min each on one core): use at least "
        f"{rounded3(2.0 * math.pi / abs(p.operating.omega_c) / MAX_STEPS_PER_ROTATION, up=True):.3g} s (or leave the step "
        f"to the automatic choice)")


def least_automatic_speed(p) -> float:
    """The least inner-ring speed [rpm], 3 digits rounded up, at which the automatic step of ``p`` needs at most
    :data:`MAX_STEPS_PER_ROTATION` steps per cage rotation (the step shortens slowly with the speed: the speed
    is scaled by the steps' excess until it is within)."""
    rpm = p.operating.inner_ring_speed_rpm
    for _ in range(50):
        q = p.at_speed(rpm)
        per_rotation = 2.0 * math.pi / abs(q.operating.omega_c) / automatic_step(q)
        if per_rotation <= MAX_STEPS_PER_ROTATION:
            return rpm
        rpm = rounded3(rpm * max(per_rotation / MAX_STEPS_PER_ROTATION, 1.001), up=True)
    return rpm


def rigid_start(p, dt, play=None):
    """Rigid raceways with the automatic step: the start phase, (its duration [s], its step [s]).

    The cage starts centred and settles onto its rollers (or its land) under gravity: a fall across
    the play L (the pocket clearance s, or with worn faces :func:`worn_play`), ``v_fall = sqrt(2 g L)``,
    bouncing with the roller-cage restitution e for ``t_fall (1 + e) / (1 - e)`` (a bouncing ball; 58 ms
    on the reference bearing), at most one cage rotation. Those first contacts come faster than the
    steady impacts the automatic step is set for (measured on the reference bearing with the start phase
    off: 0.11 m/s at 500 rpm and 0.10 m/s at 3000 rpm within the first 10 ms, against the automatic
    step's estimates of 0.07 and 0.09 m/s), and at the 1 % bound they would restart the whole run with a
    shorter step. The start phase runs at the step that keeps ``v_fall`` within 0.5 % of s (the Hertz
    scene's margin), if that is shorter.
    Returns (0, dt) when there is no fall (no gravity). ``play``: :func:`worn_play` of ``p`` if the caller has it."""
    g, op = p.bearing, p.operating
    s = g.pocket_clearance
    e = p.contact.restitution
    if op.gravity <= 0.0:
        return 0.0, dt
    play = (play or worn_play(p))[0]
    t_fall = math.sqrt(2.0 * play / op.gravity)
    t_settle = t_fall * (1.0 + e) / (1.0 - e) if e < 1.0 else math.inf
    t_start = min(t_settle, 2.0 * math.pi / op.omega_c)
    dt_start = RIGID_START_OVERLAP_FRACTION * s / math.sqrt(2.0 * op.gravity * play)
    return t_start, min(dt, dt_start)


#: the scenario keys :func:`check_rigid` reads besides ``multibody.raceway_contact`` (the speed, gravity and
#: the roller-centre radius r_c and cage speed they give; the roller mass cancels in the ratio)
RIGID_CHECK_KEYS = ("operating.inner_ring_speed_rpm", "operating.gravity", "bearing.pitch_diameter_mm",
                    "bearing.roller_diameter_mm", "bearing.radial_clearance_mm")


def check_rigid(p):
    """Refuse (UserError) what the rigid raceways cannot represent: rollers that would leave the outer race.
    The refusal is marked with the keys it reads (``involves``: :data:`RIGID_CHECK_KEYS`), so that a refusal
    of a scenario names the overrides that gave them."""
    g, op = p.bearing, p.operating
    fc = g.roller_mass * rigid_radius(p) * op.omega_c**2
    w = g.roller_mass * op.gravity
    if fc < RIGID_MIN_CENTRIFUGAL_RATIO * w:
        exc = UserError(
            f"multibody.raceway_contact = 'rigid': at {op.inner_ring_speed_rpm:g} rpm a roller's centrifugal load "
            f"({fc:.3g} N) is less than {RIGID_MIN_CENTRIFUGAL_RATIO:g} x its weight ({w:.3g} N), so the rollers at "
            f"the top leave the outer race, which rigid raceways do not model; use raceway_contact = 'hertz' "
            f"below {rigid_speed_floor(p):.0f} rpm")
        exc.involves = RIGID_CHECK_KEYS
        raise exc


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


def arc_faces(sc, rr, sign, worn=None) -> "lp.ArcFaces":
    """:class:`bearingsim.multibody.loop.ArcFaces` of a scene with exact arc faces (roller radius ``rr`` [m],
    ``sign`` of the rotation); ``worn``: :func:`worn_array` (None: unworn faces)."""
    a = np.asarray(sc.pocket_body_angle, dtype=np.float64)
    sign = 1.0 if sign > 0 else -1.0
    e_r = np.stack([np.cos(a), np.sin(a)], axis=1)
    e_t = sign * np.stack([-np.sin(a), np.cos(a)], axis=1)
    play = sc.pocket_radius - rr
    near = ARC_NEAR_FRACTION * play
    from bearingsim.multibody.scene import TANGENT_HALF_LENGTH

    af = lp.ArcFaces(True, np.array([pair[0] is not None for pair in sc.arc_shapes], dtype=np.bool_),
                     np.ascontiguousarray(sc.pocket_centres, dtype=np.float64), np.ascontiguousarray(e_t),
                     np.ascontiguousarray(e_r), float(sc.pocket_radius), float(sc.extent[0]), float(sc.extent[1]),
                     float(TANGENT_HALF_LENGTH * sc.pocket_radius), float(near * near))
    if worn is None:
        return af
    lo, hi = sc.extent
    knots, h = worn_lines(sc.extent, sc.pocket_radius, worn)
    return af._replace(worn_on=True, knot_psi=knots, knot_cos=np.cos(knots), knot_sin=np.sin(knots),
                       knot_h=np.ascontiguousarray(h, dtype=np.float64), edge=worn_edges(knots, h, lo, hi))


def worn_lines(extent, pocket_radius, worn):
    """(knots (bins + 2,) [rad], h (n, 2, bins + 2) [m]) of worn arc faces: the lines ``p . u(psi) <= h(psi)``
    bounding each pocket's (front, rear) face, ``h = R + w`` at the bin centres of psi, constant in the half
    bins at the extent's ends (``worn``: :func:`worn_array`)."""
    lo, hi = extent
    bins = worn.shape[2]
    knots = np.concatenate([[lo], lo + (hi - lo) * (np.arange(bins) + 0.5) / bins, [hi]])
    h = pocket_radius + np.concatenate([worn[:, :, :1], worn, worn[:, :, -1:]], axis=2)
    return knots, h


def worn_radius(knots, h, e) -> np.ndarray:
    """Polar radius [m] of each worn face's boundary from its pocket centre in the directions ``e`` (E,)
    [rad] within the extent: shape ``h.shape[:-1] + (E,)``.

    ``knots`` (K,) [rad] and ``h`` (..., K) [m]: the face's lines ``p . u(psi) <= h(psi)``, ``h`` linear
    between the knots (:func:`worn_lines`). Along the ray at angle ``e`` the nearest line is at
    ``r(e) = min over psi of h(psi) / cos(e - psi)``; on a knot interval the derivative's numerator
    ``a cos(e - psi) - h(psi) sin(e - psi)`` (``a`` the slope of ``h``) grows with psi (its derivative is
    ``h cos(e - psi) > 0``), so the least value is at a knot or at that numerator's single zero, found by
    bisection. Unworn (``h = R``) it is ``R``."""
    h = np.asarray(h, dtype=np.float64)
    e = np.asarray(e, dtype=np.float64)
    p0, p1 = knots[:-1], knots[1:]
    h0 = h[..., None, :-1]  # (..., 1, K - 1): one row per direction
    slope = (h[..., None, 1:] - h0) / (p1 - p0)
    ee = e[:, None]

    def ratio(psi, hv, ang):
        c = np.cos(ang - psi)
        return np.where(c > 0.0, hv / np.where(c > 0.0, c, 1.0), np.inf)

    def numer(psi, sl, hl, pl, ang):
        return sl * np.cos(ang - psi) - (hl + sl * (psi - pl)) * np.sin(ang - psi)

    shape = np.broadcast_shapes(h0.shape, ee.shape)
    best = ratio(knots, h[..., None, :], ee).min(axis=-1)
    sl, hl = np.broadcast_to(slope, shape), np.broadcast_to(h0, shape)
    pl, pr, ang = np.broadcast_to(p0, shape), np.broadcast_to(p1, shape), np.broadcast_to(ee, shape)
    root = ((numer(pl, sl, hl, pl, ang) < 0.0) & (numer(pr, sl, hl, pl, ang) > 0.0)
            & (np.cos(ang - pl) > 0.0) & (np.cos(ang - pr) > 0.0))
    # bisection on the intervals with a zero only
    sl, hl, p_, ang = sl[root], hl[root], pl[root], ang[root]
    a, b = p_.copy(), pr[root].copy()
    for _ in range(100):
        m = 0.5 * (a + b)
        neg = numer(m, sl, hl, p_, ang) < 0.0
        a = np.where(neg, m, a)
        b = np.where(neg, b, m)
    m = 0.5 * (a + b)
    inner = np.full(shape, np.inf)
    inner[root] = ratio(m, hl + sl * (m - p_), ang)
    return np.minimum(best, inner.min(axis=-1))


def worn_edges(knots, h, lo, hi) -> np.ndarray:
    """(..., 2, 2) where each worn face meets the rays of its extent, (inner ``lo``, outer ``hi``) end,
    (x, y) in the face's frame [m]: the face's edges (:func:`bearingsim.multibody.loop.worn_contact`), at
    the polar radius :func:`worn_radius`. Unworn (``h = R``) the edges are the arc's ends, ``R (cos e, sin e)``."""
    r = worn_radius(knots, h, np.array([lo, hi]))
    out = np.zeros(r.shape + (2,))
    for j, e in enumerate((lo, hi)):
        out[..., j, 0] = r[..., j] * math.cos(e)
        out[..., j, 1] = r[..., j] * math.sin(e)
    return np.ascontiguousarray(out)


def worn_array(p) -> np.ndarray | None:
    """(n, 2, bins) worn depth of each pocket's (front, rear) face per bin of psi [m] (``p.wear.worn_depth``);
    None for unworn faces."""
    if p.wear.worn_depth is None:
        return None
    return np.array(p.wear.worn_depth, dtype=np.float64)


def face_radial_reach(p) -> float:
    """How far [m] the cage centre can move off the axis while the rollers still hold it: the radial reach
    of the arc faces from the pocket centre, ``R sin(min(-psi_in, psi_out))``."""
    lo, hi = p.multibody.pocket_face_extent
    worn = worn_array(p)
    deepest = float(worn.max()) if worn is not None else 0.0  # worn faces reach further
    return (p.bearing.roller_radius + 0.5 * p.bearing.pocket_clearance + deepest) * math.sin(min(-lo, hi))


def centrifugal_load(p) -> float:
    """A roller's centrifugal load on the outer race at the cage's epicyclic speed, plus 1 mN [N]."""
    return p.bearing.roller_mass * p.bearing.pitch_radius * p.operating.omega_c**2 + 1e-3


def roller_start_radius(p) -> float:
    """Radius [m] of the roller centres at t = 0: on the outer race, pressed into it by their centrifugal
    load (rigid raceways: :func:`rigid_radius`; the reduced-equivalent scene's race has no clearance)."""
    if rigid(p):
        return rigid_radius(p)
    g = p.bearing
    pd = 0.0 if paper_assumptions(p.multibody.scene) else g.radial_clearance
    return g.outer_race_radius + 0.25 * pd - g.roller_radius - laws.palmgren_approach(centrifugal_load(p),
                                                                                      g.roller_length)


#: directions from the pocket centre at which :func:`assembly_overlap` measures a face's distance
ASSEMBLY_DIRECTIONS = 361


def assembly_overlap(p, outward: float = 0.0) -> float:
    """Largest overlap [m] of a roller with a face of its pocket as the bearing is assembled: the roller at
    :func:`roller_start_radius` (plus ``outward`` [m]), ``delta`` off its pocket centre along the radius, the
    cage centred (0: none).

    A face point in the direction ``e`` from the pocket centre lies at the face's polar radius ``r(e)``
    (``R = r_r + s/2`` for an arc, the circumscribed polyline's ``R / cos(e - m)`` with ``m`` the middle of
    its segment, :func:`worn_radius` for a worn face), so its distance from the roller centre ``(0, delta)``
    is ``sqrt(r^2 + delta^2 - 2 r delta sin e)``; the least over :data:`ASSEMBLY_DIRECTIONS` directions
    spanning the face's extent, its ends included, is the nearest. (For an arc face that is the end the
    roller moved to: the distance falls as sin e grows.) Flat faces stay ``s / 2`` away."""
    lo, hi = p.multibody.pocket_face_extent
    g = p.bearing
    delta = roller_start_radius(p) - g.pitch_radius + outward
    rr = g.roller_radius
    radius = rr + 0.5 * g.pocket_clearance
    arc = np.ones(g.roller_count, dtype=bool)
    arc[list(p.multibody.flat_pockets)] = False  # a flat face spans the whole pocket: s / 2 away
    if not arc.any():
        return 0.0
    e = np.linspace(lo, hi, ASSEMBLY_DIRECTIONS)
    worn = worn_array(p)
    n_seg = p.multibody.pocket_face_segments
    if worn is not None:
        knots, h = worn_lines((lo, hi), radius, worn[arc])
        r = worn_radius(knots, h, e)  # (pockets, 2, directions)
    elif n_seg > 0:
        width = (hi - lo) / n_seg
        middle = lo + width * (np.minimum(np.floor((e - lo) / width), n_seg - 1) + 0.5)
        r = radius / np.cos(e - middle)
    else:
        r = np.full(e.shape, radius)
    dist = np.sqrt(r**2 + delta**2 - 2.0 * r * delta * np.sin(e))
    return max(float(rr - dist.min()), 0.0)


def pinch(p) -> float:
    """Overlap [m] of the most loaded roller with its pocket's faces (0: none): the assembled roller pressed
    further into the outer race by its Palmgren approach under :func:`max_roller_load` (rigid raceways hold
    it at :func:`rigid_radius`). Above 0 the rim ends of its faces pinch it in the load zone: a jammed
    pocket, whose impulses are those of the rollers' raceway loads, not of a roller free in its pocket."""
    if paper_assumptions(p.multibody.scene):  # rollers held on the pitch circle: no raceway presses them out
        return 0.0
    approach = 0.0 if rigid(p) else laws.palmgren_approach(max_roller_load(p), p.bearing.roller_length)
    return assembly_overlap(p, approach)


def check_assembly(p) -> None:
    """Refuse a bearing whose rollers, as assembled, already overlap a pocket face by more than
    ``PENETRATION_LIMIT`` of the pocket clearance (:func:`assembly_overlap`): no time step removes it."""
    overlap = assembly_overlap(p)
    if overlap > PENETRATION_LIMIT * p.bearing.pocket_clearance:
        raise UserError(assembly_refusal(p, f"overlap a pocket face by {overlap:.3g} m"))


def check_face_segments(p) -> None:
    """Refuse one straight segment per arc face (``multibody.pocket_face_segments = 1``) on a free roller-guided
    cage (the full scene guided by its rollers): the segment is tangent to the arc at the extent's middle
    ``m = (psi_in + psi_out) / 2``, so a pocket's two faces are straight lines tilted by ``m`` either way, and
    a roller on the pocket's centre line ``y`` off its centre along the radius is ``s/2 - y sin m`` from each.
    They close on it only at ``y = s / (2 sin m)`` on one side (1.70 mm on the reference cage, ``m`` = -3.38
    deg; exact faces and polylines of 2 or more segments, slanted both ways, about 0.2-0.5 mm either way), and
    never on the other: the cage drifts that far off the axis and wedges a roller between faces 2 |m| apart,
    where it overlaps them by more than the 1 % bound at any step (measured: 2.1-2.3 um at t = 18-19.5 ms with
    steps of 4.0, 1.03 and 0.70 us, with and without friction). A land-guided or held cage does not drift."""
    if p.multibody.pocket_face_segments != 1 or p.multibody.scene != "full" or p.bearing.cage_guidance != "rollers":
        return
    lo, hi = p.multibody.pocket_face_extent
    m = 0.5 * (lo + hi)
    s = p.bearing.pocket_clearance
    if abs(math.sin(m)) > 1e-12:
        where = (f"close on a roller only {s / (2.0 * abs(math.sin(m))) * 1e3:.3g} mm "
                 f"{'inward' if m < 0 else 'outward'} of its pocket centre and never "
                 f"{'outward' if m < 0 else 'inward'} (exact faces: about 0.2 mm either way), where they wedge it "
                 f"between lines {2.0 * abs(math.degrees(m)):.2g} deg apart")
    else:
        where = "never close on a roller moving along the radius (parallel lines)"
    raise UserError(
        f"multibody.pocket_face_segments = 1: one straight segment per arc face (tangent at the extent's middle, "
        f"psi = {math.degrees(m):.3g} deg) hardly guides the roller-guided cage radially: a pocket's two faces "
        f"{where}; the cage drifts there and the roller overlaps the faces at any step; use 2 or more segments "
        f"(0: the exact arc faces) or guide the cage on a ring land (bearing.cage_guidance)")


def ring_start_offset(p) -> float:
    """Distance [m] of the inner ring's centre below the axis as a run starts it: the continuous quasi-static
    displacement (:func:`bearingsim.laws.quasi_static_load_zone`), at least P_d/2 (0 in the reduced-equivalent
    scene, which has no inner ring)."""
    g = p.bearing
    if paper_assumptions(p.multibody.scene):
        return 0.0
    pd = g.radial_clearance
    _, delta_qs = laws.quasi_static_load_zone(p.operating.radial_load, g.roller_count, g.roller_length, pd)
    return max(0.5 * pd, delta_qs)


def check_land_assembly(p) -> None:
    """Refuse an inner-land-guided cage whose land, as the bearing is assembled (the inner ring at
    :func:`ring_start_offset`, the cage centred on the axis), already reaches into the cage rim by more than
    ``LAND_OVERLAP_FRACTION`` of half the land clearance: the penalty contact would start with a force of
    (overlap / that bound) times its reference force, which no step removes. An outer land is centred on
    the axis, as the cage starts."""
    g = p.bearing
    if g.cage_guidance != "inner_land" or p.multibody.scene != "full":
        return
    half = 0.5 * g.cage_land_clearance
    start = ring_start_offset(p)
    overlap = start - half
    if overlap > LAND_OVERLAP_FRACTION * half:
        least = rounded3(2.0 * start / (1.0 + LAND_OVERLAP_FRACTION) * 1e3, up=True)
        raise UserError(
            f"bearing.cage_land_clearance_mm = {g.cage_land_clearance * 1e3:.4g} is too small for this bearing's "
            f"radial play under its load (bearing.radial_clearance_mm = {g.radial_clearance * 1e3:.4g}, "
            f"operating.radial_load_N = {p.operating.radial_load:.4g}): the inner ring as assembled "
            f"({start * 1e6:.3g} um below the axis, where the load puts it) carries its land {overlap * 1e6:.3g} um "
            f"into the rim of the cage centred on the axis, more than {LAND_OVERLAP_FRACTION:.0%} of half the land "
            f"clearance, which no step removes; give bearing.cage_land_clearance_mm at least {least:.3g} mm, or "
            f"guide the cage on the outer land")


def assembly_refusal(p, what: str) -> str:
    """The refusal of a bearing whose rollers, as assembled, ``what`` (the check before the run and the
    first step's overlap say the same)."""
    g = p.bearing
    return (f"bearing.pocket_clearance_mm = {g.pocket_clearance * 1e3:.4g} is too small for this bearing's radial "
            f"play (bearing.radial_clearance_mm = {g.radial_clearance * 1e3:.4g}): the rollers as assembled (on "
            f"the outer race, cage centred) {what}, more than {PENETRATION_LIMIT:.0%} of the pocket clearance, "
            f"which no shorter step removes")


class MultibodySetup(NamedTuple):
    """What one run fixes before its first step, computed once from the parameters by :func:`make_setup`
    (SI). The step loop's named inputs (``prm``, ``cfg``, ``land``, ``limits``, ``hold_rule``) are built
    here, so :func:`run` only places the scene and drives the loop."""

    p: object  #: the run's :class:`bearingsim.parameters.Parameters`
    scene: str  #: ``multibody.scene``
    reduced_eq: bool  #: the paper's assumptions in the plane (:func:`paper_assumptions`)
    kinematic: bool  #: the cage turns at the epicyclic speed (:data:`KINEMATIC_CAGE_SCENES`)
    rigid: bool  #: rigid raceways (:func:`rigid`)
    dt: float  #: the time step [s]
    dt_how: str  #: how it was chosen (the archive's ``dt_choice``)
    dt_explicit_limit: float  #: the explicit stability limit 2/omega_n [s] (inf: none)
    t_start: float  #: rigid raceways, automatic step: the start phase's length [s] (0: none)
    dt_start: float  #: the start phase's step [s] (``dt`` without one)
    radial_play: float  #: the diametral clearance the rollers' path has (0 in the reduced-equivalent scene) [m]
    rigid_radius: float  #: rigid raceways: the largest roller-centre radius [m]
    roller_start_radius: float  #: the rollers' centres at t = 0 [m]
    centrifugal_load: float  #: a roller's centrifugal load (+1 mN) [N]
    ring_how: str  #: the inner ring's model, as described in the provenance
    prm: fk.RacewayParams
    cfg: rk.RecorderConfig
    land: fk.LandParams
    limits: lp.LoopLimits
    hold_rule: lp.HoldRule
    phi: float  #: the reduced-equivalent scene's load-zone half angle [rad] (0 elsewhere)
    face_reach: float  #: :func:`face_radial_reach` [m]
    worn: np.ndarray | None  #: :func:`worn_array`: each face's worn depth per bin of psi [m] (None: unworn)


def make_setup(p, dt=None, penetration_limit=PENETRATION_LIMIT) -> MultibodySetup:
    """The :class:`MultibodySetup` of the parameters ``p`` (``dt`` overrides the step's choice; UserError
    for what the scene cannot run)."""
    geo, op = p.bearing, p.operating
    scene_kind = p.multibody.scene
    # two separate choices of the scene (docs/crosscheck.md): the paper's assumptions (no inner ring,
    # no traction, fixed spin, rollers held at the front of their pockets in the load zone, roller path
    # on the pitch circle) and a kinematic cage turning at the epicyclic speed
    reduced_eq = paper_assumptions(scene_kind)
    n = geo.roller_count
    if n < 3:
        raise UserError(f"bearing.roller_count = {n}: the multibody model needs at least 3 rollers")
    is_rigid = rigid(p)
    if is_rigid:
        check_rigid(p)
    h, dt_how, dt_lim, t_start, h_start = _steps(p, dt, is_rigid)
    s = geo.pocket_clearance
    rp = geo.pitch_radius
    K = laws.palmgren_stiffness(geo.roller_length)
    # the reduced-equivalent scene keeps the paper's roller path on the pitch circle (no clearance)
    pd = 0.0 if reduced_eq else geo.radial_clearance
    # rigid raceways: roller centres on the outer race, at most r_c from the axis (a unilateral joint);
    # the inner-race contact carries both contacts' compliance in series, Q = K 2^(-10/9) delta^(10/9)
    r_c = rigid_radius(p)
    K_race = K * 2.0 ** (-10.0 / 9.0) if is_rigid else K
    # rollers start on the outer race (centrifugal), moving with the cage
    n_centrifugal = centrifugal_load(p)
    r0 = roller_start_radius(p)
    ring_mass, ring_how = inner_ring_model(p)
    prm = _raceway_params(p, reduced_eq, is_rigid, pd, r_c, K_race, ring_mass)
    nrot = p.numerics.rotations
    cfg = rk.RecorderConfig(sign=float(op.sign), roller_count=int(n), warmup_rotations=float(p.numerics.warmup_rotations),
                            rotations=nrot, theta_bins=THETA_BINS, impact_speed_threshold=IMPACT_SPEED_THRESHOLD_M_S,
                            pocket_centre_radius=float(geo.pitch_radius),
                            psi_lo=float(p.multibody.pocket_face_extent[0]),
                            psi_hi=float(p.multibody.pocket_face_extent[1]))
    # reduced-equivalent: held rollers sit at the front of their pockets on the outer race
    phi = p.reduced.load_zone_half_angle if reduced_eq else 0.0
    # the rollers hold the cage only while its centre stays within the radial reach of the face arcs
    face_reach = face_radial_reach(p)
    # a land-guided cage is held by its land (the full scene's free cage only)
    land = land_params(p, active=scene_kind == "full" and geo.cage_guidance != "rollers")
    orbit_limit = face_reach
    if land.active:  # the inner land moves with the inner ring, at most P_d/2 plus its raceway approach
        orbit_limit = land.half_clearance * (1.0 + LAND_ORBIT_MARGIN) + (
            0.5 * pd + raceway_approach_limit(p) if land.inner else 0.0)
    total_rot = p.numerics.warmup_rotations + nrot
    travel_end = 2.0 * math.pi * total_rot
    steps_est = int(math.ceil(travel_end / op.omega_c / h + t_start / h_start))
    lim = lp.LoopLimits(
        travel_end=travel_end, travel_record=2.0 * math.pi * p.numerics.warmup_rotations,
        penetration=penetration_limit * s,  # (the stability scan passes 0.5 to look for blow-up alone)
        omega=3.0 * op.omega_i + 10.0, omega_nominal=float(op.omega_c), orbit=float(orbit_limit),
        raceway_approach=raceway_approach_limit(p), out_every=_sample_every(p, h),
        max_steps=int(3 * steps_est + 1000), chunk_steps=chunk_steps(p), **rk.motion_limits(p))
    hold = lp.HoldRule(active=reduced_eq, phi=float(phi),
                       radius=r_c if is_rigid else rp - laws.palmgren_approach(n_centrifugal, geo.roller_length),
                       front_offset=0.5 * s, omega_cage=float(op.sign * op.omega_c))
    return MultibodySetup(
        p=p, scene=scene_kind, reduced_eq=reduced_eq, kinematic=scene_kind in KINEMATIC_CAGE_SCENES, rigid=is_rigid,
        dt=h, dt_how=dt_how, dt_explicit_limit=dt_lim, t_start=t_start, dt_start=h_start, radial_play=pd,
        rigid_radius=r_c, roller_start_radius=r0, centrifugal_load=n_centrifugal, ring_how=ring_how, prm=prm,
        cfg=cfg, land=land, limits=lim, hold_rule=hold, phi=phi, face_reach=face_reach, worn=worn_array(p))


def chunk_steps(p) -> int:
    """Steps the compiled loop takes before it returns to Python at the latest (a pending signal is handled
    there, the progress bar moves): ``CHUNK_STEPS`` (~0.3 s) with exact faces, divided by N^1.5 for a polyline
    of N segments a face (``multibody.pocket_face_segments``), whose step costs more the more segments there
    are (63: 50-65 times, docs/geometry.md; 1000: about 1e4 times, 0.17 s a step on 2 shared cores), so that
    a chunk lasts no longer. The chunk's end changes no number: the loop goes on from where it returned."""
    return max(1, int(lp.CHUNK_STEPS / max(1, p.multibody.pocket_face_segments) ** 1.5))


def _steps(p, dt, is_rigid):
    """(step [s], how it was chosen, explicit limit [s], start phase [s], its step [s]): :func:`choose_dt`,
    and with rigid raceways and the automatic step the cage's settling at a step of its own
    (:func:`rigid_start`; a start phase of 0 s when that step is not shorter)."""
    auto = dt is None and p.numerics.dt is None
    play = worn_play(p) if auto else None  # the worn play, once (its polar radii take a bisection)
    h, dt_how, dt_lim = choose_dt(p, dt, play)
    t_start, h_start = rigid_start(p, h, play) if is_rigid and auto else (0.0, h)
    if h_start < h:
        dt_how += f"; the first {t_start:.3g} s (the cage settling onto its rollers) at {h_start:.3e} s"
    else:
        t_start = 0.0
    return h, dt_how, dt_lim, t_start, h_start


def _raceway_params(p, reduced_eq, is_rigid, pd, r_c, K_race, ring_mass) -> fk.RacewayParams:
    """The raceway kernel's :class:`~bearingsim.multibody.forces.RacewayParams`: the races widened by a
    quarter of the diametral play ``pd`` each [m], the contact stiffness ``K_race``, the rigid scene's
    radius ``r_c`` [m] and the inner ring's mass (0: quasi-static)."""
    geo, op = p.bearing, p.operating
    rr = geo.roller_radius
    ro_race = geo.outer_race_radius + 0.25 * pd
    ri_race = geo.inner_race_radius - 0.25 * pd
    return fk.RacewayParams(
        roller_radius=float(rr), roller_mass=float(geo.roller_mass), roller_inertia=float(geo.roller_inertia),
        outer_race_radius=float(ro_race), inner_race_radius=float(ri_race),
        outer_race_geom_radius=float(geo.outer_race_radius), inner_race_geom_radius=float(geo.inner_race_radius),
        palmgren_stiffness=float(K_race), damping_time=0.0 if is_rigid else CONTACT_DAMPING_S,
        damping_fade=DAMPING_FADE_M,
        traction_mu_max=float(p.contact.traction_mu_max),
        traction_slip_ref=float(p.contact.traction_slip_ref), min_entrainment=MIN_ENTRAINMENT_M_S,
        drag_coefficient=float(p.contact.drag_coefficient), drag_direction_eps=DRAG_DIRECTION_EPS_M_S,
        omega_ring=float(op.sign * op.omega_i), radial_load=float(op.radial_load), gravity=float(op.gravity),
        inner_ring=not reduced_eq, traction=not reduced_eq, spin_free=not reduced_eq,
        newton_max_step=NEWTON_MAX_STEP_M, ring_mass=float(ring_mass), rigid=is_rigid, rigid_radius=float(r_c))


def _sample_every(p, step) -> int:
    """Steps between output samples (and health checks) at ``numerics.output_rate`` for a step ``step`` [s]."""
    return max(1, int(round(1.0 / (p.numerics.output_rate * step))))


ORBIT_KEEP = 4096  # the last cage-centre samples kept for the orbit figure


class _Placed(NamedTuple):
    """The pymunk scene of a run, placed at t = 0, with the step loop open on it."""

    sc: object  #: :class:`bearingsim.multibody.scene.Scene`
    io: object  #: the step loop (:func:`bearingsim.multibody.chipmunk.open_step_loop`)
    why: str | None  #: why the plain loop runs, if it does
    inp: lp.StepInputs
    wk: lp.StepWork


def _place(su: MultibodySetup, step_loop) -> _Placed:
    """Build the scene, put the rollers on the outer race moving with the cage, and open the step loop."""
    p = su.p
    geo, op = p.bearing, p.operating
    n = geo.roller_count
    n_seg = p.multibody.pocket_face_segments
    sc = build_scene(geo, op, p.contact.restitution, p.contact.cage_friction, extent=p.multibody.pocket_face_extent,
                     n_seg=n_seg, kinematic_cage=su.kinematic, spin_free=not su.reduced_eq,
                     flat_pockets=p.multibody.flat_pockets, centred_cage=su.scene == "centred_cage",
                     rigid_radius=su.rigid_radius if su.rigid else None, worn=su.worn)
    nb = n + 1
    r0 = su.roller_start_radius
    omega_cage = op.sign * op.omega_c
    for i, b in enumerate(sc.rollers):
        a = sc.pocket_body_angle[i]
        b.position = (r0 * math.cos(a), r0 * math.sin(a))
        b.velocity = (-omega_cage * r0 * math.sin(a), omega_cage * r0 * math.cos(a))
    # pocket angles from the load-zone centre at t = 0, in [0, 2 pi)
    theta0 = np.mod(-2.0 * math.pi * np.arange(n) / n, 2.0 * math.pi)
    # start at the continuous quasi-static displacement (close to equilibrium: small start transient)
    # (the same start for rigid raceways: the continuous distribution's displacement is that of two
    # contacts in series already)
    ids = sc.body_ids
    order = np.argsort(ids)
    if su.reduced_eq or su.rigid:  # held rollers (reduced-equivalent), rollers on the race (rigid): states set too
        set_fields = lp.BODY_SET_ALL
        set_arr = np.zeros(nb * 7)
    else:
        set_fields = lp.BODY_SET_FORCE
        set_arr = np.zeros(nb * 3)
    e = float(p.contact.restitution)
    wk = lp.StepWork(
        ring_c=np.array([0.0, -ring_start_offset(p)]), ring_c_prev=np.zeros(2), ring_v=np.zeros(2),
        hold=np.zeros(n, dtype=np.bool_),
        # full scene: the kernel writes the (fx, fy, torque) rows straight into the set buffer
        out_f=np.zeros(nb * 3) if (su.reduced_eq or su.rigid) else set_arr, set_arr=set_arr,
        diag=np.zeros(n, dtype=fk.DIAG), smp=np.zeros(2048, dtype=lp.SAMPLE),
        orbit=np.full((ORBIT_KEEP, 3), np.nan), land_out=np.zeros(4), land_win=np.zeros((p.numerics.rotations, 3)),
        n_out=np.full(n, su.centrifugal_load),  # rigid: the first step's outer-race loads, before a joint has acted
        n_held=np.zeros(n),
        e_set=np.full(n, e), e_want=np.full(n, e), touched=np.zeros(n, dtype=np.bool_),
        n_extra=np.zeros(n),
        arc_ends=sc.face_segments[:, :2, :].copy() if sc.arc_shapes is not None else np.zeros((n, 2, 4)),
        arc_todo=np.zeros((n, 2), dtype=np.bool_), rest_win=np.zeros((p.numerics.rotations, 3)),
        rot_win=np.zeros((p.numerics.rotations, 3)), mot=rk.motion_block(n))
    # room for every roller against every face segment of every pocket: pymunk never grows the arrays
    arb_cap = max(4096, 2 * max(n_seg, 1) * n * n + 64)
    rr = geo.roller_radius
    masks = face_geometry(sc, rr, lp.MASK_MARGIN_M)
    arc = arc_faces(sc, rr, op.sign, su.worn) if sc.arc_shapes is not None else lp.ARC_FACES_OFF
    io, why = chipmunk.open_step_loop(sc.space, nb, set_fields, set_arr, arb_cap, step_loop, sc.joints,
                                      [next(iter(b.shapes)) for b in sc.rollers], [*sc.rollers, sc.cage], masks,
                                      sc.arc_shapes)
    inp = lp.StepInputs(
        h=float(su.dt), prm=su.prm, cfg=su.cfg, lim=su.limits, hold_rule=su.hold_rule, land=su.land,
        pocket_a=np.ascontiguousarray(sc.pocket_body_angle, dtype=np.float64), theta0=theta0,
        ids_sorted=ids[order].astype(np.uint64), ids_index=order.astype(np.int64),
        onset_restitution=su.rigid, restitution=e, arc=arc)
    return _Placed(sc, io, why, inp, wk)


def _series(sink, su: MultibodySetup):
    """The time series a run streams to ``sink``: (appender, sample fields) pairs (None: no sink). The
    inner ring's says which ring it is: dynamic (a mass, :func:`inner_ring_model`) or quasi-static."""
    if sink is None:
        return None
    series = [
        (sink.timeseries("cage_angular_speed", (), "rad/s", "cage angular speed in the direction of rotation"),
         ("cage_speed",)),
        (sink.timeseries("cage_slip", (), "1", "1 - cage speed / epicyclic speed (Eq. 11)"), ("cage_slip",)),
        (sink.timeseries("cage_centre", (2,), "m", "cage centre (x, y); y up, radial load along -y"),
         ("cage_x", "cage_y")),
    ]
    if not su.reduced_eq:
        ring = "dynamic" if su.prm.ring_mass > 0.0 else "quasi-static"
        series.append((sink.timeseries("inner_ring_centre", (2,), "m", f"{ring} inner-ring centre (x, y)"),
                       ("ring_x", "ring_y")))
    return series


class MultibodyRaw(NamedTuple):
    """What one run of the step loop gives (:func:`run`): its set-up, its accumulators and its end state,
    SI. :meth:`bearingsim.multibody.MultibodyResult.from_raw` lays it out as a result."""

    setup: MultibodySetup
    steps: int  #: steps taken
    wall_s: float  #: the run's wall time [s]
    loop_s: float  #: the step loop's wall time [s]
    pymunk_step_s: float  #: time inside pymunk's step (NaN: not timed)
    step_loop: str  #: "compiled" or "plain"
    step_loop_reason: str | None  #: why the plain loop ran, if it did
    t_end: float  #: simulated time [s]
    t_record: float  #: recorded time [s] (0: the recording never started)
    win: np.ndarray  #: per-rotation window accumulators (:func:`bearingsim.multibody.recorder.accumulators`)
    first_imp: np.ndarray  #: first rear-face impact speed in the no-load zone [rotation, pocket] (NaN: none)
    f_bin: np.ndarray  #: pocket force per theta bin, summed over steps
    t_bin: np.ndarray  #: steps per pocket and theta bin
    q_bin: np.ndarray  #: raceway loads per theta bin, summed over steps
    tq_bin: np.ndarray  #: steps per theta bin
    glob: np.void  #: whole-run accumulators (overlaps, torques)
    impacts: np.ndarray  #: the impact table, sorted by (time, pocket, face)
    prof: np.ndarray  #: the wear profile over the faces
    impacts_dropped: bool  #: the impact table filled up
    cage_w_start: float | None  #: cage speed when recording started [rad/s] (None: never)
    cage_w_end: float  #: cage speed at the end [rad/s]
    newton_failures: int  #: steps whose inner-ring force balance did not converge
    orbit_max: float  #: largest distance of the cage centre from the axis [m]
    final_state: np.ndarray  #: the bodies' states at the end
    orbit: np.ndarray  #: the last :data:`ORBIT_KEEP` cage-centre samples (t, x, y), oldest first
    ring_centre_mean: np.ndarray  #: mean inner-ring centre over the recorded steps [m] (NaN: no ring)
    lift_max: float | None  #: rigid raceways: largest lift of a roller off the outer race [m]
    beyond_max: float | None  #: rigid raceways: largest move of a roller beyond the race [m]
    beyond_vr: float | None  #: rigid raceways: the radial speed with it [m/s]
    beyond_before: float | None  #: rigid raceways: the move beyond the race before the joint acted [m]
    land: dict | None  #: land-guided cage: per-rotation impulses, torque, overlap, stiffness, half clearance
    rest_win: np.ndarray  #: (R, 3) per cage rotation: sums of the sampled cage centre's x and y [m], sample count
    #: (R, 3) per cage rotation: its time [s] (from and to where the cage's travel crosses its ends, within a step),
    #: the sum of the inner-ring centre's y over its steps [m], their count
    rot_win: np.ndarray


def run(p, sink=None, progress=False, dt=None, penetration_limit=PENETRATION_LIMIT,
        step_loop=None) -> MultibodyRaw:
    """Run the parameters ``p``; return the step loop's :class:`MultibodyRaw`.

    Time series go to ``sink`` (``timeseries(...)`` appenders; see :class:`bearingsim.results.MemorySink`).

    ``step_loop``: "compiled", "plain" or None (see :mod:`bearingsim.multibody.chipmunk`); which one ran is
    ``raw.step_loop``.
    """
    t_wall0 = time.perf_counter()
    su = make_setup(p, dt, penetration_limit)
    pl = _place(su, step_loop)
    acc = rk.accumulators(p.numerics.rotations, p.bearing.roller_count, THETA_BINS, IMPACT_CAPACITY)
    ls = np.zeros(1, dtype=lp.LOOP_STATE)
    t_loop0 = time.perf_counter()
    motion = (rk.MotionSeries(sink, p.bearing.roller_count, not su.reduced_eq)
              if sink is not None and p.numerics.motion_rotations > 0 else None)
    _drive(su, pl, acc, ls, _series(sink, su), motion, progress)
    loop_s = time.perf_counter() - t_loop0
    return _raw(su, pl, acc, ls[0], loop_s, t_wall0)


def _drive(su: MultibodySetup, pl: _Placed, acc, ls, series, motion, progress) -> None:
    """Advance the step loop to the end of the run, streaming samples to ``series`` and the bodies' poses
    to ``motion`` (:class:`bearingsim.multibody.recorder.MotionSeries`, or None) and moving the progress
    bar; raise for a run that cannot go on (:func:`_stop`)."""
    n = su.p.bearing.roller_count
    sign = su.p.operating.sign
    total_rot = su.p.numerics.warmup_rotations + su.p.numerics.rotations
    io, wk, inp_main = pl.io, pl.wk, pl.inp
    inp = inp_main
    if su.t_start > 0.0:  # the start phase: its own step (and samples at the same rate)
        inp = inp._replace(h=float(su.dt_start), lim=su.limits._replace(
            t_phase_end=float(su.t_start), out_every=_sample_every(su.p, su.dt_start)))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total_rot, unit="rot", desc="cage rotations", file=sys.stderr)
    bar_done = 0
    io.read_states()
    st = ls[0]
    while True:
        code = io.advance(inp, wk, acc, ls)
        k = int(st["n_samples"])
        if series is not None and k:
            smp = wk.smp[:k]
            for ts, cols in series:
                ts.append(smp["step"].copy(), smp["t"].copy(),
                          smp[cols[0]].copy() if len(cols) == 1 else np.stack([smp[c] for c in cols], axis=1))
        st["n_samples"] = 0
        if motion is not None:
            motion.flush(wk.mot, int(st["n_motion"]))
        st["n_motion"] = 0
        state = io.states[int(st["cur"])]
        if bar is not None:
            done = min(total_rot, int(sign * state[n, 2] / (2.0 * math.pi)))
            if done > bar_done:
                bar.update(done - bar_done)
                bar_done = done
        if code in (lp.CODE_BLOCK_FULL, lp.CODE_PHASE_END) and \
                int(st["newton_failures"]) > MAX_NEWTON_FAILURE_FRACTION * su.limits.max_steps:  # a stop says its own
            if bar is not None:
                bar.close()
            raise SimulationUnstable(newton_refusal(su.p, int(st["newton_failures"]), int(st["step"]),
                                                    su.limits.max_steps))
        if code == lp.CODE_BLOCK_FULL:
            continue
        if code == lp.CODE_PHASE_END:
            # the overlap is checked every out_every steps: the phase's last ones are checked here
            if acc.glob[0]["maxpen_all"] <= su.limits.penetration:
                inp = inp_main
                continue
            code = lp.CODE_PENETRATION  # stopped with the start phase's step
        if code == lp.CODE_DONE:
            break
        if bar is not None:
            bar.close()
        _stop(code, su, inp, wk, acc, state, float(st["t"]), int(st["step"]))
    if bar is not None:
        bar.update(total_rot - bar_done)
        bar.close()


def newton_refusal(p, fails: int, steps: int, max_steps: int | None = None) -> str:
    """The refusal of a run whose quasi-static ring's force balance failed in more than
    :data:`MAX_NEWTON_FAILURE_FRACTION` of its ``steps`` (:func:`bearingsim.plausibility.check`, the run done), or,
    with ``max_steps``, of the most steps it may take, said as soon as that is certain (the step loop)."""
    advice = "set a smaller numerics.dt_s or multibody.inner_ring=dynamic"
    if max_steps is None:
        return (f"the inner ring's force balance did not converge in {fails} of {steps} steps ({fails / steps:.2%}; "
                f"provenance ring_newton_failures); {advice}")
    return (f"the inner ring's force balance did not converge in {fails} of the first {steps} steps "
            f"({fails / steps:.2%}), already more than {MAX_NEWTON_FAILURE_FRACTION:.0%} of the at most {max_steps} "
            f"steps the run may take (provenance ring_newton_failures); {advice}")


def _stop(code, su: MultibodySetup, inp, wk, acc, state, t, step):
    """Raise the error of a step loop that stopped with ``code`` before the end of the run."""
    n = su.p.bearing.roller_count
    h = inp.h
    lim = su.limits
    if code == lp.CODE_NONFINITE:
        raise SimulationUnstable(f"non-finite state at t = {t:.6g} s (step {step}); "
                                 + (unstable_advice(su.p, h, su.dt_how)
                                    or f"try a smaller numerics.dt_s than {h:.3g} s"))
    if code == lp.CODE_PENETRATION:
        g = acc.glob[0]
        raise PenetrationExceeded(g["maxpen_all"], lim.penetration, h, g["maxpen_time"], g["maxpen_approach"],
                                  su.dt_how)
    if code == lp.CODE_BLOWUP:
        raise SimulationUnstable(
            f"raceway approach {max(wk.diag['delta_out'].max(), wk.diag['delta_in'].max() if su.rigid else 0.0):.3g} m "
            f"(limit {lim.raceway_approach:.3g} m, 3x the "
            f"Palmgren approach under the whole operating.radial_load_N) or cage speed {state[n, 5]:.3g} rad/s "
            f"(limit {lim.omega:.3g}) out of bounds at t = {t:.6g} s (energy blow-up); {_blowup_advice(su, h)}")
    if code == lp.CODE_STALLED:
        total_rot = su.p.numerics.warmup_rotations + su.p.numerics.rotations
        raise SimulationUnstable(
            f"cage did not complete {total_rot} rotations in {step} steps "
            f"(cage speed {state[n, 5]:.3g} rad/s): the cage stalled")
    off = math.hypot(state[n, 0], state[n, 1]) * 1e3
    if code == lp.CODE_CAGE_LOST and su.land.active:
        raise SimulationUnstable(
            f"the cage centre moved {off:.4g} mm off the bearing axis at "
            f"t = {t:.6g} s, more than {LAND_ORBIT_MARGIN:.0%} of half the land clearance "
            f"(bearing.cage_land_clearance_mm) beyond its {su.p.bearing.cage_guidance.replace('_', ' ')}: the land "
            f"contact did not hold it; "
            + (unstable_advice(su.p, h, su.dt_how) or f"try a smaller numerics.dt_s than {h:.3g} s"))
    if code == lp.CODE_CAGE_LOST:
        raise SimulationUnstable(
            f"the cage centre moved {off:.4g} mm off the bearing axis at "
            f"t = {t:.6g} s, beyond the radial reach of its pocket faces ({su.face_reach * 1e3:.4g} mm): the rollers no "
            f"longer hold it; {_hold_advice(su.p)}")
    raise RuntimeError(f"multibody step loop: pymunk grew a batch buffer at step {step} (code {code})")


def _blowup_advice(su: MultibodySetup, h: float) -> str:
    """What to change after an energy blow-up with step ``h``: a smaller step (the automatic one for a given step
    longer than it, :func:`unstable_advice`). A quasi-static ring resting on a single roller, which no step
    mends, never runs (:func:`inner_ring_model` refuses it)."""
    return unstable_advice(su.p, h, su.dt_how) or f"try a smaller numerics.dt_s than {h:.3g} s"


def one_roller_ring_advice(p) -> str | None:
    """The remedy of a quasi-static ring resting on a single roller
    (:func:`bearingsim.laws.loaded_rollers_with_one_at_centre` < 2 under load, where ``multibody.inner_ring =
    "auto"`` makes it dynamic), or None for any other ring. Such a ring has no stable sideways equilibrium
    (docs/stability.md, The inner ring): its force balance fails and it blows up whatever the step."""
    g, load = p.bearing, p.operating.radial_load
    if inner_ring_mode(p)[0] == "quasi_static" and load > 0.0:
        k = laws.loaded_rollers_with_one_at_centre(load, g.roller_count, g.roller_length, g.radial_clearance)
        if k < 2:
            return (f"the quasi-static inner ring rests on one roller here ({k} loaded with one at the load-zone "
                    f"centre), which has no stable sideways equilibrium: a massless ring jumps between supports "
                    f"(docs/stability.md, The inner ring) and a smaller numerics.dt_s does not help; set "
                    f"multibody.inner_ring = \"dynamic\" (or \"auto\", which chooses it here)")
    return None


def _hold_advice(p) -> str:
    """What lets the rollers hold a roller-guided cage that got away from them: wider faces where the cage
    wall allows them, a smaller pocket play, or a ring land to guide the cage."""
    b, mb = p.bearing, p.multibody
    rest = (f"give a smaller pocket clearance (bearing.pocket_clearance_mm = {b.pocket_clearance * 1e3:g} mm) or guide "
            f"the cage on a ring land (bearing.cage_guidance)")
    if mb.pocket_face_rule != "given":
        return f"the faces already span the cage wall (multibody.pocket_face_half_angle_deg = 'auto'): {rest}"
    if b.cage_inner_radius is None or b.cage_outer_radius is None:
        return f"widen the faces (multibody.pocket_face_half_angle_deg), {rest}"
    lo, hi = laws.pocket_face_extent(b.pitch_radius, b.roller_radius + 0.5 * b.pocket_clearance, b.cage_inner_radius,
                                     b.cage_outer_radius)
    wall = math.degrees(min(-lo, hi))
    given = math.degrees(min(-mb.pocket_face_extent[0], mb.pocket_face_extent[1]))
    if given < wall * (1.0 - 1e-9):
        return (f"widen the faces (multibody.pocket_face_half_angle_deg = {given:.4g}; the cage wall allows up to "
                f"{wall:.4g} deg, or 'auto'), {rest}")
    return f"the faces already span the cage wall (multibody.pocket_face_half_angle_deg = {given:.4g} deg): {rest}"


def _raw(su: MultibodySetup, pl: _Placed, acc, st, loop_s: float, t_wall0: float) -> MultibodyRaw:
    """The :class:`MultibodyRaw` of a finished run."""
    n = su.p.bearing.roller_count
    n_imp = int(st["n_imp"])
    # impacts in one step come in pymunk's arbiter order, which follows shape addresses: sort them by
    # (time, pocket, face) so that the table is the same in every run (front before rear, as before the
    # face codes of the two models were made the same)
    imp = acc.impacts[:n_imp]
    imp = imp[np.lexsort((imp["face"] != rk.FACE_FRONT, imp["pocket"], imp["time"]))]
    wall = time.perf_counter() - t_wall0
    io, wk = pl.io, pl.wk
    prev = io.states[int(st["cur"])]
    rec_started = st["recording"] == 1
    t = float(st["t"])
    ring_n = st["ring_n"]
    n_orbit = int(st["n_orbit"])
    land = su.land
    rigid_ = su.rigid
    return MultibodyRaw(
        setup=su, steps=int(st["step"]), wall_s=wall, loop_s=loop_s,
        pymunk_step_s=st["pymunk_ns"] * 1e-9 if io.timed else float("nan"), step_loop=io.name,
        step_loop_reason=pl.why, t_end=t, t_record=t - st["t_rec0"] if rec_started else 0.0, win=acc.win,
        first_imp=acc.first_imp, f_bin=acc.f_bin, t_bin=acc.t_bin, q_bin=acc.q_bin, tq_bin=acc.tq_bin,
        glob=acc.glob.copy()[0], impacts=imp, prof=acc.prof, impacts_dropped=n_imp >= IMPACT_CAPACITY,
        cage_w_start=st["cage_w_start"] if rec_started else None, cage_w_end=prev[n, 5],
        newton_failures=int(st["newton_failures"]), orbit_max=st["orbit_max"], final_state=prev.copy(),
        orbit=np.roll(wk.orbit, -(n_orbit % ORBIT_KEEP), axis=0),
        ring_centre_mean=(np.array([st["ring_sum_x"], st["ring_sum_y"]]) / ring_n if ring_n and not su.reduced_eq
                          else np.full(2, np.nan)),
        lift_max=float(st["lift_max"]) if rigid_ else None,
        beyond_max=float(st["beyond_max"]) if rigid_ else None, beyond_vr=float(st["beyond_vr"]) if rigid_ else None,
        beyond_before=float(st["beyond_before"]) if rigid_ else None,
        land=(dict(win=wk.land_win.copy(), tau=float(st["land_tau"]), overlap_max=float(st["land_overlap_max"]),
                   stiffness=land.stiffness, half_clearance=land.half_clearance) if land.active else None),
        rest_win=wk.rest_win.copy(), rot_win=wk.rot_win.copy(),
    )
