"""The pocket faces of the multi-pocket model against their geometry (docs/geometry.md).

An arc pocket face is the arc of the pocket circle (centre c on the pitch circle, radius R = r + s/2)
over psi in [psi_in, psi_out] from the circumferential direction. The contact of a roller (centre c + d,
radius r) with it is that of two circles: normal d / |d|, gap s/2 - |d|, while the direction of d lies
within the face's extent; past its end, the roller meets the arc's end point. These tests check the
exact faces (``multibody.pocket_face_segments = 0``, the default) against those formulas, the extent
against the cage wall, and what depends on them.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from bearingsim import laws
from bearingsim.multibody import loop as lp
from bearingsim.multibody.core import arc_faces
from bearingsim.multibody.core import run
from bearingsim.multibody.scene import build_scene
from bearingsim.scenario import load_scenario
from tests.conftest import SCENARIOS, si
from tests.test_cli import assert_user_error, bearingsim

MB = SCENARIOS / "multibody_3000rpm.toml"


def _scene(extent=(-math.radians(33.0), math.radians(26.0)), sign=1):
    """The reference bearing's scene with exact faces, cage at rest at angle 0, no gravity."""
    p = si(load_scenario(MB, [f"operating.direction={'forward' if sign > 0 else 'reverse'}"]))
    sc = build_scene(p.bearing, p.operating, 0.8, 0.1, extent=extent, n_seg=0, kinematic_cage=False,
                     spin_free=True)
    return p, sc


def _place(p, sc, i, d, worn=None, ends_out=None):
    """Put roller ``i`` at pocket centre + d (cage at rest at angle 0: cage frame = world frame), place
    the exact faces as the step loop does (``h`` = 0: positions as they are) and return the pymunk
    contact of the roller with each of its two faces, (front, rear), None where they do not touch.
    ``worn``: (n, 2, bins) worn depth of the (front, rear) faces [m]; ``ends_out``: receives the placed
    segments (n, 2, 4)."""
    n = p.bearing.roller_count
    state = np.zeros((n + 1, 6))
    for k, b in enumerate(sc.rollers):
        b.position = tuple(sc.pocket_centres[k])
        state[k, 0:2] = sc.pocket_centres[k]
    state[i, 0:2] = sc.pocket_centres[i] + np.asarray(d)
    sc.rollers[i].position = tuple(state[i, 0:2])
    af = arc_faces(sc, p.bearing.roller_radius, p.operating.sign, worn)._replace(near2=0.0)
    ends = np.zeros((n, 2, 4)) if ends_out is None else ends_out
    todo = np.zeros((n, 2), dtype=np.bool_)
    lp.arc_faces(state, 0.0, af, ends, todo)
    roller = next(iter(sc.rollers[i].shapes))
    out = []
    for f in range(2):
        seg = sc.arc_shapes[i][f]
        seg.unsafe_set_endpoints(tuple(ends[i, f, 0:2]), tuple(ends[i, f, 2:4]))
        sc.cage.position = sc.cage.position  # refresh the cached transforms of the cage's shapes
        seg.cache_bb()
        roller.cache_bb()
        try:
            cps = roller.shapes_collide(seg)
        except AssertionError:  # pymunk 7 asserts on a point set of 0 points: no contact
            cps = None
        out.append(cps if cps is not None and cps.points else None)
    return out


def _frame(p, sc, i, face):
    """(u, e_r) of pocket ``i``'s face: u along the face's middle (+-e_t), e_r outward."""
    a = sc.pocket_body_angle[i]
    e_r = np.array([math.cos(a), math.sin(a)])
    e_t = p.operating.sign * np.array([-math.sin(a), math.cos(a)])
    return (e_t if face == 0 else -e_t), e_r


@pytest.mark.slow
@pytest.mark.parametrize("sign", [1, -1])
@pytest.mark.parametrize("psi_deg", [0.0, 10.0, -20.0, 25.0, -32.0])
@pytest.mark.parametrize("face", [0, 1])
def test_exact_face_contact_is_the_circle_s(psi_deg, face, sign):
    """A roller pressed 1 um into a face at angle psi within the extent: pymunk's contact has the normal
    d/|d| and the depth |d| - s/2 of two circles, to rounding (1e-12 in the normal, 1e-15 m in the
    depth: the arithmetic of a few products of numbers of order 1e-2 m), for both faces, several angles
    and both directions of rotation; the other face is not touched."""
    p, sc = _scene(sign=sign)
    R = sc.pocket_radius
    half_s = 0.5 * p.bearing.pocket_clearance
    i = 3
    u, e_r = _frame(p, sc, i, face)
    psi = math.radians(psi_deg)
    direction = math.cos(psi) * u + math.sin(psi) * e_r
    depth = 1e-6
    got = _place(p, sc, i, (half_s + depth) * direction)
    cps = got[face]
    assert cps is not None and got[1 - face] is None
    assert len(cps.points) == 1
    # pymunk's normal points from the roller (shape a) to the face (shape b): along d
    assert np.allclose(np.array(cps.normal), direction, atol=1e-12, rtol=0.0)
    assert -cps.points[0].distance == pytest.approx(depth, abs=1e-15)
    assert R - p.bearing.roller_radius == pytest.approx(half_s, rel=1e-12, abs=0)


