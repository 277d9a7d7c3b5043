"""HDF5 archives: H5MD-like layout, a ``unit`` on every physical dataset, written atomically.

Layout (format documented in ``docs/archive.md``)::

    /h5md                      attrs version; /h5md/creator attrs name, version
    /bearingsim                attrs format_version, model, scenario_name, complete
    /scenario                  resolved scenario as TOML text (dataset)
    /provenance                attrs: package versions, git commit, created_utc, wall_time_s, ...
    /parameters/*              derived SI quantities (scalars with units)
    /results/per_rotation/*    [rotations, pockets] arrays
    /results/impacts/*         impact table, one column dataset each
    /results/summary           attrs
    /observables/<name>/{step,time,value}   time series

A run writes ``.<name>.tmp-<pid>`` beside the target and renames it when complete; on any error the
temporary file is removed, so a file at the target name is always a complete archive.
"""
from __future__ import annotations

import datetime as _dt
import os
import platform
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from bearingsim import __version__
from bearingsim.errors import UserError
from bearingsim import outputs  # reliability hook

FORMAT_VERSION = "1.0"
_CHUNK_BYTES = 256 * 1024


def _lazy_h5py():
    import h5py

    return h5py


def package_versions() -> dict[str, str]:
    out = {"python": sys.version.split()[0]}
    for mod in ("numpy", "scipy", "pymunk", "h5py", "numba", "matplotlib", "pydantic"):
        try:
            out[mod] = __import__(mod).__version__
        except Exception:  # pragma: no cover - optional package missing
            out[mod] = "not installed"
    return out


def git_commit() -> str:
    """Commit of the bearingsim source tree if it is a git checkout, else 'unknown'."""
    here = Path(__file__).resolve().parent
    try:
        res = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=5
        )
        if res.returncode == 0:
            dirty = subprocess.run(
                ["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no"],
                capture_output=True,
                text=True,
                timeout=5,
            )
            return res.stdout.strip() + ("-dirty" if dirty.stdout.strip() else "")
    except (OSError, subprocess.SubprocessError):
        pass
    return "unknown"


