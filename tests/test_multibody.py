"""Physics tests of the multi-pocket model (issue 3). Each test says why its check must hold.

Runs are short (a few cage rotations) and shared through module-scoped fixtures.
"""
from __future__ import annotations

import math
import re
import subprocess
import sys

import h5py
import numpy as np
import pytest

from bearingsim import archive
from bearingsim.scenario import load_scenario
from tests.conftest import SCENARIOS, si

from bearingsim.simulation import run as simulate
from bearingsim.multibody.core import choose_dt
from bearingsim.multibody.scene import build_scene

PHI_DEG = 23.5  # paper Sec. 2.3, load-zone half angle at 970 N


def _scenario(rpm=3000, scene="full", rotations=4, warmup=1, extra=()):
    return load_scenario(SCENARIOS / "multibody_3000rpm.toml", [
        f"operating.inner_ring_speed_rpm={rpm}", f"multibody.scene={scene}",
        f"numerics.rotations={rotations}", f"numerics.warmup_rotations={warmup}",
        f"reduced.load_zone_half_angle_deg={PHI_DEG}", *extra])


@pytest.fixture(scope="module")
def full_3000():
    """Full scene, 3000 rpm, 20 recorded rotations after 1 warm-up rotation (~20 s)."""
    return simulate(_scenario(rotations=20))


@pytest.fixture(scope="module")
def full_3000_reverse():
    return simulate(_scenario(rotations=20, extra=["operating.direction=reverse"]))


@pytest.fixture(scope="module")
def full_3000_frictionless():
    return simulate(_scenario(rotations=10, extra=["contact.cage_friction=0"]))


# ------------------------------------------------------------------------------------------------
def test_rebound_ratio_equals_restitution():
    """Newton's restitution law, which pymunk applies at every contact: after one roller-cage impact
    the normal relative speed is -e times the approach speed. Minimal scene: kinematic cage at rest,
    no gravity, no raceways, one roller moving straight at its front face. Tolerance 0.5 %: the only
    deviation is pymunk's position-bias velocity, bounded by slop/dt (1e-8 m / 1e-6 s = 1 % of
    1 m/s; measured much smaller at 0.1 m/s)."""
    sc = _scenario()
    geo, op = si(sc).bearing, si(sc).operating
    e = sc.contact.restitution
    s = build_scene(geo, op, e, 0.0, extent=(-math.radians(45), math.radians(45)), n_seg=3, kinematic_cage=True,
                    spin_free=True)
    s.space.gravity = (0.0, 0.0)
    s.cage.angular_velocity = 0.0
    for b in s.rollers:
        b.velocity = (0.0, 0.0)
        b.angular_velocity = 0.0
    a = s.pocket_body_angle[0]
    et = np.array([-math.sin(a), math.cos(a)]) * op.sign
    v0 = 0.1
    roller = s.rollers[0]
    roller.velocity = tuple(v0 * et)
    h = 1e-6
    v_after = None
    for _ in range(20000):
        s.space.step(h)
        vn = float(np.dot(np.array(roller.velocity), et))
        if vn < 0.0:
            v_after = -vn
            break
    assert v_after is not None, "roller never hit the front face"
    assert v_after / v0 == pytest.approx(e, rel=5e-3)


@pytest.mark.slow
def test_no_penetration(full_3000):
    """A roller never passes through a cage face: pymunk's contact solver keeps the overlap at the
    collision slop plus what one step's approach can add. Bound from the issue: 1 % of s."""
    s = full_3000.parameters.bearing.pocket_clearance
    assert full_3000.summary["max_penetration_all_m"] < 0.01 * s, full_3000.summary["max_penetration_all_m"]


def test_cage_angular_momentum_balance(full_3000):
    """Over 20 steady rotations the torque impulses of all roller contacts (normal and friction)
    equal the change of the cage's angular momentum (the cage has no other torque). Closes within
    1 % of the drive impulse moment sum(I_acc) r_p.

    Why 1 %: the tolerance must lie above the closure the solver reaches and below the smallest term the
    balance holds, so that leaving a term out fails. Measured over these 20 rotations: residual 2.4e-6 of
    the drive (0.234 N m s); the normal contacts' net torque impulse -0.0162 N m s and the friction's
    +0.0163 N m s nearly cancel (the cage turns at a steady speed: its momentum changes by 1.0e-4 N m s), so
    each is 6.9 % of the drive, and a balance without the friction torque is off by 7.0 %. 1 % lies 7 times
    below that and 4000 times above the measured closure."""
    assert abs(full_3000.summary["torque_balance_residual"]) < 0.01


@pytest.mark.slow
def test_frictionless_acc_dec_balance(full_3000_frictionless):
    """With frictionless pockets the only torques on the cage are the circumferential pocket forces;
    at steady cage speed their long-run mean cancels: I_acc / I_dec -> 1 (docs/physics.md).
    Tolerance 3 % (issue): residual cage acceleration over 10 rotations and the radial component
    of arc-face contacts away from the centre line."""
    r = full_3000_frictionless
    ratio = r.per_rotation["I_acc"].mean() / r.per_rotation["I_dec"].mean()
    assert ratio == pytest.approx(1.0, abs=0.03), ratio