@pytest.mark.parametrize("face", [0, 1])
@pytest.mark.parametrize("end", ["in", "out"])
def test_a_roller_past_the_face_s_end_meets_its_edge(face, end):
    """A roller whose direction lies 8 deg past a face's end touches the arc's end point (a corner): the
    normal runs from the roller's centre to that point, the depth is r - |P - q|; a roller short of
    that distance touches nothing."""
    p, sc = _scene()
    R, r = sc.pocket_radius, p.bearing.roller_radius
    lo, hi = sc.extent
    i = 5
    u, e_r = _frame(p, sc, i, face)
    psi_end = lo if end == "in" else hi
    psi = psi_end + (math.radians(-8.0) if end == "in" else math.radians(8.0))
    corner = R * (math.cos(psi_end) * u + math.sin(psi_end) * e_r)  # from the pocket centre
    direction = math.cos(psi) * u + math.sin(psi) * e_r
    # the offset at which the roller's circle reaches the corner: |corner - t direction| = r
    b = corner @ direction
    t_touch = b - math.sqrt(b * b - (corner @ corner - r * r))
    for t, touches in ((t_touch + 1e-6, True), (t_touch - 1e-6, False)):
        got = _place(p, sc, i, t * direction)
        assert (got[face] is not None) == touches, (t, got)
        if touches:
            q = t * direction
            want_n = (corner - q) / np.linalg.norm(corner - q)
            assert np.allclose(np.array(got[face].normal), want_n, atol=1e-9, rtol=0.0)
            assert -got[face].points[0].distance == pytest.approx(r - np.linalg.norm(corner - q), abs=1e-14)


def test_face_extent_is_the_cage_wall_s():
    """By default each face spans what the cage ring allows: its end points lie on the cage's inner and
    outer cylinders (the preset's 91 / 104 mm), to rounding; the extent is wider inside the pitch circle
    (ring curvature): -32.9 / +26.2 deg for the reference bearing."""
    p = si(load_scenario(MB))
    lo, hi = p.multibody.pocket_face_extent
    g = p.bearing
    R = g.roller_radius + 0.5 * g.pocket_clearance
    for psi, r_wall in ((lo, g.cage_inner_radius), (hi, g.cage_outer_radius)):
        end = np.array([0.0, g.pitch_radius]) + R * np.array([math.cos(psi), math.sin(psi)])  # e_t = x, e_r = y
        assert np.linalg.norm(end) == pytest.approx(r_wall, rel=1e-12, abs=0)
    assert math.degrees(lo) == pytest.approx(-32.94, abs=0.01) and math.degrees(hi) == pytest.approx(26.18, abs=0.01)
    assert p.multibody.pocket_face_rule == "cage wall"
    given = si(load_scenario(MB, ["multibody.pocket_face_half_angle_deg=20"]))
    assert given.multibody.pocket_face_extent == pytest.approx((-math.radians(20), math.radians(20)))
    assert laws.pocket_face_extent(0.05, 0.006, 0.03, 0.07) == (-math.pi / 2, math.pi / 2)  # a wall beyond the pocket


@pytest.mark.slow
def test_a_face_wider_than_the_wall_is_refused(tmp_path):
    """A half angle past the cage wall's outer end (26.2 deg) is a user error naming the key, one line,
    nothing written; 'auto' without the cage's diameters names the missing one."""
    res = bearingsim("run", MB, "--set", "multibody.pocket_face_half_angle_deg=30", "-o", tmp_path / "x.h5")
    assert_user_error(res, "multibody.pocket_face_half_angle_deg")
    assert "26.2" in res.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
