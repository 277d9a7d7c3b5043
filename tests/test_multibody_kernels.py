"""Unit tests of the multibody model's compiled kernels: raceway force laws, ring balance, recording,
and the two step loops (compiled chipmunk calls and plain pymunk) giving the same numbers.

Each test states its source and why its tolerance is what it is.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from bearingsim import laws as kin
from bearingsim.multibody import chipmunk
from bearingsim.multibody import forces as fk
from bearingsim.multibody import recorder as rk
from bearingsim.multibody.core import run
from bearingsim.multibody.scene import pocket_angles
from bearingsim.reduced.core import FACE_FRONT, FACE_REAR
from bearingsim.scenario import load_scenario
from tests.conftest import SCENARIOS, si

ROLLER_LENGTH = 13e-3  # NU214-Suzuki2023 [m]
ROLLER_RADIUS = 6.5e-3  # [m]
ROLLER_MASS = 0.013  # [kg]
K = kin.palmgren_stiffness(ROLLER_LENGTH)


def _params(**over):
    """Raceway parameters of the reference bearing (no clearance), overridable by name."""
    p = dict(roller_radius=ROLLER_RADIUS, roller_mass=ROLLER_MASS, roller_inertia=0.5 * ROLLER_MASS * ROLLER_RADIUS**2,
             outer_race_radius=0.0555, inner_race_radius=0.0425, outer_race_geom_radius=0.0555,
             inner_race_geom_radius=0.0425, palmgren_stiffness=K, damping_time=2.5e-6, damping_fade=5e-9,
             traction_mu_max=0.05, traction_slip_ref=0.01, min_entrainment=0.1, drag_coefficient=0.0,
             drag_direction_eps=1e-3, omega_ring=0.0, radial_load=0.0, gravity=0.0, inner_ring=False,
             traction=False, spin_free=False, newton_max_step=2e-6, ring_mass=0.0)
    p.update(over)
    return fk.RacewayParams(**p)


# --- normal force ---------------------------------------------------------------------------------
@pytest.mark.parametrize("load", [10.0, 100.0, 1000.0, 5000.0])
def test_normal_force_is_palmgren_line_contact(load):
    """Harris & Kotzalas, Rolling Bearing Analysis (5th ed.), Eq. 6.49 in its usual engineering form
    ``delta = 3.84e-5 Q^0.9 / l^0.8`` [mm, N, mm]: at that approach and no approach rate the kernel's
    load is Q. Tolerance 0.2 %: the book's coefficient has three digits (3.84 +- 0.005, i.e. 0.13 % in
    delta, 0.145 % in Q = K delta^(10/9))."""
    delta = 3.84e-5 * load**0.9 / (ROLLER_LENGTH * 1e3) ** 0.8 * 1e-3
    q, _, _ = fk._normal_force(delta, 0.0, K, 2.5e-6, 5e-9)
    assert q == pytest.approx(load, rel=2e-3)


@pytest.mark.parametrize("delta, rate", [(1e-6, 0.0), (2e-6, 1e-3), (3e-9, 1e-4), (1e-5, -0.05)])
def test_normal_force_derivatives_match_finite_differences(delta, rate):
    """dQ/d(delta) and dQ/d(rate) of the kernel against central differences, inside (3 nm) and outside
    the damping fade. Step 1e-4 of the variable: truncation error ~1e-8 relative (Q is smooth on each
    side of the fade depth, which no step crosses), round-off ~1e-12; tolerance 1e-6."""
    c_r, fade = 2.5e-6, 5e-9
    q, dq_dd, dq_drate = fk._normal_force(delta, rate, K, c_r, fade)
    assert q > 0.0
    e = 1e-4 * delta
    fd = (fk._normal_force(delta + e, rate, K, c_r, fade)[0] - fk._normal_force(delta - e, rate, K, c_r, fade)[0]) / (2 * e)
    assert dq_dd == pytest.approx(fd, rel=1e-6)
    er = 1e-4 * max(abs(rate), 1e-3)
    fdr = (fk._normal_force(delta, rate + er, K, c_r, fade)[0] - fk._normal_force(delta, rate - er, K, c_r, fade)[0]) / (2 * er)
    assert dq_drate == pytest.approx(fdr, rel=1e-6)


def test_normal_force_is_zero_without_contact_and_continuous_at_contact():
    """No tension: Q = 0 for delta <= 0 and when damping would pull (Q >= 0). Continuity at delta = 0
    at any approach rate: inside the fade depth the damping force ``c_r k_lin (delta / d_fade) rate``
    grows like delta^(10/9), as the elastic force does, so Q -> 0 with delta as delta^(10/9) (ratio
    over a decade 10^(-10/9), to round-off: 1e-9)."""
    assert fk._normal_force(-1e-6, 1.0, K, 2.5e-6, 5e-9) == (0.0, 0.0, 0.0)
    assert fk._normal_force(1e-7, -1e3, K, 2.5e-6, 5e-9)[0] == 0.0
    q15 = fk._normal_force(1e-15, 1.0, K, 2.5e-6, 5e-9)[0]
    q16 = fk._normal_force(1e-16, 1.0, K, 2.5e-6, 5e-9)[0]
    assert q15 > 0.0 and q16 / q15 == pytest.approx(10.0 ** (-10.0 / 9.0), rel=1e-9)


# --- quasi-static inner ring ----------------------------------------------------------------------
def _ring_rollers(n, clearance_radial=0.0):
    """Roller centres [m] around the inner raceway, one at the bottom, symmetric about the y axis."""
    a = -0.5 * math.pi + 2.0 * math.pi * np.arange(n) / n
    r = 0.0425 + ROLLER_RADIUS + clearance_radial
    return np.ascontiguousarray(np.stack([r * np.cos(a), r * np.sin(a)], axis=1))


def test_ring_centre_balances_the_load_on_a_symmetric_set():
    """W = 970 N on 16 rollers without clearance, elastic only (no damping): the ring sinks straight
    down (x = 0 to round-off, 1e-15 m), the raceway loads sum to W along -y (Newton tolerance 1e-9 W),
    and the largest roller load is Stribeck's ``Q_max = 4.08 W / Z`` for line contact and zero
    clearance (Harris & Kotzalas, Sec. 7.2); 4.08 is Stribeck's rounded value for many rollers, so the
    discrete 16-roller set (7 rollers loaded; 4.084 here) is allowed 0.5 %."""
    n, load, h = 16, 970.0, 1e-6
    prm = _params(damping_time=0.0, radial_load=load, inner_ring=True)
    xp = _ring_rollers(n)
    c = np.zeros(2)
    it, res = fk.solve_ring_centre(xp, np.zeros(n), np.zeros(2), h, prm, c)
    assert it >= 0 and res <= 1e-9 * (load + 1.0)
    assert abs(c[0]) < 1e-15 and c[1] < 0.0
    d = xp - c
    dist = np.hypot(d[:, 0], d[:, 1])
    delta = np.clip(prm.inner_race_radius + ROLLER_RADIUS - dist, 0.0, None)
    q = K * delta ** (10.0 / 9.0)
    force = (q[:, None] * d / dist[:, None]).sum(axis=0)  # on the rollers, along the ring-to-roller normals
    assert force[1] == pytest.approx(-load, rel=1e-9)
    assert abs(force[0]) < 1e-9 * load
    assert q.max() == pytest.approx(4.08 * load / n, rel=0.005)


@pytest.mark.parametrize("load", [970.0, 10.0])
def test_ring_centre_converges_as_rollers_enter_and_leave_the_load_zone(load):
    """The quasi-static ring on 16 rollers turned on a circle 40 um outside the inner race (the reference
    bearing's radial clearance) under W = 970 N, 400 steps of 4 us at 250 rad/s (one roller pitch: every
    phase of a roller entering and leaving the load zone), with contact damping and the approach rate over
    each step, started from the elastic balance. Newton alone failed in 122 of these 401 solves (the elastic
    start among them, 302 N left): it cycles across the kink of a roller entering contact, as in the full
    scene's failing steps (docs/archive.md, ring_newton_failures). Every solve converges to its tolerance,
    1e-9 (W + 1 N), or, where the bracketing closes to adjacent floats, to the rounding of the force sum: at
    W = 10 N the tolerance (1.1e-8 N) is below what a contact closing at the damping fade's stiffness resolves
    (one ulp of a roller's 0.049 m distance, 6.9e-18 m, times ~3e8 N/m), and one of the 401 solves had ended
    there, rx flipping sign between adjacent floats (1e-7 N), counted as not converged. Where the returned
    residual exceeds the tolerance it is within that rounding (8 ulps times the contacts' stiffness)."""
    n, h, omega = 16, 4e-6, 250.0
    prm = _params(radial_load=load, inner_ring=True)
    r = prm.inner_race_radius + ROLLER_RADIUS + 40e-6
    a0 = -0.5 * math.pi + 2.0 * math.pi * np.arange(n) / n + 0.013

    def rollers(k):
        a = a0 + omega * h * k
        return np.ascontiguousarray(np.stack([r * np.cos(a), r * np.sin(a)], axis=1))

    x = rollers(0)
    c = np.array([0.0, -40e-6])
    it, res = fk.solve_ring_centre(x, np.zeros(n), c.copy(), h, prm._replace(damping_time=0.0), c)
    failed = [] if it >= 0 else [("start", res)]
    for k in range(400):
        xn = rollers(k + 1)
        delta_prev = prm.inner_race_radius + ROLLER_RADIUS - np.hypot(x[:, 0] - c[0], x[:, 1] - c[1])
        out = c.copy()
        it, res = fk.solve_ring_centre(xn, delta_prev, c, h, prm, out)
        if it < 0 or res > 1e-9 * (load + 1.0) + _rounding(xn, delta_prev, h, prm, out):
            failed.append((k, res))
        c, x = out, xn
    assert failed == [], f"{len(failed)} of 401 solves did not converge: {failed[:5]}"


def _rounding(xp, delta_prev, h, prm, c):
    """What rounding alone leaves of the ring's force sum at ``c`` [N]: 8 ulps of a roller's distance from the
    centre times the contacts' stiffness, summed here in numpy from the force law's own slopes."""
    d = np.hypot(xp[:, 0] - c[0], xp[:, 1] - c[1])
    delta = prm.inner_race_radius + ROLLER_RADIUS - d
    s = 0.0
    for i in np.flatnonzero(delta > 0.0):
        q, dq_dd, dq_drate = fk._normal_force(delta[i], (delta[i] - delta_prev[i]) / h, prm.palmgren_stiffness,
                                              prm.damping_time, prm.damping_fade)
        s += (dq_dd + dq_drate / h) if q > 0.0 else 0.0
    return 8.0 * s * np.finfo(float).eps * (prm.inner_race_radius + ROLLER_RADIUS)


# --- one roller on the outer race -----------------------------------------------------------------
def _orbiting_roller(omega, r0):
    state = np.zeros((2, 6))  # roller, cage (unused by the force kernel)
    state[0, 0] = r0
    state[0, 4] = omega * r0
    return state


@pytest.mark.slow
def test_roller_on_outer_race_carries_its_centrifugal_load():
    """A roller orbiting at omega on radius r0 presses on the outer race with its centrifugal load
    ``m r0 omega^2``: with the race placed so that the roller overlaps it by the Palmgren approach of that load,
    ``delta = (m r0 omega^2 / K)^0.9``, the kernel's contact force is the centripetal force, and the
    approach it reports is delta. With h = 1 ps the prediction ``x + h v`` moves the roller outward by
    r0 (omega h)^2 / 2 ~ 1e-21 m and the damping adds c_r k_lin r0 omega^2 h / 2 ~ 2e-6 N to the 57 N
    load: tolerance 1e-6."""
    omega, r0, h = 300.0, 0.04875, 1e-12
    qc = ROLLER_MASS * r0 * omega**2
    delta = (qc / K) ** 0.9
    prm = _params(outer_race_radius=r0 + ROLLER_RADIUS - delta)
    state = _orbiting_roller(omega, r0)
    out_f = np.zeros(6)
    diag = np.zeros(1, dtype=fk.DIAG)
    fk.raceway_forces(state, h, prm, np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(1, dtype=np.bool_), out_f, diag, np.zeros(1), np.zeros(1))
    assert diag[0]["delta_out"] == pytest.approx(delta, rel=1e-6, abs=0)
    assert diag[0]["q_out"] == pytest.approx(qc, rel=1e-6)
    # force on the roller: radially inward, magnitude m r0 omega^2 (no traction, drag, gravity)
    assert out_f[0] == pytest.approx(-qc, rel=1e-6)
    assert abs(out_f[1]) < 1e-6 * qc


# --- rigid raceways: the outer race's part in the force kernel ------------------------------------
RC = 0.04877  # roller-centre radius on the outer race [m]
G = 9.81


def _rigid_roller(radius, v_radial, h):
    """The force kernel's radial force on one roller at the bottom of the bearing (gravity outward), at
    ``radius`` from the axis moving outward at ``v_radial``; returns (total radial force on the roller,
    pymunk's gravity included [N, outward +], n_held [N])."""
    prm = _params(rigid=True, rigid_radius=RC, gravity=G)
    state = np.zeros((2, 6))
    state[0, 1] = -radius
    state[0, 4] = -v_radial
    out_f = np.zeros(6)
    n_held = np.zeros(1)
    fk.raceway_forces(state, h, prm, np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(1, dtype=np.bool_), out_f,
                      np.zeros(1, dtype=fk.DIAG), np.zeros(1), n_held)
    return -(out_f[1] - ROLLER_MASS * G), n_held[0]


def test_rigid_race_carries_the_outward_load_of_a_roller_on_it():
    """A roller resting on the outer race with an outward load (here its weight, at the bottom): the race
    takes the whole load in the step, so the roller gets no outward speed (a slide joint exactly at its
    length is slack in chipmunk, and the load would throw the roller off the race by F h / m), and the
    race's share is the load (it adds to the joint's in the normal force for traction). Exact to rounding."""
    f, held = _rigid_roller(RC, 0.0, 1e-5)
    assert abs(f) < 1e-12 and held == pytest.approx(ROLLER_MASS * G, rel=1e-12, abs=0)


@pytest.mark.parametrize("gap", [1e-12, 1e-9, 1e-7])
def test_rigid_race_lets_a_near_roller_land_on_it_not_through_it(gap):
    """A roller ``gap`` inside the circle, at rest, under a load that would carry it through the race
    within a step (g h^2 >> gap at h = 1 ms): it keeps only the force that brings it onto the circle at
    the next position update, ``m gap / h^2`` (relative 1e-9: rounding of radii ~0.05 m against gaps down
    to 1e-12 m shows at 1e-5 of the gap), and the race takes the rest."""
    h = 1e-3
    f, held = _rigid_roller(RC - gap, 0.0, h)
    assert f == pytest.approx(ROLLER_MASS * gap / h**2, rel=1e-5, abs=1e-12)
    assert f + held == pytest.approx(ROLLER_MASS * G, rel=1e-9)


def test_rigid_race_leaves_a_lifted_roller_its_whole_load():
    """A roller 1 mm inside the circle (the cage lifted it): the race is not reached within the step and
    takes nothing; the roller falls back under its whole load. Exact to rounding."""
    f, held = _rigid_roller(RC - 1e-3, 0.0, 1e-5)
    assert f == pytest.approx(ROLLER_MASS * G, rel=1e-12, abs=0) and held == 0.0


def test_rigid_race_gives_back_the_joints_correction_speed():
    """A roller the joint put back from u = 1 um outside the circle leaves that step with the correction
    speed u / h inward in its real velocity (chipmunk's joints correct through velocities), plus here
    0.5 u / h of its own. Where the joint is then slack the kernel gives the correction back (the race is
    plastic: the roller is put back, not thrown off): the force m (u / h) / h outward, on top of the load
    the race does not take. Relative 1e-6 (the outward load is 1e-7 of the give-back; its share is
    checked in the sum)."""
    u, h = 1e-6, 1e-5
    f, held = _rigid_roller(RC + u, -1.5 * u / h, h)
    give_back = ROLLER_MASS * u / h**2
    assert f == pytest.approx(give_back + ROLLER_MASS * G, rel=1e-9)
    assert held == pytest.approx(-give_back, rel=1e-9)


@pytest.mark.parametrize("spin", [200.0, -200.0])
def test_traction_opposes_slip(spin):
    """A roller spinning on the fixed outer race without orbiting slides at ``-omega r_r`` along the
    tangent T; the traction force along T and its torque must both oppose that sliding (they take
    power out of it). At this slip (200 slip_ref) tanh is 1 to machine precision, so the magnitudes are
    ``mu_max Q`` and ``r_r mu_max Q`` (tolerance 1e-9; the implicit velocity Jacobian vanishes where
    tanh is saturated)."""
    r0, h = 0.04875, 1e-7
    qc = 50.0
    delta = (qc / K) ** 0.9
    prm = _params(outer_race_radius=r0 + ROLLER_RADIUS - delta, traction=True, spin_free=True)
    state = np.zeros((2, 6))
    state[0, 0] = r0
    state[0, 5] = spin
    out_f = np.zeros(6)
    diag = np.zeros(1, dtype=fk.DIAG)
    fk.raceway_forces(state, h, prm, np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(1, dtype=np.bool_), out_f, diag, np.zeros(1), np.zeros(1))
    q = diag[0]["q_out"]
    # outer contact at +x: N = (-1, 0), T = rot90(N) = (0, -1); roller surface slides at s = -omega r_r along T
    slide = -spin * ROLLER_RADIUS
    f_t = -out_f[1]
    torque = out_f[2]
    assert f_t * slide < 0.0 and torque * spin < 0.0
    assert abs(f_t) == pytest.approx(prm.traction_mu_max * q, rel=1e-9)
    assert abs(torque) == pytest.approx(ROLLER_RADIUS * prm.traction_mu_max * q, rel=1e-9)
    assert np.sign(diag[0]["slip_out"]) == np.sign(slide)


@pytest.mark.parametrize("off", [-0.005, 0.002, 0.01, 0.025])
def test_traction_follows_its_tanh_curve_below_saturation(off):
    """The traction law mu(slip) = mu_max tanh(slip / slip_ref) (the shape of measured EHL traction curves,
    Johnson & Tevaarwerk 1977) where the cage works, slip of the order of slip_ref: the test above holds it
    only at 200 slip_ref, where tanh is 1, so a slip_ref taken twice passed every test. A roller orbiting at
    v = 5 m/s on the fixed outer race, its spin ``off`` (fraction) beyond pure rolling, one contact of
    :func:`_contact` (no implicit correction): the slip is the sliding speed over the entrainment speed (the
    mean surface speed relative to the orbiting contact point), computed here by hand, and the traction along
    the tangent and its torque are mu Q. Tolerance 1e-12 (the same floating-point formula)."""
    prm = _params(traction=True, spin_free=True, traction_slip_ref=0.01, traction_mu_max=0.05)
    r0, v = 0.04875, 5.0
    orbit = v / r0
    w = -(v / ROLLER_RADIUS) * (1.0 + off)  # pure rolling on the outer race at off = 0: -v - w r_r = 0
    delta = (50.0 / K) ** 0.9  # Q = 50 N at no approach rate
    f, jac = np.zeros(3), np.zeros((3, 3))
    q, _, slip, _ = fk._contact(r0, 0.0, 0.0, v, w, -1.0, 0.0, delta, 0.0, 0.0, 0.0, prm.outer_race_geom_radius,
                                0.0, orbit, prm, jac, f)
    # contact at +x: N = (-1, 0), T = rot90(N) = (0, -1); the roller's surface slides along T at -v - w r_r
    sliding = -v - w * ROLLER_RADIUS
    entrainment = 0.5 * (abs(w - orbit) * ROLLER_RADIUS + abs(orbit) * prm.outer_race_geom_radius)
    assert q == pytest.approx(50.0, rel=1e-12, abs=0) and slip == pytest.approx(sliding / entrainment, rel=1e-12, abs=0)
    assert abs(slip / prm.traction_slip_ref) < 3.0  # below saturation: tanh(3) = 0.995
    mu = prm.traction_mu_max * math.tanh(slip / prm.traction_slip_ref)
    assert -f[1] == pytest.approx(-mu * q, rel=1e-12, abs=0)  # the force along T opposes the sliding
    assert f[2] == pytest.approx(ROLLER_RADIUS * mu * q, rel=1e-12, abs=0)  # torque -r_r (-mu Q)


# --- recording ------------------------------------------------------------------------------------
N_POCKETS = 4
IDS = np.array([10, 11, 12, 13, 20], dtype=np.uint64)  # rollers 0..3, cage


def _cfg():
    return rk.RecorderConfig(sign=1.0, roller_count=N_POCKETS, warmup_rotations=0.0, rotations=1, theta_bins=360,
                             impact_speed_threshold=0.01)


def _record(arbiters, prev, now, t=1e-3, h=1e-6):
    """Run record_step on a list of (id_a, id_b, impulse on A, normal A->B, point A, point B, overlap)."""
    arb_f = np.zeros(rk.ARB_F * len(arbiters))
    arb_i = np.zeros(rk.ARB_I * len(arbiters), dtype=np.uint64)
    for k, (ida, idb, jimp, nrm, pa, pb, pen) in enumerate(arbiters):
        arb_f[k * rk.ARB_F:(k + 1) * rk.ARB_F] = [*jimp, *nrm, *pa, *pb, -pen]
        arb_i[k * rk.ARB_I:(k + 1) * rk.ARB_I] = [ida, idb, 1]
    order = np.argsort(IDS)
    acc = rk.accumulators(1, N_POCKETS, 360, 16)
    pocket_a = pocket_angles(N_POCKETS, 1)
    theta0 = np.mod(-2.0 * math.pi * np.arange(N_POCKETS) / N_POCKETS, 2.0 * math.pi)
    n_imp = rk.record_step(arb_f, arb_i, len(arbiters), IDS[order], order.astype(np.int64), prev, now, t, h, _cfg(),
                           pocket_a, theta0, np.zeros(N_POCKETS, dtype=fk.DIAG), acc, 0,
                           np.zeros(N_POCKETS, dtype=np.bool_))
    return acc, n_imp


def _pocket0_states(v_rel):
    """Cage at rest at the origin; roller 0 in pocket 0 (bottom, e_t = +x) moving at v_rel along +x."""
    st = np.zeros((N_POCKETS + 1, 6))
    st[0, 0:2] = (0.0, -0.04875)
    st[0, 3] = v_rel
    return st, st.copy()


# pocket 0 sits at the bottom; the cage turns counter-clockwise (sign +1), so e_t there is +x
J, JT, V = 2e-4, 3e-5, 0.2
FRONT_CONTACT = ((1.0, 0.0), (ROLLER_RADIUS, -0.04875), (ROLLER_RADIUS, -0.04875))  # normal roller -> cage, points
REAR_CONTACT = ((-1.0, 0.0), (-ROLLER_RADIUS, -0.04875), (-ROLLER_RADIUS, -0.04875))


@pytest.mark.slow
@pytest.mark.parametrize("roller_is_a", [True, False])
def test_front_face_impulse_is_I_acc(roller_is_a):
    """A roller moving ahead (+e_t) into the front face pushes the cage forward: the cage receives
    J along e_t, which counts as I_acc = J (normal impulse J, friction |JT|), not as I_dec, and the
    impact row says front face, pocket 0, theta 0, approach speed V. The arbiter's total impulse is the
    one applied to body A (chipmunk's cpArbiterTotalImpulse), its normal points from A to B; the answer
    must not depend on which body pymunk lists first. Exact arithmetic on these values: 1e-15."""
    nrm, pr, pc = FRONT_CONTACT
    on_roller = (-J, -JT)  # normal impulse on the roller along -n, friction impulse along -y
    if roller_is_a:
        arb = (10, 20, on_roller, nrm, pr, pc, 1e-6)
    else:
        arb = (20, 10, (-on_roller[0], -on_roller[1]), (-nrm[0], -nrm[1]), pc, pr, 1e-6)
    prev, now = _pocket0_states(V)
    acc, n_imp = _record([arb], prev, now)
    w = acc.win[0, 0]
    assert w["I_acc"] == pytest.approx(J, abs=1e-15) and w["I_dec"] == 0.0
    assert w["Jn_front"] == pytest.approx(J, abs=1e-15) and w["Jn_rear"] == 0.0
    assert w["Jf_front"] == pytest.approx(JT, abs=1e-15)
    assert acc.f_bin[0]["front"].sum() == pytest.approx(J, abs=1e-15) and acc.f_bin[0]["rear"].sum() == 0.0
    assert acc.glob[0]["maxpen_front"] == pytest.approx(1e-6, rel=1e-6, abs=0) and acc.glob[0]["maxpen_rear"] == 0.0
    assert n_imp == 1
    row = acc.impacts[0]
    assert row["face"] == FACE_FRONT and row["pocket"] == 0 and row["rotation"] == 0
    assert row["theta_deg"] == pytest.approx(0.0, abs=1e-12)
    assert row["approach_speed"] == pytest.approx(V, abs=1e-15)
    assert row["impulse"] == pytest.approx(J, abs=1e-15)
    assert np.all(acc.win[0, 1:]["I_acc"] == 0.0)


def test_rear_face_impulse_is_I_dec():
    """A roller lagging (-e_t) against the rear face is pulled forward by the cage: the cage receives J
    along -e_t, which counts as I_dec = +J on the rear face (and is the first rear impact of the
    rotation, since theta = 0 < 180 deg). Exact: 1e-15."""
    nrm, pr, pc = REAR_CONTACT
    prev, now = _pocket0_states(-V)
    acc, n_imp = _record([(10, 20, (J, 0.0), nrm, pr, pc, 2e-6)], prev, now)
    w = acc.win[0, 0]
    assert w["I_dec"] == pytest.approx(J, abs=1e-15) and w["I_acc"] == 0.0
    assert w["Jn_rear"] == pytest.approx(J, abs=1e-15) and w["Jn_front"] == 0.0
    assert acc.f_bin[0]["rear"].sum() == pytest.approx(J, abs=1e-15)
    assert acc.glob[0]["maxpen_rear"] == pytest.approx(2e-6, rel=1e-6, abs=0)
    assert n_imp == 1 and acc.impacts[0]["face"] == FACE_REAR
    assert acc.first_imp[0, 0] == pytest.approx(V, abs=1e-15)


def test_slow_contacts_are_chatter_and_empty_arbiters_are_skipped():
    """A contact approaching below the 0.01 m/s threshold is chatter, not an impact, but its impulse
    still counts; an arbiter with contact count 0 (cached, separated) adds nothing."""
    nrm, pr, pc = FRONT_CONTACT
    prev, now = _pocket0_states(0.005)
    acc, n_imp = _record([(10, 20, (-J, 0.0), nrm, pr, pc, 0.0)], prev, now)
    assert n_imp == 0 and acc.glob[0]["n_chatter"] == 1.0
    assert acc.glob[0]["chatter_vmax"] == pytest.approx(0.005, abs=1e-15)
    assert acc.win[0, 0]["I_acc"] == pytest.approx(J, abs=1e-15)
    arb_f = np.zeros(rk.ARB_F)
    arb_f[0:4] = (-J, 0.0, 1.0, 0.0)
    arb_i = np.array([10, 20, 0], dtype=np.uint64)
    acc0 = rk.accumulators(1, N_POCKETS, 360, 16)
    order = np.argsort(IDS)
    rk.record_step(arb_f, arb_i, 1, IDS[order], order.astype(np.int64), prev, now, 1e-3, 1e-6, _cfg(),
                   pocket_angles(N_POCKETS, 1), np.zeros(N_POCKETS), np.zeros(N_POCKETS, dtype=fk.DIAG), acc0, 0,
                   np.zeros(N_POCKETS, dtype=np.bool_))
    assert acc0.win["I_acc"].sum() == 0.0 and acc0.glob[0]["n_chatter"] == 0.0


@pytest.mark.parametrize("sign", [1, -1])
def test_pocket_theta_advances_with_cage_travel(sign):
    """theta of pocket i is ``(travel - 2 pi i / n) mod 2 pi`` with travel = sign x cage angle: 0 at the
    load-zone centre (the bottom) for pocket 0 at the start, growing in the direction of rotation for
    either direction (round-off of angles of a few rad: 1e-12)."""
    n = 16
    pa = pocket_angles(n, sign)
    for travel in (0.0, 0.3, 2.0, 7.5):
        for i in range(n):
            th = rk.pocket_theta(float(sign), sign * travel, pa[i])
            expected = (travel - 2.0 * math.pi * i / n) % (2.0 * math.pi)
            diff = (th - expected + math.pi) % (2.0 * math.pi) - math.pi  # 0 and 2 pi are the same angle
            assert 0.0 <= th < 2.0 * math.pi and abs(diff) < 1e-12


# --- the two step loops ---------------------------------------------------------------------------
COMPARED = ("steps", "t_end", "t_record", "win", "first_imp", "f_bin", "t_bin", "q_bin", "tq_bin", "glob", "impacts",
            "final_state", "orbit", "ring_centre_mean", "cage_w_start", "cage_w_end", "newton_failures", "orbit_max",
            "lift_max", "beyond_max", "beyond_before", "beyond_vr")


def _assert_same_bytes(a, b):
    """Every compared result of two runs is the same bytes."""
    for key in COMPARED:
        x, y = np.asarray(getattr(a, key)), np.asarray(getattr(b, key))
        assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), key


def _same_bytes_without(probe, says, sc, monkeypatch):
    """Run ``sc`` in the compiled loop with ``chipmunk.<probe>`` passing (its shortcut taken), then with it
    failing: the second run's loop reason says ``<says> (...)``, the first's does not, and the two runs
    are the same bytes. Returns the first run's results."""
    assert getattr(chipmunk, probe)() is None
    taken = run(si(sc), step_loop="compiled")
    assert says not in taken.step_loop_reason
    monkeypatch.setattr(chipmunk, probe, lambda: "a layout the probe did not find")
    without = run(si(sc), step_loop="compiled")
    assert f"{says} (a layout the probe did not find)" in without.step_loop_reason
    _assert_same_bytes(taken, without)
    return taken


@pytest.mark.skipif(chipmunk.guard() is not None, reason="the compiled loop cannot run with this pymunk")
@pytest.mark.parametrize("scenario, extra", [("multibody_3000rpm", []), ("multibody_reduced_equivalent_3000rpm", []),
                                             ("multibody_3000rpm", ["multibody.raceway_contact=rigid"]),
                                             ("../tests/data/worn_stage05_rigid", [])])
@pytest.mark.slow
def test_plain_pymunk_loop_gives_the_compiled_numbers_bit_for_bit(scenario, extra):
    """The plain loop (``Space.step`` and ``pymunk.batch``) calls the same kernels on the same inputs as
    the compiled one, so every accumulator, the impact table and the final state are identical bytes
    (one rotation, no warm-up: ~11 500 steps, a few hundred impacts). With rigid raceways the plain loop
    reads the joints' impulses through ``Constraint.impulse``, the compiled one through
    ``cpConstraintGetImpulse``: the same numbers. Worn faces (a life study's stage, tests/data) too."""
    sc = load_scenario(SCENARIOS / f"{scenario}.toml", ["numerics.rotations=1", "numerics.warmup_rotations=0", *extra])
    compiled = run(si(sc), step_loop="compiled")
    plain = run(si(sc), step_loop="plain")
    assert (compiled.step_loop, plain.step_loop) == ("compiled", "plain")
    assert len(compiled.impacts) > 0
    _assert_same_bytes(compiled, plain)


@pytest.mark.skipif(chipmunk.guard() is not None, reason="the compiled loop cannot run with this pymunk")
@pytest.mark.parametrize("scenario, extra", [("multibody_3000rpm", ["multibody.raceway_contact=rigid"]),
                                             ("multibody_reduced_equivalent_3000rpm", [])])
def test_direct_body_writes_give_the_batched_setter_s_numbers(scenario, extra, monkeypatch):
    """The compiled loop writes forces, positions and velocities straight into each ``cpBody``; where
    the probe finds another struct layout it uses pymunk's batched setter and says so in the loop's
    reason. Both give the same bytes (rigid raceways and the reduced-equivalent scene set positions and
    velocities, not only forces). With the installed pymunk the layout holds and the direct writes run."""
    sc = load_scenario(SCENARIOS / f"{scenario}.toml", ["numerics.rotations=1", "numerics.warmup_rotations=0", *extra])
    _same_bytes_without("body_layout", "bodies set through pymunk's batched setter", sc, monkeypatch)


@pytest.mark.skipif(chipmunk.guard() is not None, reason="the compiled loop cannot run with this pymunk")
@pytest.mark.parametrize("scenario, extra", [("multibody_6000rpm", ["multibody.raceway_contact=rigid"]),
                                             ("multibody_3000rpm", ["multibody.flat_pockets=[0, 5]"]),
                                             ("multibody_reduced_equivalent_3000rpm", [])])
def test_narrowed_face_masks_change_no_number(scenario, extra, monkeypatch):
    """The compiled loop narrows each roller's collision mask, before each step, to the face segments it
    can touch in that step (``loop.face_masks``); chipmunk then skips the narrow-phase tests of the
    others. A segment left out could not have touched the roller, so every number is the same bytes as
    with the full masks (rigid raceways, flat pockets, the held rollers of the reduced-equivalent scene).
    The plain loop never narrows them: ``test_plain_pymunk_loop_gives_the_compiled_numbers_bit_for_bit``
    checks the same from the other side."""
    sc = load_scenario(SCENARIOS / f"{scenario}.toml", ["numerics.rotations=1", "numerics.warmup_rotations=0", *extra])
    narrowed = _same_bytes_without("mask_layout", "face masks not narrowed", sc, monkeypatch)
    assert len(narrowed.impacts) > 0


@pytest.mark.skipif(chipmunk.guard() is not None, reason="the compiled loop cannot run with this pymunk")
@pytest.mark.parametrize("extra", [[], ["multibody.scene=reduced_equivalent"], ["bearing.cage_guidance=inner_land"]])
def test_joints_solved_outside_pymunk_change_no_number(extra, monkeypatch):
    """Rigid raceways: the joint of a roller that touches nothing in a step (empty mask) is left slack in
    pymunk and solved after the step by ``chipmunk.joint_solve``, chipmunk's own arithmetic for a body
    held by a slide joint alone. Every number is the same bytes as with every joint in pymunk's solve
    (the full scene with its start phase, whose change of step size scales the cached
    impulses; the reduced-equivalent scene; a land-guided cage). At 3000 rpm: the automatic step (17.8 us)
    is longer than the start phase's (16 us), so the run has a start phase (at 6000 rpm its 14 us is not)."""
    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["numerics.rotations=1", "numerics.warmup_rotations=0",
                                                               "multibody.raceway_contact=rigid", *extra])
    own = _same_bytes_without("joint_layout", "every joint left to pymunk", sc, monkeypatch)
    assert len(own.impacts) > 0 and own.setup.t_start > 0.0


