"""Plausibility of a finished run, checked before anything is written.

A run that finishes with non-finite numbers, an inner ring displaced further than the contact law
allows for its load, or too few time-series samples is not a result: :func:`check` raises
:class:`bearingsim.errors.SimulationUnstable` (exit 3) with advice naming the key to change, and the
caller writes no archive.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from bearingsim import laws
from bearingsim.errors import SimulationUnstable
from bearingsim.stats import SUMMARY_SEM_OF, t_quantile
from bearingsim.wording import counted, given_step

# The mean inner-ring displacement along the load is at most half the diametral clearance plus the
# approach at the inner and the outer race of a roller that carries the whole load alone; twice that
# bound leaves room for vibration about the mean. A larger displacement means the ring has left the
# rollers (a blown-up or unloaded ring), not a result.
DISPLACEMENT_MARGIN = 2.0
# Fewest recorded samples of the cage orbit that make a figure and a mean of it.
MIN_ORBIT_SAMPLES = 2
# What the note of a few steps in which the quasi-static ring's force balance did not converge says
# (more than multibody.core.MAX_NEWTON_FAILURE_FRACTION of the steps are refused). Newton's iteration
# cycles across a kink of the contact law (a roller entering the load zone, its damping fading in; an
# opening contact in a run's first two steps); forces.solve_ring_centre then solves the step again with
# Armijo-halved steps and, where that stalls, by bracketing, and only a step all of them fail keeps the
# last iterate for its raceway forces. Measured: 0 such steps in multibody_3000rpm, multibody_6000rpm and
# multibody_1000rpm (Newton alone failed in 14, 193 and 9).
NEWTON_NOTE = ("bearingsim: note: the inner ring's force balance did not converge in {fails} of {steps} steps "
               "({share:.2%}; refused above 1%): those isolated steps kept the solve's last iterate for their raceway "
               "forces (provenance ring_newton_failures, docs/archive.md)")
# A statistically steady multibody run: the cage speed fluctuates about its mean (roller impacts move
# it by < 1 % at 3000 rpm), it does not drift. A change from the start to the end of the recorded
# rotations of more than this fraction of the mean cage speed is a trend (a cage still accelerating
# or decelerating): the run's means describe a transient, which a note says. Measured: every
# scenarios/hard/multibody_* case but the unloaded one, and 500-6000 rpm runs with rigid raceways,
# drift by at most 0.8 %; the unloaded bearing's cage coasts down by 4.7 % in one recorded rotation
# and 9.5 % in two (a bound of 20 % let that pass without a note).
MAX_CAGE_SPEED_DRIFT = 0.03
# The start of a multibody run: the cage starts centred on the axis and settles onto its rollers (or its
# land) during the warm-up rotations. One warm-up rotation leaves the next ones off the steady state at
# some speeds (on the reference bearing the first recorded rotation is +10 % at 3000 rpm and the first
# four swing by up to 2.6 % at 1000 rpm; docs/statistics.md). The first recorded rotation's pocket-mean I_dec
# x1 is judged as one new observation against the m later ones (mean, sd): t = (x1 - mean) / (sd sqrt(1 + 1/m))
# is Student's t with m - 1 degrees of freedom when x1 scatters as they do, so |t| beyond its
# 1 - START_TRANSIENT_FALSE_ALARM / 2 quantile (and an offset above START_TRANSIENT_MIN_REL of the mean) gets a
# note in at most START_TRANSIENT_FALSE_ALARM of transient-free runs at every rotation count. (The rule before, 3 sd of
# the later ones, claimed 0.3 % and flagged 12 % of transient-free runs at 4 rotations, 2.2 % at 10.) With
# few rotations the test has little power. Measured (3000 rpm, 1 warm-up rotation, 20 runs of load 970 + 0.01 k N
# each): the first recorded rotation reads +8.9 % (Hertz raceways, the default) and +9.9 % (rigid) on average,
# the later rotations' sd is about 1.5 % of their mean (median), and the rule flags, Hertz: 5 of 20 runs at
# 5 rotations, 13 at 6; rigid: 4 of 20 at 4, 12 at 5, 18 at 6, 19 at 7; with 3 warm-up rotations (rigid) it
# flags none of 20 at 5 and none at 7. So from START_TRANSIENT_MIN_ROTATIONS = 6 on it sees that transient in
# more than half of the runs with either raceway model; below, the warm-up is not judged (a note says so:
# warmup_not_judged, with the transient's size).
START_TRANSIENT_FALSE_ALARM = 0.01
START_TRANSIENT_MIN_REL = 0.01
START_TRANSIENT_MIN_ROTATIONS = 6

# Where the cage rests (its centre's mean position in each recorded rotation, as an angle from the bottom:
# /results/per_rotation/cage_rest_angle) stays within about 12 degrees in a steady run: at most 8.3 deg over
# the runs measured at 970 N (3000 and 6000 rpm for 20 rotations, 500 and 1000 rpm, both land guidances, rigid
# raceways, pocket clearances 0.1 and 0.4 mm, the rig), 10.2 and 11.3 deg at 12 and 10 kN (3000 rpm, 20
# rotations; docs/whatif.md, Radial load), and of the scenarios/hard multibody cases restitution 0.99 spans
# 11.8 deg over 4 rotations. Under load a roller-guided cage can take a second
# resting place (docs/whatif.md, Radial load): a 14 kN run at 3000 rpm that changes place among its recorded
# rotations spans 51 deg, the 20000 rpm and 3-roller hard cases 94 and 32 deg. A span beyond
# CAGE_REST_SPAN_DEG gets a note: the run's means mix the places it rested in. Not judged where the cage's
# mean position lies within CAGE_REST_MIN_OFFSET of the pocket clearance of the axis in some rotation (a
# centred or kinematic cage, a whirling one: the angle of a point at the axis says nothing).
CAGE_REST_SPAN_DEG = 20.0
CAGE_REST_MIN_OFFSET = 0.25
# The pockets of a multibody run are identical in geometry, but the cage's motion can lock into a pattern that
# loads them unevenly (docs/wear.md, Uneven pockets: a light cage at 6000 rpm whirls at 4 times its rotation
# frequency, phase-locked to it, and the pockets' wear repeats every 4 pockets, the front faces' coefficient of
# variation 0.437 where identical pockets would show 0.015). Each face's sliding work per pocket (what Archard's
# law wears, the coefficient of variation ``bearingsim wear`` prints beside the one identical pockets would show:
# bearingsim.stats.pocket_cov, pocket_sampling_cov) is tested for equal pocket means (an F test,
# bearingsim.stats.pocket_spread_critical) at half of POCKET_SPREAD_FALSE_ALARM, so that runs of identical pockets
# get the note in at most that share, both faces together, when the scatter is normal (0.045-0.13 % of 20 000
# simulated runs); the reference runs' own arrays, pockets renumbered at random per rotation, got it in 0 to 0.62 %
# (the impulses' tails). Measured: the reference runs read ratios 0.69 to 1.17
# (multibody_6000rpm, 3000rpm, 1000rpm at their default rotations) against critical ratios 1.86 to 2.96.
POCKET_SPREAD_FALSE_ALARM = 0.001
# The least coefficient of variation over pockets the note of uneven pockets names: below it the pockets are even
# whatever the scatter says. A scene whose rotations repeat (the kinematic cage on Hertz raceways, settled) has a
# rotation-to-rotation scatter near round-off, and its pockets differ by the time grid's phase alone (about 1e-6 of
# the mean: multibody_6000rpm, scene kinematic_cage, 2 warm-up + 10 rotations), which the F test alone calls uneven.
POCKET_SPREAD_MIN_COV = 0.001
# A mean cage speed above this multiple of the epicyclic speed (Eq. 11; a roller-guided cage slips
# behind it, never ahead by much) is a cage driven by something other than rolling: the advice for too
# few samples then names the traction and drag keys, not the output rate.
OVERSPEED_FACTOR = 1.5


def palmgren_approach_m(load_N: float, roller_length_m: float) -> float:
    """Approach [m] of one roller pressed on one raceway with ``load_N`` [N]: Palmgren's line contact
    ``Q = K delta^(10/9)`` (:func:`bearingsim.laws.palmgren_stiffness`; Harris & Kotzalas Eq. 6.40 writes
    the same law as delta = 3.84e-5 Q^0.9 / l^0.8 in mm)."""
    return laws.palmgren_approach(load_N, roller_length_m)


def max_ring_displacement_m(p) -> float:
    """Largest plausible mean inner-ring displacement [m] for the load of the SI parameters ``p``."""
    # the ring's load is the radial load alone, whatever its mass: a dynamic ring is driven by -W and the roller
    # reactions (multibody.forces.raceway_forces), its weight counted in W, not added to it; the rollers' centrifugal
    # loads press them into the outer race, which leaves the ring that approach as play too (the whole bound
    # without clearance and load)
    g = p.bearing
    centrifugal = g.roller_mass * g.pitch_radius * p.operating.omega_c ** 2
    bound = (0.5 * g.radial_clearance
             + 2.0 * palmgren_approach_m(p.operating.radial_load, g.roller_length)
             + palmgren_approach_m(centrifugal, g.roller_length))
    return DISPLACEMENT_MARGIN * bound


def _nonfinite(summary: dict) -> list[str]:
    bad = []
    for k, v in summary.items():
        if isinstance(v, (bool, np.bool_, str)):
            continue
        try:
            if not math.isfinite(float(v)):
                bad.append(k)
        except (TypeError, ValueError):
            continue
    return bad


def check(result) -> list[str]:
    """Raise :class:`SimulationUnstable` if ``result`` (:class:`bearingsim.results.Result`) is not a
    plausible run of its parameters.

    Returns
    -------
    list of str
        One-line notes for the user about a run that is plausible but not clean.
    """
    notes = []
    p = result.parameters
    summary = dict(result.summary)
    if getattr(result, "scenario", None) is not None:
        from bearingsim.scenario import out_of_range_note

        note = out_of_range_note(result.scenario)
        if note:
            notes.append(note)
    bad = _nonfinite(summary)
    no_impact = {"first_impact_speed_m_s", "first_impact_energy_J"}
    if p.model == "multibody" and bad and set(bad) <= no_impact:
        # NaN is defined there: no rear-face impact above the impact threshold in any no-load pass
        notes.append("bearingsim: note: no rear-face impact was recorded in the no-load zone; "
                     "first_impact_speed_m_s and first_impact_energy_J are NaN (none)")
        bad = []
    # the reduced model's pass, as the reduced-equivalent scene runs it in every pocket: a pass in which no
    # roller touches a face leaves that scene's torque balance without a scale (I_acc = I_dec = 0) too
    one_pass = p.model == "reduced" or (p.multibody.scene == "reduced_equivalent" and _untouched(result))
    no_pass_impact = one_pass and set(bad) <= no_impact | {"torque_balance_residual"}
    if bad:
        if (no_pass_impact
                and p.contact.drag_coefficient == 0.0 and p.operating.gravity == 0.0):
            # Eq. 1 with F_o = 0 and g = 0: nothing moves the roller off the front face it starts on, at
            # any half angle, so naming the pass's length would send the user after the wrong key
            advice = ("the no-load pass has no rear-face impact; with lubrication.drag_coefficient = 0 and "
                      "operating.gravity = false no force acts on the roller in its pocket (Eq. 1), so it stays "
                      "on the front face it starts on: give the drag coefficient a value or switch gravity on")
        elif no_pass_impact:
            advice = ("the no-load pass has no rear-face impact; reduced.load_zone_half_angle_deg "
                      f"= {summary.get('load_zone_half_angle_deg', float('nan')):.4g} deg leaves too short a pass")
        else:
            advice = _advice(result)
        raise SimulationUnstable(f"non-finite result ({', '.join(sorted(bad))}); {advice}")
    for name in ("I_dec", "I_acc"):
        arr = np.asarray(result.per_rotation.get(name, np.zeros(0)))
        if arr.size and not np.all(np.isfinite(arr)):
            raise SimulationUnstable(f"non-finite {name} per rotation; {_advice(result)}")
    if p.model == "reduced":
        notes += [n for n in (_lift_off_note(p), _no_load_zone_note(p)) if n is not None]
    if p.model == "multibody":
        disp = abs(float(summary.get("inner_ring_displacement_m", 0.0)))
        limit = max_ring_displacement_m(p)
        if disp > limit:
            raise SimulationUnstable(
                f"inner ring displaced {disp:.3g} m, more than the {limit:.3g} m the Palmgren contact law allows "
                f"for this load and clearance; {_advice(result)}")
        for note in (_unloaded_ring_note(result), _no_classical_load_zone_note(result), _pinched_note(result),
                     land_overlap_note(result), land_untouched_note(result), _rigid_kinematic_note(result),
                     _traction_step_note(result)):
            if note is not None:
                notes.append(note)
        orbit = result.get("cage_orbit")
        samples = int(np.sum(np.isfinite(orbit[:, 0]))) if np.ndim(orbit) == 2 else 0
        if samples < MIN_ORBIT_SAMPLES:
            raise SimulationUnstable(f"{counted(samples, 'time-series sample')} recorded; {_few_samples_advice(result)}")
        for note in (cage_speed_drift(result), start_transient(result), warmup_not_judged(result),
                     cage_rest_change(result), impact_table_note(result), uneven_pockets(result)):
            if note is not None:
                notes.append(note)
        fails = int(result.provenance.get("ring_newton_failures", 0) or 0)
        steps = int(summary.get("steps", 0) or 0)
        if fails and steps:
            from bearingsim.multibody.core import MAX_NEWTON_FAILURE_FRACTION, newton_refusal

            if fails > MAX_NEWTON_FAILURE_FRACTION * steps:
                raise SimulationUnstable(newton_refusal(p, fails, steps))
            notes.append(NEWTON_NOTE.format(fails=fails, steps=steps, share=fails / steps))
    return notes


def _untouched(result) -> bool:
    """True if no pocket face carried any impulse over the recorded rotations (I_acc and I_dec all 0)."""
    arrays = [np.asarray(result.per_rotation.get(name, np.zeros(0))) for name in ("I_dec", "I_acc")]
    return all(a.size and np.all(a == 0.0) for a in arrays)


def land_untouched_note(result) -> str | None:
    """The note of a land-guided cage that never touched its land over the recorded rotations (summary
    ``land_normal_impulse_mean_Ns`` 0): its rollers held it within half its land clearance, so the run is a
    roller-guided cage's, its numbers those of ``bearing.cage_guidance = "rollers"`` (docs/whatif.md: from a land
    clearance of about 0.40 mm up on the reference bearing)."""
    p = result.parameters
    impulse = result.summary.get("land_normal_impulse_mean_Ns")
    if impulse is None or impulse != 0.0 or p.bearing.cage_guidance == "rollers" or not p.bearing.cage_land_clearance:
        return None
    half = 0.5 * p.bearing.cage_land_clearance
    offset = result.summary.get("cage_rest_offset_m")
    held = f", {offset * 1e6:.3g} um off the axis" if offset is not None and math.isfinite(offset) else ""
    return (f"bearingsim: note: the cage never touched its {p.bearing.cage_guidance.replace('_', ' ')} over the "
            f"recorded rotations (land_normal_impulse_mean_Ns = 0): its rollers held it{held}, within half its land "
            f"clearance ({half * 1e6:.3g} um, bearing.cage_land_clearance_mm = {p.bearing.cage_land_clearance * 1e3:g}), "
            f"so the run is a roller-guided cage's; a smaller land clearance guides it on its land (docs/whatif.md)")


def land_overlap_note(result) -> str | None:
    """The note of a land-guided cage whose rim went further into its land than the design bound,
    ``LAND_OVERLAP_FRACTION`` of c_L/2: the penalty stiffness keeps that bound under the steady reference force
    only, and an impact on the land goes beyond it (docs/stability.md, *Land-guided cage*)."""
    from bearingsim.multibody.core import LAND_OVERLAP_FRACTION

    p = result.parameters
    overlap = result.summary.get("land_overlap_max_m")
    if overlap is None or p.bearing.cage_guidance == "rollers" or not p.bearing.cage_land_clearance:
        return None
    half = 0.5 * p.bearing.cage_land_clearance
    if not overlap > LAND_OVERLAP_FRACTION * half:
        return None
    inner = p.bearing.cage_guidance == "inner_land"
    cause = ("a quasi-static inner ring's centre can jump between steps and carry its land into the cage "
             "(multibody.inner_ring = dynamic has no such jumps), or the cage hit the land in the start's fall"
             if inner else "the cage hit the land, as in the start's fall at a small radial load")
    return (f"bearingsim: note: the cage rim overlapped its {p.bearing.cage_guidance.replace('_', ' ')} by "
            f"{overlap * 1e6:.3g} um, {overlap / half * 100:.2g} % of half the land clearance, beyond the "
            f"{LAND_OVERLAP_FRACTION * 100:g} % its penalty stiffness holds under a steady force "
            f"(summary land_overlap_max_m; docs/stability.md, Land-guided cage): an impact on the land; {cause}")


def pocket_spread(result) -> list[tuple[str, float, float, float, np.ndarray]]:
    """Per face (front, rear) of a multibody result whose pockets are identical in geometry: ``(face, cov,
    sampling cov, critical ratio, pocket means)`` of the per-rotation sliding work ``slide_work_<face>``
    (:func:`bearingsim.stats.pocket_cov`, :func:`bearingsim.stats.pocket_sampling_cov`, and the ratio of the two
    that identical pockets exceed in half of :data:`POCKET_SPREAD_FALSE_ALARM` of runs); [] when it cannot be
    judged: another model, the ``reduced_equivalent`` scene (its rotations repeat), pockets of different shapes
    or starting depths (``flat_pockets``, ``[wear] worn_depth_*``), no sliding work recorded, fewer than 2
    rotations or no scatter."""
    p = result.parameters
    if p.model != "multibody" or p.multibody.scene == "reduced_equivalent" or not _same_pockets(p):
        return []
    out = []
    for face in ("front", "rear"):
        arr = np.asarray(result.per_rotation.get(f"slide_work_{face}", np.zeros((0, 0))), dtype=float)
        if arr.ndim != 2 or arr.shape[0] < 2 or arr.shape[1] < 2 or not np.all(np.isfinite(arr)):
            continue
        cov, sampling, crit = face_spread(arr)
        if sampling > 0.0:
            out.append((face, cov, sampling, crit, arr.mean(axis=0)))
    return out


def face_spread(per_rotation) -> tuple[float, float, float]:
    """The test of equal pocket means of one face's ``[rotations, pockets]`` array: ``(cov, sampling cov,
    critical ratio)`` (:func:`bearingsim.stats.pocket_cov` of the pockets' means,
    :func:`bearingsim.stats.pocket_sampling_cov`, and the ratio of the two that identical pockets exceed in half of
    :data:`POCKET_SPREAD_FALSE_ALARM` of runs); the pockets differ when ``cov > critical ratio * sampling cov``.
    A run's note of uneven pockets (:func:`pocket_spread`) and a life study's stages judge by it."""
    from bearingsim.stats import pocket_cov, pocket_sampling_cov, pocket_spread_critical

    v = np.asarray(per_rotation, dtype=float)
    crit = pocket_spread_critical(v.shape[1], v.shape[0], POCKET_SPREAD_FALSE_ALARM / 2.0)
    return pocket_cov(v.mean(axis=0)), pocket_sampling_cov(v), crit


def _same_pockets(p) -> bool:
    """Whether every pocket of the SI parameters ``p`` has one shape and one starting depth."""
    flat = len(p.multibody.flat_pockets)
    if flat not in (0, p.bearing.roller_count):
        return False
    depth = p.wear.worn_depth
    return depth is None or bool(np.all(np.asarray(depth, dtype=float) == np.asarray(depth, dtype=float)[0]))


def uneven_pockets(result) -> str | None:
    """A note when a face's pockets wore (slid) unevenly beyond what the rotations' scatter allows
    (:func:`pocket_spread`) and by at least :data:`POCKET_SPREAD_MIN_COV`, naming its coefficient of variation, the one identical pockets would show, and the
    most and least worn pockets; else None."""
    parts = []
    for face, cov, sampling, crit, means in pocket_spread(result):
        if not (cov > crit * sampling and cov >= POCKET_SPREAD_MIN_COV):
            continue
        hi, lo = int(np.argmax(means)), int(np.argmin(means))
        parts.append(f"{face} faces {cov:.3f} where identical pockets would show {sampling:.3f} (the bound is "
                     f"{crit:.2f} times that), most worn pocket {hi} ({means[hi] / means.mean():.2f} x the mean), "
                     f"least pocket {lo} ({means[lo] / means.mean():.2f} x)")
    if not parts:
        return None
    return (f"bearingsim: note: uneven pockets: the coefficient of variation over pockets of the sliding work "
            f"(what wears) is {'; '.join(parts)}; pockets of equal load and normal scatter exceed the bound in "
            f"{POCKET_SPREAD_FALSE_ALARM:.1%} of runs. The cage's motion locked into a pattern that loads the "
            f"pockets unevenly, which the means hide: the faces wear unevenly and a life's clearance limit follows "
            f"the worst pocket ('bearingsim wear' gives each pocket's; docs/wear.md, Uneven pockets)")


def impact_table_note(result) -> str | None:
    """The note of a run whose impact table filled its rows (:attr:`bearingsim.results.Result.impacts_end_s`):
    up to when it lists impacts. The impulses, wear and every other result are summed in the step loop, not from
    the table, and count every impact."""
    t = result.impacts_end_s
    if t is None:
        return None
    imp = result.impacts
    rows, rotations = len(imp["time_s"]), int(result.parameters.numerics.rotations)
    when = f" in recorded rotation {int(imp['rotation'][-1]) + 1} of {rotations} (t = {t:.4g} s)"
    return (f"bearingsim: note: the impact table filled its {rows} rows{when}: /results/impacts lists the impacts "
            "up to there only; the impulses, wear and every other result count every impact")


def _lift_off_note(p) -> str | None:
    """The reduced model's roller stays on the pitch circle (its Eq. 1). Below the speed where the centrifugal
    force m r_p omega_c^2 no longer outweighs gravity, N of Eq. 3 turns negative around the top: the roller
    leaves the outer race there, which the model does not follow (it only drops F_o where N <= 0)."""
    op, g = p.operating, p.operating.gravity
    centripetal = p.bearing.pitch_radius * op.omega_c ** 2
    if g <= 0.0 or centripetal >= g:
        return None
    arc = 2.0 * math.degrees(math.pi - math.acos(-centripetal / g))
    least = op.inner_ring_speed_rpm * math.sqrt(g / centripetal)
    return (f"bearingsim: note: at {op.inner_ring_speed_rpm:g} rpm the roller's centrifugal acceleration "
            f"r_p omega_c^2 = {centripetal:.3g} m/s^2 is less than g: over {arc:.0f} deg around the top N <= 0 "
            "(Eq. 3) and the roller leaves the outer race, which the reduced model does not follow (it keeps the "
            f"roller on the pitch circle, without drag there); its numbers hold from {least:.0f} rpm up "
            "(docs/physics.md); model = \"multibody\" follows the roller off the race")


def _no_load_zone_note(p) -> str | None:
    """With the load zone the load gives ("auto") and no radial load there is no load zone: the reduced
    model still turns its cage at the epicyclic speed (Eq. 11), which nothing drives without load."""
    if p.reduced.load_zone_half_angle > 0.0:
        return None
    return ("bearingsim: note: the load zone is 0 deg (no radial load on it): the reduced model still turns the "
            "cage at the epicyclic speed (Eq. 11), which no loaded roller drives; the whole bearing "
            "(model = \"multibody\") shows the cage slowing without load")


def _unloaded_ring_note(result) -> str | None:
    """Without radial load nothing acts on the inner ring (the load W is the only force on it, quasi-static
    or dynamic): any place in the radial clearance where no roller touches it balances, so the displacement
    the run reports is where it was started and drifted to, not a result."""
    p = result.parameters
    if p.operating.radial_load > 0.0 or str(result.provenance.get("inner_ring", "none")).startswith("none"):
        return None
    disp = abs(float(result.summary.get("inner_ring_displacement_m", 0.0)))
    # the classical half angle is arccos(P_d / 2 delta_r) of that drift: without clearance 90 deg for any drift
    phi = float(result.summary.get("load_zone_half_angle_deg", 0.0))
    also = (f", nor load_zone_half_angle_deg = {phi:.4g} (arccos(P_d / 2 delta_r) of it; no roller carries a load)"
            if phi != 0.0 else "")
    return (f"bearingsim: note: operating.radial_load_N = 0: no force places the inner ring within the radial "
            f"clearance, so inner_ring_displacement_m = {disp:.3g} m is where the run started it (P_d/2 = "
            f"{0.5 * p.bearing.radial_clearance:.3g} m) and let it drift, not a result{also}; a radial load as small as "
            "the rotor's weight places it")


def _no_classical_load_zone_note(result) -> str | None:
    """The classical half angle arccos(P_d / 2 delta_r) is 0 ("no roller loaded") when the ring's mean
    displacement along the load is at most P_d/2. Under load that happens when the ring does not rest in a
    load zone but rides from roller to roller (a dynamic ring on few rollers: 3 rollers at 970 N, 24.6 um
    against 40 um), while the inner race carried load: the 0 is no result, which the note says. The contact
    half angle is 0 when the theta bin just before the load-zone centre carried under 1 % of the largest mean
    load (:func:`_inner_race_load_text`): under load that 0 is no result either, and the note says so too."""
    p = result.parameters
    summary = result.summary
    if p.operating.radial_load <= 0.0 or "inner_ring_displacement_m" not in summary:
        return None
    phi = float(summary.get("load_zone_half_angle_deg", float("nan")))
    contact = float(summary.get("load_zone_contact_half_angle_deg", float("nan")))
    loaded = _inner_race_load_text(result) if contact == 0.0 else None
    if loaded is not None:
        zero = "load_zone_contact_half_angle_deg = 0 is no result"
        if phi != 0.0:
            return f"bearingsim: note: {zero}: the inner race carried load {loaded}"
        carried = f"{loaded}; {zero} either"
    elif phi == 0.0 and contact > 0.0:
        carried = f"over +-{contact:.3g} deg (load_zone_contact_half_angle_deg)"
    else:
        return None
    disp = float(summary["inner_ring_displacement_m"])
    return (f"bearingsim: note: load_zone_half_angle_deg = 0 is no result: the inner ring's mean displacement "
            f"along the load, {disp * 1e6:.3g} um, is not more than half the radial clearance "
            f"({0.5 * p.bearing.radial_clearance * 1e6:.3g} um), so arccos(P_d / 2 delta_r) finds no roller loaded, "
            f"while the inner race carried load {carried}: the "
            f"ring ({str(result.provenance.get('inner_ring', '?')).split(';')[0]}) did not rest in a load zone")


def _inner_race_load_text(result) -> str | None:
    """Where the inner race carried load, when it did (``/results/raceway_load_inner`` above 1 % of its maximum
    in some theta bin) but not in the bin just before theta = 0, where the contact half angle's loaded range
    starts (:func:`bearingsim.multibody._load_zone_half_angle`), which is then 0; else None."""
    arr = getattr(result, "data", {}).get("results/raceway_load_inner")
    q = np.asarray(arr.data, float) if arr is not None else np.zeros(0)
    if q.size == 0 or not q.max() > 0.0 or q[-1] > 0.01 * q.max():
        return None
    return (f"in {np.count_nonzero(q > 0.01 * q.max())} of {q.size} theta bins (/results/raceway_load_inner above "
            f"1 % of its maximum, {q.max():.4g} N) but not in the bin just before the load-zone centre "
            f"({-360.0 / q.size:g} to 0 deg: {q[-1]:.3g} N), where the contact half angle's loaded range starts")


def _rigid_kinematic_note(result) -> str | None:
    """Rigid raceways in the kinematic-cage scene: its step is far from converged there (docs/fast_scene.md,
    The kinematic cage: +18 % and +13 % per halving at 3000 rpm), where the Hertz raceways' divided step is."""
    from bearingsim.multibody.core import rigid

    p = result.parameters
    if p.multibody.scene != "kinematic_cage" or not rigid(p):
        return None
    return ("bearingsim: note: rigid raceways in the kinematic_cage scene: its impulses are far from converged in "
            "the time step (at 3000 rpm I_dec reads 7.9 / 9.4 / 10.6 mN s at 17.8 / 8.9 / 4.4 us, against 12.6 "
            "on Hertz raceways; docs/fast_scene.md, The kinematic cage): set multibody.raceway_contact = \"hertz\" "
            "for that scene")


