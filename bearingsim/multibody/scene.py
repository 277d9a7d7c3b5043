"""The pymunk scene of the multi-pocket model: rollers, cage with arc pocket faces. SI throughout.

Frame: x to the right, y up; the radial load on the inner ring points down (-y), so the load-zone
centre is at the bottom. ``sign`` = +1 is counter-clockwise (forward) inner-ring rotation, -1 reverse.

Pocket faces. A pocket is a circle of diameter ``2 r_r + s`` (radius ``R``) around the pocket centre on
the pitch circle. The cage material only exists within its radial wall, so each face is the arc of that
circle over ``psi`` in ``[psi_in, psi_out]`` from the circumferential direction (``multibody.pocket_face_extent``,
by default what the cage wall allows: :func:`bearingsim.laws.pocket_face_extent`): the *front* face lies
ahead of the pocket centre in the direction of cage rotation, the *rear* face behind it.

Exact faces (``n_seg`` = 0, the default). Each arc face is one pymunk segment that the step loop places,
before every step, on the tangent of the arc at the direction of the roller's centre from the pocket
centre where chipmunk's position update will put it (:func:`bearingsim.multibody.loop.arc_faces`),
with that direction clamped to the face's extent. Chipmunk's circle-to-segment test then finds the
closest point of the segment to the roller's centre: the tangent point, whose normal is the pocket
radius through the roller's centre and whose gap is ``R - |d| - r_r = s/2 - |d|`` (``d``: the roller
centre's offset from the pocket centre), the contact with the true circle. A roller whose direction
lies past the face's end meets the segment's end point, which is the end of the arc: the face's edge,
a point contact. No other point of a tangent segment is nearer than ``R`` to the pocket centre, so a
segment left where it was cannot touch a roller that is nowhere near its face.

Polyline faces (``n_seg`` = N >= 1: ``multibody.pocket_face_segments``, to measure that approximation).
Each arc is replaced by ``N`` pymunk segments that are *tangent* to the true arc at their midpoints
(circumscribed polyline): the polyline never intrudes into the pocket, at the cost of up to
``R (1/cos(beta/N) - 1)`` extra play at the vertices (``beta``: the face's angular span).

Flat pockets (``multibody.flat_pockets``): the paper's instrumented pocket, whose curved faces "were
machined flat to mount the load cells" set "to match the diameter of the cage pocket" (Sec. 2.1). Each
face is one plane segment normal to ``e_t`` at ``R`` from the pocket centre (faces ``2R = D + s`` apart,
parallel to the pocket's radial centre line) reaching ``R`` either side of the pitch circle, more than
any radial position the roller takes (raceway clearance and cage eccentricity are a fraction of a
millimetre). It pushes only circumferentially: it does not guide the cage radially.

Collision filtering: rollers collide only with the cage. Elasticities are ``e`` on the roller and 1 on
the cage (pymunk multiplies them), friction likewise ``cage_friction`` and 1. Each face segment has a
category bit of its own (the same for the same segment of every pocket: face ``f`` (0 front, 1 rear),
segment ``k``: bit ``1 + f n_seg + k``; exact faces are one segment each), and a roller's mask holds all of them; the compiled step loop
narrows a roller's mask, step by step, to the segments of its pocket that it can touch in that step
(:func:`bearingsim.multibody.loop.face_masks`), which spares chipmunk the narrow-phase tests of the
others and changes no contact.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pymunk

from bearingsim.parameters import pocket_angles  # noqa: F401 - re-exported: the pocket centres' angles

ROLLER_CATEGORY = 0b01
CAGE_CATEGORY = 0b10  # every face segment when there are too many for a bit each (then no narrowed masks)


@dataclass
class Scene:
    """A built pymunk space and what the solver needs to know about it."""

    space: pymunk.Space
    rollers: list
    cage: pymunk.Body
    pocket_body_angle: np.ndarray  # (n,) angle of each pocket centre in the cage frame [rad]
    pocket_radius: float  # R = r_r + s/2 [m]
    face_vertices: list  # [pocket][face] polyline vertices (k + 1, 2) in the cage frame [m]
    body_ids: np.ndarray  # (n + 1,) pymunk body ids in batch order (rollers, then cage)
    joints: list = field(default_factory=list)  # rigid raceways: each roller's outer-race joint, in roller order
    #: (n, S, 4) each pocket's face segments (ax, ay, bx, by) in the cage frame [m], S = 2 n_seg (unused rows 0)
    face_segments: np.ndarray | None = None
    #: (n, S) uint32 category bit of each segment (0: no segment); None: the segments share ``CAGE_CATEGORY``
    face_bits: np.ndarray | None = None
    pocket_centres: np.ndarray | None = None  # (n, 2) pocket centres in the cage frame [m]
    #: exact faces: [pocket][face] the pymunk segment of each arc face (None: a flat pocket's); None: polyline faces
    arc_shapes: list | None = None
    extent: tuple[float, float] = (0.0, 0.0)  # (psi_in, psi_out) of the arc faces [rad]


def segment_bit(face: int, k: int, n_seg: int) -> int:
    """Category bit of segment ``k`` of face ``face`` (0 front, 1 rear) of a pocket: ``1 << (1 + face n_seg + k)``."""
    return 1 << (1 + face * n_seg + k)


def own_bits(n_seg: int) -> bool:
    """Whether each face segment can have a category bit of its own (chipmunk's masks are 32 bits)."""
    return 1 + 2 * n_seg <= 32


def face_polyline(centre, e_t, e_r, radius, extent, n_seg):
    """Vertices of a polyline circumscribing the arc ``centre + R (cos psi e_t + sin psi e_r)``.

    ``psi`` spans ``extent = (psi_lo, psi_hi)``; each of the ``n_seg`` segments touches the arc at its
    midpoint. Returns an ``(n_seg + 1, 2)`` array [m].
    """
    lo, hi = extent
    dpsi = (hi - lo) / n_seg
    r_v = radius / math.cos(0.5 * dpsi)
    psi = lo + dpsi * np.arange(n_seg + 1)
    # the two end vertices lie on the extension of the end segments, at the arc's angular limits
    pts = centre[None, :] + r_v * (np.cos(psi)[:, None] * e_t[None, :] + np.sin(psi)[:, None] * e_r[None, :])
    return pts


def face_tangent(centre, e_t, e_r, radius, extent):
    """The exact face's segment before the first step: tangent to the arc at ``psi`` = 0 (the face's
    middle on the pocket's circumferential centre line), as :func:`bearingsim.multibody.loop.arc_faces`
    places it for a roller there. Returns a ``(2, 2)`` array [m]."""
    lo, hi = extent
    half = TANGENT_HALF_LENGTH * radius
    p = centre + radius * e_t
    return np.array([p - min(half, radius * math.tan(-lo)) * e_r, p + min(half, radius * math.tan(hi)) * e_r])


#: half length of an exact face's tangent segment, as a fraction of R (chipmunk only ever meets the segment
#: at its tangent point, or at an end that is the arc's end; the length only has to be more than 0)
TANGENT_HALF_LENGTH = 0.05


def build_scene(geometry, op, restitution: float, cage_friction: float, *, extent: tuple[float, float],
                n_seg: int, kinematic_cage: bool, spin_free: bool, spatial_hash: bool = True,
                flat_pockets=(), centred_cage: bool = False, rigid_radius: float | None = None,
                worn=None) -> Scene:
    """Build the space: ``roller_count`` rollers at their pocket centres and the cage.

    Parameters
    ----------
    geometry : :class:`bearingsim.scenario.BearingGeometry` (SI).
    op : :class:`bearingsim.scenario.OperatingPoint` (SI).
    restitution : roller-cage coefficient of restitution e [-].
    cage_friction : roller-cage Coulomb friction coefficient [-].
    extent : angular extent ``(psi_in, psi_out)`` of each arc face from the circumferential direction [rad].
    n_seg : segments per arc face; 0: exact arc faces (one tangent segment each, placed by the step loop).
    kinematic_cage : cage turned at the epicyclic speed (reduced-equivalent scene) instead of free.
    spin_free : rollers may change their spin (False: infinite moment of inertia).
    spatial_hash : use pymunk's spatial-hash broadphase (faster than the default tree here).
    flat_pockets : indices of the pockets with flat faces (one segment each).
    centred_cage : hold the (free) cage's centre on the bearing axis with a pivot joint to the static
        body at (0, 0); it still turns freely under its contact torques (the ``centred_cage`` scene).
    rigid_radius : rigid raceways (``multibody.raceway_contact = "rigid"``): hold each roller on the
        outer race with a unilateral joint, centre at most this far from the axis [m] (a
        ``pymunk.SlideJoint`` from 0 to ``rigid_radius`` to a static anchor at the axis). pymunk solves it
        with the roller-cage contacts, so a cage pushing a roller outward meets the raceway in the same
        step; a roller pulled inward leaves it.
    worn : (n, 2, bins) worn depth of each pocket's (front, rear) face [m], or None. Arc faces take it in
        the step loop (:func:`bearingsim.multibody.loop.worn_contact`); a flat face is moved outwards by
        its mean worn depth (a plane stays a plane: a uniform shift).
    """
    n = geometry.roller_count
    R = geometry.roller_radius + 0.5 * geometry.pocket_clearance
    sign = op.sign
    space = _space(op, R, n, n_seg, spatial_hash)
    a = pocket_angles(n, sign)
    omega_cage = sign * op.omega_c
    exact = n_seg == 0
    n_seg = max(n_seg, 1)  # an exact face is one segment
    bits_each = own_bits(n_seg)
    all_faces = sum(segment_bit(f, k, n_seg) for f in (0, 1) for k in range(n_seg)) if bits_each else CAGE_CATEGORY
    rollers = _add_rollers(space, geometry, op, a, restitution, cage_friction, spin_free,
                           pymunk.ShapeFilter(categories=ROLLER_CATEGORY, mask=all_faces))
    if kinematic_cage:
        cage = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    else:
        cage = pymunk.Body(geometry.cage_mass, geometry.cage_inertia)
    cage.position = (0.0, 0.0)
    cage.angle = 0.0
    cage.angular_velocity = float(omega_cage)
    faces = _add_faces(space, cage, geometry.pitch_radius, R, a, sign, extent, n_seg, exact, bits_each,
                       set(int(i) for i in flat_pockets), worn)
    joints = _add_joints(space, cage, rollers, centred_cage and not kinematic_cage, rigid_radius)
    ids = np.array([b.id for b in rollers] + [cage.id], dtype=np.uint64)
    verts, seg_ends, seg_bits, centres, arc_shapes = faces
    return Scene(space, rollers, cage, a, R, verts, ids, joints, seg_ends, seg_bits if bits_each else None, centres,
                 arc_shapes if exact else None, tuple(float(x) for x in extent))


def _space(op, R: float, n: int, n_seg: int, spatial_hash: bool):
    """An empty pymunk space set for this scale (gravity along -y)."""
    space = pymunk.Space()
    space.gravity = (0.0, -op.gravity)
    space.collision_slop = 1e-8  # m: the default 0.1 is 10 cm at this scale
    space.collision_persistence = 1  # no re-reported cached impulses
    # overlap recovery: pymunk removes 1 - bias^dt of an overlap per step through a pseudo-velocity
    # (split impulse: no kinetic energy is added). The default (0.9^60 per second) removes 2.5e-5 of it
    # per step at dt = 4 us, so overlaps never heal; and the fast-spinning cage is rotated exactly while
    # the contact constraint is linearised, which drifts rollers into the slanted guidance segments by
    # ~r (omega_c dt)^2 / 2 per step (0.3 um at 20000 rpm). bias = 0 removes the overlap in one step.
    space.collision_bias = 0.0
    space.iterations = 10
    if spatial_hash:
        space.use_spatial_hash(2.0 * R, 4 * n * (n_seg + 1))
    return space


def _add_rollers(space, geometry, op, a, restitution, cage_friction, spin_free, roller_filter) -> list:
    """The rollers at their pocket centres (angles ``a``), moving with the cage and spinning as in pure
    rolling, added to ``space``."""
    rp = geometry.pitch_radius
    omega_cage = op.sign * op.omega_c
    spin = op.sign * (op.omega_c - op.omega_r)  # absolute roller spin in pure rolling, Eq. (11)-(12)
    rollers = []
    for i in range(geometry.roller_count):
        moment = geometry.roller_inertia if spin_free else float("inf")
        b = pymunk.Body(geometry.roller_mass, moment)
        c = np.array([rp * math.cos(a[i]), rp * math.sin(a[i])])
        b.position = (float(c[0]), float(c[1]))
        b.velocity = (float(-omega_cage * c[1]), float(omega_cage * c[0]))
        b.angular_velocity = float(spin)
        shape = pymunk.Circle(b, geometry.roller_radius)
        shape.elasticity = restitution
        shape.friction = cage_friction
        shape.filter = roller_filter
        space.add(b, shape)
        rollers.append(b)
    return rollers


def _add_faces(space, cage, rp, R, a, sign, extent, n_seg, exact, bits_each, flat, worn):
    """Every pocket's front and rear face as segments of ``cage`` (flat, exact tangent or polyline), added
    to ``space`` with the cage (``worn``: see :func:`build_scene`). Returns (vertices, segment ends, segment bits, pocket centres, exact faces'
    segments)."""
    n = len(a)
    verts = []
    shapes = []
    seg_ends = np.zeros((n, 2 * n_seg, 4))
    seg_bits = np.zeros((n, 2 * n_seg), dtype=np.uint32)
    centres = np.zeros((n, 2))
    arc_shapes = [[None, None] for _ in range(n)]  # exact faces: each arc pocket's (front, rear) segment
    for i in range(n):
        c = np.array([rp * math.cos(a[i]), rp * math.sin(a[i])])
        centres[i] = c
        e_r = np.array([math.cos(a[i]), math.sin(a[i])])
        e_t = sign * np.array([-math.sin(a[i]), math.cos(a[i])])
        verts.append([])
        for f, direction in enumerate((e_t, -e_t)):  # front, rear
            if i in flat:
                off = R + (float(np.mean(worn[i, f])) if worn is not None else 0.0)
                pts = np.array([c + off * direction - R * e_r, c + off * direction + R * e_r])
            elif exact:
                pts = face_tangent(c, direction, e_r, R, extent)
            else:
                pts = face_polyline(c, direction, e_r, R, extent, n_seg)
            verts[i].append(pts)
            for k in range(len(pts) - 1):
                seg = pymunk.Segment(cage, tuple(pts[k]), tuple(pts[k + 1]), 0.0)
                if exact and i not in flat:
                    arc_shapes[i][f] = seg
                seg.elasticity = 1.0
                seg.friction = 1.0
                bit = segment_bit(f, k, n_seg) if bits_each else CAGE_CATEGORY
                seg.filter = pymunk.ShapeFilter(categories=bit, mask=ROLLER_CATEGORY)
                seg_ends[i, f * n_seg + k] = (*pts[k], *pts[k + 1])
                seg_bits[i, f * n_seg + k] = bit
                shapes.append(seg)
    space.add(cage, *shapes)
    return verts, seg_ends, seg_bits, centres, arc_shapes


def _add_joints(space, cage, rollers, centred: bool, rigid_radius) -> list:
    """The centred cage's pivot and the rigid raceways' slide joints (returned), added to ``space``."""
    if centred:
        # a static anchor of its own, not added to the space: the space's own static_body would be
        # added to its bodies, and the batched body read expects rollers and cage only
        anchor = pymunk.Body(body_type=pymunk.Body.STATIC)
        pivot = pymunk.PivotJoint(anchor, cage, (0.0, 0.0), (0.0, 0.0))
        # correct any drift of the centre within one step (like collision_bias = 0 above); the joint
        # applies a force through the cage centre only, so it adds no torque about it
        pivot.error_bias = 0.0
        space.add(pivot)
    joints = []
    if rigid_radius is not None:
        anchor = pymunk.Body(body_type=pymunk.Body.STATIC)  # not added to the space (as the pivot's)
        for b in rollers:
            j = pymunk.SlideJoint(anchor, b, (0.0, 0.0), (0.0, 0.0), 0.0, float(rigid_radius))
            j.error_bias = 0.0  # a roller outside the circle is put back within one step
            joints.append(j)
        space.add(*joints)
    return joints
