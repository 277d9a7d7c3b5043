"""One time step of the multi-pocket model as two compiled kernels, and the plain pymunk step loop.

Per time step ``h`` of :func:`bearingsim.multibody.core.run`:

1. :func:`before_step` on the body states before the step: end and stall checks, start of the
   recorded period, (reduced-equivalent scene) rollers inside the load zone put at the front of their
   pockets, raceway forces (:func:`bearingsim.multibody.forces.raceway_forces`) written into the set
   buffer;
2. pymunk: the forces (and, reduced-equivalent, the held states) handed to the bodies, one step
   ``h``, the body states and the arbiters read back;
3. :func:`after_step`: time and step advanced, the arbiters attributed to pockets, faces and rotations
   (:func:`bearingsim.multibody.recorder.record_step`) and, every ``out_every`` steps, a time-series
   sample and the run's health checks.

Step 2 is done either by the compiled loop of :mod:`bearingsim.multibody.chipmunk`, which calls
chipmunk's C functions from numba so that no Python runs between steps, or by :class:`PlainLoop`
here, a Python loop over ``Space.step`` and pymunk's public ``pymunk.batch`` functions (slower, the
same numbers: it calls the same two kernels with the same inputs). Both return to Python with a code
(``CODE_*``) when the run is done, when the sample block is full or ``CHUNK_STEPS`` steps have passed
(Python flushes the samples, moves the progress bar and sees Ctrl-C), or when a check failed (Python
raises the matching error). State that lives across calls is one :data:`LOOP_STATE` record.

The kernels of a step (these two, the force and recording kernels they call, and the helpers those
call every step) are compiled with numba's ``inline="always"``: called as functions they took their
parameter tuples and work arrays as arguments on every call, ~1.5 us of a 6000 rpm rigid step
(docs/fast_scene.md); inlined, the compiled loop is one function and computes the same bytes.
"""
from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np
import pymunk.batch as pb
from numba import njit

from bearingsim import compiled_laws, laws
from bearingsim._jit import drop_stale_caches
from bearingsim.multibody import forces as fk
from bearingsim.multibody import recorder as rk
from bearingsim.reduced import core as _reduced_core

BODY_GET = (pb.BodyFields.POSITION | pb.BodyFields.ANGLE | pb.BodyFields.VELOCITY
            | pb.BodyFields.ANGULAR_VELOCITY)
BODY_SET_FORCE = pb.BodyFields.FORCE | pb.BodyFields.TORQUE
BODY_SET_ALL = (pb.BodyFields.POSITION | pb.BodyFields.VELOCITY | pb.BodyFields.FORCE
                | pb.BodyFields.TORQUE)
ARB_GET = (pb.ArbiterFields.BODY_A_ID | pb.ArbiterFields.BODY_B_ID | pb.ArbiterFields.CONTACT_COUNT
           | pb.ArbiterFields.TOTAL_IMPULSE | pb.ArbiterFields.NORMAL | pb.ArbiterFields.POINT_A_1
           | pb.ArbiterFields.POINT_B_1 | pb.ArbiterFields.DISTANCE_1)

# return codes of the step loops (CODE_CONTINUE: the step kernels have nothing to report)
CODE_CONTINUE = -1
CODE_DONE, CODE_BLOCK_FULL, CODE_NONFINITE, CODE_PENETRATION, CODE_BLOWUP, CODE_STALLED = range(6)
CODE_BUFFER_GREW, CODE_CAGE_LOST, CODE_PHASE_END = 6, 7, 8
CHUNK_STEPS = 20_000  # return to Python at least this often (progress bar, Ctrl-C: ~0.3 s)
DELTA_LIMIT_M = 50e-6  # floor of LoopLimits.raceway_approach (core.raceway_approach_limit)

#: Loop state that lives across calls of the step loop, one record (array shape (1,)).
LOOP_STATE = np.dtype([
    ("step", np.int64),  # steps done
    ("cur", np.int64),  # which of the two state arrays holds the current state (0 or 1)
    ("n_imp", np.int64),  # impact rows used
    ("n_samples", np.int64),  # samples in the block not yet handed to Python
    ("n_orbit", np.int64),  # cage-centre samples written into the orbit ring buffer
    ("recording", np.int64),  # 1 once the cage has turned through the warm-up rotations
    ("newton_failures", np.int64),  # steps whose ring-centre solve did not converge
    ("t", np.float64),  # time [s]
    ("pymunk_ns", np.float64),  # time spent in pymunk's step [ns]
    ("ring_sum_x", np.float64), ("ring_sum_y", np.float64),  # sum of inner-ring centres, recorded steps [m]
    ("ring_n", np.float64),  # number of steps in those sums
    ("cage_w_start", np.float64),  # cage angular velocity when recording started [rad/s]
    ("t_rec0", np.float64),  # time when recording started [s]
    ("orbit_max", np.float64),  # largest cage-centre offset in the recorded period [m]
    ("land_tau", np.float64),  # angular impulse of the land friction on the cage, recorded steps [N m s]
    ("land_overlap_max", np.float64),  # largest overlap of the cage rim with its land in the run [m]
    ("lift_max", np.float64),  # rigid raceways: largest distance of a roller inside its outer-race circle [m]
    ("beyond_max", np.float64),  # rigid raceways: largest distance of a roller centre outside its circle after a step [m]
    ("beyond_before", np.float64),  # rigid raceways: that roller's distance outside it before that step [m]
    ("beyond_vr", np.float64),  # rigid raceways: that roller's radial speed before that step [m/s]
    ("n_motion", np.int64),  # rows of the motion block not yet handed to Python
    ("motion_next", np.float64),  # cage travel of the next motion pose (recorder.record_motion) [rad]
    ("t_motion", np.float64),  # time of the last motion pose [s]
    ("travel_prev", np.float64),  # cage travel at the start of the previous step [rad]
    ("h_prev", np.float64),  # the previous step [s]
], align=True)

