"""The reduced single-pocket model of the seed paper (Suzuki et al. 2023, §2.3), made exact.

One roller in one pocket of a cage turning at the epicyclic speed (Eq. 11), from the no-load-zone
entrance θ = φ to its exit θ = 2π − φ, starting at the front face at rest relative to the cage.
Two solvers of the same equations (Eqs. 1–9, corrected as in ``docs/physics.md``):

* ``event`` (:mod:`bearingsim.reduced.event`): closed form between contacts, impact instants by root
  finding, Zeno sequences closed exactly; the validated reference;
* ``euler`` (:mod:`bearingsim.reduced.euler`): the paper's explicit scheme (Eqs. 7–8), first order.

Every cage rotation of this model repeats the same no-load pass from the same start (the paper's
assumption: the roller leaves the load zone at the front of its pocket at the cage speed), so a run
solves one pass and records it for each of ``numerics.rotations`` rotations; the scatter over
rotations is zero by construction (the multibody model is where it comes from). Reverse rotation is
the mirror image of forward rotation with θ measured along the cage's rotation, so it yields the same
numbers.

The model takes :class:`bearingsim.parameters.Parameters` and returns a :class:`ReducedResult`; it
never sees a scenario file or an archive.

Sign convention of the archive: impulses are positive magnitudes; ``I_dec`` is the rear face's (the
cage drags a lagging roller), ``I_acc`` the front face's (in this model, the front-face impulse of the
no-load pass: gravity throws the roller forward on the descending side at low speed).
"""
from __future__ import annotations

import math

import numpy as np

from bearingsim import laws
from bearingsim.codes import FACE_NAMES as CODE_FACE_NAMES
from bearingsim.reduced.core import FACE_REAR, PassInputs
from bearingsim.reduced.euler import check_step as euler_check_step, default_dt, solve_euler
from bearingsim.reduced.event import PassSolution, solve_event
from bearingsim.datatypes import AttrGroup, NamedArray
from bearingsim.model_versions import MODEL_FIGURES, MODEL_VERSIONS
from bearingsim.results import Result

__all__ = ["simulate", "solve_pass", "ReducedResult", "PassInputs", "PassSolution", "MODEL_VERSION"]

#: version of this model's numbers, stored in each result's provenance (:mod:`bearingsim.model_versions`:
#: bumped when a change moves numbers)
MODEL_VERSION = MODEL_VERSIONS["reduced"]

FACE_NAMES = np.array(CODE_FACE_NAMES)  # indexed by the face codes (bearingsim/codes.py)

SUMMARY_UNITS = {
    "I_dec_mean_Ns": "N s", "I_dec_std_Ns": "N s", "I_acc_mean_Ns": "N s", "I_acc_std_Ns": "N s",
    "first_impact_speed_m_s": "m/s", "first_impact_energy_J": "J", "load_zone_half_angle_deg": "deg",
}


def solve_pass(inp: PassInputs, method: str = "event", dt: float | None = None, trace_points: int = 2000,
               automatic: bool | None = None):
    """Solve one no-load pass with ``method`` (``"event"`` or ``"euler"``; euler needs ``dt`` or uses
    :func:`bearingsim.reduced.euler.default_dt`; ``automatic``: ``dt`` is that default, default
    ``dt is None``, which only changes which key a refused step's message names)."""
    if method == "event":
        return solve_event(inp, trace_points=trace_points)
    if automatic is None:
        automatic = dt is None
    return solve_euler(inp, dt if dt is not None else default_dt(inp), trace_points=trace_points,
                       automatic=automatic)


#: what the reduced model's wear numbers are of: its no-load pass alone
WEAR_DESCRIPTION = ("Archard wear of the pocket's faces from the no-load pass's impulses (Eq. 16): rear_* of I_dec, "
                    "front_* of I_acc, the pass's front-face impacts alone; the load zone's drive F_acc on the front "
                    "face is not part of this model (the whole bearing's front and rear wear are alike, Fig. 14)")