#: the gate of the step note (:func:`_traction_step_note`), a heuristic set between the measured cases of
#: docs/multibody.md, *Its time step*: a step of at least this fraction of the traction's relaxation time
#: (:func:`bearingsim.multibody.core.traction_relaxation_time`; no change to half the step resolved at 0.08, 1000 rpm
#: and 300 N; +0.62 % at 0.15, 1500 rpm) ...
TRACTION_STEP_NOTE = 0.1
#: ... and at least this share of I_dec taken within the load zone's half angle (:func:`load_zone_share`: 0.34-0.72
#: where the change to half the step is resolved at 500-1500 rpm; 0.00 on an outer land and at 3000 rpm and 3 kN)
LOAD_ZONE_PUSH_SHARE = 0.25


def load_zone_share(result) -> float:
    """The share of a run's rear-face (I_dec) impulse taken within its load zone, ``|theta|`` below
    ``load_zone_half_angle_deg`` (from ``/results/force_vs_theta_dec``, every pocket; NaN without them): where
    the cage pushes its rollers through the load zone much of I_dec is taken there (on the reference bearing, 20
    rotations: 0.72 at 500 rpm, 0.59 at 1000 rpm, 0.34 at 1500 rpm), where they run free of their rear faces almost
    none (0.00 on an outer land at 1000 rpm and at 3000 rpm and 3 kN; 2 rotations: 0.085 at 2000 rpm)."""
    data = getattr(result, "data", {})
    f, th = data.get("results/force_vs_theta_dec"), data.get("results/theta_deg")
    phi = float(result.summary.get("load_zone_half_angle_deg", math.nan))
    if f is None or th is None or not phi > 0.0:
        return math.nan
    force = np.asarray(f.data, float).sum(axis=1)
    theta = np.asarray(th.data, float)
    total = force.sum()
    inside = (theta < phi) | (theta > 360.0 - phi)
    return float(force[inside].sum() / total) if total > 0.0 else math.nan