def test_force_location(full_3000):
    """Paper Sec. 3.1 / Fig. 5: the roller drives the cage (net front-face force) in the load zone,
    and braking (F_dec) begins after the no-load-zone entrance theta = phi, once the roller has
    lagged across the pocket clearance. Checks: (a) > 80 % of the positive net circumferential force
    (F_acc - F_dec, mean over pockets) lies within |theta| <= phi + 15 deg; (b) no F_dec before
    phi; the first theta > phi where the mean F_dec exceeds 10 % of its no-load-zone maximum lies
    within phi + 60 deg (the reduced model's first impact is at phi + 40..55 deg)."""
    r = full_3000
    th = r.get("theta_deg")
    phi = r.summary["load_zone_half_angle_deg"]
    net = (r.get("force_vs_theta_acc") - r.get("force_vs_theta_dec")).mean(axis=1)
    pos = np.clip(net, 0, None)
    lz = (th <= phi + 15) | (th >= 360 - phi - 15)
    assert pos[lz].sum() > 0.8 * pos.sum(), pos[lz].sum() / pos.sum()
    fdec = r.get("force_vs_theta_dec").mean(axis=1)
    nl = (th > phi) & (th < 180)
    onset = th[nl][np.argmax(fdec[nl] > 0.1 * fdec[nl].max())]
    assert phi < onset < phi + 60, onset


@pytest.mark.slow
def test_forward_reverse_same_I_dec(full_3000, full_3000_reverse):
    """Mirror symmetry (paper Fig. 7): reversing the rotation mirrors the scene, so the mean I_dec is
    the same up to the scatter of two chaotic runs (rounding differs between the mirrored computations).

    The tolerance is that scatter, from the data: each mean's standard error from 5 batch means of 4
    rotations (docs/statistics.md; the pocket mean per rotation), and the difference within t = 2.306 of
    their combined error (Student's 97.5 % point at 8 degrees of freedom, Welch's for two equal errors of 4
    each: a 5 % two-sided test). Measured: 14.464 and 14.383 mN s, -0.57 % apart, standard errors 0.091 and
    0.088 mN s, combined 0.87 % of the mean: the difference is 0.65 of it. The former bound, 5 % ("std/mean
    ~0.3, correlated"), was 5.7 combined errors."""
    def mean_and_sem(r):
        per_rotation = r.per_rotation["I_dec"].mean(axis=1)
        batches = np.array([b.mean() for b in np.array_split(per_rotation, 5)])
        return per_rotation.mean(), batches.std(ddof=1) / math.sqrt(5)

    (a, sa), (b, sb) = mean_and_sem(full_3000), mean_and_sem(full_3000_reverse)
    assert abs(b - a) <= 2.306 * math.hypot(sa, sb), (a, b, sa, sb)


@pytest.mark.slow
def test_each_pockets_rotation_starts_where_it_crosses_the_load_zone_centre(full_3000, full_3000_reverse):
    """A pocket's recorded rotation k is its own window, from its k-th crossing of the load-zone centre (theta =
    0, after the warm-up) to the next: so within one (pocket, rotation) the theta of its impacts, taken in time
    order, only grows, from 0 to 360 deg, in either direction of rotation. Windows that started at a common
    time for all pockets, or anywhere else, would hold a wrap from 360 back to 0 (dropping each pocket's start
    angle from the window index passed every physics test). Every impact of the 20 rotations checked, both
    directions; none is in the warm-up or beyond the last rotation."""
    for res in (full_3000, full_3000_reverse):
        imp = res.impacts
        rotations = res.per_rotation["I_dec"].shape[0]
        assert set(np.unique(imp["rotation"]).tolist()) == set(range(rotations))
        for i in range(res.per_rotation["I_dec"].shape[1]):
            for k in range(rotations):
                m = (imp["pocket"] == i) & (imp["rotation"] == k)
                th = imp["theta_deg"][m][np.argsort(imp["time_s"][m], kind="stable")]
                assert np.all(np.diff(th) >= 0.0) and np.all((th >= 0.0) & (th < 360.0)), (i, k, th)


def test_where_the_cage_rests_is_its_orbit_mean_and_mirrors_with_the_rotation(full_3000, full_3000_reverse):
    """The summary's cage_rest_offset_m / cage_rest_angle_deg are the mean of the result's own
    /results/cage_orbit (1e-12), and mirror symmetry (paper Fig. 7): reversed, the cage rests at the
    mirror image, so its angle counted in the direction of rotation is the same (forward x > 0, reverse
    x < 0). Tolerance 10 deg: the two runs' resting angles are means over their last 4096 samples of a
    chaotic motion (59-60 deg at 3000 rpm in 20- and 40-rotation runs: docs/geometry.md, Cage motion)."""
    for r in (full_3000, full_3000_reverse):
        o = np.asarray(r.get("cage_orbit"))
        x, y = o[:, 1].mean(), o[:, 2].mean()
        assert r.summary["cage_rest_offset_m"] == pytest.approx(math.hypot(x, y), rel=1e-12, abs=0)
        sign = r.parameters.operating.sign
        assert r.summary["cage_rest_angle_deg"] == pytest.approx(math.degrees(math.atan2(sign * x, -y)), abs=1e-9)
    fwd, rev = (np.asarray(r.get("cage_orbit"))[:, 1].mean() for r in (full_3000, full_3000_reverse))
    assert fwd > 0 > rev, (fwd, rev)
    assert full_3000_reverse.summary["cage_rest_angle_deg"] == pytest.approx(
        full_3000.summary["cage_rest_angle_deg"], abs=10.0)


