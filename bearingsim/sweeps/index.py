"""The sweep's index (``sweep.csv`` and ``sweep.h5``) and the resume check of case archives.

One row per case, in the sweep's case order: ``case`` (content hash), the swept keys (the value the
case ran at: the one it sets, or for a key it does not set, such as an extra case's axes, the value of
its resolved scenario; empty only where that has none), ``status``
(``done``: run now; ``cached``: a complete archive of the same scenario, computed by the same version
of its model (:mod:`bearingsim.model_versions`), was already there; ``stale``: run now because the
archive of the same scenario there was computed by another version of the model, or by a bearingsim
that stored none; ``failed``; ``pending``: not run because the sweep was interrupted), ``error`` (one line),
``archive`` (path relative to the sweep folder; empty for a case run without one), ``wall_s`` (the
run's own wall time, ``wall_time_s`` of its provenance, which its archive stores: one number whether the
case is done or cached; of a failed case, the time to its failure), ``model_version`` (the version of the
model that computed the numbers, :mod:`bearingsim.model_versions`; empty if unknown), ``notes`` (the run's
plausibility notes, :func:`bearingsim.plausibility.check`, one a line without the ``bearingsim: note:``
prefix; empty for a clean run) and the summary numbers (SI, as in the archives' ``/results/summary``,
plus the standard errors ``I_dec_sem_Ns``, ``I_acc_sem_Ns``, ``first_impact_speed_sem_m_s``, ``cage_slip_sem`` and
``load_zone_half_angle_sem_deg``, see :func:`bearingsim.stats.summary_standard_errors`).

``sweep.h5`` holds the same table as one dataset per column under ``/index`` (numbers as float64,
NaN where a case has no value; text as UTF-8), the column order in the attribute ``columns``, every
swept key in ``axes``, the grid's axes in ``grid`` (JSON lists), the sweep ``mode`` (``product`` or
``zip``), ``grid_rows`` (the grid's cases come first; explicit extra cases follow) and, for a sweep of a
scenario, ``scenario_toml``: its base scenario resolved, with the sweep's ``--set`` applied (``scenario``
is the scenario file's path); a staged study adds its own (a life study's options, ``life_study``:
:data:`bearingsim.studies.life.INDEX_ATTR`). Both files are written to a temporary name and renamed.
"""
from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np

from bearingsim import archive
from bearingsim.outputs import write_atomic_bytes

INDEX_FORMAT = "bearingsim sweep index 1"
CSV_SIGNATURE = b"case,"  # the first bytes of every sweep.csv bearingsim writes (its header)
FIXED = ("status", "error", "archive", "wall_s", "model_version", "notes")
# summary numbers shown first when present; any others follow in name order
PREFERRED = ("I_dec_mean_Ns", "I_dec_sem_Ns", "I_dec_std_Ns", "I_acc_mean_Ns", "I_acc_sem_Ns", "I_acc_std_Ns",
             "first_impact_speed_m_s", "first_impact_speed_sem_m_s", "first_impact_energy_J", "cage_slip", "cage_slip_sem",
             "cage_rest_angle_deg", "load_zone_half_angle_deg", "load_zone_half_angle_sem_deg")




def summary_columns(rows: list[dict]) -> list[str]:
    """Summary number names present in ``rows``: the preferred ones first, then the rest sorted, then the wear
    rates (:data:`bearingsim.wear.SWEEP_RATES`, last: the columns an index had before them keep their places)."""
    from bearingsim.wear import SWEEP_RATES

    present = set()
    for r in rows:
        present.update(r.get("summary", {}))
    return ([k for k in PREFERRED if k in present] + sorted(present - set(PREFERRED) - set(SWEEP_RATES))
            + [k for k in SWEEP_RATES if k in present])


def _is_number(v) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


def write_index(outdir: Path, rows: list[dict], keys: list[str], meta: dict) -> tuple[Path, Path]:
    """Write ``sweep.csv`` and ``sweep.h5`` for ``rows`` atomically; return both paths.

    Each row holds ``case``, ``values`` (dict over ``keys``), ``status``, ``error``, ``archive``,
    ``wall_s`` and ``summary`` (dict of floats). A sweep that rewrites its index as cases finish uses
    an :class:`IndexWriter`, which formats only the rows that changed.
    """
    return IndexWriter(outdir, rows, keys, meta).write()