#: Time-series samples, one row every ``out_every`` steps (array shape (block,)).
SAMPLE = np.dtype([
    ("step", np.int64),
    ("t", np.float64),  # [s]
    ("cage_speed", np.float64),  # cage angular speed in the direction of rotation [rad/s]
    ("cage_slip", np.float64),  # 1 - cage speed / epicyclic speed
    ("cage_x", np.float64), ("cage_y", np.float64),  # cage centre [m]
    ("ring_x", np.float64), ("ring_y", np.float64),  # inner-ring centre [m]
], align=True)


class LoopLimits(NamedTuple):
    """When the step loop stops, and the health checks of a run."""

    travel_end: float  #: cage travel at which the run is done [rad]
    travel_record: float  #: cage travel at which recording starts [rad]
    penetration: float  #: largest roller-cage overlap accepted [m]
    omega: float  #: largest cage angular speed accepted [rad/s]
    omega_nominal: float  #: epicyclic cage speed, for the slip [rad/s]
    orbit: float  #: largest cage-centre offset accepted (reach of the pocket faces) [m]
    raceway_approach: float  #: largest outer-raceway approach accepted (beyond: an energy blow-up) [m]
    out_every: int  #: steps between samples and checks
    max_steps: int  #: steps after which the cage counts as stalled
    t_phase_end: float = math.inf  #: time at which the start phase (its own step) ends [s]
    motion_lo: float = 0.0  #: cage travel of the first motion pose [rad] (:func:`~bearingsim.multibody.recorder.motion_limits`)
    motion_hi: float = 0.0  #: cage travel of the last one [rad]
    motion_step: float = 0.0  #: cage travel between two motion poses [rad]; 0: no motion stored
    chunk_steps: int = CHUNK_STEPS  #: steps after which the loop returns to Python at the latest (signals, progress)


class HoldRule(NamedTuple):
    """Reduced-equivalent scene: rollers inside the load zone ride at the front of their pockets."""

    active: bool  #: the rule applies (reduced-equivalent scene)
    phi: float  #: load-zone half angle [rad]
    radius: float  #: radius of the held roller centres (on the outer race) [m]
    front_offset: float  #: offset of a held roller from its pocket centre along e_t, s/2 [m]
    omega_cage: float  #: signed angular speed of the kinematic cage [rad/s]


class ArcFaces(NamedTuple):
    """Exact arc pocket faces (:mod:`bearingsim.multibody.scene`): what :func:`arc_faces` needs to place
    each face's tangent segment before a step. Cage frame, SI."""

    active: bool  #: exact faces (else every face is a static segment and nothing is placed)
    arc: np.ndarray  #: (n,) bool, pocket with arc faces (False: a flat pocket, static segments)
    centre: np.ndarray  #: (n, 2) pocket centres [m]
    e_t: np.ndarray  #: (n, 2) unit vector along the cage's rotation at each pocket centre (the front face's side)
    e_r: np.ndarray  #: (n, 2) outward radial unit vector at each pocket centre
    radius: float  #: R = r_r + s/2, the pocket circle's radius [m]
    psi_lo: float  #: the faces' inner end, angle from the circumferential direction (<= 0) [rad]
    psi_hi: float  #: their outer end (>= 0) [rad]
    half_length: float  #: largest half length of a tangent segment [m]
    #: squared offset from the pocket centre below which a roller's faces are left where they are: a
    #: roller that far inside its pocket cannot reach either face in the step [m^2]
    near2: float
    #: worn faces (:func:`worn_contact`): else every face is the circle of radius ``radius``
    worn_on: bool = False
    knot_psi: np.ndarray = np.zeros(0)  #: (K,) knots of the worn profile in psi: psi_lo, the bin centres, psi_hi [rad]
    knot_cos: np.ndarray = np.zeros(0)  #: (K,) cos of each knot
    knot_sin: np.ndarray = np.zeros(0)  #: (K,) sin of each knot
    #: (n, 2, K) each pocket's (front, rear) face: distance of its tangent line from the pocket centre at
    #: each knot, R + worn depth [m] (linear between knots)
    knot_h: np.ndarray = np.zeros((0, 2, 0))
    #: (n, 2, 2, 2) each worn face's edges, (inner, outer) end: where the worn face meets the rays of its
    #: extent, (x, y) in the face's frame (x along its middle, y outward) [m]
    #: (:func:`bearingsim.multibody.core.worn_edges`)
    edge: np.ndarray = np.zeros((0, 2, 2, 2))


#: inactive :class:`ArcFaces` (polyline or flat faces: every segment static)
ARC_FACES_OFF = ArcFaces(False, np.zeros(0, dtype=np.bool_), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 2)),
                         0.0, 0.0, 0.0, 0.0, 0.0)


