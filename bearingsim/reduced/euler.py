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
# Steps of one pass: the compiled loop takes ~60 ns a step (3000 rpm, one core of a 2020s x86 machine),
# so 1e8 steps is ~6 s. The automatic step needs ~2e5 at 3000 rpm and ~4e7 at 150 rpm with a 0.001 mm
# pocket clearance; a run that would need more is refused before it starts (the event method solves
# the same pass in milliseconds whatever the clearance).
MAX_STEPS_PER_PASS = 100_000_000
# The compiled loop returns to Python at least every CHUNK_STEPS steps (~0.1 s), so that a pending
# SIGINT/SIGTERM is raised there and the run's clean-up paths run (as the multibody loop does).
CHUNK_STEPS = 2_000_000
# return codes of _euler_steps
CODE_DONE, CODE_CHUNK_END, CODE_IMPACTS_FULL = 0, 1, 2
# the loop state carried between calls of _euler_steps
F_T, F_L, F_V, F_IDEC, F_IACC, F_IDEC_REST, F_IACC_REST = range(7)
I_STEP, I_MODE, I_NIMP, I_NTRACE, I_STARTED = range(5)


@njit(cache=True)
def _euler_steps(par, dt, nsteps, stride, fst, ist, impacts, trace, max_steps):
    """Advance the pass by at most ``max_steps`` steps from the state in ``fst``/``ist``.

    Returns a code only (``CODE_*``): everything else is written into the arrays passed in. Numba boxes
    a returned array by calling Python code, which runs a pending signal's handler; the exception it
    raises there is not checked and the process dies of SIGSEGV, so a kernel that may run while a
    signal arrives must return no array.
    """
    m, s, omega, g, e = par.mass, par.clearance, par.omega_c, par.gravity, par.restitution
    th0, th1, K, A = par.theta_start, par.theta_end, par.drag_scale, par.centripetal
    resting = par.resting_contact
    duration = (th1 - th0) / omega
    cap = impacts.shape[0]
    ntr = trace.shape[0]
    if ist[I_STARTED] == 0:
        fst[F_L] = s
        fst[F_V] = 0.0
        a0 = net_accel(th0, K, A, g)
        ist[I_MODE] = REST_FRONT if a0 > 0.0 else FREE
        ist[I_STARTED] = 1
    t, l, v = fst[F_T], fst[F_L], fst[F_V]
    I_dec, I_acc, I_dec_rest, I_acc_rest = fst[F_IDEC], fst[F_IACC], fst[F_IDEC_REST], fst[F_IACC_REST]
    mode, n_imp, ntrace = ist[I_MODE], ist[I_NIMP], ist[I_NTRACE]
    n = ist[I_STEP]
    n_stop = min(nsteps, n + max_steps)
    code = CODE_CHUNK_END
    while n < n_stop:
        if n_imp >= cap:  # a step makes at most one impact: stop before it, with the state of its start
            code = CODE_IMPACTS_FULL
            break
        h = dt if t + dt <= duration else duration - t
        th = th0 + omega * t
        if n % stride == 0 and ntrace < ntr:
            trace[ntrace, 0] = th
            trace[ntrace, 1] = l
            trace[ntrace, 2] = v
            trace[ntrace, 3] = I_dec
            trace[ntrace, 4] = I_acc
            ntrace += 1
        n += 1
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
        impacts[n_imp, 0] = th0 + omega * t
        impacts[n_imp, 1] = u
        impacts[n_imp, 2] = J
        impacts[n_imp, 3] = face
        impacts[n_imp, 4] = kind
        n_imp += 1
        if face == FACE_REAR:
            I_dec += J
            v = 0.0 if rest_now else e * u
            mode = REST_REAR if rest_now else FREE
        else:
            I_acc += J
            v = 0.0 if rest_now else -e * u
            mode = REST_FRONT if rest_now else FREE
    if n >= nsteps and code == CODE_CHUNK_END:
        code = CODE_DONE
        if ntrace < ntr:
            trace[ntrace, 0] = th1
            trace[ntrace, 1] = l
            trace[ntrace, 2] = v
            trace[ntrace, 3] = I_dec
            trace[ntrace, 4] = I_acc
            ntrace += 1
    fst[F_T], fst[F_L], fst[F_V] = t, l, v
    fst[F_IDEC], fst[F_IACC], fst[F_IDEC_REST], fst[F_IACC_REST] = I_dec, I_acc, I_dec_rest, I_acc_rest
    ist[I_MODE], ist[I_NIMP], ist[I_NTRACE], ist[I_STEP] = mode, n_imp, ntrace, n
    return code


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


def steps_per_pass(inp: PassInputs, dt: float) -> int:
    """Number of steps of size ``dt`` [s] the scheme takes for one pass (the last one shortened)."""
    duration = (inp.theta_end - inp.theta_start) / inp.omega_c
    return int(math.ceil(duration / dt - 1e-9))