def test_joint_solve_is_chipmunk_s_slide_joint_bit_for_bit():
    """``chipmunk.joint_solve`` against pymunk stepping a body on a slide joint alone: on the circle moving
    along it (taut, warm-started from the last step's impulse), at a new step size (cached impulse scaled
    by h / h_prev), pulled off (slack: no impulse) and pushed back out (taut again): the same velocity and
    accumulated impulse to the last bit, with the impulse pymunk reports. (``chipmunk.joint_layout`` runs
    this once per process before the compiled loop uses it.)"""
    import pymunk

    anchor = pymunk.Body(body_type=pymunk.Body.STATIC)
    space = pymunk.Space()
    space.iterations = 10
    space.gravity = (0.0, -9.81)
    b = pymunk.Body(0.05, 1e-6)
    b.position = (0.061, 0.0)
    b.velocity = (0.0, 7.0)
    j = pymunk.SlideJoint(anchor, b, (0.0, 0.0), (0.0, 0.0), 0.0, 0.061)
    j.error_bias = 0.0
    space.add(b, j)
    prev_h, jn, taut, slack = 0.0, 0.0, 0, 0
    steps = [(1.7e-5, (2.0, 0.5))] * 5 + [(1.2e-5, (0.0, 0.0))] * 3 + [(1.2e-5, (-900.0, 0.0))] + [(1.2e-5, (900.0, 9.0))] * 3
    for h, force in steps:
        b.force = force
        v0 = b.velocity
        space.step(h)
        m_inv = 1.0 / 0.05
        vx = v0.x + (0.0 + force[0] * m_inv) * h
        vy = v0.y + (-9.81 + force[1] * m_inv) * h
        got = chipmunk.joint_solve.py_func(b.position.x, b.position.y, vx, vy, m_inv, 0.061, h,
                                           0.0 if prev_h == 0.0 else h / prev_h, jn, 10)
        assert got[0] == b.velocity.x and got[1] == b.velocity.y and abs(got[2]) == j.impulse
        prev_h, jn = h, got[2]
        taut += got[2] != 0.0
        slack += got[2] == 0.0
    assert taut >= 9 and slack >= 1