@njit(cache=True, inline="always")
def worn_contact(px, py, kpsi, kc, ks, kh, cl, sl, ch, sh, edge, ell):
    """Where a roller touches a worn face: the segment to place, ``(ax, ay, bx, by)`` in the face's
    frame (``x`` along its middle, ``y`` outward, from the pocket centre) [m].

    A worn face is the pocket circle pushed outwards by the worn depth ``w(psi)``: the pocket is the set
    ``K`` of points ``p`` with ``p . u(psi) <= h(psi) = R + w(psi)`` for every ``psi`` of the extent
    (the lines at ``h(psi)`` from the pocket centre, normal to the direction ``psi``; ``h`` linear in psi
    between the knots ``kpsi``, values ``kh``), and the face's material is what lies outside ``K``
    within the extent's sector ``S`` (between the rays ``psi_lo``, ``psi_hi``: ``(cl, sl)``, ``(ch, sh)``).
    The roller (centre ``(px, py)``) touches the point of that material nearest to its centre. That point
    is either the foot of the perpendicular from the centre on one of the lines, where the foot lies in
    ``S`` (every such foot is a point of the material: the line bounds ``K``), or one of the face's two
    edges ``edge[0]``, ``edge[1]``, where its boundary meets the rays. On the lines, the distance
    ``g(psi) = h(psi) - (px, py) . u(psi)`` is least at a knot or where ``g' = a + rho sin(psi - phi)``
    changes sign (``a``: the slope of ``h``; ``rho``, ``phi``: the centre's distance and direction); a
    least ``g`` over the psi whose foot lies in ``S`` that is not one of those lies where the foot is on
    a ray, no nearer than that ray's edge. So the nearest point is the nearest of the feet (in ``S``) of
    the knots and of those stationary points, and the two edges.

    A foot: the segment lies on its line, over ``ell`` either side of the foot and never past the rays.
    An edge: the segment ends at it, at right angles to the line from the roller's centre (chipmunk's
    closest point is then the edge itself: a point contact, normal from the edge to the centre), and
    runs ``ell`` into the face. Unworn (``h = R``) this is the exact arc's contact: the foot at the
    roller's direction within the extent, the arc's end past it."""
    rho = math.sqrt(px * px + py * py)
    best = math.inf
    bc = 0.0
    bs = 0.0
    bh = 0.0
    for k in range(kpsi.shape[0]):
        g = kh[k] - (px * kc[k] + py * ks[k])
        if g < best:
            fx = px + g * kc[k]
            fy = py + g * ks[k]
            if fy * cl - fx * sl >= 0.0 and fx * sh - fy * ch >= 0.0:  # the foot lies in the sector
                best = g
                bc = kc[k]
                bs = ks[k]
                bh = kh[k]
    if rho > 0.0:
        phi = math.atan2(py, px)
        for k in range(kpsi.shape[0] - 1):
            a = (kh[k + 1] - kh[k]) / (kpsi[k + 1] - kpsi[k])
            if a + px * ks[k] - py * kc[k] < 0.0 < a + px * ks[k + 1] - py * kc[k + 1]:
                psi = phi - math.asin(min(1.0, max(-1.0, a / rho)))
                if kpsi[k] < psi < kpsi[k + 1]:
                    c = math.cos(psi)
                    s = math.sin(psi)
                    h = kh[k] + a * (psi - kpsi[k])
                    g = h - (px * c + py * s)
                    if g < best:
                        fx = px + g * c
                        fy = py + g * s
                        if fy * cl - fx * sl >= 0.0 and fx * sh - fy * ch >= 0.0:
                            best = g
                            bc = c
                            bs = s
                            bh = h
    nearest_edge = -1
    for e in range(2):
        dist = math.sqrt((edge[e, 0] - px) ** 2 + (edge[e, 1] - py) ** 2)
        if dist < best:
            best = dist
            nearest_edge = e
    if nearest_edge < 0:
        tx = -bs  # along the line, toward larger psi
        ty = bc
        s_f = px * tx + py * ty  # the foot, from the line's point nearest the pocket centre
        s_lo = bh * (sl * bc - cl * bs) / (cl * bc + sl * bs)  # the rays of the extent: h tan(psi_lo - psi)
        s_hi = bh * (sh * bc - ch * bs) / (ch * bc + sh * bs)
        s_a = max(s_lo, s_f - ell)
        s_b = min(s_hi, s_f + ell)
        return bh * bc + s_a * tx, bh * bs + s_a * ty, bh * bc + s_b * tx, bh * bs + s_b * ty
    ex = edge[nearest_edge, 0]
    ey = edge[nearest_edge, 1]
    tx = (py - ey) / best  # at right angles to the line from the centre to the edge ...
    ty = (ex - px) / best
    if nearest_edge == 0:  # ... into the face: toward larger psi from the inner end, smaller from the outer
        inward = -tx * sl + ty * cl > 0.0
    else:
        inward = tx * sh - ty * ch > 0.0
    if not inward:
        tx = -tx
        ty = -ty
    return ex, ey, ex + ell * tx, ey + ell * ty


class StepInputs(NamedTuple):
    """Everything the step kernels read and never change during a run."""

    h: float  #: time step [s]
    prm: fk.RacewayParams
    cfg: rk.RecorderConfig
    lim: LoopLimits
    hold_rule: HoldRule
    land: fk.LandParams  #: the land contact of a land-guided cage (``active`` False: roller-guided)
    pocket_a: np.ndarray  #: (n,) pocket centre angles in the cage frame [rad]
    theta0: np.ndarray  #: (n,) angle of each pocket from the load-zone centre at t = 0 [rad]
    ids_sorted: np.ndarray  #: (nb,) pymunk body ids, sorted (uint64)
    ids_index: np.ndarray  #: (nb,) batch row of each sorted id
    onset_restitution: bool = False  #: rigid raceways: restitution only in the first step of a roller's contact
    restitution: float = 0.0  #: e of the roller shapes [-]
    arc: ArcFaces = ARC_FACES_OFF  #: exact arc faces (placed before each step by :func:`arc_faces`)


@njit(cache=True, inline="always")
def _move_segment(e, ax, ay, bx, by):
    """Set the segment ends ``e`` (ax, ay, bx, by) to the given ones; True when they changed (the loop then
    hands the segment to chipmunk)."""
    if e[0] == ax and e[1] == ay and e[2] == bx and e[3] == by:
        return False
    e[0] = ax
    e[1] = ay
    e[2] = bx
    e[3] = by
    return True


