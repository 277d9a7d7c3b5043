"""A ``bearingsim validate`` folder read back: its two studies' tables, the Fig. 9 analog
(:mod:`bearingsim.studies.fig9`, ``fig9_idec_vs_speed.csv``) and the rig scene against it
(:mod:`bearingsim.studies.rig`, ``rig_idec_vs_speed.csv``), and their figures, for ``bearingsim table``
and ``bearingsim report`` of the folder.

A folder is a validate folder when it holds the Fig. 9 table as the study writes it (its header) and its
case index ``sweep.h5`` holds the Fig. 9 study's cases (the ``study`` column); the rig table counts only
while the index holds the rig's cases too (``--rig-rotations 0`` runs no rig; a rig table left from an
earlier run of the folder is not shown).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bearingsim.studies import fig9, rig


@dataclass
class ValidateTables:
    """What a validate folder holds: the Fig. 9 table (:func:`bearingsim.studies.fig9.read_fig9`), the
    rig rows (:func:`bearingsim.studies.rig.read_rig`; None without the rig) and its recorded rotations,
    and the figures the studies drew there (paths, in the order they are shown)."""

    folder: Path
    fig9: dict[str, np.ndarray]
    rig: list[dict] | None
    rig_rotations: int
    figures: list[Path]


def _starts_with(path: Path, signature: bytes) -> bool:
    if not path.is_file() or path.is_symlink():
        return False
    with open(path, "rb") as fh:
        return fh.read(len(signature)) == signature


def studies_in(folder) -> set[str]:
    """The studies whose cases the folder's case index (``sweep.h5``) holds: its ``study`` column's values
    (empty without an index or without that column)."""
    from bearingsim import archive
    from bearingsim.errors import UserError
    from bearingsim.sweeps.index import INDEX_FORMAT, read_index

    index = Path(folder) / "sweep.h5"
    if not archive.is_table_file(index, INDEX_FORMAT):
        return set()
    try:
        cols, _ = read_index(index)
    except (UserError, OSError, KeyError, ValueError):
        return set()
    return {str(v) for v in cols.get("study", [])}


def is_validate_table(path) -> bool:
    """True for a validate folder's Fig. 9 table (``DIR/fig9_idec_vs_speed.csv``): the study's header, and
    the Fig. 9 cases in the folder's case index."""
    path = Path(path)
    return path.name == fig9.CSV_NAME and _starts_with(path, fig9.CSV_SIGNATURE) and "fig9" in studies_in(path.parent)


def own_tables(folder) -> list[str]:
    """The names of the tables the validate study wrote in ``folder``: the Fig. 9 table, and the rig's when
    the folder's cases include the rig (a user's CSV of another name is not the study's)."""
    folder = Path(folder)
    has_rig = "rig" in studies_in(folder) and _starts_with(folder / rig.CSV_NAME, rig.CSV_SIGNATURE)
    return [fig9.CSV_NAME, *([rig.CSV_NAME] if has_rig else [])]


def read_validate(folder) -> ValidateTables:
    """The tables and figures of validate folder ``folder`` (:func:`is_validate_table` of its Fig. 9
    table is the caller's to check); its figures are those bearingsim drew there (:func:`bearingsim.outputs.is_own_png`:
    a user's picture of that name is not shown as the study's)."""
    from bearingsim.outputs import is_own_png

    folder = Path(folder)
    rig_csv = folder / rig.CSV_NAME
    has_rig = "rig" in studies_in(folder) and _starts_with(rig_csv, rig.CSV_SIGNATURE)
    rows = rig.read_rig(rig_csv) if has_rig else None
    names = [fig9.PNG_NAME, *(rig.FIGURE_NAMES if has_rig else ())]
    figures = [folder / n for n in names if is_own_png(folder / n)]
    return ValidateTables(folder, fig9.read_fig9(folder / fig9.CSV_NAME), rows,
                          int(rows[0]["rotations"]) if rows else 0, figures)


def format_tables(tables: ValidateTables) -> str:
    """Both tables for the terminal: the Fig. 9 analog, then the rig table as ``bearingsim validate``
    prints it (or a line saying the folder has none)."""
    parts = [fig9.format_table(tables.fig9)]
    if tables.rig is not None:
        parts.append(rig.format_table(tables.rig, tables.rig_rotations))
    else:
        parts.append("rig scene: no rig table in this folder (run with --rig-rotations 0, or no rig speed finished)")
    return "\n".join(parts)
