"""Raceway force laws of the multi-pocket model as one compiled kernel. SI throughout.

Every roller touches two raceways through force laws (not pymunk shapes):

* normal: Palmgren line contact ``Q = K delta^(10/9)`` (Palmgren 1959; Harris & Kotzalas, *Rolling
  Bearing Analysis*, Eq. 6.49) plus a stiffness-proportional contact damping
  ``c = c_r k_lin`` (``c_r`` after Kraemer, *Dynamics of Rotors and Foundations*, 1993, as used by
  Sopanen & Mikkola, Proc. IMechE K 217:201, 2003) that is faded in over the first few nanometres of
  approach so that ``Q`` is continuous at ``delta = 0``; ``Q >= 0``;
* tangential: EHL traction ``mu(slip) = mu_max tanh(slip / slip_ref)`` with ``slip`` the sliding speed
  over the entrainment speed (shape of measured traction curves, Johnson & Tevaarwerk 1977);
* the oil-film rolling resistance of the seed paper, Eq. (2), ``F_o = c N^0.246 V^0.648`` with that
  contact's own ``N = Q`` and entrainment speed ``V``, acting on the roller centre against its motion
  relative to that raceway.

The radial clearance ``P_d`` (diametral) is split between the races: the outer raceway radius is
``r_o + P_d/4``, the inner one ``r_i - P_d/4``.

Time integration (how pymunk and this kernel fit together). pymunk's step moves positions first with
the old velocities, ``x_{n+1} = x_n + h v_n``, then adds ``h F / m`` to the velocities, then solves the
roller-cage contacts. Forces set before the step are therefore evaluated here at the *predicted*
positions ``x_{n+1}`` (never at ``x_n``: that is forward Euler and unstable with Hertz stiffness): the
normal forces are symplectic Euler, stable for ``h < 2/omega_n`` of the stiffest contact. The contact
damping uses the approach rate over the step, ``(delta_{n+1} - delta_n) / h``, which is exactly zero for
a roller orbiting on its raceway. (An earlier version linearised the normal force implicitly in
Cartesian coordinates about ``v_n``; because the contact normal turns by ``omega h`` per step, that
turned the orbital speed into a spurious approach rate ``omega h v`` and doubled the raceway loads at
6000 rpm; it is gone.) Traction and drag, whose velocity stiffness is large at low entrainment speed,
stay implicitly linearised in velocity: one 3x3 (2x2 with fixed spin) solve per roller.

The inner ring turns at a prescribed speed. Its centre is either

* quasi-static (``ring_mass = 0``): each step a 2-D Newton solve on the predicted roller positions
  makes the inner-raceway normal forces (elastic and damping) balance the radial load. Tangential
  raceway forces are not fed back into the ring balance (they are two orders below the normal loads
  and the ring's lateral position would move by ~1e-8 m). Defined only while at least two rollers
  carry the load: on a single roller the ring's sideways equilibrium is unstable;
* dynamic (``ring_mass = M > 0``, the rotor's mass): integrated like the bodies in pymunk
  (symplectic Euler: position with the old velocity, then ``v += h F / M``) under the radial load and
  the reactions of every inner-raceway contact (normal, traction and drag), evaluated at the predicted
  positions of rollers and ring.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from bearingsim import compiled_laws, laws


class RacewayParams(NamedTuple):
    """Inputs of :func:`raceway_forces` that are fixed for a run. SI throughout."""

    roller_radius: float  #: r_r [m]
    roller_mass: float  #: [kg]
    roller_inertia: float  #: about the roller axis [kg m^2]
    outer_race_radius: float  #: outer raceway radius with half the radial clearance, r_o + P_d/4 [m]
    inner_race_radius: float  #: inner raceway radius with half the radial clearance, r_i - P_d/4 [m]
    outer_race_geom_radius: float  #: r_o without clearance, for the entrainment speed [m]
    inner_race_geom_radius: float  #: r_i without clearance [m]
    palmgren_stiffness: float  #: K of Q = K delta^(10/9) [N/m^(10/9)]
    damping_time: float  #: c_r of the contact damping c = c_r k_lin [s]
    damping_fade: float  #: approach over which the damping fades in [m]
    traction_mu_max: float  #: mu_max of mu(slip) = mu_max tanh(slip / slip_ref)
    traction_slip_ref: float  #: slip_ref
    min_entrainment: float  #: floor of the entrainment speed in the slip ratio [m/s]
    drag_coefficient: float  #: c of Eq. (2), F_o = c N^0.246 V^0.648 [SI]
    drag_direction_eps: float  #: regularisation speed of the sign of the drag force [m/s]
    omega_ring: float  #: inner-ring angular speed, signed [rad/s]
    radial_load: float  #: W, along -y [N]
    gravity: float  #: g, along -y [m/s^2]
    inner_ring: bool  #: an inner raceway is present
    traction: bool  #: raceway traction is on
    spin_free: bool  #: roller spin is a degree of freedom (else fixed)
    newton_max_step: float  #: step limit of the ring-centre Newton iteration [m]
    ring_mass: float  #: 0: quasi-static (massless) inner ring; > 0: dynamic ring of this mass [kg]
    rigid: bool = False  #: rigid raceways: the outer-race contact is a pymunk joint whose force is given
    rigid_radius: float = 0.0  #: rigid raceways: radius of the roller centres on the outer race [m]


#: Per-roller contact diagnostics of a step, array shape (n,).
DIAG = np.dtype([
    ("q_out", np.float64), ("q_in", np.float64),  # raceway loads [N]
    ("delta_out", np.float64), ("delta_in", np.float64),  # approaches [m]
    ("slip_out", np.float64), ("slip_in", np.float64),  # sliding speed / entrainment speed
    ("drag_out", np.float64), ("drag_in", np.float64),  # oil-film rolling resistance F_o [N]
    ("lift", np.float64),  # rigid raceways: distance of the roller centre inside its outer-race circle [m]
], align=True)

TEN_NINTHS = 10.0 / 9.0
NEWTON_ITERATIONS = 60  # of the ring centre's Newton iteration
NEWTON_HALVINGS = 30  # of its step (Armijo's rule), down to 2^-29 of Newton's step


@njit(cache=True, inline="always")
def _normal_force(delta, delta_rate, K, c_r, d_fade):
    """Normal force [N], its derivative in delta [N/m] and in delta_rate [N s/m] of one contact."""
    if delta <= 0.0:
        return 0.0, 0.0, 0.0
    q_el = compiled_laws.palmgren_load(K, delta)  # Q = K delta^(10/9), delta > 0 here
    k_lin = TEN_NINTHS * K * delta ** (1.0 / 9.0)
    fade = delta / d_fade if delta < d_fade else 1.0
    dfade = 1.0 / d_fade if delta < d_fade else 0.0
    c = c_r * k_lin * fade
    q = q_el + c * delta_rate
    if q <= 0.0:
        return 0.0, 0.0, 0.0
    # d(c)/d(delta): c_r (k_lin' fade + k_lin fade'); k_lin' = k_lin / (9 delta)
    dc = c_r * (k_lin / (9.0 * delta) * fade + k_lin * dfade)
    return q, k_lin + dc * delta_rate, c


@njit(cache=True)
def _ring_balance(xp, delta_prev, h, prm, cx, cy):
    """Force balance of the quasi-static inner ring centred at (cx, cy): the residual
    ``sum_i Q_i N_i + (0, W)`` [N] and its Jacobian in the centre [N/m], ``(rx, ry, j00, j01, j10, j11)``.
    Each component increases with its own coordinate (a ring moved towards rollers presses them harder)."""
    rr = prm.roller_radius
    r_race = prm.inner_race_radius
    K = prm.palmgren_stiffness
    c_r = prm.damping_time
    d_fade = prm.damping_fade
    rx = 0.0
    ry = prm.radial_load
    j00 = 0.0
    j01 = 0.0
    j10 = 0.0
    j11 = 0.0
    for i in range(xp.shape[0]):
        dx = xp[i, 0] - cx
        dy = xp[i, 1] - cy
        d = math.sqrt(dx * dx + dy * dy)
        nx = dx / d
        ny = dy / d
        delta = r_race + rr - d
        if delta <= 0.0:
            continue
        rate = (delta - delta_prev[i]) / h
        q, dq_dd, dq_drate = _normal_force(delta, rate, K, c_r, d_fade)
        if q <= 0.0:
            continue
        rx += q * nx
        ry += q * ny
        # d delta / dc = N ; d rate / dc = N / h (through c_dot); d N / dc = -(I - N N^T) / d
        g = dq_dd + dq_drate / h
        qd = q / d
        j00 += g * nx * nx - qd * (1.0 - nx * nx)
        j01 += g * nx * ny + qd * nx * ny
        j10 += g * ny * nx + qd * nx * ny
        j11 += g * ny * ny - qd * (1.0 - ny * ny)
    return rx, ry, j00, j01, j10, j11


@njit(cache=True, inline="always")
def _safeguarded(t, f, df, lo, hi):
    """Next iterate towards a root bracketed in (lo, hi): Newton's from t if it stays inside, else the midpoint."""
    if df > 0.0:
        tn = t - f / df
        if lo < tn < hi:
            return tn
    return 0.5 * (lo + hi)


