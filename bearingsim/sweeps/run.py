"""Running a sweep: resume, batches, failures, interruption, index, progress.

The sweep folder ``DIR`` holds ``sweep.csv`` and ``sweep.h5`` (the index,
:mod:`bearingsim.sweeps.index`), for a product grid ``map.h5`` (the same numbers as arrays over the
axes, :mod:`bearingsim.sweeps.grid`), ``cases/<hash>.h5`` (one archive per case that keeps one: by
default the multibody cases, :func:`bearingsim.sweeps.worker.keeps_archive`) and, with figures, the
sweep's PNGs.
A lock file ``DIR/.sweep.lock`` (:class:`bearingsim.outputs.FolderLock`) keeps two sweeps or studies
from writing the same folder at once.
"""
from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import re
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from bearingsim.errors import UserError
from bearingsim.wording import counted
from bearingsim.outputs import (_HDF5_SIGNATURE, FolderLock, _remove_if_own, remove_folder_files,
                                write_atomic_bytes)
from bearingsim.sweeps.index import IndexWriter, read_cached
from bearingsim.sweeps.spec import Case, SweepSpec, resolve_cases

# how many cheap (reduced-model) cases one task runs: enough that a task lasts far longer than its
# dispatch, few enough that every worker gets several tasks and the bar moves
MAX_BATCH = 200
MIN_TAIL_BATCH = 10
INDEX_EVERY_S = 1.0
# ... or less often when the index is large: its rewrites take at most this share of the sweep's time
# (a 10 000-row index takes ~50-80 ms to write; every second that was ~2 s of a 30 s map, on a core the
# workers need)
INDEX_TIME_SHARE = 0.02

_log = logging.getLogger(__name__)  # a failed case, when no progress bar shows it
_CASE_NAME = re.compile(r"[0-9a-f]{16}")  # a case archive's name: its hash (spec.case_hash)


@dataclass
class StagedRound:
    """The cases of :func:`run_sweep` are a round of a staged study (:func:`bearingsim.studies.run_studies`):
    the study checks its folder itself (its later cases are not known before the earlier ones have run, so
    :func:`check_same_sweep` cannot tell its own earlier run from another study's); ``earlier``, the rows
    of the cases earlier rounds ran or took, by hash, are kept as they are (not read again from their
    archives, and a case run this time stays ``done``); and the engine is left started for the next round
    (its workers keep the compiled model they have loaded), the caller stopping it. ``rows``: set by
    :func:`run_sweep` once it has read what the folder holds (the round's rows, which its cases then fill), so
    that the caller has this round's rows when a signal ends the round after its cases ran but before
    :func:`run_sweep` returned (the caller's own handler raising in it). ``meta``: root attributes the study
    adds to the case index (``sweep.h5``), written with it from the round's start (a life study's options,
    which its folder check reads before its history is written)."""

    earlier: dict = field(default_factory=dict)
    rows: list | None = None
    meta: dict = field(default_factory=dict)


