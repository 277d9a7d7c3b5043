"""Running studies: their cases on the sweep engine, then each study's table and figures.

A study (:class:`Study`) is a list of cases (resolved scenarios, :class:`bearingsim.sweeps.spec.Case`)
plus what it makes of their archives: a table and figures. :func:`run_studies` runs the cases of one or
more studies in one folder on the one sweep engine (:func:`bearingsim.sweeps.run_sweep`: a local pool of
processes or a dask cluster, resume from the archives already there, failures kept, SIGINT/SIGTERM/SIGHUP,
progress), holding the folder's lock (:class:`bearingsim.outputs.FolderLock`) until every table and
figure is written (atomically, :func:`bearingsim.outputs.atomic_file`).

The folder then holds ``cases/<hash>.h5`` (one archive per case, named by the content hash of its
scenario), ``sweep.csv``/``sweep.h5`` (the index of the cases: status, error, summary numbers) and the
studies' own tables and figures. Running the same command again reuses every archive computed by the
same model version (``cached``) and runs only what is missing, failed or stale.
"""
from __future__ import annotations

import os
import signal
from dataclasses import dataclass, field
from pathlib import Path

from bearingsim.errors import UserError
from bearingsim.stats import batch_sem  # noqa: F401 - the studies' estimator, re-exported
from bearingsim.sweeps.spec import Case, case_hash


def table_csv(rows: list[dict], columns) -> bytes:
    """A study's table as CSV (:func:`bearingsim.outputs.csv_bytes`): the header, then each row's
    ``columns``: text as it is, an integer as an integer, a float by ``repr`` (every digit), NaN as an empty
    field."""
    import math

    import numpy as np

    from bearingsim.outputs import csv_bytes

    def cell(v) -> str:
        if isinstance(v, str):
            return v
        if isinstance(v, (int, np.integer)):
            return str(int(v))
        return "" if math.isnan(v) else repr(float(v))

    return csv_bytes(columns, ([cell(r[c]) for c in columns] for r in rows))


def table_columns(rows: list[dict], columns) -> dict:
    """A study's rows as the columns of an index table (:func:`bearingsim.archive.write_table_file`):
    a text column as objects, any other as float64 (the first row says which)."""
    import numpy as np

    return {c: (np.array([r[c] for r in rows], dtype=object) if isinstance(rows[0][c], str)
                else np.array([r[c] for r in rows], dtype=float)) for c in columns}

#: statuses of a case whose archive holds its numbers
FINISHED = ("done", "cached", "stale")


def case_of(scenario, values: dict) -> Case:
    """The case of a resolved scenario; ``values`` label it in messages and in the case index."""
    text = scenario.to_toml()
    return Case(hash=case_hash(text), values=dict(values), toml=text, model=scenario.model,
                scenario=scenario.model_)


class Study:
    """A list of cases plus a table and figures.

    Subclasses set :attr:`cases` and :attr:`outputs` and define :meth:`finish`. A staged study (``staged``
    True: a life study's stages, each run in the pockets the stages before it wore) knows only its first
    cases before anything runs and adds the others from the results (:meth:`next_cases`).

    Attributes
    ----------
    cases : list of Case
        What to run (each case once; two studies may share a case); of a staged study, its first cases.
    outputs : list of (file name, signature, what)
        The files the study writes into the folder, checked before anything runs
        (:func:`bearingsim.outputs.check_replaceable`: a user's file or a link there is refused).
    """

    name = "study"
    cases: list[Case]
    outputs: list[tuple[str, object, str]]
    staged = False

    def cases_to_come(self, known: set[str]) -> int:
        """How many of a staged study's cases are not among ``known`` (the hashes of the cases the engine
        has seen): its later stages, what an interrupted or failed study counts as not run beside the
        known cases; 0 for a study that is not staged."""
        return 0

    def next_cases(self, outdir: Path, records: dict[str, dict]) -> list[Case]:
        """The cases the finished ones call for (``records`` as in :meth:`finish`): a staged study's next
        stage, none when it is done. Called after every round of cases, while no case has failed."""
        return []

    def check_folder(self, outdir: Path, force: bool) -> None:
        """A staged study's check of what ``outdir`` holds, before anything runs: its later cases are not
        known yet, so the engine cannot tell its own earlier run from another study's
        (:func:`bearingsim.sweeps.run.check_same_sweep`); with ``force`` another study's files are removed."""

    def index_attrs(self) -> dict:
        """Root attributes a staged study records in the folder's case index (``sweep.h5``) from its first round
        on, before any case runs: what its :meth:`check_folder` reads of an earlier run stopped before the study
        wrote its table ({} by default)."""
        return {}

    def finish(self, outdir: Path, records: dict[str, dict]) -> list[Path]:
        """Build the table from the cases' records (``records[hash]``: a row of the case index with
        ``status``, ``error``, ``archive`` relative to ``outdir``, ``summary``), write it and the
        figures into ``outdir`` and return the paths written. Failed cases are kept in the table as
        the study sees fit (NaN numbers or a missing row), never an exception."""
        raise NotImplementedError