@njit(cache=True, inline="always")
def _widen(t, step):
    """One step of a bracket's search from ``t``: ``(lo, hi, next t, next step)``, the step doubled."""
    lo, hi = (t, t + step) if step > 0.0 else (t + step, t)
    return lo, hi, t + step, step * 2.0


@njit(cache=True, inline="always")
def _narrow(f, t, lo, hi):
    """The bracket ``(lo, hi)`` closed in to ``t`` on the side of its residual ``f``'s sign, and whether it has
    closed to adjacent floats (no midpoint between them): ``(lo, hi, closed)``."""
    if f < 0.0:
        lo = t
    else:
        hi = t
    return lo, hi, not lo < 0.5 * (lo + hi) < hi


@njit(cache=True, inline="always")
def _float_limited(f, s, prm, tol):
    """Whether a residual ``f`` [N] left where a bracket has closed to adjacent floats is the rounding of the
    force sum: within ``tol`` plus 8 ulps of a roller's distance from the ring centre times the contacts'
    stiffness ``s`` [N/m] (the trace of the Jacobian; a stiff or fast-closing contact's rounding alone can
    exceed ``tol``), not a jump of the forces between those floats."""
    return abs(f) <= tol + 8.0 * s * 2.220446049250313e-16 * (prm.inner_race_radius + prm.roller_radius)


