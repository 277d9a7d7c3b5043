"""Driver of the multi-pocket model: scene, time step, step loop, recording. SI throughout.

See the package docstring of :mod:`bearingsim.multibody` for the definitions of the recorded
quantities. The step loop per time step ``h``:

1. ``pymunk.batch.get_space_bodies`` -> state ``(x, y, angle, vx, vy, omega)`` of every body;
2. (reduced-equivalent scene) rollers inside the load zone are put at the front of their pockets,
   moving with the cage;
3. one numba kernel (:func:`bearingsim.multibody.forces.raceway_forces`) evaluates the raceway
   forces at the predicted positions, implicitly linearised, and hands them to pymunk in one batch;
4. ``Space.step(h)`` (roller-cage contacts by pymunk);
5. one numba kernel (:func:`bearingsim.multibody.recorder.record_step`) attributes the batch arbiter
   impulses to pockets, faces and rotations into fixed-size accumulators.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np
import pymunk.batch as pb
from numba import njit
from pymunk._chipmunk_cffi import ffi, lib

from bearingsim import kinematics as kin
from bearingsim.errors import SimulationUnstable, UserError
from bearingsim.multibody import forces as fk
from bearingsim.multibody import recorder as rk
from bearingsim.multibody.scene import build_scene

# --- fixed model choices (documented, not tuned) ------------------------------------------------
POCKET_FACE_HALF_ANGLE_DEG = 45.0  # angular half-width of each pocket face arc about e_t
POCKET_FACE_SEGMENTS = 3  # pymunk segments per face (odd: a central segment tangent at e_t)
CONTACT_DAMPING_S = 2.5e-6  # c = c_r k_lin [s]; lower end of the range 0.25e-5..2.5e-5 s of Kraemer (1993) / Sopanen & Mikkola (2003): the normal force is explicit
DAMPING_FADE_M = 5.0e-9  # fade-in depth of the contact damping (continuity of Q at delta = 0)
MIN_ENTRAINMENT_M_S = 0.1  # floor of the entrainment speed in the traction slip ratio
DRAG_DIRECTION_EPS_M_S = 1.0e-3  # regularisation speed of the sign of the drag force
NEWTON_MAX_STEP_M = 2.0e-6  # step limit of the ring-centre Newton iteration
IMPACT_SPEED_THRESHOLD_M_S = 0.01  # approach speed above which a contact step is an impact
THETA_BINS = 360
IMPACT_CAPACITY = 200_000
# automatic dt: fraction of the explicit Hertz stability limit 2/omega_n (the kernel is implicitly
# linearised, so this is an accuracy choice: ~12 steps per contact period)
DT_FRACTION = 0.5
DT_MAX_FACTOR = 2.0  # dt above this multiple of 2/omega_n is refused (UserError); between 1x and 2x a run may still blow up (SimulationUnstable)
IMPACT_OVERLAP_FRACTION = 0.005  # auto dt: one step's approach at the impact speed <= 0.5 % of s
DT_CAP_S = 2.0e-5  # never above this (impact resolution: s / v_rel >> dt for v_rel ~ 1 m/s)

BODY_GET = (pb.BodyFields.POSITION | pb.BodyFields.ANGLE | pb.BodyFields.VELOCITY
            | pb.BodyFields.ANGULAR_VELOCITY)
BODY_SET_FORCE = pb.BodyFields.FORCE | pb.BodyFields.TORQUE
BODY_SET_ALL = (pb.BodyFields.POSITION | pb.BodyFields.VELOCITY | pb.BodyFields.FORCE
                | pb.BodyFields.TORQUE)
ARB_GET = (pb.ArbiterFields.BODY_A_ID | pb.ArbiterFields.BODY_B_ID | pb.ArbiterFields.CONTACT_COUNT
           | pb.ArbiterFields.TOTAL_IMPULSE | pb.ArbiterFields.NORMAL | pb.ArbiterFields.POINT_A_1
           | pb.ArbiterFields.POINT_B_1 | pb.ArbiterFields.DISTANCE_1)


PENETRATION_LIMIT = 0.01  # largest roller-cage overlap accepted, as a fraction of the pocket clearance


class PenetrationExceeded(Exception):
    """A roller overlapped a cage face by more than ``PENETRATION_LIMIT`` of s: the step is too long
    for the approach speeds of this scene (the run is stopped, not written)."""

    def __init__(self, pen, limit, dt, t, approach):
        self.pen, self.limit, self.dt, self.t, self.approach = pen, limit, dt, t, approach
        super().__init__(f"roller-cage overlap {pen:.3g} m > {limit:.3g} m at t = {t:.4g} s with dt = {dt:.3g} s "
                         f"(approach speed {approach:.3g} m/s)")

    def suggested_dt(self) -> float:
        """A step that keeps the same approach under 80 % of the limit (the overlap is ~ v dt)."""
        return 0.8 * self.dt * self.limit / self.pen


def load_zone_phi(scenario) -> float:
    """Load-zone half angle [rad] used by the reduced-equivalent scene (same rule as the reduced model)."""
    v = scenario.reduced.load_zone_half_angle_deg
    if isinstance(v, (int, float)):
        return math.radians(float(v))
    g = scenario.geometry
    phi, _ = kin.quasi_static_load_zone(scenario.operating_point.radial_load, g.roller_count,
                                        g.roller_length, g.radial_clearance)
    return phi


STANDARD_GRAVITY = 9.80665  # m/s^2


def inner_ring_model(scenario):
    """(mass [kg], description) of the inner ring: mass 0 is quasi-static (massless).

    ``multibody.inner_ring = "auto"`` keeps the quasi-static ring while the load is always shared by at
    least two rollers (:func:`bearingsim.kinematics.loaded_rollers_with_one_at_centre` >= 2) or there
    is no load, and otherwise makes it dynamic: a ring resting on a single roller has no stable
    sideways equilibrium, so the rotor's inertia decides where it goes. The dynamic ring's mass is
    ``multibody.inner_ring_mass_kg``; "auto" takes the radial load as the weight of the rotor the
    bearing carries (the paper's rig), ``M = W / g_n``.
    """
    mb = scenario.multibody
    if scenario.multibody.scene != "full":
        return 0.0, "none (reduced-equivalent scene)"
    geo = scenario.geometry
    load = scenario.operating_point.radial_load
    mode = mb.inner_ring
    why = ""
    if mode == "auto":
        if load <= 0.0:
            mode, why = "quasi_static", "auto: no radial load"
        else:
            k = kin.loaded_rollers_with_one_at_centre(load, geo.roller_count, geo.roller_length,
                                                      geo.radial_clearance)
            mode = "quasi_static" if k >= 2 else "dynamic"
            why = (f"auto: {k} roller(s) loaded with one at the load-zone centre "
                   f"({'>= 2: quasi-static' if k >= 2 else 'the ring would rest on one roller: dynamic'})")
    if mode == "quasi_static":
        return 0.0, "quasi-static (massless)" + (f"; {why}" if why else "")
    if mb.inner_ring_mass_kg == "auto":
        if load <= 0.0:
            raise UserError("multibody.inner_ring_mass_kg: a dynamic inner ring without radial load needs its "
                            "mass (there is no rotor weight to take it from); set it in kg")
        mass = load / STANDARD_GRAVITY
        src = f"W / g_n = {mass:.4g} kg"
    else:
        mass = float(mb.inner_ring_mass_kg)
        src = f"multibody.inner_ring_mass_kg = {mass:.4g} kg"
    return mass, f"dynamic, mass {src}" + (f"; {why}" if why else "")


def max_roller_load(scenario) -> float:
    """Estimate of the largest raceway load [N]: Stribeck 5 W / Z plus the centrifugal load."""
    g = scenario.geometry
    op = scenario.operating_point
    return 5.0 * op.radial_load / g.roller_count + g.roller_mass * g.pitch_radius * op.omega_c**2 + 1.0


def stability_limit(scenario) -> float:
    """Explicit stability limit 2/omega_n [s] of a roller between two linearised Palmgren contacts."""
    g = scenario.geometry
    K = kin.palmgren_stiffness(g.roller_length)
    q = max_roller_load(scenario)
    delta = (q / K) ** 0.9
    k_lin = 10.0 / 9.0 * q / delta
    omega_n = math.sqrt(2.0 * k_lin / g.roller_mass)
    return 2.0 / omega_n


def impact_dt(scenario) -> float:
    """Impact resolution [s]: a rear impact may overlap the face by at most 0.5 % of s in one step.

    Approach speed estimate: free flight across the clearance under the no-load-zone deceleration
    (F_o at the centrifugal load, plus g), ``v = sqrt(2 a s)``, as in the reduced model.
    """
    g = scenario.geometry
    op = scenario.operating_point
    n_c = g.roller_mass * g.pitch_radius * op.omega_c**2
    f_o = kin.oil_film_drag(float(scenario.lubrication.drag_coefficient), n_c, op.rolling_velocity)
    a = float(f_o) / g.roller_mass + op.gravity + 1e-3
    v = math.sqrt(2.0 * a * g.pocket_clearance)
    return IMPACT_OVERLAP_FRACTION * g.pocket_clearance / v


def choose_dt(scenario, dt=None):
    """(dt [s], how it was chosen, explicit limit [s]). Raises UserError for a dt far above stable."""
    lim = stability_limit(scenario)
    largest = DT_MAX_FACTOR * lim
    if dt is None and scenario.numerics.dt_s is not None:
        dt = float(scenario.numerics.dt_s)
        how = "numerics.dt_s"
    elif dt is not None:
        how = "simulate(dt=...)"
    else:
        dti = impact_dt(scenario)
        dt = min(DT_FRACTION * lim, dti, DT_CAP_S)
        how = (f"auto: min of {DT_FRACTION} x 2/omega_n of the stiffest raceway contact "
               f"(Palmgren, Q_max = {max_roller_load(scenario):.0f} N; 2/omega_n = {lim:.3e} s), "
               f"impact resolution {IMPACT_OVERLAP_FRACTION} s / v_impact = {dti:.3e} s, and {DT_CAP_S:.0e} s")
    if dt > largest:
        raise UserError(
            f"numerics.dt_s = {dt:.3g} s is far above the stable time step of this bearing "
            f"(Hertz limit 2/omega_n = {lim:.3g} s): use at most {largest:.3g} s, or remove numerics.dt_s "
            f"for the automatic {min(DT_FRACTION * lim, DT_CAP_S):.3g} s")
    return float(dt), how, lim


def _entry_point(dispatcher, args):
    """The compiled entry point of ``dispatcher`` for these arguments (skips numba's per-call type
    dispatch, ~0.1 us per argument; the arguments' types never change during a run)."""
    import numba

    sig = tuple(numba.typeof(a) for a in args)
    try:
        return dispatcher.overloads[sig].entry_point
    except KeyError:  # pragma: no cover - unexpected signature mismatch: keep the dispatcher
        return dispatcher


class _Block:
    """Fixed-size block buffer in front of an archive time series (append whole blocks: flat memory)."""

    def __init__(self, ts, width, rows=2048):
        self.ts = ts
        self.step = np.zeros(rows, dtype=np.int64)
        self.time = np.zeros(rows)
        self.val = np.zeros((rows, width))
        self.width = width
        self.k = 0

    def add(self, step, t, *vals):
        k = self.k
        self.step[k] = step
        self.time[k] = t
        self.val[k, :] = vals
        self.k = k + 1
        if self.k == len(self.time):
            self.flush()

    def flush(self):
        if self.k:
            v = self.val[: self.k]
            self.ts.append(self.step[: self.k].copy(), self.time[: self.k].copy(),
                           v[:, 0].copy() if self.width == 1 else v.copy())
            self.k = 0


class _BatchIO:
    """Allocation-free batched access to the space (pymunk.batch's C iterators, called directly).

    The state is double-buffered in two fixed C arrays viewed by numpy (no copy per step); the arbiter
    buffers are preallocated. ``step`` calls ``cpSpaceStep`` directly: the scene never adds or removes
    anything and has no callbacks, so pymunk's Python bookkeeping around the step is not needed.
    """

    def __init__(self, space, nb, set_fields, set_arr, arb_cap=4096):
        self.sp = space._space
        self.nb = nb
        self._keep = []
        self.get_fn = ffi.addressof(lib, "pmSpaceBodyGetIteratorFuncBatched")
        self.set_fn = ffi.addressof(lib, "pmSpaceBodySetIteratorFuncBatched")
        self.arb_fn = ffi.addressof(lib, "pmSpaceArbiterIteratorFuncBatched")
        self.ia = lib.pmIntArrayNew(nb)
        self.fa = []
        self.gd = []
        self.views = []
        for _ in range(2):
            fa = lib.pmFloatArrayNew(2 * nb * 6 + 16)
            d = ffi.new("pmBatchedData *")
            d.fields = BODY_GET.value
            d.floatArray = fa
            d.intArray = self.ia
            self.fa.append(fa)
            self.gd.append(d)
            self.views.append(None)
        self.maxes = [-1, -1]
        self.set_buf = pb.Buffer()
        self.set_buf.set_float_buf(set_arr)
        self.sd = ffi.new("pmBatchedData *")
        self.sd.fields = set_fields.value
        self.sd.floatArray = self.set_buf._float_arr
        self.sd.intArray = self.set_buf._int_arr
        self.arb_cap = arb_cap
        self.afa = lib.pmFloatArrayNew(rk.ARB_F * arb_cap)
        self.aia = lib.pmIntArrayNew(rk.ARB_I * arb_cap)
        self.amax = (-1, -1)
        self.ad = ffi.new("pmBatchedData *")
        self.ad.fields = ARB_GET.value
        self.ad.floatArray = self.afa
        self.ad.intArray = self.aia
        self._arb_views()

    def _arb_views(self):
        self.amax = (self.afa.max, self.aia.max)
        self.arb_f = np.frombuffer(ffi.buffer(self.afa.arr, 8 * self.afa.max), dtype=np.float64)
        self.arb_i = np.frombuffer(ffi.buffer(self.aia.arr, 8 * self.aia.max), dtype=np.uint64)

    def get(self, k):
        fa = self.fa[k]
        fa.num = 0
        lib.cpSpaceEachBody(self.sp, self.get_fn, self.gd[k])
        if fa.max != self.maxes[k]:  # first call, or the C array was reallocated
            self.maxes[k] = fa.max
            self.views[k] = np.frombuffer(ffi.buffer(fa.arr, 8 * self.nb * 6),
                                          dtype=np.float64).reshape(self.nb, 6)
        return self.views[k]

    def set(self):
        self.sd.floatArray.num = 0
        lib.cpSpaceEachBody(self.sp, self.set_fn, self.sd)

    def arbiters(self):
        """Number of arbiters read into ``arb_f`` / ``arb_i``."""
        self.afa.num = 0
        self.aia.num = 0
        lib.cpSpaceEachCachedArbiter(self.sp, self.arb_fn, self.ad)
        if (self.afa.max, self.aia.max) != self.amax:
            self._arb_views()  # the C arrays grew (reallocated)
        return self.aia.num // rk.ARB_I

    def step(self, h):
        lib.cpSpaceStep(self.sp, h)


def run(scenario, archive=None, progress=False, dt=None, _hook=None, penetration_limit=PENETRATION_LIMIT):
    """Run the scenario; return a dict of raw accumulators (see :class:`MultibodyResult`)."""
    t_wall0 = time.perf_counter()
    geo = scenario.geometry
    op = scenario.operating_point
    scene_kind = scenario.multibody.scene
    reduced_eq = scene_kind == "reduced_equivalent"
    n = geo.roller_count
    if n < 3:
        raise UserError(f"bearing.roller_count = {n}: the multibody model needs at least 3 rollers")
    h, dt_how, dt_lim = choose_dt(scenario, dt)
    sign = op.sign
    e = float(scenario.contact.restitution)
    mu_c = float(scenario.contact.cage_friction)
    warm = int(scenario.numerics.warmup_rotations)
    nrot = int(scenario.numerics.rotations)
    s = geo.pocket_clearance
    rr = geo.roller_radius
    rp = geo.pitch_radius
    K = kin.palmgren_stiffness(geo.roller_length)
    # the reduced-equivalent scene keeps the paper's roller path on the pitch circle (no clearance)
    pd = 0.0 if reduced_eq else geo.radial_clearance
    ro_race = geo.outer_race_radius + 0.25 * pd
    ri_race = geo.inner_race_radius - 0.25 * pd

    sc = build_scene(geo, op, e, mu_c, half_angle=math.radians(POCKET_FACE_HALF_ANGLE_DEG),
                     n_seg=POCKET_FACE_SEGMENTS, kinematic_cage=reduced_eq, spin_free=not reduced_eq)
    space = sc.space
    nb = n + 1
    # rollers start on the outer race (centrifugal), moving with the cage
    n_centrifugal = geo.roller_mass * rp * op.omega_c**2 + 1e-3
    r0 = ro_race - rr - (n_centrifugal / K) ** 0.9
    omega_cage = sign * op.omega_c
    for i, b in enumerate(sc.rollers):
        a = sc.pocket_body_angle[i]
        b.position = (r0 * math.cos(a), r0 * math.sin(a))
        b.velocity = (-omega_cage * r0 * math.sin(a), omega_cage * r0 * math.cos(a))

    prm = np.zeros(fk.N_PARAMS)
    prm[fk.P_RR] = rr
    prm[fk.P_MASS] = geo.roller_mass
    prm[fk.P_INERTIA] = geo.roller_inertia
    prm[fk.P_RO_RACE] = ro_race
    prm[fk.P_RI_RACE] = ri_race
    prm[fk.P_RO_GEOM] = geo.outer_race_radius
    prm[fk.P_RI_GEOM] = geo.inner_race_radius
    prm[fk.P_K] = K
    prm[fk.P_CDAMP] = CONTACT_DAMPING_S
    prm[fk.P_DFADE] = DAMPING_FADE_M
    prm[fk.P_MU] = float(scenario.multibody.traction_mu_max)
    prm[fk.P_SLIPREF] = float(scenario.multibody.traction_slip_ref)
    prm[fk.P_UMIN] = MIN_ENTRAINMENT_M_S
    prm[fk.P_CDRAG] = float(scenario.lubrication.drag_coefficient)
    prm[fk.P_WEPS] = DRAG_DIRECTION_EPS_M_S
    prm[fk.P_OMEGA_RING] = sign * op.omega_i
    prm[fk.P_LOAD] = op.radial_load
    prm[fk.P_GRAV] = op.gravity
    prm[fk.P_INNER] = 0.0 if reduced_eq else 1.0
    prm[fk.P_TRACTION] = 0.0 if reduced_eq else 1.0
    prm[fk.P_SPIN] = 0.0 if reduced_eq else 1.0
    prm[fk.P_NEWTON_STEP] = NEWTON_MAX_STEP_M
    ring_mass, ring_how = inner_ring_model(scenario)
    prm[fk.P_RING_MASS] = ring_mass

    # pocket angles from the load-zone centre at t = 0, in [0, 2 pi)
    theta0 = np.mod(-2.0 * math.pi * np.arange(n) / n, 2.0 * math.pi)
    cfg = np.zeros(rk.N_CFG)
    cfg[rk.C_SIGN] = sign
    cfg[rk.C_N] = n
    cfg[rk.C_WARM] = warm
    cfg[rk.C_ROT] = nrot
    cfg[rk.C_NBINS] = THETA_BINS
    cfg[rk.C_VTHR] = IMPACT_SPEED_THRESHOLD_M_S
    cfg[rk.C_MASS] = geo.roller_mass
    win = np.zeros((nrot, n, rk.N_WCOL))
    first_imp = np.full((nrot, n), np.nan)
    f_bin = np.zeros((n, THETA_BINS, 2))
    t_bin = np.zeros((n, THETA_BINS))
    q_bin = np.zeros((THETA_BINS, 2))
    tq_bin = np.zeros(THETA_BINS)
    j_int = np.zeros((n, 2))
    glob = np.zeros(rk.N_GLOB)
    impacts = np.zeros((IMPACT_CAPACITY, rk.N_ICOL))
    n_imp = 0
    diag = np.zeros((n, fk.N_DIAG))
    hold = np.zeros(n, dtype=np.bool_)
    # start at the continuous quasi-static displacement (close to equilibrium: small start transient)
    _, delta_qs = kin.quasi_static_load_zone(op.radial_load, n, geo.roller_length, pd) if not reduced_eq else (0, 0)
    ring_c = np.array([0.0, -max(0.5 * pd, delta_qs)])
    ring_c_prev = np.zeros(2)
    ring_v = np.zeros(2)
    ids = sc.body_ids
    order = np.argsort(ids)
    ids_sorted = ids[order].astype(np.uint64)
    ids_index = order.astype(np.int64)

    # reduced-equivalent: held rollers sit at the front of their pockets on the outer race
    phi = load_zone_phi(scenario) if reduced_eq else 0.0
    if reduced_eq:
        set_fields = BODY_SET_ALL
        set_arr = np.zeros(nb * 7)
    else:
        set_fields = BODY_SET_FORCE
        set_arr = np.zeros(nb * 3)
    # full scene: the kernel writes the (fx, fy, torque) rows straight into the set buffer
    out_f = np.zeros(nb * 3) if reduced_eq else set_arr
    io = _BatchIO(space, nb, set_fields, set_arr)

    total_rot = warm + nrot
    travel_end = 2.0 * math.pi * total_rot
    omega_nom = op.omega_c
    steps_est = int(math.ceil(travel_end / omega_nom / h))
    out_every = max(1, int(round(1.0 / (float(scenario.numerics.output_rate_hz) * h))))
    ts_cage = ts_slip = ts_orbit = ts_ring = None
    if archive is not None:
        ts_cage = _Block(archive.timeseries("cage_angular_speed", (), "rad/s",
                                            "cage angular speed in the direction of rotation"), 1)
        ts_slip = _Block(archive.timeseries("cage_slip", (), "1",
                                            "1 - cage speed / epicyclic speed (Eq. 11)"), 1)
        ts_orbit = _Block(archive.timeseries("cage_centre", (2,), "m",
                                             "cage centre (x, y); y up, radial load along -y"), 2)
        if not reduced_eq:
            ts_ring = _Block(archive.timeseries("inner_ring_centre", (2,), "m",
                                                "quasi-static inner-ring centre (x, y)"), 2)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total_rot, unit="rot", desc="cage rotations", file=sys.stderr)
    bar_done = 0
    cur = 0
    prev = io.get(cur)
    cage_w_start = None
    t = 0.0
    step = 0
    pymunk_s = 0.0
    orbit_max = 0.0
    pen_limit = penetration_limit * s  # (the stability scan passes 0.5 to look for blow-up alone)
    ring_sum_x = 0.0
    ring_sum_y = 0.0
    ring_n = 0
    newton_fail = 0
    rec_started = False
    hold_radius = rp - (n_centrifugal / K) ** 0.9
    front_off = 0.5 * s
    max_steps = int(3 * steps_est + 1000)
    perf = time.perf_counter
    rf = fk.raceway_forces
    rs = rk.record_step
    pocket_a = np.ascontiguousarray(sc.pocket_body_angle, dtype=np.float64)
    ORBIT_KEEP = 4096
    orbit_buf = np.full((ORBIT_KEEP, 3), np.nan)
    n_orbit = 0
    t_loop0 = perf()
    while True:
        travel = sign * prev[n, 2]
        if travel >= travel_end:
            break
        if step > max_steps:
            raise SimulationUnstable(
                f"cage did not complete {total_rot} rotations in {max_steps} steps "
                f"(cage speed {prev[n, 5]:.3g} rad/s): the cage stalled")
        if not rec_started and travel >= 2.0 * math.pi * warm:
            rec_started = True
            cage_w_start = prev[n, 5]
            t_rec0 = t
        if reduced_eq:
            _hold_rollers(prev, n, sign, phi, sc.pocket_body_angle, hold, hold_radius, front_off,
                          omega_cage)
        if rf(prev, h, prm, ring_c, ring_c_prev, ring_v, hold, out_f, diag) < 0:
            newton_fail += 1
        if rec_started:
            ring_sum_x += ring_c[0]
            ring_sum_y += ring_c[1]
            ring_n += 1
        if reduced_eq:
            _pack_all(prev, out_f, set_arr, nb)
        io.set()
        t0 = perf()
        io.step(h)
        pymunk_s += perf() - t0
        t += h
        step += 1
        cur ^= 1
        now = io.get(cur)
        n_arb = io.arbiters()
        rargs = (io.arb_f, io.arb_i, n_arb, ids_sorted, ids_index, prev, now, t, h, cfg,
                 pocket_a, theta0, diag, win, first_imp, f_bin, t_bin, q_bin, tq_bin, j_int, glob,
                 impacts, n_imp)
        n_imp = rs(*rargs)
        if step == 1:
            rs = _entry_point(rk.record_step, rargs)
            rf = _entry_point(fk.raceway_forces, (prev, h, prm, ring_c, ring_c_prev, ring_v, hold, out_f, diag))
        if _hook is not None:
            _hook(step, t, prev, now, io, n_arb, diag, ring_c)
        prev = now
        if step % out_every == 0:
            if not np.all(np.isfinite(now)):
                raise SimulationUnstable(f"non-finite state at t = {t:.6g} s (step {step}); "
                                         f"try a smaller numerics.dt_s than {h:.3g} s")
            if glob[rk.G_MAXPEN_ALL] > pen_limit:
                raise PenetrationExceeded(glob[rk.G_MAXPEN_ALL], pen_limit, h, glob[rk.G_MAXPEN_TIME],
                                          glob[rk.G_MAXPEN_APPROACH])
            dmax = diag[:, fk.D_DELTA_OUT].max()
            if dmax > 50e-6 or abs(now[n, 5]) > 3.0 * op.omega_i + 10.0:
                raise SimulationUnstable(
                    f"raceway approach {dmax:.3g} m or cage speed {now[n, 5]:.3g} rad/s out of bounds "
                    f"at t = {t:.6g} s (energy blow-up); try a smaller numerics.dt_s than {h:.3g} s")
            wc = sign * now[n, 5]
            if rec_started:
                orbit_buf[n_orbit % ORBIT_KEEP] = (t, now[n, 0], now[n, 1])
                n_orbit += 1
                orbit_max = max(orbit_max, math.hypot(now[n, 0], now[n, 1]))
            if ts_cage is not None:
                ts_cage.add(step, t, wc)
                ts_slip.add(step, t, 1.0 - wc / omega_nom)
                ts_orbit.add(step, t, now[n, 0], now[n, 1])
                if ts_ring is not None:
                    ts_ring.add(step, t, ring_c[0], ring_c[1])
            if bar is not None:
                done = min(total_rot, int(sign * now[n, 2] / (2.0 * math.pi)))
                if done > bar_done:
                    bar.update(done - bar_done)
                    bar_done = done
    for blk in (ts_cage, ts_slip, ts_orbit, ts_ring):
        if blk is not None:
            blk.flush()
    if bar is not None:
        bar.update(total_rot - bar_done)
        bar.close()
    loop_s = perf() - t_loop0
    wall = time.perf_counter() - t_wall0
    t_rec = t - t_rec0 if rec_started else 0.0
    return dict(
        scenario=scenario, scene=scene_kind, inner_ring=ring_how, dt=h, dt_choice=dt_how, dt_explicit_limit=dt_lim, steps=step,
        wall_s=wall, loop_s=loop_s, pymunk_step_s=pymunk_s, t_end=t, t_record=t_rec, win=win, first_imp=first_imp,
        f_bin=f_bin, t_bin=t_bin, q_bin=q_bin, tq_bin=tq_bin, glob=glob.copy(), impacts=impacts[:n_imp].copy(),
        impacts_dropped=n_imp >= IMPACT_CAPACITY, cage_w_start=cage_w_start, cage_w_end=prev[n, 5],
        cage_inertia=geo.cage_inertia, newton_failures=newton_fail, orbit_max=orbit_max, phi=phi,
        final_state=prev.copy(), orbit=np.roll(orbit_buf, -(n_orbit % ORBIT_KEEP), axis=0),
        ring_centre_mean=(np.array([ring_sum_x, ring_sum_y]) / ring_n if ring_n and not reduced_eq
                          else np.full(2, np.nan)),
        radial_clearance=geo.radial_clearance,
    )


@njit(cache=True)
def _hold_rollers(state, n, sign, phi, pocket_a, hold, radius, front_off, omega_cage):
    """Reduced-equivalent: rollers in the load zone ride at the front of their pockets with the cage."""
    phic = state[n, 2]
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
            px = radius * ca + front_off * etx
            py = radius * sa + front_off * ety
            # velocity of that point of the (kinematic) cage
            state[i, 0] = px
            state[i, 1] = py
            state[i, 3] = -omega_cage * py
            state[i, 4] = omega_cage * px


@njit(cache=True)
def _pack_all(state, out_f, set_arr, nb):
    a = set_arr.reshape(nb, 7)
    a[:, 0:2] = state[:, 0:2]
    a[:, 2:4] = state[:, 3:5]
    f = out_f.reshape(nb, 3)
    a[:, 4:7] = f