class IndexWriter:
    """``sweep.csv`` and ``sweep.h5`` of ``rows``, written again and again as rows change.

    Each row is formatted once (its CSV line and its cells of the ``sweep.h5`` columns) and again only
    after :meth:`changed` names it, so rewriting the index of a 10 000-case sweep costs the writing of
    two files, not the formatting of 10 000 rows (~0.3 s each time). The files are the ones
    :func:`write_index` writes for the same rows.
    """

    def __init__(self, outdir: Path, rows: list[dict], keys: list[str], meta: dict):
        self.outdir, self.rows, self.keys, self.meta = Path(outdir), rows, list(keys), meta
        self._summ: list[str] | None = None  # summary columns the cached cells are for
        self._dirty: set[int] = set(range(len(rows)))
        self._lines: list[str] = [""] * len(rows)
        self._cols: dict[str, np.ndarray] = {}
        self._units: dict[str, str] = {}
        self._buf = io.StringIO()
        self._csv = csv.writer(self._buf)

    def changed(self, i: int) -> None:
        """Row ``i`` was updated: format it again at the next :meth:`write`."""
        self._dirty.add(i)

    def _reset(self, summ: list[str]) -> None:
        rows, n = self.rows, len(self.rows)
        self._summ = summ
        self._dirty = set(range(n))
        cols = {"case": np.array([r["case"] for r in rows], dtype=object)}
        units = {}
        for k in self.keys:
            vals = [_value(r, k) for r in rows]
            if all(v is None or _is_number(v) for v in vals):
                cols[k] = np.array([math.nan if v is None else float(v) for v in vals])
            else:
                cols[k] = np.array(["" if v is None else str(v) for v in vals], dtype=object)
            units[k] = unit_of(k)
        for col in ("status", "error", "archive", "notes"):
            cols[col] = np.empty(n, dtype=object)
        cols["wall_s"] = np.full(n, math.nan)
        units["wall_s"] = "s"
        cols["model_version"] = np.full(n, math.nan)
        for k in summ:
            cols[k] = np.full(n, math.nan)
            units[k] = unit_of(k)
        self._cols, self._units = cols, units

    def write(self) -> tuple[Path, Path]:
        """Write both files (atomically) with every row as it is now; return their paths."""
        rows, keys = self.rows, self.keys
        summ = summary_columns(rows)
        if summ != self._summ:
            self._reset(summ)
        cols, buf, w = self._cols, self._buf, self._csv
        for i in self._dirty:
            r = rows[i]
            s = r.get("summary", {})
            buf.seek(0)
            buf.truncate()
            w.writerow([r["case"], *[_cell(_value(r, k)) for k in keys], r["status"], r.get("error", ""),
                        r.get("archive", ""), _fmt(r.get("wall_s")), _version_text(r.get("model_version")),
                        notes_text(r.get("notes")), *[_fmt(s.get(k)) for k in summ]])
            self._lines[i] = buf.getvalue()
            for col in ("status", "error", "archive"):
                cols[col][i] = r.get(col, "")
            cols["wall_s"][i] = _float(r.get("wall_s"))
            cols["model_version"][i] = _float(r.get("model_version"))
            cols["notes"][i] = notes_text(r.get("notes"))
            for k in summ:
                cols[k][i] = _float(s.get(k))
        self._dirty = set()

        columns = ["case", *keys, *FIXED, *summ]
        csv_path, h5_path = self.outdir / "sweep.csv", self.outdir / "sweep.h5"
        buf.seek(0)
        buf.truncate()
        w.writerow(columns)
        text = buf.getvalue() + "".join(self._lines)
        write_atomic_bytes(csv_path, text.encode("utf-8"))
        attrs = {"format": INDEX_FORMAT, "columns": json.dumps(columns), "axes": json.dumps(keys), **self.meta}
        archive.write_table_file(h5_path, {c: cols[c] for c in columns}, self._units, attrs, _descriptions())
        return csv_path, h5_path

    @property
    def columns(self) -> dict[str, np.ndarray]:
        """The index's columns as last written (one array per column, in column order)."""
        return {c: self._cols[c] for c in ["case", *self.keys, *FIXED, *(self._summ or [])]}


def _descriptions() -> dict[str, str]:
    """The descriptions ``sweep.h5`` stores with its columns: those of the wear rates."""
    from bearingsim.wear import SWEEP_RATES

    return dict(SWEEP_RATES)


def notes_text(notes) -> str:
    """A row's notes (a list of lines) as its ``notes`` cell: one a line, "" for none."""
    return "\n".join(notes or ())


def notes_of(cell) -> list[str]:
    """The notes of a ``notes`` cell (:func:`notes_text`) as a list; [] for an empty cell or none."""
    return [line for line in str(cell or "").split("\n") if line]


def _value(row: dict, key: str):
    """A row's value of swept ``key``: the one its case sets, else the one its resolved scenario has
    (``ran_at``, :attr:`bearingsim.sweeps.spec.Case.ran_at`), else None."""
    values = row["values"]
    return values[key] if key in values else row.get("ran_at", {}).get(key)


def _cell(v) -> str:
    return "" if v is None else v


