"""The paper's measurement rig as a scene, against the reduced model (``bearingsim validate``).

The paper validated its reduced model against impulses measured by load cells in one pocket of a
running bearing (Suzuki et al. 2023, Sec. 2.1, Table 2, Fig. 9: 970 N, forward, up to 4000 rpm). That
pocket's faces were machined flat; the other 15 were the cage's own. :func:`rig_scenario` is that
bearing in the full multibody scene (pocket 0 flat, ``scenarios/rig_<rpm>rpm.toml``), and the study
:class:`Rig` compares pocket 0's I_dec per cage rotation with the reduced model's at the same speed (the
paper's conditions, phi = 23.5 deg: the Fig. 9 study's case at c = 0.02, which runs once when both
studies run together).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from bearingsim.outputs import is_own_png, write_csv
from bearingsim.scenario import resolve
from bearingsim.studies.engine import FINISHED, Study, batch_sem, case_of, load_result
from bearingsim.studies.fig9 import reference_case
from bearingsim.wording import counted

RIG_SPEEDS_RPM = (500, 1000, 2000, 3000, 4000)
RIG_ROTATIONS = 20

__all__ = ["RIG_ROTATIONS", "RIG_SPEEDS_RPM", "Rig", "batch_sem", "format_table", "read_rig", "rig_scenario", "rig_table",
           "save_rig"]


def rig_scenario(rpm: float, rotations: int = RIG_ROTATIONS, warmup: int = 1):
    """The rig scene at ``rpm`` (the content of ``scenarios/rig_<rpm>rpm.toml``)."""
    raw = {
        "schema_version": 1, "name": f"rig_{rpm:g}rpm", "model": "multibody",
        "bearing": {"preset": "NU214-Suzuki2023"},
        "operating": {"inner_ring_speed_rpm": rpm, "direction": "forward", "radial_load_N": 970.0},
        "multibody": {"scene": "full", "flat_pockets": [0]},
        "numerics": {"rotations": rotations, "warmup_rotations": warmup},
    }
    return resolve(raw, "bearingsim.studies.rig")


def rig_row(rpm: float, rotations: int, result, reduced_I_dec_Ns: float) -> dict:
    """One speed's row of the rig table from the rig scene's result and the reduced model's I_dec. Pocket
    0's scatter over rotations (std) is NaN from fewer than 2 rotations, as its standard error is
    (:func:`bearingsim.stats.batch_sem`): one rotation has no scatter to show, not a scatter of 0."""
    d = result.per_rotation["I_dec"]
    a = result.per_rotation["I_acc"]
    return {
        "rpm": rpm, "rotations": rotations,
        "pocket0_I_dec_mean_Ns": float(d[:, 0].mean()),
        "pocket0_I_dec_std_Ns": float(d[:, 0].std()) if len(d) >= 2 else float("nan"),
        "pocket0_I_dec_sem_Ns": batch_sem(d[:, 0]),
        "pocket0_I_acc_mean_Ns": float(a[:, 0].mean()),
        "arc_pockets_I_dec_mean_Ns": float(d[:, 1:].mean()), "arc_pockets_I_dec_std_Ns": float(d[:, 1:].std()),
        "reduced_I_dec_Ns": reduced_I_dec_Ns,
        "theta_deg": result.get("theta_deg"), "F_acc_pocket0": result.get("force_vs_theta_acc")[:, 0],
        "F_dec_pocket0": result.get("force_vs_theta_dec")[:, 0],
        "load_zone_half_angle_deg": result.summary["load_zone_half_angle_deg"],
    }


class Rig(Study):
    """The rig scene at each speed beside the reduced model: two cases per speed. :attr:`rows` holds
    one dict per speed after :meth:`finish`; a speed whose rig or reduced case failed has no row
    (:attr:`missing` names it)."""

    name = "rig"

    def __init__(self, speeds=RIG_SPEEDS_RPM, rotations: int = RIG_ROTATIONS):
        self.speeds, self.rotations = [float(n) for n in speeds], int(rotations)
        self.pairs = [(case_of(rig_scenario(n, self.rotations), {"study": "rig", "rpm": n}), reference_case(n))
                      for n in self.speeds]
        self.cases = [c for pair in self.pairs for c in pair]
        self.outputs = [(CSV_NAME, CSV_SIGNATURE, "rig table"),
                        (FIGURE_NAMES[0], is_own_png, "figure"), (FIGURE_NAMES[1], is_own_png, "figure")]
        self.rows: list[dict] = []
        self.missing: list[float] = []

    def finish(self, outdir, records) -> list[Path]:
        self.rows, self.missing = [], []
        for n, (rig, ref) in zip(self.speeds, self.pairs):
            r, q = records[rig.hash], records[ref.hash]
            if r["status"] not in FINISHED or q["status"] not in FINISHED:
                self.missing.append(n)
                continue
            self.rows.append(rig_row(n, self.rotations, load_result(outdir, r), float(q["summary"]["I_dec_mean_Ns"])))
        return save_rig(outdir, self.rows) if self.rows else []


def rig_table(speeds=RIG_SPEEDS_RPM, rotations: int = RIG_ROTATIONS, jobs: int = 2, *, outdir=None,
              engine=None) -> list[dict]:
    """Run the :class:`Rig` study (``jobs`` local processes or ``engine``; in ``outdir``, default a
    temporary folder) and return one dict per speed."""
    from bearingsim.studies.engine import in_folder

    study = Rig(speeds, rotations)
    in_folder([study], outdir, jobs=jobs, engine=engine)
    return study.rows


CSV_COLUMNS = ("rpm", "rotations", "pocket0_I_dec_mean_Ns", "pocket0_I_dec_std_Ns", "pocket0_I_dec_sem_Ns",
               "pocket0_I_acc_mean_Ns", "arc_pockets_I_dec_mean_Ns", "arc_pockets_I_dec_std_Ns", "reduced_I_dec_Ns",
               "pocket0_over_reduced")
#: the study's table, the first bytes of it (its header) and its figures (I_dec against speed; pocket 0's
#: forces, the Fig. 5 analog)
CSV_NAME, CSV_SIGNATURE = "rig_idec_vs_speed.csv", b"rpm,rotations,"
FIGURE_NAMES = ("rig_idec_vs_speed.png", "rig_pocket0_forces.png")


def read_rig(path) -> list[dict]:
    """The rows ``rig_idec_vs_speed.csv`` holds (the numbers of :attr:`Rig.rows`, :data:`CSV_COLUMNS`)."""
    import csv

    with open(path, newline="", encoding="utf-8") as fh:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(fh)]


def format_table(rows: list[dict], rotations: int) -> str:
    """The rig table for the terminal, as ``bearingsim validate`` prints it: pocket 0's I_dec (mean ± std
    over rotations; n/a from one rotation), the reduced model's, their ratio and the arc pockets' mean."""
    lines = [f"rig scene (pocket 0 flat), 1 warm-up + {counted(rotations, 'rotation')}, against the reduced model:",
             f"  {'rpm':>6s} {'pocket 0 I_dec [mN s]':>24s} {'reduced [mN s]':>15s} {'ratio':>6s} {'arc pockets [mN s]':>19s}"]
    for r in rows:
        std = r["pocket0_I_dec_std_Ns"] * 1e3
        std = f"{std:5.2f}" if math.isfinite(std) else "  n/a"  # one rotation: no scatter (tables: n/a)
        lines.append(f"  {r['rpm']:6g} {r['pocket0_I_dec_mean_Ns'] * 1e3:11.2f} ± {std} (std) "
                     f"{r['reduced_I_dec_Ns'] * 1e3:15.2f} {r['pocket0_I_dec_mean_Ns'] / r['reduced_I_dec_Ns']:6.2f} "
                     f"{r['arc_pockets_I_dec_mean_Ns'] * 1e3:19.2f}")
    return "\n".join(lines)


def _spread_points(ax, n, rows, name: str, marker: str, color: str, label: str) -> None:
    """``name``'s I_dec mean ± std against the speeds ``n``; a std of n/a (one rotation: the table's n/a) is
    no bar and an open marker, and the legend's label says so."""
    from bearingsim.plotting import mark_without_error

    y, std = (np.array([r[f"{name}_I_dec_{c}_Ns"] * 1e3 for r in rows], dtype=float) for c in ("mean", "std"))
    none = np.isnan(std) & np.isfinite(y)
    if none.any():
        some = "" if none.all() else f", {int(none.sum())} of {counted(len(y), 'speed')}"
        label += f" (open marker: std n/a{some})"
    ax.errorbar(n, y, yerr=std, fmt=marker, color=color, capsize=3, label=label)
    mark_without_error(ax, n, y, std, color, marker)