def _traction_step_note(result) -> str | None:
    """A free cage that pushes its rollers through the load zone (:data:`LOAD_ZONE_PUSH_SHARE` of I_dec or more
    taken there) with a step of :data:`TRACTION_STEP_NOTE` or more of the traction's relaxation time: where the
    face force is split from the implicit traction (:func:`bearingsim.multibody.core.traction_relaxation_time`),
    and the reference bearing's runs depend on the step beyond their standard errors; the note says so and
    points to ``--check-step`` (it does not predict this run's error: its size and sign vary from case to case).
    None otherwise."""
    from bearingsim.multibody.core import max_roller_load, rolling_speed, traction_relaxation_time

    p = result.parameters
    if p.multibody.scene not in ("full", "centred_cage"):  # the kinematic cage's step is divided for it
        return None
    tau = traction_relaxation_time(p)
    h = float(result.summary.get("dt_s", math.nan))
    share = load_zone_share(result)
    if not (h / tau >= TRACTION_STEP_NOTE and share >= LOAD_ZONE_PUSH_SHARE):
        return None
    return (f"bearingsim: note: the cage pushes its rollers through the load zone ({share:.0%} of I_dec is taken "
            f"within its half angle) with a step ({h * 1e6:.3g} us) of {h / tau:.2g} of the traction's relaxation "
            f"time there (tau = m slip_ref u / (2 mu_max Q) = {tau * 1e6:.3g} us, Q ≈ {max_roller_load(p):.0f} N the "
            f"most loaded roller's load, u = {rolling_speed(p):.3g} m/s its rolling speed): the force kernel's implicit "
            f"traction and pymunk's contact solve, taken one after the other, give a face that holds a roller a "
            f"force low by about h / tau in each step, and such runs of the reference bearing change by 0.3-0.8 % "
            f"(Hertz raceways; the automatic step reads I_dec 1.2 % low at 1000 rpm, 1.9 % at 500 rpm) and 1.1-1.7 % "
            f"(rigid, either sign) to half the step, beyond their standard errors (docs/multibody.md, Its time step): "
            f"--check-step measures this run's")