def check_writable_dir(folder: str | Path) -> Path:
    """Create ``folder`` if needed and make sure files can be written in it, else a one-line UserError."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / f".bearingsim-probe-{os.getpid()}"
        probe.touch()
        probe.unlink()
    except OSError as exc:
        raise UserError(f"{folder}: output folder is not writable ({exc.strerror or exc})") from None
    return folder


class TimeSeries:
    """An H5MD ``{step, time, value}`` group appended in buffered blocks (streamed, not held)."""

    def __init__(self, group, value_shape: tuple[int, ...], unit: str, block: int = 4096):
        self._group = group
        self._shape = tuple(value_shape)
        self._block = block
        self._buf_step: list = []
        self._buf_time: list = []
        self._buf_value: list = []
        self._buffered = 0  # rows waiting in the buffers
        row_bytes = 8 * int(np.prod(self._shape, dtype=np.int64) or 1)
        chunk_rows = max(16, min(65536, _CHUNK_BYTES // row_bytes))
        kw = dict(compression="gzip", compression_opts=4, shuffle=True)
        self._step = group.create_dataset("step", (0,), maxshape=(None,), dtype="i8", chunks=(chunk_rows,), **kw)
        self._time = group.create_dataset("time", (0,), maxshape=(None,), dtype="f8", chunks=(chunk_rows,), **kw)
        self._time.attrs["unit"] = "s"
        self._value = group.create_dataset(
            "value", (0, *self._shape), maxshape=(None, *self._shape), dtype="f8",
            chunks=(chunk_rows, *self._shape), **kw,
        )
        self._value.attrs["unit"] = unit

    def append(self, step, time_s, value) -> None:
        """Append one sample (scalars) or a block (1-D step/time, value[n, *shape])."""
        step = np.atleast_1d(np.asarray(step, dtype=np.int64))
        self._buf_step.append(step)
        self._buf_time.append(np.atleast_1d(np.asarray(time_s, dtype=np.float64)))
        self._buf_value.append(np.asarray(value, dtype=np.float64).reshape((len(step), *self._shape)))
        self._buffered += len(step)
        if self._buffered >= self._block:
            self.flush()

    def flush(self) -> None:
        if not self._buf_step:
            return
        s = np.concatenate(self._buf_step)
        t = np.concatenate(self._buf_time)
        v = np.concatenate(self._buf_value)
        n0 = self._step.shape[0]
        for ds, arr in ((self._step, s), (self._time, t), (self._value, v)):
            ds.resize(n0 + len(s), axis=0)
            ds[n0:] = arr
        self._buf_step, self._buf_time, self._buf_value = [], [], []
        self._buffered = 0


class ArchiveWriter:
    """Context manager that writes one run's archive atomically.

    Parameters
    ----------
    path : target file name (``.h5``). Its folder is created if missing.
    scenario : resolved :class:`bearingsim.scenario.Scenario`.
    provenance : extra provenance attributes (dt, dt choice, seed, solver, ...).
    """

    def __init__(self, path: str | Path, scenario, provenance: dict[str, Any] | None = None):
        self.path = Path(path)
        self.scenario = scenario
        self.provenance = dict(provenance or {})
        self._series: list[TimeSeries] = []
        self._t0 = time.perf_counter()
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise UserError(f"{self.path}: cannot create output folder ({exc.strerror})") from None
        if self.path.is_dir():
            raise UserError(f"{self.path}: output path is a directory")
        outputs.check_target(self.path, [getattr(scenario, "source", None)])  # reliability hook
        self.tmp = self.path.with_name(f".{self.path.name}.tmp-{os.getpid()}")
        try:
            self.tmp.touch()
        except OSError as exc:
            raise UserError(f"{self.path}: output is not writable ({exc.strerror})") from None
        self.tmp.unlink()

    def __enter__(self) -> "ArchiveWriter":
        h5py = _lazy_h5py()
        try:  # reliability hook: a full disk or I/O error at creation is one line naming the path
            self.f = h5py.File(self.tmp, "w")
        except OSError as exc:  # reliability hook
            self.tmp.unlink(missing_ok=True)  # reliability hook
            raise outputs.write_error(self.path, exc) from None  # reliability hook
        f = self.f
        f.attrs["title"] = f"bearingsim archive: {self.scenario.name}"
        h5md = f.create_group("h5md")
        h5md.attrs["version"] = np.array([1, 1])
        creator = h5md.create_group("creator")
        creator.attrs["name"] = "bearingsim"
        creator.attrs["version"] = __version__
        g = f.create_group("bearingsim")
        g.attrs["format_version"] = FORMAT_VERSION
        g.attrs["model"] = self.scenario.model
        g.attrs["scenario_name"] = self.scenario.name
        g.attrs["complete"] = False
        ds = f.create_dataset("scenario", data=self.scenario.to_toml())
        ds.attrs["format"] = "TOML (resolved: defaults, preset and overrides applied)"
        ds.attrs["source"] = str(self.scenario.source)
        return self

    # --- writing helpers -------------------------------------------------------------------
    def write_array(self, name: str, data, unit: str, description: str = "", compress: bool = False):
        arr = np.asarray(data)
        kw = {}
        if compress and arr.size > 4096:
            kw = dict(compression="gzip", compression_opts=4, shuffle=True, chunks=True)
        ds = self.f.create_dataset(name, data=arr, **kw)
        ds.attrs["unit"] = unit
        if description:
            ds.attrs["description"] = description
        return ds

    def write_table(self, name: str, columns: dict[str, Any], units: dict[str, str], description: str = ""):
        g = self.f.create_group(name)
        if description:
            g.attrs["description"] = description
        g.attrs["columns"] = list(columns)
        for col, values in columns.items():
            arr = np.asarray(values)
            if arr.dtype.kind == "U":
                arr = arr.astype("S")
            ds = g.create_dataset(col, data=arr)
            ds.attrs["unit"] = units.get(col, "1")
        return g

    def set_attrs(self, group: str, attrs: dict[str, Any], units: dict[str, str] | None = None):
        g = self.f.require_group(group)
        for k, v in attrs.items():
            g.attrs[k] = v
        for k, u in (units or {}).items():
            g.attrs[f"{k}__unit"] = u
        return g

    def timeseries(self, name: str, value_shape=(), unit: str = "1", description: str = "") -> TimeSeries:
        g = self.f.create_group(f"observables/{name}")
        if description:
            g.attrs["description"] = description
        ts = TimeSeries(g, value_shape, unit)
        self._series.append(ts)
        return ts

    def discard_timeseries(self) -> None:
        """Delete every time series written so far (a run restarted with a new time step)."""
        for ts in self._series:
            name = ts._group.name
            del self.f[name]
        self._series.clear()

    # --- completion ---------------------------------------------------------------------------
    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is not None:
            try:
                outputs.close_quietly(self.f)  # reliability hook (was self.f.close())
            except OSError:  # reliability hook: on a full disk the close fails too; the write error is reported
                pass  # reliability hook
            finally:
                self.tmp.unlink(missing_ok=True)
            if issubclass(exc_type, OSError):  # reliability hook
                raise outputs.write_error(self.path, exc) from None  # reliability hook
            return False
        try:
            for ts in self._series:
                ts.flush()
            prov = self.f.create_group("provenance")
            prov.attrs["bearingsim_version"] = __version__
            prov.attrs["git_commit"] = git_commit()
            prov.attrs["created_utc"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
            prov.attrs["wall_time_s"] = time.perf_counter() - self._t0
            prov.attrs["platform"] = platform.platform()
            prov.attrs["command"] = " ".join(sys.argv)
            for k, v in package_versions().items():
                prov.attrs[f"version_{k}"] = v
            for k, v in self.provenance.items():
                prov.attrs[k] = v
            self.f["bearingsim"].attrs["complete"] = True
            outputs.close_quietly(self.f)  # reliability hook (was self.f.close())
            os.replace(self.tmp, self.path)
        except OSError as exc:  # reliability hook: ENOSPC/EIO on flush or close
            self.tmp.unlink(missing_ok=True)  # reliability hook
            raise outputs.write_error(self.path, exc) from None  # reliability hook
        except BaseException:
            self.tmp.unlink(missing_ok=True)
            raise
        return False


def open_archive(path: str | Path):
    """Open a complete bearingsim archive read-only, or raise a one-line :class:`UserError`."""
    h5py = _lazy_h5py()
    p = Path(path)
    if not p.exists():
        raise UserError(f"{p}: file not found")
    if p.is_dir():
        raise UserError(f"{p}: is a directory, not an archive")
    try:
        ok = h5py.is_hdf5(p)
    except OSError:
        ok = False
    if not ok:
        raise UserError(f"{p}: not an HDF5 file (truncated, or not a bearingsim archive)")
    try:
        f = h5py.File(p, "r")
    except OSError as exc:
        raise UserError(f"{p}: cannot open HDF5 file ({exc})") from None
    try:
        g = f.get("bearingsim")
        if g is None or "format_version" not in g.attrs:
            raise UserError(f"{p}: HDF5 file but not a bearingsim archive (no /bearingsim group)")
        if not bool(g.attrs.get("complete", False)):
            raise UserError(f"{p}: incomplete bearingsim archive (the run did not finish)")
        major = str(g.attrs["format_version"]).split(".")[0]
        if major != FORMAT_VERSION.split(".")[0]:
            raise UserError(f"{p}: archive format {g.attrs['format_version']} not readable by this bearingsim")
    except UserError:
        f.close()
        raise
    except Exception as exc:  # damaged metadata
        f.close()
        raise UserError(f"{p}: damaged archive ({exc.__class__.__name__}: {exc})") from None
    return f


def describe(path: str | Path) -> str:
    """Human-readable listing of an archive: header, provenance, summary, then every dataset."""
    f = open_archive(path)
    lines: list[str] = []
    try:
        g = f["bearingsim"]
        lines.append(f"{path}: bearingsim archive, format {g.attrs['format_version']}, model {g.attrs['model']}, "
                     f"scenario {g.attrs['scenario_name']!s}")
        if "provenance" in f:
            pv = f["provenance"].attrs
            keys = ["bearingsim_version", "git_commit", "created_utc", "wall_time_s"]
            lines.append("provenance: " + ", ".join(f"{k}={pv[k]}" for k in keys if k in pv))
            extra = [k for k in pv if k not in keys and not k.startswith("version_") and k not in ("platform", "command")]
            if extra:
                lines.append("run: " + ", ".join(f"{k}={pv[k]}" for k in extra))
        if "results/summary" in f:
            lines.append("summary:")
            sa = f["results/summary"].attrs
            for k in sorted(sa):
                if k.endswith("__unit"):
                    continue
                unit = sa.get(f"{k}__unit", "")
                v = sa[k]
                vs = f"{v:.6g}" if isinstance(v, (float, np.floating)) else str(v)
                lines.append(f"  {k:32s} {vs} {unit}")
        lines.append("datasets:")

        def visit(name, obj):
            if hasattr(obj, "shape") and name != "scenario":
                unit = obj.attrs.get("unit", "")
                lines.append(f"  /{name:52s} {str(obj.shape):14s} {obj.dtype!s:8s} {unit}")

        f.visititems(visit)
    except (KeyError, TypeError, ValueError) as exc:  # reliability hook: attributes missing or malformed
        raise UserError(f"{path}: damaged archive (missing or malformed attribute {exc})") from None  # reliability hook
    finally:
        f.close()
    return outputs.printable("\n".join(lines))  # reliability hook: escape control characters
