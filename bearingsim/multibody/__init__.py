"""Multi-pocket model: every roller and the cage in a pymunk space, through load and no-load zone.

Scenes (``[multibody] scene``)
------------------------------
``"full"``
    ``roller_count`` rollers (planar rigid bodies, free spin) and a free cage (x, y, angle). Outer ring
    fixed; inner ring turning at omega_i in the ``sign`` direction with a quasi-static centre that
    carries the radial load (-y). Raceway contacts are force laws in one numba kernel
    (:mod:`bearingsim.multibody.forces`): Palmgren line contact ``Q = K delta^(10/9)`` with the radial
    clearance, EHL traction ``mu_max tanh(slip/slip_ref)`` (Johnson & Tevaarwerk 1977), the oil-film
    resistance ``F_o = c N^0.246 V^0.648`` (Eq. 2) at each contact with its own N and V, gravity.
    The load zone emerges from the contact mechanics. Roller-cage contacts are pymunk contacts
    (restitution e, friction mu) on pocket faces that are exact arcs around the pocket centre (pocket
    diameter D + s) over what the cage wall allows (:mod:`bearingsim.multibody.scene`, docs/geometry.md).
``"centred_cage"``
    As ``"full"``, but the cage centre is held on the bearing axis by a pivot joint (the cage still
    turns freely under its contact torques): rung 4 of ``bearingsim crosscheck``.
``"kinematic_cage"``
    As ``"full"`` (raceway contacts, traction, inner ring: the load zone emerges), but the cage is a
    kinematic body centred on the axis turning at the epicyclic speed: rung 3 of the cross-check.
``"reduced_equivalent"``
    The seed paper's assumptions in the plane: cage kinematic at the epicyclic speed, no inner ring,
    roller spin fixed, no traction. Inside the load zone (``|theta| < phi``; phi =
    ``reduced.load_zone_half_angle_deg`` or the quasi-static value when ``"auto"``, the same rule as the
    reduced model) every roller is carried at the FRONT of its pocket with zero relative speed, so it
    enters the no-load zone like the reduced model's start condition; in the no-load zone it is free
    under the outer-race force law, F_o and gravity. Its I_dec per pass is the reduced model's.

Angles and rotations
--------------------
theta is a pocket centre's angle from the load-zone centre (the bottom, -y) measured in the direction of
cage rotation, in [0, 360) deg. Pocket i's initial angle is ``theta_i0 = (-360 i / Z) mod 360``.
**Rotation k of pocket i** is the interval of cage travel (cage angle turned in the direction of
rotation, from t = 0) ``[360 (W + k) - theta_i0, 360 (W + k + 1) - theta_i0)`` deg, W =
``numerics.warmup_rotations``: it starts when pocket i crosses the load-zone centre (theta = 0) and
contains one whole load zone exit, no-load zone and load zone entry. Everything before rotation 0 is
discarded. The run stops at a cage travel of ``360 (W + R)`` deg (R = ``numerics.rotations``), so
W >= 1 is needed for complete windows (with W = 0 the first window of pockets i > 0 is partial).

The model takes :class:`bearingsim.parameters.Parameters` and returns a :class:`MultibodyResult`; time
series go to the sink it is given (:class:`bearingsim.results.MemorySink` by default,
:class:`bearingsim.archive.Spool` to stream them into an archive). It never sees a scenario file or
an archive.

Recorded quantities (per pocket i, per rotation k)
-------------------------------------------------
* face: a roller-cage contact is on the *front* face when its normal from roller to cage points along
  e_t, the cage's direction of rotation at the pocket centre, else on the *rear* face;
* ``I_acc`` = sum of the circumferential (e_t) component of the front-face impulses on the cage,
  ``I_dec`` = minus the same on the rear face (both >= 0: the roller drives the cage, resp. the cage drags
  a lagging roller along and is braked by it), [N s]. This is what the paper's load cells measured. ``Jn_front/Jn_rear``: normal
  impulses, ``Jf_front/Jf_rear``: friction impulse magnitudes, ``slide_work_front/rear``: sum of
  ``J_n |v_slide|`` [N m] with the tangential relative speed of the contact points;
* impacts (`/results/impacts`, face column "rear" or "front", as in the reduced model): a contact step whose normal
  approach speed exceeds 0.01 m/s (anything slower is
  resting-contact chatter, which pymunk resolves with restitution on every step);
* wear per pocket face and cage rotation [m^3]: the paper's index ``k J_n r_r omega_r / H`` (Eq. 16, of the
  face's normal impulse J_n: on the arc faces the push is oblique; docs/physics.md) and
  the sliding work ``k sum(J_n |v_slide|) / H``.
"""
from __future__ import annotations

import math

import numpy as np

from bearingsim import laws
from bearingsim.errors import SimulationUnstable
from bearingsim.multibody import recorder as rk
from bearingsim.multibody.core import (face_radial_reach, IMPACT_SPEED_THRESHOLD_M_S, PENETRATION_LIMIT, THETA_BINS,
                                       PenetrationExceeded, assembly_refusal, check_assembly, check_face_segments,
                                       check_land_assembly, check_rigid, choose_dt, automatic_step,
                                       check_step_count, paper_assumptions, rigid, run,
                                       unstable_advice)
from bearingsim.datatypes import AttrGroup, NamedArray
from bearingsim.model_versions import MODEL_FIGURES, MODEL_VERSIONS
from bearingsim.results import MemorySink, Result

__all__ = ["simulate", "MultibodyResult", "MODEL_VERSION"]

#: version of this model's numbers, stored in each result's provenance (:mod:`bearingsim.model_versions`:
#: bumped when a change moves numbers)
MODEL_VERSION = MODEL_VERSIONS["multibody"]