@pytest.mark.parametrize("segments", [0, 3, 9])
def test_land_contact_does_not_depend_on_the_faces(segments):
    """An outer-land-guided cage rides on its land whatever the faces are drawn with: exact faces and
    polylines of 3 and 9 segments all give a land normal impulse of the order of the cage's weight and
    the rollers' pushes, where a cage off its land has none.

    Scale: the cage's weight over the rotation, m g T = 0.2 kg x 9.807 m/s^2 x 46.15 ms (3000 rpm, cage at
    136.1 rad/s) = 0.0905 N s; the rollers push the cage onto its land too (without gravity the exact
    faces give 0.115 N s). Measured as here (1 warm-up + 1 rotation) over 8 trajectories differing only
    in the last bits of the load (operating.radial_load_N = 970 + k * 0.00000097, k = 0..7; mean +- std,
    lowest): exact faces 0.1219 +- 0.0016 (0.1192), 3 segments 0.1558 +- 0.0028 (0.1522), 9 segments
    0.1328 +- 0.0016 (0.1296) N s. Bound 0.11 N s (about 1.2 m g T): 7 std below the exact faces' mean, the
    lowest kind (0.1 N s, reasoned, before). The kinds do not agree within their scatter (the 3-segment
    polyline is 28 % above the exact faces, 12 std): its slanted segments push the rollers radially at
    the wrong angle (docs/geometry.md), which changes how hard, not whether, the land carries the cage.
    Can fail: a diametral land clearance of 0.6 mm (bearing.cage_land_clearance_mm; half of it, 0.3 mm, beyond
    the ~0.23 mm the rollers let the cage move) leaves the cage on its rollers, land impulse 0.0 with each kind."""
    sc = load_scenario(MB, ["bearing.cage_guidance=outer_land", f"multibody.pocket_face_segments={segments}",
                            "numerics.rotations=1", "numerics.warmup_rotations=1"])
    raw = run(si(sc))
    assert raw.land is not None
    assert raw.land["win"][:, 0].min() > 0.11


@pytest.mark.slow
def test_exact_faces_reach_the_fine_polyline_s_limit():
    """The circumscribed polyline converges to the exact arc as its segments shrink: over the same two
    rotations at 3000 rpm the exact faces' I_dec is nearer a 15-segment polyline's than the 3-segment
    polyline is, and lies where the converged series puts it against the 15-segment one.

    docs/geometry.md measures 3 to 63 segments over 30 rotations: 17 segments +2.8 % above the exact
    faces, shrinking as 1/N^2, so 15 segments ~ +2.8 % x (17/15)^2 = +3.6 %: exact / 15-segment - 1 ~
    -3.5 %. Over two rotations, measured as here over 16 trajectories differing only in the last bits
    of the load (operating.radial_load_N = 970 + k * 0.00000097, k = 0..15, each with the three runs):
    exact / 15-segment - 1 = -3.7 % +- 1.7 % (mean +- std; -6.1 .. +0.2 %), the series' value within
    its standard error (0.4 %). Window -3.5 % +- 7 % (4 std): the 10 % either side this test had lay 3.7
    std below the mean, so the low side moves out by 0.5 points, and 8 std above it: the high side is
    tightened to +3.5 %: a 9-segment polyline in the exact faces' place (+7.5 % +- 2.2 % over 15 segments,
    8 trajectories measured the same way) fails it in 7 of 8 trajectories, where +10 % let it pass in all.
    The 3-segment polyline gives +57 % +- 2.5 % (lowest +51 %) over the 15-segment one and fails both
    checks."""
    res = {}
    for n_seg in (0, 3, 15):
        sc = load_scenario(MB, [f"multibody.pocket_face_segments={n_seg}", "numerics.rotations=2"])
        res[n_seg] = float(run(si(sc)).win["I_dec"].sum())
    assert abs(res[0] - res[15]) < abs(res[3] - res[15])
    assert res[0] / res[15] - 1 == pytest.approx(-0.035, abs=0.07)


def test_one_segment_faces_on_a_roller_guided_cage_are_refused_before_the_run(tmp_path):
    """One straight segment per arc face (``multibody.pocket_face_segments = 1``), tangent at the extent's
    middle (psi = -3.38 deg on the reference cage), closes on a roller only 0.1 mm / sin 3.38 deg = 1.70 mm
    inward of its pocket centre and never outward: a roller-guided cage drifted there (measured: 1.74 mm off
    the axis at t = 18.4 ms) and wedged a roller between the faces, which stopped the main job with exit 3 and
    ever shorter steps advised (overlap 2.15 um at 1.03 us, 2.13 um at 0.70 us). It is refused before the run,
    naming the key (``--dry-run`` too); two segments, and a land-guided or centred cage with one, still run."""
    main = SCENARIOS / "multibody_6000rpm.toml"
    sets = ["--set", "numerics.rotations=2", "--set", "multibody.pocket_face_segments=1"]
    for extra in ([], ["--dry-run"]):
        res = bearingsim("run", main, "-q", "--no-plots", "-o", tmp_path / "r.h5", *sets, *extra)
        assert_user_error(res, "multibody.pocket_face_segments = 1", "1.7 mm inward", "2 or more segments")
        assert list(tmp_path.iterdir()) == []
    from bearingsim.simulation import check_run

    for ok in (["multibody.pocket_face_segments=2"],
               ["multibody.pocket_face_segments=1", "bearing.cage_guidance=outer_land"],
               ["multibody.pocket_face_segments=1", "multibody.scene=centred_cage"]):
        check_run(load_scenario(main, ok))