def _pinched_note(result) -> str | None:
    """Rollers pinched by their pockets in the load zone (:func:`bearingsim.multibody.core.pinch`): the run
    is of jammed pockets, which a pocket clearance larger by about twice the overlap frees (the rim-end gap
    grows by half the clearance's growth)."""
    from bearingsim.multibody.core import max_roller_load, pinch

    p = result.parameters
    depth = pinch(p)
    if depth <= 0.0:
        return None
    s_mm = p.bearing.pocket_clearance * 1e3
    return (f"bearingsim: note: the most loaded roller (about {max_roller_load(p):.0f} N: 5 W / Z and its centrifugal "
            f"load), pressed into the outer race, reaches {depth * 1e6:.2g} um into the rim ends of its pocket's faces: "
            f"in the load zone the pockets pinch their rollers, so the impulses are those of jammed pockets, not of "
            f"rollers free in them (docs/stability.md); a bearing.pocket_clearance_mm above about "
            f"{s_mm + 2e3 * depth:.4g} (now {s_mm:.4g}) frees them")


#: the checks of :func:`checks_made` whose finding is a note, not a failure: :func:`check` notes it and the run
#: is kept. The warm-up's is a statistical test (is the first recorded rotation still in the start's transient?
#: :data:`START_TRANSIENT_FALSE_ALARM` of steady runs test positive), and a resting place that changes or a cage
#: speed that drifts describe the run, valid as it is. A report shows such a check as "note", never "FAILED".
NOTED_CHECKS = ("warm-up reached a steady state", "cage rests in one place",
                "cage speed steady (no drift over the recorded rotations)")