class ReducedResult(Result):
    """One reduced-model run: the solved pass, replicated over ``rotations`` cage rotations.

    Built by :func:`simulate` (then :attr:`inputs` and :attr:`solution` hold the solver's own objects)
    or read back from an archive (then they are ``None``; everything else is the same).
    """

    model = "reduced"
    FIGURES = MODEL_FIGURES["reduced"]
    _TRACE = ("theta_deg", "l_r", "dl_r_dt", "I_dec_cumulative")
    _TRACE_ADDED = ("I_acc_cumulative",)  # archives written before it was recorded lack it
    _IMPACTS = ("time_s", "theta_deg", "approach_speed_m_s", "impulse_Ns", "pocket", "face", "rotation",
                "zeno_closure")
    LAYOUT = {
        "results/per_rotation/I_dec": ("rotations", "pockets"),
        "results/per_rotation/I_acc": ("rotations", "pockets"),
        **{f"results/impacts/{c}": ("impacts",) for c in _IMPACTS},
        **{f"results/trace/{c}": ("trace points",) for c in _TRACE + _TRACE_ADDED},
    }
    OPTIONAL = (frozenset(f"results/trace/{c}" for c in _TRACE), frozenset(f"results/trace/{c}" for c in _TRACE_ADDED))
    ADDED_ARRAYS = frozenset(f"results/trace/{c}" for c in _TRACE_ADDED)
    TEXT_ARRAYS = frozenset({"results/impacts/face"})
    SUMMARY_NUMBERS = tuple(SUMMARY_UNITS)
    FIGURE_DATA = ("results/trace",)

    @classmethod
    def archive_dims(cls, scenario) -> dict[str, int]:
        return {"rotations": scenario.numerics.rotations, "pockets": 1}  # one pocket, its pass repeated

    def __init__(self, *args, inputs: PassInputs | None = None, solution: PassSolution | None = None, **kw):
        super().__init__(*args, **kw)
        self.inputs = inputs
        self.solution = solution

    @classmethod
    def from_solution(cls, p, inp: PassInputs, sol: PassSolution, dt_choice: str) -> "ReducedResult":
        """Lay out a solved pass as a result (per rotation, impacts, trace, pass, wear, summary)."""
        rotations = p.numerics.rotations
        per_dec = np.full((rotations, 1), sol.I_dec)
        per_acc = np.full((rotations, 1), sol.I_acc)
        imp = sol.impacts
        n = imp["theta"].size
        period = 2.0 * math.pi / inp.omega_c
        rot = np.repeat(np.arange(rotations), n)
        desc = "[rotation, pocket]"
        data = {
            "results/per_rotation/I_dec": NamedArray(per_dec, "N s", "rear-face impulse per cage rotation " + desc),
            "results/per_rotation/I_acc": NamedArray(per_acc, "N s", "front-face impulse per cage rotation " + desc),
            # all impacts of all recorded rotations (the pass repeated; time from the first pass start)
            "results/impacts/time_s": NamedArray(np.tile(imp["time"], rotations) + rot * period, "s"),
            "results/impacts/theta_deg": NamedArray(np.tile(np.degrees(imp["theta"]), rotations), "deg"),
            "results/impacts/approach_speed_m_s": NamedArray(np.tile(imp["approach_speed"], rotations), "m/s"),
            "results/impacts/impulse_Ns": NamedArray(np.tile(imp["impulse"], rotations), "N s"),
            "results/impacts/pocket": NamedArray(np.zeros(n * rotations, dtype=np.int64)),
            "results/impacts/face": NamedArray(np.tile(FACE_NAMES[imp["face"]], rotations)),
            "results/impacts/rotation": NamedArray(rot),
            "results/impacts/zeno_closure": NamedArray(np.tile(imp["kind"], rotations).astype(np.int8)),
        }
        if sol.trace is not None:
            tr = sol.trace
            data.update({
                "results/trace/theta_deg": NamedArray(np.degrees(tr["theta"]), "deg", "roller angle from the load-zone centre"),
                "results/trace/l_r": NamedArray(tr["l_r"], "m", "roller position in the pocket (0 rear face, s front face)"),
                "results/trace/dl_r_dt": NamedArray(tr["dl_r_dt"], "m/s", "roller speed relative to the cage"),
                "results/trace/I_dec_cumulative": NamedArray(tr["I_dec_cumulative"], "N s", "cumulative rear-face impulse"),
                "results/trace/I_acc_cumulative": NamedArray(tr["I_acc_cumulative"], "N s",
                                                             "cumulative front-face impulse"),
            })
        rear = np.flatnonzero(imp["face"] == FACE_REAR)
        u = float(imp["approach_speed"][rear[0]]) if rear.size else math.nan
        ek = 0.5 * inp.mass * u * u
        summary = {
            "I_dec_mean_Ns": float(per_dec.mean()),
            "I_dec_std_Ns": float(per_dec.std()),
            "I_acc_mean_Ns": float(per_acc.mean()),
            "I_acc_std_Ns": float(per_acc.std()),
            "first_impact_speed_m_s": u,
            "first_impact_energy_J": ek,
            "load_zone_half_angle_deg": math.degrees(inp.theta_start),
        }
        # Archard wear of the pocket faces from the paper's index, Eq. (16), per rotation and per hour
        w = p.wear
        rear_v = laws.archard_wear_volume(w.wear_coefficient, sol.I_dec, inp.roller_radius, inp.omega_r, w.hardness)
        front_v = laws.archard_wear_volume(w.wear_coefficient, sol.I_acc, inp.roller_radius, inp.omega_r, w.hardness)
        rot_per_hour = 3600.0 * inp.omega_c / (2.0 * math.pi)
        wear = {"rear_per_rotation_m3": rear_v, "front_per_rotation_m3": front_v,
                "rear_per_hour_m3_h": rear_v * rot_per_hour, "front_per_hour_m3_h": front_v * rot_per_hour}
        groups = {
            "results/pass": AttrGroup(
                {"I_dec_Ns": sol.I_dec, "I_acc_Ns": sol.I_acc, "I_dec_resting_Ns": sol.I_dec_resting,
                 "I_acc_resting_Ns": sol.I_acc_resting, "theta_start_deg": math.degrees(inp.theta_start),
                 "theta_end_deg": math.degrees(inp.theta_end), "duration_s": inp.pass_duration,
                 "l_end_m": sol.l_end, "v_end_m_s": sol.v_end, "termination": sol.termination},
                {"I_dec_Ns": "N s", "I_acc_Ns": "N s", "I_dec_resting_Ns": "N s", "I_acc_resting_Ns": "N s",
                 "theta_start_deg": "deg", "theta_end_deg": "deg", "duration_s": "s", "l_end_m": "m",
                 "v_end_m_s": "m/s"}),
            "results/operating_point": AttrGroup(
                {"omega_c_rad_s": inp.omega_c, "omega_r_rad_s": inp.omega_r, "rolling_velocity_m_s": inp.rolling_velocity},
                {"omega_c_rad_s": "rad/s", "omega_r_rad_s": "rad/s", "rolling_velocity_m_s": "m/s"}),
            "results/summary": AttrGroup(summary, dict(SUMMARY_UNITS)),
            "results/wear": AttrGroup(wear, {k: ("m^3" if k.endswith("_m3") else "m^3/h") for k in wear},
                                      WEAR_DESCRIPTION),
        }
        provenance = {"model_version": MODEL_VERSION, "solver": f"reduced/{sol.method}", "solver_wall_s": sol.wall_s,
                      "dt_s": sol.dt if sol.dt is not None else float("nan"), "dt_choice": dt_choice}
        for k, v in sol.info.items():
            if np.isscalar(v):
                provenance[f"solver_{k}"] = v
        tables = {"results/impacts": "roller-cage impacts; zeno_closure = 1 marks an impact that closes a bounce sequence"}
        res = cls(None, data, groups, provenance=provenance, tables=tables, inputs=inp, solution=sol)
        res._parameters = p
        return res

    def description(self) -> str:
        return f"reduced model ({self.provenance.get('solver', 'reduced/?').split('/')[-1]})"

    # --- figures -----------------------------------------------------------------------------
    def plot_pass(self):
        """Fig. 8 analog: l_r, dl_r/dt and the cumulative I_dec and I_acc against θ over the no-load pass, the
        rear face and I_dec in the rear face's colour, the front face and I_acc in the front face's.

        The colours: :data:`~bearingsim.plotting.REAR`, :data:`~bearingsim.plotting.FRONT`."""
        from bearingsim.plotting import FRONT, REAR, legend_outside, subplots

        self.require("results/trace", "plot_pass()")  # read without it: not "no trace recorded"
        fig, ax = subplots(3, 1, figsize=(7.5, 7.5), sharex=True)
        if "results/trace/theta_deg" not in self.data:
            ax[0].text(0.5, 0.5, "no trace recorded", transform=ax[0].transAxes, ha="center")
            return fig
        th = self.get("trace/theta_deg")
        p = self.parameters
        ax[0].plot(th, self.get("trace/l_r") * 1e6, lw=1.0, color="0.2")
        ax[0].axhline(0.0, color=REAR, lw=1.0, ls="--", label="rear face")
        ax[0].axhline(p.bearing.pocket_clearance * 1e6, color=FRONT, lw=1.0, ls="-.", label="front face")
        ax[0].set_ylabel("roller position $l_r$ [µm]")
        ax[1].plot(th, self.get("trace/dl_r_dt"), lw=1.0, color="0.2")
        ax[1].set_ylabel("speed in the pocket\n$dl_r/dt$ [m/s]")
        s = self.summary
        i_acc = s["I_acc_mean_Ns"]
        dec = f"$I_{{dec}}$ = {s['I_dec_mean_Ns'] * 1e3:.3f} mN s"
        both = (f"{dec}, $I_{{acc}}$ = {i_acc * 1e3:.3f} mN s per pass" if i_acc
                else f"{dec} per pass, $I_{{acc}}$ = 0: no front-face impact")
        ax[2].plot(th, self.get("trace/I_dec_cumulative") * 1e3, lw=1.2, color=REAR, label="$I_{dec}$ (rear face)")
        if "results/trace/I_acc_cumulative" in self.data:  # archives written before it was recorded lack it
            ax[2].plot(th, self.get("trace/I_acc_cumulative") * 1e3, lw=1.2, color=FRONT, ls="--",
                       label="$I_{acc}$ (front face)" + ("" if i_acc else " = 0"))
        else:  # said in the legend, so that a missing curve is not read as I_acc = 0
            ax[2].plot([], [], lw=0, color=FRONT, label="$I_{acc}$: not recorded\nin this archive (an\nearlier version's)")
        ax[2].set_ylabel("cumulative impulse [mN s]")
        ax[2].set_xlabel("θ from the load-zone centre, in the direction of rotation [deg]")
        ax[0].set_title(f"{self.title()}\nc = {p.contact.drag_coefficient:g}, e = {p.contact.restitution:g}, "
                        f"{both}", fontsize=9)
        for a in ax:
            a.grid(alpha=0.3)
            a.axvline(180.0, color="0.6", lw=0.6, label="θ = 180° (top)")
        legend_outside(ax[0])
        legend_outside(ax[2])
        return fig