def test_load_zone_half_angle(full_3000):
    """Paper Sec. 2.3: the load zone at 970 N has a half angle of 23.5 deg. That number is the classical
    half angle psi_l = arccos(P_d / (2 delta_r)) (Harris & Kotzalas Sec. 7.2) of the ring displacement
    delta_r; here delta_r is the time-mean displacement of the inner ring that emerges from the Palmgren
    contacts, the radial clearance and the moving rollers. +-3 deg (issue): discrete rollers make
    delta_r oscillate by ~0.5 um (+-1.5 deg of psi_l).

    The same half angle against a converged reference of this bearing's physics: the time mean of delta_r
    of 16 discrete rollers, quasi-statically (:func:`_discrete_mean_displacement`, independent of the
    simulator's kernels), each roller pressed onto the outer race by its centrifugal load m r_p omega_c^2
    (11.7 N at 3000 rpm), gives 24.00 deg (23.91 without the centrifugal load; the continuous theory's 23.75).
    Tolerance 0.04 deg: half the smallest effect the reference holds, the centrifugal load's 0.088 deg, so a
    whole bearing without it fails; the time mean over 20 rotations of 16 roller passes each leaves
    about 0.77 deg / 320 = 0.002 deg of the oscillation. Measured: 23.987 deg, 0.012 deg from the reference
    (a raceway contact 5 % stiffer than Palmgren's gives 23.65 deg: inside the paper's +-3 deg, not this)."""
    assert full_3000.summary["load_zone_half_angle_deg"] == pytest.approx(PHI_DEG, abs=3.0)
    hp = 0.5 * si(full_3000.scenario).bearing.radial_clearance
    reference = math.degrees(math.acos(hp / _discrete_mean_displacement(full_3000.scenario)))
    assert full_3000.summary["load_zone_half_angle_deg"] == pytest.approx(reference, abs=0.04), reference


def _discrete_mean_displacement(scenario, samples=90, centrifugal=True):
    """Time-mean displacement delta_r [m] of the inner ring along the load, quasi-statically, over all
    positions of a discrete roller set (the ring free in x and y), each roller carrying its inner-contact
    load Q and, with ``centrifugal``, pressed onto the outer race by m r_p omega_c^2 as well: the two Palmgren
    contacts in series take up delta_r cos psi - P_d / 2 = delta(Q) + delta(Q + F_c). Written here
    independently of the simulator's kernels (laws.palmgren_approach is Harris & Kotzalas Eq. 6.40,
    tests/test_laws.py)."""
    from scipy.optimize import brentq, root

    from bearingsim.laws import palmgren_approach

    p = si(scenario)
    g = p.bearing
    z, hp, load, length = g.roller_count, 0.5 * g.radial_clearance, p.operating.radial_load, g.roller_length
    fc = g.roller_mass * g.pitch_radius * p.operating.omega_c ** 2 if centrifugal else 0.0

    def inner_load(a):  # Q with delta(Q) + delta(Q + F_c) = a; the roller sunk delta(F_c) into the outer race
        if a <= palmgren_approach(fc, length):  # leaves that much more gap to the inner ring
            return 0.0
        hi = 1.0
        while palmgren_approach(hi, length) + palmgren_approach(hi + fc, length) < a:
            hi *= 2.0
        return brentq(lambda q: palmgren_approach(q, length) + palmgren_approach(q + fc, length) - a, 0.0, hi,
                      xtol=1e-9, rtol=1e-14)

    displacements, guess = [], np.array([0.0, hp + 4e-6])
    for psi0 in np.linspace(0.0, 2 * np.pi / z, samples, endpoint=False):
        psi = np.mod(psi0 + 2 * np.pi * np.arange(z) / z + np.pi, 2 * np.pi) - np.pi

        def f(d):
            q = np.array([inner_load(d[0] * math.sin(ps) + d[1] * math.cos(ps) - hp) for ps in psi])
            return [np.sum(q * np.sin(psi)) / load, np.sum(q * np.cos(psi)) / load - 1.0]

        sol = root(f, guess, method="hybr", options={"xtol": 1e-12})
        assert np.max(np.abs(f(sol.x))) < 1e-8  # force balance to 1e-8 of the load
        guess = sol.x
        displacements.append(sol.x[1])
    return float(np.mean(displacements))


def _discrete_contact_edge(scenario, samples=90):
    """Largest angle [deg] from the load-zone centre at which a roller still carries load, quasi-
    statically, over all positions of a discrete roller set whose inner ring is free in x and y (two
    force equations per configuration). Written here independently of the simulator's kernels."""
    from scipy.optimize import root

    from bearingsim.laws import palmgren_stiffness

    g = si(scenario).bearing
    z, hp, load = g.roller_count, 0.5 * g.radial_clearance, si(scenario).operating.radial_load
    ks = palmgren_stiffness(g.roller_length) / 2.0 ** (10.0 / 9.0)  # inner and outer contact in series
    edge, guess = 0.0, np.array([0.0, hp + 4e-6])
    for psi0 in np.linspace(0.0, 2 * np.pi / z, samples, endpoint=False):
        psi = np.mod(psi0 + 2 * np.pi * np.arange(z) / z + np.pi, 2 * np.pi) - np.pi

        def q(d):
            return ks * np.clip(d[0] * np.sin(psi) + d[1] * np.cos(psi) - hp, 0.0, None) ** (10.0 / 9.0)

        def f(d):
            return [np.sum(q(d) * np.sin(psi)) / load, np.sum(q(d) * np.cos(psi)) / load - 1.0]

        sol = root(f, guess, method="hybr", options={"xtol": 1e-13})
        assert np.max(np.abs(f(sol.x))) < 1e-9  # force balance to 1e-9 of the load
        guess = sol.x
        edge = max(edge, np.degrees(np.abs(psi[q(sol.x) > 0.0])).max())
    return edge