def checks_made(result) -> list[tuple[str, str, bool | None]]:
    """What :func:`check` verifies of ``result``, for a report: one ``(check, what was measured against
    its limit, passed)`` per check, with the limits :func:`check` uses (a report shows them beside the
    notes and the verdict of :func:`check` itself, which stays the one that refuses a run). ``passed`` is
    None for a check that could not be made of this result (too few recorded rotations; a cage-speed
    drift, whose start and end speeds only a fresh run holds): the row says why, and is not a pass. ``passed``
    False of a check in :data:`NOTED_CHECKS` is a note of the run, not a failure."""
    p = result.parameters
    summary = dict(result.summary)
    bad = _nonfinite(summary)
    allowed = {"first_impact_speed_m_s", "first_impact_energy_J"} if p.model == "multibody" else set()
    out = [("summary numbers finite", f"{len(summary)} numbers; not finite: {', '.join(sorted(bad)) or 'none'}"
            + (" (no rear-face impact in the no-load zone: allowed)" if bad and set(bad) <= allowed else ""),
            not bad or set(bad) <= allowed)]
    arrays = [np.asarray(result.per_rotation.get(n, np.zeros(0))) for n in ("I_dec", "I_acc")]
    finite = all(bool(np.all(np.isfinite(a))) for a in arrays)
    out.append(("I_dec and I_acc per rotation finite", f"{sum(a.size for a in arrays)} values", finite))
    if p.model != "multibody":
        return out
    if "inner_ring_displacement_m" in summary:
        disp, limit = abs(float(summary["inner_ring_displacement_m"])), max_ring_displacement_m(p)
        out.append(("inner-ring displacement within the Palmgren bound",
                    f"{disp * 1e6:.4g} µm against {limit * 1e6:.4g} µm ({DISPLACEMENT_MARGIN:g} x (half the "
                    "radial clearance + twice the approach of one roller carrying the load + a roller's centrifugal "
                    "approach))", disp <= limit))
    orbit = result.get("cage_orbit")
    samples = int(np.sum(np.isfinite(orbit[:, 0]))) if np.ndim(orbit) == 2 else 0
    out.append(("cage-orbit samples recorded", f"{samples} against at least {MIN_ORBIT_SAMPLES}",
                samples >= MIN_ORBIT_SAMPLES))
    off = _first_rotation_offset(result)
    if off is not None:
        rel, t, n = off
        out.append(("warm-up reached a steady state", f"first recorded rotation's I_dec {rel:+.1%} off the mean of "
                    f"the {n} later ones, t = {t:.1f}, against at most {start_transient_critical(n):.2f} (Student's t, "
                    f"{START_TRANSIENT_FALSE_ALARM:.0%} of steady runs beyond) or {START_TRANSIENT_MIN_REL:.0%}",
                    not transient_flagged(off)))
    else:
        rotations = np.shape(result.per_rotation.get("I_dec", np.zeros(0)))[0] if np.ndim(
            result.per_rotation.get("I_dec", np.zeros(0))) else 0
        out.append(("warm-up reached a steady state", f"not evaluated: {counted(rotations, 'recorded rotation')}, "
                    f"at least {START_TRANSIENT_MIN_ROTATIONS} needed (with fewer the later ones' scatter hides "
                    "the start's transient in most runs)", None))
    rest = _rest_span(result)
    out.append(("cage rests in one place", (f"its resting angle spanned {rest[0]:.1f} deg over the recorded rotations "
                                            f"against at most {CAGE_REST_SPAN_DEG:g}") if rest is not None else
                "not evaluated: no per-rotation resting place (an archive of multibody model version 5 or "
                "before, one recorded rotation, or a cage at the axis)",
                None if rest is None else rest[0] <= CAGE_REST_SPAN_DEG))
    raw = getattr(result, "raw", None)
    if raw is None or raw.cage_w_start is None:
        out.append(("cage speed steady (no drift over the recorded rotations)", "not evaluated: the cage speeds at "
                    "the start and the end of the recording are a fresh run's, not stored in an archive "
                    f"(at most {MAX_CAGE_SPEED_DRIFT:.0%} of the mean; 'bearingsim run' notes a drift, and its archive "
                    "stores the run's notes)", None))
    else:
        note = cage_speed_drift(result)
        ws, we = float(raw.cage_w_start), float(raw.cage_w_end)
        mean = abs(float(summary.get("cage_speed_mean_rad_s", float("nan"))))
        out.append(("cage speed steady (no drift over the recorded rotations)",
                    f"{ws:.4g} to {we:.4g} rad/s ({(we - ws) / mean:+.1%} of the mean) against at most "
                    f"{MAX_CAGE_SPEED_DRIFT:.0%}", note is None))
    fails = int(result.provenance.get("ring_newton_failures", 0) or 0)
    steps = int(summary.get("steps", 0) or 0)
    if steps:
        from bearingsim.multibody.core import MAX_NEWTON_FAILURE_FRACTION

        out.append(("inner ring's force balance converged", f"not in {fails} of {steps} steps ({fails / steps:.2%}) "
                    f"against at most {MAX_NEWTON_FAILURE_FRACTION:.0%}", fails <= MAX_NEWTON_FAILURE_FRACTION * steps))
    return out