@njit(cache=True)
def _ring_y(xp, delta_prev, h, prm, cx, cy, tol):
    """The ring's vertical balance at a given ``cx``: the root of ``ry(cy)`` (increasing), bracketed by
    steps from ``cy`` doubling from 1e-10 m, then closed in by :func:`_safeguarded` to ``tol`` or to the
    resolution of float64. Returns ``(cy, rx, ry, dg, s, ok)``: ``dg`` = ``j00 - j01 j10 / j11``, the derivative
    of ``rx`` along the balanced path; ``s`` the contacts' stiffness (``|j00| + |j11|``) [N/m]; ``ok`` where
    ``|ry| <= tol`` or the bracket closed to float64 resolution with ``ry`` its rounding
    (:func:`_float_limited`); not ``ok`` where no root was found."""
    rx, ry, j00, j01, j10, j11 = _ring_balance(xp, delta_prev, h, prm, cx, cy)
    t = lo = hi = cy
    f0 = ry
    step = 1e-10 if ry < 0.0 else -1e-10
    while abs(ry) > tol and (ry < 0.0) == (f0 < 0.0) and abs(step) < 1e-2:  # bracket
        lo, hi, t, step = _widen(t, step)
        rx, ry, j00, j01, j10, j11 = _ring_balance(xp, delta_prev, h, prm, cx, t)
    found = (ry < 0.0) != (f0 < 0.0)
    ok = abs(ry) <= tol
    for _ in range(200):
        if ok or not found:  # balanced, or no root within 1 cm
            break
        lo, hi, closed = _narrow(ry, t, lo, hi)
        if closed:  # float64 resolution
            ok = _float_limited(ry, abs(j00) + abs(j11), prm, tol)
            break
        t = _safeguarded(t, ry, j11, lo, hi)
        rx, ry, j00, j01, j10, j11 = _ring_balance(xp, delta_prev, h, prm, cx, t)
        ok = abs(ry) <= tol
    dg = j00 - j01 * j10 / j11 if j11 > 0.0 else j00
    return t, rx, ry, dg, abs(j00) + abs(j11), ok


@njit(cache=True)
def _bracketed_ring_centre(xp, delta_prev, h, prm, out_c, tol):
    """The ring centre by nested 1-D root finding, where Newton has failed: ``rx`` along the path of
    vertical balance (:func:`_ring_y`) is continuous and increasing but for the ring's curvature; its root
    is bracketed from ``out_c[0]`` by doubling steps and closed in by :func:`_safeguarded`. Continuous
    contact forces give a root whatever their kinks. ``out_c``: in, the start; out, the centre.
    Returns (residual norm [N], converged): converged where both balances are within ``tol / 2`` or closed to
    float64 resolution with a residual that is their rounding (:func:`_float_limited`)."""
    cx = out_c[0]
    half = 0.5 * tol
    cy, rx, ry, dg, s, ok_y = _ring_y(xp, delta_prev, h, prm, cx, out_c[1], half)
    f0 = rx
    step = 1e-10 if rx < 0.0 else -1e-10
    lo = hi = cx
    while abs(rx) > half and (rx < 0.0) == (f0 < 0.0) and abs(step) < 1e-2:  # bracket
        lo, hi, cx, step = _widen(cx, step)
        cy, rx, ry, dg, s, ok_y = _ring_y(xp, delta_prev, h, prm, cx, cy, half)
    found = (rx < 0.0) != (f0 < 0.0)
    ok_x = abs(rx) <= half
    for _ in range(200):
        if ok_x or not found:  # balanced, or no root within 1 cm
            break
        lo, hi, closed = _narrow(rx, cx, lo, hi)
        if closed:  # float64 resolution
            ok_x = _float_limited(rx, s, prm, half)
            break
        cx = _safeguarded(cx, rx, dg, lo, hi)
        cy, rx, ry, dg, s, ok_y = _ring_y(xp, delta_prev, h, prm, cx, cy, half)
        ok_x = abs(rx) <= half
    out_c[0] = cx
    out_c[1] = cy
    res = math.sqrt(rx * rx + ry * ry)
    return res, res <= tol or (ok_x and ok_y)


@njit(cache=True)
def _ring_newton(xp, delta_prev, h, prm, out_c, tol, armijo):
    """Newton's iteration for the ring centre from ``out_c`` (out: its last iterate), each step limited to
    ``prm.newton_max_step``; with ``armijo``, halved until the residual norm falls (Armijo's rule), and
    stopped where no halving does. Returns (iterations, residual norm [N]); iterations < 0 if not converged."""
    max_step = prm.newton_max_step
    cx = out_c[0]
    cy = out_c[1]
    rx, ry, j00, j01, j10, j11 = _ring_balance(xp, delta_prev, h, prm, cx, cy)
    res = math.sqrt(rx * rx + ry * ry)
    for it in range(NEWTON_ITERATIONS):
        if res <= tol:
            out_c[0] = cx
            out_c[1] = cy
            return it, res
        det = j00 * j11 - j01 * j10
        if abs(det) <= 1e-12 * (j00 * j00 + j11 * j11) + 1e-300:
            # fewer than two loaded contacts: regularise (Levenberg) so the step heads along the
            # residual towards the rollers that must take the load; the step limit below bounds it
            lam = 1e-3 * (abs(j00) + abs(j11)) + 1.0
            j00 += lam
            j11 += lam
            det = j00 * j11 - j01 * j10
        sx = -(j11 * rx - j01 * ry) / det
        sy = -(-j10 * rx + j00 * ry) / det
        sn = math.sqrt(sx * sx + sy * sy)
        if sn > max_step:
            sx *= max_step / sn
            sy *= max_step / sn
        t = 1.0
        for _ in range(NEWTON_HALVINGS if armijo else 1):
            rx, ry, j00, j01, j10, j11 = _ring_balance(xp, delta_prev, h, prm, cx + t * sx, cy + t * sy)
            r_try = math.sqrt(rx * rx + ry * ry)
            if not armijo or r_try <= (1.0 - 1e-4 * t) * res:
                break
            t *= 0.5
        else:
            break  # no step along Newton's direction lowers the residual: stalled at a kink
        cx += t * sx
        cy += t * sy
        res = r_try
        if sn < 1e-16:
            break
    out_c[0] = cx
    out_c[1] = cy
    return -1, res


