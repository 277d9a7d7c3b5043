"""What runs inside a worker: a batch of cases, each into its archive (or none), failures caught one by one.

Imported by local pool processes and by dask workers (which need ``bearingsim`` installed; they need
no file system shared with the client: with ``return_bytes`` the archive comes back as bytes).
"""
from __future__ import annotations

import logging
import signal
import tempfile
import time
from pathlib import Path

import numpy as np

from bearingsim.wording import run_notes

log = logging.getLogger(__name__)


def one_line_error(exc: BaseException) -> str:
    """A failure as one line: ``str(exc)`` for bearingsim's own errors, ``path: what`` for the system's error
    about a file (a raw "NotADirectoryError: [Errno 20] Not a directory: '...'" was recorded), else
    ``Class: message``."""
    from bearingsim.errors import SimulationUnstable, UserError

    if isinstance(exc, (UserError, SimulationUnstable)):
        text = str(exc)
    elif isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        text = f"{exc.filename}: {exc.strerror}"
    else:
        text = f"{exc.__class__.__name__}: {exc}"
    text = " ".join(text.split())
    return text[:500] or exc.__class__.__name__


def _numbers(summary: dict) -> dict[str, float]:
    out = {}
    for k, v in summary.items():
        if isinstance(v, (bool, np.bool_)):
            continue
        if isinstance(v, (int, float, np.integer, np.floating)) and k != "wall_s":
            out[k] = float(v)
    return out


ARCHIVE_POLICIES = ("auto", "all", "none")


def keeps_archive(model: str, archives: str) -> bool:
    """Whether a case of ``model`` gets its archive under the sweep's policy ``archives``: ``all``
    every case, ``none`` no case, ``auto`` the multibody cases only (a reduced-model case's numbers
    are in the sweep's index and map; its archive costs three times its solution)."""
    return archives == "all" or (archives == "auto" and model != "reduced")


def _run_in_memory(scenario, notes: bool = True, archive: bool = True):
    """Run a case in memory and, with ``archive``, build its archive in memory: what
    :func:`bearingsim.simulation.run_scenario` does (plausibility check and its notes included),
    with the file written in one piece by the caller. Returns (result, archive bytes or None)."""
    from bearingsim import archive as archive_module, simulation

    result = simulation.run(scenario)  # plausibility checked there
    for note in result.notes:
        if notes:
            log.info(note)
    return result, (archive_module.to_bytes(result) if archive else None)


#: True in a pool worker once it has been told to end (SIGTERM, :mod:`bearingsim.sweeps.engines`): the stop's
#: exception is raised wherever the worker is, and the code it lands in may turn it into another (numba's
#: compiled code, while it calls back into Python: "SystemError: CPUDispatcher(...) returned a result with
#: an exception set"), which a case would record as its failure before the worker went on to wait for a task
ending = False
#: True in a worker while it warms up (:func:`warm_up`): it holds nothing of the sweep's (no task queue lock,
#: no file), so SIGTERM then ends it at once (:mod:`bearingsim.sweeps.engines`) rather than by an exception
#: raised inside numba's loading of its compiled kernels, whose objects, left half made, could be freed twice
#: (a worker of a sweep refused while its cases were resolved wrote glibc's "free(): double free detected" on
#: the sweep's stderr)
warming = False


class WorkerStop(SystemExit):
    """SIGTERM in a worker process: it ends the worker (raised by the signal's handler, and by
    :func:`end_if_told` once the worker is ending)."""


def end_if_told() -> None:
    """End this worker (:class:`WorkerStop`, exit status 143 as SIGTERM's own) if it has been told to."""
    if ending:
        raise WorkerStop(128 + signal.SIGTERM)


