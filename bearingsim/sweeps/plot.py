"""Figures of a sweep, drawn from its index (``sweep.h5``) alone.

Every sweep draws something, or says in one line (the ``notes``) why a figure could not be drawn:

* the grid of its axes (``sweep_I.png`` or ``sweep_map.png``), I_dec and I_acc per cage rotation in two
  panels, error bars of one standard error (``I_*_sem_Ns``; see
  :func:`bearingsim.stats.impulse_standard_errors`). A point without one (``n/a`` in the tables: one
  recorded rotation, or an index without the column) has no bar and an open marker, a case chart's bar
  is hatched, a map's cell value starred, and the panel's title says so (:func:`error_title`); a map's
  title gives its cells' largest standard error and the difference the tables' test resolves instead of
  bars (:func:`map_title`):

  - one axis, or zipped axes: a line plot against the (first numeric) axis; the other zipped keys' values
    in a tick row each under its values, named in the axis label (their change is not the axis's); a line
    of fewer than 3 values along the axis is markers alone (two joined would read as a trend), and an
    impulse axis starts at 0 when no value is negative;
  - two axes of a product, both numeric or both text: heat maps (``sweep_map.png``), one cell per
    sampled pair, the sampled values ticked (rounded as far as their step allows) and each cell's value
    written in it; the I_acc map under the I_dec map, the figure at most 9 in wide and its texts legible
    in a report's 6.5 in text width;
  - otherwise: one line per combination of the other axes (at most 8).

  The lines and bars of I_dec are drawn in the house colour of the rear face, those of I_acc in the front
  face's (:data:`bearingsim.plotting.REAR`, :data:`~bearingsim.plotting.FRONT`); the lines of one panel
  differ in marker and line style.

  A text key (``bearing.cage_guidance``) is a categorical axis: its values in the order swept.
* explicit extra ``[[cases]]`` (or a sweep of cases alone): a per-case chart of every case
  (``sweep_cases.png``), each labelled with its swept values.

Titles name the sweep as one of its base scenario over its varied keys (``sweep of paper_3000rpm over inner
ring speed (6 cases)``: no case need run at the base's own values), and under it what every case shares; a
panel's title is wrapped to the panel's width (:func:`bearingsim.plotting.fit_titles`). Axes are labelled
with the parameter's name and unit, read from the key's unit suffix. Failed and not-run cases are gaps (NaN),
never zeros.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from bearingsim.plotting import (FRONT, LINE_STYLES, REAR, error_title, fit_suptitle, fit_titles,
                                 hatch_without_error, mark_without_error)
from bearingsim.scenario import is_integer_key
from bearingsim.sweeps.index import index_batches, name_of, read_index, unit_of
from bearingsim.wording import counted, distinct_texts

#: every figure a sweep may draw into its folder (a sweep checks them before it starts)
FIGURE_NAMES = ("sweep_I.png", "sweep_map.png", "sweep_cases.png")

MAX_LINES = 8
MAX_CASES = 60  # most cases a per-case chart labels one by one
MAP_TICKS = 20  # most labelled ticks on a heat map's axis (a longer axis labels every k-th value)
ZIP_TICKS = 10  # most labelled ticks on a zipped sweep's abscissa (each a column of the zipped keys' values)
MAP_TEXT_CELLS = 20  # most rows of a heat map that still get their values written in the cells
MAP_TEXT_COLUMNS = 12  # most columns that do: 7 pt values of 5 characters fill a column at a report's width
MAP_WIDTH_IN = (6.0, 9.0)  # width of a heat map [in], its panels one above the other: 2.4 in + 0.7 in per column
MAP_CELLS_IN = (2.4, 4.5)  # height of a panel's cells [in]: 0.4 in per row within these bounds
PRINT_WIDTH_IN = 6.5  # a report's text width [in]: a map's texts are at least MIN_PRINT_PT once shrunk to it
MIN_PRINT_PT = 7.0
MIN_JOINED = 3  # fewest values along a line figure's axis joined by a line (two joined would read as a trend)
QUANTITIES = (("I_dec", "$I_{dec}$"), ("I_acc", "$I_{acc}$"))
Y_LABEL = "per pocket and cage rotation [mN s]"
FACE_COLOURS = {"I_dec": REAR, "I_acc": FRONT}  # the house colours: I_dec the rear face's, I_acc the front's


def axis_label(key: str) -> str:
    """``operating.inner_ring_speed_rpm`` -> ``inner ring speed [rpm]`` (no unit: the name alone)."""
    unit = unit_of(key)
    return f"{name_of(key)} [{unit}]" if unit != "1" else name_of(key)


def _numeric(col) -> bool:
    return np.asarray(col).dtype.kind == "f"


def _present(col) -> np.ndarray:
    """Rows where a key has a value (numbers: finite; text: non-empty)."""
    col = np.asarray(col)
    return np.isfinite(col) if _numeric(col) else np.array([str(v) != "" for v in col], dtype=bool)


def _sampled(col, rows) -> list:
    """The distinct values of a key over ``rows``: sorted numbers, or text in the order swept."""
    vals = [col[i] for i in rows]
    if _numeric(col):
        return sorted({float(v) for v in vals if math.isfinite(v)})
    return list(dict.fromkeys(str(v) for v in vals if str(v) != ""))


def sweep_title(meta: dict, n_cases: int) -> str:
    """``sweep of paper_3000rpm over inner ring speed × pocket clearance (12 cases)``: the base scenario and
    the sweep's varied keys; zipped keys ``speed, drag coefficient (zipped, 4 cases)``; extra cases ``; 2 cases
    over restitution, direction``; a second line ``every case: ...``, what the cases share
    (:func:`sweep_title_lines`)."""
    head, shared = sweep_title_lines(meta, n_cases)
    return head + (f"\nevery case: {shared}" if shared else "")


def sweep_title_lines(meta: dict, n_cases: int) -> tuple[str, str]:
    """(the sweep's title, what its cases share or ""): the title names the base scenario as what is swept,
    never as what ran (a sweep of paper_3000rpm over 500-6000 rpm has no case at 3000 rpm)."""
    keys = list(meta.get("axes", []))
    grid = list(meta.get("grid", []))
    n_grid = min(int(meta.get("grid_rows", n_cases)), n_cases) if grid else 0
    sep = " × " if meta.get("mode") == "product" else ", "
    zipped = "zipped, " if meta.get("mode") == "zip" and len(grid) > 1 else ""
    parts = [f"{sep.join(name_of(k) for k in grid)} ({zipped}{counted(n_grid, 'case')})"] if grid else []
    extra = [k for k in keys if k not in grid]
    if n_cases > n_grid:  # the cases off the grid, with the keys they set
        parts.append(f"{counted(n_cases - n_grid, 'case')}" + (" over " + ", ".join(map(name_of, extra)) if extra
                                                               else " off the grid"))
    what = "; ".join(parts) or counted(n_cases, "case")
    base = _base_name(meta)
    head = f"sweep of {base}{' over ' if grid else ': '}{what}" if base else f"sweep of {what}"
    shared = str(meta.get("context") or "")  # what the cases share (older indexes: none), after the base's name
    return head, shared.removeprefix(f"{base}: ") if base else shared


def _base_name(meta: dict) -> str:
    """The name of a sweep's base scenario: the one it stores, else its file's stem; "" for a sweep of cases
    without one."""
    import tomllib

    try:
        name = tomllib.loads(meta.get("scenario_toml") or "").get("name")
    except tomllib.TOMLDecodeError:
        name = None
    if isinstance(name, str) and name:
        return name
    return Path(str(meta["scenario"])).stem if meta.get("scenario") else ""


def plot_sweep_index(index_path: str | Path, outdir: str | Path | None = None,
                     notes: list[str] | None = None) -> list[Path]:
    """Draw the sweep's figures from its index and return the PNG paths written.

    Parameters
    ----------
    index_path : path
        The sweep's ``sweep.h5``.
    outdir : path, optional
        Folder for the PNGs (default: the index's folder): ``sweep_I.png`` (lines), ``sweep_map.png``
        (heat maps) and, with extra cases, ``sweep_cases.png`` (per-case chart).
    notes : list, optional
        Receives one line for each figure that could not be drawn, and why.
    """
    notes = notes if notes is not None else []
    index_path = Path(index_path)
    outdir = Path(outdir) if outdir is not None else index_path.parent
    outdir.mkdir(parents=True, exist_ok=True)
    cols, meta = read_index(index_path)
    total = len(cols["case"])
    n = min(meta["grid_rows"], total)
    if "I_dec_mean_Ns" not in cols or not np.isfinite(cols["I_dec_mean_Ns"]).any():
        notes.append("no figure: no case has a result (every case failed or was not run)")
        return []
    title = sweep_title(meta, total)
    written: list[Path] = []
    grid = [k for k in meta["grid"] if k in cols]
    if n and grid:
        path = _grid_figure(cols, meta, grid, range(n), outdir, title, notes)
        if path is not None:
            written.append(path)
    if n < total:  # extra cases (or cases alone): not on a grid
        if total > MAX_CASES:
            notes.append(f"no per-case figure: {total} cases are more than the {MAX_CASES} one chart labels")
        else:
            written.append(_cases_chart(cols, meta, outdir / "sweep_cases.png", title))
    return written


def _grid_figure(cols, meta, grid, rows, outdir, title, notes) -> Path | None:
    rows = list(rows)
    numeric = [k for k in grid if _numeric(cols[k]) and np.isfinite(cols[k][rows]).any()]
    if meta.get("mode") == "zip":  # zipped axes move together: one abscissa, the others a tick row each
        x_key = (numeric or grid)[0]
        return _lines(cols, [x_key], rows, outdir / "sweep_I.png", title, notes,
                      zipped=[k for k in grid if k != x_key])
    if len(grid) == 2 and len(numeric) != 1:  # both numeric or both text: a map of the pairs
        return _heat_map(cols, meta, grid, rows, outdir / "sweep_map.png", title)
    axes = numeric[:1] + [k for k in grid if k not in numeric[:1]]  # numeric abscissa when there is one
    return _lines(cols, axes, rows, outdir / "sweep_I.png", title, notes)


def _positions(cols, key, rows):
    """(abscissa per row, tick positions, tick labels or None): numbers as they are, text by rank."""
    if _numeric(cols[key]):
        return np.asarray(cols[key], dtype=float), None, None
    cats = _sampled(cols[key], rows)
    pos = {c: float(i) for i, c in enumerate(cats)}
    x = np.array([pos.get(str(v), math.nan) for v in cols[key]])
    return x, list(range(len(cats))), cats


def _lines(cols, axes, rows, path: Path, title: str, notes, zipped=()) -> Path | None:
    x_key, others = axes[0], axes[1:]
    x_all, ticks, tick_labels = _positions(cols, x_key, rows)
    groups: dict[tuple, list[int]] = {}
    texts = {k: distinct_texts(list(cols[k])) for k in others}  # each line's values, told apart
    for i in rows:
        if math.isfinite(x_all[i]):
            groups.setdefault(tuple(texts[k][i] for k in others), []).append(i)
    if len(groups) > MAX_LINES:
        notes.append(f"no line figure: {len(groups)} combinations of "
                     + ", ".join(name_of(k) for k in others) + f" are more than the {MAX_LINES} lines one figure shows")
        return None
    from bearingsim.plotting import subplots

    fig, panels = subplots(1, 2, figsize=(10, 4.2), sharex=True, constrained_layout=True)
    for gi, (other, idx) in enumerate(groups.items()):  # each panel in its face's colour; a line's own style
        marker, ls = LINE_STYLES[gi % len(LINE_STYLES)]
        idx = sorted(idx, key=lambda i: x_all[i])
        x = x_all[idx]
        extra = ", ".join(f"{name_of(k)} = {v} {unit_of(k) if unit_of(k) != '1' else ''}".strip()
                          for k, v in zip(others, other))
        for ax, (name, sym) in zip(panels, QUANTITIES):
            if f"{name}_mean_Ns" not in cols:
                continue
            y = np.asarray(cols[f"{name}_mean_Ns"])[idx] * 1e3
            err = _sem_mN_s(cols, name, len(x_all))[idx]  # NaN: no bar (matplotlib draws none), not a 0 bar
            # a line says the values between are in between: categories (text values by rank) have none
            joined = ticks is None and len(set(x)) >= MIN_JOINED
            ax.errorbar(x, y, yerr=_bar_lengths(err), marker=marker, ls=ls if joined else "none",
                        color=FACE_COLOURS[name], capsize=3, ms=4, label=extra or None)
            mark_without_error(ax, x, y, err, FACE_COLOURS[name], marker, ms=4)  # no error: an open marker
    drawn = [i for idx in groups.values() for i in idx]
    for ax, (name, sym) in zip(panels, QUANTITIES):
        ax.set_xlabel(axis_label(x_key))
        ax.set_ylabel(f"{sym} {Y_LABEL}")
        y = np.asarray(cols.get(f"{name}_mean_Ns", np.full(len(x_all), math.nan)), dtype=float)
        shown = [i for i in drawn if math.isfinite(y[i])]
        ax.set_title(_titled(sym, error_title(_sem_mN_s(cols, name, len(x_all))[shown])), fontsize=9)
        if zipped:
            _zipped_ticks(ax, cols, x_key, zipped, drawn, x_all, tick_labels)
        elif ticks is not None:
            ax.set_xticks(ticks, tick_labels)
        elif is_integer_key(x_key):  # a roller count has no 14.5
            from matplotlib.ticker import MaxNLocator

            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        if ticks is None and not zipped:
            _close_ticks(ax, _sampled(cols[x_key], drawn))
        ax.grid(alpha=0.3)
        if np.all(y[shown] >= 0.0):  # an impulse is never negative: no axis below 0 (a lone 0 drew -0.04..0.04),
            # room for a marker at the top, and below 0 for half a marker (one at 0 would be cut), less than a tick
            top = max(ax.get_ylim()[1], 1.06e3 * float(np.max(y[shown], initial=0.0)))  # y in N s, the axis mN s
            ax.set_ylim(-0.03 * top, top)
    for ax in panels[::-1]:  # one legend, on the last panel with lines
        if others and ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="best")
            break
    fig.suptitle(title, fontsize=10)
    fit_titles(fig, panels)
    from bearingsim.plotting import save_figure

    return save_figure(fig, path, tight=False)


def _close_ticks(ax, xs: list) -> None:
    """Ticks at the sampled values ``xs`` written whole (:func:`tick_texts`: ``970.000001, 970.000002``) where
    they differ by less than 1e-4 of their size, which matplotlib ticks as an offset (``1e-6+9.7e2``) or, as
    plain numbers, too long to fit; other axes keep matplotlib's ticks."""
    if len(xs) < 2 or xs[-1] - xs[0] >= 1e-4 * max(abs(xs[0]), abs(xs[-1])):
        return
    step = -(-len(xs) // ZIP_TICKS)  # a long axis labels every k-th value
    ax.set_xticks(xs[::step], tick_texts(xs)[::step])


def _zipped_ticks(ax, cols, x_key, zipped, rows, x_all, names=None):
    """The ticks of a zipped sweep's abscissa: one per value drawn, the zipped keys' values under it (a tick row
    each), and the axis label naming them, so that no zipped key's change is read as ``x_key``'s. ``names``: a
    text key's categories by position."""
    at: dict[float, list[int]] = {}
    for i in rows:
        at.setdefault(float(x_all[i]), []).append(i)
    ticks = sorted(at)
    labels = []
    texts = {k: distinct_texts(list(cols[k])) for k in (x_key, *zipped)}
    for p in ticks:
        first = names[int(p)] if names is not None else texts[x_key][at[p][0]]
        rows_below = ["/".join(dict.fromkeys(texts[k][i] for i in at[p])) for k in zipped]
        labels.append("\n".join([first, *rows_below]))
    step = -(-len(ticks) // ZIP_TICKS)  # a long axis labels every k-th value
    ax.set_xticks(ticks[::step], labels[::step])
    rows_named = ("its values: the second tick row" if len(zipped) == 1
                  else f"their values: tick rows 2-{len(zipped) + 1}")
    ax.set_xlabel(f"{axis_label(x_key)}\nzipped with {', '.join(map(axis_label, zipped))}\n({rows_named})")


def _sem_mN_s(cols, name: str, n: int) -> np.ndarray:
    """The standard errors of ``name``'s means [mN s]; NaN where there is none (and for every row of an
    index without the column)."""
    sem = cols.get(f"{name}_sem_Ns")
    return np.full(n, math.nan) if sem is None else np.asarray(sem, dtype=float) * 1e3


def _bar_lengths(err) -> np.ndarray:
    """The error bars to draw for standard errors ``err``: NaN (no bar, not one of 0) where there is none
    (NaN) and where it is 0 (an exact model's value: no error to draw, the panel's title says exact)."""
    err = np.asarray(err, dtype=float)
    return np.where(err > 0.0, err, np.nan)


def _titled(sym: str, errors: str) -> str:
    """A panel's title: its quantity and what its error bars are (nothing to say: the quantity alone)."""
    return f"{sym} ({errors})" if errors else sym


def _sample_of(col, i: int):
    """Row ``i``'s value of a key as :func:`_sampled` lists it (a number as a float, text as text)."""
    return float(col[i]) if _numeric(col) else str(col[i])


def _heat_map(cols, meta, axes, rows, path: Path, title: str) -> Path:
    """One cell per sampled pair, centred on its tick (sampled values only: no extrapolated edges),
    equal cells, each with its value written; I_dec and I_acc in two panels, one above the other, with their
    own scales. The figure is at most 9 in wide, its texts sized to read at least 7 pt at a report's 6.5 in
    (:func:`_map_layout`); the ticks are the sampled values rounded as far as their step allows
    (:func:`tick_texts`)."""
    xk, yk = axes
    xs, ys = _sampled(cols[xk], rows), _sampled(cols[yk], rows)
    xpos = {v: j for j, v in enumerate(xs)}  # by value: two values %g writes alike are two cells
    ypos = {v: j for j, v in enumerate(ys)}
    from bearingsim.plotting import subplots

    size, pt = _map_layout(len(xs), len(ys))
    fig, panels = subplots(2, 1, figsize=size, constrained_layout=True)
    text = len(xs) <= MAP_TEXT_COLUMNS and len(ys) <= MAP_TEXT_CELLS  # values written while they fit their cells
    batches = index_batches(cols, meta, len(cols["case"]))  # each case's batch means (the tables' test)
    n_gap = 0
    for ax, (name, sym) in zip(panels, QUANTITIES):
        grid, err, nb = (np.full((len(ys), len(xs)), np.nan) for _ in range(3))
        col, sem = cols.get(f"{name}_mean_Ns"), _sem_mN_s(cols, name, len(cols["case"]))
        for i in rows:
            xi, yi = xpos.get(_sample_of(cols[xk], i)), ypos.get(_sample_of(cols[yk], i))
            if xi is not None and yi is not None and col is not None:
                grid[yi, xi], err[yi, xi], nb[yi, xi] = col[i] * 1e3, sem[i], batches[i]
        n_gap = max(n_gap, int(np.isnan(grid).sum()))
        has = np.isfinite(grid)
        star = np.isnan(err) & has if np.isfinite(err[has]).any() else np.zeros_like(has)  # some cells lack one
        mesh = ax.pcolormesh(np.arange(len(xs) + 1) - 0.5, np.arange(len(ys) + 1) - 0.5,
                             np.ma.masked_invalid(grid), shading="flat", cmap="viridis")
        bar = fig.colorbar(mesh, ax=ax)
        bar.set_label(f"{sym} per pocket and\ncage rotation [mN s]", fontsize=pt)
        bar.ax.tick_params(labelsize=pt)
        finite = grid[np.isfinite(grid)]
        mid = 0.5 * (finite.min() + finite.max()) if finite.size else 0.0
        if text:
            for (yi, xi), z in np.ndenumerate(grid):
                ax.text(xi, yi, f"{z:.3g}{'*' if star[yi, xi] else ''}" if math.isfinite(z) else "–", ha="center",
                        va="center", fontsize=pt,
                        color="black" if not math.isfinite(z) or z > mid else "white")
        _map_ticks(ax, xk, yk, xs, ys, pt)
        ax.set_title(map_title(sym, grid[has], err[has], marked=text, batches=nb[has]), fontsize=pt)
    fig.suptitle(title + (f" ({counted(n_gap, 'cell')} failed or not run: blank)" if n_gap else ""),
                 fontsize=pt * 10 / 7)
    fit_titles(fig, panels)
    fit_suptitle(fig)
    from bearingsim.plotting import save_figure

    return save_figure(fig, path, tight=False)


def _map_layout(nx: int, ny: int) -> tuple[tuple[float, float], float]:
    """((width, height) [in], the font size [pt] of its smallest texts) of a heat map of ``nx`` columns and
    ``ny`` rows, its two panels one above the other: a wider map's texts larger by the factor it is shrunk
    to a report's text width, so that they print at least :data:`MIN_PRINT_PT`."""
    width = min(MAP_WIDTH_IN[1], max(MAP_WIDTH_IN[0], 2.4 + 0.7 * nx))
    cells = min(MAP_CELLS_IN[1], max(MAP_CELLS_IN[0], 0.4 * ny))
    pt = MIN_PRINT_PT * max(1.0, width / PRINT_WIDTH_IN)
    return (width, 2 * (cells + 1.1 + 0.06 * pt) + 0.6), round(pt + 0.05, 1)


def _map_ticks(ax, xk, yk, xs, ys, pt: float) -> None:
    """A heat map's ticks and axis labels: every k-th sampled value (at most :data:`MAP_TICKS` an axis),
    rounded (:func:`tick_texts`), in ``pt`` points or larger."""
    kx, ky = -(-len(xs) // MAP_TICKS), -(-len(ys) // MAP_TICKS)  # every k-th value labelled
    ax.set_xticks(range(0, len(xs), kx), tick_texts(xs)[::kx], rotation=90 if kx > 1 else 0)
    ax.set_yticks(range(0, len(ys), ky), tick_texts(ys)[::ky])
    ax.tick_params(labelsize=pt * 8 / 7)
    ax.set_xlabel(axis_label(xk), fontsize=pt * 8 / 7)
    ax.set_ylabel(axis_label(yk), fontsize=pt * 8 / 7)


def tick_texts(values) -> list[str]:
    """The tick labels of sampled ``values`` (text as it is): numbers to the fewest decimals (none at least)
    that leave each within 1 % of the smallest step between them, so that distinct values stay distinct
    (``1000, 1786, 2571`` for 1000..6500 in 8; ``0.1, 0.15``; ``1000.4, 1000.8``), trailing zeros dropped.
    Values too close to their neighbours for 10 decimals are written with the digits that tell them apart
    (:func:`distinct_texts`)."""
    if not values or not all(isinstance(v, (float, int, np.floating)) for v in values):
        return distinct_texts(list(values))
    vals = np.asarray(values, dtype=float)
    steps = np.diff(np.unique(vals))
    tol = 0.01 * float(steps.min()) if steps.size else 0.0
    for dec in range(11):
        if np.all(np.abs(np.round(vals, dec) - vals) <= tol) and (steps.size or np.all(np.round(vals, dec) == vals)):
            return [_plain(v, dec) for v in vals]
    return distinct_texts([float(v) for v in values])


def _plain(v: float, dec: int) -> str:
    text = f"{round(v, dec):.{dec}f}"
    text = text.rstrip("0").rstrip(".") if "." in text else text
    return "0" if text == "-0" else text


def map_title(sym: str, values, sem, marked: bool = True, batches=None) -> str:
    """A heat map panel's title: what its cells' standard errors ``sem`` [mN s], each from ``batches`` batch
    means (None: :data:`bearingsim.stats.BATCHES` each), say of the colours of their ``values`` (failed
    cells left out). A map has no error bars, so the title gives the largest standard error X and the
    difference the tables' test (:func:`bearingsim.stats.significant`) resolves for any two of the cells:
    t sqrt(se1^2 + se2^2) is at most t sqrt(2) X, and the Welch-Satterthwaite degrees of freedom of two
    errors are at least the fewer's, b - 1 for the fewest batch means b of a cell with an error, so t is at
    most :func:`bearingsim.stats.critical_ses` of X and an exact partner (0) of b batches each: the tables
    resolve every difference above t sqrt(2) X; below it, only the table says (and the colours span below
    it is said). One t per panel, whatever the map's size. Exact cells (all 0) and cells without one (n/a)
    as ``error_title`` says them; ``marked``: such cells' values are starred (written in the cells)."""
    from bearingsim.stats import BATCHES, critical_ses

    sem = np.asarray(sem, dtype=float)
    missing = int(np.isnan(sem).sum())
    if not sem.size or missing == sem.size or np.nanmax(sem) == 0.0:
        return _titled(sym, error_title(sem, "cell"))
    nb = np.full(sem.size, BATCHES) if batches is None else np.asarray(batches, dtype=float)
    fewest = int(np.min(nb[sem > 0.0]))  # NaN > 0 is False: cells with an error only
    top = float(np.nanmax(sem))
    t = critical_ses(top, 0.0, fewest, fewest)  # the fewest degrees of freedom two such errors can have
    text = f"{sym}: standard errors up to {top:.2g} mN s ({fewest}+ batch means"
    if not math.isfinite(t):  # a standard error of one batch mean: no degrees of freedom, no test
        text += "):\nno difference is judged by the tables' test"
    else:
        noise, span = t * math.sqrt(2.0) * top, float(np.ptp(values))
        text += (f"):\nthe tables' test resolves every difference\nabove {t:.3g} × √2 × {top:.2g} = "
                 f"{noise:.2g} mN s" + (f"\n(the colours span {span:.2g} mN s)" if span < noise else ""))
    if missing:
        text += f"\n{'*: ' if marked else ''}{missing} of {counted(sem.size, 'cell')} without one (n/a)"
    return text


def _cases_chart(cols, meta, path: Path, title: str) -> Path:
    """Every case of the index as one bar, labelled by its swept values; I_dec and I_acc in two panels."""
    keys = [k for k in meta["axes"] if k in cols]
    total = len(cols["case"])
    labels = []
    texts = {k: distinct_texts(list(cols[k])) for k in keys}
    for i in range(total):
        parts = [f"{name_of(k)} = {texts[k][i]}" for k in keys if _present(cols[k])[i]]
        status = str(cols["status"][i]) if "status" in cols else ""
        if status in ("failed", "pending"):
            parts.append("(failed)" if status == "failed" else "(not run)")
        labels.append(", ".join(parts) or "(base scenario)")
    pos = np.arange(total)
    from bearingsim.plotting import subplots

    fig, panels = subplots(1, 2, figsize=(11, 1.5 + 0.32 * total), sharey=True, constrained_layout=True)
    for k, (ax, (name, sym)) in enumerate(zip(panels, QUANTITIES)):
        if f"{name}_mean_Ns" in cols:
            y = np.asarray(cols[f"{name}_mean_Ns"]) * 1e3
            err = _sem_mN_s(cols, name, total)  # NaN: no error bar (matplotlib draws none), not a 0 one
            ok = np.isfinite(y)  # failed or not run: no bar (a gap, not a zero)
            bars = ax.barh(pos[ok], y[ok], xerr=_bar_lengths(err[ok]), color=FACE_COLOURS[name], capsize=3)
            hatch_without_error(bars, np.isnan(err[ok]))  # a value without an error: hatched
            ax.set_title(_titled(sym, error_title(err[ok], "bar")), fontsize=9)
        ax.set_xlabel(f"{sym} {Y_LABEL}")
        ax.grid(alpha=0.3, axis="x")
    panels[0].set_yticks(pos, labels, fontsize=7)
    panels[0].invert_yaxis()
    fig.suptitle(title, fontsize=10)
    fit_titles(fig, panels)
    from bearingsim.plotting import save_figure

    return save_figure(fig, path, tight=False)