@njit(cache=True)
def solve_ring_centre(xp, delta_prev, c_prev, h, prm, out_c):
    """Quasi-static inner-ring centre: the root of sum_i Q_i N_i = (0, -W).

    Newton's iteration (:func:`_ring_newton`); where it does not converge in ``NEWTON_ITERATIONS``, it has
    cycled across a kink of the contact law (a roller entering the load zone, whose damping is faded in
    over its first ``damping_fade``; at a run's start, an opening contact whose force is cut off at zero),
    and the solve starts again from the guess with the step halved until the residual falls (Armijo's rule),
    then, where that stalls, by nested bracketing (:func:`_bracketed_ring_centre`) from its last iterate.
    A step that Newton alone solves keeps its iterates (with rigid raceways, every step).

    Parameters
    ----------
    xp : (n, 2) predicted roller centres [m].
    delta_prev : (n,) inner-race approach of each roller at the current positions and ``c_prev`` [m];
        the damping uses the rate ``(delta - delta_prev) / h`` over the step.
    c_prev : (2,) ring centre of the previous step [m].
    h : time step [s].
    prm : :class:`RacewayParams`.
    out_c : (2,) in: initial guess, out: solution [m].

    Returns
    -------
    (iterations, residual norm [N]); iterations < 0 if none converged (to 1e-9 (W + 1 N), or where the bracketing
    closed to float64 resolution, to the rounding of the force sum there: :func:`_float_limited`).
    """
    tol = 1e-9 * (prm.radial_load + 1.0)
    gx = out_c[0]
    gy = out_c[1]
    it, res = _ring_newton(xp, delta_prev, h, prm, out_c, tol, False)
    if it >= 0:
        return it, res
    out_c[0] = gx
    out_c[1] = gy
    it, res = _ring_newton(xp, delta_prev, h, prm, out_c, tol, True)
    if it >= 0:
        return NEWTON_ITERATIONS + it, res
    res, ok = _bracketed_ring_centre(xp, delta_prev, h, prm, out_c, tol)
    return (2 * NEWTON_ITERATIONS if ok else -1), res


@njit(cache=True, inline="always")
def _contact(
    px, py, vx, vy, w, nx, ny, delta, rate, u_race, w_race, r_race_geom, omega_race, orbit, prm, jac, f,
    q_given=-1.0,
):
    """Add one raceway contact to the generalized force ``f`` (fx, fy, torque) and its Jacobians.

    ``(nx, ny)`` is the direction of the normal force on the roller, ``u_race`` the raceway surface
    speed along the tangent ``T = rot90(N)`` at the contact [m/s], ``w_race`` the speed along T of the
    raceway material at the roller centre [m/s], ``orbit`` the roller's orbital angular speed [rad/s].
    ``jac`` is (C, K) packed as a 3x3 velocity Jacobian and 2x2 stiffness in a (3, 5) array.
    ``q_given >= 0``: the normal force is that of a constraint (rigid raceways), known from the
    previous step; it is not added to ``f`` (the constraint applies it) and sets traction and drag.

    Returns
    -------
    (load Q [N], approach delta [m], slip ratio (sliding / entrainment speed), drag F_o [N]); slip and
    drag are 0 where the contact is open (and slip where traction is off).
    """
    rr = prm.roller_radius
    if q_given >= 0.0:
        q = q_given
    else:
        q, dq_dd, dq_drate = _normal_force(delta, rate, prm.palmgren_stiffness, prm.damping_time, prm.damping_fade)
    if q <= 0.0:
        return q, delta, 0.0, 0.0
    tx = -ny
    ty = nx
    if q_given < 0.0:
        f[0] += q * nx
        f[1] += q * ny
    # The normal force is explicit at the predicted position (symplectic Euler): linearising it in
    # Cartesian coordinates about v_n would turn the orbital motion (the normal turns by omega h per
    # step) into a spurious approach rate omega h v and an O(omega h)^2 k force bias.
    # entrainment (rolling) speed: mean surface speed of roller and raceway relative to the contact
    # point, which moves with the roller's orbit (reduces to the paper's Eq. 4 in pure rolling)
    u_ent = 0.5 * (abs(w - orbit) * rr + abs(omega_race - orbit) * r_race_geom)
    u_ref = max(u_ent, prm.min_entrainment)
    # oil-film rolling resistance, Eq. (2), on the roller centre against its motion relative to the race
    fo = compiled_laws.oil_film_drag_scalar(prm.drag_coefficient, q, u_ent)  # Eq. (2) with this contact's N and V
    rel = vx * tx + vy * ty - w_race
    weps = prm.drag_direction_eps
    sq = math.sqrt(rel * rel + weps * weps)
    f[0] -= fo * rel / sq * tx
    f[1] -= fo * rel / sq * ty
    gd = fo * weps * weps / (sq * sq * sq)
    jac[0, 0] -= gd * tx * tx
    jac[0, 1] -= gd * tx * ty
    jac[1, 0] -= gd * ty * tx
    jac[1, 1] -= gd * ty * ty
    if prm.traction:
        # sliding speed of the roller surface over the raceway along T; generalized direction
        # a = (tx, ty, -rr) for (vx, vy, w)
        s = vx * tx + vy * ty - w * rr - u_race
        x = s / (prm.traction_slip_ref * u_ref)
        th = math.tanh(x)
        mu = prm.traction_mu_max * th
        ft = -mu * q
        f[0] += ft * tx
        f[1] += ft * ty
        f[2] += -rr * ft
        g = prm.traction_mu_max * (1.0 - th * th) * q / (prm.traction_slip_ref * u_ref)
        a0 = tx
        a1 = ty
        a2 = -rr
        jac[0, 0] -= g * a0 * a0
        jac[0, 1] -= g * a0 * a1
        jac[0, 2] -= g * a0 * a2
        jac[1, 0] -= g * a1 * a0
        jac[1, 1] -= g * a1 * a1
        jac[1, 2] -= g * a1 * a2
        jac[2, 0] -= g * a2 * a0
        jac[2, 1] -= g * a2 * a1
        jac[2, 2] -= g * a2 * a2
        return q, delta, s / u_ref, fo
    return q, delta, 0.0, fo