@njit(cache=True, inline="always")
def arc_faces(state, h, af, ends, todo):
    """Place the exact arc faces for the coming step: each face's segment on the arc's tangent at the
    direction of its roller's centre from the pocket centre, clamped to the face's extent.

    The roller and the cage are taken where chipmunk's position update puts them, ``p + v h`` and
    ``angle + omega h`` (chipmunk then finds the contacts there): the tangent point is the point of the
    true circle nearest to the roller's centre, so chipmunk's closest point on the segment, its normal and
    its distance are those of the exact arc. (The update also adds the last step's overlap-correction
    velocity, which moves a body along the normal of the contact it corrects: it shifts the roller's
    direction by the correction over its offset, a change of the gap of second order, ~1e-14 m here.)

    No trigonometry: in each face's frame (``u`` = +-e_t along the face's middle, ``e_r`` outward) the
    roller's direction ``(x, y)`` is inside the extent when ``sin(psi - psi_in) >= 0`` and
    ``sin(psi_out - psi) >= 0`` (cross products with the ends' unit vectors), else it is moved to the end
    nearer in angle (larger cosine). The segment runs along the tangent ``(-y, x)`` from the tangent
    point, at most ``half_length`` either way and never past the rays of the face's ends
    (``R tan(psi - psi_in)``, ``R tan(psi_out - psi)``), so a clamped face's segment ends at the arc's end.

    ``ends``: (n, 2, 4) each pocket's (front, rear) segment ends (ax, ay, bx, by) in the cage frame, updated;
    ``todo``: (n, 2) bool, set where a segment moved (the loop hands those to chipmunk). A roller within
    ``near2`` of its pocket centre leaves its faces as they are: every point of a tangent segment is at
    least R from the pocket centre, out of its reach.

    Worn faces (``af.worn_on``): the segment is :func:`worn_contact`'s, at the point of the worn face's
    material nearest to the roller's centre (a foot on one of its lines, ``R + w`` from the pocket centre,
    or one of its edges)."""
    n = todo.shape[0]
    cx = state[n, 0] + state[n, 3] * h
    cy = state[n, 1] + state[n, 4] * h
    a = state[n, 2] + state[n, 5] * h
    c = math.cos(a)
    s = math.sin(a)
    R = af.radius
    ell = af.half_length
    cl = math.cos(af.psi_lo)
    sl = math.sin(af.psi_lo)
    ch = math.cos(af.psi_hi)
    sh = math.sin(af.psi_hi)
    for i in range(n):
        todo[i, 0] = False
        todo[i, 1] = False
        if not af.arc[i]:
            continue
        px = state[i, 0] + state[i, 3] * h - cx
        py = state[i, 1] + state[i, 4] * h - cy
        dx = c * px + s * py - af.centre[i, 0]  # roller centre from the pocket centre, cage frame
        dy = -s * px + c * py - af.centre[i, 1]
        d2 = dx * dx + dy * dy
        if d2 < af.near2 or d2 == 0.0:
            continue
        inv = 1.0 / math.sqrt(d2)
        erx = af.e_r[i, 0]
        ery = af.e_r[i, 1]
        y0 = (dx * erx + dy * ery) * inv
        for f in range(2):
            ux = af.e_t[i, 0] if f == 0 else -af.e_t[i, 0]
            uy = af.e_t[i, 1] if f == 0 else -af.e_t[i, 1]
            if af.worn_on:  # the worn face's segment in the face's frame (worn_contact), then in the cage frame
                wax, way, wbx, wby = worn_contact(dx * ux + dy * uy, dx * erx + dy * ery, af.knot_psi, af.knot_cos,
                                                  af.knot_sin, af.knot_h[i, f], cl, sl, ch, sh, af.edge[i, f], ell)
                ax_ = af.centre[i, 0] + wax * ux + way * erx
                ay_ = af.centre[i, 1] + wax * uy + way * ery
                bx_ = af.centre[i, 0] + wbx * ux + wby * erx
                by_ = af.centre[i, 1] + wbx * uy + wby * ery
                todo[i, f] = _move_segment(ends[i, f], ax_, ay_, bx_, by_)
                continue
            x = (dx * ux + dy * uy) * inv  # the roller's direction in this face's frame
            y = y0
            s_lo = y * cl - x * sl  # sin(psi - psi_lo)
            s_hi = x * sh - y * ch  # sin(psi_hi - psi)
            if s_lo < 0.0 or s_hi < 0.0:  # past an end: the end nearer in angle
                if x * cl + y * sl >= x * ch + y * sh:
                    x = cl
                    y = sl
                else:
                    x = ch
                    y = sh
                s_lo = y * cl - x * sl
                s_hi = x * sh - y * ch
            c_lo = x * cl + y * sl  # cos(psi - psi_lo)
            c_hi = x * ch + y * sh  # cos(psi_hi - psi)
            l_lo = R * s_lo / c_lo if c_lo > 0.0 and R * s_lo < ell * c_lo else ell
            l_hi = R * s_hi / c_hi if c_hi > 0.0 and R * s_hi < ell * c_hi else ell
            qx = af.centre[i, 0] + R * (x * ux + y * erx)  # tangent point
            qy = af.centre[i, 1] + R * (x * uy + y * ery)
            tx = -y * ux + x * erx  # tangent, toward larger psi
            ty = -y * uy + x * ery
            todo[i, f] = _move_segment(ends[i, f], qx - l_lo * tx, qy - l_lo * ty, qx + l_hi * tx, qy + l_hi * ty)


#: the narrowed masks keep a face segment whose distance from the roller's circle after pymunk's position
#: update is below this [m]: rounding of the same arithmetic is ~1e-17 m, contact needs distance < 0
MASK_MARGIN_M = 1.0e-9


class FaceMasks(NamedTuple):
    """Compiled loop: each roller's collision mask narrowed, before each step, to the face segments of its
    pocket that it can touch in that step (:func:`face_masks`)."""

    active: bool  #: narrow the masks (else every roller keeps all face segments)
    #: (n, S, 5) each pocket's face segments in the cage frame: start (ax, ay) [m], b - a (ex, ey) [m],
    #: 1 / |b - a|^2 [1/m^2]
    seg: np.ndarray
    bits: np.ndarray  #: (n, S) uint32 category bit of each segment (0: no segment)
    centre: np.ndarray  #: (n, 2) pocket centres in the cage frame [m]
    #: (R - r - margin)^2 [m^2]: a roller centre closer to its pocket centre touches no face (R: the faces'
    #: inscribed radius); -1: never
    clear2: float
    reach2: float  #: (r + margin)^2 [m^2]: a segment closer to the roller centre may be touched
    #: (n,) bool, pocket with exact arc faces: its two segments move (:func:`arc_faces`), so a roller
    #: beyond ``clear2`` is tested against them where they are placed for the step (``arc_ends``)
    arc: np.ndarray = np.zeros(0, dtype=np.bool_)