def _one_pocket_masks(q, vb_roller=(0.0, 0.0), cage_angle=0.0, cage_w=0.0, h=1e-5, n_seg=5):
    """face_masks for a 4-pocket scene with the roller of pocket 0 at ``q`` (cage frame, relative to its
    pocket centre, after the step's position update), the cage at the origin turned by ``cage_angle``;
    ``n_seg`` = 0: exact faces, placed by ``arc_faces`` for the step first, as the compiled loop does."""
    from types import SimpleNamespace

    from bearingsim.multibody import loop as lp
    from bearingsim.multibody.core import arc_faces, face_geometry
    from bearingsim.multibody.scene import build_scene

    geo = SimpleNamespace(roller_count=4, roller_radius=0.01, pitch_radius=0.05, pocket_clearance=0.001,
                          roller_mass=0.1, roller_inertia=1e-5, cage_mass=1.0, cage_inertia=1e-3)
    op = SimpleNamespace(sign=1, gravity=0.0, omega_c=0.0, omega_r=0.0)
    sc = build_scene(geo, op, 0.5, 0.1, extent=(-math.radians(45.0), math.radians(45.0)), n_seg=n_seg,
                     kinematic_cage=False, spin_free=True)
    fm = face_geometry(sc, 0.01, lp.MASK_MARGIN_M)
    a1 = cage_angle + cage_w * h  # where the position update turns the cage
    c, s = math.cos(a1), math.sin(a1)
    p_cage = sc.pocket_centres[0] + np.asarray(q)  # cage frame
    p_world = np.array([c * p_cage[0] - s * p_cage[1], s * p_cage[0] + c * p_cage[1]])
    state = np.zeros((5, 6))
    for i in range(1, 4):  # the other rollers at their pocket centres (turned with the cage)
        x, y = sc.pocket_centres[i]
        state[i, 0:2] = (c * x - s * y, s * x + c * y)
    # positions before the step, such that p + (v + v_bias) h lands where wanted
    vb = np.zeros((5, 3))
    vb[0, 0:2] = vb_roller
    state[0, 3:5] = (0.2, -0.1)
    state[0, 0:2] = p_world - (state[0, 3:5] + vb[0, 0:2]) * h
    state[4, 2] = cage_angle
    state[4, 5] = cage_w
    ends = sc.face_segments[:, :2, :].copy() if n_seg == 0 else np.zeros((4, 2, 4))
    if n_seg == 0:
        lp.arc_faces.py_func(state, h, arc_faces(sc, 0.01, 1), ends, np.zeros((4, 2), dtype=np.bool_))
    want = np.zeros(4, dtype=np.uint32)
    lp.face_masks.py_func(state, vb, h, fm, ends, want)
    return want, sc