class SweepInterrupted(Exception):
    """SIGINT, SIGTERM or SIGHUP arrived during a sweep; ``signum`` says which."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


@dataclass
class SweepOutcome:
    """What a sweep did: the index files, the rows and the counts by status."""

    outdir: Path
    csv: Path
    h5: Path
    rows: list[dict]
    map: Path | None = None  # map.h5, for a product grid
    interrupted: int | None = None  # the signal number, if interrupted
    wall_s: float = 0.0
    figures: list[Path] = field(default_factory=list)
    figure_notes: list[str] = field(default_factory=list)  # why a figure was not drawn, one line each

    def count(self, status: str) -> int:
        return sum(r["status"] == status for r in self.rows)

    def counts(self) -> str:
        """``"3 done, 2 cached, 0 failed"``, and the stale cases when there are (computed again this time)."""
        text = f"{self.count('done')} done, {self.count('cached')} cached, {self.count('failed')} failed"
        if self.count("stale"):
            text += f", {self.count('stale')} stale (another model version's: computed again)"
        return text

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.rows if r["status"] == "failed"]


def _item(c: Case) -> tuple:
    """What a worker gets of a case: (hash, resolved TOML), and the validated scenario model when the
    case has it (a local pool uses it; a dask cluster gets the text only)."""
    return (c.hash, c.toml) if c.scenario is None else (c.hash, c.toml, c.scenario)


def make_batches(cases: list[Case], workers: int) -> list[list[tuple]]:
    """Cases grouped into tasks: multibody cases one per task, reduced cases in batches.

    A reduced case costs about a millisecond to solve and a few milliseconds with its archive, so
    they go in batches of up to :data:`MAX_BATCH`, small enough that each worker still gets about
    four batches; in a sweep large enough for full batches, the last ones shrink (down to
    :data:`MIN_TAIL_BATCH`) so the workers finish together.
    """
    reduced = [_item(c) for c in cases if c.model == "reduced"]
    other = [[_item(c)] for c in cases if c.model != "reduced"]
    workers = max(1, workers)
    size = max(1, min(MAX_BATCH, math.ceil(len(reduced) / (4 * workers)))) if reduced else 1
    batches, i = [], 0
    while i < len(reduced):
        left = len(reduced) - i
        n = size
        if size == MAX_BATCH and left <= 4 * workers * size:
            # the last batches of a large sweep shrink, so that no worker idles long at the end
            n = min(size, max(MIN_TAIL_BATCH, math.ceil(left / (2 * workers))))
        batches.append(reduced[i:i + n])
        i += n
    return other + batches


#: the signals that stop a sweep (SIGHUP: its terminal went away) as one: finished cases and the index kept
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class _Signals:
    """SIGINT/SIGTERM/SIGHUP raise :class:`SweepInterrupted` once in the main thread; later ones are ignored
    while the sweep cleans up.

    A signal can land while Python runs a callback whose exceptions it cannot propagate (a weakref
    callback, a ``__del__``): the exception is then "unraisable", and the sweep sees ``fired`` instead
    (the engines poll it, :func:`run_sweep` checks it after every batch). Python would print such an
    exception with its traceback (a clean-clone CI run saw one, from ``weakref.py``); while the handlers
    are in, ``sys.unraisablehook`` drops :class:`SweepInterrupted` and passes everything else on."""

    def __init__(self):
        self.old = {}
        self.old_hook = None
        self.fired: int | None = None

    _held = False

    def _handler(self, signum, frame):
        if self.fired is None:
            self.fired = signum
            if not self._held:
                raise SweepInterrupted(signum)

    def hold(self) -> None:
        """From now on, until the handlers are taken out, a signal is recorded in ``fired``, not raised: a clean-up
        that must finish (the index and the map written, the workers ended) is not cut short by it. Call it as
        ``try: hold() except SweepInterrupted: hold()``: the first signal can land on the call itself (a function
        call is where Python runs a handler; a SIGINT there, on the way into the hold, ended a sweep with
        SweepInterrupted's traceback and exit 1), and a handler raises once, so the second call holds. (A hold
        that ended before the handlers were taken out left a moment in which the first signal raised again.)"""
        self._held = True

    def _unraisable(self, unraisable):
        if not isinstance(unraisable.exc_value, SweepInterrupted):
            self.old_hook(unraisable)

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            for s in STOP_SIGNALS:
                if s == signal.SIGHUP and signal.getsignal(s) == signal.SIG_IGN:
                    continue  # started under nohup: to outlive its terminal
                self.old[s] = signal.signal(s, self._handler)
            self.old_hook = sys.unraisablehook
            sys.unraisablehook = self._unraisable
        return self

    def __exit__(self, *exc):
        for s, h in self.old.items():
            signal.signal(s, h)
        if self.old_hook is not None:
            sys.unraisablehook = self.old_hook
            self.old_hook = None
        return False


def check_sweep_outputs(outdir: Path, figures: bool = True) -> None:
    """Refuse, before any case runs, a sweep folder whose index, figure or ``cases`` paths hold what
    the sweep did not write (a user's ``sweep.csv``, a link, a folder): one line naming the file, and
    nothing in the folder is replaced (:func:`bearingsim.outputs.check_replaceable`)."""
    from bearingsim import archive
    from bearingsim.outputs import check_replaceable, is_own_png
    from bearingsim.sweeps.grid import MAP_FORMAT, MAP_NAME
    from bearingsim.sweeps.index import CSV_SIGNATURE, INDEX_FORMAT
    from bearingsim.sweeps.plot import FIGURE_NAMES

    check_replaceable(outdir / "sweep.csv", CSV_SIGNATURE, "sweep index")
    for name, fmt, read in (("sweep.h5", INDEX_FORMAT, archive.read_table_file),
                            (MAP_NAME, MAP_FORMAT, archive.read_grid_file)):
        try:  # damaged or unreadable: said so, not taken for a user's file, nor replaced as the sweep's own
            err = archive.unreadable_error(outdir / name)
            if err is None and archive.root_format(outdir / name) == fmt:
                read(outdir / name, fmt)
        except UserError as exc:
            err = exc
        if err is not None:
            raise UserError(f"{err}; not replaced (remove it, or choose another -o folder)")
    check_replaceable(outdir / "sweep.h5", lambda p: archive.is_table_file(p, INDEX_FORMAT), "sweep index")
    check_replaceable(outdir / MAP_NAME, lambda p: archive.is_grid_file(p, MAP_FORMAT), "sweep map")
    for name in FIGURE_NAMES if figures else ():
        check_replaceable(outdir / name, is_own_png, "figure")
    cases = outdir / "cases"
    if cases.is_symlink() or (cases.exists() and not cases.is_dir()):
        raise UserError(f"{cases}: the sweep's folder of case archives is "
                        f"{'a symbolic link' if cases.is_symlink() else 'not a folder'}; not used (remove it)")


def check_same_sweep(outdir: Path, cases: list[Case], force: bool = False, base_toml: str | None = None) -> None:
    """Refuse a folder that holds another sweep or study: cases in its index (``sweep.h5``; failed and
    pending ones, which left no result, aside) or archives in ``cases/`` that the new one does not have. Resuming the same
    sweep (or one that only adds cases) passes. With ``force`` the other sweep's or study's case archives,
    index, map, figures and tables are removed instead (:func:`bearingsim.outputs.remove_folder_files`), so
    that nothing of it is mixed into the new one or read as its. ``base_toml``: the new sweep's base scenario
    resolved with its ``--set`` (the index's ``scenario_toml``); when the folder's index was written for another,
    the refusal names the keys that differ (the same command line, run again after its scenario file was edited,
    was told that the same command resumes the folder)."""
    from bearingsim import archive
    from bearingsim.sweeps.index import INDEX_FORMAT, read_index

    new = {c.hash for c in cases}
    old = set()
    versions = {}  # the model version that computed each of the index's cases
    old_base = None  # the base scenario the folder's sweep ran, as its index stores it
    index = outdir / "sweep.h5"
    if archive.is_table_file(index, INDEX_FORMAT):
        with contextlib.suppress(UserError, OSError, KeyError, ValueError):
            cols, meta = read_index(index)
            old_base = meta.get("scenario_toml") or None
            versions = dict(zip((str(h) for h in cols.get("case", [])), cols.get("model_version", [])))
            status = [str(x) for x in cols.get("status", [])]
            # a failed case left no result to mix in: the same study run again with it mended resumes; nor
            # did a pending one (its sweep was interrupted before it ran): a sweep interrupted and run again
            # with fewer values was refused for the cases it never ran
            old |= {str(h) for k, h in enumerate(cols.get("case", []))
                    if not (k < len(status) and status[k] in ("failed", "pending"))}
    cases_dir = outdir / "cases"
    if cases_dir.is_dir() and not cases_dir.is_symlink():
        # a file of the new sweep's cases is judged by its resume (_replaceable_archive); of the others, only
        # bearingsim's archives are another sweep's cases (a user's HDF5 file named by a hash is neither counted
        # nor removed by --force)
        old |= {h for h in _case_archives(cases_dir) if h in new or h in old
                or archive.is_archive(cases_dir / f"{h}.h5")}
    other = old - new
    if not other:
        return
    if not force:
        verb = "is" if len(other) == 1 else "are"
        raise UserError(f"{outdir}: holds another sweep or study ({counted(len(other), 'case')} of its {len(old)} "
                        f"{verb} not in this one); not mixed in: give another -o folder, or add --force to replace it "
                        f"{_base_changed(old_base, base_toml, index) or _resume_hint(other, versions)}")
    remove_other_study(outdir, other)


def _base_changed(old: str | None, new: str | None, index: Path) -> str | None:
    """The refusal's hint when the folder's sweep ran another base scenario than ``new`` (both resolved TOML, as
    the index's ``scenario_toml``): the keys that differ, old -> new (a scenario file edited since, or another
    ``--set``; ``index``: the folder's ``sweep.h5``); None when they are the same or either is unknown."""
    import tomllib

    from bearingsim.scenario import differing_keys

    if not old or not new or old == new:
        return None
    try:
        keys = differing_keys(tomllib.loads(old), tomllib.loads(new))
    except (tomllib.TOMLDecodeError, TypeError, ValueError):
        return None
    if not keys:
        return None
    shown = "; ".join(f"{k} {a} -> {b}" for k, a, b in keys[:3]) + ("; ..." if len(keys) > 3 else "")
    return (f"(its cases were run on another base scenario: {shown}; a scenario file edited since, or another "
            f"--set: 'bearingsim show {index}' prints the folder's)")


def _resume_hint(other: set[str], versions: dict) -> str:
    """How the folder's own command would fare: the cases not in this sweep were all computed by a model
    version this bearingsim does not have (:data:`bearingsim.model_versions.MODEL_VERSIONS`): a study whose
    cases changed with the model (the cross-check's rung 3 at multibody version 8) is refused to the command that
    made it too, and --force computes them again; otherwise the same command as before resumes it."""
    from bearingsim.model_versions import MODEL_VERSIONS

    known = set(MODEL_VERSIONS.values())
    got = [float(versions.get(h, math.nan)) for h in other]
    if got and all(math.isfinite(v) and v not in known for v in got):
        return ("(they were computed by an earlier version of the model, whose cases this bearingsim defines "
                "otherwise, so the command that made them is refused too: --force replaces them and computes them "
                "again)")
    return "(the same command as before resumes it)"


def remove_other_study(outdir: Path, hashes=None) -> None:
    """Remove the sweep or study in ``outdir`` that ``--force`` replaces: its case archives, bearingsim's own only
    (:func:`bearingsim.archive.is_archive`; those of ``hashes``, or every ``cases/<hash>.h5``: a user's file there
    stays), then its index, map, figures and study tables (:func:`bearingsim.outputs.remove_folder_files`), so that
    none is left to be read as the new one's."""
    from bearingsim import archive

    cases_dir = outdir / "cases"
    names = ([cases_dir / f"{h}.h5" for h in hashes] if hashes is not None
             else [p for p in cases_dir.glob("*.h5") if _CASE_NAME.fullmatch(p.stem)])
    for path in names:
        _remove_if_own(path, archive.is_archive)
    remove_folder_files(outdir)


def _case_archives(cases_dir: Path) -> set[str]:
    """The hashes of the case archives in ``cases_dir``: regular files named ``<16 hex digits>.h5`` that
    start as an HDF5 file. A user's file there (``notes.h5``) was taken for a case of another sweep: the
    same sweep's resume was refused, and ``--force`` removed the file."""
    found = set()
    for p in cases_dir.glob("*.h5"):
        if _CASE_NAME.fullmatch(p.stem) and not p.is_symlink() and p.is_file():
            with contextlib.suppress(OSError), open(p, "rb") as fh:
                if fh.read(len(_HDF5_SIGNATURE)) == _HDF5_SIGNATURE:
                    found.add(p.stem)
    return found


def _clean_temporaries(cases_dir: Path) -> None:
    """Remove temporary archives left by workers ended mid-write (this sweep holds the folder's lock)."""
    for p in cases_dir.glob(".*.h5.tmp-*"):
        p.unlink(missing_ok=True)


def _progress(total: int, enabled: bool, initial: int, desc: str = "sweep", unit: str = "case"):
    if not enabled:
        return None
    from tqdm import tqdm

    import shutil

    tqdm.monitor_interval = 0  # no monitor thread
    size = shutil.get_terminal_size((100, 24))  # a terminal that reports no size (a bare pty) gets 100 x 24
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, ncols=min(max(size.columns, 60), 160),
                nrows=max(size.lines, 2), smoothing=0.1, initial=initial)  # cached cases: not in the rate


def _resume(cases: list[Case], rows: list[dict], outdir: Path, archives: str,
            earlier: dict | None = None) -> tuple[list[Case], set]:
    """Fill ``rows`` with what is already there; return (the cases to run, the hashes of stale ones).

    ``earlier``: the rows of cases an earlier round of the same study ran or took (a staged study), by
    hash: taken as they are, status included (a case this command ran stays ``done``, not ``cached``).

    A case is taken (``cached``) from its archive ``cases/<hash>.h5`` when that stores exactly its
    scenario computed by the current model version (:func:`~bearingsim.sweeps.index.read_cached`);
    a case that keeps no archive under ``archives`` is also taken from its row of the previous index
    (:func:`~bearingsim.sweeps.index.trusted_row`: same content hash, same model version). A stale
    archive or row, or none, means the case runs again; a stale, incomplete or different archive is removed first
    if bearingsim wrote it, and anything else at its name refused (:func:`_replaceable_archive`). A cached case
    keeps the notes of its run: its archive's when it stores them, else its row's in the previous index."""
    from bearingsim.sweeps.index import read_rows, trusted_row
    from bearingsim.sweeps.worker import keeps_archive

    cases_dir = outdir / "cases"
    old = read_rows(outdir / "sweep.h5")  # numbers of cases without an archive; notes of every case
    todo, stale = [], set()
    replaced = []  # bearingsim's archives of cases to run again: removed once none of the others is refused
    for c, row in zip(cases, rows):
        if earlier and c.hash in earlier:
            row.update(earlier[c.hash])
            continue
        rec = read_cached(cases_dir / f"{c.hash}.h5", c.toml)
        where = f"cases/{c.hash}.h5"
        if rec is None or rec["status"] == "stale":
            # the sweep's own archive, incomplete or stale: it is run again and replaced; anything else refused
            if _replaceable_archive(cases_dir / f"{c.hash}.h5", c, outdir, keeps_archive(c.model, archives)):
                replaced.append(cases_dir / f"{c.hash}.h5")
            if not keeps_archive(c.model, archives):
                rec = trusted_row(old.get(c.hash), c.model) or rec
                where = ""
        if rec is None or rec["status"] == "stale":
            todo.append(c)
            if rec is not None:
                stale.add(c.hash)
        else:
            row.update(rec, archive=where)
            if "notes" not in rec:  # an archive that stores no notes: its row's in the previous index
                row["notes"] = list(old.get(c.hash, {}).get("notes", ()))
    for path in replaced:
        path.unlink(missing_ok=True)
    return todo, stale


def _replaceable_archive(path: Path, case: Case, outdir: Path, keeps: bool) -> bool:
    """Whether the file at the case archive's name ``path``, of a case to run again, is to be removed: it is
    bearingsim's own, an archive it wrote (:func:`bearingsim.archive.is_archive`: HDF5 with the root group
    ``/bearingsim`` and its ``format_version``; incomplete, stale or of another scenario). Anything else there (a
    folder, a link, a user's file, a file HDF5 cannot open, so that nothing tells it is bearingsim's) is refused in
    one line naming it, before any case runs and with the folder's index and files as they were, when the case is
    to write its archive there (``keeps``); else it is in no one's way and left as it is (False, as for no file)."""
    from bearingsim import archive

    if not os.path.lexists(path):
        return False
    if not path.is_symlink() and path.is_file() and archive.is_archive(path):
        return True
    if not keeps:
        return False
    err = None if path.is_symlink() or not path.is_file() else archive.unreadable_error(path)
    if path.is_symlink():
        kind = "a symbolic link, not bearingsim's"
    elif path.is_dir():
        kind = "a folder, not bearingsim's"
    elif not path.is_file():
        kind = "not a regular file, not bearingsim's"
    elif err is not None:  # damaged, truncated or unreadable: what it held cannot be told
        reason = " ".join(str(err).removeprefix(f"{path}: ").split())
        kind = f"not known to be bearingsim's: {reason}"
    else:
        kind = "a file, not bearingsim's (not an archive bearingsim wrote)"
    raise UserError(f"{path}: archive of the case {case.label()} of {outdir} is {kind}; not replaced (remove it)")


def _pending_rows(cases: list[Case]) -> list[dict]:
    """The index's row of each case before it runs: ``pending``, no numbers."""
    return [{"case": c.hash, "values": c.values, "ran_at": c.ran_at, "status": "pending", "error": "", "archive": "",
             "wall_s": math.nan, "model_version": None, "summary": {}, "notes": []} for c in cases]


def run_sweep(spec: SweepSpec | list[Case], outdir: str | Path, *, engine=None, figures: bool = True,
              progress: bool | None = None, log=None, lock: FolderLock | None = None,
              desc: str = "sweep", force: bool = False, archives: str = "auto",
              staged: StagedRound | None = None) -> SweepOutcome:
    """Run every case of ``spec`` that has no valid result yet, and index them all.

    Parameters
    ----------
    spec : SweepSpec or list of Case
        The sweep (resolved and validated here before anything runs) or its resolved cases.
    outdir : path
        Sweep folder (created).
    engine : LocalEngine or DaskEngine, optional
        Where cases run; default a local pool of one process. The engine is started here and stopped
        (its queued cases cancelled) when the sweep ends, however it ends.
    figures : bool
        Draw the index figures (:func:`bearingsim.sweeps.plot.plot_sweep_index`) at the end.
    progress : bool, optional
        Show a progress bar on stderr; default: when stderr is a terminal.
    log : callable, optional
        Receives one line per failed case (default: the progress bar, or a warning of the
        ``bearingsim.sweeps.run`` logger).
    lock : FolderLock, optional
        The folder's lock, already held by the caller (a study holds it until its table is written);
        default: taken here and released when the sweep ends.
    desc : str
        The progress bar's label (a study's name).
    force : bool
        Replace another sweep or study in ``outdir`` (default: refused, :func:`check_same_sweep`).
    archives : str
        Which cases get an archive in ``outdir/cases/``: ``auto`` (the multibody cases; a reduced
        case's numbers are in the index and, for a product grid, ``map.h5``), ``all`` or ``none``
        (:func:`bearingsim.sweeps.worker.keeps_archive`).
    staged : StagedRound, optional
        These cases are a round of a staged study (:class:`StagedRound`); default: a sweep of its own.

    Returns
    -------
    SweepOutcome
        ``interrupted`` is the signal number if SIGINT/SIGTERM/SIGHUP stopped the sweep (the index is
        written and finished archives kept either way).
    """
    from bearingsim.sweeps.engines import LocalEngine
    from bearingsim.sweeps.grid import MAP_NAME, grid_axes, write_map
    from bearingsim.sweeps.worker import ARCHIVE_POLICIES

    t0 = time.perf_counter()
    engine = engine or LocalEngine(1)
    try:  # however these end, the engine is stopped
        if archives not in ARCHIVE_POLICIES:
            raise UserError(f"--archives: expected one of {', '.join(ARCHIVE_POLICIES)} (got {archives!r})")
        grid = grid_axes(spec)
        cases, keys, meta, map_attrs = _resolve(spec, engine, archives, grid)
        engine.start(len(cases))  # an unreachable scheduler stops the sweep before anything is written
        outdir, lock, own = _open_folder(outdir, lock, cases, figures, force, archives, staged is None,
                                         meta.get("scenario_toml"))
        _tidy_folder(outdir, grid is not None)
    except BaseException:
        engine.stop()
        raise
    progress = sys.stderr.isatty() if progress is None else progress
    rows = _pending_rows(cases)
    outcome = SweepOutcome(outdir, outdir / "sweep.csv", outdir / "sweep.h5", rows,
                           map=outdir / MAP_NAME if grid else None)
    index = IndexWriter(outdir, rows, keys, {**meta, **(staged.meta if staged else {})})  # a staged study's own too
    with lock if own else contextlib.nullcontext():
        outcome.interrupted = _run_cases(engine, cases, rows, index, outdir / "cases", archives, progress, desc, log,
                                         lambda: write_map(outcome.map, grid, index.columns, map_attrs) if grid else None,
                                         staged)
    outcome.wall_s = time.perf_counter() - t0
    if figures and outcome.interrupted is None:
        from bearingsim.sweeps.plot import plot_sweep_index

        try:
            outcome.figures = plot_sweep_index(outcome.h5, outdir, notes=outcome.figure_notes)
        except KeyboardInterrupt as exc:  # the cases are run and indexed: the command line says so
            exc.resume_note = (f"{counted(len(rows), 'case')} indexed in {outcome.h5}, its figures not all written "
                               f"('bearingsim plot {outcome.h5}' draws them)")
            raise
    return outcome


def _tidy_folder(outdir: Path, has_map: bool) -> None:
    """Before the cases run, remove quietly the temporary files of the folder's index, map, figures and
    tables that a sweep or study killed by SIGKILL left while writing one
    (:func:`bearingsim.outputs.clean_stale_temporaries` of :data:`bearingsim.outputs.FOLDER_FILES`) and, for
    a sweep with no map of its own (zipped axes, no axes, a study's cases), the map an earlier product sweep
    of some of these cases left (``check_sweep_outputs`` let through only bearingsim's): it is not this
    sweep's and would be read as it (a zip sweep that added cases left the product's map of two).
    The sweep figures an earlier run drew (:data:`bearingsim.sweeps.plot.FIGURE_NAMES`, bearingsim's own PNGs
    only) go too: they were drawn from the index this run rewrites, and a sweep that draws figures draws its
    own again at its end (a one-axis sweep's sweep_I.png stayed beside the sweep_map.png of the same folder
    swept over a second axis, and in a cross-check run into a sweep's folder)."""
    from bearingsim.outputs import FOLDER_FILES, _remove_if_own, clean_stale_temporaries, is_own_png
    from bearingsim.sweeps.grid import MAP_NAME
    from bearingsim.sweeps.plot import FIGURE_NAMES

    clean_stale_temporaries(outdir, report=lambda line: None, names=FOLDER_FILES)
    if not has_map:
        (outdir / MAP_NAME).unlink(missing_ok=True)
    for name in FIGURE_NAMES:
        _remove_if_own(outdir / name, is_own_png)


def _run_cases(engine, cases, rows, index, cases_dir, archives, progress, desc, log, write_map,
               staged=None) -> int | None:
    """Resume, run what is left on ``engine`` and keep the index (and, through ``write_map``, the map)
    written however the run ends; the signal number if SIGINT/SIGTERM/SIGHUP stopped it, else None."""
    with _Signals() as signals:
        engine.should_stop = lambda: signals.fired is not None
        bar = None
        interrupted = None
        stale: set = set()
        resumed = False  # the rows hold what the folder had: the index may be written from them
        try:
            _clean_temporaries(cases_dir)
            # stale: hashes of cases whose archive or row came from another version of the model
            todo, stale = _resume(cases, rows, cases_dir.parent, archives, staged.earlier if staged else None)
            resumed = True
            if staged is not None:  # the round's rows from here on, however run_sweep ends (StagedRound)
                staged.rows = rows
            index.write()
            counts = {"done": 0, "stale": 0, "failed": 0, "cached": 0}
            for r in rows:  # of the cases not to run: cached, or (a staged study's earlier rounds) run this time
                counts[r["status"]] = counts.get(r["status"], 0) + (r["status"] != "pending")
            bar = _progress(len(cases), progress, len(cases) - len(todo), desc)
            if bar is not None:
                bar.set_postfix(counts, refresh=True)
            say = log or ((lambda line: bar.write(line, file=sys.stderr)) if bar is not None else _log.warning)
            if todo:
                _collect(engine, todo, cases, rows, stale, counts, index, bar, say, signals, cases_dir, archives)
            if signals.fired is not None:
                raise SweepInterrupted(signals.fired)
        except SweepInterrupted as exc:
            interrupted = exc.signum
        finally:
            try:
                signals.hold()
            except SweepInterrupted:  # the first signal, landed on the call: in fired now (_Signals.hold)
                signals.hold()
            # a signal from here on (it cut the index's writing short once) is only noted, until the handlers go
            try:
                if staged is None:  # a staged study's next round uses it: its caller stops it
                    engine.stop()
            finally:
                if bar is not None:
                    bar.close()
                _clean_temporaries(cases_dir)
                # a resume cut short (a signal, or an error such as a folder at a case archive's name) left the
                # rows it had not reached 'pending': written, the index lost their numbers (a SIGINT during the
                # resume of 1000 finished cases left 349 of them to be run again); the folder keeps its own
                if resumed:
                    if signals.fired is not None:  # the workers have ended: what they finished is on disk
                        _index_finished(cases, rows, index, cases_dir, stale)
                    index.write()
                    write_map()
    if not resumed and signals.fired is not None:  # stopped before any case ran, nothing written: as a signal
        _stop_as_at_start(signals.fired)               # while the sweep starts
    return interrupted if interrupted is not None else signals.fired


def _stop_as_at_start(signum: int) -> None:
    """A sweep stopped by ``signum`` before it wrote anything: the signal goes to the handler that was in place
    before the sweep's (the command line's says the sweep was interrupted before any case ran), as a signal
    while the sweep is still starting does; KeyboardInterrupt if that handler ignored it."""
    signal.raise_signal(signum)
    raise KeyboardInterrupt(signal.Signals(signum).name)


def _index_finished(cases, rows, index, cases_dir: Path, stale: set) -> None:
    """Index the cases of an interrupted sweep that a worker finished in a batch cut short: a batch returns
    its records when all its cases have run (up to :data:`MAX_BATCH`), so the rows of the ones it had run
    stayed ``pending`` though their archives were written. Each pending row whose case's archive is complete
    and current (:func:`~bearingsim.sweeps.index.read_cached`, the resume's own check and numbers) becomes
    ``done`` (``stale`` when it replaced a stale archive), as its record would have made it."""
    for i, (c, row) in enumerate(zip(cases, rows)):
        if row["status"] != "pending":
            continue
        rec = read_cached(cases_dir / f"{c.hash}.h5", c.toml)
        if rec is None or rec["status"] == "stale":
            continue
        rec["status"] = "stale" if c.hash in stale else "done"
        row.update(rec, archive=f"cases/{c.hash}.h5", notes=rec.get("notes", []))
        index.changed(i)


def _open_folder(outdir, lock, cases: list[Case], figures: bool, force: bool, archives: str, check_folder: bool,
                 base_toml: str | None = None):
    """Check the sweep folder and take its lock (unless the caller holds it): (folder, lock, whether the
    lock is taken here). Refused: an unwritable folder, foreign files, another sweep or study (unless
    the caller checks that itself: ``check_folder`` False)."""
    from bearingsim.archive import check_writable_dir
    from bearingsim.sweeps.worker import keeps_archive

    outdir = check_writable_dir(outdir)
    own = lock is None
    if own:
        # a user's file is refused before the lock file is made too (a read-only check), so that refusal leaves
        # the folder as it was; another sweep's files are judged, and with --force removed, only under the lock,
        # never while that sweep may still be writing them
        check_sweep_outputs(outdir, figures)
        lock = FolderLock(outdir).acquire()
    elif not lock.held or lock.path.parent.resolve() != outdir.resolve():
        raise ValueError("run_sweep(lock=...): give the held FolderLock of the sweep folder")
    try:
        check_sweep_outputs(outdir, figures)
        if check_folder:
            check_same_sweep(outdir, cases, force, base_toml)
        if any(keeps_archive(c.model, archives) for c in cases):
            (outdir / "cases").mkdir(exist_ok=True)
    except BaseException:
        if own:
            lock.release()
        raise
    return outdir, lock, own


def _collect(engine, todo, cases, rows, stale, counts, index, bar, say, signals, cases_dir, archives) -> None:
    """Run the cases ``todo`` on ``engine`` and take their records as they come: archives written, rows and
    counts updated, failures said, the index rewritten now and then; stops on a signal."""
    from bearingsim.sweeps.worker import keeps_archive

    by_hash = {c.hash: i for i, c in enumerate(cases)}
    last_index = time.monotonic()
    index_s = 0.0  # how long the last rewrite took
    for records in engine.run(make_batches(todo, engine.workers), str(cases_dir) if engine.shared_fs else None,
                              archives):
        for rec in records:
            i = by_hash[rec["hash"]]
            row = rows[i]
            data = rec.pop("archive", None)
            if rec["status"] == "done" and data is not None:
                write_atomic_bytes(cases_dir / f"{rec['hash']}.h5", data)
            status = "stale" if rec["status"] == "done" and rec["hash"] in stale else rec["status"]
            kept = rec["status"] == "done" and keeps_archive(cases[i].model, archives)
            row.update(status=status, error=rec["error"], wall_s=rec["wall_s"], notes=rec.get("notes", []),
                       summary=rec["summary"], model_version=rec.get("model_version"),
                       archive=f"cases/{rec['hash']}.h5" if kept else "")
            index.changed(i)
            counts[status] += 1
            if rec["status"] == "failed":
                say(f"failed: case {row['case']} ({cases[i].label()}): {rec['error']}")
        if bar is not None:
            bar.set_postfix(counts, refresh=False)
            bar.update(len(records))
        if time.monotonic() - last_index >= max(INDEX_EVERY_S, index_s / INDEX_TIME_SHARE):
            t_index = time.monotonic()
            index.write()
            last_index = time.monotonic()
            index_s = last_index - t_index
        if signals.fired is not None:  # its exception was swallowed (raised inside a callback)
            raise SweepInterrupted(signals.fired)


def _resolve(spec, engine, archives: str, grid) -> tuple[list[Case], list[str], dict, dict]:
    """The cases of ``spec`` (a :class:`SweepSpec`, resolved here while a local pool's workers load the
    model, or a list of cases), the swept keys, the index's metadata and the map's attributes."""
    if not isinstance(spec, SweepSpec):
        cases = list(spec)
        keys = list(dict.fromkeys(k for c in cases for k in c.values))
        return cases, keys, {"scenario": "", "mode": "cases", "origin": "run_sweep(cases)", "grid": json.dumps([]),
                             "grid_rows": 0}, {}
    warm_up = getattr(engine, "warm_up", None)
    if warm_up is not None:  # a local pool's workers load the model while the cases are resolved
        warm_up(spec, archives)
    cases = resolve_cases(spec)
    from bearingsim.scenario import load_scenario, sweep_context

    base = load_scenario(spec.scenario, spec.sets)
    meta = {"scenario": str(spec.scenario), "mode": spec.mode, "origin": spec.origin,
            "grid": json.dumps([k for k, _ in spec.axes]), "grid_rows": len(cases) - len(spec.extra),
            "context": sweep_context(base, spec.keys), "scenario_toml": base.to_toml()}
    return cases, spec.keys, meta, (_map_attrs(spec) if grid else {})


def _map_attrs(spec: SweepSpec) -> dict:
    """Root attributes of a sweep's ``map.h5``: bearingsim's version and the base scenario."""
    from bearingsim._version import __version__
    from bearingsim.scenario import load_scenario

    base = load_scenario(spec.scenario, spec.sets)
    return {"bearingsim_version": __version__, "scenario": base.to_toml(), "base_scenario": str(spec.scenario),
            "sweep": spec.origin}
