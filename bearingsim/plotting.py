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


def save_figure(fig, path) -> Path:
    """Lay out, write (120 dpi) and close one report figure; return its path."""
    path = Path(path)
    fig.tight_layout()
    fig.savefig(path, dpi=120, bbox_inches="tight")  # keeps a legend placed outside the axes
    plt.close(fig)
    return path
