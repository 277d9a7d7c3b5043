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
bound on |a'| from each panel's Chebyshev coefficients, down to pieces proved monotone by a bound on
|a''|, whose single root is then located by safeguarded Newton to machine precision). Between
consecutive roots of a, v is monotone, so it has at most one root (found by safeguarded Newton); between
roots of v, l is monotone, so a face is reached inside a sub-segment exactly when the gap changes sign
at its ends. Each crossing is then located by safeguarded Newton (derivative v/ω), started from the
second-order Taylor prediction of the crossing, to the rounding of the closed form: iteration stops
when |l − target| is within a few ulps of the magnitudes of the terms summed into l (below that its
sign is noise; the crossing is defined to ~1e-12 relative in θ on bounce sequences, not to 1 ulp).

**Cost.** One evaluation of the closed form runs the three Clenshaw recurrences of f, F1 and F2 in one
loop, with everything that depends on the flight start only (F1(θs), F2(θs), cos θs, sin θs) computed
once per flight; the scan reuses the states at segment ends, so an impact costs about ten evaluations.
Table, roots and pass run in one compiled call.

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

from bearingsim import laws
from bearingsim._jit import drop_stale_caches
from bearingsim.errors import SimulationUnstable
from bearingsim.reduced import core as _core
from bearingsim.reduced.core import (
    FACE_FRONT,
    FACE_REAR,
    PassConstants,
    FREE,
    KIND_IMPACT,
    KIND_ZENO,
    REST_FRONT,
    REST_REAR,
    PassInputs,
    drag_accel,
    gravity_dv,
    sin_minus_x,
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
# A face crossing (a root of v) is accepted when |l − target| (|v|) is below this many ulps of the
# magnitudes summed into l (v), lmag (vmag) of _flight: inside that band the computed sign is noise.
_ROUND_L = 4.0 * 2.0**-52
STATUS_OK = 0
STATUS_OVERFLOW = 1
STATUS_STUCK = 2
STATUS_TABLE_OVERFLOW = 3
TABLE_OVERFLOW_MESSAGE = "event solver: drag table needs more than 65536 Chebyshev panels"


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
            fv[j] = K * nm**laws.DRAG_LOAD_EXPONENT if nm > 0.0 else 0.0
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

    Returns (breaks, fco, q1, q2, F1L, F2L, co, npan); npan = −1 when more than ``cap`` panels are needed.
    ``co[p]`` holds the coefficients of f, F1 and F2 (local parts) of panel p, zero-padded to a common
    length, for the fused evaluation :func:`_cheb3`.
    """
    n = nodes.shape[0] - 1
    breaks = np.empty(cap + 1)
    fco = np.empty((cap, n + 1))
    fscale = K * max(A + g, 0.0) ** laws.DRAG_LOAD_EXPONENT
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
            return breaks, fco, fco, fco, breaks, breaks, np.empty((0, 3, 0)), -1
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
                    return breaks, fco, fco, fco, breaks, breaks, np.empty((0, 3, 0)), -1
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
    co = np.zeros((npan, 3, n + 3))
    for p in range(npan):
        for k in range(n + 1):
            co[p, 0, k] = fco[p, k]
        for k in range(n + 2):
            co[p, 1, k] = q1[p, k]
        for k in range(n + 3):
            co[p, 2, k] = q2[p, k]
    return breaks, fco, q1, q2, F1L, F2L, co, npan


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
def _accel(tab, npan, g, th):
    """a(θ) consistent with the table (the derivative of the closed-form v)."""
    return -g * math.sin(th) - _f_eval(tab, npan, th)


@njit(cache=True)
def _cheb3(co, p, x):
    """(f, F1 − F1L, F2 − F2L-part) at local x of panel p: the three Clenshaw recurrences in one loop.

    The three series share x, so running them together costs about one recurrence's latency. The rows
    of ``co`` are zero-padded to a common length; leading zeros leave the recurrence exactly 0, so each
    value is bit-for-bit that of :func:`_clenshaw` on the unpadded coefficients.
    """
    x2 = 2.0 * x
    f1 = 0.0
    f2 = 0.0
    a1 = 0.0
    a2 = 0.0
    b1 = 0.0
    b2 = 0.0
    for k in range(co.shape[2] - 1, 0, -1):
        f0 = x2 * f1 - f2 + co[p, 0, k]
        a0 = x2 * a1 - a2 + co[p, 1, k]
        b0 = x2 * b1 - b2 + co[p, 2, k]
        f2 = f1
        f1 = f0
        a2 = a1
        a1 = a0
        b2 = b1
        b1 = b0
    return x * f1 - f2 + co[p, 0, 0], x * a1 - a2 + co[p, 1, 0], x * b1 - b2 + co[p, 2, 0]


@njit(cache=True)
def _flight_start(tab, npan, omega, ths, ls, vs):
    """Constants of a free flight that starts at (θs, ls, vs), evaluated once per flight.

    Returns fs = [θs, ls, vs, panel of θs, q1 part of F1(θs), q2 part of F2(θs), F1(θs), F2(θs),
    cos θs, sin θs] for :func:`_flight`.
    """
    breaks, co, F1L, F2L = tab[0], tab[6], tab[4], tab[5]
    ps = _panel(breaks, npan, ths)
    xs = _local_x(breaks, ps, ths)
    _, c1s, c2s = _cheb3(co, ps, xs)
    fs = np.empty(10)
    fs[0] = ths
    fs[1] = ls
    fs[2] = vs
    fs[3] = ps
    fs[4] = c1s
    fs[5] = c2s
    fs[6] = F1L[ps] + c1s
    fs[7] = F2L[ps] + F1L[ps] * (ths - breaks[ps]) / omega + c2s
    fs[8] = math.cos(ths)
    fs[9] = math.sin(ths)
    return fs


@njit(cache=True)
def _flight(tab, npan, omega, g, fs, th):
    """(l, v, a, lmag, vmag) at θ of the free flight with start constants ``fs`` (see :func:`_flight_start`).

    The closed form of the module docstring: gravity as in :func:`bearingsim.reduced.core.gravity_dv`
    and ``gravity_dl`` (same cancellation-free expressions, with cos θs, sin θs and sin(h/2) shared),
    the drag from one fused evaluation of f, F1 and F2; a(θ) = −g sin θ − f(θ) is the derivative of v.
    lmag (vmag) is the sum of the magnitudes of the terms summed into l (v): l carries a rounding error
    of a few ulps of lmag, which is how precisely a crossing of a face can be located at all.
    """
    breaks, co, F1L, F2L = tab[0], tab[6], tab[4], tab[5]
    ths = fs[0]
    ls = fs[1]
    vs = fs[2]
    ps = int(fs[3])
    p = _panel(breaks, npan, th)
    x = _local_x(breaks, p, th)
    cf, c1, c2 = _cheb3(co, p, x)
    h = th - ths
    sh = math.sin(0.5 * h)
    dv_grav = -2.0 * g / omega * math.sin(ths + 0.5 * h) * sh
    F1 = F1L[p] + c1
    v = vs + dv_grav - (F1 - fs[6])
    tau = h / omega
    dl_grav = g / omega**2 * (fs[8] * sin_minus_x(h) - fs[9] * (2.0 * sh**2))
    if p == ps:  # same panel: local polynomials, no large cumulative constants to cancel
        dl_drag = c2 - fs[5] - fs[4] * tau
        mag_drag = abs(c2) + abs(fs[5]) + abs(fs[4] * tau)
    else:
        F2 = F2L[p] + F1L[p] * (th - breaks[p]) / omega + c2
        dl_drag = F2 - fs[7] - fs[6] * tau
        mag_drag = abs(F2) + abs(fs[7]) + abs(fs[6] * tau)
    l = ls + vs * tau + dl_grav - dl_drag
    lmag = abs(ls) + abs(vs * tau) + abs(dl_grav) + mag_drag
    vmag = abs(vs) + abs(dv_grav) + abs(F1) + abs(fs[6])
    return l, v, -g * math.sin(th) - cf, lmag, vmag


# ---- roots of a(θ) ---------------------------------------------------------------------------
@njit(cache=True)
def _cheb_deriv(c, n, out):
    """Chebyshev coefficients (n−1 of them, into ``out``) of d/dx Σ_{k<n} c_k T_k(x)."""
    for k in range(n):
        out[k] = 0.0
    for k in range(n - 1, 0, -1):
        out[k - 1] = (out[k + 1] if k + 1 < n else 0.0) + 2.0 * k * c[k]
    out[0] *= 0.5


@njit(cache=True)
def _accel_root_in(fco, p, dco, breaks, g, half, x0, f0, x1, f1):
    """The root of a(θ) in [x0, x1], where a is monotone and a(x0), a(x1) have opposite signs.

    Safeguarded Newton (derivative from the differentiated panel series ``dco``), started at the
    regula-falsi point; stops at the rounding of θ, or when |a| is below the rounding of its terms.
    """
    n = fco.shape[1]
    lo = x0
    hi = x1
    lo_pos = f0 > 0.0
    x = x0 + (x1 - x0) * (f0 / (f0 - f1))
    if not (x0 < x < x1):
        x = 0.5 * (x0 + x1)
    for _ in range(200):
        xl = _local_x(breaks, p, x)
        sg = g * math.sin(x)
        fx = _clenshaw(fco[p], n, xl)
        ax = -sg - fx
        if abs(ax) <= 4.0 * 2.0**-52 * (abs(sg) + abs(fx)):
            return x
        if (ax > 0.0) == lo_pos:
            lo = x
        else:
            hi = x
        if not (hi - lo > 4e-16 * max(abs(lo), abs(hi))):
            return 0.5 * (lo + hi)
        da = -g * math.cos(x) - _clenshaw(dco, n - 1, xl) / half
        xn = x - ax / da if da != 0.0 else 0.5 * (lo + hi)
        if not (min(lo, hi) < xn < max(lo, hi)):
            xn = 0.5 * (lo + hi)
        elif abs(xn - x) <= 4e-16 * abs(x):
            return xn
        x = xn
    return 0.5 * (lo + hi)


@njit(cache=True)
def _accel_roots(tab, npan, g):
    """Sign changes of a(θ) over the table, to machine precision; never misses one wider than 1e-12 rad.

    Each panel is subdivided (bisection, keeping the end values) until every piece is either
    excluded — |a| at its ends exceeds L × width, L a bound on |a'| from the panel's Chebyshev
    coefficients (|T_k'| ≤ k²) — or proved monotone — |a'| at its midpoint exceeds M × width/2, M a
    bound on |a''| (|T_k''| ≤ k²(k²−1)/3) — and so holds at most one root, present exactly when a
    changes sign at its ends; that root is then located by safeguarded Newton. Pieces narrower than
    1e-12 rad that are neither are bisected for a sign change as before.
    """
    breaks, fco = tab[0], tab[1]
    n = fco.shape[1]
    roots = np.empty(_MAX_AROOTS)
    nr = 0
    sa = np.empty(256)
    sb = np.empty(256)
    sfa = np.empty(256)
    sfb = np.empty(256)
    dco = np.empty(n)
    for p in range(npan):
        a0 = breaks[p]
        a1 = breaks[p + 1]
        half = 0.5 * (a1 - a0)
        dmax = 0.0
        d2max = 0.0
        for k in range(1, n):
            dmax += k * k * abs(fco[p, k])
            d2max += k * k * (k * k - 1) / 3.0 * abs(fco[p, k])
        # 10 % margin: the bound is tight for a linear a(θ), and rounding must not exclude a root
        lip = 1.1 * (abs(g) + (dmax / half if half > 0 else 0.0))
        lip2 = 1.1 * (abs(g) + (d2max / (half * half) if half > 0 else 0.0))
        _cheb_deriv(fco[p], n, dco)
        sa[0] = a0
        sb[0] = a1
        sfa[0] = -g * math.sin(a0) - _clenshaw(fco[p], n, _local_x(breaks, p, a0))
        sfb[0] = -g * math.sin(a1) - _clenshaw(fco[p], n, _local_x(breaks, p, a1))
        top = 1
        while top > 0:
            top -= 1
            x0 = sa[top]
            x1 = sb[top]
            f0 = sfa[top]
            f1 = sfb[top]
            if abs(f0) + abs(f1) > lip * (x1 - x0) or lip == 0.0:
                continue  # no root inside
            m = 0.5 * (x0 + x1)
            xm = _local_x(breaks, p, m)
            dam = -g * math.cos(m) - _clenshaw(dco, n - 1, xm) / half
            if abs(dam) > lip2 * 0.5 * (x1 - x0):  # a is strictly monotone on [x0, x1]
                if (f0 > 0.0) != (f1 > 0.0) and nr < _MAX_AROOTS:
                    roots[nr] = _accel_root_in(fco, p, dco, breaks, g, half, x0, f0, x1, f1)
                    nr += 1
                continue
            if (x1 - x0) <= 1e-12 or top >= 250:
                if (f0 > 0.0) != (f1 > 0.0):
                    lo = x0
                    hi = x1
                    flo = f0 > 0.0
                    for _ in range(200):
                        mm = 0.5 * (lo + hi)
                        if mm <= lo or mm >= hi:
                            break
                        fm = -g * math.sin(mm) - _clenshaw(fco[p], n, _local_x(breaks, p, mm))
                        if (fm > 0.0) == flo:
                            lo = mm
                        else:
                            hi = mm
                    if nr < _MAX_AROOTS:
                        roots[nr] = 0.5 * (lo + hi)
                        nr += 1
                continue
            fm = -g * math.sin(m) - _clenshaw(fco[p], n, xm)
            sa[top] = m
            sb[top] = x1
            sfa[top] = fm
            sfb[top] = f1
            sa[top + 1] = x0
            sb[top + 1] = m
            sfa[top + 1] = f0
            sfb[top + 1] = fm
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
def _taylor_time(d, v, a):
    """Smallest τ > 0 with d + v τ + a τ²/2 = 0 (cancellation-free quadratic formula), or −1 if none."""
    if a == 0.0:
        if v != 0.0 and -d / v > 0.0:
            return -d / v
        return -1.0
    disc = v * v - 2.0 * a * d
    if disc < 0.0:
        return -1.0
    q = -0.5 * (v + math.copysign(math.sqrt(disc), v))
    best = -1.0
    if q != 0.0:
        t1 = 2.0 * q / a
        t2 = d / q
        if t1 > 0.0:
            best = t1
        if t2 > 0.0 and (best < 0.0 or t2 < best):
            best = t2
    return best


@njit(cache=True)
def _root_gap(tab, npan, omega, g, fs, target, xa, la, va, aa, xb, lb):
    """θ in [xa, xb] where l(θ) = target; l − target changes sign on [xa, xb] and l is monotone.

    (la, va, aa) is the state at xa and lb the gap at xb, known from the scan. Safeguarded Newton
    (derivative v/ω, bisection when a step leaves the bracket), started from the second-order Taylor
    prediction of the crossing from xa (or the regula-falsi point when that prediction leaves the
    bracket): the flights between bounces are short, so the start is already close and Newton needs
    a few steps. Stops when the bracket or the Newton step is at the rounding of θ.
    """
    lo_is_neg = (la - target) < 0.0
    lo = xa
    hi = xb
    tau = _taylor_time(la - target, va, aa)
    x = xa + omega * tau
    if not (tau > 0.0 and xa < x < xb):
        x = xa + (xb - xa) * ((la - target) / (la - lb))
        if not (xa < x < xb):
            x = 0.5 * (xa + xb)
    for _ in range(300):
        lx, vx, _, lmag, _ = _flight(tab, npan, omega, g, fs, x)
        gx = lx - target
        if abs(gx) <= _ROUND_L * (lmag + abs(target)):
            return x  # a root of l − target to the rounding of the closed form
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
def _root_velocity(tab, npan, omega, g, fs, xa, va, aa, xb, vb):
    """θ in (xa, xb) where the flight's v = 0 (v monotone and changing sign on [xa, xb]).

    (va, aa) at xa and vb at xb are known from the scan. Safeguarded Newton (derivative a/ω) started
    from the first-order prediction xa − ω va/aa (or the regula-falsi point when that leaves the bracket).
    """
    lo_is_neg = va < 0.0
    lo = xa
    hi = xb
    x = xa - omega * va / aa if aa != 0.0 else xa
    if not (xa < x < xb):
        x = xa + (xb - xa) * (va / (va - vb))
        if not (xa < x < xb):
            x = 0.5 * (xa + xb)
    for _ in range(300):
        _, vx, ax, _, vmag = _flight(tab, npan, omega, g, fs, x)
        if abs(vx) <= _ROUND_L * vmag:
            return x  # a root of v to the rounding of the closed form
        if (vx < 0.0) == lo_is_neg:
            lo = x
        else:
            hi = x
        if not (hi - lo > 4e-16 * max(abs(lo), abs(hi))):
            return 0.5 * (lo + hi)
        slope = ax / omega
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
    m, s, omega, g, e = par.mass, par.clearance, par.omega_c, par.gravity, par.restitution
    th0, th1 = par.theta_start, par.theta_end
    resting = par.resting_contact
    zeno_h = par.zeno_height * s
    zeno_floor = par.zeno_floor * s
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
    sub_x = np.empty(3)  # sub-segment ends of one scan segment, with l, v, a there
    sub_l = np.empty(3)
    sub_v = np.empty(3)
    sub_a = np.empty(3)
    sub_sign = np.empty(2)  # sign of v on each sub-segment
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
        fs = _flight_start(tab, npan, omega, th, l, v)
        # scan the segments between roots of a; (lc, vc, ac) is the state at thc, exact at the start
        thc = th
        lc = l
        vc = v
        ac = _accel(tab, npan, g, th)
        hit = False
        thi = 0.0
        face = -1
        while thc < th1:
            thn = min(_next_root(roots, thc), th1)
            ln, vn, an, _, _ = _flight(tab, npan, omega, g, fs, thn)
            # v is monotone on [thc, thn]: one sub-segment, or two split at its root. On each, v keeps
            # one sign (taken from an end where it is not zero), so l is monotone there and a face is
            # reached exactly when the gap changes sign at the sub-segment's ends.
            nsub = 1
            sub_x[0] = thc
            sub_l[0] = lc
            sub_v[0] = vc
            sub_a[0] = ac
            if (vc < 0.0 and vn > 0.0) or (vc > 0.0 and vn < 0.0):
                xr = _root_velocity(tab, npan, omega, g, fs, thc, vc, ac, thn, vn)
                lr, vr, ar, _, _ = _flight(tab, npan, omega, g, fs, xr)
                sub_x[1] = xr
                sub_l[1] = lr
                sub_v[1] = vr
                sub_a[1] = ar
                sub_sign[0] = vc
                sub_sign[1] = vn
                nsub = 2
            else:
                sub_sign[0] = vc if vc != 0.0 else vn
            sub_x[nsub] = thn
            sub_l[nsub] = ln
            for k in range(nsub):
                xa = sub_x[k]
                xb = sub_x[k + 1]
                if xb <= xa:
                    continue
                la = sub_l[k]
                lb = sub_l[k + 1]
                if sub_sign[k] < 0.0:
                    if la <= 0.0:
                        hit = True
                        thi = xa
                    elif lb <= 0.0:
                        hit = True
                        thi = _root_gap(tab, npan, omega, g, fs, 0.0, xa, la, sub_v[k], sub_a[k], xb, lb)
                    if hit:
                        face = FACE_REAR
                        break
                elif sub_sign[k] > 0.0:
                    if la >= s:
                        hit = True
                        thi = xa
                    elif lb >= s:
                        hit = True
                        thi = _root_gap(tab, npan, omega, g, fs, s, xa, la, sub_v[k], sub_a[k], xb, lb)
                    if hit:
                        face = FACE_FRONT
                        break
            if hit:
                break
            thc = thn
            lc = ln
            vc = vn
            ac = an
        if not hit:
            l = lc
            v = vc
            th = th1
            continue
        # ---- impact at thi
        if n_imp >= cap:
            status = STATUS_OVERFLOW
            break
        _, vi, ai, _, _ = _flight(tab, npan, omega, g, fs, thi)
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
    """l, v, cumulative I_dec and cumulative I_acc at sorted θ (left[i]: take the limit from the left at θ)."""
    m, omega, g = par.mass, par.omega_c, par.gravity
    resting = par.resting_contact
    n = thetas.shape[0]
    lo = np.empty(n)
    vo = np.empty(n)
    io = np.empty(n)
    ao = np.empty(n)
    starts = pieces[:n_pc, 0].copy()
    fs = np.empty(10)
    fs_piece = -1  # the piece whose flight constants fs holds (they depend on the piece only)
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
        idec = pieces[kk, 4]
        iacc = pieces[kk, 5]
        if mode == FREE:
            if kk != fs_piece:
                fs = _flight_start(tab, npan, omega, ths, pieces[kk, 2], pieces[kk, 3])
                fs_piece = kk
            l, v, _, _, _ = _flight(tab, npan, omega, g, fs, th)
        else:
            l = pieces[kk, 2]
            v = 0.0
            if resting:  # the resting push so far, as the pass adds it at the piece's end
                push = m * (-gravity_dv(ths, th, omega, g) + _F1(tab, npan, th) - _F1(tab, npan, ths))
                if mode == REST_REAR:
                    idec += push
                elif mode == REST_FRONT:
                    iacc -= push
        lo[i] = l
        vo[i] = v
        io[i] = idec
        ao[i] = iacc
    return lo, vo, io, ao


@njit(cache=True)
def _table(par, K, A, tol, min_width, nroots_n, root_n0, root_n1, nodes, cosmat):
    """The drag table of the pass (see :func:`_build_table`), grown until its panels fit; returns
    ``(tab, npan)`` with npan < 0 if more than 65536 panels would be needed."""
    omega, g, th0, th1 = par.omega_c, par.gravity, par.theta_start, par.theta_end
    cap = 64
    while True:
        t = _build_table(th0, th1, omega, K, A, g, tol, min_width, nroots_n, root_n0, root_n1, nodes, cosmat, cap)
        npan = t[7]
        if npan >= 0 or cap > (1 << 14):
            break
        cap *= 4
    return (t[0], t[1], t[2], t[3], t[4], t[5], t[6]), npan


@njit(cache=True)
def _solve(par, K, A, tol, min_width, nroots_n, root_n0, root_n1, nodes, cosmat, capacity):
    """Table, roots of a and the pass in one compiled call (one dispatch, few arrays to box).

    Returns (status, npan, n_imp, n_pieces, totals, impacts[:n_imp], pieces[:n_pieces], roots, tab)
    (``tab``: the drag table, which the trace evaluates again);
    status STATUS_TABLE_OVERFLOW when the table needs more than 65536 panels, STATUS_OVERFLOW when
    more than 67 million events would be needed.
    """
    g = par.gravity
    tab, npan = _table(par, K, A, tol, min_width, nroots_n, root_n0, root_n1, nodes, cosmat)
    if npan < 0:
        return STATUS_TABLE_OVERFLOW, npan, 0, 0, np.zeros(8), np.empty((0, 5)), np.empty((0, 6)), np.empty(0), tab
    roots = _accel_roots(tab, npan, g)
    while True:
        status, totals, impacts, n_imp, pieces, n_pc = _event_pass(par, tab, npan, roots, capacity)
        if status != STATUS_OVERFLOW or capacity > (1 << 24):
            break
        capacity *= 4
    return status, npan, n_imp, n_pc, totals, impacts[:n_imp].copy(), pieces[:n_pc].copy(), roots, tab


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
    trace : dict ``theta`` [rad], ``l_r`` [m], ``dl_r_dt`` [m/s], ``I_dec_cumulative``, ``I_acc_cumulative``
        [N s], or None
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


def pass_constants(inp: PassInputs, zeno_height: float, zeno_floor: float) -> PassConstants:
    """The compiled solvers' constants of the pass ``inp``."""
    return PassConstants(
        float(inp.mass), float(inp.pocket_clearance), float(inp.omega_c), float(inp.gravity),
        float(inp.restitution), float(inp.theta_start), float(inp.theta_end), float(inp.drag_scale),
        float(inp.centripetal), bool(inp.resting_contact), float(zeno_height), float(zeno_floor),
    )


def drag_table(inp: PassInputs, cheb_tol: float = DEFAULT_CHEB_TOL, min_width: float = DEFAULT_MIN_WIDTH):
    """Piecewise-Chebyshev table of f = F_o/m and its time integrals over the pass.

    Returns ``(tab, npan)``; ``tab`` = (breaks [rad], f coefficients, F1 and F2 local antiderivative
    coefficients, F1 and F2 at panel starts, the three coefficient sets packed per panel). Raises :class:`SimulationUnstable` if the table overflows.
    """
    nroots = inp.normal_load_roots()
    r = list(nroots) + [0.0, 0.0]
    tab, npan = _table(pass_constants(inp, DEFAULT_ZENO_HEIGHT, DEFAULT_ZENO_FLOOR), inp.drag_scale, inp.centripetal,
                       cheb_tol, min_width, len(nroots), r[0], r[1], CHEB_NODES, CHEB_COS)
    if npan < 0:
        raise SimulationUnstable(TABLE_OVERFLOW_MESSAGE)
    return tab, int(npan)


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
    nroots = inp.normal_load_roots()
    r = list(nroots) + [0.0, 0.0]
    par = pass_constants(inp, zeno_height, zeno_floor)
    status, npan, n_imp, n_pc, totals, imp, pieces, roots, tab = _solve(
        par, inp.drag_scale, inp.centripetal, cheb_tol, min_width, len(nroots), r[0], r[1],
        CHEB_NODES, CHEB_COS, capacity,
    )
    wall = time.perf_counter() - t0
    if status == STATUS_TABLE_OVERFLOW:
        raise SimulationUnstable(TABLE_OVERFLOW_MESSAGE)
    if status == STATUS_OVERFLOW:
        raise SimulationUnstable("event solver: more than 67 million events in one pass")
    if status == STATUS_STUCK:
        raise SimulationUnstable("event solver: no progress (stuck event loop)")
    if not all(math.isfinite(x) for x in totals.tolist()):
        raise SimulationUnstable("event solver: non-finite impulse")
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
        info=dict(panels=npan, accel_roots=roots, pieces=n_pc, cheb_tol=cheb_tol,
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
        lr, vr, ir, ia = _trace(par, tab, npan, pieces, n_pc, th_all, left)
        sol.trace = dict(theta=th_all, l_r=lr, dl_r_dt=vr, I_dec_cumulative=ir, I_acc_cumulative=ia)
    return sol


drop_stale_caches(__name__, (_core, laws))  # the kernels here compile in those of reduced/core.py and laws.py
