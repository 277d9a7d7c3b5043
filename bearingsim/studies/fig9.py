"""Studies of the reduced model: the Fig. 9 analog (I_dec against speed) of `bearingsim validate`."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from bearingsim.reduced.core import PassInputs
from bearingsim.reduced.event import solve_event
from bearingsim.outputs import write_csv
from bearingsim.parameters import Parameters
from bearingsim.scenario import resolve

FIG9_SPEEDS_RPM = (500, 750, 1000, 1500, 2000, 3000, 4000, 5000, 6000)
FIG9_DRAG = (0.01, 0.02, 0.03)


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
    return resolve(raw, "bearingsim.reduced.studies")


def idec_per_rotation(rpm: float, drag: float = 0.02, previous: bool = False) -> float:
    """I_dec of one cage rotation [N s] by the event solver."""
    return solve_event(PassInputs.from_parameters(Parameters.from_scenario(paper_scenario(rpm, drag, previous))),
                       trace_points=0).I_dec


def fig9_table(speeds=FIG9_SPEEDS_RPM, drags=FIG9_DRAG) -> dict[str, np.ndarray]:
    """I_dec per rotation [N s] against speed: present model for each c, and the previous model (c = 0.02)."""
    table = {"speed_rpm": np.asarray(speeds, float)}
    for c in drags:
        table[f"I_dec_c{c:g}_Ns"] = np.array([idec_per_rotation(n, c) for n in speeds])
    table["I_dec_previous_c0.02_Ns"] = np.array([idec_per_rotation(n, 0.02, previous=True) for n in speeds])
    return table


def save_fig9(outdir: str | Path) -> list[Path]:
    """Write ``fig9_idec_vs_speed.csv`` and ``.png`` to ``outdir``; return their paths."""
    from bearingsim.archive import check_writable_dir
    from bearingsim.plotting import plt

    outdir = check_writable_dir(outdir)
    table = fig9_table()
    cols = list(table)
    csv_path = write_csv(outdir / "fig9_idec_vs_speed.csv", cols,
                         [[f"{table['speed_rpm'][i]:g}"] + [f"{table[c][i]:.6e}" for c in cols[1:]]
                          for i in range(len(table["speed_rpm"]))])

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    n = table["speed_rpm"]
    for c, mk in zip(FIG9_DRAG, "os^"):
        ax.plot(n, table[f"I_dec_c{c:g}_Ns"] * 1e3, marker=mk, label=f"present model, c = {c:g}")
    ax.plot(n, table["I_dec_previous_c0.02_Ns"] * 1e3, "k--", marker="x",
            label="previous model (no gravity, no resting contact), c = 0.02")
    ax.set_xlabel("inner ring speed [rpm]")
    ax.set_ylabel("$I_{dec}$ per cage rotation [mN s]")
    ax.set_title("Reduced model, NU214 reference bearing, 970 N, φ = 23.5° (Fig. 9 analog)", fontsize=9)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    png = outdir / "fig9_idec_vs_speed.png"
    from bearingsim.plotting import save_figure

    save_figure(fig, png, dpi=130, tight=False)  # atomic; a link or a user's file there is refused
    return [csv_path, png]