SUMMARY_UNITS = {
    "I_dec_mean_Ns": "N s", "I_dec_std_Ns": "N s", "I_acc_mean_Ns": "N s", "I_acc_std_Ns": "N s",
    "first_impact_speed_m_s": "m/s", "first_impact_energy_J": "J", "cage_speed_mean_rad_s": "rad/s",
    "cage_slip": "1", "load_zone_half_angle_deg": "deg",
    "load_zone_contact_half_angle_deg": "deg", "inner_ring_displacement_m": "m", "torque_balance_residual": "1",
    "max_penetration_m": "m", "max_penetration_all_m": "m", "cage_orbit_max_m": "m", "cage_rest_offset_m": "m",
    "cage_rest_angle_deg": "deg", "dt_s": "s", "steps": "1",
}


#: summary numbers added after archives were written without them (model version 6: where the cage rests,
#: :func:`_cage_rest`): an archive of an earlier version reads without them
SUMMARY_ADDED = ("cage_rest_offset_m", "cage_rest_angle_deg")

RIGID_SUMMARY_UNITS = {"roller_lift_max_m": "m", "roller_beyond_race_max_m": "m"}

LAND_SUMMARY_UNITS = {
    "land_normal_impulse_mean_Ns": "N s", "land_friction_impulse_mean_Ns": "N s",
    "land_torque_impulse_Nms": "N m s", "land_overlap_max_m": "m", "land_stiffness_N_m": "N/m",
}

MAX_DT_RETRIES = 4

#: the wear profile's quantities (docs/wear.md): normal impulse [N s], sliding work [J], contact steps [1]
PROFILE_QUANTITIES = {"impulse": ("impulse", "N s"), "work": ("work", "J"), "hits": ("hits", "1")}
PROFILE_PATHS = frozenset({"results/wear/profile_psi_deg"} | {
    f"results/wear/profile_{q}_{f}" for q in PROFILE_QUANTITIES for f in ("front", "rear")})


def simulate(p, sink=None, progress=False, dt=None) -> "MultibodyResult":
    """Run the multi-pocket model for the SI parameters ``p``. ``dt`` [s] overrides ``numerics.dt``
    and the automatic choice; time series go to ``sink`` (kept in memory when None).

    A roller may not overlap a cage face by more than ``PENETRATION_LIMIT`` (1 %) of the pocket
    clearance: the overlap is the approach covered in the step in which a contact is found, ~v dt.
    With the automatic time step the run is restarted with a step shortened to the measured approach
    speed (at most ``MAX_DT_RETRIES`` times; the history goes into ``dt_choice``); with a given time
    step it stops with :class:`SimulationUnstable` naming the automatic step when the given one is longer
    (:func:`core.unstable_advice`), else the largest step that would keep the measured approach within the limit.
    """
    if sink is None:
        sink = MemorySink()
    else:  # a sink used before still holds that run's series, which are not this run's (nor its archive's)
        sink.discard_timeseries()
    auto = dt is None and p.numerics.dt is None
    retries = []
    first_how = ""  # how the first run's step was chosen (with the rigid scene's start phase, if any)
    while True:
        try:
            raw = run(p, sink=sink, progress=progress, dt=dt)
            break
        except PenetrationExceeded as exc:
            if exc.t <= 1.5 * exc.dt:
                # the overlap was there after the first step, in which the bodies, assembled moving with
                # the cage, cover far less than it (~ g dt^2): it is the assembled state, which no
                # shorter step removes (each restart would shorten the step by the ratio of the overlap
                # to the limit again, down to steps of 1e-13 s that never end)
                raise SimulationUnstable(f"{exc}: in the first step, so "
                                         + assembly_refusal(p, "already overlap a pocket face")) from None
            first_how = first_how or exc.how
            new_dt = exc.suggested_dt()
            if not auto or len(retries) >= MAX_DT_RETRIES:
                key = "numerics.dt_s" if not auto else "the automatic time step"
                advice = ((not auto and unstable_advice(p, exc.dt, exc.how))
                          or f"{key} is too long for this scene, use numerics.dt_s <= {new_dt:.3g} s")
                raise SimulationUnstable(
                    f"{exc}: more than {PENETRATION_LIMIT:.0%} of the pocket clearance; {advice}") from None
            retries.append(f"restarted at dt = {new_dt:.3g} s after overlap {exc.pen:.3g} m > "
                           f"{PENETRATION_LIMIT:.0%} s at dt = {exc.dt:.3g} s (approach {exc.approach:.3g} m/s)")
            dt = new_dt
            sink.discard_timeseries()
    if retries:  # the last run was given its dt: describe how the first one was chosen, then the restarts
        raw = raw._replace(setup=raw.setup._replace(dt_how="; ".join([first_how or choose_dt(p)[1], *retries])))
    res = MultibodyResult.from_raw(p, raw)
    res.series = sink.collect()
    return res


def check_start(p, dt: float | None = None) -> None:
    """Refuse, without running, what :func:`simulate` would refuse before its first step: rigid raceways
    at a speed where the rollers would leave the outer race (:func:`core.check_rigid`), rollers that
    overlap their pockets' faces as assembled (:func:`core.check_assembly`), one segment per face on a
    roller-guided cage (:func:`core.check_face_segments`), an inner land that overlaps the cage
    as assembled (:func:`core.check_land_assembly`), and a given ``dt`` (or
    ``numerics.dt``) far above the stable step (one line naming the key; :func:`core.choose_dt`). The
    automatic step is never refused as unstable (at most ``DT_FRACTION`` of the limit, below ``DT_MAX_FACTOR``
    of it), only at a crawl, where it needs more than ``MAX_STEPS_PER_ROTATION`` steps per cage rotation (as
    :func:`core.choose_dt` refuses it)."""
    if rigid(p):
        check_rigid(p)
    check_face_segments(p)
    check_assembly(p)
    check_land_assembly(p)
    if dt is not None or p.numerics.dt is not None:
        choose_dt(p, dt)
    else:
        check_step_count(p, automatic_step(p), "auto")


