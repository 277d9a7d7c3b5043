"""Multi-pocket model: every roller and the cage in a pymunk space, through load and no-load zone.

Scenes (``[multibody] scene``)
------------------------------
``"full"``
    ``roller_count`` rollers (planar rigid bodies, free spin) and a free cage (x, y, angle). Outer ring
    fixed; inner ring turning at omega_i in the ``sign`` direction with a quasi-static centre that
    carries the radial load (-y). Raceway contacts are force laws in one numba kernel
    (:mod:`bearingsim.multibody.forces`): Palmgren line contact ``Q = K delta^(10/9)`` with the radial
    clearance, EHL traction ``mu_max tanh(slip/slip_ref)`` (Johnson & Tevaarwerk 1977), the oil-film
    resistance ``F_o = c N^0.246 V^0.648`` (Eq. 2) at each contact with its own N and V, gravity.
    The load zone emerges from the contact mechanics. Roller-cage contacts are pymunk contacts
    (restitution e, friction mu) on pocket faces that are arcs around the pocket centre (pocket
    diameter D + s), front and rear faces as separate polylines of a few segments.
``"reduced_equivalent"``
    The seed paper's assumptions in the plane: cage kinematic at the epicyclic speed, no inner ring,
    roller spin fixed, no traction. Inside the load zone (``|theta| < phi``; phi =
    ``reduced.load_zone_half_angle_deg`` or the quasi-static value when ``"auto"``, the same rule as the
    reduced model) every roller is carried at the FRONT of its pocket with zero relative speed, so it
    enters the no-load zone like the reduced model's start condition; in the no-load zone it is free
    under the outer-race force law, F_o and gravity. Its I_dec per pass is the reduced model's.

Angles and rotations
--------------------
theta is a pocket centre's angle from the load-zone centre (the bottom, -y) measured in the direction of
cage rotation, in [0, 360) deg. Pocket i's initial angle is ``theta_i0 = (-360 i / Z) mod 360``.
**Rotation k of pocket i** is the interval of cage travel (cage angle turned in the direction of
rotation, from t = 0) ``[360 (W + k) - theta_i0, 360 (W + k + 1) - theta_i0)`` deg, W =
``numerics.warmup_rotations``: it starts when pocket i crosses the load-zone centre (theta = 0) and
contains one whole load zone exit, no-load zone and load zone entry. Everything before rotation 0 is
discarded. The run stops at a cage travel of ``360 (W + R)`` deg (R = ``numerics.rotations``), so
W >= 1 is needed for complete windows (with W = 0 the first window of pockets i > 0 is partial).

Recorded quantities (per pocket i, per rotation k)
-------------------------------------------------
* face: a roller-cage contact is on the *front* face when its normal from roller to cage points along
  e_t, the cage's direction of rotation at the pocket centre, else on the *rear* face;
* ``I_acc`` = sum of the circumferential (e_t) component of the front-face impulses on the cage,
  ``I_dec`` = minus the same on the rear face (both >= 0: the roller drives, resp. the cage brakes
  the roller), [N s]. This is what the paper's load cells measured. ``Jn_front/Jn_rear``: normal
  impulses, ``Jf_front/Jf_rear``: friction impulse magnitudes, ``slide_work_front/rear``: sum of
  ``J_n |v_slide|`` [N m] with the tangential relative speed of the contact points;
* impacts (`/results/impacts`, face column "rear" or "front", as in the reduced model): a contact step whose normal
  approach speed exceeds 0.01 m/s (anything slower is
  resting-contact chatter, which pymunk resolves with restitution on every step);
* wear per pocket face and cage rotation [m^3]: the paper's index ``k I r_r omega_r / H`` (Eq. 16) and
  the sliding work ``k sum(J_n |v_slide|) / H``.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from bearingsim.multibody import recorder as rk
from bearingsim.errors import SimulationUnstable
from bearingsim.multibody.core import (IMPACT_SPEED_THRESHOLD_M_S, PENETRATION_LIMIT, THETA_BINS,
                                       PenetrationExceeded, choose_dt, run)

__all__ = ["simulate", "MultibodyResult"]

SUMMARY_UNITS = {
    "I_dec_mean_Ns": "N s", "I_dec_std_Ns": "N s", "I_acc_mean_Ns": "N s", "I_acc_std_Ns": "N s",
    "first_impact_speed_m_s": "m/s", "first_impact_energy_J": "J", "cage_speed_mean_rad_s": "rad/s",
    "cage_slip": "1", "load_zone_half_angle_deg": "deg",
    "load_zone_contact_half_angle_deg": "deg", "inner_ring_displacement_m": "m", "torque_balance_residual": "1",
    "max_penetration_m": "m", "dt_s": "s", "wall_s": "s", "steps": "1", "pymunk_step_s": "s",
}


MAX_DT_RETRIES = 4


def simulate(scenario, archive=None, progress=False, dt=None) -> "MultibodyResult":
    """Run the multi-pocket model. ``dt`` [s] overrides ``numerics.dt_s`` and the automatic choice.

    A roller may not overlap a cage face by more than ``PENETRATION_LIMIT`` (1 %) of the pocket
    clearance: the overlap is the approach covered in the step in which a contact is found, ~v dt.
    With the automatic time step the run is restarted with a step shortened to the measured approach
    speed (at most ``MAX_DT_RETRIES`` times; the history goes into ``dt_choice``); with a given time
    step it stops with :class:`SimulationUnstable` naming the largest step that would do.
    """
    auto = dt is None and scenario.numerics.dt_s is None
    retries = []
    while True:
        try:
            raw = run(scenario, archive=archive, progress=progress, dt=dt)
            break
        except PenetrationExceeded as exc:
            new_dt = exc.suggested_dt()
            if not auto or len(retries) >= MAX_DT_RETRIES:
                key = "numerics.dt_s" if not auto else "the automatic time step"
                raise SimulationUnstable(
                    f"{exc}: more than {PENETRATION_LIMIT:.0%} of the pocket clearance; {key} is too long "
                    f"for this scene, use numerics.dt_s <= {new_dt:.3g} s") from None
            retries.append(f"restarted at dt = {new_dt:.3g} s after overlap {exc.pen:.3g} m > "
                           f"{PENETRATION_LIMIT:.0%} s at dt = {exc.dt:.3g} s (approach {exc.approach:.3g} m/s)")
            dt = new_dt
            if archive is not None:
                archive.discard_timeseries()
    if retries:  # the last run was given its dt: describe how the first one was chosen, then the restarts
        raw["dt_choice"] = "; ".join([choose_dt(scenario)[1], *retries])
    res = MultibodyResult(raw)
    if archive is not None:
        archive.provenance["dt_s"] = res.dt
        archive.provenance["dt_choice"] = raw["dt_choice"]
        archive.provenance["solver"] = "pymunk 7 (roller-cage) + numba raceway kernel"
        archive.provenance["steps"] = res.steps
        archive.provenance["ring_newton_failures"] = raw["newton_failures"]
        archive.provenance["inner_ring"] = raw["inner_ring"]
    return res


def _load_zone_from_ring(ring_centre_mean, radial_clearance):
    """Load-zone half angle [deg] from the mean inner-ring displacement (Harris & Kotzalas Sec. 7.2):
    the arc over which the ring's displacement delta_r along the load closes the clearance,
    ``psi_l = arccos(P_d / (2 delta_r))``; 0 when delta_r <= P_d / 2, 90 deg for zero clearance."""
    delta_r = -float(ring_centre_mean[1])  # the load points along -y
    if not math.isfinite(delta_r):
        return float("nan")
    half_pd = 0.5 * radial_clearance
    if delta_r <= half_pd:
        return 90.0 if half_pd == 0.0 and delta_r > 0.0 else 0.0
    return math.degrees(math.acos(half_pd / delta_r))


def _load_zone_half_angle(q_bin, tq_bin):
    """Half width [deg] of the theta range around 0 where the mean inner-race load > 1 % of its max."""
    nb = len(tq_bin)
    q = np.where(tq_bin > 0, q_bin["inner"] / np.maximum(tq_bin, 1e-300), 0.0)
    if q.max() <= 0:
        return 0.0
    loaded = q > 0.01 * q.max()
    centres = (np.arange(nb) + 0.5) * 360.0 / nb
    c = np.where(centres > 180.0, centres - 360.0, centres)
    # contiguous loaded region containing theta = 0
    order = np.argsort(c)
    c_sorted, l_sorted = c[order], loaded[order]
    i0 = int(np.argmin(np.abs(c_sorted)))
    if not l_sorted[i0]:
        return 0.0
    lo = i0
    while lo > 0 and l_sorted[lo - 1]:
        lo -= 1
    hi = i0
    while hi < nb - 1 and l_sorted[hi + 1]:
        hi += 1
    width = c_sorted[hi] - c_sorted[lo] + 360.0 / nb
    return 0.5 * width


def _save(fig, path) -> Path:
    """Lay out, write (120 dpi) and close one report figure; return its path."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


