"""bearingsim: roller/cage dynamics of rolling bearings and the cage-wear impulse.

SI units throughout the package; units appear in names only at the edges (scenario keys, plots).

The Python API::

    import bearingsim
    sc = bearingsim.load_scenario("scenarios/paper_3000rpm.toml", set={"operating.inner_ring_speed_rpm": 500})
    r = bearingsim.run(sc)            # a Result: r.summary, r.per_rotation["I_dec"], r.impacts, r.plot_*()
    r.save("x.h5")
    r2 = bearingsim.load("x.h5")      # the same result, read back from the archive

Every module and subpackage is an attribute of the package on first use (``bearingsim.outputs.ArchiveWriteError``,
``bearingsim.studies.life.read_life`` after a plain ``import bearingsim``): imported then, not before
(PEP 562), so ``import bearingsim`` stays light.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from bearingsim._version import __version__  # noqa: E402
from bearingsim.errors import SimulationUnstable, UnreadKeyWarning, UserError  # noqa: E402

if TYPE_CHECKING:  # the annotations' classes; imported when used, so that `import bearingsim` stays light
    import os
    from pathlib import Path

    from bearingsim.results import Result
    from bearingsim.scenario import Scenario
    from bearingsim.studies.sensitivity import SensitivityResult
    from bearingsim.studies.uncertainty import UncertaintyResult
    from bearingsim.sweeps.engines import DaskEngine, LocalEngine


def load_scenario(path: str | os.PathLike[str], set: dict[str, Any] | None = None,
                  overrides: list[str] | None = None) -> Scenario:
    """Read a scenario file, merge its preset and the package defaults, apply overrides, validate.

    Parameters
    ----------
    path : scenario TOML file.
    set : ``{"dotted.key": value}`` overrides with Python values (``{"numerics.rotations": 10}``).
    overrides : ``["dotted.key=VALUE", ...]`` overrides as on the command line (VALUE read as TOML).

    ``overrides`` are applied, then ``set``: a key given in both takes its value from ``set``; a key given
    twice in ``overrides`` is refused (a ``UserError`` naming it, as a repeated ``--set``).

    Keys the file, ``overrides`` or ``set`` give that the run does not read (``numerics.dt_s`` with the
    reduced model's event method, a multibody key in a reduced scenario) are named in one
    :class:`bearingsim.UnreadKeyWarning`, the note ``bearingsim run`` prints; so is a given
    ``output.motion_rotations`` longer than the recorded rotations with ``output.motion_start_rotation =
    "last"``, of which the run reads only the recorded rotations (:func:`bearingsim.scenario.motion_window_note`).
    """
    import warnings

    from bearingsim import scenario

    sc = scenario.load_scenario(path, overrides, values=set, origin="overrides")
    for note in scenario.given_key_notes(sc, scenario.given_keys(path, overrides, set)):
        warnings.warn(f"bearingsim: note: {note}", UnreadKeyWarning, stacklevel=2)
    return sc


def run(scenario: Scenario, *, progress: bool = False, sink: Any = None, dt: float | None = None,
        check_step: bool = False) -> Result:
    """Run a resolved scenario (see :func:`bearingsim.simulation.run`) and return its result; ``check_step``:
    run it again at half its time step and note the change of each mean impulse (``bearingsim run --check-step``).

    A run that is plausible but not clean returns its result with its one-line notes in ``result.notes``,
    each also issued as a :class:`bearingsim.errors.PlausibilityWarning`. A ``dt`` the run does not read
    (the reduced model's event method has no time step) is named in a :class:`bearingsim.UnreadKeyWarning`."""
    import warnings

    from bearingsim.errors import PlausibilityWarning
    from bearingsim.plausibility import STEP_CHECK_HEAD
    from bearingsim.scenario import unread_note
    from bearingsim.simulation import run as _run

    result = _run(scenario, progress=progress, sink=sink, dt=dt, check_step=check_step)
    note = unread_note(result.scenario, ["numerics.dt_s"]) if dt is not None else None
    if note:
        warnings.warn(f"bearingsim: note: {note}", UnreadKeyWarning, stacklevel=2)
    for note in result.notes:  # a step check asked for is a measurement in result.notes, not a warning
        if not note.startswith(STEP_CHECK_HEAD):
            warnings.warn(note, PlausibilityWarning, stacklevel=2)
    return result


def load(path: str | os.PathLike[str]) -> Result:
    """Read an archive back into its result (:func:`bearingsim.simulation.load`)."""
    from bearingsim.simulation import load as _load

    return _load(path)


def sensitivity(scenario: Scenario, outdir: str | os.PathLike[str] | None = None, *, keys: list[str] | None = None,
                step: float = 0.10, jobs: int = 1, engine: LocalEngine | DaskEngine | None = None) -> SensitivityResult:
    """Normalised sensitivities of I_dec, I_acc, cage slip and eccentricity to every ranged key
    (:func:`bearingsim.studies.sensitivity.run_sensitivity`, docs/sensitivity.md): ``.table``,
    ``.plot_tornado()``. ``outdir`` keeps the case archives (None: a temporary folder)."""
    from bearingsim.scenario import check_scenario_argument
    from bearingsim.studies.sensitivity import run_sensitivity

    check_scenario_argument(scenario, "sensitivity()")
    return run_sensitivity(scenario, outdir, keys, step, jobs=jobs, engine=engine)


def uncertainty(scenario: Scenario, samples: int, outdir: str | os.PathLike[str] | None = None, *, seed: int = 0,
                keys: list[str] | None = None, jobs: int = 1,
                engine: LocalEngine | DaskEngine | None = None) -> UncertaintyResult:
    """Every ranged key sampled over its range (Sobol' design, N (k + 2) runs): median and 5-95 %
    interval of each headline number and first-order and total Sobol indices with bootstrap intervals
    (:func:`bearingsim.studies.uncertainty.run_uncertainty`): ``.table``, ``.spread``, ``.plot_indices()``."""
    from bearingsim.scenario import check_scenario_argument
    from bearingsim.studies.uncertainty import run_uncertainty

    check_scenario_argument(scenario, "uncertainty()")
    return run_uncertainty(scenario, outdir, samples, seed, keys, jobs=jobs, engine=engine)


def report(path: str | os.PathLike[str], out: str | os.PathLike[str] | None = None, *,
           animation: str | None = "gif") -> Path:
    """Write one self-contained HTML report of a run archive, or of a sweep or study folder, to ``out``
    (None: beside ``path``, named after it) and return its path (:func:`bearingsim.reports.report`,
    docs/report.md)."""
    from bearingsim.reports import report as _report

    return _report(path, out, animation=animation)


def animate(path: str | os.PathLike[str], out: str | os.PathLike[str], **kw: Any) -> Path:
    """Animate the motion stored in a multibody archive into ``out`` (.mp4 or .gif) and return its path
    (:func:`bearingsim.simulation.animate`, docs/animation.md)."""
    from bearingsim.simulation import animate as _animate

    return _animate(path, out, **kw)


def __getattr__(name):
    from bearingsim._lazy import submodule

    return submodule(__name__, name)


def __dir__():
    from bearingsim._lazy import submodule_names

    return sorted(set(globals()) | set(submodule_names(__path__)))


__all__ = ["UserError", "SimulationUnstable", "UnreadKeyWarning", "__version__", "load_scenario", "run", "load",
           "sensitivity", "uncertainty", "report", "animate"]