class StepWork(NamedTuple):
    """Arrays the step kernels write, besides the recorder's accumulators."""

    ring_c: np.ndarray  #: (2,) inner-ring centre [m]
    ring_c_prev: np.ndarray  #: (2,) scratch
    ring_v: np.ndarray  #: (2,) inner-ring velocity (dynamic ring) [m/s]
    hold: np.ndarray  #: (n,) bool, rollers held this step
    out_f: np.ndarray  #: (nb * 3,) (fx, fy, torque) per body [N, N m]
    set_arr: np.ndarray  #: the buffer pymunk's batched setter reads (is ``out_f`` when only forces are set; else :func:`pack_all` fills it)
    diag: np.ndarray  #: (n,) :data:`bearingsim.multibody.forces.DIAG`
    smp: np.ndarray  #: (block,) :data:`SAMPLE`
    orbit: np.ndarray  #: (keep, 3) ring buffer of (t [s], x [m], y [m]) of the cage centre
    land_out: np.ndarray  #: (4,) the land contact of the step (:func:`bearingsim.multibody.forces.land_force`)
    land_win: np.ndarray  #: (R, 3) per cage rotation: land normal impulse [N s], friction impulse [N s], friction torque impulse [N m s]
    n_out: np.ndarray  #: (n,) rigid raceways: outer-race normal force of each roller over the last step, from its joint [N]
    n_held: np.ndarray  #: (n,) rigid raceways: the outer race's reaction applied by the force kernel in the last step [N]
    e_set: np.ndarray  #: (n,) elasticity each roller shape has now (onset restitution) [-]
    e_want: np.ndarray  #: (n,) elasticity each roller shape is to have in the next step [-]
    touched: np.ndarray  #: (n,) bool, rollers that touched a cage face in the last step (rigid raceways)
    n_extra: np.ndarray  #: (n,) rigid raceways: the outer race's force of :func:`~bearingsim.multibody.forces.race_orbit` in the step [N]
    arc_ends: np.ndarray  #: (n, 2, 4) exact faces: each pocket's (front, rear) segment as placed (ax, ay, bx, by), cage frame [m]
    arc_todo: np.ndarray  #: (n, 2) bool, exact faces: the segments :func:`arc_faces` moved for the coming step
    rest_win: np.ndarray  #: (R, 3) per cage rotation: sums of the sampled cage centre's x and y [m], sample count
    #: (R, 3) per cage rotation: its time [s] (from and to where the cage's travel crosses its ends, within a step),
    #: the sum of the inner-ring centre's y over its steps [m], their count
    rot_win: np.ndarray
    #: (rows, columns) motion poses (:func:`bearingsim.multibody.recorder.record_motion`)
    mot: np.ndarray = np.zeros((1, 1))


@njit(cache=True)
def _hold_rollers(state, n, sign, rule, pocket_a, hold):
    """Reduced-equivalent: rollers in the load zone ride at the front of their pockets with the cage."""
    phic = state[n, 2]
    phi = rule.phi
    for i in range(n):
        th = rk.pocket_theta(sign, phic, pocket_a[i])
        inside = th < phi or th > 2.0 * math.pi - phi
        hold[i] = inside
        if inside:
            a = phic + pocket_a[i]
            ca = math.cos(a)
            sa = math.sin(a)
            # pocket centre on the pitch circle; roller on the outer race, shifted by s/2 along e_t
            etx = -sign * sa
            ety = sign * ca
            px = rule.radius * ca + rule.front_offset * etx
            py = rule.radius * sa + rule.front_offset * ety
            # velocity of that point of the (kinematic) cage
            state[i, 0] = px
            state[i, 1] = py
            state[i, 3] = -rule.omega_cage * py
            state[i, 4] = rule.omega_cage * px


@njit(cache=True)
def pack_all(state, out_f, set_arr, nb):
    """Fill pymunk's batched setter's buffer of :data:`BODY_SET_ALL` rows (p, v, f, t) from the states
    (positions and velocities that the step's rules set: held rollers, rollers on a rigid race) and the
    forces."""
    a = set_arr.reshape(nb, 7)
    f = out_f.reshape(nb, 3)
    for i in range(nb):  # element by element: a slice assignment compiles numba's shape-error formatting
        a[i, 0] = state[i, 0]
        a[i, 1] = state[i, 1]
        a[i, 2] = state[i, 3]
        a[i, 3] = state[i, 4]
        a[i, 4] = f[i, 0]
        a[i, 5] = f[i, 1]
        a[i, 6] = f[i, 2]


@njit(cache=True)
def _land_step(prev, travel, inp, wk, s):
    """Land contact force on the cage (after the raceway forces, which zero the set buffer), and its
    impulses over the step: per cage rotation (rotation k: cage travel in [2 pi (W + k), 2 pi (W + k + 1)))
    and, for the cage's angular-momentum balance, the friction torque impulse of the recorded steps."""
    h = inp.h
    out = wk.land_out
    fk.land_force(prev, h, inp.land, wk.ring_c, wk.ring_c_prev, wk.out_f, out)
    s.land_overlap_max = max(s.land_overlap_max, out[fk.LAND_OVERLAP])
    if s.recording == 1:
        s.land_tau += out[fk.LAND_TORQUE] * h
        k = int(math.floor(travel / (2.0 * math.pi) - inp.cfg.warmup_rotations))
        if 0 <= k < wk.land_win.shape[0]:
            wk.land_win[k, 0] += out[fk.LAND_N] * h
            wk.land_win[k, 1] += abs(out[fk.LAND_FT]) * h
            wk.land_win[k, 2] += out[fk.LAND_TORQUE] * h


