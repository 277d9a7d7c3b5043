"""What-if sweeps: many cases of one scenario, resumable, on a local pool or a dask cluster.

``run_sweep(spec, outdir, engine=...)`` runs the cases (:mod:`bearingsim.sweeps.run`), each into
``outdir/cases/<content hash>.h5`` when it keeps an archive (by default the multibody cases), and
indexes them in ``sweep.csv``/``sweep.h5`` (:mod:`bearingsim.sweeps.index`) and, for a product grid,
``map.h5`` (one array per quantity over the axes: :mod:`bearingsim.sweeps.grid`, ``read_map``);
``plot_sweep_index`` draws the sweep's figures from the index.
"""
import importlib

#: where each name of the package lives: imported on first use (PEP 562), so that importing one light
#: submodule (``bearingsim.sweeps.index``, for ``bearingsim keys``) does not load the scenario reader,
#: the runner and their dependencies
_SOURCES = {
    "DaskEngine": "engines", "LocalEngine": "engines",
    "SweepMap": "grid", "read_map": "grid",
    "index_dataframe": "index", "read_index": "index",
    "plot_sweep_index": "plot",
    "SweepOutcome": "run", "run_sweep": "run",
    "Case": "spec", "SweepSpec": "spec", "case_hash": "spec", "load_sweep_file": "spec", "resolve_cases": "spec",
    "spec_from_args": "spec",
}

__all__ = ["Case", "DaskEngine", "LocalEngine", "SweepMap", "SweepOutcome", "SweepSpec", "case_hash", "index_dataframe", "load_sweep_file",
           "plot_sweep_index", "read_index", "read_map", "resolve_cases", "run_sweep", "spec_from_args"]


def __getattr__(name):
    if name in _SOURCES:
        value = getattr(importlib.import_module(f"{__name__}.{_SOURCES[name]}"), name)
        globals()[name] = value
        return value
    from bearingsim._lazy import submodule

    return submodule(__name__, name)  # its submodules (bearingsim.sweeps.worker, ...), or AttributeError


def __dir__():
    from bearingsim._lazy import submodule_names

    return sorted(set(globals()) | set(__all__) | set(submodule_names(__path__)))
