"""The reduced single-pocket model of the seed paper (Suzuki et al. 2023, §2.3), made exact.

One roller in one pocket of a cage turning at the epicyclic speed (Eq. 11), from the no-load-zone
entrance θ = φ to its exit θ = 2π − φ, starting at the front face at rest relative to the cage.
Two solvers of the same equations (Eqs. 1–9, corrected as in ``shared/PHYSICS.md`` §2):

* ``event`` (:mod:`bearingsim.reduced.event`): closed form between contacts, impact instants by root
  finding, Zeno sequences closed exactly; the validated reference;
* ``euler`` (:mod:`bearingsim.reduced.euler`): the paper's explicit scheme (Eqs. 7–8), first order.

Every cage rotation of this model repeats the same no-load pass from the same start (the paper's
assumption: the roller leaves the load zone at the front of its pocket at the cage speed), so a run
solves one pass and records it for each of ``numerics.rotations`` rotations; the scatter over
rotations is zero by construction (the multibody model is where it comes from). Reverse rotation is
the mirror image of forward rotation with θ measured along the cage's rotation, so it yields the same
numbers.

Sign convention of the archive: impulses are positive magnitudes; ``I_dec`` is the rear face's (the
cage drags a lagging roller), ``I_acc`` the front face's (in this model, the front-face impulse of the
no-load pass: gravity throws the roller forward on the descending side at low speed).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bearingsim.reduced.core import PassInputs, load_zone_half_angle
from bearingsim.reduced.euler import default_dt, solve_euler
from bearingsim.reduced.event import PassSolution, solve_event

__all__ = ["simulate", "solve_pass", "ReducedResult", "PassInputs", "PassSolution"]

FACE_NAMES = np.array(["rear", "front"])


def solve_pass(inp: PassInputs, method: str = "event", dt: float | None = None, trace_points: int = 2000):
    """Solve one no-load pass with ``method`` (``"event"`` or ``"euler"``; euler needs ``dt`` or uses
    :func:`bearingsim.reduced.euler.default_dt`)."""
    if method == "event":
        return solve_event(inp, trace_points=trace_points)
    return solve_euler(inp, dt if dt is not None else default_dt(inp), trace_points=trace_points)


@dataclass
class ReducedResult:
    """One reduced-model run: the solved pass, replicated over ``rotations`` cage rotations."""

    scenario: object
    inputs: PassInputs
    solution: PassSolution
    rotations: int
    dt_choice: str

    # --- derived -----------------------------------------------------------------------------
    @property
    def first_rear_impact(self) -> tuple[float, float]:
        """(approach speed [m/s], kinetic energy ½ m u² [J]) of the first rear-face impact (NaN if none)."""
        imp = self.solution.impacts
        rear = np.flatnonzero(imp["face"] == 0)
        if rear.size == 0:
            return math.nan, math.nan
        u = float(imp["approach_speed"][rear[0]])
        return u, 0.5 * self.inputs.mass * u * u

    @property
    def per_rotation_I_dec(self) -> np.ndarray:
        return np.full((self.rotations, 1), self.solution.I_dec)

    @property
    def per_rotation_I_acc(self) -> np.ndarray:
        return np.full((self.rotations, 1), self.solution.I_acc)

    @property
    def summary(self) -> dict[str, float]:
        u, ek = self.first_rear_impact
        return {
            "I_dec_mean_Ns": float(self.per_rotation_I_dec.mean()),
            "I_dec_std_Ns": float(self.per_rotation_I_dec.std()),
            "I_acc_mean_Ns": float(self.per_rotation_I_acc.mean()),
            "I_acc_std_Ns": float(self.per_rotation_I_acc.std()),
            "first_impact_speed_m_s": u,
            "first_impact_energy_J": ek,
            "load_zone_half_angle_deg": math.degrees(self.inputs.theta_start),
        }

    SUMMARY_UNITS = {
        "I_dec_mean_Ns": "N s", "I_dec_std_Ns": "N s", "I_acc_mean_Ns": "N s", "I_acc_std_Ns": "N s",
        "first_impact_speed_m_s": "m/s", "first_impact_energy_J": "J", "load_zone_half_angle_deg": "deg",
    }

    def impact_table(self) -> dict[str, np.ndarray]:
        """All impacts of all recorded rotations (the pass repeated; time from the first pass start)."""
        imp = self.solution.impacts
        n = imp["theta"].size
        period = 2.0 * math.pi / self.inputs.omega_c
        rot = np.repeat(np.arange(self.rotations), n)
        return {
            "time_s": np.tile(imp["time"], self.rotations) + rot * period,
            "theta_deg": np.tile(np.degrees(imp["theta"]), self.rotations),
            "approach_speed_m_s": np.tile(imp["approach_speed"], self.rotations),
            "impulse_Ns": np.tile(imp["impulse"], self.rotations),
            "pocket": np.zeros(n * self.rotations, dtype=np.int64),
            "face": np.tile(FACE_NAMES[imp["face"]], self.rotations),
            "rotation": rot,
            "zeno_closure": np.tile(imp["kind"], self.rotations).astype(np.int8),
        }

    def wear(self) -> dict[str, float]:
        """Archard wear of the pocket faces from the paper's index (Eq. 16): V = k I_c r_r ω_r / H.

        ``*_per_rotation_m3`` per cage rotation; ``*_per_hour_m3_h`` at this speed. k and H are the
        scenario's ``[wear] wear_coefficient`` and ``hardness_Pa``.
        """
        sc = self.scenario
        k, hard = float(sc.wear.wear_coefficient), float(sc.wear.hardness_Pa)
        sliding = self.inputs.roller_radius * self.inputs.omega_r  # r_r ω_r [m/s]
        rot_per_hour = 3600.0 * self.inputs.omega_c / (2.0 * math.pi)
        rear = k * self.solution.I_dec * sliding / hard
        front = k * self.solution.I_acc * sliding / hard
        return {"rear_per_rotation_m3": rear, "front_per_rotation_m3": front,
                "rear_per_hour_m3_h": rear * rot_per_hour, "front_per_hour_m3_h": front * rot_per_hour}

    # --- archive -----------------------------------------------------------------------------
    def write(self, aw) -> None:
        sol = self.solution
        inp = self.inputs
        aw.write_array("results/per_rotation/I_dec", self.per_rotation_I_dec, "N s",
                       "rear-face impulse per cage rotation [rotation, pocket]")
        aw.write_array("results/per_rotation/I_acc", self.per_rotation_I_acc, "N s",
                       "front-face impulse per cage rotation [rotation, pocket]")
        aw.write_table(
            "results/impacts", self.impact_table(),
            {"time_s": "s", "theta_deg": "deg", "approach_speed_m_s": "m/s", "impulse_Ns": "N s",
             "pocket": "1", "face": "1", "rotation": "1", "zeno_closure": "1"},
            "roller-cage impacts; zeno_closure = 1 marks an impact that closes a bounce sequence",
        )
        if sol.trace is not None:
            tr = sol.trace
            aw.write_array("results/trace/theta_deg", np.degrees(tr["theta"]), "deg", "roller angle from the load-zone centre")
            aw.write_array("results/trace/l_r", tr["l_r"], "m", "roller position in the pocket (0 rear face, s front face)")
            aw.write_array("results/trace/dl_r_dt", tr["dl_r_dt"], "m/s", "roller speed relative to the cage")
            aw.write_array("results/trace/I_dec_cumulative", tr["I_dec_cumulative"], "N s", "cumulative rear-face impulse")
        aw.set_attrs(
            "results/pass",
            {"I_dec_Ns": sol.I_dec, "I_acc_Ns": sol.I_acc, "I_dec_resting_Ns": sol.I_dec_resting,
             "I_acc_resting_Ns": sol.I_acc_resting, "theta_start_deg": math.degrees(inp.theta_start),
             "theta_end_deg": math.degrees(inp.theta_end), "duration_s": inp.pass_duration,
             "l_end_m": sol.l_end, "v_end_m_s": sol.v_end, "termination": sol.termination},
            {"I_dec_Ns": "N s", "I_acc_Ns": "N s", "I_dec_resting_Ns": "N s", "I_acc_resting_Ns": "N s",
             "theta_start_deg": "deg", "theta_end_deg": "deg", "duration_s": "s", "l_end_m": "m", "v_end_m_s": "m/s"},
        )
        aw.set_attrs(
            "results/operating_point",
            {"omega_c_rad_s": inp.omega_c, "omega_r_rad_s": inp.omega_r, "rolling_velocity_m_s": inp.rolling_velocity},
            {"omega_c_rad_s": "rad/s", "omega_r_rad_s": "rad/s", "rolling_velocity_m_s": "m/s"},
        )
        aw.set_attrs("results/summary", self.summary, self.SUMMARY_UNITS)
        aw.set_attrs("results/wear", self.wear(), {k: ("m^3" if k.endswith("_m3") else "m^3/h") for k in self.wear()})
        aw.provenance["solver"] = f"reduced/{sol.method}"
        aw.provenance["solver_wall_s"] = sol.wall_s
        aw.provenance["dt_s"] = sol.dt if sol.dt is not None else float("nan")
        aw.provenance["dt_choice"] = self.dt_choice
        for k, v in sol.info.items():
            if np.isscalar(v):
                aw.provenance[f"solver_{k}"] = v

    # --- figures -----------------------------------------------------------------------------
    def save_figures(self, stem: Path) -> list[Path]:
        """Fig. 8 analog: l_r, dl_r/dt and cumulative I_dec against θ over the no-load pass."""
        from bearingsim.plotting import plt

        sol = self.solution
        if sol.trace is None:
            return []
        tr = sol.trace
        th = np.degrees(tr["theta"])
        fig, ax = plt.subplots(3, 1, figsize=(7.0, 7.5), sharex=True)
        ax[0].plot(th, tr["l_r"] * 1e3, lw=1.0)
        ax[0].set_ylabel("$l_r$ [mm]\n(0 rear, s front)")
        ax[1].plot(th, tr["dl_r_dt"], lw=1.0)
        ax[1].set_ylabel("$dl_r/dt$ [m/s]")
        ax[2].plot(th, tr["I_dec_cumulative"] * 1e3, lw=1.2)
        ax[2].set_ylabel("cumulative $I_{dec}$ [mN s]")
        ax[2].set_xlabel("θ from the load-zone centre [deg]")
        sc = self.scenario
        ax[0].set_title(
            f"{sc.name}: reduced model ({sol.method}), {sc.operating.inner_ring_speed_rpm:g} rpm, "
            f"c = {sc.lubrication.drag_coefficient:g}, e = {sc.contact.restitution:g}, "
            f"$I_{{dec}}$ = {sol.I_dec * 1e3:.3f} mN s",
            fontsize=9,
        )
        for a in ax:
            a.grid(alpha=0.3)
            a.axvline(180.0, color="0.6", lw=0.6)
        fig.tight_layout()
        out = Path(f"{stem}_pass.png")
        fig.savefig(out, dpi=130)
        plt.close(fig)
        return [out]


def simulate(scenario, archive=None, progress: bool = False, dt: float | None = None) -> ReducedResult:
    """Run the reduced model for ``scenario`` (see the module docstring)."""
    inp = PassInputs.from_scenario(scenario)
    method = scenario.reduced.method
    dt_choice = "event-driven: no time step"
    if method == "euler":
        if dt is None:
            dt = scenario.numerics.dt_s
            dt_choice = "numerics.dt_s"
        if dt is None:
            dt = default_dt(inp)
            dt_choice = "automatic: 1/1000 of the largest allowed step (euler.max_stable_dt)"
    sol = solve_pass(inp, method, dt)
    return ReducedResult(scenario, inp, sol, int(scenario.numerics.rotations), dt_choice)


__all__ += ["load_zone_half_angle"]