@functools.lru_cache(maxsize=None)
def start_transient_critical(later: int) -> float:
    """The |t| beyond which :func:`start_transient` notes a first rotation judged against ``later`` (>= 2)
    rotations: Student's t quantile 1 - :data:`START_TRANSIENT_FALSE_ALARM` / 2, ``later`` - 1 degrees of freedom."""
    return t_quantile(1.0 - START_TRANSIENT_FALSE_ALARM / 2.0, later - 1)


def transient_offset(x) -> tuple[float, float, int] | None:
    """(offset of the first value of the series ``x`` from the mean of the later ones, relative to that
    mean; the offset's t, (x1 - mean) / (sd sqrt(1 + 1/m)) of the m later ones; m) or None for a mean <= 0
    or fewer than 3 values."""
    x = np.asarray(x, dtype=float)
    rest = x[1:]
    if rest.size < 2:
        return None
    mean = float(rest.mean())
    sd = float(rest.std(ddof=1)) * math.sqrt(1.0 + 1.0 / rest.size)
    d = float(x[0]) - mean
    if mean <= 0.0:
        return None
    return d / mean, (abs(d) / sd if sd > 0.0 else (math.inf if d else 0.0)), int(rest.size)


def transient_flagged(off: tuple[float, float, int]) -> bool:
    """Whether an offset of :func:`transient_offset` is the start's transient: beyond
    :func:`start_transient_critical` and :data:`START_TRANSIENT_MIN_REL`."""
    rel, t, later = off
    return abs(rel) > START_TRANSIENT_MIN_REL and t > start_transient_critical(later)


def _first_rotation_offset(result) -> tuple[float, float, int] | None:
    """:func:`transient_offset` of a multibody result's pocket-mean I_dec over its recorded rotations, when it
    has at least :data:`START_TRANSIENT_MIN_ROTATIONS`, else None."""
    if result.parameters.model != "multibody":
        return None
    arr = np.asarray(result.per_rotation.get("I_dec", np.zeros(0)), dtype=float)
    if arr.ndim != 2 or arr.shape[0] < START_TRANSIENT_MIN_ROTATIONS or not np.all(np.isfinite(arr)):
        return None
    return transient_offset(arr.mean(axis=1))


def start_transient(result) -> str | None:
    """A note when a multibody run's first recorded rotation is still off the steady state that the later
    ones show (:func:`transient_flagged`), else None."""
    off = _first_rotation_offset(result)
    if off is None or not transient_flagged(off):
        return None
    rel, t, n = off
    return (f"bearingsim: note: the first recorded rotation's I_dec is {rel:+.1%} off the mean of the {n} later "
            f"ones (its test statistic t = {t:.1f} exceeds {start_transient_critical(n):.2f}, which "
            f"{START_TRANSIENT_FALSE_ALARM:.0%} of steady runs exceed): the warm-up did not reach a steady state, "
            f"and it biases the mean I_dec by {rel / (n + 1):+.2%}; set more numerics.warmup_rotations (now "
            f"{result.parameters.numerics.warmup_rotations}) or more numerics.rotations (docs/statistics.md)")


def warmup_not_judged(result) -> str | None:
    """A note when a multibody run recorded fewer rotations than :func:`start_transient` judges the warm-up
    from (:data:`START_TRANSIENT_MIN_ROTATIONS`), else None: its means may hold the start's transient unseen,
    whose size on the reference bearing docs/statistics.md gives.

    :func:`start_transient` judges every multibody scene, but the ``reduced_equivalent`` scene has no start
    transient to judge: its cage turns kinematically at the epicyclic speed and the load zone carries every
    roller at the front of its pocket with zero relative speed, so each pass starts from the same state and
    its rotations repeat (their standard error about 0); it gets no note. The other scenes, the
    ``kinematic_cage`` one included (its rollers and inner ring settle from the assembled state), may
    carry a transient and get it."""
    p = result.parameters
    if p.model != "multibody" or p.multibody.scene == "reduced_equivalent":
        return None
    arr = np.asarray(result.per_rotation.get("I_dec", np.zeros(0)))
    n = int(arr.shape[0]) if arr.ndim == 2 else 0
    if n >= START_TRANSIENT_MIN_ROTATIONS:
        return None
    warmup = result.parameters.numerics.warmup_rotations
    first = 10.0 if warmup < 2 else 1.0  # [%] the first recorded rotation's excess, docs/statistics.md
    means = np.nanmean(arr, axis=1) * 1e3 if n >= 2 else np.zeros(0)  # this run's evidence [mN s]
    own = (f"; this run's rotations read I_dec {' / '.join(f'{v:.4g}' for v in means)} mN s (mean over pockets)"
           if len(means) else "")
    return (f"bearingsim: note: the warm-up could not be judged: {counted(n, 'recorded rotation')}, and the check "
            f"of the start's transient needs at least {START_TRANSIENT_MIN_ROTATIONS} (with fewer the later ones "
            f"scatter too much: it would see the transient below in under half of the runs); on the reference "
            f"bearing the first recorded rotation after one warm-up rotation reads 9 to 10 % high at 3000 rpm, "
            f"after two within about 1 % (docs/statistics.md), "
            f"so up to about +{first / n:.2g} % in the mean of {counted(n, 'rotation')} after {warmup}{own}; set "
            f"numerics.rotations to {START_TRANSIENT_MIN_ROTATIONS} or more (now {n}), or more "
            f"numerics.warmup_rotations")