def test_inner_race_contact_extent_matches_discrete_quasi_statics(full_3000):
    """The measured inner-race contact extends beyond the classical half angle: with 16 discrete rollers
    the inner ring, free sideways, shifts towards a roller leaving the zone (+-2 um) and keeps it loaded
    to ~27 deg. A quasi-static calculation of the same discrete bearing (independent code, above) gives
    the edge; +-1.5 deg covers the 1 deg bins of the time-mean load profile (1 % of its maximum is the
    cut) and the roller's play in its pocket and the dynamic loads."""
    edge = _discrete_contact_edge(full_3000.scenario)
    assert full_3000.summary["load_zone_contact_half_angle_deg"] == pytest.approx(edge, abs=1.5), edge


@pytest.mark.slow
def test_dynamic_inner_ring_agrees_with_quasi_static_where_both_apply(full_3000):
    """With 16 rollers at 970 N the load is always shared by >= 2 rollers, so a dynamic inner ring (the
    rotor's mass W/g) must carry the same mean load on the same mean displacement as the quasi-static
    one: the ring's momentum balance makes the time-mean contact reaction equal W. The dynamic ring
    (8 rotations) against ``full_3000`` (the quasi-static ring, 20 rotations).

    Tolerances from the scatter of the difference over 16 independent trajectories: pairs run with
    operating.radial_load_N = 970 + k * 0.00000097 (k = 0..15; a last-bits perturbation that only
    decorrelates the chaotic trajectories), each pair as here (``simulate(_scenario(rotations=20,
    extra=[load]))`` and ``simulate(_scenario(rotations=8, extra=["multibody.inner_ring=dynamic",
    load]))``), dynamic / quasi-static - 1:

    - mean displacement: -0.491 % +- 0.013 % (mean +- std; -0.510 .. -0.462 %), a systematic offset
      (Hertz nonlinearity under the ring's vibration shifts the mean slightly) that the scatter hardly
      moves; bound 0.6 % = offset + 8 std. A dynamic ring under 10 % less load (873 N) lies -1.12 % off
      and fails (the 2 % this test had let it pass); one carrying the rotor's weight twice (1940 N), +4.6 %.
    - mean I_dec: +1.90 % +- 0.48 % (+0.92 .. +2.56 %); bound 4 % = offset + 4.3 std (the 10 % this test
      had was reasoned from the per-rotation scatter, std/mean ~0.4, not measured on the means). Of the
      offset, +0.75 % +- 0.11 % (standard error, 8 trajectories: the quasi-static ring's first 8 rotations
      against its 20) is the start transient's larger share in 8 rotations than in 20; like with like,
      8 rotations each, the rings differ by +1.09 % +- 0.19 % (docs/stability.md). The
      ring carrying the rotor's weight twice gives -6.2 % and fails (the 10 % had let it pass).
    """
    sc = _scenario(rotations=8, extra=["multibody.inner_ring=dynamic"])
    r = simulate(sc)
    assert "dynamic" in r.provenance["inner_ring"]
    assert r.summary["inner_ring_displacement_m"] == pytest.approx(
        full_3000.summary["inner_ring_displacement_m"], rel=0.006, abs=0)
    assert r.per_rotation["I_dec"].mean() == pytest.approx(full_3000.per_rotation["I_dec"].mean(), rel=0.04)


@pytest.mark.parametrize("extra, ring", [
    ([], "quasi-static"),  # auto at 970 N: 3 rollers loaded
    (["multibody.inner_ring=dynamic"], "dynamic"),
    (["operating.radial_load_N=200"], "dynamic"),  # auto: one roller loaded
])
def test_the_inner_ring_series_says_which_ring_it_is(tmp_path, extra, ring):
    """/observables/inner_ring_centre@description said "quasi-static inner-ring centre (x, y)" for every run,
    a dynamic ring (given, or chosen by "auto") too, against the provenance's `inner_ring`: it names the ring
    the run had, in the result and in its archive."""
    r = simulate(_scenario(rotations=1, extra=extra))
    assert r.provenance["inner_ring"].startswith(ring)
    assert r.series["inner_ring_centre"].description == f"{ring} inner-ring centre (x, y)"
    with h5py.File(r.save(tmp_path / "r.h5"), "r") as f:
        assert f["observables/inner_ring_centre"].attrs["description"] == f"{ring} inner-ring centre (x, y)"


def test_inner_ring_auto_choice():
    """A ring resting on a single roller has no stable sideways equilibrium: "auto" keeps the massless
    quasi-static ring only when >= 2 rollers carry the load with one roller at the centre (16 rollers at
    970 N: 3 loaded), and makes it dynamic with the rotor's mass W/g otherwise (3 rollers: the
    neighbours at 120 deg can never be loaded; 16 rollers at 300 N: only the centre roller)."""
    from bearingsim.laws import loaded_rollers_with_one_at_centre as loaded
    from bearingsim.laws import STANDARD_GRAVITY
    from bearingsim.multibody.core import inner_ring_model

    g = si(_scenario()).bearing
    assert loaded(970.0, 16, g.roller_length, g.radial_clearance) == 3
    assert loaded(970.0, 3, g.roller_length, g.radial_clearance) == 1
    assert loaded(300.0, 16, g.roller_length, g.radial_clearance) == 1
    assert loaded(970.0, 16, g.roller_length, 0.0) == 7  # no clearance: every roller below the centre
    assert inner_ring_model(si(_scenario()))[0] == 0.0
    mass, how = inner_ring_model(si(_scenario(extra=["bearing.roller_count=3"])))
    assert mass == pytest.approx(970.0 / STANDARD_GRAVITY) and "dynamic" in how


