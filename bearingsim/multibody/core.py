"""Driver of the multi-pocket model: scene, time step, run set-up, errors, results. SI throughout.

See the package docstring of :mod:`bearingsim.multibody` for the definitions of the recorded
quantities. The step loop itself is compiled (:func:`bearingsim.multibody.loop.advance`: per time step
``h`` the body states are read in one batch, the raceway forces computed by one numba kernel
(:func:`bearingsim.multibody.forces.raceway_forces`) at the predicted positions and handed to pymunk
in one batch, ``cpSpaceStep(h)`` solves the roller-cage contacts, and
:func:`bearingsim.multibody.recorder.record_step` attributes the arbiter impulses to pockets, faces
and rotations); Python only sees it every 2048 output samples, to write them and move the progress bar.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from bearingsim import laws
from bearingsim.errors import SimulationUnstable, UserError
from bearingsim.multibody import forces as fk
from bearingsim.multibody import loop as lp
from bearingsim.multibody import recorder as rk
from bearingsim.multibody.scene import build_scene

# --- fixed model choices (documented, not tuned) ------------------------------------------------
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


def inner_ring_model(p):
    """(mass [kg], description) of the inner ring: mass 0 is quasi-static (massless).

    ``multibody.inner_ring = "auto"`` keeps the quasi-static ring while the load is always shared by at
    least two rollers (:func:`bearingsim.kinematics.loaded_rollers_with_one_at_centre` >= 2) or there
    is no load, and otherwise makes it dynamic: a ring resting on a single roller has no stable
    sideways equilibrium, so the rotor's inertia decides where it goes. The dynamic ring's mass is
    ``multibody.inner_ring_mass_kg``; "auto" takes the radial load as the weight of the rotor the
    bearing carries (the paper's rig), ``M = W / g_n``.
    """
    mb = p.multibody
    if mb.scene != "full":
        return 0.0, "none (reduced-equivalent scene)"
    geo = p.bearing
    load = p.operating.radial_load
    mode = mb.inner_ring
    why = ""
    if mode == "auto":
        if load <= 0.0:
            mode, why = "quasi_static", "auto: no radial load"
        else:
            k = laws.loaded_rollers_with_one_at_centre(load, geo.roller_count, geo.roller_length,
                                                      geo.radial_clearance)
            mode = "quasi_static" if k >= 2 else "dynamic"
            why = (f"auto: {k} roller(s) loaded with one at the load-zone centre "
                   f"({'>= 2: quasi-static' if k >= 2 else 'the ring would rest on one roller: dynamic'})")
    if mode == "quasi_static":
        return 0.0, "quasi-static (massless)" + (f"; {why}" if why else "")
    if mb.inner_ring_mass is None:
        if load <= 0.0:
            raise UserError("multibody.inner_ring_mass_kg: a dynamic inner ring without radial load needs its "
                            "mass (there is no rotor weight to take it from); set it in kg")
        mass = load / laws.STANDARD_GRAVITY
        src = f"W / g_n = {mass:.4g} kg"
    else:
        mass = mb.inner_ring_mass
        src = f"multibody.inner_ring_mass_kg = {mass:.4g} kg"
    return mass, f"dynamic, mass {src}" + (f"; {why}" if why else "")


def max_roller_load(p) -> float:
    """Estimate of the largest raceway load [N]: Stribeck 5 W / Z plus the centrifugal load."""
    g = p.bearing
    op = p.operating
    return 5.0 * op.radial_load / g.roller_count + g.roller_mass * g.pitch_radius * op.omega_c**2 + 1.0


def stability_limit(p) -> float:
    """Explicit stability limit 2/omega_n [s] of a roller between two linearised Palmgren contacts."""
    g = p.bearing
    K = laws.palmgren_stiffness(g.roller_length)
    q = max_roller_load(p)
    delta = (q / K) ** 0.9
    k_lin = 10.0 / 9.0 * q / delta
    omega_n = math.sqrt(2.0 * k_lin / g.roller_mass)
    return 2.0 / omega_n


def impact_dt(p) -> float:
    """Impact resolution [s]: a rear impact may overlap the face by at most 0.5 % of s in one step.

    Approach speed estimate: free flight across the clearance under the no-load-zone deceleration
    (F_o at the centrifugal load, plus g), ``v = sqrt(2 a s)``, as in the reduced model.
    """
    g = p.bearing
    op = p.operating
    n_c = g.roller_mass * g.pitch_radius * op.omega_c**2
    f_o = laws.oil_film_drag(p.contact.drag_coefficient, n_c, op.rolling_velocity)
    a = float(f_o) / g.roller_mass + op.gravity + 1e-3
    v = math.sqrt(2.0 * a * g.pocket_clearance)
    return IMPACT_OVERLAP_FRACTION * g.pocket_clearance / v


def choose_dt(p, dt=None):
    """(dt [s], how it was chosen, explicit limit [s]). Raises UserError for a dt far above stable."""
    lim = stability_limit(p)
    largest = DT_MAX_FACTOR * lim
    if dt is None and p.numerics.dt is not None:
        dt = p.numerics.dt
        how = "numerics.dt_s"
    elif dt is not None:
        how = "simulate(dt=...)"
    else:
        dti = impact_dt(p)
        dt = min(DT_FRACTION * lim, dti, DT_CAP_S)
        how = (f"auto: min of {DT_FRACTION} x 2/omega_n of the stiffest raceway contact "
               f"(Palmgren, Q_max = {max_roller_load(p):.0f} N; 2/omega_n = {lim:.3e} s), "
               f"impact resolution {IMPACT_OVERLAP_FRACTION} s / v_impact = {dti:.3e} s, and {DT_CAP_S:.0e} s")
    if dt > largest:
        raise UserError(
            f"numerics.dt_s = {dt:.3g} s is far above the stable time step of this bearing "
            f"(Hertz limit 2/omega_n = {lim:.3g} s): use at most {largest:.3g} s, or remove numerics.dt_s "
            f"for the automatic {min(DT_FRACTION * lim, DT_CAP_S):.3g} s")
    return float(dt), how, lim


def run(p, sink=None, progress=False, dt=None, _hook=None, penetration_limit=PENETRATION_LIMIT):
    """Run the parameters ``p``; return a dict of raw accumulators (see :class:`MultibodyResult`).

    Time series go to ``sink`` (``timeseries(...)`` appenders; see :class:`bearingsim.results.MemorySink`)."""
    t_wall0 = time.perf_counter()
    geo = p.bearing
    op = p.operating
    scene_kind = p.multibody.scene
    reduced_eq = scene_kind == "reduced_equivalent"
    n = geo.roller_count
    if n < 3:
        raise UserError(f"bearing.roller_count = {n}: the multibody model needs at least 3 rollers")
    h, dt_how, dt_lim = choose_dt(p, dt)
    sign = op.sign
    e = p.contact.restitution
    mu_c = p.contact.cage_friction
    warm = p.numerics.warmup_rotations
    nrot = p.numerics.rotations
    s = geo.pocket_clearance
    rr = geo.roller_radius
    rp = geo.pitch_radius
    K = laws.palmgren_stiffness(geo.roller_length)
    # the reduced-equivalent scene keeps the paper's roller path on the pitch circle (no clearance)
    pd = 0.0 if reduced_eq else geo.radial_clearance
    ro_race = geo.outer_race_radius + 0.25 * pd
    ri_race = geo.inner_race_radius - 0.25 * pd

    sc = build_scene(geo, op, e, mu_c, half_angle=p.multibody.pocket_face_half_angle,
                     n_seg=POCKET_FACE_SEGMENTS, kinematic_cage=reduced_eq, spin_free=not reduced_eq,
                     flat_pockets=p.multibody.flat_pockets)
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
    prm[fk.P_MU] = p.contact.traction_mu_max
    prm[fk.P_SLIPREF] = p.contact.traction_slip_ref
    prm[fk.P_UMIN] = MIN_ENTRAINMENT_M_S
    prm[fk.P_CDRAG] = p.contact.drag_coefficient
    prm[fk.P_WEPS] = DRAG_DIRECTION_EPS_M_S
    prm[fk.P_OMEGA_RING] = sign * op.omega_i
    prm[fk.P_LOAD] = op.radial_load
    prm[fk.P_GRAV] = op.gravity
    prm[fk.P_INNER] = 0.0 if reduced_eq else 1.0
    prm[fk.P_TRACTION] = 0.0 if reduced_eq else 1.0
    prm[fk.P_SPIN] = 0.0 if reduced_eq else 1.0
    prm[fk.P_NEWTON_STEP] = NEWTON_MAX_STEP_M
    ring_mass, ring_how = inner_ring_model(p)
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
    _, delta_qs = laws.quasi_static_load_zone(op.radial_load, n, geo.roller_length, pd) if not reduced_eq else (0, 0)
    ring_c = np.array([0.0, -max(0.5 * pd, delta_qs)])
    ring_c_prev = np.zeros(2)
    ring_v = np.zeros(2)
    ids = sc.body_ids
    order = np.argsort(ids)
    ids_sorted = ids[order].astype(np.uint64)
    ids_index = order.astype(np.int64)

    # reduced-equivalent: held rollers sit at the front of their pockets on the outer race
    phi = p.reduced.load_zone_half_angle if reduced_eq else 0.0
    if reduced_eq:
        set_fields = lp.BODY_SET_ALL
        set_arr = np.zeros(nb * 7)
    else:
        set_fields = lp.BODY_SET_FORCE
        set_arr = np.zeros(nb * 3)
    # full scene: the kernel writes the (fx, fy, torque) rows straight into the set buffer
    out_f = np.zeros(nb * 3) if reduced_eq else set_arr
    # room for every roller against every face segment of every pocket: pymunk never grows the arrays
    arb_cap = max(4096, 2 * POCKET_FACE_SEGMENTS * n * n + 64)
    io = lp.BatchIO(space, nb, set_fields, set_arr, arb_cap)

    total_rot = warm + nrot
    travel_end = 2.0 * math.pi * total_rot
    omega_nom = op.omega_c
    steps_est = int(math.ceil(travel_end / omega_nom / h))
    out_every = max(1, int(round(1.0 / (p.numerics.output_rate * h))))
    series = None
    if sink is not None:
        series = [
            (sink.timeseries("cage_angular_speed", (), "rad/s", "cage angular speed in the direction of rotation"),
             lp.S_W, 1),
            (sink.timeseries("cage_slip", (), "1", "1 - cage speed / epicyclic speed (Eq. 11)"), lp.S_SLIP, 1),
            (sink.timeseries("cage_centre", (2,), "m", "cage centre (x, y); y up, radial load along -y"),
             lp.S_CX, 2),
        ]
        if not reduced_eq:
            series.append((sink.timeseries("inner_ring_centre", (2,), "m", "quasi-static inner-ring centre (x, y)"),
                           lp.S_RX, 2))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total_rot, unit="rot", desc="cage rotations", file=sys.stderr)
    bar_done = 0
    io.read_states()
    hold_radius = rp - (n_centrifugal / K) ** 0.9
    front_off = 0.5 * s
    pocket_a = np.ascontiguousarray(sc.pocket_body_angle, dtype=np.float64)
    ORBIT_KEEP = 4096
    orbit_buf = np.full((ORBIT_KEEP, 3), np.nan)
    lim = np.zeros(lp.N_LIM)
    lim[lp.LIM_TRAVEL_END] = travel_end
    lim[lp.LIM_TRAVEL_REC] = 2.0 * math.pi * warm
    lim[lp.LIM_PEN] = penetration_limit * s  # (the stability scan passes 0.5 to look for blow-up alone)
    lim[lp.LIM_OMEGA] = 3.0 * op.omega_i + 10.0
    lim[lp.LIM_OMEGA_NOM] = omega_nom
    # the rollers hold the cage only while its centre stays within the radial reach of the face arcs
    face_reach = (rr + 0.5 * s) * math.sin(p.multibody.pocket_face_half_angle)
    lim[lp.LIM_ORBIT] = face_reach
    lsi = np.zeros(lp.N_LI, dtype=np.int64)
    lsi[lp.LI_OUT_EVERY] = out_every
    lsi[lp.LI_MAX_STEPS] = int(3 * steps_est + 1000)
    lsf = np.zeros(lp.N_LF)
    smp_step = np.zeros(2048, dtype=np.int64)
    smp = np.zeros((2048, lp.N_SCOL))
    args = (io.step_fn, io.each_body_fn, io.each_arb_fn, io.clock_fn, io.timed, io.ptr, *io.hdr, *io.states,
            io.arb_f, io.arb_i, io.ts, h, prm, ring_c, ring_c_prev, ring_v, hold, out_f, set_arr, diag, reduced_eq,
            phi, pocket_a, hold_radius, front_off, omega_cage, ids_sorted, ids_index, cfg, theta0, win, first_imp,
            f_bin, t_bin, q_bin, tq_bin, j_int, glob, impacts, lim, lsi, lsf, smp_step, smp, orbit_buf)
    t_loop0 = time.perf_counter()
    while True:
        code = lp.advance(*args)
        k = int(lsi[lp.LI_NSMP])
        if series is not None and k:
            for ts, col, width in series:
                ts.append(smp_step[:k].copy(), smp[:k, lp.S_T].copy(),
                          smp[:k, col].copy() if width == 1 else smp[:k, col:col + width].copy())
        lsi[lp.LI_NSMP] = 0
        t = float(lsf[lp.LF_T])
        step = int(lsi[lp.LI_STEP])
        state = io.states[int(lsi[lp.LI_CUR])]
        if bar is not None:
            done = min(total_rot, int(sign * state[n, 2] / (2.0 * math.pi)))
            if done > bar_done:
                bar.update(done - bar_done)
                bar_done = done
        if code == lp.CODE_BLOCK_FULL:
            continue
        if code == lp.CODE_DONE:
            break
        if bar is not None:
            bar.close()
        if code == lp.CODE_NONFINITE:
            raise SimulationUnstable(f"non-finite state at t = {t:.6g} s (step {step}); "
                                     f"try a smaller numerics.dt_s than {h:.3g} s")
        if code == lp.CODE_PENETRATION:
            raise PenetrationExceeded(glob[rk.G_MAXPEN_ALL], lim[lp.LIM_PEN], h, glob[rk.G_MAXPEN_TIME],
                                      glob[rk.G_MAXPEN_APPROACH])
        if code == lp.CODE_BLOWUP:
            raise SimulationUnstable(
                f"raceway approach {diag[:, fk.D_DELTA_OUT].max():.3g} m or cage speed {state[n, 5]:.3g} rad/s "
                f"out of bounds at t = {t:.6g} s (energy blow-up); try a smaller numerics.dt_s than {h:.3g} s")
        if code == lp.CODE_STALLED:
            raise SimulationUnstable(
                f"cage did not complete {total_rot} rotations in {step} steps "
                f"(cage speed {state[n, 5]:.3g} rad/s): the cage stalled")
        if code == lp.CODE_CAGE_LOST:
            raise SimulationUnstable(
                f"the cage centre moved {math.hypot(state[n, 0], state[n, 1]) * 1e3:.4g} mm off the bearing axis at "
                f"t = {t:.6g} s, beyond the radial reach of its pocket faces ({face_reach * 1e3:.4g} mm): the rollers no "
                f"longer hold it; this pocket shape needs a land-guided cage, which the model does not have: use a "
                f"larger multibody.pocket_face_half_angle_deg")
        raise RuntimeError(f"multibody step loop: pymunk grew a batch buffer at step {step} (code {code})")
    if bar is not None:
        bar.update(total_rot - bar_done)
        bar.close()
    loop_s = time.perf_counter() - t_loop0
    n_imp = int(lsi[lp.LI_NIMP])
    # impacts in one step come in pymunk's arbiter order, which follows shape addresses: sort them by
    # (time, pocket, face) so that the table is the same in every run
    imp = impacts[:n_imp]
    imp = imp[np.lexsort((imp[:, rk.I_FACE], imp[:, rk.I_POCKET], imp[:, rk.I_TIME]))]
    wall = time.perf_counter() - t_wall0
    prev = io.states[int(lsi[lp.LI_CUR])]
    rec_started = lsi[lp.LI_REC] == 1
    t_rec = t - lsf[lp.LF_T_REC0] if rec_started else 0.0
    ring_n = lsf[lp.LF_RING_N]
    n_orbit = int(lsi[lp.LI_NORBIT])
    pymunk_s = lsf[lp.LF_PYMUNK_NS] * 1e-9 if io.timed else float("nan")
    return dict(
        parameters=p, scene=scene_kind, inner_ring=ring_how, dt=h, dt_choice=dt_how, dt_explicit_limit=dt_lim, steps=step,
        wall_s=wall, loop_s=loop_s, pymunk_step_s=pymunk_s, t_end=t, t_record=t_rec, win=win, first_imp=first_imp,
        f_bin=f_bin, t_bin=t_bin, q_bin=q_bin, tq_bin=tq_bin, glob=glob.copy(), impacts=imp,
        impacts_dropped=n_imp >= IMPACT_CAPACITY, cage_w_start=lsf[lp.LF_W_START] if rec_started else None,
        cage_w_end=prev[n, 5],
        cage_inertia=geo.cage_inertia, newton_failures=int(lsi[lp.LI_NEWTON_FAIL]), orbit_max=lsf[lp.LF_ORBIT_MAX],
        phi=phi,
        final_state=prev.copy(), orbit=np.roll(orbit_buf, -(n_orbit % ORBIT_KEEP), axis=0),
        ring_centre_mean=(lsf[[lp.LF_RING_SX, lp.LF_RING_SY]] / ring_n if ring_n and not reduced_eq
                          else np.full(2, np.nan)),
        radial_clearance=geo.radial_clearance,
    )