def test_face_masks_keep_exactly_the_segments_within_reach():
    """face_masks against the geometry (R = r + s/2 = 10.5 mm, 5 segments a face, 18 deg each; the
    central segment of the front face is tangent to the arc at R along e_t): a roller centred in its
    pocket touches nothing (mask 0); pressed 1 um into the central front segment it has that segment's
    bit and no other (the neighbouring segments bend away from it); 1 um short of it, nothing; the same contact
    reached through a bias velocity, or with the cage turned and turning, is found the same way. The
    other rollers, centred, have 0."""
    from bearingsim.multibody.scene import segment_bit

    e_t0 = np.array([1.0, 0.0])  # pocket 0 sits at the bottom: its front (e_t, sign +1) is +x
    centre, _ = _one_pocket_masks((0.0, 0.0))
    assert centre.tolist() == [0, 0, 0, 0]
    gap = 0.0005  # s / 2: the roller touches the front face when moved by it along e_t
    into, _ = _one_pocket_masks(tuple((gap + 1e-6) * e_t0))
    assert into[0] == segment_bit(0, 2, 5) and into[1:].tolist() == [0, 0, 0]
    short, _ = _one_pocket_masks(tuple((gap - 1e-6) * e_t0))
    assert short[0] == 0
    rear, _ = _one_pocket_masks(tuple(-(gap + 1e-6) * e_t0))
    assert rear[0] == segment_bit(1, 2, 5)
    by_bias, _ = _one_pocket_masks(tuple((gap + 1e-6) * e_t0), vb_roller=(3.0, -1.0))
    assert by_bias[0] == segment_bit(0, 2, 5)
    turned, _ = _one_pocket_masks(tuple((gap + 1e-6) * e_t0), cage_angle=0.7, cage_w=300.0)
    assert turned[0] == segment_bit(0, 2, 5)