@pytest.mark.slow
@pytest.mark.parametrize("rpm", [1000, 3000, 6000])
def test_reduced_equivalent_matches_event_model(rpm):
    """The reduced-equivalent scene makes the reduced model's assumptions (docs/physics.md), so its mean
    I_dec per no-load pass must equal the exact event solution within 2 % (issue)."""
    from bearingsim.reduced.core import PassInputs
    from bearingsim.reduced.event import solve_event

    sc = _scenario(rpm=rpm, scene="reduced_equivalent", rotations=1)
    ref = solve_event(PassInputs.from_parameters(si(sc))).I_dec
    r = simulate(sc)
    assert r.per_rotation["I_dec"].mean() == pytest.approx(ref, rel=0.02)


@pytest.mark.slow
def test_I_dec_converges_with_dt():
    """Time-step convergence of the deterministic reduced-equivalent scene at 3000 rpm, dt from 0.5x to 1/16x
    of the explicit Hertz limit: all four I_dec agree to 0.1 % (the accuracy goal of issue 3 is 1 %), and the
    last halving moves I_dec by less than 1e-4 of it. The scheme is first order at impacts (a new contact is
    detected one step late, overlap v dt), so the differences need not shrink at every single halving: a
    test that the last one be smaller than the first failed at cage_friction 0.05, inside its plausible
    range, with the steps agreeing better than at the default (differences 1.6e-7, 4.5e-7, 3.8e-7 N s).
    Measured at the default: 5.2717 / 5.2704 / 5.2693 / 5.2690 mN s, differences 1.3e-6, 1.1e-6, 2.3e-7 N s
    (4e-5 of I_dec last)."""
    sc = _scenario(rpm=3000, scene="reduced_equivalent", rotations=1)
    _, _, lim = choose_dt(si(sc))
    vals = [simulate(sc, dt=lim * f).per_rotation["I_dec"].mean() for f in (0.5, 0.25, 0.125, 0.0625)]
    assert np.ptp(vals) < 1e-3 * np.mean(vals), vals
    assert abs(vals[-1] - vals[-2]) < 1e-4 * np.mean(vals), vals


def test_dt_far_too_large_is_user_error():
    """A dt far above the Hertz stability limit is refused up front with a message naming the key."""
    from bearingsim.errors import UserError

    sc = _scenario(extra=["numerics.dt_s=1e-4"])
    with pytest.raises(UserError, match="numerics.dt_s"):
        simulate(sc)


@pytest.mark.parametrize("scenario, sets", [("multibody_3000rpm.toml", ["numerics.dt_s=1"]),
                                           ("paper_3000rpm.toml", ["reduced.method=euler", "numerics.dt_s=1"])])
def test_a_time_step_refused_before_the_run_names_the_scenario_file(capsys, scenario, sets):
    """The run's refusal of a step far above the stable one names the file and the --set that gave the
    step, as the scenario's own refusals do: one line, exit 2, nothing written."""
    from bearingsim.cli import main

    args = ["run", str(SCENARIOS / scenario), "--dry-run", "-q"] + [a for s in sets for a in ("--set", s)]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"bearingsim: error: {SCENARIOS / scenario} with numerics.dt_s=1: numerics.dt_s"), err


def test_the_rotations_cage_slip_and_load_zone_make_up_the_summarys(full_3000):
    """Each recorded cage rotation's own cage slip, 1 - 2 pi / (T_k omega_c), T_k from and to where the cage's
    travel crosses its ends, and load zone (of the ring's mean displacement over its steps). The summary's slip
    takes the recorded time in whole steps (its start and end each at a step), so 1 - R / sum_k 1 / (1 - slip_k)
    is the summary's within its resolution dt / t_rec (docs/archive.md); the summary's load zone (of the mean over
    every recorded step) lies within the rotations' and within 1e-3 deg of their mean (the ring moves by
    nanometres from rotation to rotation). Their batch means are the standard errors the tables print."""
    from bearingsim.stats import batch_sem, result_standard_errors

    r = full_3000
    slip, phi = r.per_rotation["cage_slip"], r.per_rotation["load_zone_half_angle"]
    assert slip.shape == phi.shape == (20,) and np.all(np.isfinite(slip)) and np.all(np.isfinite(phi))
    t_rec = 2 * math.pi * 20 / r.summary["cage_speed_mean_rad_s"]
    whole = 1.0 - len(slip) / np.sum(1.0 / (1.0 - slip))
    assert abs(whole - r.summary["cage_slip"]) < r.summary["dt_s"] / t_rec
    assert slip.min() < r.summary["cage_slip"] < slip.max()  # the rotations differ: a scatter to estimate from
    zone = r.summary["load_zone_half_angle_deg"]
    assert phi.min() <= zone <= phi.max() and abs(phi.mean() - zone) < 1e-3
    se = result_standard_errors(r)
    assert se["cage_slip_sem"] == batch_sem(slip) > 0 and se["load_zone_half_angle_sem_deg"] == batch_sem(phi) > 0