def _version_text(v) -> str:
    return str(int(v)) if _is_number(v) and math.isfinite(v) else ""


def _float(v) -> float:
    return float(v) if _is_number(v) else math.nan


def _fmt(v) -> str:
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else repr(float(v)) if _is_number(v) else str(v)


def read_index(path: str | Path) -> tuple[dict[str, np.ndarray], dict]:
    """Read ``sweep.h5``: (columns as arrays, attributes with ``axes`` and ``columns`` decoded).

    Raises
    ------
    UserError
        The file is missing or is not a sweep index.
    """
    cols, meta = archive.read_table_file(path, INDEX_FORMAT)
    meta["axes"] = json.loads(meta["axes"])
    meta["grid"] = json.loads(meta.get("grid", "[]"))
    meta["grid_rows"] = int(meta.get("grid_rows", 0))
    meta["columns"] = json.loads(meta["columns"])
    cols = {name: cols[name] for name in meta["columns"]}
    return cols, meta


def index_dataframe(path, units_in_names: bool = False):
    """The index of a sweep or study folder (``DIR`` or ``DIR/sweep.h5``) as a pandas DataFrame, one
    row per case (needs the extra ``bearingsim[frames]``; :func:`bearingsim.frames.index_frame`)."""
    from bearingsim.errors import check_path
    from bearingsim.frames import index_frame

    p = Path(check_path(path, "path", "a sweep's or study's folder or its sweep.h5"))
    if p.is_dir():
        p = p / "sweep.h5"
    cols, meta = read_index(p)
    return index_frame(cols, meta["axes"], str(p.parent), unit_of, units_in_names)


# unit suffixes of scenario and summary keys -> unit text for labels
# (first match wins: "_N_m" before "_m", "_m_s" before "_s")
UNITS = (("_m3_h", "m^3/h"), ("_kgm2", "kg m²"), ("_N_m", "N/m"), ("_Nms", "N m s"), ("_Ns", "N s"), ("_m_s", "m/s"),
         ("_rad_s", "rad/s"), ("_mm", "mm"), ("_rpm", "rpm"), ("_kg", "kg"), ("_deg", "deg"), ("_Pa", "Pa"),
         ("_hz", "Hz"), ("_N", "N"), ("_J", "J"), ("_s", "s"), ("_um", "µm"), ("_m", "m"))


#: Eq. (2)'s c, with F_o and N in N and V in m/s (docs/physics.md)
DRAG_COEFFICIENT_UNIT = "N^0.754 (s/m)^0.648"
#: the units of the names whose suffix carries none: the drag coefficient's key, and the validate study's
#: columns of its cases (``rpm``: the inner ring's speed; ``drag``: the drag coefficient c)
NAMED_UNITS = {"lubrication.drag_coefficient": DRAG_COEFFICIENT_UNIT, "drag": DRAG_COEFFICIENT_UNIT, "rpm": "rpm"}


def unit_of(key: str) -> str:
    """Unit of a name (:data:`NAMED_UNITS`), else from its suffix (``operating.inner_ring_speed_rpm`` ->
    ``rpm``); ``1`` if none."""
    if key in NAMED_UNITS:
        return NAMED_UNITS[key]
    leaf = key.split(".")[-1]
    for suffix, unit in UNITS:
        if leaf.endswith(suffix):
            return unit
    return "1"


def name_of(key: str) -> str:
    """Readable name of a key without section and unit suffix (``inner ring speed``)."""
    leaf = key.split(".")[-1]
    for suffix, _ in UNITS:
        if leaf.endswith(suffix):
            leaf = leaf[: -len(suffix)]
            break
    return leaf.replace("_", " ")


def read_cached(archive_path: Path, toml_text: str) -> dict | None:
    """The record of a case whose archive is complete and stores exactly ``toml_text``, else None.

    Only a file at the final name is considered (temporary files are never trusted); an unreadable,
    incomplete or different archive gives None and the case runs again. The record has ``notes`` when
    the archive stores its run's notes (else the caller takes the previous index row's). An archive of the case's
    scenario computed by another version of its model than this one (``model_version`` in its
    provenance against :data:`bearingsim.model_versions.MODEL_VERSIONS`; none stored counts as
    another) gives ``{"status": "stale"}`` without its numbers: the case runs again too.
    """
    from bearingsim.model_versions import MODEL_VERSIONS
    from bearingsim.stats import summary_standard_errors
    from bearingsim.wear import reduced_rates

    got = archive.peek(archive_path)
    if got is None or got["scenario"] != toml_text:
        return None
    if got["model_version"] is None or got["model_version"] != MODEL_VERSIONS.get(got["model"]):
        return {"status": "stale"}
    summary = {k: v for k, v in got["summary"].items() if k != "wall_s"}
    summary.update(summary_standard_errors(got["per_rotation"], got["model"]))
    summary.update(reduced_rates(got["wear"]) if got["model"] == "reduced" else archive_rates(archive_path))
    wall = got["wall_time_s"]
    rec = {"status": "cached", "error": "", "wall_s": wall, "summary": summary, "model_version": got["model_version"]}
    if got.get("notes") is not None:  # an archive that stores its run's notes
        from bearingsim.wording import run_notes

        rec["notes"] = run_notes([got["notes"]] if isinstance(got["notes"], str) else got["notes"])
    return rec