@njit(cache=True, inline="always")
def raceway_forces(state, h, prm, ring_c, ring_c_prev, ring_v, hold, out_f, diag, n_out, n_held):
    """Implicitly linearised raceway forces on every roller for the coming pymunk step.

    Parameters
    ----------
    state : (nb, 6) body state before the step, rows (x, y, angle, vx, vy, omega) in SI; rows
        ``0..n-1`` are the rollers.
    h : time step [s].
    prm : :class:`RacewayParams`.
    ring_c : (2,) inner-ring centre [m]: in, the previous solution; out, this step's.
    ring_c_prev : (2,) scratch, receives the previous centre.
    ring_v : (2,) velocity of the ring centre [m/s] (dynamic ring: in and out; quasi-static: unused).
    hold : (n,) bool, rollers whose motion is prescribed this step (get zero force).
    out_f : (nb * 3,) flat (fx, fy, torque) per body for ``pymunk.batch.set_space_bodies`` [N, N m].
    diag : (n,) :data:`DIAG`, out: per-roller contact diagnostics (loads [N], approaches [m], slips, drags [N]).
    n_out : (n,) rigid raceways: the outer-race normal force of each roller over the previous step, from
        its constraint's impulse [N] (unused with Hertz contacts).
    n_held : (n,) rigid raceways: the outer race's reaction on each roller that this kernel applies
        (besides the joint's) [N]; in: the previous step's, out: this step's (unused with Hertz contacts).

    Rigid raceways (``prm.rigid``). Each roller is held on the outer race by a unilateral pymunk joint
    (centre at most ``prm.rigid_radius`` from the axis), so no normal force is computed there: the
    joint's force of the previous step sets that contact's traction and drag. Positions are taken on
    the joint's circle (pymunk moves a body along its chord before the joint pulls it back, so a body
    read after a step sits up to ``r (omega h)^2 / 2`` outside it). The inner-race contact keeps its
    Palmgren law, with the two contacts of a roller in series (``prm.palmgren_stiffness`` is then
    ``K 2^(-10/9)``) and no damping: the inner ring's centre, quasi-static or dynamic, shares the
    load among the rollers as in the Hertz scene. A roller on the outer race does not move along that
    contact's normal (the joint holds it), so the stiff spring sets no time step; a roller that the cage
    has pulled off the outer race and onto the inner race has the inner contact's stiffness in its
    velocity update (linearly implicit), which keeps that rare state stable at the rigid scene's step.

    The race's share (what the joint cannot do). chipmunk activates a slide joint only beyond its
    length and corrects its error through the bodies' real velocities, so left to the joint a loaded
    roller sitting exactly on the circle (or a few nm inside it) is free for a step and leaves with
    ``F h / m`` (0.5 m/s at 1e-5 s in the load zone), and a roller the joint has put back keeps the
    correction speed and leaves the race inward. Measured at 6000 rpm over 150 rotations before this
    rule: approaches of 0.17, 0.30, 0.41, 0.55 m/s at steps of 5.4, 10, 13.6, 17.5 us on slanted pocket
    faces, every one with zero impulse (the Hertz scene: 0.130 m/s at most). So, from where pymunk's
    position update will put the roller (``x + h v``): if that is beyond the circle (the joint holds it
    in the step), the race takes the roller's outward load (inner-race load, gravity); if it is inside
    (the joint is slack), the roller keeps only the outward load that brings it at most onto the circle
    by the next position update, and gets back the joint's correction speed of the last step,
    ``(r - r_c) / h`` (the race is plastic: a roller put back is stopped on it). A roller far inside the
    circle (lifted by the cage) keeps its whole load. That share goes into ``n_held``, and the
    outer-race normal force is ``n_out + n_held`` (joint and race).

    Returns
    -------
    Newton iteration count of the ring solve (negative if it failed; 0 if no inner ring).
    """
    n = diag.shape[0]
    m = prm.roller_mass
    inertia = prm.roller_inertia
    g = prm.gravity
    spin_free = prm.spin_free
    xp = np.empty((n, 2))
    din_prev = np.empty(n)
    dout_prev = np.empty(n)
    rr = prm.roller_radius
    rigid = prm.rigid
    rc = prm.rigid_radius
    # rigid: the roller's predicted centre is inside the joint's circle (off the outer race); decided
    # before the projection below, whose rounding leaves a projected centre ~1e-17 m inside the circle
    off_race = np.zeros(n, dtype=np.bool_)
    pred = np.empty((n, 4))  # rigid: predicted centre (x, y) before that projection, its radius, the current radius
    for i in range(n):
        x0 = state[i, 0]
        y0 = state[i, 1]
        xp[i, 0] = x0 + h * state[i, 3]
        xp[i, 1] = y0 + h * state[i, 4]
        if rigid:  # on the joint's circle (see above); a roller inside it has left the outer race
            r0 = math.sqrt(x0 * x0 + y0 * y0)
            if r0 > rc:
                x0 *= rc / r0
                y0 *= rc / r0
            r1 = math.sqrt(xp[i, 0] ** 2 + xp[i, 1] ** 2)
            pred[i, 0] = xp[i, 0]
            pred[i, 1] = xp[i, 1]
            pred[i, 2] = r1
            pred[i, 3] = r0
            if r1 > rc:
                xp[i, 0] *= rc / r1
                xp[i, 1] *= rc / r1
            else:
                off_race[i] = r1 < rc
        # approaches at the current positions: contact rates are (delta_{n+1} - delta_n) / h
        dout_prev[i] = math.sqrt(x0 ** 2 + y0 ** 2) + rr - prm.outer_race_radius
        din_prev[i] = prm.inner_race_radius + rr - math.sqrt((x0 - ring_c[0]) ** 2 + (y0 - ring_c[1]) ** 2)
    it = 0
    inner = prm.inner_ring
    cdx = 0.0
    cdy = 0.0
    ring_mass = prm.ring_mass
    dynamic = ring_mass > 0.0
    if inner:
        ring_c_prev[0] = ring_c[0]
        ring_c_prev[1] = ring_c[1]
        if dynamic:
            ring_c[0] += h * ring_v[0]
            ring_c[1] += h * ring_v[1]
        else:
            it, _ = solve_ring_centre(xp, din_prev, ring_c_prev, h, prm, ring_c)
        cdx = (ring_c[0] - ring_c_prev[0]) / h
        cdy = (ring_c[1] - ring_c_prev[1]) / h
    frx = 0.0
    fry = -prm.radial_load  # force on a dynamic ring: the load, plus the reactions added below
    out_f[:] = 0.0
    jac = np.zeros((3, 5))
    f = np.zeros(3)
    A = np.zeros((3, 3))
    b = np.zeros(3)
    omega_ring = prm.omega_ring
    for i in range(n):
        d_i = diag[i]
        d_i.q_out = d_i.q_in = d_i.delta_out = d_i.delta_in = 0.0
        d_i.slip_out = d_i.slip_in = d_i.drag_out = d_i.drag_in = d_i.lift = 0.0
        if hold[i]:
            out_f[3 * i + 1] = m * g  # prescribed motion: cancel pymunk's gravity
            continue
        px = xp[i, 0]
        py = xp[i, 1]
        vx = state[i, 3]
        vy = state[i, 4]
        w = state[i, 5]
        jac[:, :] = 0.0
        f[:] = 0.0
        r = math.sqrt(px * px + py * py)
        orbit = (px * vy - py * vx) / (r * r)
        # outer raceway (fixed): force along N = -p/|p|
        nx = -px / r
        ny = -py / r
        if rigid:  # the joint's force; no approach
            d_i.lift = rc - r if off_race[i] else 0.0
            d_i.q_out, d_i.delta_out, d_i.slip_out, d_i.drag_out = _contact(
                px, py, vx, vy, w, nx, ny, 0.0, 0.0, 0.0, 0.0, prm.outer_race_geom_radius, 0.0, orbit, prm, jac, f,
                n_out[i] + n_held[i])
        else:
            delta = r + rr - prm.outer_race_radius
            rate = (delta - dout_prev[i]) / h
            d_i.q_out, d_i.delta_out, d_i.slip_out, d_i.drag_out = _contact(
                px, py, vx, vy, w, nx, ny, delta, rate, 0.0, 0.0, prm.outer_race_geom_radius, 0.0, orbit, prm, jac,
                f)
        if inner:
            dx = px - ring_c[0]
            dy = py - ring_c[1]
            d = math.sqrt(dx * dx + dy * dy)
            nx = dx / d
            ny = dy / d
            delta = prm.inner_race_radius + rr - d
            rate = (delta - din_prev[i]) / h
            tx = -ny
            ty = nx
            u_race = cdx * tx + cdy * ty + omega_ring * prm.inner_race_geom_radius
            w_race = cdx * tx + cdy * ty + omega_ring * d
            f_before_x = f[0]
            f_before_y = f[1]
            d_i.q_in, d_i.delta_in, d_i.slip_in, d_i.drag_in = _contact(
                px, py, vx, vy, w, nx, ny, delta, rate, u_race, w_race, prm.inner_race_geom_radius, omega_ring,
                orbit, prm, jac, f)
            if rigid and d_i.lift > 0.0 and d_i.q_in > 0.0:
                # a roller pulled off the outer race onto the inner race sits on that contact's spring alone
                # (2/omega_n ~ 20 us): its stiffness enters the velocity update implicitly, dF/dx = -Q' N N^T
                kq = TEN_NINTHS * prm.palmgren_stiffness * delta ** (1.0 / 9.0)
                jac[0, 3] -= kq * nx * nx
                jac[0, 4] -= kq * nx * ny
                jac[1, 3] -= kq * ny * nx
                jac[1, 4] -= kq * ny * ny
            frx -= f[0] - f_before_x
            fry -= f[1] - f_before_y
        # implicit velocity update: (M - h C - h^2 K) dq = h (F + h K v + M g)
        A[0, 0] = m - h * jac[0, 0] - h * h * jac[0, 3]
        A[0, 1] = -h * jac[0, 1] - h * h * jac[0, 4]
        A[1, 0] = -h * jac[1, 0] - h * h * jac[1, 3]
        A[1, 1] = m - h * jac[1, 1] - h * h * jac[1, 4]
        b[0] = h * (f[0] + h * (jac[0, 3] * vx + jac[0, 4] * vy))
        b[1] = h * (f[1] + h * (jac[1, 3] * vx + jac[1, 4] * vy) - m * g)
        if spin_free:
            A[0, 2] = -h * jac[0, 2]
            A[1, 2] = -h * jac[1, 2]
            A[2, 0] = -h * jac[2, 0]
            A[2, 1] = -h * jac[2, 1]
            A[2, 2] = inertia - h * jac[2, 2]
            b[2] = h * f[2]
            # 3x3 solve by Cramer's rule (well conditioned: diagonal-dominant mass matrix)
            det = (A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
                   - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
                   + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]))
            d0 = (b[0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
                  - A[0, 1] * (b[1] * A[2, 2] - A[1, 2] * b[2])
                  + A[0, 2] * (b[1] * A[2, 1] - A[1, 1] * b[2])) / det
            d1 = (A[0, 0] * (b[1] * A[2, 2] - A[1, 2] * b[2])
                  - b[0] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
                  + A[0, 2] * (A[1, 0] * b[2] - b[1] * A[2, 0])) / det
            d2 = (A[0, 0] * (A[1, 1] * b[2] - b[1] * A[2, 1])
                  - A[0, 1] * (A[1, 0] * b[2] - b[1] * A[2, 0])
                  + b[0] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0])) / det
            out_f[3 * i + 2] = inertia * d2 / h
        else:
            det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
            d0 = (A[1, 1] * b[0] - A[0, 1] * b[1]) / det
            d1 = (A[0, 0] * b[1] - A[1, 0] * b[0]) / det
        # pymunk adds gravity itself: hand it the rest
        out_f[3 * i] = m * d0 / h
        out_f[3 * i + 1] = m * d1 / h + m * g
        if rigid:  # the outer race's part that the joint does not do (see above)
            r1 = pred[i, 2]  # where pymunk's position update puts it (contact corrections aside)
            ex = pred[i, 0] / r1
            ey = pred[i, 1] / r1
            f_r = out_f[3 * i] * ex + (out_f[3 * i + 1] - m * g) * ey  # outward load (gravity included)
            if off_race[i]:  # the joint is slack in this step (chipmunk activates it only beyond its length)
                v_r = state[i, 3] * ex + state[i, 4] * ey
                # the joint's correction of the last step (a roller it put back from outside the circle
                # left with that speed inward, in its real velocity), given back: the race is plastic
                dv = max(0.0, pred[i, 3] - rc) / h
                v_land = (rc - r1) / h  # outward speed that reaches the circle at the next update
                held = max(0.0, f_r - m * (v_land - v_r - dv) / h) - m * dv / h  # never beyond the circle
            else:  # on the race: the race takes the outward load (the joint would, a step too late if slack)
                held = max(0.0, f_r)
            out_f[3 * i] -= held * ex
            out_f[3 * i + 1] -= held * ey
            n_held[i] = held
    if inner and dynamic:
        ring_v[0] += h * frx / ring_mass
        ring_v[1] += h * fry / ring_mass
    return it


