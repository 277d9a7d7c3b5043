"""Studies: many-case runs on one engine.

A study is a list of cases plus a table and figures (:class:`Study`): the cross-check ladder
(:mod:`bearingsim.studies.crosscheck`, ``bearingsim crosscheck``), the paper's rig as a scene
(:mod:`bearingsim.studies.rig`) and the reduced model's Fig. 9 analog (:mod:`bearingsim.studies.fig9`),
both of ``bearingsim validate``. :func:`run_studies` runs their cases on the sweep engine
(:mod:`bearingsim.sweeps`: local processes or a dask cluster, resume from kept archives, failures kept
and reported, SIGINT/SIGTERM/SIGHUP, progress) under one folder lock, then writes each study's table and
figures atomically.
"""
from bearingsim.studies.engine import (StudiesOutcome, Study, batch_sem, case_of, in_folder, load_result,
                                       make_engine, run_studies)

__all__ = ["StudiesOutcome", "Study", "batch_sem", "case_of", "in_folder", "load_result", "make_engine",
           "run_studies"]


def __getattr__(name):  # the study modules (bearingsim.studies.life, ...) on first use (PEP 562)
    from bearingsim._lazy import submodule

    return submodule(__name__, name)


def __dir__():
    from bearingsim._lazy import submodule_names

    return sorted(set(globals()) | set(submodule_names(__path__)))
