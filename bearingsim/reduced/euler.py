"""The paper's explicit finite-difference scheme (Eqs. 7–9), with both pocket faces. SI throughout.

This is the baseline the event solver is measured against. Each step of size Δt (θ = ω_c t + φ):

    v_{n+1} = v_n + a(θ_n) Δt,     l_{n+1} = l_n + v_{n+1} Δt                  (Eqs. 7, 8)

with a(θ) = −g sin θ − F_o(θ)/m. When l_{n+1} leaves [0, s] the roller has hit a face: it is put
back on the face, its approach speed u = |v_{n+1}| gives the impulse m(1 + e)u (Eq. 6) and it
rebounds with e·u (Eq. 7, second case). When the rebound could not survive one step against the
acceleration pressing it onto the face (e·u ≤ |a|Δt), the remaining bounce sequence is closed the
way the event solver closes a Zeno sequence (credit m·u and rest; without resting contact, the
geometric sum m·u(1 + e)/(1 − e)), so both methods converge to the same limit. While resting, the
face carries ∫ m|a| dt (Eq. 9, third case) as long as a presses it onto the face; the roller lifts
off on the first step where a has turned.

The scheme is first order in Δt: impact instants and approach speeds are both O(Δt) off.
"""
from __future__ import annotations

import math
import time

import numpy as np
from numba import njit

from bearingsim import laws
from bearingsim._jit import drop_stale_caches
from bearingsim.errors import UserError
from bearingsim.reduced import core as _core
from bearingsim.reduced.core import (
    FACE_FRONT,
    FACE_REAR,
    FREE,
    KIND_IMPACT,
    KIND_ZENO,
    REST_FRONT,
    REST_REAR,
    PassInputs,
    net_accel,
)
from bearingsim.reduced.event import PassSolution

MIN_STEPS_PER_PASS = 100
MAX_TRAVEL_FRACTION = 0.1  # the fastest possible approach may cross at most 10 % of s in one step


@njit(cache=True)
def _euler_pass(par, dt, cap, stride):
    m, s, omega, g, e = par[0], par[1], par[2], par[3], par[4]
    th0, th1, K, A = par[5], par[6], par[7], par[8]
    resting = par[9] > 0.5
    duration = (th1 - th0) / omega
    nsteps = int(math.ceil(duration / dt - 1e-9))
    impacts = np.zeros((cap, 5))
    ntr = nsteps // stride + 2
    trace = np.zeros((ntr, 4))  # theta, l, v, I_dec cumulative
    n_imp = 0
    ntrace = 0
    I_dec = 0.0
    I_acc = 0.0
    I_dec_rest = 0.0
    I_acc_rest = 0.0
    l = s
    v = 0.0
    a0 = net_accel(th0, K, A, g)
    mode = REST_FRONT if a0 > 0.0 else FREE
    overflow = False
    t = 0.0
    for n in range(nsteps):
        h = dt if t + dt <= duration else duration - t
        th = th0 + omega * t
        if n % stride == 0 and ntrace < ntr:
            trace[ntrace, 0] = th
            trace[ntrace, 1] = l
            trace[ntrace, 2] = v
            trace[ntrace, 3] = I_dec
            ntrace += 1
        a = net_accel(th, K, A, g)
        if mode == REST_REAR:
            if a < 0.0:
                if resting:
                    I_dec += -m * a * h
                    I_dec_rest += -m * a * h
                t += h
                continue
            mode = FREE
        elif mode == REST_FRONT:
            if a > 0.0:
                if resting:
                    I_acc += m * a * h
                    I_acc_rest += m * a * h
                t += h
                continue
            mode = FREE
        v = v + a * h
        l = l + v * h
        t += h
        face = -1
        if l <= 0.0 and v < 0.0:
            face = FACE_REAR
            u = -v
            l = 0.0
        elif l >= s and v > 0.0:
            face = FACE_FRONT
            u = v
            l = s
        if face < 0:
            continue
        pressing = (a < 0.0) if face == FACE_REAR else (a > 0.0)
        kind = KIND_IMPACT
        J = m * (1.0 + e) * u
        rest_now = False
        if pressing and e * u <= abs(a) * h:
            kind = KIND_ZENO
            rest_now = True
            if resting or e <= 0.0 or e >= 1.0:
                J = m * u
            else:
                J = m * u * (1.0 + e) / (1.0 - e)
        if n_imp < cap:
            impacts[n_imp, 0] = th0 + omega * t
            impacts[n_imp, 1] = u
            impacts[n_imp, 2] = J
            impacts[n_imp, 3] = face
            impacts[n_imp, 4] = kind
            n_imp += 1
        else:
            overflow = True
        if face == FACE_REAR:
            I_dec += J
            v = 0.0 if rest_now else e * u
            mode = REST_REAR if rest_now else FREE
        else:
            I_acc += J
            v = 0.0 if rest_now else -e * u
            mode = REST_FRONT if rest_now else FREE
    if ntrace < ntr:
        trace[ntrace, 0] = th1
        trace[ntrace, 1] = l
        trace[ntrace, 2] = v
        trace[ntrace, 3] = I_dec
        ntrace += 1
    totals = np.array([I_dec, I_acc, I_dec_rest, I_acc_rest, l, v, float(mode), float(n_imp)])
    return overflow, totals, impacts, n_imp, trace[:ntrace], nsteps


