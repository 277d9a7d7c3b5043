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
  the step;
* where a contact lands on its face (wear profile, :data:`PROFILE`): the angle ``psi`` of the cage's
  contact point seen from the pocket centre, from the face's middle (the circumferential direction,
  ``psi`` = 0) towards the cage's rim (``psi`` > 0) or bore (< 0), ``psi = atan2(d . e_r, |d . e_t|)``
  (``d``: the contact point's offset from the pocket centre); on an arc face it is the angle on the arc,
  on a flat face ``atan(radial position / R)``. Each contact step of the recorded rotations adds its
  normal impulse and sliding work to one of ``face_bins`` equal bins of ``psi`` over the arc faces'
  extent ``[psi_lo, psi_hi]`` (a contact beyond an end counts in the end bin).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from bearingsim._jit import drop_stale_caches
from bearingsim.reduced import core as _reduced_core
from bearingsim.codes import FACE_FRONT, FACE_REAR  # one meaning of the face codes in both models


class RecorderConfig(NamedTuple):
    """Fixed inputs of :func:`record_step` (immutable for a run)."""

    sign: float  #: +1 forward, -1 reverse rotation
    roller_count: int  #: n, rollers = pockets
    warmup_rotations: float  #: W, cage rotations before rotation 0 (a whole number)
    rotations: int  #: R, recorded rotations
    theta_bins: int  #: number of bins of theta over 2 pi
    impact_speed_threshold: float  #: approach speed above which a contact step is an impact [m/s]
    pocket_centre_radius: float = 0.0  #: distance of the pocket centres from the cage centre [m]
    psi_lo: float = 0.0  #: inner end of the wear profile's range of psi [rad]
    psi_hi: float = 0.0  #: outer end (no profile is recorded unless psi_hi > psi_lo) [rad]


#: Per rotation and pocket accumulators, array shape (R, n) [N s] and [J].
WINDOW = np.dtype([
    ("I_acc", np.float64),  # circumferential impulse on the cage, front face
    ("I_dec", np.float64),  # minus the circumferential impulse on the cage, rear face
    ("Jn_front", np.float64), ("Jn_rear", np.float64),  # normal impulses
    ("Jf_front", np.float64), ("Jf_rear", np.float64),  # friction impulse magnitudes
    ("work_front", np.float64), ("work_rear", np.float64),  # sum J_n |v_slide|
], align=True)

#: Run-wide accumulators, one record (array shape (1,)).
GLOBALS = np.dtype([
    ("tau_normal", np.float64),  # angular impulse of the normal contact impulses about the cage centre [N m s]
    ("tau_friction", np.float64),  # same, friction impulses [N m s]
    ("maxpen_front", np.float64), ("maxpen_rear", np.float64),  # deepest overlap in recorded rotations [m]
    ("maxpen_all", np.float64),  # deepest overlap of the run [m]
    ("n_chatter", np.float64),  # contact steps approaching slower than the impact threshold
    ("chatter_vmax", np.float64),  # their largest approach speed [m/s]
    # where the deepest overlap of the run happened
    ("maxpen_theta_deg", np.float64), ("maxpen_time", np.float64), ("maxpen_face", np.float64),
    ("maxpen_cos", np.float64),  # n . e_t
    ("maxpen_approach", np.float64),  # approach speed [m/s]
    ("maxpen_pocket", np.float64),
], align=True)

#: One row per impact (array shape (capacity,)).
IMPACT = np.dtype([
    ("time", np.float64),  # end of the step [s]
    ("theta_deg", np.float64),  # pocket centre from the load-zone centre [deg]
    ("approach_speed", np.float64),  # [m/s]
    ("impulse", np.float64),  # normal impulse [N s]
    ("pocket", np.int64),
    ("face", np.int64),  # FACE_REAR or FACE_FRONT
    ("rotation", np.int64),  # row of the per-rotation arrays
], align=True)

#: Circumferential contact impulse by theta bin, array shape (n, bins) [N s].
FACE_BIN = np.dtype([("front", np.float64), ("rear", np.float64)], align=True)
#: Wear profile: per pocket, face (FACE_REAR, FACE_FRONT) and bin of psi, array shape (n, 2, face_bins).
PROFILE = np.dtype([
    ("impulse", np.float64),  # normal impulse J_n [N s]
    ("work", np.float64),  # sliding work J_n |v_slide| [J]
    ("hits", np.float64),  # contact steps
], align=True)
#: bins of psi of the wear profile over a face's extent (~1.8 deg, ~0.2 mm of the reference pocket's arc)
FACE_BINS = 32
#: Raceway load x time by theta bin, array shape (bins,) [N s].
RACE_BIN = np.dtype([("inner", np.float64), ("outer", np.float64)], align=True)


class Accumulators(NamedTuple):
    """The arrays :func:`record_step` adds to (created by :func:`accumulators`)."""

    win: np.ndarray  #: (R, n) WINDOW
    first_imp: np.ndarray  #: (R, n) approach speed of the first rear impact in the no-load zone [m/s], NaN: none
    f_bin: np.ndarray  #: (n, bins) FACE_BIN [N s]
    t_bin: np.ndarray  #: (n, bins) residence time [s]
    q_bin: np.ndarray  #: (bins,) RACE_BIN [N s]
    tq_bin: np.ndarray  #: (bins,) roller-time [s]
    j_int: np.ndarray  #: (n,) FACE_BIN, circumferential impulses since the last output sample [N s]
    glob: np.ndarray  #: (1,) GLOBALS
    impacts: np.ndarray  #: (capacity,) IMPACT
    prof: np.ndarray  #: (n, 2, face_bins) PROFILE, recorded rotations


def accumulators(rotations: int, roller_count: int, theta_bins: int, impact_capacity: int,
                 face_bins: int = FACE_BINS) -> Accumulators:
    """Zeroed accumulators (``first_imp`` NaN) for a run."""
    r, n = rotations, roller_count
    return Accumulators(
        win=np.zeros((r, n), dtype=WINDOW), first_imp=np.full((r, n), np.nan),
        f_bin=np.zeros((n, theta_bins), dtype=FACE_BIN), t_bin=np.zeros((n, theta_bins)),
        q_bin=np.zeros(theta_bins, dtype=RACE_BIN), tq_bin=np.zeros(theta_bins),
        j_int=np.zeros(n, dtype=FACE_BIN), glob=np.zeros(1, dtype=GLOBALS),
        impacts=np.zeros(impact_capacity, dtype=IMPACT), prof=np.zeros((n, 2, face_bins), dtype=PROFILE))


ARB_F = 9  # floats per arbiter: total impulse (2), normal (2), point a (2), point b (2), distance
ARB_I = 3  # ints per arbiter: body a id, body b id, contact count

TWO_PI = 2.0 * math.pi


@njit(cache=True, inline="always")
def pocket_theta(sign, cage_angle, pocket_angle):
    """Angle [rad, 0..2 pi) of a pocket centre from the load-zone centre in the direction of rotation."""
    th = sign * (cage_angle + pocket_angle + 0.5 * math.pi)
    th = th - TWO_PI * math.floor(th / TWO_PI)
    return th


@njit(cache=True)
def _before(k1, k2, roller, i1, i2):
    """Key order of two arbiters: roller index, then the cage contact point (x, y), then the normal."""
    if roller[i1] != roller[i2]:
        return roller[i1] < roller[i2]
    for c in range(4):
        if k1[c] != k2[c]:
            return k1[c] < k2[c]
    return False


@njit(cache=True)
def arbiter_order(arb_f, arb_i, n_arb, ids_sorted, ids_index, n):
    """Indices of the arbiters with contacts, sorted by (roller, cage contact point x, y, normal x, y).

    pymunk lists cached arbiters in the order of a hash of the shapes' memory addresses, which changes
    from run to run; summing the impulses of one step in this order instead makes every accumulated
    sum the same in every run (and in both step loops).
    """
    order = np.empty(n_arb, dtype=np.int64)
    roller = np.empty(n_arb, dtype=np.int64)
    keys = np.empty((n_arb, 4))
    m = 0
    for a in range(n_arb):
        if arb_i[a * ARB_I + 2] == 0:
            continue  # cached arbiter without contacts
        ja = ids_index[np.searchsorted(ids_sorted, arb_i[a * ARB_I])]
        o = a * ARB_F
        if ja < n:
            roller[a] = ja
            keys[a, 0] = arb_f[o + 6]
            keys[a, 1] = arb_f[o + 7]
            keys[a, 2] = arb_f[o + 2]
            keys[a, 3] = arb_f[o + 3]
        else:
            roller[a] = ids_index[np.searchsorted(ids_sorted, arb_i[a * ARB_I + 1])]
            keys[a, 0] = arb_f[o + 4]
            keys[a, 1] = arb_f[o + 5]
            keys[a, 2] = -arb_f[o + 2]
            keys[a, 3] = -arb_f[o + 3]
        # insertion sort: a step has a few dozen arbiters
        j = m
        while j > 0 and _before(keys[a], keys[order[j - 1]], roller, a, order[j - 1]):
            order[j] = order[j - 1]
            j -= 1
        order[j] = a
        m += 1
    return order[:m]


@njit(cache=True, inline="always")
def _profile_add(prof, i, face, dx, dy, alpha, etx, ety, jn, work, cfg):
    """Add a contact's normal impulse ``jn`` [N s] and sliding work [J] to the wear-profile bin of its
    ``psi`` (module docstring); ``(dx, dy)``: the cage's contact point from the cage centre, ``alpha``:
    the pocket centre's angle, ``(etx, ety)``: e_t, all in the world frame."""
    rho = dx * math.cos(alpha) + dy * math.sin(alpha) - cfg.pocket_centre_radius
    along = abs(dx * etx + dy * ety)
    psi = math.atan2(rho, along)
    nfb = prof.shape[2]
    b = int(math.floor((psi - cfg.psi_lo) / (cfg.psi_hi - cfg.psi_lo) * nfb))
    if b < 0:
        b = 0
    elif b >= nfb:
        b = nfb - 1
    r = prof[i, face, b]
    r.impulse += jn
    r.work += work
    r.hits += 1.0


@njit(cache=True, inline="always")
def record_step(arb_f, arb_i, n_arb, ids_sorted, ids_index, prev, now, t, h, cfg, pocket_a, theta0, diag, acc,
                n_imp, continuing):
    """Attribute one step's roller-cage impulses and raceway loads; return the new impact count.

    Parameters
    ----------
    arb_f, arb_i : flat float and int arbiter buffers from ``pymunk.batch.get_space_arbiters``
        (``ARB_F`` floats and ``ARB_I`` ints per arbiter, SI); ``n_arb`` arbiters are valid.
    ids_sorted, ids_index : body ids sorted, and the batch row of each (rollers 0..n-1, cage n).
    prev, now : (nb, 6) body states before and after the step (x [m], y [m], angle [rad], vx [m/s],
        vy [m/s], omega [rad/s]).
    t : time at the end of the step [s].
    h : step [s].
    cfg : :class:`RecorderConfig`.
    pocket_a : (n,) pocket centre angles in the cage frame [rad].
    theta0 : (n,) unwrapped angle of each pocket from the load-zone centre at t = 0 [rad].
    diag : (n,) :data:`bearingsim.multibody.forces.DIAG` raceway diagnostics of the step (loads [N]).
    acc : :class:`Accumulators`, added to.
    n_imp : rows of ``acc.impacts`` used before the step.
    continuing : (n,) bool, rollers whose contact goes on from the previous step (rigid raceways; all
        False otherwise): their contact steps are never impacts. At the rigid scene's step a roller
        pressed against a face approaches it by its pressing force x h / m in every step, above the
        impact threshold (the same reason restitution acts only at the onset of a contact there).
    """
    sign = cfg.sign
    n = cfg.roller_count
    warm = cfg.warmup_rotations
    nrot = cfg.rotations
    nbins = cfg.theta_bins
    vthr = cfg.impact_speed_threshold
    win = acc.win
    g = acc.glob[0]
    impacts = acc.impacts
    phic = now[n, 2]
    xc = now[n, 0]
    yc = now[n, 1]
    travel = sign * phic
    rec_on = travel >= TWO_PI * warm
    prof_on = cfg.psi_hi > cfg.psi_lo
    # raceway loads and residence time by theta (recorded period only)
    for i in range(n):
        th = pocket_theta(sign, phic, pocket_a[i])
        b = int(th / TWO_PI * nbins)
        if b >= nbins:
            b = nbins - 1
        m = math.floor((sign * phic + theta0[i]) / TWO_PI)
        k = int(m - warm)
        if 0 <= k < nrot:
            acc.t_bin[i, b] += h
            acc.q_bin[b].inner += diag[i].q_in * h
            acc.q_bin[b].outer += diag[i].q_out * h
            acc.tq_bin[b] += h
    for a in arbiter_order(arb_f, arb_i, n_arb, ids_sorted, ids_index, n):
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
        face = FACE_FRONT if front else FACE_REAR
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
        if pen > g.maxpen_all:
            g.maxpen_all = pen
            g.maxpen_theta_deg = pocket_theta(sign, phic, pocket_a[i]) * 180.0 / math.pi
            g.maxpen_time = t
            g.maxpen_face = FACE_FRONT if nx * (-sign * math.sin(phic + pocket_a[i])) + ny * (sign * math.cos(phic + pocket_a[i])) > 0.0 else FACE_REAR
            g.maxpen_cos = nx * (-sign * math.sin(phic + pocket_a[i])) + ny * (sign * math.cos(phic + pocket_a[i]))
            g.maxpen_pocket = i
            g.maxpen_approach = approach
        if front:
            acc.j_int[i].front += circ
        else:
            acc.j_int[i].rear -= circ
        th = pocket_theta(sign, phic, pocket_a[i])
        m = math.floor((sign * phic + theta0[i]) / TWO_PI)
        k = int(m - warm)
        if 0 <= k < nrot:
            w = win[k, i]
            b = int(th / TWO_PI * nbins)
            if b >= nbins:
                b = nbins - 1
            if front:
                w.I_acc += circ
                w.Jn_front += jn
                w.Jf_front += jf
                w.work_front += jn * vslide
                acc.f_bin[i, b].front += circ
                if pen > g.maxpen_front:
                    g.maxpen_front = pen
            else:
                w.I_dec -= circ
                w.Jn_rear += jn
                w.Jf_rear += jf
                w.work_rear += jn * vslide
                acc.f_bin[i, b].rear += -circ
                if pen > g.maxpen_rear:
                    g.maxpen_rear = pen
            if prof_on:
                _profile_add(acc.prof, i, face, pcx - xc, pcy - yc, alpha, etx, ety, jn, jn * vslide, cfg)
            if approach > vthr and not continuing[i]:
                if (not front) and th < math.pi and acc.first_imp[k, i] != acc.first_imp[k, i]:
                    acc.first_imp[k, i] = approach
                if n_imp < impacts.shape[0]:
                    r = impacts[n_imp]
                    r.time = t
                    r.theta_deg = th * 180.0 / math.pi
                    r.approach_speed = approach
                    r.impulse = jn
                    r.pocket = i
                    r.face = face
                    r.rotation = k
                    n_imp += 1
            elif approach > 0.0:
                g.n_chatter += 1.0
                if approach > g.chatter_vmax:
                    g.chatter_vmax = approach
        if rec_on:
            g.tau_normal += rxc * (jn * ny) - ryc * (jn * nx)
            g.tau_friction += rxc * jfy - ryc * jfx
    return n_imp


# --- motion of every body (``[output] motion_*``, docs/archive.md) -------------------------------------
#: rows of the motion block handed to Python at once
MOTION_BLOCK = 1024


def motion_columns(n: int) -> dict[str, slice]:
    """Columns of a row of the motion block (:func:`record_motion`) for ``n`` rollers: time [s], step,
    every body's (x [m], y [m], angle [rad]) (rollers 0..n-1, then the cage), the inner-ring centre
    (x, y) [m], and per pocket the mean circumferential force on its rear and front face since the
    previous row [N] (``j_int`` over the interval)."""
    nb = n + 1
    return {"time": slice(0, 1), "step": slice(1, 2), "bodies": slice(2, 2 + 3 * nb),
            "ring": slice(2 + 3 * nb, 4 + 3 * nb), "force": slice(4 + 3 * nb, 4 + 3 * nb + 2 * n)}


def motion_block(n: int) -> np.ndarray:
    """An empty motion block of :data:`MOTION_BLOCK` rows for ``n`` rollers."""
    return np.zeros((MOTION_BLOCK, motion_columns(n)["force"].stop))


def motion_limits(p) -> dict:
    """The motion window as the step loop sees it (:class:`bearingsim.multibody.loop.LoopLimits`):
    cage travel [rad] of its first and last pose and between two poses (0: no motion)."""
    nu = p.numerics
    if nu.motion_rotations <= 0.0:
        return dict(motion_lo=0.0, motion_hi=0.0, motion_step=0.0)
    lo = TWO_PI * (nu.warmup_rotations + nu.motion_start)
    return dict(motion_lo=lo, motion_hi=lo + TWO_PI * nu.motion_rotations,
                motion_step=TWO_PI / nu.motion_samples_per_rotation)


@njit(cache=True, inline="always")
def record_motion(now, t, step, sign, lim, ring_c, j_int, mot, s):
    """Store a pose of every body when the cage has turned to the next pose of the motion window; return
    True when the block ``mot`` is full (Python then flushes it).

    Poses are due at cage travel ``lo + j dphi`` (``lim.motion_lo``, ``motion_step``), j = 0 .. up to
    ``motion_hi``, each taken after the first step that reaches it (a step longer than ``dphi`` skips
    the poses it passed: the next one due is the first after it). ``j_int`` (circumferential face
    impulses since it was last zeroed; called before the step's impulses are added to it) is divided by
    the time since then and zeroed at each pose, and at ``lo - dphi``, so the first pose's forces cover
    one interval too: a pose's forces are the mean over the steps whose cage travel after the step lies
    from the previous pose's up to its own, the steps the recorder counts in a rotation by the same rule. ``s``: the loop state record
    (``motion_next``: travel of the next pose [rad], ``t_motion``: time of the last one [s], ``n_motion``:
    rows of ``mot`` used); ``now``: (n + 1, 6) body states (rollers, cage)."""
    n = j_int.shape[0]
    travel = sign * now[n, 2]
    if travel < s.motion_next or s.motion_next > lim.motion_hi + 0.5 * lim.motion_step:
        return False
    if travel >= lim.motion_lo - 0.5 * lim.motion_step:  # a pose of the window (else: the zeroing before it)
        row = mot[s.n_motion]
        dt = t - s.t_motion
        inv = 1.0 / dt if dt > 0.0 else 0.0
        row[0] = t
        row[1] = step
        for i in range(n + 1):
            row[2 + 3 * i] = now[i, 0]
            row[3 + 3 * i] = now[i, 1]
            row[4 + 3 * i] = now[i, 2]
        c = 2 + 3 * (n + 1)
        row[c] = ring_c[0]
        row[c + 1] = ring_c[1]
        for i in range(n):
            row[c + 2 + 2 * i] = j_int[i].rear * inv
            row[c + 3 + 2 * i] = j_int[i].front * inv
        s.n_motion += 1
    for i in range(n):
        j_int[i].rear = 0.0
        j_int[i].front = 0.0
    s.t_motion = t
    j = math.floor((travel - lim.motion_lo) / lim.motion_step) + 1.0
    s.motion_next = lim.motion_lo + j * lim.motion_step
    return s.n_motion == mot.shape[0]


class MotionSeries:
    """The motion's time series in a run's sink (names ``motion_*``, docs/archive.md), filled from the
    step loop's motion blocks by :meth:`flush`."""

    def __init__(self, sink, n: int, with_ring: bool):
        self.n = n
        self.cols = motion_columns(n)
        ts = sink.timeseries
        self.rollers_xy = ts("motion_roller_position", (n, 2), "m", "roller centres (x, y), rollers = pockets")
        self.rollers_a = ts("motion_roller_angle", (n,), "rad", "roller angles (counter-clockwise, unwrapped)")
        self.cage_xy = ts("motion_cage_position", (2,), "m", "cage centre (x, y); y up, radial load along -y")
        self.cage_a = ts("motion_cage_angle", (), "rad", "cage angle (counter-clockwise, unwrapped; 0 at t = 0)")
        self.ring = ts("motion_inner_ring_centre", (2,), "m", "inner-ring centre (x, y)") if with_ring else None
        self.force = ts("motion_pocket_force", (n, 2), "N",
                        "mean circumferential roller force on each pocket's rear (column 0, braking the cage) "
                        "and front face (column 1, driving the cage) since the previous sample")

    def flush(self, block: np.ndarray, k: int) -> None:
        """Append the first ``k`` rows of ``block`` (:func:`motion_columns`)."""
        if not k:
            return
        rows = block[:k]
        c, n = self.cols, self.n
        step = rows[:, 1].astype(np.int64)
        t = rows[:, 0].copy()
        bodies = rows[:, c["bodies"]].reshape(k, n + 1, 3)
        self.rollers_xy.append(step, t, bodies[:, :n, :2].copy())
        self.rollers_a.append(step, t, bodies[:, :n, 2].copy())
        self.cage_xy.append(step, t, bodies[:, n, :2].copy())
        self.cage_a.append(step, t, bodies[:, n, 2].copy())
        if self.ring is not None:
            self.ring.append(step, t, rows[:, c["ring"]].copy())
        self.force.append(step, t, rows[:, c["force"]].reshape(k, n, 2).copy())


drop_stale_caches(__name__, (_reduced_core,))  # record_step compiles in the face codes of reduced/core.py