@pytest.mark.slow  # two kinematic-cage runs at an eighth of the step: 6 s
def test_a_kinematic_cages_rotations_take_the_epicyclic_period_to_round_off():
    """The kinematic cage turns at exactly the epicyclic speed, so each recorded rotation's time, taken from and to
    where the cage's travel crosses its ends within a step (linear in the step: exact for a constant speed),
    is 2 pi / omega_c to round-off (1e-9 relative; whole steps would be off by up to dt / T, 1e-5 here). Its
    archive has no per-rotation slip (nothing to measure: the summary's slip is its step resolution), and the
    scene without an inner ring gives its given load zone in every rotation: a standard error of 0."""
    from bearingsim.stats import result_standard_errors

    for scene in ("kinematic_cage", "reduced_equivalent"):
        r = simulate(_scenario(rotations=3, scene=scene))
        period = 2 * math.pi / si(r.scenario).operating.omega_c
        np.testing.assert_allclose(r.raw.rot_win[:, 0], period, rtol=1e-9)
        assert r.summary["dt_s"] / period > 1e-6  # whole steps could not do it
        assert "cage_slip" not in r.per_rotation and "cage_slip_sem" not in result_standard_errors(r)
    assert result_standard_errors(r)["load_zone_half_angle_sem_deg"] == 0.0
    assert np.all(r.per_rotation["load_zone_half_angle"] == PHI_DEG)


@pytest.mark.slow
def test_cli_main_job(tmp_path):
    """The README's main job writes an archive with the public names and units."""
    out = tmp_path / "mb.h5"
    res = subprocess.run([sys.executable, "-m", "bearingsim", "run", str(SCENARIOS / "multibody_6000rpm.toml"),
                          "-o", str(out), "--no-plots", "--set", "numerics.rotations=3"],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    sc = load_scenario(SCENARIOS / "multibody_6000rpm.toml", ["numerics.rotations=3"])
    with h5py.File(out) as f:
        assert f["/results/per_rotation/I_dec"].shape == (sc.numerics.rotations, 16)
        assert f["/results/per_rotation/I_dec"].attrs["unit"] == "N s"
        assert f["/results/per_rotation/I_acc"].shape == (sc.numerics.rotations, 16)
        s, su = archive.group_attrs(f["/results/summary"])
        for k in ("I_dec_mean_Ns", "I_dec_std_Ns", "I_acc_mean_Ns", "I_acc_std_Ns", "first_impact_speed_m_s",
                  "first_impact_energy_J", "cage_speed_mean_rad_s", "cage_slip", "load_zone_half_angle_deg"):
            assert k in s and k in su, k
        for col in ("time_s", "theta_deg", "approach_speed_m_s", "impulse_Ns", "pocket", "face", "rotation"):
            assert col in f["/results/impacts"]
        # each impact's rotation is a row of per_rotation, and per pocket it never goes back in time
        imp = {k: f["/results/impacts"][k][()] for k in ("time_s", "pocket", "rotation")}
        assert set(np.unique(imp["rotation"])) == set(range(sc.numerics.rotations))  # impacts in every rotation
        for p in range(16):
            sel = imp["pocket"] == p
            order = np.argsort(imp["time_s"][sel], kind="stable")
            assert np.all(np.diff(imp["rotation"][sel][order]) >= 0)
        assert f["/results/force_vs_theta"].shape == (360, 16)
        prov = archive.group_attrs(f["provenance"])[0]
        assert "dt_s" in prov and "dt_choice" in prov
        for k in ("paper_index_front", "paper_index_rear", "sliding_work_front", "sliding_work_rear"):
            assert f[f"/results/wear/{k}"].attrs["unit"] == "m^3"


TIGHT = ([], ["numerics.dt_s=1e-6"], ["multibody.raceway_contact=rigid"])


@pytest.mark.parametrize("extra", TIGHT)
def test_a_pocket_too_tight_for_the_assembled_bearing_is_refused_before_the_run_naming_the_clearance(extra):
    """Geometry, not time step: the rollers start on the outer race, P_d/4 = 20 um outside the pitch circle,
    in pockets centred on it, so a roller reaches into the rim end of its arc face (psi = +26.7 deg, the wall's
    end for this R = r + s/2) by (P_d/4) sin 26.7 deg - s/2 + O(delta^2 / R) = 6.45 um at s = 5 um, far above
    the 1 % of s allowed, before anything moves; no time step removes it, so the run refuses it before its first step (a UserError,
    exit 2), whatever the step or the raceways."""
    import bearingsim

    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml",
                       ["bearing.pocket_clearance_mm=0.005", "numerics.rotations=1", *extra])
    with pytest.raises(bearingsim.UserError) as err:
        simulate(sc)
    msg = str(err.value)
    assert "bearing.pocket_clearance_mm = 0.005 is too small" in msg and "numerics.dt_s <=" not in msg, msg
    # 6.45 um; 6.47 um with rigid raceways, whose rollers are not pressed into the race by their weight
    assert float(re.search(r"overlap a pocket face by (\S+) m", msg)[1]) == pytest.approx(6.46e-6, abs=0.02e-6)