class MultibodyResult:
    """Result of :func:`simulate`. Arrays are per rotation x pocket unless stated."""

    def __init__(self, raw):
        self.raw = raw
        sc = raw["scenario"]
        geo = sc.geometry
        op = sc.operating_point
        self.scenario = sc
        self.scene = raw["scene"]
        self.dt = raw["dt"]
        self.steps = raw["steps"]
        self.wall_s = raw["wall_s"]
        self.pymunk_step_s = raw["pymunk_step_s"]
        self.rotations = sc.numerics.rotations
        w = raw["win"]
        self.per_rotation_I_acc = w["I_acc"].copy()
        self.per_rotation_I_dec = w["I_dec"].copy()
        self.per_rotation_Jn_front = w["Jn_front"].copy()
        self.per_rotation_Jn_rear = w["Jn_rear"].copy()
        self.per_rotation_Jf_front = w["Jf_front"].copy()
        self.per_rotation_Jf_rear = w["Jf_rear"].copy()
        self.per_rotation_work_front = w["work_front"].copy()
        self.per_rotation_work_rear = w["work_rear"].copy()
        self.first_impact_speed = raw["first_imp"]
        self.impacts = raw["impacts"]
        nb = THETA_BINS
        self.theta_deg = (np.arange(nb) + 0.5) * 360.0 / nb
        tb = raw["t_bin"]  # (n, nb)
        with np.errstate(invalid="ignore", divide="ignore"):
            self.force_acc = np.where(tb > 0, raw["f_bin"]["front"] / tb, 0.0).T  # (nb, n)
            self.force_dec = np.where(tb > 0, raw["f_bin"]["rear"] / tb, 0.0).T
            tq = raw["tq_bin"]
            self.load_inner = np.where(tq > 0, raw["q_bin"]["inner"] / np.maximum(tq, 1e-300), 0.0)
            self.load_outer = np.where(tq > 0, raw["q_bin"]["outer"] / np.maximum(tq, 1e-300), 0.0)
        full = self.scene == "full"
        # two measures of the load zone (docs/archive.md): the classical half angle from the mean ring
        # displacement (what the paper's 23.5 deg is) and the extent of the measured inner-race contact
        # (wider with discrete rollers: the laterally free ring shifts towards the exiting roller)
        self.ring_centre_mean = raw["ring_centre_mean"]
        self.load_zone_half_angle_deg = (_load_zone_from_ring(self.ring_centre_mean, raw["radial_clearance"])
                                         if full else math.degrees(raw["phi"]))
        self.load_zone_contact_half_angle_deg = (_load_zone_half_angle(raw["q_bin"], raw["tq_bin"])
                                                 if full else math.degrees(raw["phi"]))
        t_rec = raw["t_record"]
        self.cage_speed_mean = 2.0 * math.pi * self.rotations / t_rec if t_rec > 0 else float("nan")
        self.cage_slip = 1.0 - self.cage_speed_mean / op.omega_c
        g = raw["glob"]
        self.torque_impulse_normal = g["tau_normal"]
        self.torque_impulse_friction = g["tau_friction"]
        ws, we = raw["cage_w_start"], raw["cage_w_end"]
        self.cage_momentum_change = geo.cage_inertia * (we - ws) if ws is not None else float("nan")
        drive = abs(self.per_rotation_I_acc.sum()) * geo.pitch_radius
        self.torque_balance_residual = (
            (self.torque_impulse_normal + self.torque_impulse_friction - self.cage_momentum_change)
            / drive if drive > 0 else float("nan"))
        self.max_penetration = max(g["maxpen_front"], g["maxpen_rear"])
        self.max_penetration_all = g["maxpen_all"]
        k = float(sc.wear.wear_coefficient)
        H = float(sc.wear.hardness_Pa)
        fac = k * geo.roller_radius * op.omega_r / H
        self.wear_index_front = fac * self.per_rotation_I_acc.mean(axis=0)
        self.wear_index_rear = fac * self.per_rotation_I_dec.mean(axis=0)
        self.wear_work_front = k * self.per_rotation_work_front.mean(axis=0) / H
        self.wear_work_rear = k * self.per_rotation_work_rear.mean(axis=0) / H
        fi = self.first_impact_speed[np.isfinite(self.first_impact_speed)]
        v1 = float(fi.mean()) if fi.size else float("nan")
        self.summary = {
            "I_dec_mean_Ns": float(self.per_rotation_I_dec.mean()),
            "I_dec_std_Ns": float(self.per_rotation_I_dec.std()),
            "I_acc_mean_Ns": float(self.per_rotation_I_acc.mean()),
            "I_acc_std_Ns": float(self.per_rotation_I_acc.std()),
            "first_impact_speed_m_s": v1,
            "first_impact_energy_J": 0.5 * geo.roller_mass * v1 * v1,
            "cage_speed_mean_rad_s": float(self.cage_speed_mean),
            "cage_slip": float(self.cage_slip),
            "load_zone_half_angle_deg": float(self.load_zone_half_angle_deg),
            "load_zone_contact_half_angle_deg": float(self.load_zone_contact_half_angle_deg),
            "inner_ring_displacement_m": float(-self.ring_centre_mean[1]),
            "torque_balance_residual": float(self.torque_balance_residual),
            "max_penetration_m": float(self.max_penetration),
            "dt_s": float(self.dt),
            "wall_s": float(self.wall_s),
            "steps": int(self.steps),
            "pymunk_step_s": float(self.pymunk_step_s),
        }
        self.orbit = raw["orbit"]

    # ------------------------------------------------------------------------------------------
    def write(self, aw) -> None:
        n = self.per_rotation_I_dec.shape[1]
        pr = "/results/per_rotation"
        desc = "per cage rotation (rows; see bearingsim.multibody docstring) and pocket (columns)"
        aw.write_array(f"{pr}/I_acc", self.per_rotation_I_acc, "N s",
                       "front-face impulse, circumferential component, " + desc)
        aw.write_array(f"{pr}/I_dec", self.per_rotation_I_dec, "N s",
                       "rear-face impulse, circumferential component (braking), " + desc)
        aw.write_array(f"{pr}/Jn_front", self.per_rotation_Jn_front, "N s", "front-face normal impulse, " + desc)
        aw.write_array(f"{pr}/Jn_rear", self.per_rotation_Jn_rear, "N s", "rear-face normal impulse, " + desc)
        aw.write_array(f"{pr}/Jf_front", self.per_rotation_Jf_front, "N s", "front-face friction impulse, " + desc)
        aw.write_array(f"{pr}/Jf_rear", self.per_rotation_Jf_rear, "N s", "rear-face friction impulse, " + desc)
        aw.write_array(f"{pr}/slide_work_front", self.per_rotation_work_front, "J",
                       "sum J_n |v_slide| on the front face, " + desc)
        aw.write_array(f"{pr}/slide_work_rear", self.per_rotation_work_rear, "J",
                       "sum J_n |v_slide| on the rear face, " + desc)
        aw.write_array(f"{pr}/first_impact_speed", self.first_impact_speed, "m/s",
                       "approach speed of the first rear-face impact in the no-load zone (NaN: none), " + desc)
        aw.write_array("/results/theta_deg", self.theta_deg, "deg", "bin centres of theta (load-zone centre = 0)")
        aw.write_array("/results/force_vs_theta", self.force_acc - self.force_dec, "N",
                       "mean circumferential roller-cage force on the cage (F_acc - F_dec) per theta bin "
                       "(rows, /results/theta_deg) and pocket (columns), recorded rotations")
        aw.write_array("/results/force_vs_theta_acc", self.force_acc, "N", "mean F_acc (front face) [theta bin, pocket]")
        aw.write_array("/results/force_vs_theta_dec", self.force_dec, "N", "mean F_dec (rear face) [theta bin, pocket]")
        if self.scene == "full":
            aw.write_array("/results/raceway_load_inner", self.load_inner, "N",
                           "mean inner-race roller load per theta bin (all rollers)")
            aw.write_array("/results/raceway_load_outer", self.load_outer, "N",
                           "mean outer-race roller load per theta bin (all rollers)")
        imp = self.impacts
        aw.write_table("/results/impacts", {
            "time_s": imp["time"], "theta_deg": imp["theta_deg"],
            "approach_speed_m_s": imp["approach_speed"], "impulse_Ns": imp["impulse"],
            "pocket": imp["pocket"],
            "face": np.where(imp["face"] == rk.FACE_FRONT, "front", "rear"),  # codes and strings of the reduced model
            "rotation": imp["rotation"],
        }, {"time_s": "s", "theta_deg": "deg", "approach_speed_m_s": "m/s", "impulse_Ns": "N s",
            "pocket": "1", "face": "1", "rotation": "1"},
            description=f"roller-cage impacts (approach speed > {IMPACT_SPEED_THRESHOLD_M_S} m/s) in the "
                        "recorded rotations; face 'rear' or 'front'; impulse = normal impulse; theta of the pocket centre; "
                        "rotation = row of /results/per_rotation the impact counts in")
        aw.write_array("/results/wear/paper_index_front", self.wear_index_front, "m^3",
                       "Archard wear per cage rotation, front face, k I_acc r_r omega_r / H (paper Eq. 16), per pocket")
        aw.write_array("/results/wear/paper_index_rear", self.wear_index_rear, "m^3",
                       "Archard wear per cage rotation, rear face, k I_dec r_r omega_r / H, per pocket")
        aw.write_array("/results/wear/sliding_work_front", self.wear_work_front, "m^3",
                       "Archard wear per cage rotation, front face, k sum(J_n |v_slide|) / H, per pocket")
        aw.write_array("/results/wear/sliding_work_rear", self.wear_work_rear, "m^3",
                       "Archard wear per cage rotation, rear face, k sum(J_n |v_slide|) / H, per pocket")
        attrs = dict(self.summary)
        attrs["scene"] = self.scene
        attrs["pockets"] = n
        aw.set_attrs("/results/summary", attrs, {k: v for k, v in SUMMARY_UNITS.items()})

    # ------------------------------------------------------------------------------------------
    def save_figures(self, stem) -> list[Path]:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        stem = Path(stem)
        stem.parent.mkdir(parents=True, exist_ok=True)
        title = f"{self.scenario.name} ({self.scene}, {self.scenario.operating.inner_ring_speed_rpm:g} rpm)"
        out = []
        n = self.per_rotation_I_dec.shape[1]
        # forces against theta (Fig. 5 analog): pocket 0 and the mean over pockets
        fig, ax = plt.subplots(figsize=(8, 4))
        ax.plot(self.theta_deg, self.force_acc[:, 0], lw=0.8, color="C0", label="F_acc pocket 0")
        ax.plot(self.theta_deg, -self.force_dec[:, 0], lw=0.8, color="C3", label="-F_dec pocket 0")
        ax.plot(self.theta_deg, self.force_acc.mean(axis=1), lw=1.5, color="C0", ls="--", label="F_acc mean")
        ax.plot(self.theta_deg, -self.force_dec.mean(axis=1), lw=1.5, color="C3", ls="--", label="-F_dec mean")
        phi = self.load_zone_half_angle_deg
        for x in (phi, 360 - phi):
            ax.axvline(x, color="grey", lw=0.6, ls=":")
        ax.set_xlabel("theta from load-zone centre [deg]")
        ax.set_ylabel("mean circumferential pocket force [N]")
        ax.set_xlim(0, 360)
        ax.set_title(title + ": pocket force vs theta")
        ax.legend(fontsize=8)
        out.append(_save(fig, f"{stem}_forces.png"))
        # impulses per pocket (Fig. 7 analog)
        fig, ax = plt.subplots(figsize=(8, 4))
        x = np.arange(n)
        ax.errorbar(x - 0.12, self.per_rotation_I_acc.mean(0) * 1e3, yerr=self.per_rotation_I_acc.std(0) * 1e3,
                    fmt="o", label="I_acc (front)")
        ax.errorbar(x + 0.12, self.per_rotation_I_dec.mean(0) * 1e3, yerr=self.per_rotation_I_dec.std(0) * 1e3,
                    fmt="s", label="I_dec (rear)")
        ax.set_xlabel("pocket")
        ax.set_ylabel("impulse per cage rotation [mN s]")
        ax.set_title(title + f": mean +- std over {self.rotations} rotations")
        ax.legend()
        out.append(_save(fig, f"{stem}_impulses.png"))
        # cage-centre orbit
        fig, ax = plt.subplots(figsize=(5, 5))
        o = self.orbit[np.isfinite(self.orbit[:, 0])]
        ax.plot(o[:, 1] * 1e6, o[:, 2] * 1e6, lw=0.6)
        ax.set_aspect("equal")
        ax.set_xlabel("cage centre x [um]")
        ax.set_ylabel("cage centre y [um]")
        ax.set_title("cage-centre orbit (recorded, last samples)", fontsize=9)
        out.append(_save(fig, f"{stem}_orbit.png"))
        # wear per pocket face (Fig. 14 analog)
        fig, ax = plt.subplots(figsize=(8, 4))
        wdt = 0.2
        ax.bar(x - 1.5 * wdt, self.wear_index_front * 1e18, wdt, label="front, k I r_r w_r / H")
        ax.bar(x - 0.5 * wdt, self.wear_index_rear * 1e18, wdt, label="rear, k I r_r w_r / H")
        ax.bar(x + 0.5 * wdt, self.wear_work_front * 1e18, wdt, label="front, k sum(F|v_s|dt) / H")
        ax.bar(x + 1.5 * wdt, self.wear_work_rear * 1e18, wdt, label="rear, k sum(F|v_s|dt) / H")
        ax.set_xlabel("pocket")
        ax.set_ylabel("wear per cage rotation [um^3]")
        ax.set_title(title + ": Archard wear per pocket face")
        ax.legend(fontsize=8)
        out.append(_save(fig, f"{stem}_wear.png"))
        return out
