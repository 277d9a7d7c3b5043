"""Figures of a sweep, drawn from its index (``sweep.h5``) alone.

* one numeric axis: I_dec and I_acc per cage rotation against the swept value, with error bars of one
  standard error (``I_*_sem_Ns``; see :func:`bearingsim.sweeps.worker.standard_errors`);
* two numeric axes (a product grid): a heat map of I_dec per cage rotation;
* more axes: one line per combination of the other axes (at most 8), else no figure;
* zipped axes: a line plot against the first of them. Explicit extra cases are not drawn.

Axes are labelled with the parameter's name and unit, read from the key's unit suffix.
Failed and not-run cases are gaps (NaN), never zeros.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from bearingsim.sweeps.index import name_of, read_index, unit_of

#: every figure a sweep may draw into its folder (a sweep checks them before it starts)
FIGURE_NAMES = ("sweep_I.png", "sweep_map.png")

MAX_LINES = 8


def axis_label(key: str) -> str:
    """``operating.inner_ring_speed_rpm`` -> ``inner ring speed [rpm]`` (no unit: the name alone)."""
    unit = unit_of(key)
    return f"{name_of(key)} [{unit}]" if unit != "1" else name_of(key)


def _numeric(col) -> bool:
    return np.asarray(col).dtype.kind == "f"


def plot_sweep_index(index_path: str | Path, outdir: str | Path | None = None) -> list[Path]:
    """Draw the sweep's figures from its index and return the PNG paths written.

    Parameters
    ----------
    index_path : path
        The sweep's ``sweep.h5``.
    outdir : path, optional
        Folder for the PNGs (default: the index's folder). Files are ``sweep_I.png`` (line plot)
        or ``sweep_map.png`` (heat map).
    """
    from bearingsim.plotting import plt

    index_path = Path(index_path)
    outdir = Path(outdir) if outdir is not None else index_path.parent
    outdir.mkdir(parents=True, exist_ok=True)
    cols, meta = read_index(index_path)
    n = meta["grid_rows"]
    cols = {k: v[:n] for k, v in cols.items()}  # the grid only; explicit extra cases are not on it
    numeric = [k for k in meta["grid"] if _numeric(cols[k]) and np.isfinite(cols[k]).any()]
    if not numeric or "I_dec_mean_Ns" not in cols or n == 0:
        return []
    title = f"sweep of {Path(str(meta.get('scenario', ''))).stem or 'cases'}"
    if meta.get("mode") == "zip":  # zipped axes move together: the first numeric one is the abscissa
        title += " (zipped with " + ", ".join(
            f"{name_of(k)} {np.nanmin(cols[k]):g}–{np.nanmax(cols[k]):g}" for k in numeric[1:]) + ")" \
            if len(numeric) > 1 else ""
        axes = numeric[:1]
    elif len(meta["grid"]) == 2 and len(numeric) == 2:
        return [_heat_map(plt, cols, numeric, outdir / "sweep_map.png", title)]
    else:  # abscissa: the first numeric axis; one line per value of the others (text values too)
        axes = numeric[:1] + [k for k in meta["grid"] if k != numeric[0]]
    return [_lines(plt, cols, axes, outdir / "sweep_I.png", title)] if _line_groups(cols, axes) else []


def _line_groups(cols, axes) -> dict | None:
    others = axes[1:]
    groups: dict[tuple, list[int]] = {}
    for i in range(len(cols["case"])):
        if not math.isfinite(cols[axes[0]][i]):
            continue
        groups.setdefault(tuple(cols[k][i] for k in others), []).append(i)
    return groups if len(groups) <= MAX_LINES else None


def _lines(plt, cols, axes, path: Path, title: str) -> Path:
    x_key = axes[0]
    groups = _line_groups(cols, axes)
    fig, ax = plt.subplots(figsize=(6.5, 4.2), constrained_layout=True)
    for gi, (other, idx) in enumerate(sorted(groups.items())):
        idx = sorted(idx, key=lambda i: cols[x_key][i])
        x = np.asarray(cols[x_key])[idx]
        extra = ", ".join(f"{name_of(k)} = {_show(v)} {unit_of(k) if unit_of(k) != '1' else ''}".strip()
                          for k, v in zip(axes[1:], other))
        for name, style in (("I_dec", "-o"), ("I_acc", "--s")):
            if f"{name}_mean_Ns" not in cols:
                continue
            y = np.asarray(cols[f"{name}_mean_Ns"])[idx] * 1e3
            sem = cols.get(f"{name}_sem_Ns")
            err = np.nan_to_num(np.asarray(sem)[idx] * 1e3) if sem is not None else None
            label = f"$I_{{{name[2:]}}}$" + (f" ({extra})" if extra else "")
            ax.errorbar(x, y, yerr=err, fmt=style, color=f"C{gi}", capsize=3, ms=4, label=label)
    ax.set_xlabel(axis_label(x_key))
    ax.set_ylabel("impulse per pocket and cage rotation [mN s]\n(error bars: ±1 standard error)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    from bearingsim.plotting import save_figure

    return save_figure(fig, path, tight=False)


def _show(v) -> str:
    return f"{v:g}" if isinstance(v, (float, np.floating)) else str(v)


def _heat_map(plt, cols, axes, path: Path, title: str) -> Path:
    xk, yk = axes
    x = np.asarray(cols[xk])
    y = np.asarray(cols[yk])
    z = np.asarray(cols["I_dec_mean_Ns"]) * 1e3
    xs = np.unique(x[np.isfinite(x)])
    ys = np.unique(y[np.isfinite(y)])
    grid = np.full((ys.size, xs.size), np.nan)
    for xi, yi, zi in zip(x, y, z):
        if math.isfinite(xi) and math.isfinite(yi):
            grid[np.searchsorted(ys, yi), np.searchsorted(xs, xi)] = zi
    fig, ax = plt.subplots(figsize=(6.5, 4.8), constrained_layout=True)
    mesh = ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(grid), shading="flat", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="$I_{dec}$ per pocket and cage rotation [mN s]")
    ax.set_xlabel(axis_label(xk))
    ax.set_ylabel(axis_label(yk))
    n_gap = int(np.isnan(grid).sum())
    ax.set_title(title + (f" ({n_gap} cells failed or not run: blank)" if n_gap else ""), fontsize=9)
    from bearingsim.plotting import save_figure

    return save_figure(fig, path, tight=False)


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around sorted centres (half-way between neighbours)."""
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5]) if v[0] == 0 else np.array([v[0] * 0.95, v[0] * 1.05])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])