@njit(cache=True, inline="always")
def onset_elasticity(arb_i, n_arb, inp, wk):
    """Rigid raceways: the roller elasticity for the next step, into ``wk.e_want``: 0 for a roller that
    touched a cage face in this step (its contact goes on: an approach within it is the step's force
    impulse, not an impact), ``inp.restitution`` for the others (their next contact is an impact).

    With a step longer than the traction's relaxation time (m slip_ref u / (mu_max Q), ~10 us at
    6000 rpm in the load zone) the implicit traction brings a roller pressed against a face back to its
    rolling speed in every step, and restitution on every step of that contact compounds its approach
    to dv / (1 - e) (dv: the roller's rolling speed against the cage's); with it only at the onset of a
    contact the approach stays dv. The Hertz scene's 4 us step keeps that chatter small, and it keeps
    pymunk's restitution on every step."""
    n = wk.e_want.shape[0]
    for i in range(n):
        wk.e_want[i] = inp.restitution
        wk.touched[i] = False
    for a in range(n_arb):
        if arb_i[a * rk.ARB_I + 2] == 0:
            continue
        for j in range(2):
            row = inp.ids_index[np.searchsorted(inp.ids_sorted, arb_i[a * rk.ARB_I + j])]
            if row < n:
                wk.e_want[row] = 0.0
                wk.touched[row] = True  # the recorder counts its next contact step as this contact


@njit(cache=True, inline="always")
def _segment_within(ax, ay, ex, ey, inv2, qx, qy, reach2):
    """Whether the segment from ``(ax, ay)`` along ``(ex, ey)`` (``inv2`` = 1 / |e|^2, 0 for a point) comes
    closer to ``(qx, qy)`` than ``sqrt(reach2)``."""
    t = min(max(((qx - ax) * ex + (qy - ay) * ey) * inv2, 0.0), 1.0)
    ux = ax + t * ex - qx
    uy = ay + t * ey - qy
    return ux * ux + uy * uy < reach2


@njit(cache=True, inline="always")
def face_masks(state, vb, h, fm, arc_ends, want):
    """The collision mask of each roller for the coming step, into ``want`` (uint32): the category bits
    of the face segments of its pocket within ``MASK_MARGIN_M`` of its circle where chipmunk's position
    update will put roller and cage, ``p + (v + v_bias) h`` and ``a + (w + w_bias) h`` (the same
    arithmetic; ``vb``: (nb, 3) the bodies' bias velocities (vx, vy, w) left by the last step's overlap
    correction). chipmunk finds contacts after that update and only between overlapping shapes (circle
    to segment: distance below the radius), so a segment left out could not have touched the roller in
    this step: the masks change no contact and no number, they only spare the narrow-phase tests.

    A roller centre closer than ``R - r`` to its pocket centre touches no face (every face point is at
    least ``R`` from it: the polyline circumscribes the arc, an exact face's tangent segment touches it
    at one point, a flat face is a plane at ``R``), so most
    rollers need one distance; the others are tested against each segment of their pocket, an exact
    face's where :func:`arc_faces` has placed it for this step (``arc_ends``: (n, 2, 4), cage frame). A
    roller stays in its own pocket (it would have to pass through a face)."""
    n = want.shape[0]
    cx = state[n, 0] + (state[n, 3] + vb[n, 0]) * h
    cy = state[n, 1] + (state[n, 4] + vb[n, 1]) * h
    a = state[n, 2] + (state[n, 5] + vb[n, 2]) * h
    c = math.cos(a)
    s = math.sin(a)
    seg = fm.seg
    for i in range(n):
        px = state[i, 0] + (state[i, 3] + vb[i, 0]) * h - cx
        py = state[i, 1] + (state[i, 4] + vb[i, 1]) * h - cy
        qx = c * px + s * py  # in the cage frame
        qy = -s * px + c * py
        dx = qx - fm.centre[i, 0]
        dy = qy - fm.centre[i, 1]
        m = np.uint32(0)
        if dx * dx + dy * dy >= fm.clear2 and fm.arc.shape[0] and fm.arc[i]:
            for f in range(2):  # an exact face: its segment as arc_faces placed it for this step
                e = arc_ends[i, f]
                ex = e[2] - e[0]
                ey = e[3] - e[1]
                e2 = ex * ex + ey * ey
                if _segment_within(e[0], e[1], ex, ey, 1.0 / e2 if e2 > 0.0 else 0.0, qx, qy, fm.reach2):
                    m |= fm.bits[i, f]
        elif dx * dx + dy * dy >= fm.clear2:
            for j in range(seg.shape[1]):
                bit = fm.bits[i, j]
                if bit != 0 and _segment_within(seg[i, j, 0], seg[i, j, 1], seg[i, j, 2], seg[i, j, 3], seg[i, j, 4],
                                                qx, qy, fm.reach2):
                    m |= bit
        want[i] = m