#: rigid raceways: a roller centre within this distance inside its outer-race circle is on the race [m]
RACE_ORBIT_TOL_M = 1e-9
#: rigid raceways: a roller on the race is handed to pymunk this fraction outside its circle, so that the
#: joint holds it in the step and the force kernel's "beyond the circle" test is not left to rounding
RACE_ORBIT_OUTSIDE = 1e-14


@njit(cache=True, inline="always")
def race_orbit(state, h, prm, hold, n_extra, diag):
    """Rigid raceways: rollers on the outer race in the no-load zone advance along it as an exact
    rotation; returns nothing. (``docs/fast_scene.md``, *Rollers on the race move on their circle*.)

    pymunk moves a body along a straight line, ``x + h v``, and the slide joint puts a roller back on
    its circle through its real velocity: the roller then enters each contact solve moving inward at
    ``r omega^2 h / 2`` against the cage, whose points pymunk moves on exact circles with tangent
    velocities (at 3000 rpm and 22 us, 9 mm/s; the contact reads it as an approach or a separation on
    the slanted face segments). Here a roller on the race is handed to pymunk with the velocity it has
    at the point the rotation by ``v_t h / r`` reaches, from the position that pymunk's ``x + h v``
    takes to that point: the contact solve sees the roller's velocity as it sees the cage's.

    * on the circle (centre at most ``RACE_ORBIT_TOL_M`` inside it, and not leaving it faster than the
      centripetal acceleration ``v_t^2 / r_c`` brings it back within the step): it lands on the circle
      with its tangential speed ``v_t`` and no radial speed; the race carries the centripetal force
      and stops the radial speed, ``m (v_t^2 / r_c + v_r / h)`` (at least 0; ``v_r`` outward positive);
    * beyond the circle (pushed out by a contact's overlap correction, or being put back by the joint):
      only its tangential motion is rotated, its radial position and speed stay pymunk's (it lands at
      ``r + h v_r``), and the race carries ``m v_t^2 / r``.

    That force goes into ``n_extra`` [N], added to the joint's for the normal force of the outer contact
    (traction, drag). Left alone: rollers in ``hold`` (reduced-equivalent scene, prescribed), rollers
    the inner race loaded in the last step (``diag.q_in``: in the load zone, rotating them made the
    rollers at its centre rattle between their faces at 500 rpm), and rollers off the race.

    state : (nb, 6) body states before the step (rows 0..n-1 the rollers), changed in place.
    """
    n = n_extra.shape[0]
    rc = prm.rigid_radius
    m = prm.roller_mass
    r_out = rc * (1.0 + RACE_ORBIT_OUTSIDE)
    for i in range(n):
        n_extra[i] = 0.0
        if hold[i] or diag[i].q_in > 0.0:
            continue  # prescribed (reduced-equivalent scene), or in the load zone (held by both races)
        x = state[i, 0]
        y = state[i, 1]
        r = math.sqrt(x * x + y * y)
        if r < rc - RACE_ORBIT_TOL_M:
            continue  # off the race
        erx = x / r
        ery = y / r
        vr = state[i, 3] * erx + state[i, 4] * ery
        vt = -state[i, 3] * ery + state[i, 4] * erx
        beyond = r - rc > RACE_ORBIT_TOL_M
        if beyond:
            # pushed beyond the circle (a contact's overlap correction, or the joint's error): its radial
            # motion is left to pymunk as it is (the joint puts it back through its velocity), only the
            # tangential motion follows the circle
            r1 = r + h * vr
            vrn = vr
        elif vr < -vt * vt / rc * h:
            continue  # leaving the race faster than the centripetal acceleration returns it within the step
        else:
            r1 = r_out
            vrn = 0.0
        th = vt * h / r
        c = math.cos(th)
        s = math.sin(th)
        ex = erx * c - ery * s  # e_r where the rotation takes the roller
        ey = erx * s + ery * c
        vx = vrn * ex - vt * ey
        vy = vrn * ey + vt * ex
        state[i, 0] = r1 * ex - h * vx
        state[i, 1] = r1 * ey - h * vy
        state[i, 3] = vx
        state[i, 4] = vy
        n_extra[i] = m * vt * vt / r if beyond else max(0.0, m * (vt * vt / rc + vr / h))