@pytest.mark.slow
@pytest.mark.parametrize("path, extra, rel", [
    *((SCENARIOS / "multibody_3000rpm.toml", extra, 1e-3) for extra in TIGHT),
    (SCENARIOS / "multibody_3000rpm.toml", ["multibody.pocket_face_segments=8"], 5e-3),
    (SCENARIOS.parent / "tests" / "data" / "worn_stage05_rigid.toml", [], 1e-3),
], ids=["free", "given-step", "rigid", "polyline-8", "worn-stage-5"])
def test_the_assembled_overlap_is_the_overlap_the_first_step_finds(path, extra, rel):
    """core.assembly_overlap (the check before the run) against the simulator's own contact detection: the
    model run without the check stops in its first step (PenetrationExceeded) with the overlap it measured,
    which is the assembled one to 0.1 % (in one step of ~2e-6 s the bodies, moving with the cage, change
    their distance by ~g dt^2 ~ 4e-11 m, 1e-5 of it) on exact arcs, worn ones (a life study's stage 5, whose
    nearest point is inside the face, not at its worn rim end) and, to 0.5 %, a polyline of 8 segments
    (the nearest point of a chord found among 361 directions: 0.13 % short of it)."""
    from bearingsim.multibody import core

    p = si(load_scenario(path, ["bearing.pocket_clearance_mm=0.005", "numerics.rotations=1", *extra]))
    with pytest.raises(core.PenetrationExceeded) as err:
        core.run(p)
    assert err.value.t <= 1.5 * err.value.dt  # the first step
    assert core.assembly_overlap(p) == pytest.approx(err.value.pen, rel=rel, abs=0)


@pytest.mark.slow
@pytest.mark.parametrize("scenario", ["multibody_3000rpm.toml", "rig_1000rpm.toml"])
def test_the_tightest_pocket_the_check_passes_is_the_tightest_the_first_step_passes(scenario):
    """The clearance s* at which the assembled overlap is 1 % of s (found by root search on
    core.assembly_overlap) is the simulator's own bound: 3 % below it the model run without the check
    stops in its first step; 3 % above it the run completes (one warm-up and one recorded rotation). So the
    check refuses nothing the run would accept, and the free cage's and the rig's pockets (exact arcs of
    their own extents) both agree."""
    from scipy.optimize import brentq

    from bearingsim.multibody import core, simulate as model_run

    def params(s_mm):
        return si(load_scenario(SCENARIOS / scenario, [f"bearing.pocket_clearance_mm={s_mm!r}",
                                                        "numerics.rotations=1", "numerics.warmup_rotations=1"]))

    def excess(s_mm):
        p = params(s_mm)
        return core.assembly_overlap(p) - core.PENETRATION_LIMIT * p.bearing.pocket_clearance

    s_star = brentq(excess, 0.001, 0.2, xtol=1e-9)
    assert 0.01 < s_star < 0.03  # ~ (P_d/4) sin(psi_hi) / (1/2 + 1 %) = 17.5 um for P_d = 80 um
    with pytest.raises(core.PenetrationExceeded) as err:
        core.run(params(0.97 * s_star))
    assert err.value.t <= 1.5 * err.value.dt
    assert model_run(params(1.03 * s_star)).per_rotation["I_dec"].shape[0] == 1


@pytest.mark.slow
def test_pockets_that_pinch_their_most_loaded_roller_jam_and_say_so():
    """core.pinch: the most loaded roller (Stribeck's 5 W / Z plus its centrifugal load, 316 N at 970 N)
    pressed into the outer race by its Palmgren approach (0.88 um) reaches into the rim ends of its faces
    below a clearance s_free = 0.01866 mm on the reference bearing, where the roller at rest leaves a gap.
    The runs agree with that bound, which nothing was fitted to: 2 % below it the pockets jam (I_dec about
    ten times a roomy pocket's: 276 against 26.8 mN s at 3000 rpm, 1 rotation; bound 5x), 2 % above it
    I_dec is a free pocket's (28.9 mN s; bound 1.2x). Only the pinched run gets the note."""
    from scipy.optimize import brentq

    from bearingsim.multibody import core

    def scenario(s_mm):
        return load_scenario(SCENARIOS / "multibody_3000rpm.toml",
                             [f"bearing.pocket_clearance_mm={s_mm!r}", "numerics.rotations=1"])

    s_free = brentq(lambda s_mm: core.pinch(si(scenario(s_mm))) - 1e-15, 0.0176, 0.03, xtol=1e-9)
    assert s_free == pytest.approx(0.01866, abs=2e-5)
    roomy, pinched, free = (simulate(scenario(s)) for s in (0.03, 0.98 * s_free, 1.02 * s_free))
    assert pinched.summary["I_dec_mean_Ns"] > 5.0 * roomy.summary["I_dec_mean_Ns"]
    assert free.summary["I_dec_mean_Ns"] < 1.2 * roomy.summary["I_dec_mean_Ns"]
    assert [n for n in pinched.notes if "pinch their rollers" in n] and not [
        n for r in (roomy, free) for n in r.notes if "pinch" in n]