@njit(cache=True, inline="always")
def before_step(prev, inp, wk, ls):
    """Checks and raceway forces before a step; return ``CODE_CONTINUE`` or the code to stop with.

    Parameters
    ----------
    prev : (nb, 6) body states before the step (x [m], y [m], angle [rad], vx [m/s], vy [m/s],
        omega [rad/s]); held rollers are overwritten.
    inp : :class:`StepInputs`.
    wk : :class:`StepWork`; ``out_f`` receives the bodies' forces (the loop hands them, and ``prev``'s
        positions and velocities where the scene sets those, to pymunk).
    ls : (1,) :data:`LOOP_STATE`.
    """
    s = ls[0]
    lim = inp.lim
    n = inp.cfg.roller_count
    sign = inp.cfg.sign
    travel = sign * prev[n, 2]
    if travel >= lim.travel_end:
        if s.recording == 1 and s.travel_prev < lim.travel_end:  # the last recorded rotation ends inside the step
            _rotation_boundary(wk.rot_win, s.travel_prev, travel, s.h_prev, inp.cfg.warmup_rotations)
            s.travel_prev = travel
        return CODE_DONE
    if s.step > lim.max_steps:
        return CODE_STALLED
    if s.t >= lim.t_phase_end:
        return CODE_PHASE_END
    if s.recording == 0 and travel >= lim.travel_record:
        s.recording = 1
        s.cage_w_start = prev[n, 5]
        s.t_rec0 = s.t
    if inp.hold_rule.active:
        _hold_rollers(prev, n, sign, inp.hold_rule, inp.pocket_a, wk.hold)
    if inp.prm.rigid:
        fk.race_orbit(prev, inp.h, inp.prm, wk.hold, wk.n_extra, wk.diag)
    if fk.raceway_forces(prev, inp.h, inp.prm, wk.ring_c, wk.ring_c_prev, wk.ring_v, wk.hold, wk.out_f,
                         wk.diag, wk.n_out, wk.n_held) < 0:
        s.newton_failures += 1
    if inp.land.active:
        _land_step(prev, travel, inp, wk, s)
    if s.recording == 1:
        s.ring_sum_x += wk.ring_c[0]
        s.ring_sum_y += wk.ring_c[1]
        s.ring_n += 1.0
        # the same per recorded cage rotation k (cage travel in [2 pi (W + k), 2 pi (W + k + 1))), the step's
        # time to the rotation it starts in, and the part of the previous step after a rotation's start to it
        k = int(math.floor(travel / (2.0 * math.pi) - inp.cfg.warmup_rotations))
        if 0 <= k < wk.rot_win.shape[0]:
            wk.rot_win[k, 0] += inp.h
            wk.rot_win[k, 1] += wk.ring_c[1]
            wk.rot_win[k, 2] += 1.0
        _rotation_boundary(wk.rot_win, s.travel_prev, travel, s.h_prev, inp.cfg.warmup_rotations)
    s.travel_prev = travel
    s.h_prev = inp.h
    return CODE_CONTINUE


@njit(cache=True, inline="always")
def _rotation_boundary(rot_win, travel0, travel1, h, warmup):
    """A step of ``h`` [s] from cage travel ``travel0`` to ``travel1`` [rad] that crosses the start of a recorded
    rotation (cage travel 2 pi (W + k)) or the recording's end: the part of the step after it, the step's time
    in the ratio of the travel (linear within the step), moves from the rotation the step started in to rotation
    k (``rot_win[:, 0]``; the recording's start and end have none on one side). The rotations' times are then
    the cage's own, not whole steps."""
    k0 = int(math.floor(travel0 / (2.0 * math.pi) - warmup))
    k1 = int(math.floor(travel1 / (2.0 * math.pi) - warmup))
    if k1 <= k0 or travel1 <= travel0:
        return
    part = h * (travel1 - 2.0 * math.pi * (warmup + k1)) / (travel1 - travel0)
    if 0 <= k1 < rot_win.shape[0]:
        rot_win[k1, 0] += part
    if 0 <= k0 < rot_win.shape[0]:
        rot_win[k0, 0] -= part


@njit(cache=True, inline="always")
def after_step(st0, st1, arb_f, arb_i, n_arb, inp, wk, acc, ls):
    """Advance time and step, record the step, sample and check; return ``CODE_CONTINUE`` or a code.

    Parameters
    ----------
    st0, st1 : (nb, 6) the two state arrays; pymunk has written the state after the step into the one
        that did not hold the state before it (``ls[0].cur`` is toggled here).
    arb_f, arb_i, n_arb : pymunk's batched arbiters (see :func:`bearingsim.multibody.recorder.record_step`).
    inp : :class:`StepInputs`.
    wk : :class:`StepWork`.
    acc : :class:`bearingsim.multibody.recorder.Accumulators`.
    ls : (1,) :data:`LOOP_STATE`.
    """
    s = ls[0]
    lim = inp.lim
    n = inp.cfg.roller_count
    nb = n + 1
    sign = inp.cfg.sign
    s.t += inp.h
    s.step += 1
    s.cur ^= 1
    if s.cur == 0:
        now = st0
        prev = st1
    else:
        now = st1
        prev = st0
    t = s.t
    # the pose before the step's impulses are added: a pose's face forces are those of the steps whose cage
    # travel (after the step) lies between the previous pose's and its own, as the recorder counts rotations
    motion_full = lim.motion_step > 0.0 and rk.record_motion(now, t, s.step, sign, lim, wk.ring_c, acc.j_int,
                                                             wk.mot, s)
    s.n_imp = rk.record_step(arb_f, arb_i, n_arb, inp.ids_sorted, inp.ids_index, prev, now, t, inp.h, inp.cfg,
                             inp.pocket_a, inp.theta0, wk.diag, acc, s.n_imp, wk.touched)
    if s.step % lim.out_every == 0:
        ok = True
        for i in range(nb):
            for j in range(6):
                if not math.isfinite(now[i, j]):
                    ok = False
        if not ok:
            return CODE_NONFINITE
        if acc.glob[0].maxpen_all > lim.penetration:
            return CODE_PENETRATION
        dmax = 0.0
        for i in range(n):
            d_i = wk.diag[i]
            dmax = max(dmax, d_i.delta_out)
            if inp.prm.rigid:  # the inner-race approach too (a roller off the outer race), and the joint's circle
                dmax = max(dmax, d_i.delta_in)
                s.lift_max = max(s.lift_max, d_i.lift)
                # how far pymunk's step left the roller outside its outer-race circle, and from what: the
                # distance before the step and the radial speed it moved with (x_new = x + h v)
                beyond = math.hypot(now[i, 0], now[i, 1]) - inp.prm.rigid_radius
                if beyond > s.beyond_max:
                    r_prev = math.hypot(prev[i, 0], prev[i, 1])
                    s.beyond_max = beyond
                    s.beyond_before = r_prev - inp.prm.rigid_radius
                    s.beyond_vr = (prev[i, 0] * prev[i, 3] + prev[i, 1] * prev[i, 4]) / r_prev
        if dmax > lim.raceway_approach or abs(now[n, 5]) > lim.omega:
            return CODE_BLOWUP
        if math.hypot(now[n, 0], now[n, 1]) > lim.orbit:
            return CODE_CAGE_LOST
        wc = sign * now[n, 5]
        if s.recording == 1:
            orbit = wk.orbit
            k = s.n_orbit % orbit.shape[0]
            orbit[k, 0] = t
            orbit[k, 1] = now[n, 0]
            orbit[k, 2] = now[n, 1]
            s.n_orbit += 1
            s.orbit_max = max(s.orbit_max, math.hypot(now[n, 0], now[n, 1]))
            # where the cage rests, per cage rotation (rotation k: cage travel in [2 pi (W + k), 2 pi (W + k + 1)))
            kr = int(math.floor(sign * now[n, 2] / (2.0 * math.pi) - inp.cfg.warmup_rotations))
            if 0 <= kr < wk.rest_win.shape[0]:
                wk.rest_win[kr, 0] += now[n, 0]
                wk.rest_win[kr, 1] += now[n, 1]
                wk.rest_win[kr, 2] += 1.0
        k = s.n_samples
        r = wk.smp[k]
        r.step = s.step
        r.t = t
        r.cage_speed = wc
        r.cage_slip = 1.0 - wc / lim.omega_nominal
        r.cage_x = now[n, 0]
        r.cage_y = now[n, 1]
        r.ring_x = wk.ring_c[0]
        r.ring_y = wk.ring_c[1]
        s.n_samples = k + 1
        if k + 1 == wk.smp.shape[0]:
            return CODE_BLOCK_FULL
    if motion_full:
        return CODE_BLOCK_FULL
    return CODE_CONTINUE