# --- worn faces ---------------------------------------------------------------------------------------
def _worn(n, face, i, row):
    """(n, 2, bins) worn depth: ``row`` [m] on face ``face`` (0 front, 1 rear) of pocket ``i``, else 0."""
    w = np.zeros((n, 2, len(row)))
    w[i, face] = row
    return w


@pytest.mark.parametrize("sign", [1, -1])
def test_a_cage_bar_carries_one_pockets_front_face_and_its_neighbours_rear_face(sign):
    """The bar between pockets i - 1 and i carries pocket i's front face and pocket i - 1's rear face, in
    either direction of rotation: the pocket centre nearest to the middle of pocket i's front face (as the
    scene builds it) is pocket i - 1's, to its rear face pocket i + 1's; the two faces' points at the same
    psi lie at the same distance from the cage's axis (their bins of one index face each other across the
    bar); and laws.worn_bar_depth sums exactly those. The cage-bar checks summed the deepest front and the
    deepest rear depth of any pockets and bins, as if a pocket's two faces lay on one bar."""
    p, sc = _scene(sign=sign)
    n = p.bearing.roller_count
    af = arc_faces(sc, p.bearing.roller_radius, p.operating.sign)
    centres = np.asarray(sc.pocket_centres)
    for i in range(n):
        for f, neighbour in ((0, (i - 1) % n), (1, (i + 1) % n)):
            seg = sc.arc_shapes[i][f]
            middle = 0.5 * (np.array(seg.a) + np.array(seg.b))
            others = [k for k in range(n) if k != i]
            assert min(others, key=lambda k: np.linalg.norm(centres[k] - middle)) == neighbour, (i, f)
        j = (i - 1) % n
        for psi in np.radians([-32.0, -10.0, 0.0, 12.0, 26.0]):
            front = centres[i] + af.radius * (math.cos(psi) * af.e_t[i] + math.sin(psi) * af.e_r[i])
            rear = centres[j] + af.radius * (-math.cos(psi) * af.e_t[j] + math.sin(psi) * af.e_r[j])
            assert np.linalg.norm(front) == pytest.approx(np.linalg.norm(rear), rel=1e-12, abs=0)
    bins = 4
    front, rear = np.zeros((bins, n)), np.zeros((bins, n))
    front[1, 5], rear[1, 4], rear[2, 5] = 2.0, 3.0, 7.0
    on_bar = laws.worn_bar_depth(front, rear)
    assert on_bar[1, 5] == 5.0 and on_bar[2, 6] == 7.0 and on_bar.sum() == 12.0


@pytest.mark.parametrize("sign", [1, -1])
@pytest.mark.parametrize("face", [0, 1])
@pytest.mark.parametrize("psi_deg", [0.0, 15.0, -25.0])
def test_a_uniformly_worn_face_moves_the_contact_outwards_by_w(face, psi_deg, sign):
    """A face worn uniformly by w = 30 um is the pocket circle of radius R + w on that face: a roller at
    angle psi pressed 1 um into it has pymunk's contact with normal d/|d| and depth |d| - (s/2 + w)
    (the same rounding tolerances as the unworn face's test: 1e-12, 1e-15 m); at |d| = s/2 + w - 1 um,
    where it would be 29 um into the unworn face, it touches nothing; the other face is not touched. In
    either direction of rotation (``sign``): the front face is the one ahead in the cage's motion."""
    p, sc = _scene(sign=sign)
    n, i, w = p.bearing.roller_count, 3, 30e-6
    half_s = 0.5 * p.bearing.pocket_clearance
    u, e_r = _frame(p, sc, i, face)
    psi = math.radians(psi_deg)
    direction = math.cos(psi) * u + math.sin(psi) * e_r
    worn = _worn(n, face, i, np.full(32, w))
    got = _place(p, sc, i, (half_s + w + 1e-6) * direction, worn)
    cps = got[face]
    assert cps is not None and got[1 - face] is None and len(cps.points) == 1
    assert np.allclose(np.array(cps.normal), direction, atol=1e-12, rtol=0.0)
    assert -cps.points[0].distance == pytest.approx(1e-6, abs=1e-15)
    assert _place(p, sc, i, (half_s + w - 1e-6) * direction, worn) == [None, None]


