"""Attribution of pymunk's roller-cage contact impulses to pockets, faces, rotations. SI throughout.

One compiled kernel reads pymunk's batched arbiter list after each step and updates fixed-size
accumulators, so the cost of a step is the same at any run length. Definitions (also in the
package docstring of :mod:`bearingsim.multibody`):

* the pocket of a contact is its roller's index (roller ``i`` lives in pocket ``i``);
* the face is *front* when the contact normal, from roller to cage, points along the cage's
  rotation at the pocket centre (``e_t``), else *rear*;
* the circumferential impulse on the cage is ``J_cage . e_t``: ``I_acc`` sums it on front faces,
  ``I_dec`` sums its negative on rear faces (both positive when the roller drives, resp. brakes,
  the cage); normal impulse ``J_cage . n`` and the magnitude of the friction impulse are summed
  beside them;
* the approach speed of a contact is the normal relative speed of the two contact points before the
  step (the speed pymunk's restitution acts on); a contact step whose approach speed exceeds
  ``impact_speed_threshold`` is an impact, anything slower is resting-contact chatter;
* sliding work ``sum J_n |v_slide|`` uses the tangential relative speed of the contact points after
  the step.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

# cfg vector indices
C_SIGN, C_N, C_WARM, C_ROT, C_NBINS, C_VTHR, C_MASS = 0, 1, 2, 3, 4, 5, 6
N_CFG = 7
# window accumulator columns
W_IACC, W_IDEC, W_JN_F, W_JN_R, W_JF_F, W_JF_R, W_WORK_F, W_WORK_R = range(8)
N_WCOL = 8
# global accumulator slots
G_TAU_N, G_TAU_F, G_MAXPEN_F, G_MAXPEN_R, G_MAXPEN_ALL, G_N_CHATTER, G_CHATTER_VMAX = range(7)
G_MAXPEN_THETA, G_MAXPEN_TIME, G_MAXPEN_FACE = 7, 8, 9  # where the deepest overlap happened
G_MAXPEN_COS, G_MAXPEN_APPROACH, G_MAXPEN_POCKET = 10, 11, 12  # n . e_t, approach speed, pocket
N_GLOB = 13
# impact table columns
I_TIME, I_THETA, I_SPEED, I_IMPULSE, I_POCKET, I_FACE, I_ROT = range(7)
N_ICOL = 7
ARB_F = 9  # floats per arbiter: total impulse (2), normal (2), point a (2), point b (2), distance
ARB_I = 3  # ints per arbiter: body a id, body b id, contact count

TWO_PI = 2.0 * math.pi


@njit(cache=True)
def pocket_theta(sign, cage_angle, pocket_angle):
    """Angle [rad, 0..2 pi) of a pocket centre from the load-zone centre in the direction of rotation."""
    th = sign * (cage_angle + pocket_angle + 0.5 * math.pi)
    th = th - TWO_PI * math.floor(th / TWO_PI)
    return th


@njit(cache=True)
def record_step(arb_f, arb_i, n_arb, ids_sorted, ids_index, prev, now, t, h, cfg, pocket_a, theta0,
                diag, win, first_imp, f_bin, t_bin, q_bin, tq_bin, j_int, glob, impacts, n_imp):
    """Attribute one step's roller-cage impulses and raceway loads; return the new impact count.

    Parameters
    ----------
    arb_f, arb_i : flat float and int arbiter buffers from ``pymunk.batch.get_space_arbiters``;
        ``n_arb`` arbiters are valid.
    ids_sorted, ids_index : body ids sorted, and the batch row of each (rollers 0..n-1, cage n).
    prev, now : (nb, 6) body states before and after the step (x, y, angle, vx, vy, omega).
    t : time at the end of the step [s]; h : step [s].
    cfg : configuration vector (``C_*``).
    pocket_a : (n,) pocket centre angles in the cage frame [rad]; theta0 : (n,) unwrapped angle of
        each pocket from the load-zone centre at t = 0 [rad].
    diag : (n, N_DIAG) raceway diagnostics of the step (loads).
    win : (R, n, N_WCOL) per-rotation accumulators; first_imp : (R, n) first rear impact speed.
    f_bin : (n, nb, 2) circumferential contact impulse by theta bin [N s]; t_bin : (n, nb) time [s];
    q_bin : (nb, 2) raceway load x time (inner, outer) [N s]; tq_bin : (nb,) roller-time [s].
    j_int : (n, 2) circumferential impulses since the last output sample [N s].
    glob : (N_GLOB,) global accumulators; impacts : (cap, N_ICOL) impact rows; n_imp : rows used.
    """
    sign = cfg[C_SIGN]
    n = int(cfg[C_N])
    warm = cfg[C_WARM]
    nrot = int(cfg[C_ROT])
    nbins = int(cfg[C_NBINS])
    vthr = cfg[C_VTHR]
    phic = now[n, 2]
    xc = now[n, 0]
    yc = now[n, 1]
    travel = sign * phic
    rec_on = travel >= TWO_PI * warm
    # raceway loads and residence time by theta (recorded period only)
    for i in range(n):
        th = pocket_theta(sign, phic, pocket_a[i])
        b = int(th / TWO_PI * nbins)
        if b >= nbins:
            b = nbins - 1
        m = math.floor((sign * phic + theta0[i]) / TWO_PI)
        k = int(m - warm)
        if 0 <= k < nrot:
            t_bin[i, b] += h
            q_bin[b, 0] += diag[i, 1] * h
            q_bin[b, 1] += diag[i, 0] * h
            tq_bin[b] += h
    for a in range(n_arb):
        count = arb_i[a * ARB_I + 2]
        if count == 0:
            continue  # cached arbiter without contacts
        ida = arb_i[a * ARB_I]
        idb = arb_i[a * ARB_I + 1]
        ja = ids_index[np.searchsorted(ids_sorted, ida)]
        jb = ids_index[np.searchsorted(ids_sorted, idb)]
        o = a * ARB_F
        if ja < n:
            i = ja
            jcx = -arb_f[o]
            jcy = -arb_f[o + 1]
            nx = arb_f[o + 2]
            ny = arb_f[o + 3]
            prx = arb_f[o + 4]
            pry = arb_f[o + 5]
            pcx = arb_f[o + 6]
            pcy = arb_f[o + 7]
        else:
            i = jb
            jcx = arb_f[o]
            jcy = arb_f[o + 1]
            nx = -arb_f[o + 2]
            ny = -arb_f[o + 3]
            prx = arb_f[o + 6]
            pry = arb_f[o + 7]
            pcx = arb_f[o + 4]
            pcy = arb_f[o + 5]
        pen = -arb_f[o + 8]
        alpha = phic + pocket_a[i]
        etx = -sign * math.sin(alpha)
        ety = sign * math.cos(alpha)
        front = nx * etx + ny * ety > 0.0
        face = 0 if front else 1
        jn = jcx * nx + jcy * ny
        jfx = jcx - jn * nx
        jfy = jcy - jn * ny
        jf = math.sqrt(jfx * jfx + jfy * jfy)
        circ = jcx * etx + jcy * ety
        # contact-point velocities before (approach) and after (sliding) the step
        rxr = prx - now[i, 0]
        ryr = pry - now[i, 1]
        rxc = pcx - xc
        ryc = pcy - yc
        vax = prev[i, 3] - prev[i, 5] * ryr - (prev[n, 3] - prev[n, 5] * ryc)
        vay = prev[i, 4] + prev[i, 5] * rxr - (prev[n, 4] + prev[n, 5] * rxc)
        approach = vax * nx + vay * ny
        vbx = now[i, 3] - now[i, 5] * ryr - (now[n, 3] - now[n, 5] * ryc)
        vby = now[i, 4] + now[i, 5] * rxr - (now[n, 4] + now[n, 5] * rxc)
        vn = vbx * nx + vby * ny
        vsx = vbx - vn * nx
        vsy = vby - vn * ny
        vslide = math.sqrt(vsx * vsx + vsy * vsy)
        if pen > glob[G_MAXPEN_ALL]:
            glob[G_MAXPEN_ALL] = pen
            glob[G_MAXPEN_THETA] = pocket_theta(sign, phic, pocket_a[i]) * 180.0 / math.pi
            glob[G_MAXPEN_TIME] = t
            glob[G_MAXPEN_FACE] = 0.0 if nx * (-sign * math.sin(phic + pocket_a[i])) + ny * (sign * math.cos(phic + pocket_a[i])) > 0.0 else 1.0
            glob[G_MAXPEN_COS] = nx * (-sign * math.sin(phic + pocket_a[i])) + ny * (sign * math.cos(phic + pocket_a[i]))
            glob[G_MAXPEN_POCKET] = i
            glob[G_MAXPEN_APPROACH] = approach
        if front:
            j_int[i, 0] += circ
        else:
            j_int[i, 1] -= circ
        th = pocket_theta(sign, phic, pocket_a[i])
        m = math.floor((sign * phic + theta0[i]) / TWO_PI)
        k = int(m - warm)
        if 0 <= k < nrot:
            if front:
                win[k, i, W_IACC] += circ
                win[k, i, W_JN_F] += jn
                win[k, i, W_JF_F] += jf
                win[k, i, W_WORK_F] += jn * vslide
            else:
                win[k, i, W_IDEC] -= circ
                win[k, i, W_JN_R] += jn
                win[k, i, W_JF_R] += jf
                win[k, i, W_WORK_R] += jn * vslide
            b = int(th / TWO_PI * nbins)
            if b >= nbins:
                b = nbins - 1
            f_bin[i, b, face] += circ if front else -circ
            if pen > glob[G_MAXPEN_F + face]:
                glob[G_MAXPEN_F + face] = pen
            if approach > vthr:
                if (not front) and th < math.pi and first_imp[k, i] != first_imp[k, i]:
                    first_imp[k, i] = approach
                if n_imp < impacts.shape[0]:
                    impacts[n_imp, I_TIME] = t
                    impacts[n_imp, I_THETA] = th * 180.0 / math.pi
                    impacts[n_imp, I_SPEED] = approach
                    impacts[n_imp, I_IMPULSE] = jn
                    impacts[n_imp, I_POCKET] = i
                    impacts[n_imp, I_FACE] = face
                    impacts[n_imp, I_ROT] = k
                    n_imp += 1
            elif approach > 0.0:
                glob[G_N_CHATTER] += 1.0
                if approach > glob[G_CHATTER_VMAX]:
                    glob[G_CHATTER_VMAX] = approach
        if rec_on:
            glob[G_TAU_N] += rxc * (jn * ny) - ryc * (jn * nx)
            glob[G_TAU_F] += rxc * jfy - ryc * jfx
    return n_imp