def check_step(inp: PassInputs, dt: float, automatic: bool = False) -> int:
    """Refuse a step the scheme cannot take (one line naming the key); return the number of steps.

    ``dt`` must be positive, at most :func:`max_stable_dt`, and need at most ``MAX_STEPS_PER_PASS``
    steps for the pass. ``automatic``: ``dt`` is :func:`default_dt` (``numerics.dt_s`` left out), whose
    size is set by the pocket clearance, so the message names that key.
    """
    dt_max = max_stable_dt(inp)
    try:
        step = float(dt)
    except (TypeError, ValueError):
        step = math.nan
    if not (math.isfinite(step) and step > 0.0):
        raise UserError(f"numerics.dt_s: {dt!r} s is not a time step; give a positive number of seconds "
                        f"(at most {dt_max:.3g} s for the euler method here) or leave dt_s out")
    dt = step
    if not dt <= dt_max:
        raise UserError(
            f"numerics.dt_s: {dt:.3g} s is too large for the euler method at this speed; "
            f"use at most {dt_max:.3g} s (or leave dt_s out for the automatic choice)"
        )
    nsteps = steps_per_pass(inp, dt)
    if nsteps > MAX_STEPS_PER_PASS:
        if automatic:
            # the step is 1/1000 of the time the fastest approach, sqrt(2 a_max s), takes to cross 10 % of s:
            # the steps of a pass go as s^(-1/2) and as the pass's duration (1 / speed)
            least = inp.pocket_clearance * 1e3 * (nsteps / MAX_STEPS_PER_PASS) ** 2 * 1.01
            raise UserError(
                f"bearing.pocket_clearance_mm: {inp.pocket_clearance * 1e3:.3g} mm makes the euler method's automatic "
                f"step (numerics.dt_s left out) {dt:.3g} s, {nsteps:.3g} steps for one pass of {nsteps * dt:.3g} s, "
                f"more than {MAX_STEPS_PER_PASS:.0e}; use reduced.method = \"event\", a clearance of at least "
                f"{least:.3g} mm, or a higher operating.inner_ring_speed_rpm (a shorter pass)")
        raise UserError(
            f"numerics.dt_s: {dt:.3g} s needs {nsteps:.3g} euler steps for one pass, more than "
            f"{MAX_STEPS_PER_PASS:.0e}; use at least {1.01 * inp.pass_duration / MAX_STEPS_PER_PASS:.3g} s "
            f"(or reduced.method = \"event\")")
    return nsteps


def solve_euler(inp: PassInputs, dt: float, *, trace_points: int = 2000, capacity: int = 4096,
                automatic: bool = False) -> PassSolution:
    """Integrate one no-load pass with the paper's scheme at step ``dt`` [s].

    Raises :class:`UserError` (naming ``numerics.dt_s``, or ``bearing.pocket_clearance_mm`` for the
    ``automatic`` step) when ``dt`` is not positive, exceeds :func:`max_stable_dt` or needs more than
    ``MAX_STEPS_PER_PASS`` steps (:func:`check_step`). The compiled loop runs in chunks of
    ``CHUNK_STEPS`` steps, so SIGINT/SIGTERM stop it within a chunk.
    """
    nsteps = check_step(inp, dt, automatic)
    dt = float(dt)
    dt_max = max_stable_dt(inp)
    from bearingsim.reduced.event import pass_constants

    par = pass_constants(inp, 0.0, 0.0)
    stride = max(1, int(math.ceil(inp.pass_duration / dt)) // max(trace_points, 1))
    impacts = np.zeros((max(int(capacity), 1), 5))
    trace = np.zeros((nsteps // stride + 2, 5))  # theta, l, v, I_dec and I_acc cumulative
    fst = np.zeros(7)
    ist = np.zeros(5, dtype=np.int64)
    t0 = time.perf_counter()
    while True:
        code = _euler_steps(par, float(dt), nsteps, stride, fst, ist, impacts, trace, CHUNK_STEPS)
        if code == CODE_DONE:
            break
        if code == CODE_IMPACTS_FULL:
            impacts = np.concatenate([impacts, np.zeros((7 * impacts.shape[0], 5))])
    totals = fst
    n_imp = int(ist[I_NIMP])
    trace = trace[: int(ist[I_NTRACE])]
    wall = time.perf_counter() - t0
    imp = impacts[:n_imp]
    theta = imp[:, 0].copy()
    sol = PassSolution(
        method="euler",
        I_dec=float(totals[F_IDEC]),
        I_acc=float(totals[F_IACC]),
        I_dec_resting=float(totals[F_IDEC_REST]),
        I_acc_resting=float(totals[F_IACC_REST]),
        impacts=dict(
            theta=theta,
            time=(theta - inp.theta_start) / inp.omega_c,
            approach_speed=imp[:, 1].copy(),
            impulse=imp[:, 2].copy(),
            face=imp[:, 3].astype(np.int64),
            kind=imp[:, 4].astype(np.int64),
        ),
        l_end=float(totals[F_L]),
        v_end=float(totals[F_V]),
        trace=None,
        wall_s=wall,
        termination="end of the no-load pass reached (theta = 2*pi - phi)",
        dt=float(dt),
        info=dict(steps=int(nsteps), dt_max=dt_max),
    )
    if trace_points > 0:
        sol.trace = dict(theta=trace[:, 0].copy(), l_r=trace[:, 1].copy(), dl_r_dt=trace[:, 2].copy(),
                         I_dec_cumulative=trace[:, 3].copy(), I_acc_cumulative=trace[:, 4].copy())
    return sol


drop_stale_caches(__name__, (_core, laws))  # the kernels here compile in those of reduced/core.py and laws.py
