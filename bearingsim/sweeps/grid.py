"""A product sweep's cases as one labelled dataset: ``map.h5``, one array per quantity over the axes.

For a sweep whose axes form a product grid (``mode = "product"``), ``DIR/map.h5`` holds, beside the
index, every number of the grid's cases as arrays shaped over the axes in axis order:

* one coordinate per axis (``/<key>``, the swept values: float64, or text for a text key such as
  ``bearing.cage_guidance``), an HDF5 dimension scale named after the key, with ``units`` (from the
  key's suffix, :func:`bearingsim.sweeps.index.unit_of`) and ``long_name``;
* one variable per summary number of the index (``I_dec_mean_Ns``, ``I_dec_sem_Ns``, ...), ``wall_s``
  and ``model_version`` (float64, NaN where a case failed, is pending or has no value), and ``status``
  and ``case`` (the content hash, as in the index) as text, each with its dimensions attached to the
  axes' scales;
* root attributes: ``format``, ``dims`` (the axes, JSON), ``bearingsim_version``, ``scenario`` (the
  base scenario with the sweep's overrides, resolved, as TOML), ``base_scenario`` (its file) and
  ``sweep`` (the sweep file or ``--param``).

xarray reads it without bearingsim (``xr.open_dataset("DIR/map.h5", engine="h5netcdf")``), and so
does any netCDF-4 reader; :func:`read_map` reads it with h5py alone. Extra ``[[cases]]`` and zipped
axes are not a grid: they are in the index only. The map holds the same numbers as the index
(float64 in both) and is written, atomically, whenever the index is written for the last time
(at the end of the sweep, interrupted or not).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bearingsim import archive
from bearingsim.sweeps.index import name_of, unit_of
from bearingsim.wording import counted

MAP_FORMAT = "bearingsim sweep map 1"
MAP_NAME = "map.h5"
#: index columns that are not variables of the map: the axes are its coordinates, the rest is text
#: about single cases (``error``, ``archive``) that the index keeps
NOT_MAPPED = ("error", "archive", "notes")
LONG_NAMES = {"status": "status of the case (done, cached, stale, failed, pending)",
              "case": "content hash of the case's resolved scenario",
              "model_version": "version of the model that computed the case",
              "wall_s": "wall time of the case"}


@dataclass
class SweepMap:
    """A sweep's ``map.h5`` read with numpy arrays (:func:`read_map`).

    Attributes
    ----------
    dims : list of str
        The axes (swept keys), in the order of the arrays' dimensions.
    coords : dict of str to ndarray
        The swept values of each axis (float64, or ``str`` objects for a text key).
    data : dict of str to ndarray
        Each quantity, shaped ``[len(coords[d]) for d in dims]`` (float64 with NaN, or text).
    units, long_names : dict of str to str
        Of every coordinate and variable that has one.
    attrs : dict
        The file's root attributes (``scenario``, ``bearingsim_version``, ...).
    """

    dims: list[str]
    coords: dict[str, np.ndarray]
    data: dict[str, np.ndarray]
    units: dict[str, str] = field(default_factory=dict)
    long_names: dict[str, str] = field(default_factory=dict)
    attrs: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.data[name] if name in self.data else self.coords[name]

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(self.coords[d]) for d in self.dims)

    def to_xarray(self):
        """The map as an ``xarray.Dataset`` (dims and coordinates named after the axes, ``units`` and
        ``long_name`` attributes); needs the extra ``bearingsim[frames]``."""
        from bearingsim.frames import map_xarray

        return map_xarray(self)


def grid_axes(spec) -> list[tuple[str, list]] | None:
    """The axes of ``spec`` (a :class:`~bearingsim.sweeps.spec.SweepSpec`) if they form a product
    grid, else None (zipped axes, no axes, or a list of cases)."""
    axes = getattr(spec, "axes", None)
    if not axes or getattr(spec, "mode", None) != "product":
        return None
    return list(axes)


def _coordinate(values: list) -> np.ndarray:
    """Axis values as the index stores them: float64 when every value is a number, else text."""
    from bearingsim.sweeps.index import _is_number

    if all(_is_number(v) for v in values):
        return np.array([float(v) for v in values])
    return np.array([str(v) for v in values], dtype=object)


def write_map(path: Path, axes: list[tuple[str, list]], columns: dict[str, np.ndarray], attrs: dict) -> Path:
    """Write ``map.h5`` at ``path`` from the index ``columns`` (one array per index column, the grid's
    cases first, in product order over ``axes``) atomically; return the path."""
    from bearingsim.wear import SWEEP_RATES

    shape = tuple(len(v) for _, v in axes)
    n = math.prod(shape)
    keys = [k for k, _ in axes]
    coords = []
    for k, values in axes:
        c = _coordinate(values)
        a = {"long_name": name_of(k)}
        if c.dtype.kind == "f":
            a["units"] = unit_of(k)
        coords.append((k, c, a))
    variables = {}
    for name, col in columns.items():
        if name in keys or name in NOT_MAPPED:
            continue
        arr = np.asarray(col)[:n].reshape(shape)
        a = {"long_name": LONG_NAMES.get(name) or SWEEP_RATES.get(name) or name_of(name)}
        if arr.dtype.kind == "f" and name != "model_version":
            a["units"] = unit_of(name)
        variables[name] = (arr, a)
    root = {"format": MAP_FORMAT, "dims": json.dumps(keys), **attrs}
    return archive.write_grid_file(path, coords, variables, root)


def read_map(path) -> SweepMap:
    """Read a sweep's map (``DIR`` or ``DIR/map.h5``) into a :class:`SweepMap` (numpy only).

    Raises
    ------
    UserError
        The file is missing or is not a sweep map (or ``path`` is not a path).
    """
    from bearingsim.errors import check_path

    p = Path(check_path(path, "path", "a sweep's folder or its map.h5"))
    if p.is_dir():
        p = p / MAP_NAME
    data, attrs, root = archive.read_grid_file(p, MAP_FORMAT)
    dims = json.loads(root["dims"])
    coords = {d: data.pop(d) for d in dims}
    units = {k: a["units"] for k, a in attrs.items() if "units" in a}
    long_names = {k: a["long_name"] for k, a in attrs.items() if "long_name" in a}
    return SweepMap(dims, coords, data, units, long_names, root)


def describe_map(path) -> str:
    """What a sweep's ``map.h5`` holds (``bearingsim inspect``): its axes with their values, the cases
    by status, then every variable with its shape and unit."""
    from bearingsim.outputs import printable

    m = read_map(path)

    def values(c):
        if c.dtype.kind == "f" and len(c) > 4:
            return f"{c[0]:g} .. {c[-1]:g}"
        return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in c)

    by: dict[str, int] = {}
    for s in np.asarray(m.data.get("status", [])).ravel():
        by[str(s)] = by.get(str(s), 0) + 1
    lines = [f"{path}: bearingsim sweep map (one array per quantity over the axes; xarray reads it with "
             f"engine=\"h5netcdf\")",
             f"base scenario {m.attrs.get('base_scenario', '?')} (its TOML: 'bearingsim show {path}'); "
             f"bearingsim {m.attrs.get('bearingsim_version', '?')}",
             "cases: " + (", ".join(f"{k} {v}" for k, v in sorted(by.items())) or "(none)"), "axes:"]
    for d in m.dims:
        unit = f" [{m.units[d]}]" if d in m.units else ""
        lines.append(f"  {d}{unit}: {counted(len(m.coords[d]), 'value')}, {values(m.coords[d])}")
    lines.append("variables:")
    for k, v in m.data.items():
        lines.append(f"  {k:32s} {str(v.shape):14s} {'text' if v.dtype.kind == 'O' else str(v.dtype):8s} "
                     f"{m.units.get(k, '')}")
    return printable("\n".join(lines))