class PlainLoop:
    """The step loop in Python over pymunk's public API (``Space.step``, ``pymunk.batch``).

    ``states``: the two (nb, 6) state arrays; ``timed``: the time in pymunk's step is measured.
    """

    name = "plain"
    timed = True

    def __init__(self, space, nb, set_fields, set_arr, joints=(), roller_shapes=(), arc_shapes=None):
        self.space = space
        self.arc_shapes = arc_shapes  # exact faces: [pocket][face] segments placed before each step
        self.joints = list(joints)
        self.roller_shapes = list(roller_shapes)
        self.nb = nb
        self.set_fields = set_fields
        self.states = [np.zeros((nb, 6)), np.zeros((nb, 6))]
        self._bodies = pb.Buffer()
        self._arbiters = pb.Buffer()
        self._set = pb.Buffer()
        self._set.set_float_buf(set_arr)

    def _read_bodies(self, out):
        self._bodies.clear()
        pb.get_space_bodies(self.space, BODY_GET, self._bodies)
        out[:] = np.frombuffer(self._bodies.float_buf(), dtype=np.float64).reshape(self.nb, 6)

    def read_states(self):
        """Fill state array 0 from the space (before the first step)."""
        self._read_bodies(self.states[0])
        return self.states[0]

    def advance(self, inp, wk, acc, ls):
        """Step until :func:`before_step` or :func:`after_step` report a code, or ``inp.lim.chunk_steps`` steps."""
        st0, st1 = self.states
        step_return = int(ls[0]["step"]) + inp.lim.chunk_steps
        h = inp.h
        while True:
            cur = int(ls[0]["cur"])
            code = before_step(self.states[cur], inp, wk, ls)
            if code != CODE_CONTINUE:
                return code
            if inp.arc.active:  # the same C call as the compiled loop's (cpSegmentShapeSetEndpoints)
                arc_faces(self.states[cur], h, inp.arc, wk.arc_ends, wk.arc_todo)
                for i, f in zip(*np.nonzero(wk.arc_todo)):
                    e = wk.arc_ends[i, f]
                    self.arc_shapes[i][f].unsafe_set_endpoints((e[0], e[1]), (e[2], e[3]))
            if self.set_fields == BODY_SET_ALL:
                pack_all(self.states[cur], wk.out_f, wk.set_arr, self.nb)
            pb.set_space_bodies(self.space, self.set_fields, self._set)
            t0 = time.perf_counter_ns()
            self.space.step(h)
            ls[0]["pymunk_ns"] += time.perf_counter_ns() - t0
            for k, j in enumerate(self.joints):  # rigid raceways: the outer-race forces of the step
                wk.n_out[k] = j.impulse / h + wk.n_extra[k]
            self._read_bodies(self.states[cur ^ 1])
            self._arbiters.clear()
            pb.get_space_arbiters(self.space, ARB_GET, self._arbiters)
            arb_f = np.frombuffer(self._arbiters.float_buf(), dtype=np.float64)
            arb_i = np.frombuffer(self._arbiters.int_buf(), dtype=np.uint64)
            code = after_step(st0, st1, arb_f, arb_i, arb_i.shape[0] // rk.ARB_I, inp, wk, acc, ls)
            if code != CODE_CONTINUE:
                return code
            if inp.onset_restitution:
                onset_elasticity(arb_i, arb_i.shape[0] // rk.ARB_I, inp, wk)
                for i, shape in enumerate(self.roller_shapes):
                    if wk.e_want[i] != wk.e_set[i]:
                        shape.elasticity = wk.e_want[i]
                        wk.e_set[i] = wk.e_want[i]
            if ls[0]["step"] >= step_return:
                return CODE_BLOCK_FULL


drop_stale_caches(__name__, (fk, rk, _reduced_core, laws, compiled_laws))  # the step kernels compile in the force and recording kernels