def _profile_arrays(prof, extent) -> dict:
    """The wear profile (:data:`bearingsim.multibody.recorder.PROFILE`, (n, 2, bins)) as archive arrays
    ``[face bin, pocket]`` per face, summed over the recorded rotations, with the bins' centres in psi."""
    lo, hi = extent
    nfb = prof.shape[2]
    psi = np.degrees(lo + (np.arange(nfb) + 0.5) * (hi - lo) / nfb)
    where = ("summed over the recorded rotations, per bin of psi (rows, /results/wear/profile_psi_deg) and "
             "pocket (columns)")
    out = {"results/wear/profile_psi_deg": NamedArray(
        psi, "deg", "bin centres of psi, the contact point's angle seen from the pocket centre, from the face's "
                    "middle (0) towards the cage rim (> 0) or bore (< 0); equal bins over the faces' extent")}
    for q, (field, unit) in PROFILE_QUANTITIES.items():
        what = {"impulse": "normal impulse", "work": "sliding work J_n |v_slide|", "hits": "contact steps"}[q]
        for f, code in (("front", rk.FACE_FRONT), ("rear", rk.FACE_REAR)):
            out[f"results/wear/profile_{q}_{f}"] = NamedArray(
                np.ascontiguousarray(prof[:, code, :][field].T), unit, f"{what} on the {f} face, {where}")
    return out


def _load_zone_half_angle(q_bin, tq_bin):
    """Half width [deg] of the theta range around 0 where the mean inner-race load > 1 % of its max."""
    nb = len(tq_bin)
    q = np.where(tq_bin > 0, q_bin["inner"] / np.maximum(tq_bin, 1e-300), 0.0)
    if q.max() <= 0:
        return 0.0
    loaded = q > 0.01 * q.max()
    centres = (np.arange(nb) + 0.5) * 360.0 / nb
    c = np.where(centres > 180.0, centres - 360.0, centres)
    # contiguous loaded region containing theta = 0
    order = np.argsort(c)
    c_sorted, l_sorted = c[order], loaded[order]
    i0 = int(np.argmin(np.abs(c_sorted)))
    if not l_sorted[i0]:
        return 0.0
    lo = i0
    while lo > 0 and l_sorted[lo - 1]:
        lo -= 1
    hi = i0
    while hi < nb - 1 and l_sorted[hi + 1]:
        hi += 1
    width = c_sorted[hi] - c_sorted[lo] + 360.0 / nb
    return 0.5 * width


def _rest_place(x, y, sign: int):
    """(distance from the axis [m], angle from the bottom counted in the direction of rotation [deg]) of
    the cage centre's mean position (x, y) (y up, the load along -y): where the cage rests. A whirling or
    centred cage's mean lies near the axis, where the angle says little: read it beside the distance."""
    return np.hypot(x, y), np.degrees(np.arctan2(sign * x, -y))


def _cage_rest(orbit, sign: int) -> dict:
    """The summary's :func:`_rest_place` of the mean over the kept samples of the cage's orbit (rows t, x,
    y: the end of the recording)."""
    o = orbit[np.isfinite(orbit[:, 0])]
    x, y = (o[:, 1].mean(), o[:, 2].mean()) if len(o) else (math.nan, math.nan)
    offset, angle = _rest_place(x, y, sign)
    return {"cage_rest_offset_m": float(offset), "cage_rest_angle_deg": float(angle)}


def _summary(p, raw, per) -> tuple[dict, dict]:
    """The headline numbers of a run and their units."""
    geo, op = p.bearing, p.operating
    # every scene but the reduced-equivalent one has an inner ring: its load zone emerges
    with_ring = not paper_assumptions(raw.setup.scene)
    # two measures of the load zone (docs/archive.md): the classical half angle from the mean ring
    # displacement (what the paper's 23.5 deg is) and the extent of the measured inner-race contact
    # (wider with discrete rollers: the laterally free ring shifts towards the exiting roller)
    ring_centre_mean = raw.ring_centre_mean
    if with_ring:
        phi_deg = math.degrees(laws.load_zone_from_displacement(-ring_centre_mean[1], geo.radial_clearance))
        phi_contact_deg = _load_zone_half_angle(raw.q_bin, raw.tq_bin)
    else:
        phi_deg = phi_contact_deg = math.degrees(raw.setup.phi)
    t_rec = raw.t_record
    cage_speed_mean = 2.0 * math.pi * p.numerics.rotations / t_rec if t_rec > 0 else float("nan")
    g = raw.glob
    ws, we = raw.cage_w_start, raw.cage_w_end
    momentum_change = geo.cage_inertia * (we - ws) if ws is not None else float("nan")
    drive = abs(per["I_acc"].sum()) * geo.pitch_radius
    if drive == 0.0:  # nothing drives the cage (a kinematic cage turned by its prescription): scale by
        drive = abs(per["I_dec"].sum()) * geo.pitch_radius  # the braking; -1 = all from the prescription
    land = raw.land
    tau = g["tau_normal"] + g["tau_friction"]
    if land is not None:  # the land friction torque on a land-guided cage
        tau = tau + land["tau"]
    torque_residual = ((tau - momentum_change) / drive if drive > 0 else float("nan"))
    fi = raw.first_imp[np.isfinite(raw.first_imp)]
    v1 = float(fi.mean()) if fi.size else float("nan")
    summary = {
        "I_dec_mean_Ns": float(per["I_dec"].mean()),
        "I_dec_std_Ns": float(per["I_dec"].std()),
        "I_acc_mean_Ns": float(per["I_acc"].mean()),
        "I_acc_std_Ns": float(per["I_acc"].std()),
        "first_impact_speed_m_s": v1,
        "first_impact_energy_J": 0.5 * geo.roller_mass * v1 * v1,
        "cage_speed_mean_rad_s": float(cage_speed_mean),
        "cage_slip": float(1.0 - cage_speed_mean / op.omega_c),
        "load_zone_half_angle_deg": float(phi_deg),
        "load_zone_contact_half_angle_deg": float(phi_contact_deg),
        "torque_balance_residual": float(torque_residual),
        "max_penetration_m": float(max(g["maxpen_front"], g["maxpen_rear"])),
        "max_penetration_all_m": float(g["maxpen_all"]),
        "cage_orbit_max_m": float(raw.orbit_max),
        **_cage_rest(raw.orbit, op.sign),
        "dt_s": float(raw.setup.dt),
        "steps": int(raw.steps),
    }
    if with_ring:  # the reduced-equivalent scene has no inner ring
        summary["inner_ring_displacement_m"] = float(-ring_centre_mean[1])
    units = dict(SUMMARY_UNITS)
    if raw.lift_max is not None:  # rigid raceways (docs/fast_scene.md)
        summary["roller_lift_max_m"] = float(raw.lift_max)
        summary["roller_beyond_race_max_m"] = float(raw.beyond_max)
        units.update(RIGID_SUMMARY_UNITS)
    if land is not None:
        summary.update({
            "land_normal_impulse_mean_Ns": float(land["win"][:, 0].mean()),
            "land_friction_impulse_mean_Ns": float(land["win"][:, 1].mean()),
            "land_torque_impulse_Nms": float(land["tau"]),
            "land_overlap_max_m": float(land["overlap_max"]),
            "land_stiffness_N_m": float(land["stiffness"]),
        })
        units.update(LAND_SUMMARY_UNITS)
    return summary, units