def _rest_span(result) -> tuple[float, float, float] | None:
    """(span [deg], first and last end [deg]) of where a multibody result's cage rested over its recorded
    rotations (/results/per_rotation/cage_rest_angle), or None: an archive without them, fewer than 2
    rotations, or a cage at the axis (:data:`CAGE_REST_MIN_OFFSET`). The span is taken round the circle
    from the first rotation's angle; its ends are the stored angles at either end of the arc, which runs
    from the first to the last in the direction of rotation (across 180 deg when the first is the larger)."""
    pr = result.per_rotation
    if result.parameters.model != "multibody" or "cage_rest_angle" not in pr:
        return None
    a = np.asarray(pr["cage_rest_angle"], dtype=float)
    o = np.asarray(pr["cage_rest_offset"], dtype=float)
    ok = np.isfinite(a) & np.isfinite(o)
    a, o = a[ok], o[ok]
    if a.size < 2 or o.min() < CAGE_REST_MIN_OFFSET * result.parameters.bearing.pocket_clearance:
        return None
    d = (a - a[0] + 180.0) % 360.0 - 180.0
    return float(d.max() - d.min()), float(a[np.argmin(d)]), float(a[np.argmax(d)])


def cage_rest_change(result) -> str | None:
    """A note when a multibody run's cage did not rest in one place over its recorded rotations (a span of
    its resting angle beyond :data:`CAGE_REST_SPAN_DEG`), else None; the span to 0.1 deg, as the check of
    :func:`checks_made` gives it. Its explanation follows the guidance: a roller-guided cage can rest in two
    places under load; a land-guided cage runs on its land."""
    got = _rest_span(result)
    if got is None or got[0] <= CAGE_REST_SPAN_DEG:
        return None
    span, lo, hi = got
    across = " across 180" if lo > hi else ""  # the stored angles lie in -180 .. 180 deg
    guidance = result.parameters.bearing.cage_guidance
    if guidance == "rollers":
        why = "under load a roller-guided cage can rest in two: docs/whatif.md, Radial load"
    else:
        why = (f"this cage runs on its {guidance.split('_')[0]} ring's land, within half the land clearance of that "
               f"ring's centre (docs/stability.md, Land-guided cage), and the angle says where along the land; the "
               f"two resting places of docs/whatif.md, Radial load are a roller-guided cage's")
    return (f"bearingsim: note: the cage did not rest in one place: the angle of its centre's mean position from "
            f"the bottom spanned {span:.1f} deg over the recorded rotations ({lo:.1f} to {hi:.1f} deg{across}, "
            f"/results/per_rotation/cage_rest_angle; a steady run's stays within about 12 deg, the bound is "
            f"{CAGE_REST_SPAN_DEG:g}), so the run's means mix the places it rested in ({why})")


def cage_speed_drift(result) -> str | None:
    """A note when the cage speed of a fresh multibody run drifted over its recorded rotations by more
    than :data:`MAX_CAGE_SPEED_DRIFT` of its mean (not statistically steady), else None."""
    raw = getattr(result, "raw", None)
    if raw is None or raw.cage_w_start is None:  # read back from an archive, or never recorded
        return None
    ws, we = float(raw.cage_w_start), float(raw.cage_w_end)
    mean = abs(float(result.summary.get("cage_speed_mean_rad_s", float("nan"))))
    if not (math.isfinite(ws) and math.isfinite(we) and mean > 0) or abs(we - ws) <= MAX_CAGE_SPEED_DRIFT * mean:
        return None
    return (f"bearingsim: note: not statistically steady: the cage speed went from {ws:.4g} to {we:.4g} rad/s over "
            f"the recorded rotations ({(we - ws) / mean:+.0%} of its mean {mean:.4g} rad/s); cage_slip and the "
            f"impulses are means over a transient (more numerics.warmup_rotations, or check "
            f"multibody.traction_mu_max and lubrication.drag_coefficient)")


def _advice(result) -> str:
    """What to change after a run that is not a result: the key that most likely caused it, judged
    from what the run did (a step the user gave that is longer than the automatic one, the inner ring
    the run actually had, the cage guidance), not from the scenario's words ("auto")."""
    p = result.parameters
    step = _given_step_advice(result)
    if step:
        return step
    if p.model == "multibody" and str(result.provenance.get("inner_ring", "")).startswith("dynamic"):
        return ("check multibody.inner_ring_mass_kg and operating.radial_load_N, or set "
                "multibody.inner_ring=quasi_static, or a smaller numerics.dt_s")
    if p.model == "multibody":
        land = (", bearing.cage_land_clearance_mm and contact.land_friction (the land-guided cage)"
                if p.bearing.cage_guidance != "rollers" and p.multibody.scene == "full" else "")
        return (f"check operating.radial_load_N and operating.inner_ring_speed_rpm{land}, or set a smaller "
                "numerics.dt_s")
    return "check bearing.roller_mass_kg, lubrication.drag_coefficient and reduced.load_zone_half_angle_deg"


def automatic_dt(p) -> float | None:
    """The step [s] the model would choose for the SI parameters ``p`` without ``numerics.dt_s``
    (None: the reduced model's event method, which has no step)."""
    import dataclasses

    q = dataclasses.replace(p, numerics=dataclasses.replace(p.numerics, dt=None))
    if p.model == "multibody":
        from bearingsim.multibody.core import choose_dt

        return float(choose_dt(q)[0])
    if p.reduced.method == "euler":
        from bearingsim.reduced.core import PassInputs
        from bearingsim.reduced.euler import default_dt

        return float(default_dt(PassInputs.from_parameters(q)))
    return None


def _given_step_advice(result) -> str | None:
    """Advice naming ``numerics.dt_s``, or the ``dt`` argument of :func:`bearingsim.run` when the step came from
    it, when the run used a step the user gave that is longer than the automatic step (None otherwise: then
    the step is not the first suspect)."""
    how = str(result.provenance.get("dt_choice", ""))
    dt = result.provenance.get("dt_s")
    if not how.startswith(("numerics.dt_s", "simulate(dt=")) or dt is None or not math.isfinite(float(dt)):
        return None
    try:
        auto = automatic_dt(result.parameters)
    except Exception:  # noqa: BLE001 - advice only: a step the model cannot choose is no comparison
        return None
    if auto is None or not float(dt) > auto:
        return None
    # simulate(dt=...): the dt argument of bearingsim.run, stored as numerics.dt_s
    return given_step(float(dt), auto, how.startswith("simulate(dt="))


def _few_samples_advice(result) -> str:
    """Why a multibody run recorded too few cage-orbit samples, and the key to change: a step longer
    than the sampling interval (one sample per step at most), a cage that turned its recorded rotations
    much faster than its epicyclic speed (traction or drag, not the output rate), or the output rate
    and the run length themselves."""
    p = result.parameters
    rate = p.numerics.output_rate
    dt = step_of(result)
    if math.isfinite(dt) and dt * rate > 1.0:
        step = _given_step_advice(result)
        return step or (f"the step {dt:.3g} s is longer than the sampling interval 1/numerics.output_rate_hz = "
                        f"{1.0 / rate:.3g} s; set a smaller numerics.dt_s")
    speed = abs(float(result.summary.get("cage_speed_mean_rad_s", float("nan"))))
    nominal = p.operating.omega_c
    if math.isfinite(speed) and speed > OVERSPEED_FACTOR * nominal:
        return (f"the cage turned at {speed:.4g} rad/s, {speed / nominal:.3g} times its epicyclic speed "
                f"{nominal:.4g} rad/s (Eq. 11), so its recorded rotations took little time: check "
                "multibody.traction_mu_max, multibody.traction_slip_ref and lubrication.drag_coefficient")
    return "raise numerics.output_rate_hz or numerics.rotations"


#: how the note of a step check begins (:func:`step_check_note`): a measurement asked for, not a warning
STEP_CHECK_HEAD = "bearingsim: note: time step checked at half of it"


def percent_text(x: float) -> str:
    """A relative change as the step check gives it: ``+80%``, ``-1.00%``, ``+0.036%``, ``+6.2e-07%``."""
    pc = x * 100.0
    if abs(pc) >= 10.0:
        return f"{pc:+.0f}%"
    if abs(pc) >= 0.1:
        return f"{pc:+.2f}%"
    return f"{pc:+.2g}%"


