"""Results as pandas DataFrames and xarray Datasets (the optional extra ``bearingsim[frames]``).

``Result.to_dataframe(what)`` and ``Result.to_xarray()`` (:mod:`bearingsim.results`) and
:func:`bearingsim.sweeps.index.index_dataframe` build their tables here. Units: every DataFrame carries
``df.attrs["units"]`` (column -> unit, SI, as in the archive); every xarray variable its
``attrs["units"]``; ``units_in_names=True`` also writes them into the column names (``"I_dec [N s]"``).
pandas and xarray are imported only when called: without them bearingsim works, and these calls raise
:class:`MissingExtra` naming the extra to install.
"""
from __future__ import annotations

import numpy as np

#: what :meth:`Result.to_dataframe` builds
FRAMES = ("per_rotation", "impacts", "observables", "summary")
EXTRA_HINT = "pip install 'bearingsim[frames]' (or pip install pandas xarray)"


class MissingExtra(ImportError):
    """pandas or xarray is not installed; the message names the extra that installs it."""


def need(module: str, what: str):
    """Import ``module`` (``"pandas"``/``"xarray"``) for ``what``, or raise :class:`MissingExtra` when it is
    not installed; any other failure of its import (a module of the user's shadowing one it imports, a
    broken install) is raised as it is, so that its message says what failed."""
    import importlib

    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name != module:
            raise
        raise MissingExtra(f"{what} needs {module}, which is not installed: {EXTRA_HINT}") from None


def _named(frame, units: dict[str, str], units_in_names: bool):
    frame.attrs["units"] = dict(units)
    if units_in_names:
        frame = frame.rename(columns={c: f"{c} [{u}]" for c, u in units.items()})
        frame.attrs["units"] = {f"{c} [{u}]": u for c, u in units.items()}
    return frame


def _under(result, prefix: str) -> dict:
    p = prefix + "/"
    return {k[len(p):]: v for k, v in result.data.items() if k.startswith(p) and "/" not in k[len(p):]}


def _observables(result) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, str]]:
    """(time [s], columns, units) of the result's time series sampled at the same instants; a vector
    series gives one column per component (``cage_centre_x``, ``cage_centre_y``). The motion series
    (``motion_*``, poses for animations, sampled per cage travel: docs/archive.md) are not among them:
    read them from ``Result.series``. By name, the order an archive lists them in: a fresh result's frame
    and its archive's have the same columns in the same order."""
    series = {k: s for k, s in sorted(result.series.items()) if not k.startswith("motion_")}
    if not series:
        return np.array([]), {}, {}
    times = {name: s.time for name, s in series.items()}
    first = next(iter(times.values()))
    if any(len(t) != len(first) or not np.array_equal(t, first) for t in times.values()):
        raise ValueError("the result's time series are not sampled at the same times: read them one by one "
                         "from Result.series")
    cols, units = {}, {}
    for name, s in series.items():
        v = np.asarray(s.value)
        if v.ndim == 1:
            cols[name], units[name] = v, s.unit
        else:
            flat = v.reshape(len(v), -1)
            suffixes = "xyz" if flat.shape[1] <= 3 else [str(i) for i in range(flat.shape[1])]
            for j in range(flat.shape[1]):
                cols[f"{name}_{suffixes[j]}"], units[f"{name}_{suffixes[j]}"] = flat[:, j], s.unit
    return np.asarray(first), cols, units