def test_face_masks_keep_only_the_exact_face_within_reach():
    """Exact faces: each face's one segment is placed on the arc's tangent nearest the roller
    (``arc_faces``), and the mask keeps a face only when that segment is within reach (R = 10.5 mm, faces
    +-45 deg). Pressed 1 um into the front arc at 20 deg from its middle: the front face's bit alone;
    1 um short of it: nothing; against the rear arc: the rear's alone; moved 1.5 x the play straight out
    along the pocket's radius, beyond both faces' extent (the cage wall there is open): nothing, so a
    rigid-raceway roller there leaves its joint to ``joint_solve``; further out it meets both faces' outer
    edges (R at +-45 deg), where |d e_r - R u(45 deg)| = r: d = R sin45 - sqrt(r^2 - R^2 cos^2 45) = 0.727 mm,
    checked at 0.98 and 1.02 d. The first and the last but one fail if the exact faces keep both bits
    whenever the roller is off its pocket centre."""
    from bearingsim.multibody.scene import segment_bit

    gap = 0.0005  # s / 2
    psi = math.radians(20.0)
    u = np.array([math.cos(psi), math.sin(psi)])  # pocket 0 at the bottom: front +x, e_r -y
    u[1] = -u[1]
    into, _ = _one_pocket_masks(tuple((gap + 1e-6) * u), n_seg=0)
    assert into[0] == segment_bit(0, 0, 1) and into[1:].tolist() == [0, 0, 0]
    short, _ = _one_pocket_masks(tuple((gap - 1e-6) * u), n_seg=0)
    assert short[0] == 0
    rear, _ = _one_pocket_masks(tuple(-(gap + 1e-6) * u), n_seg=0)
    assert rear[0] == segment_bit(1, 0, 1)
    R, r, c45 = 0.0105, 0.01, math.cos(math.radians(45.0))
    d_edge = R * c45 - math.sqrt(r * r - (R * c45) ** 2)
    out, _ = _one_pocket_masks((0.0, -0.98 * d_edge), n_seg=0)
    assert out[0] == 0
    edges, _ = _one_pocket_masks((0.0, -1.02 * d_edge), n_seg=0)
    assert edges[0] == segment_bit(0, 0, 1) | segment_bit(1, 0, 1)