def step_check_note(result, half) -> str:
    """The note of a run checked at half its time step (``bearingsim run --check-step``): each mean impulse at
    the step and at half of it with their standard errors (batch means; none for the reduced model, exact),
    the change and whether it is resolved by the tables' rule (:func:`bearingsim.stats.significant`), then the
    same of the other numbers with a standard error, the first impact speed, the cage slip and the load zone
    (:func:`_other_step_change`). The
    whole bearing is chaotic: the two runs are two trajectories, so an unresolved change is bounded by about
    twice the combined standard error, not to zero (docs/statistics.md); for the first-order scheme the step's
    error is about twice the change, and the verdict says so (:func:`_step_change`). When either run's
    first recorded rotation is a start transient (:func:`start_transient`), the means and their standard
    errors hold it (it can hide a change of the steady state): the note compares them again without each
    run's first recorded rotation."""
    from bearingsim.stats import result_standard_errors, sem_batches

    dt = step_of(result)
    se_a, se_b = result_standard_errors(result), result_standard_errors(half)
    nb = sem_batches(len(result.per_rotation["I_dec"]))
    parts = [_step_change(q, result.summary[f"{q}_mean_Ns"], se_a[f"{q}_sem_Ns"], half.summary[f"{q}_mean_Ns"],
                          se_b[f"{q}_sem_Ns"], nb) for q in ("I_dec", "I_acc")]
    parts += [_other_step_change(k, result.summary_units.get(k, "1"), result.summary[k], se_a[e], half.summary[k],
                                 se_b[e], nb)
              for k, e in SUMMARY_SEM_OF.items() if not k.endswith("_Ns") and e in se_a and e in se_b
              and k in result.summary and k in half.summary]
    return f"{STEP_CHECK_HEAD} ({dt:.3g} s and {dt / 2:.3g} s): " + "; ".join(parts) + _steady_step_change(result, half)


def _other_step_change(key: str, si_unit: str, a: float, ea: float, b: float, eb: float, nb: int) -> str:
    """``"cage_slip 0.3789 at the step, 0.4051 % at half of it: +0.0262 ± 0.0038 % (resolved)"``: a summary number
    other than the impulses (the first impact speed, the cage slip, the load zone's half angle) at the step and at
    half of it, its change as a difference in the unit the tables show it in (a slip near 0 has no meaningful
    relative change; ``si_unit`` its unit in the summary), ± the combined standard error, and whether the change is
    resolved by the tables' rule."""
    from bearingsim.stats import significant
    from bearingsim.wording import shown_as

    scale, unit = shown_as(key, si_unit)
    name = key.removesuffix("_m_s").removesuffix("_deg")
    if not (math.isfinite(a) and math.isfinite(b)):
        return f"{name}: not compared (none at {'the step' if not math.isfinite(a) else 'half of it'})"
    mark = significant(b, eb, a, ea, nb, nb)
    exact = ea == 0.0 and eb == 0.0
    if mark is None:
        verdict = "not judged: no standard error"
    elif mark:
        verdict = "exact, the model is deterministic" if exact else "resolved"
    else:
        verdict = "no change beyond round-off" if exact else "not resolved"
    err = math.hypot(ea, eb) * scale
    spread = f" ± {err:.2g}" if err > 0.0 and math.isfinite(err) else ""
    return (f"{name} {a * scale:.5g} at the step, {b * scale:.5g} {unit} at half of it: {(b - a) * scale:+.3g}"
            f"{spread} {unit} ({verdict})")


def _step_change(q: str, a: float, ea: float, b: float, eb: float, nb: int) -> str:
    """``"I_dec 50.858 at the step, 51.101 mN s at half of it: +0.48% ± 0.30% (verdict)"``: the mean impulse
    ``a`` ± ``ea`` at the step against ``b`` ± ``eb`` at half of it [N s], each error from ``nb`` batch means.
    The change is not the step's error: for a scheme of order p the error is the change over 1 - 2^-p, twice it
    at first order (Richardson: the limit is about 2 b - a) and more below it; the whole bearing's scheme
    converges at first order or slower at 500-1000 rpm (docs/multibody.md, *Its time step*). So the verdict
    gives the first-order error, or twice the bound on the change when the change is not resolved."""
    from bearingsim.stats import critical_ses, significant

    if not a > 0.0:
        return (f"{q} {a * 1e3:.4g} at the step, {b * 1e3:.4g} mN s at half of it (no impulse at the step to "
                "compare with)")
    rel, rel_se = b / a - 1.0, math.hypot(ea, eb) / a
    mark = significant(b, eb, a, ea, nb, nb)
    if mark is None:
        verdict = "not judged: no standard error from one rotation"
    elif ea == 0.0 and eb == 0.0:
        verdict = f"exact, the model is deterministic; {_first_order_error(rel)}" if mark else \
            "no change beyond round-off"
    elif mark:
        verdict = f"resolved: the number depends on the step; {_first_order_error(rel)}"
    else:
        bound = critical_ses(ea, eb, nb, nb) * rel_se
        verdict = (f"not resolved: the change is below about {bound:.1%}, so the step's error is below about "
                   f"{2 * bound:.1%} for a first-order scheme, more for a slower one")
    spread = f" ± {percent_text(rel_se)[1:]}" if rel_se > 0.0 else ""
    return f"{q} {a * 1e3:.5g} at the step, {b * 1e3:.5g} mN s at half of it: {percent_text(rel)}{spread} ({verdict})"


def _first_order_error(rel: float) -> str:
    """What a change ``rel`` from the step to half of it says of the step's error for a first-order scheme: the
    run at the step off the extrapolated limit 2 b - a, -2 rel / (1 + 2 rel) (about twice the change)."""
    if not rel > -0.5:  # the extrapolation has no meaning for a change this large
        return "the step's error is at least twice this change for a first-order scheme"
    return (f"the step's error is about twice this change for a first-order scheme, more for a slower one: the run "
            f"at the step is {percent_text(-2.0 * rel / (1.0 + 2.0 * rel))} off the first-order extrapolation")


def _steady_step_change(result, half) -> str:
    """The step check's comparison again without each run's first recorded rotation, when either run's first
    one is a start transient (:func:`transient_flagged`); "" otherwise. At 500 rpm on the reference bearing (2
    warm-up rotations) the run at half the step starts 6 % low and its later rotations scatter by 0.01 %: the
    means' standard error is that one rotation, and hid the steady states' change (docs/multibody.md)."""
    from bearingsim.stats import batch_sem, pocket_means, sem_batches

    runs = (("at the step", result), ("at half of it", half))
    offs = [(name, _first_rotation_offset(r)) for name, r in runs]
    off = [f"{name} {o[0]:+.1%}" for name, o in offs if o is not None and transient_flagged(o)]
    if not off:
        return ""
    parts = []
    for q in ("I_dec", "I_acc"):
        xa, xb = (pocket_means(r.per_rotation[q])[1:] for _, r in runs)
        parts.append(_step_change(q, float(xa.mean()), batch_sem(xa), float(xb.mean()), batch_sem(xb),
                                  sem_batches(len(xa))))
    return (f". The first recorded rotation is a start transient ({', '.join(off)} off the later ones), which the "
            "means and errors above hold; without each run's first recorded rotation: " + "; ".join(parts))


def step_of(result) -> float:
    """The time step [s] a result ran at (its provenance's ``dt_s``), NaN for none (the reduced event method)."""
    return float(result.provenance.get("dt_s", math.nan))