def test_a_worn_profile_puts_the_contact_on_the_nearest_worn_line():
    """A face with a worn profile w(psi) (a groove 40 um deep around psi = -10 deg, 5 um at the middle,
    linear between bin centres): the roller touches the face's tangent line nearest to it, the support
    line h(psi) = R + w(psi) minimising g(psi) = h(psi) - d . u(psi). Checked against a brute-force
    minimum of g over 200001 angles of the extent (its grid error, rho dpsi^2 / 2 with rho <= 0.2 mm and
    dpsi = 5e-6 rad, is below 1e-14 m; 1e-12 m allowed): the placed segment's distance from the roller's
    centre is that minimum and its normal the direction of the minimising psi (1e-6 rad: the brute-force
    grid's spacing), for roller directions on and off the groove."""
    p, sc = _scene()
    n, i, face = p.bearing.roller_count, 6, 1
    lo, hi = sc.extent
    R, half_s = sc.pocket_radius, 0.5 * p.bearing.pocket_clearance
    centres = lo + (hi - lo) * (np.arange(32) + 0.5) / 32
    row = 5e-6 + 35e-6 * np.exp(-((centres - math.radians(-10.0)) / math.radians(4.0)) ** 2)
    worn = _worn(n, face, i, row)
    u, e_r = _frame(p, sc, i, face)
    grid = np.linspace(lo, hi, 200001)
    h = R + np.interp(grid, centres, row)  # constant beyond the end bins' centres, as the step loop
    for psi_deg, rho in ((0.0, half_s), (-10.0, half_s + 30e-6), (-4.0, half_s + 20e-6), (20.0, 0.6 * half_s)):
        psi = math.radians(psi_deg)
        d = rho * (math.cos(psi) * u + math.sin(psi) * e_r)
        ends = np.zeros((n, 2, 4))
        _place(p, sc, i, d, worn, ends)
        a, b = ends[i, face, 0:2] - sc.pocket_centres[i], ends[i, face, 2:4] - sc.pocket_centres[i]
        t = (b - a) / np.linalg.norm(b - a)
        normal = np.array([t[1], -t[0]])
        normal = normal if normal @ a > 0 else -normal  # outward, from the pocket centre
        g = h - rho * np.cos(grid - psi)  # d . u(psi') = rho cos(psi' - psi)
        k = int(np.argmin(g))
        assert (a - d) @ normal == pytest.approx(g[k], abs=1e-12)
        assert a @ normal == pytest.approx(h[k], abs=1e-12)
        got_psi = math.atan2(normal @ e_r, normal @ u)
        assert got_psi == pytest.approx(grid[k], abs=1e-6)


#: mean worn depth [um] over the 16 pockets of the front and rear faces at stage 5 of the rigid-raceway life
#: study with the shape fed back (docs/wear.md; tests/data/worn_stage05_rigid.toml is that stage's scenario):
#: deepest at the faces' edges, a few um elsewhere
STAGE05_FRONT_UM = [25.2, 4.6, 3.3, 2.9, 3.0, 2.1, 1.8, 1.6, 1.5, 1.6, 1.2, 1.3, 1.1, 1.2, 1.1, 1.0, 0.9, 1.0, 0.9,
                    0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.2, 0.1, 0.1, 0.1, 0.1, 11.2]
STAGE05_REAR_UM = [44.8, 2.9, 1.0, 0.3, 0.2, 0.2, 0.2, 0.2, 0.2, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3,
                   0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.3, 0.7, 2.1, 18.7]


def _worn_material(R, lo, hi, row):
    """Brute force, independent of the step loop: the worn face's material near a roller. The pocket is the
    set K of points p with p . u(psi) <= h(psi) = R + w(psi) for every psi of the extent (w linear between
    the bin centres of ``row`` [m], constant in the end half bins); the face's material is what lies
    outside K within the extent's sector. Returns ``(nearest, radius)``: ``nearest(d, coarse_only=False)``,
    (distance [m], point) of the material nearest to d (face frame, x along the face's middle, y outward),
    from ``radius(theta)``, the polar radius of K, ``min over psi of h(psi) / cos(theta - psi)`` over a grid
    of psi (the knots and 4001 angles), sampled over theta and refined around the coarse minima, and the
    rays of the extent beyond K."""
    centres = lo + (hi - lo) * (np.arange(len(row)) + 0.5) / len(row)
    psi = np.union1d(np.linspace(lo, hi, 4001), np.concatenate([[lo, hi], centres]))
    h = R + np.interp(psi, centres, row)

    def radius(theta):
        out = np.full(theta.shape, np.inf)
        for k in range(0, len(psi), 1000):
            c = np.cos(theta[None, :] - psi[k:k + 1000, None])
            out = np.minimum(out, (h[k:k + 1000, None] / c).min(axis=0))
        return out

    coarse = np.linspace(lo, hi, 2001)
    r_coarse = radius(coarse)
    pts = np.stack([r_coarse * np.cos(coarse), r_coarse * np.sin(coarse)], axis=1)
    rays = [r_coarse[k] + np.linspace(0.0, 1e-3, 1001) for k in (0, -1)]
    walls = np.concatenate([np.stack([t * math.cos(e), t * math.sin(e)], axis=1) for t, e in zip(rays, (lo, hi))])

    def nearest(d, coarse_only=False):
        dist = np.hypot(pts[:, 0] - d[0], pts[:, 1] - d[1])
        wall = np.hypot(walls[:, 0] - d[0], walls[:, 1] - d[1])
        best = (wall.min(), walls[int(np.argmin(wall))])
        if coarse_only:
            k = int(np.argmin(dist))
            return min(best, (dist[k], pts[k]), key=lambda x: x[0])
        step = coarse[1] - coarse[0]
        low = (dist <= np.roll(dist, 1)) & (dist <= np.roll(dist, -1))  # the coarse grid's local minima ...
        for k in np.flatnonzero(low & (dist <= dist.min() + 2e-8)):  # ... near the least (grid error ~1e-10 m)
            theta = np.linspace(max(lo, coarse[k] - 2 * step), min(hi, coarse[k] + 2 * step), 801)
            r = radius(theta)
            p = np.stack([r * np.cos(theta), r * np.sin(theta)], axis=1)
            dd = np.hypot(p[:, 0] - d[0], p[:, 1] - d[1])
            j = int(np.argmin(dd))
            best = min(best, (dd[j], p[j]), key=lambda x: x[0])
        return best

    return nearest, radius


