"""Orchestration: pick the model a scenario names, run it into an archive, write its figures.

The models themselves live in :mod:`bearingsim.reduced` and :mod:`bearingsim.multibody`; both offer
``simulate(scenario, archive=None, progress=False)`` returning a result with ``write(aw)``,
``summary`` and ``save_figures(stem)``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from bearingsim.archive import ArchiveWriter
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
    return Path(root) / f"{scenario.name}.h5"


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
    with ArchiveWriter(out, scenario) as aw:
        result = module.simulate(scenario, archive=aw, progress=progress)
        result.write(aw)
    pngs = result.save_figures(out.with_suffix("")) if figures else []
    return RunOutput(archive=out, figures=list(pngs), result=result)