def run_case(case_hash: str, toml_text: str, target: Path | None, model=None, archives: str = "all") -> dict:
    """Run one case into the archive ``target`` (written atomically), or with ``target`` None return
    the archive's bytes under ``"archive"``; a case that keeps no archive under the policy
    ``archives`` (:func:`keeps_archive`) runs in memory and returns its numbers only. ``model``: the
    validated scenario model the client wrote ``toml_text`` from (a forked local worker: the same code
    validated it), else the text is resolved again here.

    Returns a record: ``hash``, ``status`` (``done``/``failed``), ``error``, ``wall_s`` (the run's own
    wall time, ``wall_time_s`` of its provenance, which its archive stores; of a failed case, the time to
    its failure),
    ``model_version`` (of the model that computed it), ``notes`` (the run's plausibility notes,
    :func:`bearingsim.wording.run_notes`) and the summary numbers with their standard errors
    (:func:`bearingsim.stats.summary_standard_errors`, the one estimator of every command) and the wear rates of
    :func:`bearingsim.wear.sweep_rates`.
    """
    from bearingsim.scenario import Scenario
    from bearingsim.stats import summary_standard_errors
    from bearingsim.sweeps.spec import scenario_from_toml
    from bearingsim.wear import sweep_rates

    t0 = time.perf_counter()
    data = None
    try:
        if model is not None:  # toml_text is this model's to_toml(): the archive stores it as it is
            scenario = Scenario(model, "<sweep case>", toml=toml_text)
        else:
            scenario = scenario_from_toml(toml_text)
        keep = keeps_archive(scenario.model, archives)
        if not keep:  # numbers only: the same run as with an archive, without building it
            res, data = _run_in_memory(scenario, notes=False, archive=False)
        elif scenario.model == "reduced":  # one pass, no time series: the archive is built in memory
            res, data = _run_in_memory(scenario, notes=False)  # per-case notes: not on the sweep's terminal
            if target is not None:
                _write_file(target, data)
                data = None
        elif target is not None:  # long runs stream their time series into the archive's file
            res = _run_to_file(scenario, target)
        else:
            with tempfile.TemporaryDirectory(prefix="bearingsim-sweep-") as tmp:
                path = Path(tmp) / f"{case_hash}.h5"
                res = _run_to_file(scenario, path)
                data = path.read_bytes()
        summary = _numbers(res.summary)
        summary.update(summary_standard_errors(res.per_rotation, scenario.model))
        summary.update(sweep_rates(res))  # the wear rates, as 'bearingsim wear' computes them (docs/sweeps.md)
        # the run's own wall time, the one its archive stores: the same number when the case is cached later
        wall = res.provenance.get("wall_time_s")
        rec = {"hash": case_hash, "status": "done", "error": "",
               "wall_s": float(wall) if wall is not None else time.perf_counter() - t0,
               "summary": summary, "model_version": res.provenance.get("model_version"),
               "notes": run_notes(res.notes)}
        if data is not None:
            rec["archive"] = data
        return rec
    except Exception as exc:  # noqa: BLE001 - a failing case is recorded, the sweep goes on
        end_if_told()  # the stop's exception, turned into another, is not the case's failure
        return {"hash": case_hash, "status": "failed", "error": one_line_error(exc),
                "wall_s": time.perf_counter() - t0, "summary": {}}


def _run_to_file(scenario, target: Path):
    from bearingsim.simulation import run_scenario

    return run_scenario(scenario, target, figures=False, progress=False, exclusive=False, notes=False,
                        force=True).result  # the sweep owns its folder (case archives named by scenario hash)


def _write_file(target: Path, data: bytes) -> None:
    """``data`` into ``target`` through a temporary name and a rename (one line if that fails, naming what is in
    the way: :func:`bearingsim.outputs.write_error`)."""
    from bearingsim.outputs import write_atomic_bytes, write_error

    try:
        write_atomic_bytes(Path(target), data)
    except OSError as exc:
        raise write_error(target, exc) from None


def warm_up(toml_text: str, archive: bool = True) -> None:
    """Run a reduced-model scenario once and, with ``archive``, build its archive in memory, discarding
    both: the first case of a process loads the compiled model (~0.3 s). Errors are ignored (the cases
    report theirs)."""
    global warming
    from bearingsim.sweeps.spec import scenario_from_toml

    warming = True
    try:
        _run_in_memory(scenario_from_toml(toml_text), notes=False, archive=archive)
    except Exception:  # noqa: BLE001
        pass
    finally:
        warming = False


def run_batch(items: list[tuple[str, str]], cases_dir: str | None = None, archives: str = "all",
              command: str | None = None) -> list[dict]:
    """Run ``items`` (``(hash, resolved TOML)`` pairs) one after the other.

    Parameters
    ----------
    items : list of (str, str) or (str, str, model)
        Case hash and resolved scenario TOML, and optionally the validated scenario model of that
        TOML (:attr:`bearingsim.sweeps.spec.Case.scenario`).
    cases_dir : str or None
        Write each archive as ``cases_dir/<hash>.h5`` (a file system the client sees). With None,
        return each archive's bytes under ``"archive"`` (dask workers on other machines): a
        reduced-model archive is built in memory, a multibody run streams into a private temporary
        folder.
    archives : str
        Which cases get an archive (:func:`keeps_archive`): ``all``, ``none`` or ``auto``.
    command : str or None
        The sweep's command, which each case's provenance records (a dask worker's own is ``dask worker
        ...``); None: this process's (a local pool's forked worker has the sweep's).
    """
    from bearingsim.archive import given_command

    records = []
    with given_command(command):
        for h, text, *model in items:
            end_if_told()  # told to end while a case ran (its exception swallowed where it landed): no next case
            records.append(run_case(h, text, Path(cases_dir) / f"{h}.h5" if cases_dir is not None else None,
                                    model[0] if model else None, archives))
    end_if_told()  # nor a wait for the next batch: the sweep that stopped it reads no more records
    return records