@pytest.mark.slow
@pytest.mark.parametrize("face", [0, 1])
def test_a_worn_face_s_contact_is_the_nearest_point_of_its_material(face):
    """A worn face (the measured stage-5 profile: its edges 11-45 um deep, a few um elsewhere): a roller
    moved 1 um further than where it reaches the face's material, in directions within the extent, near its
    ends and past them (where the roller-guided cage holds its rollers: a roller 243 um off its pocket centre
    88 deg from the face's middle, as traced in the run of tests/data/worn_stage05_rigid.toml; 90-110 deg:
    the roller on the worn edge), has pymunk's contact at the
    point of the material nearest to its centre: depth from the brute force of :func:`_worn_material` to
    1e-10 m (the polar radius's grid error, R dpsi^2 / 8 = 6e-11 m), normal from the roller's centre to that
    point: pymunk's contact point lies on the material's boundary (its polar radius, 1e-10 m) at the
    brute-force least distance from the roller's centre (1e-10 m), and the normal runs from the centre to
    it (1e-9). (The point itself is ill-conditioned: a roller nearly as curved as the face it rests in has
    a distance that changes with the point's place along the face only to second order, 2.3 /m; hence
    these checks rather than a comparison of points.) 1 um short of it, no contact.
    The worn face's edge is where its boundary meets the extent's ray, not the end bin's line: the end
    bin's line runs beyond the material there."""
    p, sc = _scene()
    n, i = p.bearing.roller_count, 4
    lo, hi = sc.extent
    R, r = sc.pocket_radius, p.bearing.roller_radius
    row = 1e-6 * np.array(STAGE05_FRONT_UM if face == 0 else STAGE05_REAR_UM)
    worn = _worn(n, face, i, row)
    u, e_r = _frame(p, sc, i, face)
    nearest, radius = _worn_material(R, lo, hi, row)
    for phi_deg in (100.0, 95.0, 90.0, 88.4, 60.0, 28.0, 25.5, 10.0, -10.0, -31.5, -34.0, -50.0, -90.0, -110.0):
        phi = math.radians(phi_deg)
        direction = np.array([math.cos(phi), math.sin(phi)])
        a, b = 0.0, 1e-3  # the offset at which the roller reaches the material (coarse), by bisection
        for _ in range(60):
            m = 0.5 * (a + b)
            a, b = (m, b) if nearest(m * direction, coarse_only=True)[0] > r else (a, m)
        for shift, touches in ((1e-6, True), (-1e-6, False)):
            d = (a + shift) * direction
            dist, point = nearest(d)
            # (at 100 deg, 0.44 mm off its pocket centre, the roller meets the other face too)
            got = _place(p, sc, i, d[0] * u + d[1] * e_r, worn)
            assert (got[face] is not None) == touches, (phi_deg, shift, dist - r)
            if touches:
                cp = got[face].points[0]
                assert cp.distance == pytest.approx(dist - r, abs=1e-10), phi_deg
                q = np.array(cp.point_b) - sc.pocket_centres[i]
                q = np.array([q @ u, q @ e_r])  # pymunk's contact point on the face, face frame
                assert np.linalg.norm(q - d) == pytest.approx(dist, abs=1e-10), phi_deg
                theta = np.array([math.atan2(q[1], q[0])])
                assert np.linalg.norm(q) == pytest.approx(radius(theta)[0], abs=1e-10), phi_deg
                normal = np.array(got[face].normal)
                want = (q - d) / np.linalg.norm(q - d)
                assert normal @ u == pytest.approx(want[0], abs=1e-9)
                assert normal @ e_r == pytest.approx(want[1], abs=1e-9)