@pytest.mark.slow
def test_kinematic_cage_scene_is_converged_in_its_automatic_step():
    """The kinematic_cage scene (cross-check rung 3) pushes every roller from behind through the load zone, and
    its I_dec converges at first order in the step (at the full scene's Hertz step and below, 2 + 2 rotations at
    3000 rpm: 11.775 / 12.198 / 12.433 mN s at 4.0 / 2.0 / 1.0 us, +3.6 % and +1.9 % per halving,
    docs/multibody.md). Its automatic step is the
    Hertz step / 8: a halving must change I_dec by less than 1 %, what the full scene's automatic step keeps
    at 3000 and 6000 rpm (docs/multibody.md, *Its time step*: no halving's change resolved there, below about
    1.0 % and 0.5 %; measured here +0.51 %). The Hertz step would fail (+3.6 %). The scene is periodic (no scatter: docs/crosscheck.md), so
    the two runs differ by the step alone. 3000 rpm, the speed with the largest step error."""
    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml", [
        "multibody.scene=kinematic_cage", "numerics.warmup_rotations=2", "numerics.rotations=2"])
    from bearingsim.parameters import Parameters
    dt, how, _ = choose_dt(Parameters.from_scenario(sc))
    assert "kinematic cage" in how
    a = simulate(sc).summary["I_dec_mean_Ns"]
    b = simulate(sc, dt=0.5 * dt).summary["I_dec_mean_Ns"]
    assert abs(b / a - 1.0) < 0.01, (a, b)


def test_a_step_long_against_the_traction_relaxation_is_noted_where_the_cage_pushes_its_rollers():
    """plausibility._traction_step_note: the force kernel's implicit traction and pymunk's contact solve are split,
    which gives a face that holds a roller a force 1 / (1 + h / tau) of the exact one per step, tau = m slip_ref u /
    (2 mu_max Q) (core.traction_relaxation_time; u the rolling speed, so h / tau halves from 500 to 1000 rpm at the
    same step). The note needs both a step of 0.1 tau or more and a cage that pushes its rollers (a quarter of
    I_dec or more within the load zone's half angle; docs/multibody.md, *Its time step*: a heuristic gate between
    measured cases, h / tau 0.15-0.61 and shares 0.34-0.72 where the change to half the step is resolved, h / tau
    0.08 or a share of 0.00 where it is not or small): a crafted result with the same parameters gets it with 60 % of its rear-face force in the
    load zone and not with 10 %; a step of 0.08 tau (3000 rpm) does not; the kinematic cage (its step divided for
    the same split) and a run without traction never get it."""
    from types import SimpleNamespace

    from bearingsim.datatypes import NamedArray
    from bearingsim.multibody.core import automatic_step, traction_relaxation_time
    from bearingsim.parameters import Parameters
    from bearingsim.plausibility import _traction_step_note, load_zone_share

    def crafted(rpm, inside, *extra):
        p = Parameters.from_scenario(load_scenario(SCENARIOS / "multibody_3000rpm.toml", [
            f"operating.inner_ring_speed_rpm={rpm}", *extra]))
        theta = np.arange(360) + 0.5
        load_zone = (theta < 24.0) | (theta > 336.0)
        force = np.where(load_zone, inside / load_zone.sum(), (1.0 - inside) / (~load_zone).sum())
        data = {"results/theta_deg": NamedArray(theta, "deg"),
                "results/force_vs_theta_dec": NamedArray(np.repeat(force[:, None], 16, axis=1), "N")}
        h = automatic_step(p)
        result = SimpleNamespace(parameters=p, data=data, summary={"dt_s": h, "load_zone_half_angle_deg": 24.0})
        return result, h / traction_relaxation_time(p)

    ratios = [crafted(rpm, 0.6)[1] for rpm in (500, 1000, 2000, 3000, 6000)]
    assert [round(r, 2) for r in ratios] == [0.45, 0.23, 0.11, 0.08, 0.04]
    pushed, _ = crafted(1000, 0.6)
    assert load_zone_share(pushed) == pytest.approx(0.6, rel=1e-12)
    note = _traction_step_note(pushed)
    assert note and "60% of I_dec" in note and "of 0.23 of the traction's relaxation time" in note
    assert "--check-step" in note
    assert _traction_step_note(crafted(1000, 0.1)[0]) is None
    assert _traction_step_note(crafted(3000, 0.6)[0]) is None and _traction_step_note(crafted(2000, 0.6)[0])
    assert _traction_step_note(crafted(1000, 0.6, "multibody.raceway_contact=rigid")[0])  # h / tau 1.26
    assert _traction_step_note(crafted(500, 0.6, "multibody.scene=kinematic_cage")[0]) is None
    assert _traction_step_note(crafted(500, 0.6, "multibody.traction_mu_max=0")[0]) is None


@pytest.mark.slow
def test_the_reference_bearing_pushes_its_rollers_at_1000_rpm_and_not_at_2000():
    """What the note reads from a run (plausibility.load_zone_share): at 1000 rpm the cage runs ahead of its
    epicyclic speed (slip -0.41 %) and takes about half of I_dec within the load zone's half angle (0.51 in 2
    rotations), and the run gets the note; at 2000 rpm about a tenth (0.085) and no note, although its h / tau
    (0.17) is half of 1000 rpm's: the split costs little where the rollers run free of their rear faces
    (docs/multibody.md, *Its time step*: no step error resolved at 3000 and 6000 rpm)."""
    from bearingsim.plausibility import load_zone_share

    def run(rpm):
        return simulate(load_scenario(SCENARIOS / "multibody_3000rpm.toml", [
            f"operating.inner_ring_speed_rpm={rpm}", "numerics.rotations=2"]))

    slow, fast = run(1000), run(2000)
    assert load_zone_share(slow) > 0.4 and load_zone_share(fast) < 0.15
    assert [n for n in slow.notes if "pushes its rollers through the load zone" in n]
    assert not [n for n in fast.notes if "pushes its rollers" in n]