def test_plain_loop_is_chosen_by_the_environment(monkeypatch):
    """``BEARINGSIM_PLAIN_PYMUNK=1`` selects the plain loop without a keyword."""
    import pymunk

    monkeypatch.setenv(chipmunk.PLAIN_ENV, "1")
    space = pymunk.Space()
    loop, why = chipmunk.open_step_loop(space, 1, chipmunk.lp.BODY_SET_FORCE, np.zeros(3), 16)
    assert loop.name == "plain" and chipmunk.PLAIN_ENV in why


def test_version_guard_falls_back_to_the_plain_loop(monkeypatch):
    """The installed pymunk passes the guard; a pymunk major version the compiled loop was not checked
    against does not, and then the plain loop runs (and "compiled" is refused, not run)."""
    import pymunk

    from bearingsim.errors import SlowLoopWarning

    monkeypatch.delenv(chipmunk.PLAIN_ENV, raising=False)
    assert chipmunk.guard() is None
    monkeypatch.setattr(pymunk, "version", "8.0.0")
    monkeypatch.setattr(chipmunk, "_announced", False)
    why = chipmunk.guard()
    assert why is not None and "8.0.0" in why
    space = pymunk.Space()
    # announced once, loudly, with what it costs (issue 29, item 4); the second fallback is silent
    with pytest.warns(SlowLoopWarning, match=r"cannot run \(pymunk 8\.0\.0 .*times slower"):
        loop, reason = chipmunk.open_step_loop(space, 1, chipmunk.lp.BODY_SET_FORCE, np.zeros(3), 16)
    assert loop.name == "plain" and reason == why
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert chipmunk.open_step_loop(space, 1, chipmunk.lp.BODY_SET_FORCE, np.zeros(3), 16)[0].name == "plain"
    with pytest.raises(RuntimeError, match="cannot run"):
        chipmunk.open_step_loop(space, 1, chipmunk.lp.BODY_SET_FORCE, np.zeros(3), 16, step_loop="compiled")