@pytest.mark.slow
def test_a_run_on_worn_faces_stays_within_the_overlap_bound():
    """The rigid-raceway wear-test scene with the worn faces of a life study's stage 5
    (tests/data/worn_stage05_rigid.toml: 1 warm-up + 3 rotations at the automatic step, 1.32e-5 s over the
    worn play): no roller
    overlaps a face by more than 1 % of s (run raises PenetrationExceeded beyond). With the worn faces'
    edges not taken as contacts, a roller resting past the outer end of pocket 3's front face sank unseen
    into the face's material for 17 steps and was found 2.68 um deep at t = 0.068 s, moving at 0.012 m/s;
    the deepest overlap is now an impact (over 0.1 m/s), which the automatic step keeps within 0.8 % of s."""
    p = si(load_scenario(SCENARIOS.parent / "tests" / "data" / "worn_stage05_rigid.toml"))
    raw = run(p)
    g = raw.glob
    assert g["maxpen_all"] <= 0.01 * p.bearing.pocket_clearance
    assert g["maxpen_approach"] > 0.1


def _worn_scenario(base, front, rear):
    """``base`` with ``front`` / ``rear`` ((n, 32) [m]) as its worn depth."""
    um = lambda w: [[float(x * 1e6) for x in row] for row in w]  # noqa: E731
    return base.replace(**{"wear.worn_depth_front_um": um(front), "wear.worn_depth_rear_um": um(rear)})


def test_the_automatic_step_takes_the_play_worn_faces_leave():
    """Pocket 3's front face worn uniformly by 40 um, its rear by 25 um: they are the circle of radius R + w
    (test above), so a roller crosses s + 65 um there, and the automatic step's impact speed is that of a
    free flight across it, v = sqrt(2 a L) (docs/fast_scene.md, *Time step*; docs/wear.md, *Worn faces*):
    with the bound still 1 % of s, the rigid scene's step, and the Hertz scene's impact resolution, are the
    unworn ones times sqrt(s / L) (1e-12: rounding), and the rigid start phase's fall is across L too. The
    Hertz scene's step stays its stability limit (the impact resolution is longer). ``dt_choice`` says so."""
    from bearingsim.multibody.core import choose_dt, impact_dt, rigid_start, worn_play

    base = load_scenario(SCENARIOS / "wear_test_6000rpm.toml", ["multibody.raceway_contact=rigid"])
    n = base.bearing.roller_count
    front, rear = np.zeros((n, 32)), np.zeros((n, 32))
    front[3], rear[3] = 40e-6, 25e-6
    p0, p = si(base), si(_worn_scenario(base, front, rear))
    s = p.bearing.pocket_clearance
    play, pocket = worn_play(p)
    assert worn_play(p0) == (s, None)
    assert pocket == 3 and play == pytest.approx(s + 65e-6, abs=1e-15)
    dt, how, _ = choose_dt(p)
    assert dt == pytest.approx(choose_dt(p0)[0] * math.sqrt(s / play), rel=1e-12, abs=0)
    assert "worn play 0.265 mm" in how and "pocket 3" in how and "worn play" not in choose_dt(p0)[1]
    g = p.operating.gravity
    t_start, dt_start = rigid_start(p, 1.0)
    assert dt_start == pytest.approx(0.005 * s / math.sqrt(2.0 * g * play), rel=1e-12, abs=0)
    e = p.contact.restitution
    assert t_start == pytest.approx(min(math.sqrt(2.0 * play / g) * (1 + e) / (1 - e),
                                        2 * math.pi / p.operating.omega_c), rel=1e-12, abs=0)
    hz0 = si(base.replace(**{"multibody.raceway_contact": "hertz"}))
    hz = si(_worn_scenario(base.replace(**{"multibody.raceway_contact": "hertz"}), front, rear))
    assert impact_dt(hz) == pytest.approx(impact_dt(hz0) * math.sqrt(s / play), rel=1e-12, abs=0)
    assert choose_dt(hz)[0] == choose_dt(hz0)[0] < impact_dt(hz)