@dataclass
class StudiesOutcome:
    """What :func:`run_studies` did: the engine's outcome (rows of every case, counts, interruption)
    and the files each study wrote (none if interrupted)."""

    sweep: object  # bearingsim.sweeps.SweepOutcome
    written: list[Path] = field(default_factory=list)
    planned: int = 0  #: the cases known and, of a staged study, still to come (its later stages when it stopped)

    @property
    def interrupted(self) -> int | None:
        return self.sweep.interrupted

    @property
    def failed(self) -> list[dict]:
        return self.sweep.failed

    def count(self, status: str) -> int:
        return self.sweep.count(status)

    def counts(self) -> str:
        """``"3 done, 2 cached, 0 failed"`` (and stale cases when there are: :meth:`SweepOutcome.counts`)."""
        return self.sweep.counts()


def make_engine(jobs: int | None = None, scheduler: str | None = None, option: str = "-j"):
    """The engine of a command's ``-j N`` / ``--scheduler ADDRESS`` (a one-line UserError for ``-j 0``)."""
    from bearingsim.sweeps.engines import DaskEngine, LocalEngine

    if scheduler is not None:
        return DaskEngine(scheduler)
    jobs = jobs if jobs is not None else (os.cpu_count() or 1)
    if jobs < 1:
        raise UserError(f"{option} {jobs}: give at least 1 worker process")
    return LocalEngine(jobs)


def check_outputs(outdir: Path, studies) -> None:
    """Refuse, before any case runs, a study output that is a link, a folder or a user's file."""
    from bearingsim.outputs import check_replaceable

    for study in studies:
        for name, signature, what in study.outputs:
            check_replaceable(outdir / name, signature, what)


