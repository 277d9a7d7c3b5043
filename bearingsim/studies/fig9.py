"""The Fig. 9 analog of ``bearingsim validate``: the reduced model's I_dec per cage rotation against speed,
for three drag coefficients and the paper's previous model (no gravity, no resting contact).

A study (:class:`Fig9`): one reduced-model case per speed and model variant, run on the sweep engine
(:func:`bearingsim.studies.run_studies`); its table is ``fig9_idec_vs_speed.csv`` and its figure
``fig9_idec_vs_speed.png``.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from bearingsim.outputs import is_own_png, write_csv
from bearingsim.scenario import resolve
from bearingsim.studies.engine import FINISHED, Study, case_of

FIG9_SPEEDS_RPM = (500, 750, 1000, 1500, 2000, 3000, 4000, 5000, 6000)
FIG9_DRAG = (0.01, 0.02, 0.03)
#: the study's table and figure, and the first bytes of the table (its header) as the study writes it
CSV_NAME, PNG_NAME, CSV_SIGNATURE = "fig9_idec_vs_speed.csv", "fig9_idec_vs_speed.png", b"speed_rpm,"


def paper_scenario(rpm: float, drag: float = 0.02, previous: bool = False, direction: str = "forward"):
    """The paper's reduced-model conditions (§2.3: 970 N, φ = 23.5°, e = 0.8) at ``rpm``.

    ``previous`` is the paper's previous model: no gravity and no resting-contact impulse.
    """
    raw = {
        "schema_version": 1,
        "name": f"paper_{rpm:g}rpm",
        "model": "reduced",
        "bearing": {"preset": "NU214-Suzuki2023"},
        "operating": {"inner_ring_speed_rpm": float(rpm), "radial_load_N": 970.0, "direction": direction,
                      "gravity": not previous},
        "lubrication": {"drag_coefficient": float(drag)},
        "reduced": {"method": "event", "load_zone_half_angle_deg": 23.5, "resting_contact": not previous},
        "numerics": {"rotations": 1},
    }
    return resolve(raw, "bearingsim.studies.fig9")


def idec_per_rotation(rpm: float, drag: float = 0.02, previous: bool = False) -> float:
    """I_dec of one cage rotation [N s] by the event solver (in this process, no archive)."""
    from bearingsim.parameters import Parameters
    from bearingsim.reduced.core import PassInputs
    from bearingsim.reduced.event import solve_event

    return solve_event(PassInputs.from_parameters(Parameters.from_scenario(paper_scenario(rpm, drag, previous))),
                       trace_points=0).I_dec


def reference_case(rpm: float, drag: float = 0.02, previous: bool = False):
    """The case of :func:`paper_scenario` (shared by the rig study: the same case runs once)."""
    return case_of(paper_scenario(rpm, drag, previous),
                   {"study": "fig9", "rpm": float(rpm), "drag": float(drag), "variant": "previous" if previous else "present"})


def column_name(drag: float, previous: bool) -> str:
    return f"I_dec_previous_c{drag:g}_Ns" if previous else f"I_dec_c{drag:g}_Ns"


class Fig9(Study):
    """I_dec per rotation against speed: the present model for each drag coefficient, and the previous
    model at c = 0.02. :attr:`table` holds the numbers after :meth:`finish` (NaN for a failed case)."""

    name = "fig9"

    def __init__(self, speeds=FIG9_SPEEDS_RPM, drags=FIG9_DRAG):
        self.speeds, self.drags = tuple(speeds), tuple(drags)
        self.variants = [(c, False) for c in self.drags] + [(0.02, True)]
        self.grid = {(col, i): reference_case(n, c, prev)
                     for c, prev in self.variants for col in [column_name(c, prev)] for i, n in enumerate(self.speeds)}
        self.cases = list(self.grid.values())
        self.outputs = [(CSV_NAME, CSV_SIGNATURE, "Fig. 9 table"), (PNG_NAME, is_own_png, "figure")]
        self.table: dict[str, np.ndarray] = {}

    def finish(self, outdir, records) -> list[Path]:
        table = {"speed_rpm": np.asarray(self.speeds, float)}
        for c, prev in self.variants:
            col = column_name(c, prev)
            table[col] = np.array([_idec(records[self.grid[col, i].hash]) for i in range(len(self.speeds))])
        self.table = table
        return save_fig9(outdir, table)


def _idec(record: dict) -> float:
    """I_dec per rotation of a finished reduced case (its summary), NaN for a failed one."""
    if record["status"] not in FINISHED:
        return math.nan
    return float(record["summary"]["I_dec_mean_Ns"])


def fig9_table(speeds=FIG9_SPEEDS_RPM, drags=FIG9_DRAG, *, outdir=None, jobs: int = 1, engine=None) -> dict[str, np.ndarray]:
    """Run the :class:`Fig9` study (in ``outdir``, default a temporary folder) and return its table:
    ``speed_rpm`` and I_dec per rotation [N s] per column."""
    from bearingsim.studies.engine import in_folder

    study = Fig9(speeds, drags)
    in_folder([study], outdir, jobs=jobs, engine=engine)
    return study.table


def save_fig9(outdir: str | Path, table: dict[str, np.ndarray]) -> list[Path]:
    """Write ``fig9_idec_vs_speed.csv`` and ``.png`` to ``outdir``; return their paths."""
    from bearingsim.plotting import subplots, save_figure

    outdir = Path(outdir)
    cols = list(table)
    csv_path = write_csv(outdir / CSV_NAME, cols,
                         [[f"{table['speed_rpm'][i]:g}"] + [f"{table[c][i]:.6e}" for c in cols[1:]]
                          for i in range(len(table["speed_rpm"]))])

    fig, ax = subplots(figsize=(6.5, 4.5))
    n = table["speed_rpm"]
    for c, mk in zip([c for c in cols[1:] if "previous" not in c], "os^"):
        ax.plot(n, table[c] * 1e3, marker=mk, label=f"present model, c = {c[len('I_dec_c'):-len('_Ns')]}")
    for c in [c for c in cols[1:] if "previous" in c]:
        ax.plot(n, table[c] * 1e3, "k--", marker="x",
                label=f"previous model (no gravity, no resting contact), c = {c[len('I_dec_previous_c'):-len('_Ns')]}")
    ax.set_xlabel("inner ring speed [rpm]")
    ax.set_ylabel("$I_{dec}$ per cage rotation [mN s]")
    ax.set_title("Reduced model, NU214 reference bearing, 970 N, φ = 23.5° (Fig. 9 analog)", fontsize=9)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    png = save_figure(fig, outdir / PNG_NAME, dpi=130, tight=False)
    return [csv_path, png]


def read_fig9(path) -> dict[str, np.ndarray]:
    """The table ``fig9_idec_vs_speed.csv`` holds (as :attr:`Fig9.table`: ``speed_rpm`` and I_dec per
    rotation [N s] per column; NaN for a failed case)."""
    import csv

    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    return {name: np.array([float(r[j]) for r in rows[1:]]) for j, name in enumerate(rows[0])}


def column_label(col: str) -> str:
    """``I_dec_c0.01_Ns`` -> ``c = 0.01``; ``I_dec_previous_c0.02_Ns`` -> ``previous c = 0.02``."""
    name = col.removeprefix("I_dec_").removesuffix("_Ns")
    prev = name.startswith("previous_")
    return ("previous " if prev else "") + "c = " + name.removeprefix("previous_").removeprefix("c")


def format_table(table: dict[str, np.ndarray]) -> str:
    """The Fig. 9 table for the terminal: one row per speed, I_dec per cage rotation [mN s] of each drag
    coefficient and of the previous model (n/a: a failed case)."""
    cols = [c for c in table if c != "speed_rpm"]
    labels = [column_label(c) for c in cols]
    widths = [max(8, len(x)) for x in labels]
    lines = ["Fig. 9 analog: the reduced model's I_dec per cage rotation [mN s] (NU214, 970 N, φ = 23.5°; "
             "previous: no gravity, no resting contact)",
             f"  {'rpm':>6s}  " + "  ".join(f"{x:>{w}s}" for x, w in zip(labels, widths))]
    for i, n in enumerate(table["speed_rpm"]):
        cells = [f"{table[c][i] * 1e3:{w}.3f}" if math.isfinite(table[c][i]) else f"{'n/a':>{w}s}"
                 for c, w in zip(cols, widths)]
        lines.append(f"  {n:6g}  " + "  ".join(cells))
    return "\n".join(lines)