def simulate(p, sink=None, progress: bool = False, dt: float | None = None) -> ReducedResult:
    """Run the reduced model for the SI parameters ``p`` (see the module docstring).

    ``sink`` and ``progress`` are accepted for symmetry with the multibody model: one pass has no
    time series to stream and takes milliseconds. ``dt`` [s] overrides ``numerics.dt`` (euler only).
    """
    inp = PassInputs.from_parameters(p)
    dt, dt_choice = _step(p, inp, dt)
    sol = solve_pass(inp, p.reduced.method, dt, automatic=dt_choice.startswith("automatic"))
    return ReducedResult.from_solution(p, inp, sol, dt_choice)


def _step(p, inp: PassInputs, dt: float | None) -> tuple[float | None, str]:
    """(the time step [s] of the euler method, how it was chosen); (None, ...) for the event method."""
    if p.reduced.method != "euler":
        return None, "event-driven: no time step"
    if dt is not None:
        return dt, "numerics.dt_s"
    if p.numerics.dt is not None:
        return p.numerics.dt, "numerics.dt_s"
    return default_dt(inp), "automatic: 1/1000 of the largest allowed step (euler.max_stable_dt)"


def check_start(p, dt: float | None = None) -> None:
    """Refuse, without running, what :func:`simulate` would refuse before its first step: the time step
    (one line naming the key; :func:`bearingsim.reduced.euler.check_step`); the event method takes none."""
    if p.reduced.method == "euler":
        inp = PassInputs.from_parameters(p)
        step, how = _step(p, inp, dt)
        euler_check_step(inp, step, automatic=how.startswith("automatic"))
RESULT = ReducedResult
