"""Matplotlib set up for files, not screens (the Agg backend: no display needed), and the house style
of report figures: units as engineers read them (µm, mN s, µm³/h), legends outside the data."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

__all__ = ["plt", "save_figure", "legend_outside"]


def legend_outside(ax, **kw) -> None:
    """A legend to the right of the axes, where it cannot cover data."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=8, **kw)


def save_figure(fig, path, *, dpi: int = 120, tight: bool = True) -> Path:
    """Lay out, write and close one report figure; return its path.

    Written atomically (:func:`bearingsim.outputs.atomic_file`); an existing ``path`` that is not a PNG
    file (a symbolic link, a directory, a user's file) is refused with a one-line error and kept
    (:func:`bearingsim.outputs.check_replaceable`). ``tight``: ``tight_layout`` and a bounding box
    that keeps a legend placed outside the axes.
    """
    from bearingsim.outputs import PNG_SIGNATURE, atomic_file, check_replaceable

    import warnings

    path = Path(path)
    try:
        check_replaceable(path, PNG_SIGNATURE, "figure")
        with warnings.catch_warnings():
            # a scenario name in a script the font lacks (CJK with DejaVu Sans) is drawn as boxes; matplotlib
            # would also warn once per glyph and layout pass, dozens of lines for one name
            warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from (current )?font", category=UserWarning)
            if tight:
                fig.tight_layout()
            with atomic_file(path) as fh:
                fig.savefig(fh, format="png", dpi=dpi, **({"bbox_inches": "tight"} if tight else {}))
    finally:
        plt.close(fig)
    return path