#: what :func:`archive_rates` reads of an archive beside its summary and scenario
RATE_DATA = ("results/per_rotation", "results/wear")


def archive_rates(path: Path) -> dict[str, float]:
    """The wear rates of the complete multibody archive ``path`` (:func:`bearingsim.wear.sweep_rates`, the numbers
    a case run now records; a reduced archive's come with :func:`bearingsim.archive.peek`); {} for an archive that
    cannot be read."""
    from bearingsim.errors import UserError
    from bearingsim.simulation import load
    from bearingsim.wear import sweep_rates

    try:
        return sweep_rates(load(path, only=RATE_DATA))
    except (UserError, OSError):
        return {}


#: statuses of an index row whose numbers a resumed sweep may take (when its model version matches)
HAS_NUMBERS = ("done", "cached", "stale")


def read_rows(path: Path) -> dict[str, dict]:
    """The rows of an existing ``sweep.h5`` by case hash, each ``status``, ``model_version`` (None if
    the index has none), ``wall_s``, ``notes`` (a list; [] where the index has no notes column) and
    ``summary`` (every summary column, NaN included); ``{}`` when ``path`` is missing or not a sweep index."""
    from bearingsim.errors import UserError

    try:
        cols, meta = read_index(path)
    except (UserError, OSError, KeyError, ValueError):  # none, or not an index: no row is trusted
        return {}
    summ = [c for c in meta["columns"] if c != "case" and c not in meta["axes"] and c not in FIXED]
    n = len(cols["case"])
    versions = cols.get("model_version", np.full(n, math.nan))
    notes = cols.get("notes", [""] * n)
    out = {}
    for i in range(n):
        v = float(versions[i])
        out[str(cols["case"][i])] = {
            "status": str(cols["status"][i]), "model_version": int(v) if math.isfinite(v) else None,
            "wall_s": float(cols["wall_s"][i]), "notes": notes_of(notes[i]),
            "summary": {k: float(cols[k][i]) for k in summ}}
    return out


def trusted_row(row: dict | None, model: str) -> dict | None:
    """The record of a case taken from its row of the previous index (:func:`read_rows`), for a case
    run without an archive: ``cached`` with the row's numbers when the row holds numbers (``done``,
    ``cached`` or ``stale``) computed by the current version of ``model``
    (:data:`bearingsim.model_versions.MODEL_VERSIONS`); ``{"status": "stale"}`` when they came from
    another version or an index that recorded none; None (run it) for no row, or a failed or pending
    one, or a row of an index written before the wear rates (:data:`bearingsim.wear.SWEEP_RATES`), which it has
    none of. The row is the case's because the index names it by the content hash of its scenario."""
    from bearingsim.model_versions import MODEL_VERSIONS
    from bearingsim.wear import SWEEP_RATES

    if row is None or row["status"] not in HAS_NUMBERS:
        return None
    if row["model_version"] is None or row["model_version"] != MODEL_VERSIONS.get(model):
        return {"status": "stale"}
    if next(iter(SWEEP_RATES)) not in row["summary"]:  # an index written before the wear rates: run to get them
        return None
    return {"status": "cached", "error": "", "wall_s": row["wall_s"], "summary": dict(row["summary"]),
            "model_version": row["model_version"], "notes": list(row.get("notes", ()))}


def index_batches(cols: dict, meta: dict, n: int) -> list[int]:
    """The batch means each case's standard errors came from (:func:`bearingsim.stats.sem_batches` of its
    recorded rotations): ``numerics.rotations`` where the index has it as a column (swept), else the base
    scenario's (``scenario_toml``), else :data:`bearingsim.stats.BATCHES` (every run of 5 or more rotations)."""
    import tomllib

    from bearingsim import stats

    if "numerics.rotations" in cols:
        return [stats.sem_batches(int(v)) if math.isfinite(float(v)) else stats.BATCHES
                for v in cols["numerics.rotations"]]
    try:
        rotations = int(tomllib.loads(meta.get("scenario_toml") or "")["numerics"]["rotations"])
    except (KeyError, TypeError, ValueError, tomllib.TOMLDecodeError):
        return [stats.BATCHES] * n
    return [stats.sem_batches(rotations)] * n