def test_the_worn_play_is_the_depth_the_contact_meets():
    """The worn play on the measured stage-5 profile (tests/data/worn_stage05_rigid.toml, every pocket's
    own): s plus the largest, over pockets and directions theta of the extent, of the front and rear
    faces' polar radius less R in the same direction, against a brute force independent of the model: the
    polar radius of the pocket ``min over psi of h(psi) / cos(theta - psi)`` over 4001 angles psi and the
    knots, in 545 directions theta (the knots, the edges and 16 per bin: finer than the knots at which
    ``worn_play`` evaluates it). Tolerance 1e-10 m: the psi grid's error, R dpsi^2 / 8 = 6e-11 m. The end
    bins, up to 50 um deep, are bridged by their neighbours' lines: the play is s + 24.2 um, not s plus the
    deepest bins' front + rear depth (79 um)."""
    from bearingsim.multibody.core import worn_play

    p = si(load_scenario(SCENARIOS.parent / "tests" / "data" / "worn_stage05_rigid.toml"))
    worn = np.array(p.wear.worn_depth)  # (n, 2, 32) [m]
    s, lo, hi = p.bearing.pocket_clearance, *p.multibody.pocket_face_extent
    R = p.bearing.roller_radius + 0.5 * s
    centres = lo + (hi - lo) * (np.arange(32) + 0.5) / 32
    psi = np.union1d(np.linspace(lo, hi, 4001), np.concatenate([[lo, hi], centres]))
    theta = np.union1d(np.linspace(lo, hi, 32 * 16 + 1), np.concatenate([[lo, hi], centres]))
    c = np.cos(theta[None, :] - psi[:, None])
    c = np.where(c > 0.0, c, np.nan)
    extra = np.zeros((worn.shape[0], len(theta)))
    for i in range(worn.shape[0]):
        for f in range(2):
            h = R + np.interp(psi, centres, worn[i, f])
            extra[i] += np.nanmin(h[:, None] / c, axis=0) - R
    play, pocket = worn_play(p)
    assert play == pytest.approx(s + extra.max(), abs=1e-10)
    assert pocket == int(np.argmax(extra.max(axis=1)))
    assert extra.max() < 0.5 * (worn[:, 0] + worn[:, 1]).max()  # the deepest bins are bridged


@pytest.mark.slow
def test_a_run_across_a_grown_play_keeps_its_automatic_step():
    """Stage 8 of the rigid-raceway clearance life with the shape fed back
    (tests/data/worn_stage08_rigid_clearance.toml; the play a roller crosses 0.371 mm): at the automatic
    step taken over the worn play (1.03e-5 s) its roller-cage overlaps stay within the bound, 1 % of s
    (run raises PenetrationExceeded beyond). At the step taken over s alone (1.4e-5 s) a roller met a face
    at 0.17 m/s, 2.3 um deep, at t = 0.047 s, and the run restarted from its start."""
    from bearingsim.multibody.core import choose_dt

    p = si(load_scenario(SCENARIOS.parent / "tests" / "data" / "worn_stage08_rigid_clearance.toml"))
    raw = run(p)
    assert raw.setup.dt == choose_dt(p)[0]
    assert raw.glob["maxpen_all"] <= 0.01 * p.bearing.pocket_clearance


def test_zero_worn_depth_is_the_unworn_run_bit_for_bit():
    """A scenario that gives a worn depth of 0 on every face runs the unworn faces' code (no worn depth
    in its parameters) and gives every summary number and per-rotation array of the run without it, bit
    for bit (fast scene at 6000 rpm, 1 recorded rotation)."""
    from bearingsim import run

    base = load_scenario(SCENARIOS / "wear_test_6000rpm.toml", ["multibody.raceway_contact=rigid",
                                                                "numerics.rotations=1"])
    zero = [[0.0] * 32 for _ in range(base.bearing.roller_count)]
    worn = base.replace(**{"wear.worn_depth_front_um": zero, "wear.worn_depth_rear_um": zero})
    assert si(worn).wear.worn_depth is None
    a, b = run(base), run(worn)
    assert a.summary.keys() == b.summary.keys()
    for k in a.summary:
        assert repr(a.summary[k]) == repr(b.summary[k]), k
    for k in a.per_rotation:
        assert np.array_equal(a.per_rotation[k], b.per_rotation[k], equal_nan=True), k


def test_a_worn_flat_face_is_shifted_by_its_mean_worn_depth():
    """A flat face (the rig's pocket 0) stays a plane: worn, it moves outwards along e_t by the mean of its
    worn-depth row (a uniform shift), to rounding of sums of numbers of order 0.05 m (1e-15 m)."""
    p = si(load_scenario(MB))
    n = p.bearing.roller_count
    worn = np.zeros((n, 2, 32))
    worn[0, 0] = np.linspace(0.0, 40e-6, 32)  # front face, mean 20 um
    worn[0, 1, :4] = 8e-6  # rear face, mean 1 um
    extent = (-math.radians(33.0), math.radians(26.0))
    plain = build_scene(p.bearing, p.operating, 0.8, 0.1, extent=extent, n_seg=0, kinematic_cage=False,
                        spin_free=True, flat_pockets=(0,))
    sc = build_scene(p.bearing, p.operating, 0.8, 0.1, extent=extent, n_seg=0, kinematic_cage=False,
                     spin_free=True, flat_pockets=(0,), worn=worn)
    for f, mean in ((0, 20e-6), (1, 1e-6)):
        u, _ = _frame(p, sc, 0, f)
        moved = sc.face_vertices[0][f] - plain.face_vertices[0][f]
        np.testing.assert_allclose(moved, np.outer([1.0, 1.0], mean * u), rtol=0, atol=1e-15)
    for i in range(1, n):  # arc pockets: their segments are placed by the step loop
        np.testing.assert_array_equal(sc.face_segments[i], plain.face_segments[i])
