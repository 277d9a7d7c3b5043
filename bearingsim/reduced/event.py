"""Exact event-driven solution of one no-load pass of the reduced model. SI throughout.

Between contacts the roller's acceleration in the pocket is a fixed function of θ alone,
a(θ) = −g sin θ − f(θ) with f = F_o/m (see :mod:`bearingsim.reduced.core`), so the motion has a closed
form from any flight start (θ_s, l_s, v_s), with τ = (θ − θ_s)/ω_c:

    v(θ) = v_s + (g/ω)(cos θ − cos θ_s) − [F1(θ) − F1(θ_s)]
    l(θ) = l_s + v_s τ + (g/ω²)(sin θ − sin θ_s − (θ − θ_s) cos θ_s) − [F2(θ) − F2(θ_s) − F1(θ_s) τ]

where F1 = ∫ f dt and F2 = ∫ F1 dt. Gravity is integrated analytically (in a form without
cancellation); f is represented by piecewise Chebyshev interpolants of degree 32 built adaptively until
their tail coefficients fall below ``cheb_tol`` × max f (≈1e-14 by default), and the interpolants are
integrated exactly (Chebyshev antiderivatives). Panels are split at the roots of N = 0, where
f ∝ N^0.246 is singular; bisection towards such an end is a geometric grading with ratio 1/2 down to
``min_width`` rad, and f = 0 where N ≤ 0 (the roller has left the outer race).

**Impacts are never missed.** The roots of a(θ) are found once per pass (Lipschitz exclusion with a
bound on |a'| from each panel's Chebyshev coefficients, then bisection to machine precision). Between
consecutive roots of a, v is monotone, so it has at most one root (found by safeguarded Newton); between
roots of v, l is monotone, so a face is reached inside a sub-segment exactly when the gap changes sign
at its ends. Each crossing is then located by safeguarded Newton (derivative v/ω) to machine precision.

**Faces and resting contact.** A rear impact (l = 0, approach speed u) adds m(1+e)u to I_dec, a front
impact (l = s) adds m(1+e)u to I_acc (Eq. 6). While the roller rests on a face and a(θ) presses it
onto that face, the face carries the impulse ∫ m|a| dt (Eq. 9, third case), integrated exactly; it
lifts off at the root of a.

**Zeno sequences.** When the rebound height (e u)²/(2|a|) falls below ``zeno_height`` × s and the
bounce sequence's duration 2eu/((1−e)|a|) (with a safety factor 2) ends before a changes sign and
before the pass ends, the sequence is closed at once:

* with resting contact: the impact is credited m u and resting contact starts at the impact. By the
  momentum balance over the sequence, its impacts sum to m u + ∫ m|a| dt over the sequence, and that
  integral is exactly what the resting phase counts: I_dec is unchanged (to rounding) whatever
  ``zeno_height`` is;
* without resting contact (the previous model): the impact is credited the geometric sum of the
  sequence m u (1+e)/(1−e) and nothing is counted while resting.

Below ``zeno_floor`` × s (bounces at the scale of the position rounding) the sequence is closed even
when it would outlast its window; the error is then ≤ m × (a speed below 1e-6 m/s).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from bearingsim.errors import SimulationUnstable
from bearingsim.reduced.core import (
    FACE_FRONT,
    FACE_REAR,
    FREE,
    KIND_IMPACT,
    KIND_ZENO,
    REST_FRONT,
    REST_REAR,
    PassInputs,
    drag_accel,
    gravity_dl,
    gravity_dv,
)

CHEB_DEGREE = 32
_J = np.arange(CHEB_DEGREE + 1)
CHEB_NODES = np.cos(np.pi * _J / CHEB_DEGREE)  # Chebyshev-Lobatto points on [-1, 1]
CHEB_COS = np.cos(np.pi * np.outer(_J, _J) / CHEB_DEGREE)

DEFAULT_CHEB_TOL = 1e-14
DEFAULT_ZENO_HEIGHT = 1e-6  # x s: 0.2 nm on the reference pocket, far below surface roughness
DEFAULT_ZENO_FLOOR = 1e-11  # x s: a few hundred times the position rounding of the closed form
DEFAULT_MIN_WIDTH = 1e-13  # rad: smallest Chebyshev panel next to an N = 0 singularity

_MAX_AROOTS = 256
STATUS_OK = 0
STATUS_OVERFLOW = 1
STATUS_STUCK = 2


# ---- Chebyshev machinery ------------------------------------------------------------------------
@njit(cache=True)
def _clenshaw(c, n, x):
    """Σ_{k<n} c[k] T_k(x)."""
    b1 = 0.0
    b2 = 0.0
    for k in range(n - 1, 0, -1):
        b0 = 2.0 * x * b1 - b2 + c[k]
        b2 = b1
        b1 = b0
    return x * b1 - b2 + c[0]


@njit(cache=True)
def _antiderivative(c, n, scale, out):
    """Chebyshev coefficients (n+1 of them) of scale × ∫_{-1}^{x} Σ c_k T_k, which is 0 at x = −1."""
    for k in range(n + 1):
        out[k] = 0.0
    for k in range(1, n + 1):
        cm = c[k - 1]
        cp = c[k + 1] if k + 1 < n else 0.0
        if k == 1:
            out[1] = cm - 0.5 * cp
        else:
            out[k] = (cm - cp) / (2.0 * k)
    s = 0.0
    sign = -1.0
    for k in range(1, n + 1):
        s += out[k] * sign
        sign = -sign
    out[0] = -s
    for k in range(n + 1):
        out[k] *= scale


@njit(cache=True)
def _fit_panel(a, b, K, A, g, root, sin_root, nodes, cosmat, fv, out):
    """Chebyshev coefficients of f = F_o/m on [a, b] (degree len(nodes) − 1) into ``out``.

    When the interval ends at a root θ_r of N (``root`` not NaN), N/m = A + g cos θ is evaluated as
    −2g sin(θ_r + d/2) sin(d/2) with d = θ − θ_r formed from the panel's own offset, so that f keeps
    its relative accuracy next to the N^0.246 singularity (θ itself is only known to ~4e-16 rad).
    """
    n = nodes.shape[0] - 1
    mid = 0.5 * (a + b)
    half = 0.5 * (b - a)
    if math.isnan(root):
        for j in range(n + 1):
            fv[j] = drag_accel(mid + half * nodes[j], K, A, g)
    else:
        off = mid - root
        cos_root = -A / g
        for j in range(n + 1):
            d = off + half * nodes[j]
            h = 0.5 * d
            nm = -2.0 * g * (sin_root * math.cos(h) + cos_root * math.sin(h)) * math.sin(h)
            fv[j] = K * nm**0.246 if nm > 0.0 else 0.0
    for k in range(n + 1):
        s = 0.5 * (fv[0] * cosmat[0, k] + fv[n] * cosmat[n, k])
        for j in range(1, n):
            s += fv[j] * cosmat[j, k]
        out[k] = 2.0 * s / n
    out[0] *= 0.5
    out[n] *= 0.5


@njit(cache=True)
def _build_table(th0, th1, omega, K, A, g, tol, min_width, nroots_n, root_n0, root_n1, nodes, cosmat, cap):
    """Adaptive piecewise-Chebyshev table of f and of its time integrals F1, F2 on [th0, th1].

    Returns (breaks, fco, q1, q2, F1L, F2L, npan); npan = −1 when more than ``cap`` panels are needed.
    """
    n = nodes.shape[0] - 1
    breaks = np.empty(cap + 1)
    fco = np.empty((cap, n + 1))
    fscale = K * max(A + g, 0.0) ** 0.246
    # base intervals: split at the roots of N = 0 inside the pass
    base = np.empty(4)
    nb = 0
    base[nb] = th0
    nb += 1
    if nroots_n >= 1 and th0 < root_n0 < th1:
        base[nb] = root_n0
        nb += 1
    if nroots_n >= 2 and th0 < root_n1 < th1 and root_n1 > base[nb - 1]:
        base[nb] = root_n1
        nb += 1
    base[nb] = th1
    nb += 1
    npan = 0
    stack_a = np.empty(512)
    stack_b = np.empty(512)
    coef = np.empty(n + 1)
    fv = np.empty(n + 1)
    for i in range(nb - 1):
        lo = base[i]
        hi = base[i + 1]
        mid = 0.5 * (lo + hi)
        if npan >= cap:
            return breaks, fco, fco, fco, breaks, breaks, -1
        if nroots_n > 0 and A + g * math.cos(mid) <= 0.0:
            # the roller is off the outer race on the whole interval: f = 0
            breaks[npan] = lo
            for k in range(n + 1):
                fco[npan, k] = 0.0
            npan += 1
            continue
        # the N = 0 root this interval touches, if any (evaluated in local offsets)
        root = np.nan
        sin_root = 0.0
        if nroots_n > 0:
            if lo == root_n0 or lo == root_n1:
                root = lo
            elif hi == root_n0 or hi == root_n1:
                root = hi
            if not math.isnan(root):
                sin_root = math.sqrt(max(0.0, 1.0 - (A / g) ** 2))
                if root > math.pi:
                    sin_root = -sin_root
        stack_a[0] = lo
        stack_b[0] = hi
        top = 1
        while top > 0:
            top -= 1
            a = stack_a[top]
            b = stack_b[top]
            _fit_panel(a, b, K, A, g, root, sin_root, nodes, cosmat, fv, coef)
            tail = abs(coef[n]) + abs(coef[n - 1])
            if tail <= tol * fscale or (b - a) <= min_width or top >= 510:
                if npan >= cap:
                    return breaks, fco, fco, fco, breaks, breaks, -1
                breaks[npan] = a
                for k in range(n + 1):
                    fco[npan, k] = coef[k]
                npan += 1
            else:
                m = 0.5 * (a + b)
                stack_a[top] = m  # right half first so the left half is processed next
                stack_b[top] = b
                stack_a[top + 1] = a
                stack_b[top + 1] = m
                top += 2
    breaks[npan] = th1
    breaks = breaks[: npan + 1].copy()
    fco = fco[:npan].copy()
    q1 = np.empty((npan, n + 2))
    q2 = np.empty((npan, n + 3))
    F1L = np.empty(npan)
    F2L = np.empty(npan)
    tmp = np.empty(n + 3)
    acc1 = 0.0
    acc2 = 0.0
    for p in range(npan):
        half = 0.5 * (breaks[p + 1] - breaks[p])
        scale = half / omega
        _antiderivative(fco[p], n + 1, scale, tmp)  # n+2 coefficients
        for k in range(n + 2):
            q1[p, k] = tmp[k]
        _antiderivative(q1[p], n + 2, scale, tmp)  # n+3 coefficients
        for k in range(n + 3):
            q2[p, k] = tmp[k]
        F1L[p] = acc1
        F2L[p] = acc2
        q1_end = _clenshaw(q1[p], n + 2, 1.0)
        q2_end = _clenshaw(q2[p], n + 3, 1.0)
        acc2 = acc2 + acc1 * (2.0 * half) / omega + q2_end
        acc1 = acc1 + q1_end
    return breaks, fco, q1, q2, F1L, F2L, npan


@njit(cache=True)
def _panel(breaks, npan, th):
    lo = 0
    hi = npan - 1
    if th <= breaks[0]:
        return 0
    if th >= breaks[npan - 1]:
        return npan - 1
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if breaks[mid] <= th:
            lo = mid
        else:
            hi = mid - 1
    return lo


@njit(cache=True)
def _local_x(breaks, p, th):
    a = breaks[p]
    b = breaks[p + 1]
    x = (2.0 * th - a - b) / (b - a)
    if x < -1.0:
        return -1.0
    if x > 1.0:
        return 1.0
    return x


@njit(cache=True)
def _f_eval(tab, npan, th):
    breaks, fco = tab[0], tab[1]
    p = _panel(breaks, npan, th)
    return _clenshaw(fco[p], fco.shape[1], _local_x(breaks, p, th))


@njit(cache=True)
def _F1(tab, npan, th):
    breaks, q1, F1L = tab[0], tab[2], tab[4]
    p = _panel(breaks, npan, th)
    return F1L[p] + _clenshaw(q1[p], q1.shape[1], _local_x(breaks, p, th))


@njit(cache=True)
def _drag_dl(tab, npan, omega, ths, F1s, th):
    """∫_{θs}^{θ} [F1(θ') − F1(θs)] dt': the drag part of the displacement from a flight start."""
    breaks, q1, q2, F1L, F2L = tab[0], tab[2], tab[3], tab[4], tab[5]
    p = _panel(breaks, npan, th)
    ps = _panel(breaks, npan, ths)
    tau = (th - ths) / omega
    x = _local_x(breaks, p, th)
    n2 = q2.shape[1]
    if p == ps:  # same panel: local polynomials, no large cumulative constants to cancel
        xs = _local_x(breaks, p, ths)
        return _clenshaw(q2[p], n2, x) - _clenshaw(q2[p], n2, xs) - _clenshaw(q1[p], q1.shape[1], xs) * tau
    F2 = F2L[p] + F1L[p] * (th - breaks[p]) / omega + _clenshaw(q2[p], n2, x)
    xs = _local_x(breaks, ps, ths)
    F2s = F2L[ps] + F1L[ps] * (ths - breaks[ps]) / omega + _clenshaw(q2[ps], n2, xs)
    return F2 - F2s - F1s * tau


@njit(cache=True)
def _accel(tab, npan, g, th):
    """a(θ) consistent with the table (the derivative of the closed-form v)."""
    return -g * math.sin(th) - _f_eval(tab, npan, th)


@njit(cache=True)
def _flight(tab, npan, omega, g, ths, ls, vs, F1s, th):
    """(l, v) at θ of a free flight that started at (θs, ls, vs); F1s = F1(θs)."""
    v = vs + gravity_dv(ths, th, omega, g) - (_F1(tab, npan, th) - F1s)
    tau = (th - ths) / omega
    l = ls + vs * tau + gravity_dl(ths, th, omega, g) - _drag_dl(tab, npan, omega, ths, F1s, th)
    return l, v


# ---- roots of a(θ) ---------------------------------------------------------------------------
@njit(cache=True)
def _accel_roots(tab, npan, g):
    """Sign changes of a(θ) over the table, to machine precision; never misses one wider than 1e-12 rad."""
    breaks, fco = tab[0], tab[1]
    n = fco.shape[1]
    roots = np.empty(_MAX_AROOTS)
    nr = 0
    sa = np.empty(256)
    sb = np.empty(256)
    for p in range(npan):
        a0 = breaks[p]
        a1 = breaks[p + 1]
        half = 0.5 * (a1 - a0)
        dmax = 0.0
        for k in range(1, n):
            dmax += k * k * abs(fco[p, k])
        # 10 % margin: the bound is tight for a linear a(θ), and rounding must not exclude a root
        lip = 1.1 * (abs(g) + (dmax / half if half > 0 else 0.0))
        sa[0] = a0
        sb[0] = a1
        top = 1
        while top > 0:
            top -= 1
            x0 = sa[top]
            x1 = sb[top]
            f0 = -g * math.sin(x0) - _clenshaw(fco[p], n, _local_x(breaks, p, x0))
            f1 = -g * math.sin(x1) - _clenshaw(fco[p], n, _local_x(breaks, p, x1))
            if abs(f0) + abs(f1) > lip * (x1 - x0) or lip == 0.0:
                continue  # no root inside
            if (x1 - x0) <= 1e-12 or top >= 250:
                if (f0 > 0.0) != (f1 > 0.0):
                    lo = x0
                    hi = x1
                    flo = f0 > 0.0
                    for _ in range(200):
                        m = 0.5 * (lo + hi)
                        if m <= lo or m >= hi:
                            break
                        fm = -g * math.sin(m) - _clenshaw(fco[p], n, _local_x(breaks, p, m))
                        if (fm > 0.0) == flo:
                            lo = m
                        else:
                            hi = m
                    if nr < _MAX_AROOTS:
                        roots[nr] = 0.5 * (lo + hi)
                        nr += 1
                continue
            m = 0.5 * (x0 + x1)
            sa[top] = m
            sb[top] = x1
            sa[top + 1] = x0
            sb[top + 1] = m
            top += 2
        # a sign change exactly across a panel boundary (continuous f, rounding only)
        if p + 1 < npan:
            xb = breaks[p + 1]
            fl = -g * math.sin(xb) - _clenshaw(fco[p], n, 1.0)
            fr = -g * math.sin(xb) - _clenshaw(fco[p + 1], n, -1.0)
            if (fl > 0.0) != (fr > 0.0) and nr < _MAX_AROOTS:
                roots[nr] = xb
                nr += 1
    out = np.sort(roots[:nr])
    return out


@njit(cache=True)
def _next_root(roots, th):
    for i in range(roots.shape[0]):
        if roots[i] > th:
            return roots[i]
    return np.inf


# ---- safeguarded Newton ----------------------------------------------------------------------
@njit(cache=True)
def _root_gap(tab, npan, omega, g, ths, ls, vs, F1s, target, xa, xb):
    """θ in [xa, xb] where l(θ) = target; l − target changes sign on [xa, xb] and l is monotone."""
    la, _ = _flight(tab, npan, omega, g, ths, ls, vs, F1s, xa)
    lo_is_neg = (la - target) < 0.0
    lo = xa
    hi = xb
    # start from the end whose slope is larger (the crossing side)
    x = xb
    for _ in range(300):
        lx, vx = _flight(tab, npan, omega, g, ths, ls, vs, F1s, x)
        gx = lx - target
        if gx == 0.0:
            return x
        if (gx < 0.0) == lo_is_neg:
            lo = x
        else:
            hi = x
        if not (hi - lo > 4e-16 * max(abs(lo), abs(hi))):
            return hi
        slope = vx / omega
        xn = x - gx / slope if slope != 0.0 else 0.5 * (lo + hi)
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        elif abs(xn - x) <= 4e-16 * abs(x):
            return xn  # Newton has converged to rounding (the bracket may stay one-sided)
        x = xn
    return 0.5 * (lo + hi)


@njit(cache=True)
def _root_velocity(tab, npan, omega, g, ths, vs, F1s, xa, xb):
    """θ in (xa, xb) where the flight's v = 0 (v monotone and changing sign on [xa, xb])."""
    va = vs + gravity_dv(ths, xa, omega, g) - (_F1(tab, npan, xa) - F1s)
    lo_is_neg = va < 0.0
    lo = xa
    hi = xb
    x = 0.5 * (xa + xb)
    for _ in range(300):
        vx = vs + gravity_dv(ths, x, omega, g) - (_F1(tab, npan, x) - F1s)
        if vx == 0.0:
            return x
        if (vx < 0.0) == lo_is_neg:
            lo = x
        else:
            hi = x
        if not (hi - lo > 4e-16 * max(abs(lo), abs(hi))):
            return 0.5 * (lo + hi)
        slope = _accel(tab, npan, g, x) / omega
        xn = x - vx / slope if slope != 0.0 else 0.5 * (lo + hi)
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        elif abs(xn - x) <= 4e-16 * abs(x):
            return xn  # Newton has converged to rounding (the bracket may stay one-sided)
        x = xn
    return 0.5 * (lo + hi)


# ---- the pass ----------------------------------------------------------------------------------
@njit(cache=True)
def _zeno_credit(m, u, e, resting, omega, amag, th, wend):
    """Impulse credited when a Zeno sequence starting with approach speed u is closed at θ."""
    if resting:
        return m * u
    if e <= 0.0:
        return m * u
    dt_left = (wend - th) / omega
    r = 1.0 - dt_left * (1.0 - e) * amag / (2.0 * e * u)
    if r <= 0.0:  # the whole sequence fits in the window
        return m * u * (1.0 + e) / (1.0 - e)
    kmax = math.floor(math.log(r) / math.log(e))
    return m * u * (1.0 + e) * (1.0 - e ** (kmax + 1)) / (1.0 - e)


@njit(cache=True)
def _event_pass(par, tab, npan, roots, cap):
    """Solve one pass. Returns (status, totals[8], impacts[cap, 5], n_imp, pieces[cap, 6], n_pieces)."""
    m, s, omega, g, e = par[0], par[1], par[2], par[3], par[4]
    th0, th1 = par[5], par[6]
    resting = par[9] > 0.5
    zeno_h = par[10] * s
    zeno_floor = par[11] * s
    impacts = np.zeros((cap, 5))  # theta, approach speed, impulse, face, kind
    pieces = np.zeros((cap, 6))  # theta, mode, l, v, I_dec, I_acc (cumulative at piece start)
    totals = np.zeros(8)  # I_dec, I_acc, I_dec_rest, I_acc_rest, l_end, v_end, mode_end, n_events
    n_imp = 0
    n_pc = 0
    I_dec = 0.0
    I_acc = 0.0
    I_dec_rest = 0.0
    I_acc_rest = 0.0
    th = th0
    l = s
    v = 0.0
    a_start = _accel(tab, npan, g, th0)
    mode = REST_FRONT if a_start > 0.0 else FREE
    status = STATUS_OK
    guard = 0
    subs = np.empty(3)
    while True:
        guard += 1
        if guard > 50 * cap:
            status = STATUS_STUCK
            break
        if n_pc >= cap:
            status = STATUS_OVERFLOW
            break
        pieces[n_pc, 0] = th
        pieces[n_pc, 1] = mode
        pieces[n_pc, 2] = l
        pieces[n_pc, 3] = v
        pieces[n_pc, 4] = I_dec
        pieces[n_pc, 5] = I_acc
        n_pc += 1
        if th >= th1:
            break
        if mode == REST_REAR or mode == REST_FRONT:
            thn = min(_next_root(roots, th), th1)
            # ∫ (g sin θ + f) dt = −∫ a dt over the resting interval
            push = -gravity_dv(th, thn, omega, g) + (_F1(tab, npan, thn) - _F1(tab, npan, th))
            if mode == REST_REAR:
                if resting:
                    I_dec += m * push
                    I_dec_rest += m * push
                l = 0.0
            else:
                if resting:
                    I_acc -= m * push
                    I_acc_rest -= m * push
                l = s
            v = 0.0
            th = thn
            mode = FREE
            if th >= th1:
                mode = REST_REAR if l == 0.0 else REST_FRONT
            continue
        # ---- free flight from (th, l, v)
        ths = th
        ls = l
        vs = v
        F1s = _F1(tab, npan, ths)
        thc = ths
        hit = False
        thi = 0.0
        face = -1
        while thc < th1:
            thn = min(_next_root(roots, thc), th1)
            _, vc = _flight(tab, npan, omega, g, ths, ls, vs, F1s, thc)
            _, vn = _flight(tab, npan, omega, g, ths, ls, vs, F1s, thn)
            nsub = 2
            subs[0] = thc
            subs[1] = thn
            if (vc < 0.0 and vn > 0.0) or (vc > 0.0 and vn < 0.0):
                subs[1] = _root_velocity(tab, npan, omega, g, ths, vs, F1s, thc, thn)
                subs[2] = thn
                nsub = 3
            for k in range(nsub - 1):
                xa = subs[k]
                xb = subs[k + 1]
                if xb <= xa:
                    continue
                _, vm = _flight(tab, npan, omega, g, ths, ls, vs, F1s, 0.5 * (xa + xb))
                if vm < 0.0:
                    la, _ = _flight(tab, npan, omega, g, ths, ls, vs, F1s, xa)
                    lb, _ = _flight(tab, npan, omega, g, ths, ls, vs, F1s, xb)
                    if la <= 0.0:
                        hit = True
                        thi = xa
                    elif lb <= 0.0:
                        hit = True
                        thi = _root_gap(tab, npan, omega, g, ths, ls, vs, F1s, 0.0, xa, xb)
                    if hit:
                        face = FACE_REAR
                        break
                elif vm > 0.0:
                    la, _ = _flight(tab, npan, omega, g, ths, ls, vs, F1s, xa)
                    lb, _ = _flight(tab, npan, omega, g, ths, ls, vs, F1s, xb)
                    if la >= s:
                        hit = True
                        thi = xa
                    elif lb >= s:
                        hit = True
                        thi = _root_gap(tab, npan, omega, g, ths, ls, vs, F1s, s, xa, xb)
                    if hit:
                        face = FACE_FRONT
                        break
            if hit:
                break
            thc = thn
        if not hit:
            l, v = _flight(tab, npan, omega, g, ths, ls, vs, F1s, th1)
            th = th1
            continue
        # ---- impact at thi
        if n_imp >= cap:
            status = STATUS_OVERFLOW
            break
        _, vi = _flight(tab, npan, omega, g, ths, ls, vs, F1s, thi)
        ai = _accel(tab, npan, g, thi)
        if face == FACE_REAR:
            u = max(-vi, 0.0)
            pressing = ai < 0.0
        else:
            u = max(vi, 0.0)
            pressing = ai > 0.0
        amag = abs(ai)
        J = m * (1.0 + e) * u
        kind = KIND_IMPACT
        rest_now = False
        if pressing and e < 1.0:
            reb = e * u
            height = reb * reb / (2.0 * amag)
            if height < zeno_h:
                wend = min(_next_root(roots, thi), th1)
                thz = thi + 2.0 * omega * 2.0 * reb / ((1.0 - e) * amag)
                complete = thz < wend and abs(_accel(tab, npan, g, thz)) >= 0.5 * amag
                if complete or height < zeno_floor:
                    J = _zeno_credit(m, u, e, resting, omega, amag, thi, thz if complete else wend)
                    kind = KIND_ZENO
                    rest_now = True
        impacts[n_imp, 0] = thi
        impacts[n_imp, 1] = u
        impacts[n_imp, 2] = J
        impacts[n_imp, 3] = face
        impacts[n_imp, 4] = kind
        n_imp += 1
        th = thi
        if face == FACE_REAR:
            I_dec += J
            l = 0.0
            v = 0.0 if rest_now else e * u
            mode = REST_REAR if rest_now else FREE
        else:
            I_acc += J
            l = s
            v = 0.0 if rest_now else -e * u
            mode = REST_FRONT if rest_now else FREE
    totals[0] = I_dec
    totals[1] = I_acc
    totals[2] = I_dec_rest
    totals[3] = I_acc_rest
    totals[4] = l
    totals[5] = v
    totals[6] = mode
    totals[7] = n_imp
    return status, totals, impacts, n_imp, pieces, n_pc


@njit(cache=True)
def _trace(par, tab, npan, pieces, n_pc, thetas, left):
    """l, v and cumulative I_dec at sorted θ (left[i]: take the limit from the left at θ)."""
    m, s, omega, g = par[0], par[1], par[2], par[3]
    resting = par[9] > 0.5
    n = thetas.shape[0]
    lo = np.empty(n)
    vo = np.empty(n)
    io = np.empty(n)
    starts = pieces[:n_pc, 0].copy()
    for i in range(n):
        th = thetas[i]
        if left[i]:
            kk = np.searchsorted(starts, th, side="left") - 1
        else:
            kk = np.searchsorted(starts, th, side="right") - 1
        if kk < 0:
            kk = 0
        ths = pieces[kk, 0]
        mode = int(pieces[kk, 1])
        if mode == FREE:
            F1s = _F1(tab, npan, ths)
            l, v = _flight(tab, npan, omega, g, ths, pieces[kk, 2], pieces[kk, 3], F1s, th)
            idec = pieces[kk, 4]
        else:
            l = pieces[kk, 2]
            v = 0.0
            idec = pieces[kk, 4]
            if mode == REST_REAR and resting:
                idec += m * (-gravity_dv(ths, th, omega, g) + _F1(tab, npan, th) - _F1(tab, npan, ths))
        lo[i] = l
        vo[i] = v
        io[i] = idec
    return lo, vo, io


# ---- Python wrapper ----------------------------------------------------------------------------
@dataclass
class PassSolution:
    """One solved no-load pass (either method). SI units; θ in rad.

    Attributes
    ----------
    method : "event" or "euler"
    I_dec, I_acc : rear- and front-face impulse of the pass [N s] (positive magnitudes)
    I_dec_resting, I_acc_resting : the parts carried by resting contact [N s]
    impacts : dict of arrays ``theta`` [rad], ``time`` [s from the pass start], ``approach_speed``
        [m/s], ``impulse`` [N s], ``face`` (0 rear, 1 front), ``kind`` (0 impact, 1 Zeno closure)
    l_end, v_end : state at the end of the pass [m], [m/s]
    trace : dict ``theta`` [rad], ``l_r`` [m], ``dl_r_dt`` [m/s], ``I_dec_cumulative`` [N s], or None
    wall_s : wall time of the solve (table, roots and pass; not the trace) [s]
    termination : why the solve stopped
    dt : time step [s] (``None`` for the event method)
    info : solver details (panel count, accel roots, tolerances)
    """

    method: str
    I_dec: float
    I_acc: float
    I_dec_resting: float
    I_acc_resting: float
    impacts: dict
    l_end: float
    v_end: float
    trace: dict | None
    wall_s: float
    termination: str
    dt: float | None = None
    info: dict = field(default_factory=dict)


def _params(inp: PassInputs, zeno_height: float, zeno_floor: float) -> np.ndarray:
    return np.array([
        inp.mass, inp.pocket_clearance, inp.omega_c, inp.gravity, inp.restitution,
        inp.theta_start, inp.theta_end, inp.drag_scale, inp.centripetal,
        1.0 if inp.resting_contact else 0.0, zeno_height, zeno_floor,
    ])


def drag_table(inp: PassInputs, cheb_tol: float = DEFAULT_CHEB_TOL, min_width: float = DEFAULT_MIN_WIDTH):
    """Piecewise-Chebyshev table of f = F_o/m and its time integrals over the pass.

    Returns ``(tab, npan)``; ``tab`` = (breaks [rad], f coefficients, F1 and F2 local antiderivative
    coefficients, F1 and F2 at panel starts). Raises :class:`SimulationUnstable` if the table overflows.
    """
    nroots = inp.normal_load_roots()
    r = list(nroots) + [0.0, 0.0]
    cap = 64
    while True:
        out = _build_table(
            inp.theta_start, inp.theta_end, inp.omega_c, inp.drag_scale, inp.centripetal, inp.gravity,
            cheb_tol, min_width, len(nroots), r[0], r[1], CHEB_NODES, CHEB_COS, cap,
        )
        npan = int(out[6])
        if npan >= 0:
            break
        cap *= 4
        if cap > 1 << 16:
            raise SimulationUnstable("event solver: drag table needs more than 65536 Chebyshev panels")
    return out[:6], npan


def solve_event(
    inp: PassInputs,
    *,
    cheb_tol: float = DEFAULT_CHEB_TOL,
    zeno_height: float = DEFAULT_ZENO_HEIGHT,
    zeno_floor: float = DEFAULT_ZENO_FLOOR,
    min_width: float = DEFAULT_MIN_WIDTH,
    trace_points: int = 2000,
    capacity: int = 256,
) -> PassSolution:
    """Solve one no-load pass exactly (event-driven, closed form between events).

    Parameters
    ----------
    inp : pass inputs (SI)
    cheb_tol : tail tolerance of the Chebyshev panels, relative to max F_o/m [-]
    zeno_height : close a Zeno sequence when the rebound height is below this fraction of s [-]
    zeno_floor : close it unconditionally below this fraction of s [-]
    min_width : smallest panel next to an N = 0 singularity [rad]
    trace_points : uniform θ samples of the trace (impact angles are added, with the values on both
        sides); 0 for no trace
    capacity : initial size of the event buffers (doubled as needed)
    """
    if inp.omega_c <= 0.0:
        raise SimulationUnstable("event solver: the cage does not turn (omega_c = 0)")
    t0 = time.perf_counter()
    tab, npan = drag_table(inp, cheb_tol, min_width)
    roots = _accel_roots(tab, npan, inp.gravity)
    par = _params(inp, zeno_height, zeno_floor)
    while True:
        status, totals, impacts, n_imp, pieces, n_pc = _event_pass(par, tab, npan, roots, capacity)
        if status != STATUS_OVERFLOW:
            break
        capacity *= 4
        if capacity > 1 << 26:
            raise SimulationUnstable("event solver: more than 67 million events in one pass")
    wall = time.perf_counter() - t0
    if status == STATUS_STUCK:
        raise SimulationUnstable("event solver: no progress (stuck event loop)")
    if not np.all(np.isfinite(totals)):
        raise SimulationUnstable("event solver: non-finite impulse")
    imp = impacts[:n_imp]
    theta = imp[:, 0].copy()
    sol = PassSolution(
        method="event",
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
        dt=None,
        info=dict(panels=npan, accel_roots=roots.copy(), pieces=n_pc, cheb_tol=cheb_tol,
                  zeno_height=zeno_height, zeno_floor=zeno_floor, min_width=min_width),
    )
    if trace_points > 0:
        grid = np.linspace(inp.theta_start, inp.theta_end, trace_points)
        ev = theta
        th_all = np.concatenate([grid, ev, ev])
        left = np.concatenate([np.zeros(grid.size, bool), np.ones(ev.size, bool), np.zeros(ev.size, bool)])
        order = np.lexsort((~left, th_all))  # at equal θ the left limit comes first
        th_all = th_all[order]
        left = left[order]
        lr, vr, ir = _trace(par, tab, npan, pieces, n_pc, th_all, left)
        sol.trace = dict(theta=th_all, l_r=lr, dl_r_dt=vr, I_dec_cumulative=ir)
    return sol