def max_stable_dt(inp: PassInputs) -> float:
    """Largest Δt the explicit scheme is allowed [s].

    Two bounds: at least ``MIN_STEPS_PER_PASS`` steps per pass, and the fastest approach the pocket
    allows, u_max = sqrt(2 a_max s) (the roller starts at rest and can fall at most the clearance s
    between rebounds, which only lose speed), may cross at most 10 % of s in one step.
    """
    a_max = inp.gravity + inp.drag_scale * (inp.centripetal + inp.gravity) ** laws.DRAG_LOAD_EXPONENT
    u_max = math.sqrt(2.0 * max(a_max, 1e-30) * inp.pocket_clearance)
    return min(inp.pass_duration / MIN_STEPS_PER_PASS, MAX_TRAVEL_FRACTION * inp.pocket_clearance / u_max)


def default_dt(inp: PassInputs) -> float:
    """Automatic Δt: 1/1000 of the largest allowed (first order: ~0.1 % error in I_dec) [s]."""
    return max_stable_dt(inp) / 1000.0


def solve_euler(inp: PassInputs, dt: float, *, trace_points: int = 2000, capacity: int = 4096) -> PassSolution:
    """Integrate one no-load pass with the paper's scheme at step ``dt`` [s].

    Raises :class:`UserError` (naming ``numerics.dt_s``) when ``dt`` exceeds :func:`max_stable_dt`.
    """
    dt_max = max_stable_dt(inp)
    if not dt <= dt_max:
        raise UserError(
            f"numerics.dt_s: {dt:.3g} s is too large for the euler method at this speed; "
            f"use at most {dt_max:.3g} s (or leave dt_s out for the automatic choice)"
        )
    from bearingsim.reduced.event import _params

    par = _params(inp, 0.0, 0.0)
    nsteps = int(math.ceil(inp.pass_duration / dt))
    stride = max(1, nsteps // max(trace_points, 1))
    t0 = time.perf_counter()
    while True:
        overflow, totals, impacts, n_imp, trace, nsteps = _euler_pass(par, float(dt), capacity, stride)
        if not overflow:
            break
        capacity *= 8
    wall = time.perf_counter() - t0
    imp = impacts[:n_imp]
    theta = imp[:, 0].copy()
    sol = PassSolution(
        method="euler",
        I_dec=float(totals[0]),
        I_acc=float(totals[1]),
        I_dec_resting=float(totals[2]),
        I_acc_resting=float(totals[3]),
        impacts=dict(
            theta=theta,
            time=(theta - inp.theta_start) / inp.omega_c,
            approach_speed=imp[:, 1].copy(),
            impulse=imp[:, 2].copy(),
            face=imp[:, 3].astype(np.int64),
            kind=imp[:, 4].astype(np.int64),
        ),
        l_end=float(totals[4]),
        v_end=float(totals[5]),
        trace=None,
        wall_s=wall,
        termination="end of the no-load pass reached (theta = 2*pi - phi)",
        dt=float(dt),
        info=dict(steps=int(nsteps), dt_max=dt_max),
    )
    if trace_points > 0:
        sol.trace = dict(theta=trace[:, 0].copy(), l_r=trace[:, 1].copy(), dl_r_dt=trace[:, 2].copy(),
                         I_dec_cumulative=trace[:, 3].copy())
    return sol


drop_stale_caches(__name__, (_core, laws))  # the kernels here compile in those of reduced/core.py and laws.py