def result_dataframe(result, what: str = "per_rotation", units_in_names: bool = False):
    """The DataFrame of ``what`` (:data:`FRAMES`) of ``result``; see :meth:`Result.to_dataframe`."""
    if not isinstance(what, str) or what not in FRAMES:
        from bearingsim.errors import UserError

        raise UserError(f"to_dataframe({what!r}): give one of {', '.join(FRAMES)}")
    pd = need("pandas", "Result.to_dataframe")
    result.require({"observables": "observables", "summary": "results/summary"}.get(what, f"results/{what}"),
                   f"to_dataframe({what!r})")
    if what == "per_rotation":
        arrays = _under(result, "results/per_rotation")
        first = next(a.data for a in arrays.values() if np.ndim(a.data) == 2)
        rot, pocket = np.indices(first.shape[:2])
        index = pd.MultiIndex.from_arrays([rot.ravel(), pocket.ravel()], names=["rotation", "pocket"])
        # a number per rotation (the cage's: where it rests, a land's impulses) stands in each of its pockets' rows
        frame = pd.DataFrame({k: (np.asarray(a.data).reshape(-1) if np.ndim(a.data) == 2 else
                                  np.repeat(np.asarray(a.data), first.shape[1])) for k, a in arrays.items()},
                             index=index)
        units = {k: a.unit for k, a in arrays.items()}
    elif what == "impacts":
        arrays = _under(result, "results/impacts")
        frame = pd.DataFrame({k: np.asarray(a.data) for k, a in arrays.items()})
        frame.index.name = "impact"
        units = {k: a.unit for k, a in arrays.items()}
    elif what == "observables":
        time, cols, units = _observables(result)
        frame = pd.DataFrame(cols, index=pd.Index(time, name="time_s"))
        frame.attrs["index_unit"] = "s"
    elif what == "summary":
        summary = result.summary
        frame = pd.DataFrame({k: [v] for k, v in summary.items()}, index=pd.Index([result.scenario.name], name="run"))
        units = {k: result.summary_units.get(k, "1") for k in summary}
    return _named(frame, units, units_in_names)


def result_xarray(result):
    """The xarray Dataset of ``result``; see :meth:`Result.to_xarray`."""
    xr = need("xarray", "Result.to_xarray")
    for prefix in ("results/per_rotation", "results/impacts", "observables"):
        result.require(prefix, "to_xarray()")
    data_vars = {}
    for name, a in _under(result, "results/per_rotation").items():
        dims = ("rotation", "pocket") if np.ndim(a.data) == 2 else ("rotation",)  # the cage's, per rotation
        data_vars[name] = (dims, np.asarray(a.data), {"units": a.unit, "description": a.description})
    for name, a in _under(result, "results/impacts").items():
        values = np.asarray(a.data)
        if values.dtype.kind == "U":
            values = values.astype(object)
        data_vars[f"impact_{name}"] = (("impact",), values, {"units": a.unit, "description": a.description})
    time, cols, units = _observables(result)
    for name, v in cols.items():
        data_vars[name] = (("time",), v, {"units": units[name]})
    coords = {"time": ("time", time, {"units": "s"})} if cols else {}
    attrs = {k: v for k, v in result.summary.items()}
    attrs.update({f"units_{k}": u for k, u in result.summary_units.items() if k in attrs})
    attrs.update(scenario_name=result.scenario.name, model=result.scenario.model, scenario_toml=result.scenario.to_toml())
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def map_xarray(sweep_map):
    """A sweep's map (:class:`bearingsim.sweeps.grid.SweepMap`) as an xarray Dataset: one variable per
    quantity over the axes, the axes as dims and coordinates, ``units`` and ``long_name`` attributes."""
    xr = need("xarray", "SweepMap.to_xarray")
    m = sweep_map

    def attrs(name):
        a = {"long_name": m.long_names[name]} if name in m.long_names else {}
        if name in m.units:
            a["units"] = m.units[name]
        return a

    coords = {d: (d, m.coords[d], attrs(d)) for d in m.dims}
    data_vars = {k: (tuple(m.dims), v, attrs(k)) for k, v in m.data.items()}
    return xr.Dataset(data_vars, coords=coords, attrs=dict(m.attrs))


def index_frame(cols: dict, axes, folder: str, unit_of, units_in_names: bool = False):
    """A case index's columns ``cols`` (:func:`bearingsim.sweeps.index.read_index`) as a DataFrame: one row
    per case, index ``case`` (content hash), the swept keys, ``status``, ``error``, ``archive``, ``wall_s``
    and the summary numbers (SI); ``attrs``: ``units`` (from ``unit_of(column)``), ``axes`` (the swept
    keys) and ``folder``."""
    pd = need("pandas", "index_dataframe")
    frame = pd.DataFrame({k: (v.astype(str) if v.dtype == object else v) for k, v in cols.items() if k != "case"},
                         index=pd.Index(cols["case"].astype(str), name="case"))
    units = {k: unit_of(k) for k in frame.columns if k not in ("status", "error", "archive")
             and frame[k].dtype.kind == "f"}
    frame = _named(frame, units, units_in_names)
    frame.attrs.update(axes=list(axes), folder=folder)
    return frame