def test_rigid_race_carries_the_inner_race_load_of_a_roller_on_it_at_every_angle():
    """A loaded roller orbiting on the outer race (its prediction ``x + h v`` beyond the circle, so the
    joint holds it): the race takes its whole inner-race load and the roller is not counted off the race
    (lift 0), at every angle. The kernel projects the prediction onto the circle; the projected centre's
    radius rounds to ~1e-17 m inside the circle at about a fifth of the angles (75 of these 401), and taking that for
    "pulled off the outer race" put the inner contact's stiffness into the roller's velocity update
    (h^2 k ~ 9 m at 22 us): the race's share, and with it the outer-race normal force for traction and
    drag, was 10 % of the inner-race load in those steps (the load zone's mean outer-race normal force
    570 N against 725 N at 3000 rpm, 22.2 us). Relative 1e-3: the ring's contact normal is not exactly
    radial."""
    h, omega = 2.22e-5, 138.0
    prm = _params(rigid=True, rigid_radius=RC, inner_ring=True, ring_mass=1.0, damping_time=0.0,
                  outer_race_radius=RC + ROLLER_RADIUS)
    delta = 5e-6
    held_ratio, lift = [], []
    for a in np.linspace(-0.5, 0.5, 401) - 0.5 * math.pi:
        state = np.zeros((2, 6))
        state[0, :2] = RC * math.cos(a), RC * math.sin(a)
        state[0, 3:5] = -omega * RC * math.sin(a), omega * RC * math.cos(a)
        # ring centre on the roller's radius: the roller overlaps the inner race by delta
        ring_c = (RC - (prm.inner_race_radius + ROLLER_RADIUS - delta)) * np.array([math.cos(a), math.sin(a)])
        diag = np.zeros(1, dtype=fk.DIAG)
        n_held = np.zeros(1)
        fk.raceway_forces(state, h, prm, ring_c, np.zeros(2), np.zeros(2), np.zeros(1, dtype=np.bool_), np.zeros(6),
                          diag, np.zeros(1), n_held)
        assert diag[0]["q_in"] > 100.0
        held_ratio.append(n_held[0] / diag[0]["q_in"])
        lift.append(diag[0]["lift"])
    assert min(held_ratio) == pytest.approx(1.0, rel=1e-3) and max(held_ratio) == pytest.approx(1.0, rel=1e-3)
    assert not any(lift)