def save_rig(outdir, rows: list[dict]) -> list[Path]:
    """Write ``rig_idec_vs_speed.{csv,png}`` and ``rig_pocket0_forces.png`` (Fig. 5 analog) to ``outdir``."""
    from bearingsim.plotting import FRONT, REAR, legend_outside, subplots, save_figure

    outdir = Path(outdir)
    cells = []
    for r in rows:
        vals = {**r, "pocket0_over_reduced": r["pocket0_I_dec_mean_Ns"] / r["reduced_I_dec_Ns"]}
        cells.append([f"{vals[c]:g}" if c in ("rpm", "rotations") else f"{vals[c]:.6e}" for c in CSV_COLUMNS])
    csv_path = write_csv(outdir / CSV_NAME, CSV_COLUMNS, cells)

    n = np.array([r["rpm"] for r in rows])
    fig, ax = subplots(figsize=(8.5, 4.5))
    ax.plot(n, [r["reduced_I_dec_Ns"] * 1e3 for r in rows], "k-", marker="o",
            label="reduced model (paper's model, φ = 23.5°)")
    ax.fill_between(n, [r["reduced_I_dec_Ns"] * 0.75e3 for r in rows], [r["reduced_I_dec_Ns"] * 1.25e3 for r in rows],
                    color="0.85", label="reduced model ± 25 %")
    _spread_points(ax, n, rows, "pocket0", "s", "C0", "rig scene, flat pocket 0: mean ± std over rotations")
    _spread_points(ax, n, rows, "arc_pockets", "^", "C3", "rig scene, the 15 arc pockets: mean ± std")
    ax.set_xlabel("inner ring speed [rpm]")
    ax.set_ylabel("$I_{dec}$ per cage rotation [mN s]")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    rot = rows[0]["rotations"] if rows else 0
    ax.set_title(f"The paper's rig as a scene (NU214, 970 N, forward, 1 warm-up + {counted(rot, 'rotation')})\n"
                 "against the reduced model (Fig. 9 analog)", fontsize=9)
    legend_outside(ax)
    png = save_figure(fig, outdir / FIGURE_NAMES[0])

    fig, axes = subplots(len(rows), 1, figsize=(8.5, 1.8 * len(rows) + 0.8), sharex=True, squeeze=False)
    for ax, r in zip(axes[:, 0], rows):
        ax.plot(r["theta_deg"], r["F_acc_pocket0"], lw=0.8, color=FRONT, label="$F_{acc}$ (front face)")
        ax.plot(r["theta_deg"], -r["F_dec_pocket0"], lw=0.8, color=REAR, label="$-F_{dec}$ (rear face)")
        phi = r["load_zone_half_angle_deg"]
        ax.axvline(phi, color="grey", lw=0.7, ls=":", label="load-zone limits")
        ax.axvline(360 - phi, color="grey", lw=0.7, ls=":")
        ax.set_ylabel(f"{r['rpm']:g} rpm\nforce [N]")
        ax.grid(alpha=0.3)
    axes[0, 0].set_title("Flat pocket 0 of the rig scene: mean circumferential pocket force against θ (Fig. 5 analog)",
                         fontsize=9)
    legend_outside(axes[0, 0])
    axes[-1, 0].set_xlabel("θ from the load-zone centre, in the direction of rotation [deg]")
    axes[-1, 0].set_xlim(0, 360)
    png2 = save_figure(fig, outdir / FIGURE_NAMES[1])
    return [csv_path, png, png2]