class LandParams(NamedTuple):
    """Inputs of :func:`land_force` that are fixed for a run (a cage guided on a ring land). SI throughout."""

    active: bool  #: the cage runs on a ring land (else :func:`land_force` is not called)
    side: float  #: +1: outer land (contact at the cage's outer rim); -1: inner land (at the cage's bore)
    rim_radius: float  #: radius of the cage rim on the land, R_land [m]
    half_clearance: float  #: half the diametral land clearance, c_L/2 [m]
    stiffness: float  #: linear penalty stiffness k of the land contact [N/m]
    damping: float  #: contact damping c [N s/m], faded in over ``damping_fade``
    damping_fade: float  #: approach over which the damping fades in [m]
    friction: float  #: Coulomb friction coefficient mu of the rim on the land
    inner: bool  #: the land is on the inner ring (moves with its centre, turns at ``omega_ring``)
    omega_ring: float  #: signed angular speed of the guiding ring [rad/s] (0: the fixed outer ring)
    slide_eps: float  #: regularisation speed of the friction direction [m/s]


#: What :func:`land_force` reports for one step, array shape (4,): normal force N [N], friction force
#: along the tangent t = rot90(u) [N], its torque on the cage [N m], overlap e - c_L/2 [m] (<= 0: open).
LAND_N, LAND_FT, LAND_TORQUE, LAND_OVERLAP = range(4)