_PER_ROTATION_DESC = "per cage rotation (rows; see bearingsim.multibody docstring) and pocket (columns)"


def _rest_per_rotation(rest_win, sign: int) -> dict:
    """:func:`_rest_place` in each recorded rotation (``rest_win``: sums of the sampled centre's x, y and
    their count per rotation): ``/results/per_rotation/cage_rest_offset`` and ``cage_rest_angle`` (NaN: a
    rotation without a sample)."""
    count = rest_win[:, 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        offset, angle = _rest_place(rest_win[:, 0] / count, rest_win[:, 1] / count, sign)
    desc = "per cage rotation k (cage travel 2 pi (W + k) .. 2 pi (W + k + 1) from the start)"
    pr = "results/per_rotation"
    return {f"{pr}/cage_rest_offset": NamedArray(offset, "m", "distance of the cage centre's mean "
                                                 "position from the bearing axis, " + desc),
            f"{pr}/cage_rest_angle": NamedArray(angle, "deg",
                                                "that position's angle from the bottom (the load's direction), "
                                                "counted in the direction of rotation, " + desc)}


def _rotation_arrays(p, setup, rot_win) -> dict:
    """The cage slip and the load zone's half angle of each recorded cage rotation, the series whose batch means
    give those numbers' standard errors (:func:`bearingsim.stats.summary_standard_errors`), from the rotation's
    time and the inner ring's centre (its y) summed over its steps (``rot_win``): ``/results/per_rotation/cage_slip``,
    ``1 - 2 pi / (T_k omega_c)`` with T_k from and to where the cage's travel crosses the rotation's ends (the
    summary's ``cage_slip`` takes the recorded time in whole steps), absent for a cage turned at the epicyclic
    speed (:data:`~bearingsim.multibody.core.KINEMATIC_CAGE_SCENES`: it has no slip to measure); and
    ``load_zone_half_angle`` [deg], the summary's of the ring's mean displacement in that rotation, or the given
    one in every rotation of the scene without an inner ring."""
    desc = "per cage rotation k (cage travel 2 pi (W + k) .. 2 pi (W + k + 1) from the start)"
    pr = "results/per_rotation"
    out = {}
    if not setup.kinematic:
        with np.errstate(invalid="ignore", divide="ignore"):
            slip = 1.0 - 2.0 * math.pi / (rot_win[:, 0] * p.operating.omega_c)
        out[f"{pr}/cage_slip"] = NamedArray(slip, "1", "1 - (the cage's mean speed) / (its epicyclic speed) in the "
                                            "rotation, " + desc)
    if setup.reduced_eq:  # the paper's load zone, given
        phi = np.full(len(rot_win), math.degrees(setup.phi))
        what = "the given load-zone half angle (no inner ring), "
    else:
        with np.errstate(invalid="ignore", divide="ignore"):
            displacement = -rot_win[:, 1] / rot_win[:, 2]
        phi = np.array([math.degrees(laws.load_zone_from_displacement(d, p.bearing.radial_clearance))
                        for d in displacement])
        what = "classical load-zone half angle of the inner ring's mean displacement in the rotation, "
    out[f"{pr}/load_zone_half_angle"] = NamedArray(phi, "deg", what + desc)
    return out


def _per_rotation_arrays(per, first_imp, land) -> dict:
    """``/results/per_rotation``: the impulses, sliding work and first impact speed [rotation, pocket],
    and a land-guided cage's land impulses [rotation]."""
    desc = _PER_ROTATION_DESC
    pr = "results/per_rotation"
    data = {
        f"{pr}/I_acc": NamedArray(per["I_acc"], "N s", "front-face impulse, circumferential component, " + desc),
        f"{pr}/I_dec": NamedArray(per["I_dec"], "N s", "rear-face impulse, circumferential component (braking), " + desc),
        f"{pr}/Jn_front": NamedArray(per["Jn_front"], "N s", "front-face normal impulse, " + desc),
        f"{pr}/Jn_rear": NamedArray(per["Jn_rear"], "N s", "rear-face normal impulse, " + desc),
        f"{pr}/Jf_front": NamedArray(per["Jf_front"], "N s", "front-face friction impulse, " + desc),
        f"{pr}/Jf_rear": NamedArray(per["Jf_rear"], "N s", "rear-face friction impulse, " + desc),
        f"{pr}/slide_work_front": NamedArray(per["slide_work_front"], "J", "sum J_n |v_slide| on the front face, " + desc),
        f"{pr}/slide_work_rear": NamedArray(per["slide_work_rear"], "J", "sum J_n |v_slide| on the rear face, " + desc),
        f"{pr}/first_impact_speed": NamedArray(first_imp, "m/s", "approach speed of the first rear-face impact "
                                               "in the no-load zone (NaN: none), " + desc),
    }
    if land is not None:
        land_desc = ("per cage rotation k (cage travel 2 pi (W + k) .. 2 pi (W + k + 1) from the start), "
                     "land-guided cage")
        data[f"{pr}/land_normal"] = NamedArray(land["win"][:, 0].copy(), "N s",
                                               "normal impulse of the cage rim on its guiding land, " + land_desc)
        data[f"{pr}/land_friction"] = NamedArray(land["win"][:, 1].copy(), "N s",
                                                 "friction impulse magnitude on the land, " + land_desc)
        data[f"{pr}/land_torque"] = NamedArray(land["win"][:, 2].copy(), "N m s",
                                               "angular impulse of the land friction on the cage about its "
                                               "centre (counter-clockwise positive), " + land_desc)
    return data


def _theta_arrays(raw) -> dict:
    """Pocket forces per theta bin and pocket, and (with an inner ring) the raceway loads per theta bin."""
    nb = THETA_BINS
    theta_deg = (np.arange(nb) + 0.5) * 360.0 / nb
    tb = raw.t_bin  # (n, nb)
    with np.errstate(invalid="ignore", divide="ignore"):
        force_acc = np.where(tb > 0, raw.f_bin["front"] / tb, 0.0).T  # (nb, n)
        force_dec = np.where(tb > 0, raw.f_bin["rear"] / tb, 0.0).T
        tq = raw.tq_bin
        load_inner = np.where(tq > 0, raw.q_bin["inner"] / np.maximum(tq, 1e-300), 0.0)
        load_outer = np.where(tq > 0, raw.q_bin["outer"] / np.maximum(tq, 1e-300), 0.0)
    data = {
        "results/theta_deg": NamedArray(theta_deg, "deg", "bin centres of theta (load-zone centre = 0)"),
        "results/force_vs_theta": NamedArray(force_acc - force_dec, "N",
                                             "mean circumferential roller-cage force on the cage (F_acc - F_dec) per "
                                             "theta bin (rows, /results/theta_deg) and pocket (columns), recorded rotations"),
        "results/force_vs_theta_acc": NamedArray(force_acc, "N", "mean F_acc (front face) [theta bin, pocket]"),
        "results/force_vs_theta_dec": NamedArray(force_dec, "N", "mean F_dec (rear face) [theta bin, pocket]"),
    }
    if not paper_assumptions(raw.setup.scene):
        data["results/raceway_load_inner"] = NamedArray(load_inner, "N", "mean inner-race roller load per theta bin (all rollers)")
        data["results/raceway_load_outer"] = NamedArray(load_outer, "N", "mean outer-race roller load per theta bin (all rollers)")
    return data


def _impact_arrays(imp) -> dict:
    """The impact table's columns."""
    return {
        "results/impacts/time_s": NamedArray(imp["time"], "s"),
        "results/impacts/theta_deg": NamedArray(imp["theta_deg"], "deg"),
        "results/impacts/approach_speed_m_s": NamedArray(imp["approach_speed"], "m/s"),
        "results/impacts/impulse_Ns": NamedArray(imp["impulse"], "N s"),
        "results/impacts/pocket": NamedArray(imp["pocket"].astype(np.int64)),
        # face codes and strings of the reduced model (reduced/core.py)
        "results/impacts/face": NamedArray(np.where(imp["face"] == rk.FACE_FRONT, "front", "rear")),
        "results/impacts/rotation": NamedArray(imp["rotation"].astype(np.int64)),
    }


_WEAR_DESC = {
    "paper_index_front": "Archard wear per cage rotation, front face, k J_n r_r omega_r / H (paper Eq. 16 with the "
                         "normal impulse J_n, the contact force's), per pocket",
    "paper_index_rear": "Archard wear per cage rotation, rear face, k J_n r_r omega_r / H (Eq. 16), per pocket",
    "sliding_work_front": "Archard wear per cage rotation, front face, k sum(J_n |v_slide|) / H, per pocket",
    "sliding_work_rear": "Archard wear per cage rotation, rear face, k sum(J_n |v_slide|) / H, per pocket",
}


def _wear_arrays(p, per) -> dict:
    """Archard wear per cage rotation and pocket face [m^3]: the paper's index and the sliding work. Eq. 16's
    impulse is that of the contact force, the normal impulse J_n: on an arc face I_acc and I_dec are its
    circumferential component only (on the paper's flat faces the two are one)."""
    geo, op, w_ = p.bearing, p.operating, p.wear
    wear = {
        "paper_index_front": laws.archard_wear_volume(w_.wear_coefficient, per["Jn_front"].mean(axis=0),
                                                      geo.roller_radius, op.omega_r, w_.hardness),
        "paper_index_rear": laws.archard_wear_volume(w_.wear_coefficient, per["Jn_rear"].mean(axis=0),
                                                     geo.roller_radius, op.omega_r, w_.hardness),
        "sliding_work_front": w_.wear_coefficient * per["slide_work_front"].mean(axis=0) / w_.hardness,
        "sliding_work_rear": w_.wear_coefficient * per["slide_work_rear"].mean(axis=0) / w_.hardness,
    }
    return {f"results/wear/{k}": NamedArray(v, "m^3", _WEAR_DESC[k]) for k, v in wear.items()}


def _provenance(raw) -> dict:
    """How the numbers were computed: the step and how it was chosen, the solver and its timings."""
    su = raw.setup
    provenance = {
        "model_version": MODEL_VERSION, "dt_s": float(su.dt), "dt_choice": su.dt_how,
        "solver": "pymunk 7 (roller-cage) + numba raceway kernel", "steps": int(raw.steps),
        "ring_newton_failures": int(raw.newton_failures), "inner_ring": su.ring_how,
        "solver_wall_s": float(raw.wall_s), "pymunk_step_s": float(raw.pymunk_step_s),
        "step_loop": raw.step_loop, "step_loop_reason": raw.step_loop_reason,
    }
    if raw.impacts_dropped:  # the impact table stopped at its capacity (plausibility.impact_table_note)
        provenance["impacts_table_full"] = True
    if su.t_start > 0.0:  # rigid raceways: the cage's settling at a step of its own
        provenance.update(start_phase_s=float(su.t_start), start_phase_dt_s=float(su.dt_start))
    return provenance


class MultibodyResult(Result):
    """Result of :func:`simulate` (or read back from an archive). Arrays are [rotation, pocket] unless
    stated; ``raw`` holds the step loop's own accumulators on a fresh result (None when read back)."""

    model = "multibody"
    FIGURES = MODEL_FIGURES["multibody"]
    _PER_ROTATION = ("I_acc", "I_dec", "Jn_front", "Jn_rear", "Jf_front", "Jf_rear", "slide_work_front",
                     "slide_work_rear", "first_impact_speed")
    _LAND = ("land_normal", "land_friction", "land_torque")
    _REST = ("cage_rest_offset", "cage_rest_angle")  # where the cage rests (model version 6)
    _ROTATION = ("cage_slip", "load_zone_half_angle")  # their standard errors' series (model version 10)
    _IMPACTS = ("time_s", "theta_deg", "approach_speed_m_s", "impulse_Ns", "pocket", "face", "rotation")
    LAYOUT = {
        **{f"results/per_rotation/{c}": ("rotations", "pockets") for c in _PER_ROTATION},
        **{f"results/per_rotation/{c}": ("rotations",) for c in _LAND + _REST + _ROTATION},
        "results/theta_deg": ("theta bins",),
        **{f"results/{c}": ("theta bins", "pockets") for c in ("force_vs_theta", "force_vs_theta_acc",
                                                                "force_vs_theta_dec")},
        "results/raceway_load_inner": ("theta bins",), "results/raceway_load_outer": ("theta bins",),
        **{f"results/impacts/{c}": ("impacts",) for c in _IMPACTS},
        **{f"results/wear/{c}": ("pockets",) for c in ("paper_index_front", "paper_index_rear",
                                                       "sliding_work_front", "sliding_work_rear")},
        "results/wear/profile_psi_deg": ("face bins",),
        **{f"results/wear/profile_{q}_{f}": ("face bins", "pockets") for q in PROFILE_QUANTITIES for f in ("front", "rear")},
        "results/cage_orbit": ("orbit samples", 3),
    }  # in the order a run lays its arrays out (MultibodyResult.from_raw), which a result read back keeps
    OPTIONAL = (frozenset(f"results/per_rotation/{c}" for c in _LAND),  # a land-guided cage
                frozenset({"results/raceway_load_inner", "results/raceway_load_outer"}),  # a scene with a ring
                PROFILE_PATHS,  # archives written before the wear profile
                frozenset(f"results/per_rotation/{c}" for c in _REST),  # archives of model version 5 and before
                frozenset({"results/per_rotation/cage_slip"}),  # a kinematic cage
                frozenset(f"results/per_rotation/{c}" for c in _ROTATION))  # archives of model version 9 and before
    TEXT_ARRAYS = frozenset({"results/impacts/face"})
    SUMMARY_NUMBERS = tuple(k for k in SUMMARY_UNITS if k != "inner_ring_displacement_m"  # no ring: absent
                            and k not in SUMMARY_ADDED)
    SUMMARY_OPTIONAL = SUMMARY_ADDED
    FIGURE_DATA = ("results/theta_deg", "results/force_vs_theta_acc", "results/force_vs_theta_dec",
                   "results/per_rotation/I_acc", "results/per_rotation/I_dec", "results/cage_orbit", "results/wear")

    @classmethod
    def archive_dims(cls, scenario) -> dict[str, int]:
        return {"rotations": scenario.numerics.rotations, "pockets": scenario.bearing.roller_count,
                "theta bins": THETA_BINS}

    def __init__(self, *args, raw=None, **kw):
        super().__init__(*args, **kw)
        self.raw = raw

    @classmethod
    def from_raw(cls, p, raw) -> "MultibodyResult":
        """Lay out the step loop's :class:`~bearingsim.multibody.core.MultibodyRaw` as a result."""
        w = raw.win
        per = {name: w[field].copy() for name, field in (
            ("I_acc", "I_acc"), ("I_dec", "I_dec"), ("Jn_front", "Jn_front"), ("Jn_rear", "Jn_rear"),
            ("Jf_front", "Jf_front"), ("Jf_rear", "Jf_rear"), ("slide_work_front", "work_front"),
            ("slide_work_rear", "work_rear"))}
        summary, units = _summary(p, raw, per)
        data = {**_per_rotation_arrays(per, raw.first_imp, raw.land),
                **_rest_per_rotation(raw.rest_win, p.operating.sign),
                **_rotation_arrays(p, raw.setup, raw.rot_win), **_theta_arrays(raw),
                **_impact_arrays(raw.impacts), **_wear_arrays(p, per),
                **_profile_arrays(raw.prof, p.multibody.pocket_face_extent)}
        orbit = raw.orbit
        data["results/cage_orbit"] = NamedArray(orbit[np.isfinite(orbit[:, 0])], "s, m, m",
                                                "last recorded samples of the cage centre: columns time, x, y")
        groups = {"results/summary": AttrGroup({**summary, "scene": raw.setup.scene,
                                                "pockets": p.bearing.roller_count}, {**units, "pockets": "1"})}
        tables = {"results/impacts": f"roller-cage impacts (approach speed > {IMPACT_SPEED_THRESHOLD_M_S} m/s) in the "
                                     "recorded rotations; face 'rear' or 'front'; impulse = normal impulse; theta of the "
                                     "pocket centre; rotation = row of /results/per_rotation the impact counts in"
                                     + ("; the table filled up: its first rows only (provenance impacts_table_full)"
                                        if raw.impacts_dropped else "")}
        res = cls(None, data, groups, provenance=_provenance(raw), tables=tables, raw=raw)
        res._parameters = p
        return res

    def description(self) -> str:
        scene = self.groups["results/summary"].attrs.get("scene", "?")
        return f"multibody, {scene} scene"

    # --- figures -----------------------------------------------------------------------------
    def _rotations(self) -> int:
        return self.per_rotation["I_dec"].shape[0]

    def plot_forces(self):
        """Fig. 5 analog: mean circumferential pocket force against θ, pocket 0 and the mean over pockets; F_acc
        in the front face's colour, F_dec in the rear face's."""
        from bearingsim.plotting import FRONT, REAR, legend_outside, subplots

        th = self.get("theta_deg")
        fa, fd = self.get("force_vs_theta_acc"), self.get("force_vs_theta_dec")
        fig, ax = subplots(figsize=(9, 4))
        ax.plot(th, fa[:, 0], lw=0.8, color=FRONT, label="$F_{acc}$ (front face), pocket 0")
        ax.plot(th, -fd[:, 0], lw=0.8, color=REAR, label="$-F_{dec}$ (rear face), pocket 0")
        ax.plot(th, fa.mean(axis=1), lw=1.5, color=FRONT, ls="--", label="$F_{acc}$, mean over pockets")
        ax.plot(th, -fd.mean(axis=1), lw=1.5, color=REAR, ls="--", label="$-F_{dec}$, mean over pockets")
        phi = self.summary["load_zone_half_angle_deg"]
        ax.axvline(phi, color="grey", lw=0.8, ls=":", label=f"load-zone limits ±{phi:.1f}°")
        ax.axvline(360 - phi, color="grey", lw=0.8, ls=":")
        ax.axvline(180.0, color="0.6", lw=0.6, ls="-.", label="θ = 180° (top)")
        ax.axhline(0.0, color="0.3", lw=0.5)
        ax.set_xlabel("θ from the load-zone centre, in the direction of rotation [deg]")
        ax.set_ylabel("mean circumferential pocket force [N]")
        ax.set_xlim(0, 360)
        ax.set_title(f"{self.title()}\npocket force against θ over {self._rotations()} cage rotations", fontsize=9)
        legend_outside(ax)
        return fig

    def plot_impulses(self):
        """Fig. 7 analog: I_acc (front face's colour, circles) and I_dec (rear face's, squares) per pocket, the mean
        over rotations with bars of their standard deviation (the pocket's own scatter), and the bearing's mean ±
        its standard error (the run's headline, as ``bearingsim run`` prints it) as a line and band."""
        from bearingsim.plotting import FRONT, REAR, legend_outside, subplots
        from bearingsim.stats import result_standard_errors, with_error
        from bearingsim.wording import counted

        n = self._rotations()
        se = result_standard_errors(self)
        x = np.arange(self.per_rotation["I_acc"].shape[1])
        fig, ax = subplots(figsize=(11.5, 4))  # room for the legend's headline numbers
        for q, dx, fmt, face, colour in (("I_acc", -0.12, "o", "front", FRONT), ("I_dec", 0.12, "s", "rear", REAR)):
            v = self.per_rotation[q]
            ax.errorbar(x + dx, v.mean(0) * 1e3, yerr=v.std(0) * 1e3 if n > 1 else None, fmt=fmt, color=colour,
                        label=f"$I_{{{q[2:]}}}$ ({face} face), per pocket")
            mean, sem = self.summary[f"{q}_mean_Ns"] * 1e3, se[f"{q}_sem_Ns"] * 1e3
            if sem > 0.0:
                ax.axhspan(mean - sem, mean + sem, color=colour, alpha=0.15, lw=0.0)
            headline = (f"{with_error(mean, sem)} mN s (±1 standard error)" if sem > 0.0 else
                        f"{mean:.5g} mN s (no standard error from {counted(n, 'recorded rotation')})")
            ax.axhline(mean, color=colour, lw=1.0, ls="--", label=f"$I_{{{q[2:]}}}$ mean of the bearing {headline}")
        ax.set_xlabel("pocket")
        ax.set_xticks(x)
        ax.set_ylabel("impulse per cage rotation [mN s]")
        ax.set_ylim(bottom=0.0)
        spread = (f"per pocket: mean, bars: std over the {n} cage rotations of each pocket" if n > 1
                  else "1 cage rotation: no spread (no bars, no standard error)")
        ax.set_title(f"{self.title()}\n{spread}; lines: the bearing's mean"
                     + ("; bands: its standard error (batch means)" if n > 1 else ""), fontsize=9)
        legend_outside(ax)
        return fig

    def plot_orbit(self):
        """Cage-centre orbit (last recorded samples), with the bearing axis and the reach of the faces."""
        from bearingsim.plotting import legend_outside, subplots

        o = self.get("cage_orbit")
        fig, ax = subplots(figsize=(6.5, 5))
        ax.plot(o[:, 1] * 1e6, o[:, 2] * 1e6, lw=0.6, label="cage centre")
        ax.plot([0.0], [0.0], "k+", ms=12, label="bearing axis")
        p = self.parameters
        reach = face_radial_reach(p)
        circ = np.linspace(0.0, 2.0 * math.pi, 361)
        r_max = float(np.max(np.hypot(o[:, 1], o[:, 2]))) if len(o) else 0.0
        if r_max > 0.0:
            ax.plot(r_max * 1e6 * np.cos(circ), r_max * 1e6 * np.sin(circ), color="0.5", lw=0.6, ls=":",
                    label=f"largest distance from the axis ({r_max * 1e6:.0f} µm)")
        if reach <= 3.0 * r_max or r_max == 0.0:
            ax.plot(reach * 1e6 * np.cos(circ), reach * 1e6 * np.sin(circ), color="C3", lw=0.8, ls="--",
                    label=f"reach of the pocket faces ({reach * 1e6:.0f} µm)")
        else:  # far outside the orbit: named, not drawn (it would shrink the orbit to a dot)
            ax.plot([], [], " ", label=f"reach of the pocket faces: {reach * 1e6:.0f} µm (off scale)")
        if p.bearing.cage_guidance != "rollers":
            half = 0.5 * p.bearing.cage_land_clearance
            ax.plot(half * 1e6 * np.cos(circ), half * 1e6 * np.sin(circ), color="C2", lw=0.8, ls="-.",
                    label=f"half the land clearance ({half * 1e6:.0f} µm, {p.bearing.cage_guidance.replace('_', ' ')})")
        ax.set_aspect("equal")
        ax.set_xlabel("cage centre x [µm]")
        ax.set_ylabel("cage centre y [µm] (load along −y)")
        ax.set_title(f"{self.title()}\ncage-centre orbit, last {len(o)} samples", fontsize=9)
        legend_outside(ax)
        return fig

    def _index_impulse(self, face: str) -> str:
        """Which impulse the archive's paper index of ``face`` was computed from, as its dataset's description
        says: the normal impulse (model version 7 on), or before it the circumferential I_acc / I_dec."""
        desc = getattr(self.data.get(f"results/wear/paper_index_{face}"), "description", "") or ""
        q = "I_acc" if face == "front" else "I_dec"
        return f"circumferential impulse {q}" if f"k {q} " in desc else "normal impulse"

    def plot_wear(self):
        """Fig. 14 analog: Archard wear rate per pocket face, from the paper's index and the sliding work; each
        face in its colour, the sliding work's bars hatched."""
        from bearingsim.plotting import FRONT, REAR, fixed_unit_axis, legend_outside, subplots
        from bearingsim.wear import running_time

        # cage rotations per hour at the run's measured cage speed, as `bearingsim wear`; m^3 -> mm^3 (the text's)
        per_hour = running_time(self, hours=1.0)[2] * 1e9
        x = np.arange(self.per_rotation["I_dec"].shape[1])
        fig, ax = subplots(figsize=(9, 4))
        colour = {"front": FRONT, "rear": REAR}
        bars = [(self.get(f"wear/paper_index_{f}"), f"{f} face, impulse index (Eq. 16, {self._index_impulse(f)})",
                 colour[f], None) for f in ("front", "rear")]
        bars += [(self.get(f"wear/sliding_work_{f}"), f"{f} face, sliding work", colour[f], "////")
                 for f in ("front", "rear")]
        wdt = 0.2
        for j, (v, label, c, hatch) in enumerate(bars):  # a hatch is drawn in the bar's edge colour: white
            ax.bar(x + (j - 1.5) * wdt, v * per_hour, wdt, label=label, color=c, hatch=hatch,
                   edgecolor="white" if hatch else None, linewidth=0)
        ax.set_xlabel("pocket")
        ax.set_xticks(x)
        ax.set_ylabel("Archard wear volume\n[mm³ per hour]")  # one unit for every run: figures compare as they are
        fixed_unit_axis(ax)
        ax.set_title(f"{self.title()}\nwear of the pocket faces at this speed (k = {self.parameters.wear.wear_coefficient:g}, "
                     f"H = {self.parameters.wear.hardness / 1e9:g} GPa)", fontsize=9)
        legend_outside(ax)
        return fig
    def wear_report(self, *, hours=None, rotations=None):
        """Worn depth profile and volume of every face after ``hours`` or inner-ring ``rotations``
        (:func:`bearingsim.wear.wear_report`)."""
        from bearingsim.wear import wear_report

        return wear_report(self, hours=hours, rotations=rotations)

    def plot_wear_profile(self, *, hours=None, rotations=None):
        """Fig. 13 analog: worn depth against the position on the face (psi), front and rear, the mean over
        pockets and their spread, after ``hours`` or inner-ring ``rotations`` (default one hour)."""
        from bearingsim.wear import plot_wear_profile

        if hours is None and rotations is None:
            hours = 1.0
        return plot_wear_profile(self.wear_report(hours=hours, rotations=rotations), self.title())

    def plot_wear_volume(self, *, hours=None, rotations=None):
        """Fig. 14 analog: worn volume per pocket, front and rear, with the spread over pockets."""
        from bearingsim.wear import plot_wear_volume

        if hours is None and rotations is None:
            hours = 1.0
        return plot_wear_volume(self.wear_report(hours=hours, rotations=rotations), self.title())


RESULT = MultibodyResult
