"""Figures for files, not screens, and the house style of report figures: units as engineers read
them (µm, mN s, µm³/h), legends outside the data.

Each figure is a :class:`matplotlib.figure.Figure` with its own Agg canvas (no display needed), made
without pyplot: the library never switches the user's matplotlib backend nor adds figures to pyplot's
list (a notebook or a GUI application that imports bearingsim keeps its backend; a figure returned by
``Result.figures()`` is shown there as any figure is).
"""
from __future__ import annotations

import contextlib
from pathlib import Path

__all__ = ["FRONT", "REAR", "LINE_STYLES", "figure", "subplots", "save_figure", "figure_png", "legend_outside",
           "error_title", "fit_titles", "fit_suptitle", "mark_without_error", "hatch_without_error", "plain_number"]

#: the house colours of the two pocket faces, the same in every figure: FRONT is the front face, where the roller
#: pushes the cage (I_acc, F_acc), REAR the rear face, where the cage drags a lagging roller (I_dec, F_dec).
#: A dark blue and a light orange (Okabe-Ito): distinct for colour-blind readers and in greyscale (luminance
#: 0.37 and 0.64).
FRONT = "#0072B2"
REAR = "#E69F00"
#: (marker, line style) of the lines one panel compares (a sweep's lines, a cross-check's speeds), in turn: drawn in
#: one colour (the panel's face), they differ in these
LINE_STYLES = (("o", "-"), ("s", "--"), ("^", ":"), ("D", "-."), ("v", "-"), ("P", "--"), ("X", ":"), ("*", "-."))


def figure(**kw):
    """A new :class:`matplotlib.figure.Figure` (``kw`` as for it) drawn by its own Agg canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**kw)
    FigureCanvasAgg(fig)
    return fig


def subplots(nrows: int = 1, ncols: int = 1, *, figsize=None, constrained_layout: bool = False, **kw):
    """``(figure, axes)`` as :func:`matplotlib.pyplot.subplots` returns them, without pyplot
    (``kw``: ``sharex``, ``sharey``, ``squeeze``, ... of :meth:`matplotlib.figure.Figure.subplots`)."""
    fig = figure(figsize=figsize, layout="constrained" if constrained_layout else None)
    return fig, fig.subplots(nrows, ncols, **kw)


def mark_without_error(ax, x, y, err, color, marker: str = "o", **style) -> int:
    """Open markers over the drawn values ``y`` at ``x`` whose standard error ``err`` is missing (NaN: the tables'
    ``n/a``; matplotlib draws no error bar for it), in ``color``; returns how many."""
    import numpy as np

    none = np.isnan(np.asarray(err, dtype=float)) & np.isfinite(np.asarray(y, dtype=float))
    ax.plot(np.asarray(x)[none], np.asarray(y)[none], marker, color=color, mfc="white", zorder=3, **style)
    return int(none.sum())


def hatch_without_error(bars, missing) -> None:
    """Hatch the ``bars`` (a bar container) whose value has no standard error (``missing``, one flag a bar)."""
    for bar, m in zip(bars.patches, missing):
        if m:
            bar.set_hatch("//")


def error_title(sem, what: str = "point", bars: str = "±1 standard error") -> str:
    """What a panel's error bars are, from the standard errors ``sem`` of the values it draws (None: the
    table has no such column): exact (all 0, the reduced model), none (all NaN: the tables' ``n/a``), some
    missing (``open markers: none (n/a), k of n points``: such a value is drawn without a bar, marked as
    ``what`` says: an open marker, a hatched bar, a starred cell), or ``bars`` on every one; "" for an empty
    ``sem`` (a panel that draws no value)."""
    import numpy as np

    from bearingsim.wording import counted

    if sem is not None and not np.size(sem):  # nothing drawn (every value n/a): nothing to say of its errors
        return ""
    sem = np.full(1, np.nan) if sem is None else np.asarray(sem, dtype=float)
    missing = int(np.isnan(sem).sum())
    if sem.size and missing == 0 and np.all(sem == 0.0):
        return "exact: the reduced model has no standard error"
    if missing == sem.size:
        return ("" if what == "cell" else "no error bars: ") + f"no {what} has a standard error (n/a)"
    mark = {"point": "open markers", "bar": "hatched", "cell": "*"}[what]
    return f"error bars: {bars}" + (f"; {mark}: none (n/a), {missing} of {counted(sem.size, what)}" if missing else "")


def fit_titles(fig, axes) -> None:
    """Wrap each of ``axes``' titles (at spaces, lines kept) to lines no wider than its axes, measured on
    ``fig`` laid out as it stands: a long title would run past the figure's edge or into the next panel's.
    One layout pass without rendering, then a few text measurements per title."""
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    for ax in axes:
        _wrap_to(ax.title, ax.get_window_extent(renderer).width, renderer)


def fit_suptitle(fig) -> None:
    """Wrap ``fig``'s title (at spaces, lines kept) to the figure's width, as :func:`fit_titles` wraps a
    panel's (a narrow figure's long title would run past both edges); laid out again after each pass."""
    fig.draw_without_rendering()
    _wrap_to(fig._suptitle, 0.96 * fig.bbox.width, fig.canvas.get_renderer(), fig.draw_without_rendering)


def _wrap_to(text, width: float, renderer, after=None) -> None:
    """Wrap the matplotlib ``text`` (at spaces, its lines kept) until it is no wider than ``width`` [px]: each
    pass narrows the longest line by the measured excess (at most 8 passes); ``after()`` after each pass."""
    import textwrap

    for _ in range(8):
        drawn = text.get_window_extent(renderer).width
        if drawn <= width:
            break
        lines = text.get_text().split("\n")
        chars = max(12, int(max(map(len, lines)) * width / drawn) - 1)
        text.set_text("\n".join(textwrap.fill(line, chars, break_on_hyphens=False) for line in lines))
        if after is not None:
            after()


_SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def plain_number(x: float, digits: int = 3) -> str:
    """``x`` to ``digits`` significant digits as engineers read it: ``1000``, ``0.0123``, and a power of ten
    written out beyond them, ``3.6 × 10⁶``, ``5 × 10⁻⁶`` (never ``1e+03`` or ``3.6e+06``)."""
    import math

    if not math.isfinite(x) or x == 0.0:
        return f"{x:g}"
    exp = math.floor(math.log10(abs(x)))
    if -3 <= exp < 5:
        text = f"{round(x, digits - 1 - exp):.{max(0, digits - 1 - exp)}f}"
        return text.rstrip("0").rstrip(".") if "." in text else text
    mantissa = f"{x / 10.0 ** exp:.{digits - 1}f}".rstrip("0").rstrip(".")
    if mantissa in ("10", "-10"):  # 9.9996e5 rounds up to the next power
        mantissa, exp = mantissa[:-1], exp + 1
    return f"{mantissa} × 10{str(exp).translate(_SUPERSCRIPTS)}"


def legend_outside(ax, **kw) -> None:
    """A legend to the right of the axes, where it cannot cover data."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=8, **kw)


