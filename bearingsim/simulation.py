"""Orchestration: a scenario in, a result out (and, if asked, its archive and figures).

The path of one run (``docs/architecture.md``)::

    scenario file --load_scenario--> Scenario --Parameters.from_scenario--> Parameters (frozen, SI)
        --model.simulate(parameters, sink)--> Result --archive.write--> archive.h5 --archive.read--> Result
        --Result.save_figures--> PNG figures

The models (:mod:`bearingsim.reduced`, :mod:`bearingsim.multibody`) take the parameters and a sink
for their time series and return a result; they never see the scenario file or the archive.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bearingsim.model_versions import MODEL_FIGURES, MODELS  # noqa: F401 - MODELS: the models by name, re-exported here
from bearingsim.scenario import Scenario, check_run_request, check_scenario_argument

log = logging.getLogger(__name__)  # notes of a plausible run that is not clean (the command line prints them)


def model_module(name: str):
    """The module of a model: ``simulate(parameters, sink=None, progress=False, dt=None)`` and its
    result class ``RESULT``."""
    if name == "reduced":
        from bearingsim import reduced

        return reduced
    if name == "multibody":
        from bearingsim import multibody

        return multibody
    from bearingsim.errors import UserError

    raise UserError(f"model {name!r}: unknown (reduced, multibody)")


def load(path, only=None):
    """Read an archive back into the result class of its model (``only``: the datasets to read, see
    :func:`bearingsim.archive.read`; None: all)."""
    from bearingsim import archive
    from bearingsim.errors import check_path

    check_path(path, "path", "an archive")
    return archive.read(path, model_module(archive.model_of(path)).RESULT, only=only)


def animate(path, out, *, rotations=None, exaggerate=None, fps=30, progress=None, last=None) -> Path:
    """Animate the motion stored in the archive at ``path`` into ``out`` (``.mp4`` or ``.gif``); return
    ``out`` (:func:`bearingsim.animation.render_result` of the archive read back; docs/animation.md).

    ``rotations``: ``(a, b)``, the recorded cage rotations to show (default: the whole stored window);
    ``last``: only the last so many cage rotations of it; ``exaggerate``: the factor K the clearances are
    drawn at (None: automatic, about 0.3 roller radii of drawn pocket play; at most
    :func:`bearingsim.animation.max_exaggeration` of the archive's bearing); ``fps``: frames per second of
    video; ``progress``: ``progress(done, total)`` called after each frame. One-line :class:`UserError` for
    an archive without motion, a window outside the stored one, an ``exaggerate`` above that limit, or an
    output that is not ``.mp4``/``.gif`` or not replaceable.
    """
    from bearingsim import animation

    return animation.render_result(load(path, only=animation.ANIMATION_DATA), out, rotations=rotations,
                                   exaggerate=exaggerate, fps=fps, progress=progress, last=last, where=str(path))


#: what each archive command reads besides the scenario, the summary and the provenance
#: (``show`` prints the scenario; ``compare`` and ``rerun`` compare the attribute groups, the summary among
#: them, and these datasets: every number the run computed, its results and its time series, bit for bit;
#: ``table`` reads the per-rotation arrays its standard errors come from)
SCENARIO_ONLY: tuple[str, ...] = ()
COMPARED = ("results", "observables")
TABLED = ("results/per_rotation",)


#: what :func:`run` calls of a ``sink`` (:class:`bearingsim.results.MemorySink`, :class:`bearingsim.archive.Spool`)
SINK_METHODS = ("timeseries", "discard_timeseries", "collect")


def run(scenario: Scenario, *, progress: bool = False, sink=None, dt: float | None = None, check_step: bool = False):
    """Run a resolved scenario and return its :class:`bearingsim.results.Result`.

    Parameters
    ----------
    scenario : resolved scenario (:func:`bearingsim.load_scenario`).
    progress : show a progress bar on stderr (multibody runs).
    sink : where time series are streamed (default: kept in memory with the result).
    dt : time step [s] overriding ``numerics.dt_s`` and the automatic choice; it becomes the scenario's
        ``numerics.dt_s`` (validated as that key, a refusal naming the argument: "run(): dt: ...", and
        stored with the result, so its archive reruns it).
    check_step : run the scenario again at half the step it ran at, and add a note with the change of each mean
        impulse and whether it is resolved (:func:`bearingsim.plausibility.step_check_note`; the second run
        costs about twice the first and is not kept). Refused for a model without a time step
        (:func:`check_step_possible`).

    The checks are those of ``bearingsim run``: the step is validated as a scenario key, the run request
    too (:func:`bearingsim.scenario.check_run_request`: a multibody run needs a warm-up rotation), and a finished
    run that is not plausible (:func:`bearingsim.plausibility.check`) raises
    :class:`bearingsim.errors.SimulationUnstable`; the one-line notes of a plausible run that is not
    clean are in ``result.notes`` (the command line prints them).
    """
    from bearingsim import archive, plausibility
    from bearingsim.errors import UserError

    check_scenario_argument(scenario, "run()")
    if sink is not None and not all(callable(getattr(sink, m, None)) for m in SINK_METHODS):
        raise UserError(f"run(): sink: expected a sink with the methods {', '.join(SINK_METHODS)}, such as "
                        f"bearingsim.results.MemorySink (got {type(sink).__name__}; None, the default, keeps the "
                        f"time series with the result, and result.save(path) writes its archive)")
    for name, flag in (("progress", progress), ("check_step", check_step)):  # "no" is true: it would do it
        if not isinstance(flag, (bool, np.bool_)):
            raise UserError(f"run(): {name}: expected True or False (got {type(flag).__name__})")
    t0 = time.perf_counter()
    try:
        if dt is not None:
            scenario = scenario.replace(**{"numerics.dt_s": dt})
        check_run(scenario, dt)  # what `bearingsim run` refuses beyond the schema, refused on every path
    except UserError as exc:
        if dt is None:
            raise
        raise _of_argument(exc, scenario.source) from None
    if check_step:
        check_step_possible(scenario, "run(): check_step")
    params = scenario.parameters
    result = model_module(params.model).simulate(params, sink=sink, progress=progress, dt=dt)
    result.scenario = scenario
    result.provenance = {**archive.run_facts(), **result.provenance,  # the code that computed it
                         "wall_time_s": time.perf_counter() - t0}
    result.notes = plausibility.check(result)
    if check_step:
        step = plausibility.step_of(result)
        half = run(scenario.replace(**{"numerics.dt_s": step / 2.0}), progress=progress)
        result.notes.append(plausibility.step_check_note(result, half))
    return result


def check_step_possible(scenario: Scenario, name: str = "--check-step") -> None:
    """Refuse, before anything runs, a step check (``name``) of a model that has no time step (the reduced
    model's event method, whose impacts are found to machine precision between closed-form flights), and one
    whose half step the run at half the step would refuse (:func:`check_run` of it: the euler method's step
    count, a rigid scene's bounds), naming ``name`` and the half step."""
    from bearingsim import plausibility
    from bearingsim.errors import UserError

    if scenario.model == "reduced" and scenario.reduced.method == "event":
        raise UserError(f"{name}: the reduced model's event method has no time step to halve (its impacts are "
                        f"exact); reduced.method = \"euler\" has one")
    p = scenario.parameters
    step = p.numerics.dt if p.numerics.dt is not None else plausibility.automatic_dt(p)
    try:
        check_run(scenario.replace(**{"numerics.dt_s": step / 2.0}))
    except UserError as exc:
        why = str(exc).removeprefix(f"{scenario.source}: ")
        raise UserError(f"{name}: half the time step, {step / 2.0:.3g} s, is refused: {why}") from None


def _of_argument(exc, source: str):
    """``exc``, a refusal of the scenario ``source``'s ``numerics.dt_s`` that :func:`run`'s argument ``dt`` gave,
    said of the argument ("run(): dt: why"): the scenario file does not hold that value. Any other refusal
    is ``exc`` itself."""
    head = f"{source}: numerics.dt_s: "
    text = str(exc)
    return type(exc)(f"run(): dt: {text[len(head):]}") if text.startswith(head) else exc


def check_run(scenario: Scenario, dt: float | None = None) -> None:
    """Refuse, without running, what :func:`run` of ``scenario`` would refuse before its first step:
    :func:`bearingsim.scenario.check_run_request`, and the model's time step (a given ``numerics.dt_s``
    far above the stable step, the euler method's limits). ``bearingsim run --dry-run`` checks this."""
    from bearingsim.errors import UserError

    check_run_request(scenario)
    try:
        model_module(scenario.model).check_start(scenario.parameters, dt)
    except UserError as exc:  # the model names the key; the scenario's refusals name its file too
        named = UserError(f"{scenario.source}: {exc}")
        named.involves = getattr(exc, "involves", ())  # the keys the check read, for the overrides' names
        raise named from None


@dataclass
class RunOutput:
    archive: Path
    figures: list[Path] = field(default_factory=list)
    result: object = None


def default_output(scenario: Scenario, root: str | Path = "outputs") -> Path:
    """``<root>/<name>.h5``, never outside ``root`` (:func:`bearingsim.outputs.default_output`)."""
    from bearingsim import outputs

    return outputs.default_output(scenario.name, root)


def check_output(scenario: Scenario, out: str | Path | None = None, *, figures: bool = True,
                 force: bool = False) -> Path:
    """Refuse, without writing anything, what :func:`run_scenario` would refuse of its output before its
    first step: the target and its figures (:func:`bearingsim.outputs.check_target`), a folder that could
    not be made or takes no file (:func:`bearingsim.outputs.check_writable`) and, unless ``force``, an
    archive there of another scenario (:func:`check_same_scenario`). Returns the archive path.
    ``bearingsim run --dry-run`` checks this."""
    from bearingsim import outputs

    out = _target(scenario, out, figures)
    outputs.check_writable(out)
    if not force:
        check_same_scenario(out, scenario)
    return out


def _target(scenario: Scenario, out: str | Path | None, figures: bool) -> Path:
    """The archive path of a run (default ``outputs/<name>.h5``), checked with the figures it writes
    beside it (:func:`bearingsim.outputs.check_target`)."""
    from bearingsim import archive, outputs

    out = Path(out) if out is not None else default_output(scenario)
    names = model_module(scenario.model).RESULT.FIGURES if figures else ()
    return outputs.check_target(out, [scenario.source], archive.is_archive, figures=names,
                                own_file_error=archive.own_file_target_error)


def check_same_scenario(out: Path, scenario: Scenario) -> None:
    """Refuse to replace the archive ``out`` when it holds a run of another resolved scenario (a
    ``--set`` on the same file writes to the same default name): one line naming the archive, the keys
    that differ, and ``-o`` / ``--force``. A rerun of the same scenario (or of one that differs only in keys
    its model does not read), an unreadable or incomplete archive (never a result) and no file at all pass (:func:`bearingsim.archive.check_same_scenario`, which
    :meth:`Result.save` calls too)."""
    from bearingsim import archive

    archive.check_same_scenario(out, scenario)


def run_scenario(
    scenario: Scenario,
    out: str | Path | None = None,
    *,
    figures: bool = True,
    progress: bool = False,
    exclusive: bool = True,
    notes: bool = True,
    force: bool = False,
    check_step: bool = False,
) -> RunOutput:
    """Run ``scenario``, write its archive (atomically, time series streamed into it) and, optionally,
    its PNG figures, drawn from the archive as written.

    Parameters
    ----------
    scenario : resolved scenario
    out : archive path; default ``outputs/<name>.h5``
    figures : write PNG figures beside the archive (``<stem>_<figure>.png``). Once the archive is written,
        the figures at its stem of any model that this run does not write (all of them without
        ``figures``) are removed: they were drawn from the archive it replaced
        (:func:`bearingsim.outputs.remove_figures`); a run that fails leaves them as they were
    progress : show a progress bar (multibody runs)
    exclusive : hold a lock on the target while writing (refusing a concurrent run to it) and clean stale
        temporary files of dead runs in its folder first; a sweep, which locks its whole folder, passes False
    notes : print the plausibility notes of the run (:func:`bearingsim.plausibility.check`) and the note of a
        dead run's temporary file removed on stderr; ``bearingsim run -q`` and sweep cases pass False (the
        counts stay in the archive's provenance)
    force : replace an archive of a different scenario at ``out`` (default: refused,
        :func:`check_same_scenario`; a rerun of the same scenario replaces its archive)
    check_step : run it again at half its step and note the change (:func:`run`'s ``check_step``); the note is
        in the archive with the run's others
    """
    from bearingsim import archive, outputs
    from bearingsim.errors import UserError

    out = _target(scenario, out, figures)  # before the lock
    made = outputs.missing_folders(out.parent)  # created for this run: removed again if it writes no archive
    try:
        lock = outputs.OutputLock(out).acquire() if exclusive else None  # one writer per target, figures included
    except BaseException:
        outputs.remove_empty(made)
        raise
    written, drawn = False, ()
    try:
        try:
            if not force:
                check_same_scenario(out, scenario)
            if exclusive:  # its note is one of the run's notes: none with notes=False (run -q)
                outputs.clean_stale_temporaries(out.parent, report=None if notes else (lambda line: None))
            with archive.Spool(out) as spool:
                result = run(scenario, progress=progress, sink=spool, check_step=check_step)  # exit 3: no archive
                if notes:
                    for note in result.notes:
                        log.info(note)
                archive.write(result, out, spool)
            written = True
            drawn = type(result).FIGURES if figures else ()  # an earlier run's figures at this stem are not this run's
            pngs = _figures(out, result, drawn)
        finally:
            if lock is not None:
                lock.release()
            if not written:  # refused (exit 2/3), interrupted or failed: no folder of its own left behind
                outputs.remove_empty(made)
    except KeyboardInterrupt as exc:  # SIGINT/SIGTERM once the archive is written: it is a result, kept
        if written:  # the command line says so (not "no archive written"), and which figures it had to draw
            exc.archive_written = out
            exc.figures_expected = [outputs.figure_path(out.with_suffix(""), n) for n in drawn]
        raise
    return RunOutput(archive=out, figures=list(pngs), result=result)


def _figures(out: Path, result, drawn) -> list[Path]:
    """Once the archive ``out`` is written: remove the figures at its stem that this run does not draw (a
    replaced archive's), then draw those of ``drawn``; return their paths."""
    from bearingsim import archive, outputs
    from bearingsim.errors import UserError

    outputs.remove_figures(out.with_suffix(""), [n for names in MODEL_FIGURES.values() for n in names
                                                 if n not in drawn])
    if not drawn:
        return []
    try:
        return archive.read(out, type(result)).save_figures(out.with_suffix(""))
    except OSError as exc:
        raise UserError(f"{exc.filename or str(out.with_suffix('')) + '_*.png'}: cannot write figure "
                        f"({exc.strerror or exc}); the archive {out} is complete") from None