def run_studies(studies, outdir, *, engine=None, progress: bool | None = None, log=None,
                force: bool = False) -> StudiesOutcome:
    """Run the cases of ``studies`` in ``outdir`` on ``engine``, then let each study write its table
    and figures.

    Parameters
    ----------
    studies : list of Study
    outdir : path
        The folder (created); it may hold the archives of an earlier, interrupted or failed, run of
        the same studies: those are reused.
    engine : LocalEngine or DaskEngine, optional
        Default: a local pool of one process.
    progress : bool, optional
        Progress bar on stderr; default when stderr is a terminal.
    log : callable, optional
        Receives one line per failed case (default: stderr).
    force : bool
        Replace another sweep or study in ``outdir`` (default: refused,
        :func:`bearingsim.sweeps.run.check_same_sweep`).

    Returns
    -------
    StudiesOutcome
        ``interrupted`` is the signal number if SIGINT/SIGTERM/SIGHUP stopped the cases (finished archives
        and the case index are kept; no table is written; run again to resume).

    Raises
    ------
    StudyFailed
        Every case failed (each is in the case index with its error): no table or figure is written.
    """
    from bearingsim.archive import check_writable_dir
    from bearingsim.outputs import FolderLock
    from bearingsim.sweeps.engines import LocalEngine

    engine = engine or LocalEngine(1)
    try:
        cases = _new_cases([], [c for s in studies for c in s.cases])
        engine.start(len(cases))  # an unusable --scheduler is refused before the folder is made, as a sweep's
        outdir = check_writable_dir(outdir)
        check_outputs(outdir, studies)  # before the lock file: a refusal leaves the folder as it was
    except BaseException:
        engine.stop()
        raise
    with FolderLock(outdir) as lock:
        try:
            for study in studies:
                if study.staged:
                    study.check_folder(outdir, force)
        except BaseException:  # a folder of another study refused: the engine started above stops
            engine.stop()
            raise
        sweep = _run_rounds(studies, cases, outdir, engine, lock, dict(progress=progress, log=log, force=force))
        known = {r["case"] for r in sweep.rows}
        out = StudiesOutcome(sweep, planned=len(known) + sum(s.cases_to_come(known) for s in studies))
        if sweep.interrupted is None:
            if sweep.rows and all(r["status"] == "failed" for r in sweep.rows):
                raise every_case_failed("+".join(s.name for s in studies), sweep, out.planned)
            records = {r["case"]: r for r in sweep.rows}
            try:
                for study in studies:
                    out.written += study.finish(outdir, records)
            except KeyboardInterrupt as exc:  # the cases are done and kept: the same command writes the rest
                done = "its one case" if len(sweep.rows) == 1 else f"all {len(sweep.rows)} cases"
                exc.resume_note = f"{done} done and kept in {outdir}, its tables and figures not all written"
                raise
    return out


class StudyFailed(UserError):
    """Every case of a study failed: no table or figure is written (a table of empty numbers would read as
    a finished study); the cases' errors stay in the folder's case index. Exit code 1, as a study with
    failed cases."""

    exit_code = 1


def every_case_failed(what: str, sweep, planned: int = 0) -> StudyFailed:
    """The one line of a study (``what``) whose cases all failed, naming the first with its error (a line
    per failed case is said as it fails); ``planned``: its cases, those of later stages included."""
    from bearingsim.wording import counted

    n, first = len(sweep.rows), sweep.failed[0]
    name = ", ".join(f"{k}={v}" for k, v in first["values"].items())
    which = "its one case failed" if n == 1 else f"all {n} cases failed, the first"
    rest = planned - n  # a staged study stops at a failed stage
    later = f"; {counted(rest, 'later case')} not run (each needs the one before)" if rest > 0 else ""
    return StudyFailed(f"{what}: {which} ({name}: {first['error']}){later}; no table or figure written (the errors "
                       f"are in {sweep.csv}; the same command runs them again)")


def _new_cases(cases: list[Case], more) -> list[Case]:
    """``cases`` and those of ``more`` not among them yet (by content hash), in order."""
    seen = {c.hash for c in cases}
    out = list(cases)
    for c in more:
        if c.hash not in seen:
            seen.add(c.hash)
            out.append(c)
    return out


#: what a round of a staged study hands on of each case's row to the next (sweeps.run_sweep's ``earlier``)
_ROW_KEYS = ("status", "error", "archive", "wall_s", "model_version", "summary", "notes")