def fixed_unit_axis(ax, axis: str = "y") -> None:
    """Tick labels of ``axis`` in the unit its label names, whatever the numbers: no multiplier (``1e6``)
    or offset that matplotlib would choose from the data, so that two figures of one quantity compare
    without rescaling."""
    ax.ticklabel_format(axis=axis, style="plain", useOffset=False)


def save_figure(fig, path, *, dpi: int = 120, tight: bool = True) -> Path:
    """Lay out and write one report figure; return its path. (The figure is in no pyplot list: there
    is nothing to close; its memory goes with its last reference.)

    Written atomically (:func:`bearingsim.outputs.atomic_file`), marked as bearingsim's
    (:data:`bearingsim.outputs.MARK`); an existing ``path`` that is not a figure bearingsim drew (a
    symbolic link, a directory, a user's picture) is refused with a one-line error and kept
    (:func:`bearingsim.outputs.check_replaceable`). ``tight``: ``tight_layout`` and a bounding box
    that keeps a legend placed outside the axes.
    """
    from bearingsim.outputs import atomic_file, check_replaceable, is_own_png

    path = Path(path)
    check_replaceable(path, is_own_png, "figure")
    data = figure_png(fig, dpi=dpi, tight=tight)  # drawn whole before anything is written
    with atomic_file(path) as fh:
        fh.write(data)
    return path


def figure_png(fig, *, dpi: int = 120, tight: bool = True) -> bytes:
    """The PNG bytes :func:`save_figure` would write for ``fig`` (a report embeds them), with the ``Software``
    text :data:`bearingsim.outputs.MARK` (what tells bearingsim's figures from a user's pictures)."""
    import io

    from bearingsim.outputs import PNG_METADATA

    buf = io.BytesIO()
    with _missing_glyphs_quiet():
        if tight:
            fig.tight_layout()
        fig.savefig(buf, format="png", dpi=dpi, metadata=PNG_METADATA,
                    **({"bbox_inches": "tight"} if tight else {}))
    return buf.getvalue()


@contextlib.contextmanager
def _missing_glyphs_quiet():
    """matplotlib's missing-glyph warnings ignored: a scenario name in a script the font lacks (CJK with
    DejaVu Sans) is drawn as boxes, and matplotlib would also warn once per glyph and layout pass,
    dozens of lines for one name."""
    import warnings

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from (current )?font", category=UserWarning)
        yield
