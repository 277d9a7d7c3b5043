"""What-if sweeps: a scenario run over the product of values of one or more keys.

Every grid point is resolved and validated before the first run starts, so a bad value stops the
sweep at once with the key named. Each point writes its own archive; the sweep writes
``sweep.csv`` (the swept values and each run's summary) and ``sweep.png``.
"""
from __future__ import annotations

import csv
import itertools
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from bearingsim.errors import UserError
from bearingsim.scenario import load_scenario, parse_override

SUMMARY_KEYS = ("I_dec_mean_Ns", "I_dec_std_Ns", "I_acc_mean_Ns", "I_acc_std_Ns",
                "first_impact_speed_m_s", "first_impact_energy_J", "cage_slip", "load_zone_half_angle_deg")


def parse_param(item: str) -> tuple[str, list]:
    """``KEY=V1,V2,...`` → (key, values), each value read as a TOML value (bare words are strings)."""
    if "=" not in item:
        raise UserError(f"--param {item!r}: expected KEY=V1,V2,...")
    key, text = item.split("=", 1)
    values = [parse_override(f"{key}={v}")[1] for v in text.split(",") if v.strip()]
    if not values:
        raise UserError(f"--param {item!r}: no values")
    return key.strip(), values


def _point_name(base: str, combo: tuple[tuple[str, object], ...]) -> str:
    parts = [f"{k.split('.')[-1]}={v}" for k, v in combo]
    return "__".join([base, *parts]).replace("/", "_")


def _run_one(args):
    from bearingsim.simulation import run_scenario

    path, overrides, out, figures = args
    scenario = load_scenario(path, overrides)
    res = run_scenario(scenario, out, figures=figures, progress=False)
    return {k: float(v) for k, v in res.result.summary.items() if k in SUMMARY_KEYS}


def run_sweep(scenario_path, params: list[str], sets: list[str], outdir: Path, *, jobs: int = 1,
              figures: bool = True) -> Path:
    """Run the grid and return the path of ``sweep.csv``."""
    axes = [parse_param(p) for p in params]
    base = load_scenario(scenario_path, sets)
    points = []
    for values in itertools.product(*[vals for _, vals in axes]):
        combo = tuple((k, v) for (k, _), v in zip(axes, values))
        overrides = list(sets) + [f"{k}={_toml_value(v)}" for k, v in combo]
        name = _point_name(base.name, combo)
        overrides.append(f"name={_toml_value(name)}")
        load_scenario(scenario_path, overrides)  # validate every point before running any
        points.append((combo, (str(scenario_path), overrides, outdir / f"{name}.h5", figures)))
    if jobs < 1:
        raise UserError("--jobs: must be at least 1")
    outdir.mkdir(parents=True, exist_ok=True)
    if jobs == 1:
        summaries = [_run_one(p[1]) for p in points]
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            summaries = list(pool.map(_run_one, [p[1] for p in points]))
    csv_path = outdir / "sweep.csv"
    keys = [k for k, _ in axes]
    with open(csv_path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys + [k for k in SUMMARY_KEYS] + ["archive"])
        for (combo, args), summ in zip(points, summaries):
            w.writerow([v for _, v in combo] + [summ.get(k, "") for k in SUMMARY_KEYS] + [args[2].name])
    print(f"wrote {csv_path}")
    if figures:
        png = _plot(points, summaries, keys, outdir / "sweep.png")
        if png:
            print(f"wrote {png}")
    return csv_path


def _toml_value(v) -> str:
    import tomli_w

    return tomli_w.dumps({"v": v})[4:].strip()


def _plot(points, summaries, keys, path: Path):
    xs = [combo[0][1] for combo, _ in points]
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in xs):
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
    groups: dict = {}
    for (combo, _), s in zip(points, summaries):
        label = ", ".join(f"{k}={v}" for k, v in combo[1:]) or "I_dec"
        groups.setdefault(label, []).append((combo[0][1], s.get("I_dec_mean_Ns"), s.get("I_dec_std_Ns", 0.0)))
    for label, rows in groups.items():
        rows.sort()
        ax.errorbar([r[0] for r in rows], [r[1] for r in rows], yerr=[r[2] for r in rows],
                    marker="o", capsize=3, label=label)
    ax.set_xlabel(keys[0])
    ax.set_ylabel("I_dec per cage rotation [N s]")
    ax.grid(alpha=0.3)
    if len(groups) > 1:
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
