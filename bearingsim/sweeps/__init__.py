"""What-if sweeps: many cases of one scenario, resumable, on a local pool or a dask cluster.

``run_sweep(spec, outdir, engine=...)`` runs the cases (:mod:`bearingsim.sweeps.run`), each into
``outdir/cases/<content hash>.h5`` when it keeps an archive (by default the multibody cases), and
indexes them in ``sweep.csv``/``sweep.h5`` (:mod:`bearingsim.sweeps.index`) and, for a product grid,
``map.h5`` (one array per quantity over the axes: :mod:`bearingsim.sweeps.grid`, ``read_map``);
``plot_sweep_index`` draws the sweep's figures from the index.
"""
from bearingsim.sweeps.engines import DaskEngine, LocalEngine
from bearingsim.sweeps.grid import SweepMap, read_map
from bearingsim.sweeps.index import index_dataframe, read_index
from bearingsim.sweeps.plot import plot_sweep_index
from bearingsim.sweeps.run import SweepOutcome, run_sweep
from bearingsim.sweeps.spec import Case, SweepSpec, case_hash, load_sweep_file, resolve_cases, spec_from_args

__all__ = ["Case", "DaskEngine", "LocalEngine", "SweepMap", "SweepOutcome", "SweepSpec", "case_hash", "index_dataframe", "load_sweep_file",
           "plot_sweep_index", "read_index", "read_map", "resolve_cases", "run_sweep", "spec_from_args"]