def _run_rounds(studies, cases: list[Case], outdir: Path, engine, lock, options: dict):
    """Run ``cases`` on the engine; then, while the studies call for more (:meth:`Study.next_cases`) and
    none has failed or been interrupted, those too, each round indexed with all before it. Returns the
    last round's sweep outcome."""
    from bearingsim.sweeps.run import StagedRound, SweepInterrupted, SweepOutcome, _Signals, run_sweep

    desc = "+".join(s.name for s in studies)
    sweep, earlier = None, {}
    round_ = None  # the present round of a staged study: its rows, once its sweep has them (StagedRound)
    # between rounds too (a staged study computing its next cases), SIGINT/SIGTERM/SIGHUP end the study as one
    # during a round does: the finished cases kept, the same command resumes
    staged = any(s.staged for s in studies)
    recorded = {k: v for s in studies if s.staged for k, v in s.index_attrs().items()}  # in every round's index
    stopped = None  # the signal that stopped the rounds
    with _Signals() as outer:
        try:
            while True:  # a staged study's rounds share the engine: its workers keep the model they loaded
                round_ = StagedRound(earlier, meta=recorded) if staged else None
                sweep = run_sweep(cases, outdir, engine=engine, figures=False, lock=lock, desc=desc, archives="all",
                                  staged=round_, **options)  # tables and figures are made from the cases' archives
                if sweep.interrupted is not None or sweep.failed:
                    break
                records = {r["case"]: r for r in sweep.rows}
                earlier = {h: {k: r[k] for k in _ROW_KEYS} for h, r in records.items()}
                more = _new_cases(cases, [c for s in studies for c in s.next_cases(outdir, records)])
                if outer.fired is not None:  # its exception was swallowed (raised inside a callback)
                    raise SweepInterrupted(outer.fired)
                if len(more) == len(cases):
                    break
                cases = more
        except SweepInterrupted as exc:
            stopped = exc.signum
            if round_ is not None and round_.rows is not None and (sweep is None or sweep.rows is not round_.rows):
                # the signal came after the round's cases, before run_sweep returned: its rows, not the round's before
                sweep = SweepOutcome(outdir, outdir / "sweep.csv", outdir / "sweep.h5", round_.rows)
        finally:
            try:  # a signal while the engine stops is noted, not raised out of the study (a traceback, exit 1)
                outer.hold()
            except SweepInterrupted:  # the first signal, landed on the call (sweeps.run._Signals.hold)
                outer.hold()
            engine.stop()
    stopped = stopped or outer.fired
    if sweep is None:  # before any case ran: the signal goes to the handler that was in place
        signal.raise_signal(stopped)
        raise KeyboardInterrupt(signal.Signals(stopped).name)  # that handler ignored it: stopped all the same
    if stopped is not None and sweep.interrupted is None:  # the cases ran; the study is not finished: resumed
        sweep.interrupted = stopped
    return sweep


def in_folder(studies, outdir=None, *, jobs: int = 1, engine=None, progress: bool = False) -> StudiesOutcome:
    """:func:`run_studies` for the Python API: in ``outdir`` or, with None, a temporary folder removed
    afterwards; ``jobs`` local processes unless ``engine`` is given. SIGINT/SIGTERM/SIGHUP during the cases
    raise KeyboardInterrupt (finished archives in ``outdir`` are kept)."""
    import tempfile

    engine = engine or make_engine(jobs)
    if outdir is None:
        with tempfile.TemporaryDirectory(prefix="bearingsim-study-") as tmp:
            out = run_studies(studies, tmp, engine=engine, progress=progress)
    else:
        out = run_studies(studies, outdir, engine=engine, progress=progress)
    if out.interrupted is not None:
        raise KeyboardInterrupt(signal.Signals(out.interrupted).name)
    return out


def load_result(outdir: Path, record: dict):
    """The result stored in a finished case's archive, or None for a failed or pending case."""
    from bearingsim.simulation import load

    if record["status"] not in FINISHED:
        return None
    return load(Path(outdir) / record["archive"])


def summary_of(outdir: Path, record: dict) -> dict[str, float] | None:
    """The summary numbers of a finished case without loading its archive, or None for a failed or
    pending case: the sweep's record holds them (from the run itself, or read by
    :func:`bearingsim.archive.peek` for a case found in its archive); a record without them is read
    the same cheap way (the summary's attributes, not the time series)."""
    from bearingsim import archive

    if record["status"] not in FINISHED:
        return None
    if record.get("summary"):
        return record["summary"]
    got = archive.peek(Path(outdir) / record["archive"])
    if got is None:
        raise UserError(f"{Path(outdir) / record['archive']}: incomplete or damaged archive of a finished case")
    return got["summary"]