@njit(cache=True)
def land_force(state, h, lp, ring_c, ring_c_prev, out_f, out):
    """Add the land contact force and friction torque on the cage (the last body) to ``out_f``.

    The cage rim (radius ``R = lp.rim_radius``) runs on a land of the guiding ring with a diametral
    clearance ``c_L``. With ``e`` the offset of the cage centre from the guiding ring's centre (outer
    ring: the bearing axis; inner ring: its current centre) and ``u`` its direction, the rim touches the
    land when ``e > c_L/2``, at ``P = x_cage + side R u``. The normal force on the cage is
    ``N = k (e - c_L/2) + c d(e)/dt`` (clamped at 0, damping faded in as in the raceway contacts) along
    ``-u``; Coulomb friction ``mu N`` acts along the tangent ``t = rot90(u)`` against the sliding speed of
    the rim over the land (rim: ``v_cage . t + omega_cage side R``; land: 0 on the fixed outer ring,
    ``v_ring . t + omega_ring (e - R)`` on the inner ring), with the sign regularised over
    ``lp.slide_eps``. Its torque on the cage is ``side R F_t``. As the raceway forces, everything is
    evaluated at the predicted cage position ``x + h v`` (pymunk moves positions with the old
    velocities first), the damping with the overlap rate over the step.

    The reaction on an inner ring is not fed back into the ring's balance (the land force is mostly of
    the order of the cage weight, three orders below the radial load the ring carries; an impact can
    reach more: 37 kN when a quasi-static ring's centre jumped into the cage at 20000 rpm,
    docs/stability.md, *Land-guided cage*).

    Parameters
    ----------
    state : (nb, 6) body states before the step (x [m], y [m], angle [rad], vx [m/s], vy [m/s],
        omega [rad/s]); the cage is the last row.
    h : time step [s].
    lp : :class:`LandParams`.
    ring_c, ring_c_prev : (2,) inner-ring centre of this step and of the previous one [m] (inner land).
    out_f : (nb * 3,) (fx [N], fy [N], torque [N m]) per body; the cage's row is added to.
    out : (4,) out: :data:`LAND_N`, :data:`LAND_FT`, :data:`LAND_TORQUE`, :data:`LAND_OVERLAP`.
    """
    n = state.shape[0] - 1
    x = state[n, 0]
    y = state[n, 1]
    vx = state[n, 3]
    vy = state[n, 4]
    w = state[n, 5]
    gx = gy = gx0 = gy0 = gvx = gvy = 0.0
    if lp.inner:
        gx = ring_c[0]
        gy = ring_c[1]
        gx0 = ring_c_prev[0]
        gy0 = ring_c_prev[1]
        gvx = (gx - gx0) / h
        gvy = (gy - gy0) / h
    ex = x + h * vx - gx
    ey = y + h * vy - gy
    e = math.sqrt(ex * ex + ey * ey)
    delta = e - lp.half_clearance
    out[LAND_N] = 0.0
    out[LAND_FT] = 0.0
    out[LAND_TORQUE] = 0.0
    out[LAND_OVERLAP] = delta
    if delta <= 0.0:
        return
    delta0 = math.sqrt((x - gx0) ** 2 + (y - gy0) ** 2) - lp.half_clearance
    fade = delta / lp.damping_fade if delta < lp.damping_fade else 1.0
    q = lp.stiffness * delta + lp.damping * fade * (delta - delta0) / h
    if q <= 0.0:
        return
    ux = ex / e
    uy = ey / e
    tx = -uy
    ty = ux
    r = lp.side * lp.rim_radius
    slide = vx * tx + vy * ty + w * r  # rim speed along t at P
    if lp.inner:  # minus the land's: the contact point is (e - R) u from the ring centre
        slide -= gvx * tx + gvy * ty + lp.omega_ring * (e - lp.rim_radius)
    ft = -lp.friction * q * slide / math.sqrt(slide * slide + lp.slide_eps * lp.slide_eps)
    torque = r * ft
    out_f[3 * n] += -q * ux + ft * tx
    out_f[3 * n + 1] += -q * uy + ft * ty
    out_f[3 * n + 2] += torque
    out[LAND_N] = q
    out[LAND_FT] = ft
    out[LAND_TORQUE] = torque


from bearingsim._jit import drop_stale_caches  # noqa: E402

drop_stale_caches(__name__, (laws, compiled_laws))  # the contact kernels compile in the laws of laws.py
