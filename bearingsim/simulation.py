"""Orchestration: pick the model a scenario names, run it into an archive, write its figures.

The models themselves live in :mod:`bearingsim.reduced` and :mod:`bearingsim.multibody`; both offer
``simulate(scenario, archive=None, progress=False)`` returning a result with ``write(aw)``,
``summary`` and ``save_figures(stem)``.
"""
from __future__ import annotations

import sys  # reliability hook
from dataclasses import dataclass, field
from pathlib import Path

from bearingsim.archive import ArchiveWriter
from bearingsim import outputs, plausibility  # reliability hook
from bearingsim.errors import UserError  # reliability hook
from bearingsim.scenario import Scenario


def model_module(name: str):
    if name == "reduced":
        from bearingsim import reduced

        return reduced
    from bearingsim import multibody

    return multibody


@dataclass
class RunOutput:
    archive: Path
    figures: list[Path] = field(default_factory=list)
    result: object = None


def default_output(scenario: Scenario, root: str | Path = "outputs") -> Path:
    return outputs.default_output(scenario.name, root)  # reliability hook: never outside root


def run_scenario(
    scenario: Scenario,
    out: str | Path | None = None,
    *,
    figures: bool = True,
    progress: bool = False,
) -> RunOutput:
    """Run ``scenario`` and write its archive (atomically) and, optionally, its PNG figures.

    Parameters
    ----------
    scenario : resolved scenario
    out : archive path; default ``outputs/<name>.h5``
    figures : write PNG figures beside the archive (``<stem>*.png``)
    progress : show a progress bar (multibody runs)
    """
    out = Path(out) if out is not None else default_output(scenario)
    module = model_module(scenario.model)
    outputs.check_target(out, [scenario.source])  # reliability hook: before the lock creates the folder
    lock = outputs.OutputLock(out).acquire()  # reliability hook: one writer per target, figures included
    outputs.clean_stale_temporaries(out.parent)  # reliability hook
    try:  # reliability hook
        with ArchiveWriter(out, scenario) as aw:
            result = module.simulate(scenario, archive=aw, progress=progress)
            for note in plausibility.check(result, scenario, aw.provenance):  # reliability hook: exit 3 before
                print(note, file=sys.stderr)  # anything is written; notes (ring_newton_failures) on stderr
            with outputs.quiet_stderr():  # reliability hook: HDF5 error stacks on a full disk
                result.write(aw)
        try:  # reliability hook
            pngs = result.save_figures(out.with_suffix("")) if figures else []
        except OSError as exc:  # reliability hook
            raise UserError(f"{exc.filename or str(out.with_suffix('')) + '_*.png'}: cannot write figure "
                            f"({exc.strerror or exc}); the archive {out} is complete") from None
    finally:  # reliability hook
        lock.release()  # reliability hook
    return RunOutput(archive=out, figures=list(pngs), result=result)