# --- rigid raceways: the race rotation (forces.race_orbit) ------------------------------------------
def _orbit(x, y, vx, vy, h, q_in=0.0, hold=False):
    """race_orbit on one roller (row 0; row 1 a cage left alone): (state after, n_extra)."""
    prm = _params(rigid=True, rigid_radius=RC)
    state = np.zeros((2, 6))
    state[0, [0, 1, 3, 4]] = x, y, vx, vy
    diag = np.zeros(1, dtype=fk.DIAG)
    diag["q_in"] = q_in
    n_extra = np.full(1, -1.0)
    fk.race_orbit(state, h, prm, np.array([hold]), n_extra, diag)
    return state, n_extra[0]


@pytest.mark.parametrize("angle", [0.3, 2.0, 4.5])
def test_race_rotation_keeps_a_rolling_roller_on_its_circle(angle):
    """A roller rolling on the outer race (centre on the circle r_c, velocity v_t along it) is handed to
    pymunk so that its straight-line update ``x + h v`` lands on the circle at the angle the rotation by
    v_t h / r_c reaches, with its velocity tangent there: no chord drift and no joint correction. The race
    carries the centripetal force m v_t^2 / r_c. Exact to rounding (relative 1e-12 on radii ~0.05 m,
    1e-9 on the radial velocity's 1e-12 m/s against v_t = 10 m/s)."""
    h, vt = 2e-5, 10.0
    er = np.array([math.cos(angle), math.sin(angle)])
    et = np.array([-er[1], er[0]])
    st, n_extra = _orbit(*(RC * er), *(vt * et), h)
    land = st[0, 0:2] + h * st[0, 3:5]
    assert np.hypot(*land) == pytest.approx(RC, rel=1e-12, abs=0)
    turned = math.atan2(land[1], land[0]) - angle
    assert (turned + math.pi) % (2 * math.pi) - math.pi == pytest.approx(vt * h / RC, rel=1e-9)
    e_land = land / np.hypot(*land)
    assert abs(st[0, 3:5] @ e_land) < 1e-9 * vt and np.hypot(*st[0, 3:5]) == pytest.approx(vt, rel=1e-12)
    assert n_extra == pytest.approx(ROLLER_MASS * vt**2 / RC, rel=1e-12)
    assert not st[1].any()


def test_race_rotation_stops_a_small_inward_speed_on_the_race():
    """A roller on the race moving inward slower than the centripetal acceleration returns it within the
    step (|v_r| < v_t^2 h / r_c) stays on the race: its radial speed is stopped, and the race's force is
    the centripetal force less the momentum it takes, m (v_t^2 / r_c + v_r / h). Exact to rounding."""
    h, vt = 2e-5, 10.0
    vr = -0.5 * vt**2 * h / RC
    st, n_extra = _orbit(RC, 0.0, vr, vt, h)
    land = st[0, 0:2] + h * st[0, 3:5]
    assert np.hypot(*land) == pytest.approx(RC, rel=1e-12, abs=0)
    assert abs(st[0, 3:5] @ (land / np.hypot(*land))) < 1e-9 * vt
    assert n_extra == pytest.approx(ROLLER_MASS * (vt**2 / RC + vr / h), rel=1e-12)


def test_race_rotation_leaves_pymunk_the_radial_motion_of_a_roller_beyond_the_circle():
    """A roller 2 um beyond the circle, put back by the joint at 0.1 m/s inward: only its tangential
    motion follows the circle. It lands at r + h v_r, keeps v_r and v_t, and the race carries
    m v_t^2 / r. Exact to rounding."""
    h, vt, vr, r = 2e-5, 10.0, -0.1, RC + 2e-6
    st, n_extra = _orbit(r, 0.0, vr, vt, h)
    land = st[0, 0:2] + h * st[0, 3:5]
    assert np.hypot(*land) == pytest.approx(r + h * vr, rel=1e-12, abs=0)
    e_land = land / np.hypot(*land)
    assert st[0, 3:5] @ e_land == pytest.approx(vr, rel=1e-9)
    assert e_land[0] * st[0, 4] - e_land[1] * st[0, 3] == pytest.approx(vt, rel=1e-12)
    assert math.atan2(land[1], land[0]) == pytest.approx(vt * h / r, rel=1e-9)
    assert n_extra == pytest.approx(ROLLER_MASS * vt**2 / r, rel=1e-12)


@pytest.mark.parametrize("case", ["load zone", "held", "inside", "leaving"])
def test_race_rotation_leaves_other_rollers_alone(case):
    """Left to pymunk, state unchanged and no race force: a roller loaded by the inner race in the last
    step (load zone), a prescribed roller (reduced-equivalent scene), one 2 nm inside the circle (off
    the race), and one on the circle leaving inward faster than v_t^2 h / r_c."""
    h, vt = 2e-5, 10.0
    x, vr, q_in, hold = RC, 0.0, 0.0, False
    if case == "load zone":
        q_in = 100.0
    elif case == "held":
        hold = True
    elif case == "inside":
        x = RC - 2e-9
    else:
        vr = -2.0 * vt**2 * h / RC
    st, n_extra = _orbit(x, 0.0, vr, vt, h, q_in=q_in, hold=hold)
    assert list(st[0, [0, 1, 3, 4]]) == [x, 0.0, vr, vt] and n_extra == 0.0



def test_pymunk_pin_matches_the_version_guard():
    """pyproject.toml pins pymunk to the major versions whose internals the compiled loop checks
    (``chipmunk.SUPPORTED_PYMUNK``): an install cannot bring a pymunk the guard would refuse."""
    import re
    import tomllib
    from pathlib import Path

    meta = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    spec = next(d for d in meta["project"]["dependencies"] if d.startswith("pymunk"))
    lo, hi = re.fullmatch(r"pymunk>=(\d+)\.\d+(?:\.\d+)?,<(\d+)", spec.replace(" ", "")).groups()
    assert tuple(range(int(lo), int(hi))) == chipmunk.SUPPORTED_PYMUNK, spec
