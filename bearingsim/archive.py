"""HDF5 archives: the only module that uses h5py. H5MD-like layout, a ``unit`` on every physical
dataset, written atomically; :func:`write` stores any :class:`bearingsim.results.Result`, :func:`read`
gives it back as the same class.

Layout (format documented in ``docs/archive.md``)::

    /h5md                      attrs version; /h5md/creator attrs name, version; /h5md/author attr name
                               ($BEARINGSIM_AUTHOR, else "unknown": never the host's login name)
    /bearingsim                attrs format_version, model, scenario_name, complete
    /bearingsim/notes          the run's notes, one text per note (dataset)
    /scenario                  resolved scenario as TOML text (dataset)
    /provenance                attrs_json: the result's (package versions, git commit, wall_time_s, ...),
                               and created_utc, the time the archive was written
    /results/per_rotation/*    [rotations, pockets] arrays
    /results/impacts/*         impact table, one column dataset each
    /results/summary           attrs_json, units_json (one JSON object each)
    /observables/<name>/{step,time,value}   time series

Named scalar values (an attribute group, the provenance) are stored as one JSON attribute per group
since format 2.0 (an HDF5 attribute costs ~50 us to write, a reduced-model archive had ~100 of them);
format 1.x archives, one HDF5 attribute per value and ``<name>__unit`` beside it, are read as well
(:func:`group_attrs` reads either).

A run writes ``.<name>.tmp-<pid>`` beside the target and renames it when complete; on any error the
temporary file is removed, so a file at the target name is always a complete archive. A long run
streams its time series into that temporary file through a :class:`Spool` (the sink the model is
given), so they are never held in memory; :func:`write` then completes the same file.
"""
from __future__ import annotations

import contextlib
import contextvars
import datetime as _dt
import functools
import json
import os
import platform
import shlex
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

from bearingsim._version import __version__
from bearingsim.datatypes import AttrGroup, NamedArray, Series
from bearingsim import outputs
from bearingsim.errors import UserError, check_path
from bearingsim.wording import counted, run_notes

FORMAT_VERSION = "2.0"
READABLE_MAJORS = ("1", "2")  # 1.x: one HDF5 attribute per value; 2.x: attrs_json / units_json
ATTRS_JSON = "attrs_json"
UNITS_JSON = "units_json"
_CHUNK_BYTES = 256 * 1024


def _lazy_h5py():
    import h5py

    return h5py


@functools.lru_cache(maxsize=1)
def _package_versions() -> tuple:
    """(name, version) pairs, read once per process: the packages cannot change under a running
    process, and reading package metadata costs ~5 ms a package."""
    return tuple(_read_package_versions().items())


def package_versions() -> dict[str, str]:
    """Versions of python and the packages bearingsim's numbers depend on."""
    return dict(_package_versions())


def _read_package_versions() -> dict[str, str]:
    out = {"python": sys.version.split()[0]}
    from importlib import metadata

    for mod in ("numpy", "scipy", "pymunk", "h5py", "numba", "matplotlib", "pydantic"):
        try:
            out[mod] = metadata.version(mod)
        except metadata.PackageNotFoundError:  # pragma: no cover - optional package missing
            out[mod] = "not installed"
    return out


@functools.lru_cache(maxsize=1)
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
    """Create ``folder`` if needed and make sure files can be written in it, else a one-line UserError
    (a file where the folder, or one of its parents, should be: :func:`bearingsim.outputs.check_folder_path`,
    nothing created)."""
    folder = outputs.check_folder_path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"{folder}: cannot create the output folder ({exc.strerror or exc})") from None
    try:
        probe = folder / f".bearingsim-probe-{os.getpid()}"
        probe.touch()
        probe.unlink()
    except OSError as exc:
        raise UserError(f"{folder}: {outputs.no_file_in('this output folder', exc)}") from None
    return folder


class TimeSeries:
    """An H5MD ``{step, time, value}`` group appended in buffered blocks (streamed, not held)."""

    def __init__(self, group, value_shape: tuple[int, ...], unit: str, block: int = 4096, check=None):
        self._group = group
        self._check = check  # called after each block is written (Spool.check: a failed write stops the run)
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
        self._step.attrs["unit"] = "1"  # a count (docs/archive.md: every dataset has a unit)
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
        if self._check is not None:
            self._check()


def _prepare_target(path) -> Path:
    """Check that an archive can be written at ``path`` (one-line UserError if not); return it. Its folder
    is made here; the folders made are removed again when the check refuses the path."""
    path = Path(path)
    outputs.check_target(path, (), is_archive, figures=False,  # .h5 name; never replaces a non-archive
                         own_file_error=own_file_target_error)
    made = outputs.missing_folders(path.parent)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = outputs.temporary_name(path)
        try:
            tmp.touch()
        except OSError as exc:
            raise outputs.cannot_write_archive(path, exc) from None
    except OSError as exc:
        outputs.remove_empty(made)
        raise outputs.cannot_create_folder(path, exc) from None
    except UserError:
        outputs.remove_empty(made)
        raise
    tmp.unlink()
    return path


class _SpoolFile:
    """The spool's temporary file as HDF5 writes it (h5py's ``fileobj`` driver): ``os.pwrite`` and
    ``os.pread`` of this process, and never a failure seen by HDF5.

    HDF5 keeps a write that failed (a full disk: ENOSPC, or EFBIG past ``RLIMIT_FSIZE``; EIO) in its
    caches and tries it again at every flush: its file then cannot be closed (h5py raised ``RuntimeError``
    from ``close``, printed error stacks while freeing each object left open, and the interpreter crashed
    at exit, in a sweep's worker too). Here the first failure is kept (``error``) and the bytes of that
    write and of every later one are held in memory, where reads find them, so that HDF5 goes on and
    closes its file; :meth:`Spool.check` stops the run at its next block. A signal's exception raised
    inside a call (SIGINT while HDF5 writes) is kept as well (``interrupt``) and raised there.

    Parameters
    ----------
    fd : descriptor of the new temporary file, open for reading and writing
    """

    def __init__(self, fd: int):
        self.fd, self.pos, self.size = fd, 0, 0
        self.error: OSError | None = None
        self.interrupt: BaseException | None = None
        self._held: list[tuple[int, bytes]] = []  # (offset, bytes) not on disk, in the order written

    def seek(self, pos: int, whence: int = os.SEEK_SET) -> int:
        self.pos = {os.SEEK_SET: 0, os.SEEK_CUR: self.pos, os.SEEK_END: self.size}[whence] + pos
        return self.pos

    def tell(self) -> int:
        return self.pos

    def write(self, data) -> int:
        view, at, done = memoryview(data).cast("B"), self.pos, 0
        while done < len(view) and self.error is None:
            try:
                done += os.pwrite(self.fd, view[done:], at + done)
            except OSError as exc:
                self.error = exc
            except BaseException as exc:  # noqa: BLE001 - a signal's exception: raised by Spool.check
                self.interrupt = self.interrupt or exc
        if done < len(view):
            self._held.append((at + done, bytes(view[done:])))
        self.pos = at + len(view)
        self.size = max(self.size, self.pos)
        return len(view)

    def read(self, size: int = -1) -> bytes:
        at = self.pos
        size = max(0, self.size - at) if size < 0 else size
        data = None
        while data is None:
            try:
                data = bytearray(os.pread(self.fd, size, at))
            except OSError as exc:
                self.error, data = self.error or exc, bytearray()
            except BaseException as exc:  # noqa: BLE001 - a signal's exception: raised by Spool.check
                self.interrupt = self.interrupt or exc
        data.extend(bytes(size - len(data)))  # past the end: zeros, as HDF5's own driver reads
        for start, held in self._held:
            lo, hi = max(start, at), min(start + len(held), at + size)
            if lo < hi:
                data[lo - at:hi - at] = held[lo - start:hi - start]
        self.pos = at + size
        return bytes(data)

    def truncate(self, size: int) -> int:
        if self.error is None:
            try:
                os.ftruncate(self.fd, size)
            except OSError as exc:
                self.error = exc
        self.size = size
        return size

    def flush(self) -> None:
        """Nothing buffered here: every write is the system's at once."""


class Spool:
    """The sink a model streams its time series into: the temporary file of the archive to be.

    Use as a context manager around the run and :func:`write`: on any error the temporary file is
    removed. ``timeseries(name, value_shape, unit, description)`` returns an appender
    (:class:`TimeSeries`); ``discard_timeseries()`` drops what was streamed (a restarted run). HDF5
    writes the file through :class:`_SpoolFile`: a full disk stops the run at the next block written
    (:meth:`check`) with one :class:`bearingsim.outputs.ArchiveWriteError` naming the archive, and the
    file closes cleanly.
    """

    def __init__(self, path):
        self.path = _prepare_target(path)
        self.tmp = outputs.temporary_name(self.path)
        self._series: list[TimeSeries] = []
        self.f = None
        self._file: _SpoolFile | None = None

    def __enter__(self) -> "Spool":
        try:  # a full disk or I/O error at creation: one line naming the path
            self._file = _SpoolFile(outputs.create_new(self.tmp, readable=True))
            self.f = _lazy_h5py().File(self._file, "w")
            self.check()
        except OSError as exc:
            self._close()
            outputs.discard_temporary(self.tmp)
            raise outputs.write_error(self.path, exc) from None
        except BaseException:
            self._close()
            outputs.discard_temporary(self.tmp)
            raise
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        self._close()
        outputs.discard_temporary(self.tmp)  # written and renamed by write(), else abandoned
        if exc_type is not None and issubclass(exc_type, OSError) and not isinstance(exc, UserError):
            raise outputs.write_error(self.path, exc) from None
        return False

    def check(self) -> None:
        """Raise what a write into the file met: a signal's exception, or the first failed write as one
        :class:`bearingsim.outputs.ArchiveWriteError` naming the archive."""
        sf = self._file
        if sf is not None and sf.interrupt is not None:
            exc, sf.interrupt = sf.interrupt, None
            raise exc
        if sf is not None and sf.error is not None:
            raise outputs.write_error(self.path, sf.error)

    def _close(self) -> None:
        """Close the HDF5 file (HDF5 has seen no failed write: it closes) and the temporary file's descriptor."""
        if self.f is not None:
            f, self.f = self.f, None
            try:
                outputs.close_quietly(f)
            except Exception:  # noqa: BLE001 - an error already on its way is the one reported
                pass
        if self._file is not None and self._file.fd >= 0:
            fd, self._file.fd = self._file.fd, -1
            os.close(fd)

    def timeseries(self, name: str, value_shape=(), unit: str = "1", description: str = "") -> TimeSeries:
        g = self.f.create_group(f"observables/{name}")
        if description:
            g.attrs["description"] = description
        ts = TimeSeries(g, value_shape, unit, check=self.check)
        self._series.append(ts)
        return ts

    def discard_timeseries(self) -> None:
        for ts in self._series:
            del self.f[ts._group.name]
        self._series.clear()

    def collect(self) -> dict:
        """The streamed series stay in the file: nothing to hand to the result."""
        for ts in self._series:
            ts.flush()
        return {}


def write(result, path, spool: Spool | None = None) -> Path:
    """Write ``result`` as a complete archive at ``path`` (atomically); return the path.

    With ``spool`` (the sink the run streamed into), its temporary file is completed and renamed;
    otherwise the archive is built in memory (:func:`to_bytes`, time series included from
    ``result.series``) and written with plain file writes through :func:`bearingsim.outputs.atomic_file`:
    a full disk or an I/O error is then an ``OSError`` of this process, raised as one
    :class:`bearingsim.outputs.ArchiveWriteError` naming ``path``, with no temporary file left and no
    HDF5 file left open in an error state (h5py would print error stacks while freeing it, and the
    interpreter could crash at exit).
    """
    if spool is None:
        made = outputs.missing_folders(Path(check_path(path, "path", "the archive (.h5)")).parent)
        path = _prepare_target(path)
        try:
            try:
                outputs.write_atomic_bytes(path, to_bytes(result))
            except OSError as exc:  # ENOSPC/EFBIG/EIO: atomic_file has removed its temporary file
                raise outputs.write_error(path, exc) from None
        except BaseException:  # no archive: no folder made for it left behind either
            outputs.remove_empty(made)
            raise
        return path
    renaming = False
    try:
        for ts in spool._series:
            ts.flush()
        _fill(spool.f, result)
        spool._close()  # HDF5 has seen no failed write (_SpoolFile): the file closes
        spool.check()  # a write that failed (ENOSPC/EFBIG/EIO): one line, nothing left behind
        renaming = True
        os.replace(spool.tmp, spool.path)
        outputs.note_written(spool.path)
    except OSError as exc:  # the rename
        outputs.discard_temporary(spool.tmp)
        raise outputs.write_error(spool.path, exc) from None
    except BaseException:
        spool._close()
        if renaming and not os.path.lexists(spool.tmp):  # renamed, then a signal's exception: complete
            outputs.note_written(spool.path)
        outputs.discard_temporary(spool.tmp)
        raise
    return spool.path


def _fill(f, result, in_memory: bool = False) -> None:
    """Write everything of ``result`` into the open file ``f`` (its streamed series are there already)
    and mark it complete (a file built in memory, never seen incomplete, is marked once at the end)."""
    w = _Writer(f, fresh=in_memory)
    _write_header(w, result, complete=in_memory)
    for name, s in result.series.items():
        g = w.group(f"observables/{name}")
        if s.description:
            w.attr(g.id, "description", s.description)
        ts = TimeSeries(g, s.value.shape[1:], s.unit)
        ts.append(s.step, s.time, s.value)
        ts.flush()
    for path_, arr in result.data.items():
        _write_array(w, path_, arr)
    for path_, desc in result.tables.items():
        g = w.gid(path_)
        w.attr(g, "columns", [k[len(path_) + 1:] for k in result.data if k.startswith(path_ + "/")])
        if desc:
            w.attr(g, "description", desc)
    for path_, grp in result.groups.items():
        g = w.gid(path_)
        if grp.description:
            w.attr(g, "description", grp.description)
        _write_group_attrs(w, g, grp.attrs, grp.units)
    prov = _provenance(result)
    _write_group_attrs(w, w.gid("provenance"), prov, _provenance_units(prov))
    _write_notes(w, result.notes)
    if not in_memory:
        w.attr(w.gid("bearingsim"), "complete", True, replace=True)


_image_count = 0


@functools.lru_cache(maxsize=1)
def _image_plists() -> tuple:
    """(file access, file creation) property lists of an in-memory file, built once per process: the
    ones h5py builds for ``File(name, "w", driver="core", backing_store=False)`` (same file), which it
    would build again for every file (~40 us of a sweep case's archive). Built with h5py's public
    low-level API as its private ``h5py._hl.files.make_fapl`` and ``make_fcpl`` do, with their defaults
    (library version bounds earliest to latest, alignment 1, core driver without backing store; object
    times not tracked): ``make_fapl``'s arguments have defaults only since h5py 3.13."""
    h5py = _lazy_h5py()
    fapl = h5py.h5p.create(h5py.h5p.FILE_ACCESS)
    fapl.set_libver_bounds(h5py.h5f.LIBVER_EARLIEST, h5py.h5f.LIBVER_LATEST)
    fapl.set_alignment(1, 1)
    fapl.set_fapl_core(backing_store=False)
    fcpl = h5py.h5p.create(h5py.h5p.FILE_CREATE)
    fcpl.set_obj_track_times(False)
    return fapl, fcpl


def to_bytes(result) -> bytes:
    """``result`` as the bytes of a complete archive, built in memory (HDF5 core driver, no file):
    the same content :func:`write` stores, for a caller that writes the file itself (a sweep's
    worker: one write of the whole file, or bytes sent back to the sweep's client)."""
    return _image(lambda f: _fill(f, result, in_memory=True))


def _image(fill) -> bytes:
    """The bytes of an HDF5 file built in memory (core driver, no backing store) by ``fill(f)``: written
    then with plain writes (:func:`bearingsim.outputs.write_atomic_bytes`), so that a full disk is an
    ``OSError`` naming the file, never HDF5's failed write."""
    global _image_count
    h5py = _lazy_h5py()
    _image_count += 1
    name = f"bearingsim-image-{os.getpid()}-{_image_count}.h5".encode()  # never on disk: no backing store
    fapl, fcpl = _image_plists()
    f = h5py.File(h5py.h5f.create(name, h5py.h5f.ACC_TRUNC, fapl=fapl, fcpl=fcpl))
    try:
        fill(f)
        f.flush()
        return f.id.get_file_image()
    finally:
        f.close()


class _Writer:
    """Writes groups, datasets and attributes through h5py's low-level API with the HDF5 types and
    creation properties its high-level API uses (so files read back the same), at a fraction of the
    cost per object: no existence checks, no high-level wrappers, no property lists, types or
    dataspaces built again for every object. Compressed arrays go through h5py's high-level API.

    Parameters
    ----------
    f : h5py.File
        The open file.
    fresh : bool
        The file is new and nothing else writes into it (an in-memory archive): no group can exist
        before this writer creates it, so none is looked up.
    """

    _types: dict = {}  # dtype key -> (file type, memory type), shared by every writer of the process
    _plists: tuple | None = None  # (scalar dataspace, dataset and link creation lists), built once

    def __init__(self, f, fresh: bool = False):
        h5py = _lazy_h5py()
        self.f = f
        self._h5 = h5py
        self._gids = {"": f.id}  # group path -> GroupID (the file's id stands for the root group)
        self._made: set[str] = {""} if fresh else set()  # groups with nothing in them but this writer's
        self._spaces: dict[tuple, Any] = {}  # shape -> simple dataspace (HDF5 copies it into each dataset)
        if _Writer._plists is None:  # never modified once built; HDF5 copies what it uses of them
            scalar = h5py.h5s.create(h5py.h5s.SCALAR)
            dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
            dcpl.set_obj_track_times(False)  # as h5py's create_dataset
            lcpl = h5py.h5p.create(h5py.h5p.LINK_CREATE)  # as h5py's create_group for an ASCII name
            lcpl.set_create_intermediate_group(True)
            lcpl.set_char_encoding(h5py.h5t.CSET_ASCII)
            _Writer._plists = (scalar, dcpl, lcpl)
        self._scalar, self._dcpl, self._lcpl = _Writer._plists
        self._str = h5py.string_dtype()  # variable-length UTF-8 (building it costs ~1 us a call)

    def gid(self, path: str):
        """The low-level id of the group at ``path``, created (with its parents) if missing."""
        g = self._gids.get(path)
        if g is None:
            h5g = self._h5.h5g
            parent, _, leaf = path.rpartition("/")
            pid = self.gid(parent)
            name = leaf.encode("utf-8")
            if parent not in self._made and pid.links.exists(name):  # the root or a group the spool made
                g = h5g.open(pid, name)
            elif leaf.isascii():
                g = h5g.create(pid, name, lcpl=self._lcpl)
                self._made.add(path)
            else:
                g = self._h5.Group(pid).create_group(leaf).id
                self._made.add(path)
            self._gids[path] = g
        return g

    def group(self, path: str):
        """The group at ``path`` as an h5py ``Group`` (created if missing)."""
        return self._h5.Group(self.gid(path))

    def _type(self, key, dtype):
        t = self._types.get(key)
        if t is None:
            h5t = self._h5.h5t
            t = self._types[key] = (h5t.py_create(dtype, logical=True), h5t.py_create(dtype))
        return t

    def _space(self, shape: tuple):
        space = self._spaces.get(shape)
        if space is None:
            space = self._spaces[shape] = self._h5.h5s.create_simple(shape)
        return space

    def attr(self, oid, name: str, value, replace: bool = False) -> None:
        """``attrs[name] = value`` on the object whose low-level id is ``oid``, stored as h5py's
        ``attrs`` stores it: a str, bool, int or float as a scalar, anything else as the array h5py
        makes of it."""
        h5 = self._h5
        if isinstance(value, str):
            data = np.array(value, dtype=self._str)
            (htype, mtype), space = self._type("str", data.dtype), self._scalar
        elif isinstance(value, (bool, np.bool_, int, np.integer, float, np.floating)):
            data = np.asarray(value)
            (htype, mtype), space = self._type(data.dtype.str, data.dtype), self._scalar
        else:
            data = _attr_array(value)  # what h5py's attrs[name] = value stores; numpy's texts as a list's
            if not isinstance(data, np.ndarray) or data.dtype.subdtype is not None:  # h5py.Empty, ...
                h5.AttributeManager(_IdHolder(oid))[name] = value
                return
            htype, mtype = h5.h5t.py_create(data.dtype, logical=True), h5.h5t.py_create(data.dtype)
            space = h5.h5s.create_simple(data.shape)
        h5a = h5.h5a
        bname = name.encode("utf-8")
        if replace and h5a.exists(oid, bname):
            h5a.delete(oid, bname)
        a = h5a.create(oid, bname, htype, space)
        try:
            a.write(data, mtype=mtype)
        finally:
            a.close()

    def dataset(self, path: str, data: np.ndarray):
        """The low-level id of a new contiguous dataset holding ``data`` (numbers or fixed-length
        bytes, at least 1-D; or a str, stored as a scalar variable-length UTF-8 string)."""
        h5 = self._h5
        parent, _, leaf = path.rpartition("/")
        pid = self.gid(parent)
        if isinstance(data, str):
            data = np.array(data, dtype=self._str)
            (tid, mtype), space = self._type("str", data.dtype), self._scalar
        else:
            data = np.ascontiguousarray(data)
            (tid, mtype), space = self._type(data.dtype.str, data.dtype), self._space(data.shape)
        dsid = h5.h5d.create(pid, leaf.encode("utf-8"), tid, space, dcpl=self._dcpl)
        dsid.write(h5.h5s.ALL, h5.h5s.ALL, data, mtype=mtype)
        return dsid


def _h5base():
    """h5py's ``_hl.base`` (its ``array_for_new_object`` is what ``attrs[name] = value`` stores)."""
    from h5py._hl import base

    return base


def _attr_array(value):
    """The array an attribute stores of ``value``: what h5py's ``attrs[name] = value`` makes of it
    (``array_for_new_object``), an array of numpy's texts (``np.array(["a", "b"])``, dtype ``<U1``, which HDF5
    has no type for) as UTF-8 texts, as a list of str is stored (and read back)."""
    data = _h5base().array_for_new_object(value)
    if isinstance(value, np.ndarray) and value.dtype.kind == "U":  # not a list numpy makes texts of ([1, "a"])
        data = data.astype(_lazy_h5py().string_dtype())
    return data


class _IdHolder:
    """What h5py's ``AttributeManager`` needs of its parent: ``.id``."""

    def __init__(self, oid):
        self.id = oid


#: the environment variable naming the author an archive's ``/h5md/author`` records
AUTHOR_VARIABLE = "BEARINGSIM_AUTHOR"


def author() -> str:
    """The name ``/h5md/author@name`` records (H5MD 1.1 requires it): ``$BEARINGSIM_AUTHOR`` if set and not
    blank, else ``"unknown"``; never read from the host (no login name), so the same run writes the same
    header on any machine."""
    name = os.environ.get(AUTHOR_VARIABLE, "").strip()
    return name or "unknown"


def _write_header(w: _Writer, result, complete: bool = False) -> None:
    sc = result.scenario
    w.attr(w.gid(""), "title", f"bearingsim archive: {sc.name}")
    w.attr(w.gid("h5md"), "version", np.array([1, 1]))
    creator = w.gid("h5md/creator")
    w.attr(creator, "name", "bearingsim")
    w.attr(creator, "version", __version__)
    w.attr(w.gid("h5md/author"), "name", author())
    g = w.gid("bearingsim")
    w.attr(g, "format_version", FORMAT_VERSION)
    w.attr(g, "model", result.model)
    w.attr(g, "scenario_name", sc.name)
    w.attr(g, "complete", complete)
    ds = w.dataset("scenario", sc.to_toml())
    w.attr(ds, "format", "TOML (resolved: defaults, preset and overrides applied)")
    w.attr(ds, "source", str(sc.source))


NOTES = "bearingsim/notes"


def _write_notes(w: _Writer, notes) -> None:
    """The run's notes (:func:`bearingsim.plausibility.check`) as ``/bearingsim/notes``: a 1-D text
    dataset, one note per element, in the order the run made them (empty: a run without a note)."""
    h5py = _lazy_h5py()
    data = np.array([str(n) for n in notes], dtype=object).reshape(-1)
    w.group("bearingsim").create_dataset("notes", data=data, dtype=h5py.string_dtype())


def read_notes(f, path) -> list[str] | None:
    """The notes stored in the open archive ``f`` (:func:`_write_notes`), or None for an archive that
    stores none (no ``/bearingsim/notes``); a one-line UserError for one that is not a 1-D text dataset."""
    h5py = _lazy_h5py()
    if NOTES not in f:
        return None
    ds = f[NOTES]
    if not isinstance(ds, h5py.Dataset) or ds.ndim != 1 or ds.dtype.kind not in "OS" or (
            ds.dtype.kind == "O" and h5py.check_string_dtype(ds.dtype) is None):
        raise _damaged(path, f"/{NOTES} is not a list of texts")
    return [v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v) for v in ds[()].tolist()]


def _json_scalar(v):
    """``v`` as a JSON-exact Python scalar (str, bool, int, float), or None if it is not one."""
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v)  # repr round-trips exactly; NaN and +-inf as NaN, Infinity
    if isinstance(v, str):
        return v
    return None


#: what :func:`check_storable` says an archive stores of a named value
STORABLE = "a str, bool, int, float or an array of numbers or texts"
#: the most bytes HDF5 holds in one attribute (its object header message), the name and type included
ATTR_BYTES = 64 * 1024


def _unstorable(name: str, v) -> str | None:
    """Why :func:`_write_group_attrs` cannot store ``v`` as the value ``name`` ("expected ... (got ...)"), or None
    when it stores it: a scalar it writes as JSON, or a value whose attribute it writes, tried in an archive in
    memory (so what h5py would refuse mid-write is known before: an object, None, a dict, a list of mixed things,
    an array of a type HDF5 has none for, an array larger than an attribute holds)."""
    if _json_scalar(v) is not None:
        return None
    kind = f"an array of {v.dtype}" if isinstance(v, np.ndarray) else type(v).__name__
    try:
        _image(lambda f: _Writer(f, fresh=True).attr(f.id, name, v))
    except (TypeError, ValueError):
        return f"expected {STORABLE}, which an archive stores (got {kind})"
    except (OSError, RuntimeError):  # HDF5's own refusal: the attribute does not fit in its object header
        size = _attr_array(v).nbytes
        return (f"expected {STORABLE} of less than {ATTR_BYTES // 1024} KiB, which an archive's attribute holds "
                f"(got {kind} of {size} bytes)")
    return None


def check_storable(result, what: str = "save()") -> None:
    """Refuse, before anything is written, a named value of ``result`` its archive cannot store, in one line
    (:class:`bearingsim.UserError`) naming ``what`` refuses it, where it is and its type: a value of its
    provenance or of an attribute group that is not :data:`STORABLE` or is too large for an attribute
    (:func:`_unstorable`), a name or unit that is not a str."""
    named = [(f"groups[{path_!r}].attrs", grp.attrs, grp.units) for path_, grp in result.groups.items()]
    for where, values, units in [*named, ("provenance", result.provenance, {})]:
        for k, v in values.items():
            if not isinstance(k, str):
                raise UserError(f"{what}: {where}: expected names that are str (got {k!r}, a {type(k).__name__})")
            why = _unstorable(k, v)
            if why is not None:
                raise UserError(f"{what}: {where}[{k!r}]: {why}")
        for k, u in units.items():
            where_units = where.replace(".attrs", ".units")
            if not isinstance(k, str):
                raise UserError(f"{what}: {where_units}: expected names that are str (got {k!r}, a {type(k).__name__})")
            if not isinstance(u, str):
                raise UserError(f"{what}: {where_units}[{k!r}]: expected a unit, a str (got {type(u).__name__})")


def _write_group_attrs(w: _Writer, g, values: dict[str, Any], units: dict[str, str]) -> None:
    """Named values and their units as the attributes ``attrs_json`` and ``units_json`` of ``g``.

    Keys sorted (the order HDF5 lists attributes by name, so a format 1.x reader and this one give the
    same dict order). A value that is not a scalar (an array) stays an HDF5 attribute of its own.
    """
    plain, other = {}, {}
    for k, v in values.items():
        j = _json_scalar(v)
        if j is None:
            other[k] = v
        else:
            plain[k] = j
    w.attr(g, ATTRS_JSON, json.dumps(dict(sorted(plain.items())), ensure_ascii=False, allow_nan=True))
    if units:
        w.attr(g, UNITS_JSON, json.dumps(dict(sorted(units.items())), ensure_ascii=False))
    for k, v in other.items():
        w.attr(g, k, v)


def group_attrs(g) -> tuple[dict[str, Any], dict[str, str]]:
    """(values, units) of an attribute group or ``/provenance``, either layout, keys sorted.

    Format 2.x: the JSON attributes ``attrs_json`` / ``units_json`` (plus any array-valued attribute);
    format 1.x: one attribute per value and ``<name>__unit`` beside it. ``description`` is not a value.
    """
    values: dict[str, Any] = {}
    units: dict[str, str] = {}
    for k, v in g.attrs.items():
        if k == ATTRS_JSON:
            values.update(_json_object(v, g.name, k))
        elif k == UNITS_JSON:
            units.update({u: str(w) for u, w in _json_object(v, g.name, k).items()})
        elif k.endswith("__unit"):
            units[k[:-6]] = str(_plain(v))
        elif k != "description":
            values[k] = _plain(v)
    return dict(sorted(values.items())), dict(sorted(units.items()))


def _json_object(v, where: str, name: str) -> dict[str, Any]:
    """The JSON attribute ``name`` of ``where`` as a dict of scalars (ValueError for anything else: not
    text, not JSON, nested, or too deep for the parser)."""
    v = _plain(v)
    if not isinstance(v, str):
        raise ValueError(f"{where}@{name} is not text")
    try:
        d = json.loads(v)
    except RecursionError:
        raise ValueError(f"{where}@{name} is nested too deeply") from None
    if not isinstance(d, dict) or not all(v is None or isinstance(v, (str, int, float)) for v in d.values()):
        raise ValueError(f"{where}@{name} is not a JSON object of named scalars")
    return d


def _write_array(w: _Writer, path: str, arr) -> None:
    data = np.asarray(arr.data)
    if data.dtype.kind == "U":
        data = data.astype("S")
    if data.size > 4096 or data.ndim == 0 or data.dtype.kind not in "biufS":
        kw = dict(compression="gzip", compression_opts=4, shuffle=True, chunks=True) if data.size > 4096 else {}
        parent, _, leaf = path.rpartition("/")
        ds = w.group(parent).create_dataset(leaf, data=data, **kw).id
    else:
        ds = w.dataset(path, data)
    w.attr(ds, "unit", arr.unit)
    if arr.description:
        w.attr(ds, "description", arr.description)
    # no ds.close(): closing an id makes HDF5 write there, and on a full disk that error would come as a
    # RuntimeError from h5py; the ids go with the file, whose flush and close report an OSError


def run_facts() -> dict[str, Any]:
    """The facts of the code and the machine that compute a run, in every fresh result's provenance
    (:func:`bearingsim.simulation.run`): ``bearingsim_version``, ``git_commit``, ``platform``, ``command``
    and ``version_<package>`` of python and the packages its numbers depend on."""
    facts = {"bearingsim_version": __version__, "git_commit": git_commit(), "platform": platform.platform(),
             "command": command_line()}
    facts.update((f"version_{k}", v) for k, v in package_versions().items())
    return facts


#: the command a run records instead of its own process's, where that is not the one the user gave: a sweep
#: case on a dask worker records the sweep's (:func:`bearingsim.sweeps.worker.run_batch`); per thread of
#: control, as a dask worker runs its tasks in threads
_GIVEN_COMMAND: contextvars.ContextVar[str | None] = contextvars.ContextVar("bearingsim_command", default=None)


def command_line() -> str:
    """The command that runs this process, as a shell takes it again (:func:`shlex.join`: an argument with
    spaces stays one), its program named ``bearingsim`` when it is bearingsim's own entry point (the
    console script, or ``python -m bearingsim``, whose ``sys.argv[0]`` is the path of ``__main__.py``); the
    command given to :func:`given_command` where one is."""
    given = _GIVEN_COMMAND.get()
    if given is not None:
        return given
    argv = list(sys.argv)
    if argv and (Path(argv[0]).name == "bearingsim" or argv[0].endswith(".py")
                 and Path(argv[0]).resolve() == Path(__file__).resolve().parent / "__main__.py"):
        argv[0] = "bearingsim"
    return shlex.join(argv)


@contextlib.contextmanager
def given_command(command: str | None):
    """Within it :func:`command_line` gives ``command`` (None: this process's own)."""
    token = _GIVEN_COMMAND.set(command)
    try:
        yield
    finally:
        _GIVEN_COMMAND.reset(token)


def _provenance(result) -> dict[str, Any]:
    """Provenance, written in this one place: the result's own (a fresh result's holds the facts of the code
    that computed it, :func:`run_facts`) and ``created_utc``, the time the archive is written.

    A result read back from an archive keeps the provenance of the run that made it (the code, the
    machine, the command and the time it was first written): re-saving it elsewhere does not restamp it
    with the machine that saves it. A result made otherwise (no run facts) gets those of this process."""
    own = result.provenance
    here = run_facts()
    prov = {k: own.get(k, v) for k, v in here.items() if not k.startswith("version_")}
    prov["created_utc"] = own.get("created_utc", _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"))
    versions = {k: v for k, v in own.items() if k.startswith("version_")}
    prov.update(versions or {k: v for k, v in here.items() if k.startswith("version_")})
    for k, v in own.items():
        if k not in prov:
            prov[k] = v
    return prov


def _provenance_units(prov: dict) -> dict[str, str]:
    """Units of the provenance's numbers that have one: the times and steps in seconds (``dt_s``,
    ``wall_time_s``, ``solver_wall_s``, ``pymunk_step_s``: the ``_s`` suffix)."""
    return {k: "s" for k, v in prov.items() if k.endswith("_s") and isinstance(v, (int, float))
            and not isinstance(v, bool)}


#: the HDF5 format signature: at the start of the superblock, at byte 0 or 512, 1024, 2048, ... of a file
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _has_hdf5_signature(path) -> bool:
    """False when no HDF5 superblock can start anywhere in the regular file ``path`` (the signature is at
    none of the offsets where the HDF5 library looks for it: 0 and 512 * 2^k); then the file is not
    HDF5, and telling so needs no h5py (a scenario file, the usual case, is decided here)."""
    with open(path, "rb") as f:
        size = f.seek(0, 2)
        offset = 0
        while offset + len(_HDF5_SIGNATURE) <= size:
            f.seek(offset)
            if f.read(len(_HDF5_SIGNATURE)) == _HDF5_SIGNATURE:
                return True
            offset = 512 if offset == 0 else 2 * offset
    return False


def is_archive(path) -> bool:
    """True when ``path`` is an HDF5 file written by bearingsim (complete or not)."""
    try:
        # a FIFO is never opened: it would block; h5py only for a file that may be HDF5
        if not Path(path).is_file() or not _has_hdf5_signature(path):
            return False
        h5py = _lazy_h5py()
        if not h5py.is_hdf5(path):
            return False
        with h5py.File(path, "r") as f:
            return "bearingsim" in f and "format_version" in f["bearingsim"].attrs
    except Exception:  # unreadable or damaged: not something we may replace
        return False


def model_of(path) -> str:
    """The model name an archive was written by (one-line UserError for a bad file)."""
    f = open_archive(path)
    try:
        with reading(path):
            return _model_attr(f, path)
    finally:
        f.close()


def has_observable(path, name: str) -> bool:
    """True when the archive at ``path`` holds the time series ``/observables/<name>`` (metadata only;
    one-line UserError for a file that is not an archive)."""
    f = open_archive(path)
    try:
        with reading(path):
            obs = f["observables"] if "observables" in f else None
            return isinstance(obs, _lazy_h5py().Group) and name in obs
    finally:
        f.close()


def _wanted(name: str, only) -> bool:
    return only is None or any(name == p or name.startswith(p + "/") for p in only)


def read(path, result_class, only=None):
    """Read a complete archive back into ``result_class`` (one-line UserError for a bad file).

    ``bearingsim.load`` picks the class of the archive's model (:func:`bearingsim.simulation.load`).
    ``only``: the archive paths (``"results/per_rotation"``, ``"observables"`` ...) whose datasets are
    read, each with everything under it; None reads every dataset. The scenario, the attribute groups
    (the summary) and the provenance are always read, and the layout is always checked (metadata only):
    a command that needs a few arrays does not decompress the others.
    """
    f = open_archive(path)
    try:
        model = _model_attr(f, path)
        scenario = _read_scenario(f, path)
        if model != result_class.model:
            raise UserError(f"{path}: archive of the {model!r} model, not {result_class.model!r}")
        check_layout(f, path, result_class, scenario)
        data: dict[str, NamedArray] = {}
        groups: dict[str, AttrGroup] = {}
        tables: dict[str, str] = {}
        columns: dict[str, list[str]] = {}  # each table's column order, as its @columns stores it
        unread: list[str] = []  # the datasets ``only`` leaves out (Result.partial)

        def visit(name, obj):
            if name.startswith("results"):
                if hasattr(obj, "shape"):
                    if not _wanted(name, only):
                        unread.append(name)
                        return
                    v = obj[()]
                    if v.dtype.kind == "S":
                        v = v.astype("U")
                    data[name] = NamedArray(v, str(obj.attrs.get("unit", "1")), str(obj.attrs.get("description", "")))
                elif "columns" in obj.attrs:
                    tables[name] = str(obj.attrs.get("description", ""))
                    columns[name] = _column_names(obj.attrs["columns"])
                else:
                    attrs, units = group_attrs(obj)
                    if attrs:
                        groups[name] = AttrGroup(attrs, units, str(_plain(obj.attrs.get("description", ""))))

        f.visititems(visit)
        data = _in_result_order(data, columns, result_class.LAYOUT)
        series = {}
        for name, g in (f["observables"].items() if "observables" in f and _wanted("observables", only) else ()):
            series[name] = Series(g["step"][()], g["time"][()], g["value"][()], str(g["value"].attrs.get("unit", "1")),
                                  str(g.attrs.get("description", "")))
        if "observables" in f and not _wanted("observables", only):
            unread += [f"observables/{name}" for name in f["observables"]]
        provenance = group_attrs(f["provenance"])[0] if "provenance" in f else {}
        notes = read_notes(f, path) or []
    except UserError:
        raise
    except H5_ERRORS as exc:
        raise _damaged(path, f"{exc.__class__.__name__}: {exc}") from None
    finally:
        f.close()
    result = result_class(scenario, data, groups, series=series, provenance=provenance, tables=tables)
    result.notes = notes
    if unread:
        result.partial = (path, tuple(only), tuple(unread))
    return result


def _column_names(value) -> list[str]:
    """A table's ``@columns`` as a list of names (empty for a value that is not a list of names)."""
    names = [v.decode("utf-8", "replace") if isinstance(v, bytes) else v for v in np.atleast_1d(value).tolist()]
    return names if all(isinstance(v, str) for v in names) else []


def _in_result_order(data: dict, columns: dict[str, list[str]], layout) -> dict:
    """``data`` (read in the order HDF5 lists a group's members: by name) in the order of the result that
    was written: a table's columns in the order its ``@columns`` stores, every other array in the order
    of the model's :attr:`~bearingsim.results.Result.LAYOUT`, arrays it does not declare after them in
    the order read."""
    declared = {k: i for i, k in enumerate(layout)}
    start = {t: min((i for k, i in declared.items() if k.startswith(t + "/")), default=len(declared))
             for t in columns}

    def rank(item):
        i, name = item
        table, _, column = name.rpartition("/")
        if column in columns.get(table, ()):
            return start[table], columns[table].index(column), i
        return declared.get(name, len(declared)), 0, i

    return {name: data[name] for _, name in sorted(enumerate(data), key=rank)}


def _damaged(path, what: str, kind: str = "archive") -> UserError:
    return UserError(f"{path}: damaged {kind} ({what})")


#: what h5py raises of a damaged file: RuntimeError (a B-tree, local heap or symbol table node whose signature
#: is wrong: "Iteration operator failed (wrong B-tree signature)"), OSError (data it cannot read: a global heap
#: collection, a compressed chunk), KeyError, ValueError and TypeError (an object or attribute it cannot open
#: or decode)
H5_ERRORS = (RuntimeError, OSError, KeyError, ValueError, TypeError)


@contextlib.contextmanager
def reading(path, kind: str = "archive"):
    """Around the reading of an open HDF5 file: what h5py raises of a damaged file becomes one
    :class:`UserError` naming ``path`` ("damaged archive (RuntimeError: ...)"; ``kind``: what the file is),
    the one place the readers of this module turn h5py's errors into a line for the user."""
    try:
        yield
    except UserError:
        raise
    except H5_ERRORS as exc:
        raise _damaged(path, f"{exc.__class__.__name__}: {exc}", kind) from None


def _model_attr(f, path) -> str:
    """``/bearingsim@model``: the name of a known model, else a one-line UserError."""
    from bearingsim.model_versions import MODELS

    model = _plain(f["bearingsim"].attrs.get("model"))
    if model is None:
        raise _damaged(path, "no /bearingsim@model: which model wrote it is unknown")
    if not isinstance(model, str) or model not in MODELS:
        raise _damaged(path, f"/bearingsim@model is {outputs.printable(repr(model))[:60]}, not one of "
                             f"{', '.join(MODELS)}")
    return model


def _read_scenario(f, path):
    """The resolved scenario stored at ``/scenario``: a scalar text dataset read with the limits of a
    scenario file (size, nesting: :func:`bearingsim.scenario.parse_toml_text`) and validated like one."""
    from bearingsim.scenario import MAX_SCENARIO_BYTES, parse_toml_text, resolve

    h5py = _lazy_h5py()
    ds = f.get("scenario")
    if not isinstance(ds, h5py.Dataset):
        raise _damaged(path, "/scenario is missing or not a dataset")
    kind = ds.dtype.kind
    if ds.shape != () or kind not in "OS" or (kind == "O" and h5py.check_string_dtype(ds.dtype) is None):
        raise _damaged(path, f"/scenario is not a text (shape {ds.shape}, type {ds.dtype})")
    if kind == "S" and ds.dtype.itemsize > MAX_SCENARIO_BYTES:
        raise _damaged(path, f"/scenario is larger than {MAX_SCENARIO_BYTES} bytes")
    text = ds[()]
    try:
        text = text.decode("utf-8") if isinstance(text, bytes) else str(text)
    except UnicodeDecodeError:
        raise _damaged(path, "/scenario is not UTF-8 text") from None
    where = f"{path}:/scenario"
    return resolve(parse_toml_text(text, where), where)


def check_layout(f, path, result_class, scenario) -> None:
    """Refuse, with a one-line UserError naming ``path`` and what is wrong, an archive whose structure is
    not what ``result_class`` reads and draws: ``/results/summary`` a group holding the model's summary
    numbers (:attr:`Result.SUMMARY_NUMBERS`, and :attr:`Result.SUMMARY_OPTIONAL` where present), every
    array of :attr:`Result.LAYOUT` a numeric (or text) dataset of its declared dimensions, consistent with
    each other and with the scenario (:meth:`Result.archive_dims`), ``/observables`` groups of ``step``,
    ``time`` and ``value`` datasets of one length. Only metadata is read (shapes and types): nothing is decompressed."""
    h5py = _lazy_h5py()
    scenario_model = scenario.model
    if scenario_model != result_class.model:
        raise _damaged(path, f"/bearingsim@model {result_class.model!r} contradicts the model of its /scenario "
                             f"({scenario_model!r})")
    for name in ("results", "results/summary"):
        if not isinstance(f.get(name), h5py.Group):
            raise _damaged(path, f"/{name} is missing or not a group")
    if "provenance" in f and not isinstance(f["provenance"], h5py.Group):
        raise _damaged(path, "/provenance is not a group")
    summary = group_attrs(f["results/summary"])[0]
    for key in (*result_class.SUMMARY_NUMBERS, *(k for k in result_class.SUMMARY_OPTIONAL if k in summary)):
        v = summary.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise _damaged(path, f"/results/summary: {key} is {outputs.printable(repr(v))[:40]}, not a number")
    dims = dict(result_class.archive_dims(scenario))
    for path_, shape in result_class.LAYOUT.items():
        group = next((g for g in result_class.OPTIONAL if path_ in g), None)
        if group is not None and not any(p in f for p in group):
            continue  # an optional set of arrays (all or none), absent
        ds = f.get(path_)
        if not isinstance(ds, h5py.Dataset):
            raise _damaged(path, f"/{path_} is missing or not a dataset ({result_class.model} model)")
        text = path_ in result_class.TEXT_ARRAYS
        if ds.dtype.kind not in ("SOU" if text else "biuf") or ds.dtype.subdtype is not None:
            raise _damaged(path, f"/{path_} has type {ds.dtype}, expected {'text' if text else 'numbers'}")
        if len(ds.shape) != len(shape):
            raise _damaged(path, f"/{path_} has {len(ds.shape)} dimension(s) {ds.shape}, expected "
                                 f"{len(shape)} ({', '.join(map(str, shape))})")
        for name, n in zip(shape, ds.shape):
            want = name if isinstance(name, int) else dims.setdefault(name, n)
            if n != want:
                raise _damaged(path, f"/{path_} has shape {ds.shape}: {name} = {n}, expected {want}")
    obs = f.get("observables")
    if obs is not None:
        if not isinstance(obs, h5py.Group):
            raise _damaged(path, "/observables is not a group")
        for name, g in obs.items():
            parts = [g.get(k) if isinstance(g, h5py.Group) else None for k in ("step", "time", "value")]
            if not all(isinstance(d, h5py.Dataset) and d.dtype.kind in "biuf" and d.ndim >= 1 for d in parts):
                raise _damaged(path, f"/observables/{name} is not a time series (step, time, value datasets)")
            if parts[0].ndim != 1 or parts[1].ndim != 1 or not parts[0].shape[0] == parts[1].shape[0] == parts[2].shape[0]:
                raise _damaged(path, f"/observables/{name}: step, time and value differ in length")


def _plain(v):
    """An HDF5 attribute as a plain Python value (str, float, int, bool, or a numpy array)."""
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.bool_):
        return bool(v)
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, np.floating):
        return float(v)
    return v


def write_table_file(path, columns: dict[str, np.ndarray], units: dict[str, str], attrs: dict[str, Any],
                     descriptions: dict[str, str] | None = None) -> Path:
    """Write a stand-alone table (``/index/<column>`` datasets, root ``attrs``) atomically: a sweep's
    ``sweep.h5``. String columns are stored as variable-length UTF-8; a column's ``unit`` and, where
    ``descriptions`` has one, its ``description`` are attributes of its dataset."""
    h5py = _lazy_h5py()
    path = Path(path)

    def fill(f):
        for k, v in attrs.items():
            f.attrs[k] = v
        g = f.create_group("index")
        for name, arr in columns.items():
            arr = np.asarray(arr)
            if arr.dtype.kind in "OUS":
                ds = g.create_dataset(name, data=arr.astype(object), dtype=h5py.string_dtype())
            else:
                ds = g.create_dataset(name, data=arr)
            if name in units:
                ds.attrs["unit"] = units[name]
            if descriptions and name in descriptions:
                ds.attrs["description"] = descriptions[name]

    outputs.write_atomic_bytes(path, _image(fill))  # a full disk: an OSError naming path
    return path


#: what each of bearingsim's files that is not a run archive is called in the line that says it is damaged,
#: by its root ``format`` attribute
_TABLE_KINDS = {"bearingsim sweep index": "sweep index", "bearingsim sweep map": "sweep map",
                "bearingsim crosscheck index": "cross-check table", "bearingsim sensitivity index": "sensitivity table",
                "bearingsim uncertainty index": "uncertainty table", "bearingsim life": "life history"}


def _table_kind(fmt: str) -> str:
    return _TABLE_KINDS.get(fmt.rstrip("0123456789. "), "HDF5 file")


def _open_table(p: Path, fmt: str):
    """``p`` opened read-only with h5py, or a one-line UserError naming it: not a regular file, not
    readable, not HDF5, or damaged or truncated so that HDF5 cannot open it (``fmt``: the format looked for,
    which names the file in that line). The start of both table readers."""
    h5py = _lazy_h5py()
    _check_regular(p)
    if not _has_hdf5_signature(p):
        raise UserError(f"{p}: not a {fmt} (not an HDF5 file)")
    try:
        return h5py.File(p, "r")
    except OSError as exc:
        raise UserError(f"{p}: damaged or truncated {_table_kind(fmt)}, HDF5 cannot open it ({exc})") from None


def read_table_file(path, fmt: str) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """Read a table written by :func:`write_table_file` whose root attribute ``format`` is ``fmt``:
    (columns, root attributes). One-line UserError for anything else, naming the file (a damaged one:
    :func:`reading`)."""
    p = Path(path)
    f = _open_table(p, fmt)
    with f, reading(p, _table_kind(fmt)):
        if f.attrs.get("format") != fmt or "index" not in f:
            raise UserError(f"{p}: not a {fmt}")
        attrs = {k: _plain(v) for k, v in f.attrs.items()}
        cols = {name: (ds.asstr()[()] if ds.dtype.kind == "O" else ds[()]) for name, ds in f["index"].items()}
    # one row per entry of every column's first axis: a column of another length (a row cut from one column by
    # hand) made a sweep's resume fail with IndexError's traceback, after it had rewritten the index all pending
    rows = {np.shape(c)[0] if np.ndim(c) else None for c in cols.values()}
    if len(rows) > 1 or None in rows:
        counts = sorted(f"{name} {np.shape(c)[0] if np.ndim(c) else 'a scalar'}" for name, c in cols.items())
        if None not in rows:
            common = max(rows, key=lambda n: sum(np.shape(c)[0] == n for c in cols.values()))
            counts = [t for t in counts if not t.endswith(f" {common}")]
        raise _damaged(p, f"its columns are not all of one length: {', '.join(counts[:3])}"
                          f"{', ...' if len(counts) > 3 else ''}", _table_kind(fmt))
    return cols, attrs


def write_grid_file(path, axes: list[tuple[str, np.ndarray, dict[str, str]]],
                    variables: dict[str, tuple[np.ndarray, dict[str, str]]], attrs: dict[str, Any]) -> Path:
    """Write labelled arrays over a grid as netCDF-4-style HDF5, atomically: a sweep's ``map.h5``.

    Each axis ``(name, values, attrs)`` is a 1-D dataset ``/<name>`` made an HDF5 dimension scale
    named ``name``; each variable ``/<name>`` has the shape of the axes in their order, with every
    dimension attached to its axis' scale, so xarray (``engine="h5netcdf"``) and netCDF tools read
    the axes as dimensions and coordinates. Text (axis values or variables) is stored as
    variable-length UTF-8; ``attrs`` go to the root, each variable's ``attrs`` (``units``,
    ``long_name``) to its dataset.
    """
    h5py = _lazy_h5py()
    path = Path(path)

    def create(f, name, arr):
        arr = np.asarray(arr)
        if arr.dtype.kind in "OUS":
            return f.create_dataset(name, data=arr.astype(object), dtype=h5py.string_dtype())
        return f.create_dataset(name, data=arr)

    def fill(f):
        for k, v in attrs.items():
            f.attrs[k] = v
        scales = []
        for name, values, a in axes:
            ds = create(f, name, values)
            ds.make_scale(name)
            ds.attrs.update(a)
            scales.append(ds)
        for name, (arr, a) in variables.items():
            ds = create(f, name, arr)
            ds.attrs.update(a)
            for i, scale in enumerate(scales):
                ds.dims[i].attach_scale(scale)

    outputs.write_atomic_bytes(path, _image(fill))  # a full disk: an OSError naming path
    return path


def read_grid_file(path, fmt: str) -> tuple[dict[str, np.ndarray], dict[str, dict], dict[str, Any]]:
    """Read a file written by :func:`write_grid_file` whose root attribute ``format`` is ``fmt``:
    (every dataset as an array, text as ``str`` objects; each dataset's attributes; root attributes).
    One-line UserError for anything else."""
    p = Path(path)
    f = _open_table(p, fmt)
    skip = ("CLASS", "NAME", "REFERENCE_LIST", "DIMENSION_LIST")  # the dimension-scale bookkeeping
    with f, reading(p, _table_kind(fmt)):
        if f.attrs.get("format") != fmt:
            raise UserError(f"{p}: not a {fmt}")
        root = {k: _plain(v) for k, v in f.attrs.items()}
        data, attrs = {}, {}
        for name, ds in f.items():
            data[name] = ds.asstr()[()] if ds.dtype.kind == "O" else ds[()]
            attrs[name] = {k: _plain(v) for k, v in ds.attrs.items() if k not in skip}
    return data, attrs, root


def root_format(path) -> str | None:
    """The root ``format`` attribute of the HDF5 file ``path`` (what names bearingsim's own files that are
    not run archives: :data:`OWN_FILES`), read alone; None for a path that is not a regular readable HDF5
    file, nor one HDF5 can open, or whose root holds no such text: the reader of the file says what is
    wrong with it."""
    p = Path(path)
    try:
        if not p.is_file() or not _has_hdf5_signature(p):
            return None
        with _lazy_h5py().File(p, "r") as f:
            fmt = _plain(f.attrs.get("format"))
    except H5_ERRORS:
        return None
    return fmt if isinstance(fmt, str) else None


def is_grid_file(path, fmt: str) -> bool:
    """True when ``path`` is a grid file of format ``fmt`` (:func:`write_grid_file`; its root ``format``: a
    damaged one too, which :func:`read_grid_file` then names)."""
    return root_format(path) == fmt


def table_units(path, attr: str = "unit") -> dict[str, str]:
    """The ``unit`` (or another text ``attr``: ``description``) of every column of a table file
    (:func:`write_table_file`) that has one."""
    return _column_texts(path, (attr,))[attr]


def _column_texts(path, attrs: tuple[str, ...]) -> dict[str, dict[str, str]]:
    """``{attr: {column: text}}`` of the text attributes ``attrs`` of a table file's columns, read in one
    opening of the file."""
    p = Path(path)
    with _lazy_h5py().File(p, "r") as f, reading(p, "table"):
        return {a: {name: _plain(ds.attrs[a]) for name, ds in f["index"].items() if a in ds.attrs} for a in attrs}


def describe_table(path, what: str, cols: dict[str, np.ndarray], columns: list[str], lines: list[str],
                   noun: str = "row") -> str:
    """Listing of an index table (a sweep's ``sweep.h5``, a cross-check's ``crosscheck.h5``): what it is,
    how many rows (counted as ``noun``: a sweep's are cases, a life history's stages) and by status, the
    ``lines`` the caller adds, then every column with its unit and its description, where it has one."""
    n = len(cols[columns[0]]) if columns else 0
    status = cols.get("status")
    by = {}
    for v in (status if status is not None else []):
        by[str(v)] = by.get(str(v), 0) + 1
    counts = " (" + ", ".join(f"{k} {v}" for k, v in sorted(by.items())) + ")" if by else ""
    texts = _column_texts(path, ("unit", "description"))
    units, said = texts["unit"], texts["description"]
    out = [f"{path}: {what}: {counted(n, noun)}{counts}", *lines, "columns:"]
    for c in columns:
        arr = np.asarray(cols[c])
        kind = "text" if arr.dtype.kind in "OUS" else "number"
        unit = units.get(c, "")
        out.append(f"  {c:32s} {kind}" + (f" [{unit}]" if unit and unit != "1" else "")
                   + (f": {said[c]}" if said.get(c) else ""))
    return "\n".join(out)


def is_table_file(path, fmt: str) -> bool:
    """True when ``path`` is a table of format ``fmt`` (:func:`write_table_file`): its root ``format`` says
    so (a damaged table too: :func:`read_table_file` then says what is wrong with it, naming it)."""
    return root_format(path) == fmt


#: the per-rotation arrays whose batch means give the standard errors of a result's summary numbers
#: (:func:`bearingsim.stats.summary_standard_errors`), each with its dimensions: 2 ``[rotations, pockets]``,
#: 1 ``[rotations]``
SEM_SERIES = {"I_dec": 2, "I_acc": 2, "first_impact_speed": 2, "cage_slip": 1, "load_zone_half_angle": 1}


def sem_series_ok(per: dict) -> bool:
    """Whether the arrays ``per`` (name -> array, of :data:`SEM_SERIES`) are numbers of the shapes a result's are:
    ``I_dec`` ``[rotations, pockets]`` and each other one ``[rotations, pockets]`` or ``[rotations]`` as
    :data:`SEM_SERIES` says (a damaged or crafted archive's are not)."""
    shape = np.shape(per.get("I_dec"))
    return len(shape) == 2 and all(
        isinstance(a, np.ndarray) and a.dtype.kind in "fiu" and a.shape == shape[:SEM_SERIES[k]]
        for k, a in per.items())


def read_sem_series(f) -> dict:
    """The arrays of :data:`SEM_SERIES` that the open archive ``f`` has under ``/results/per_rotation``, by name."""
    return {k: f[f"results/per_rotation/{k}"][()] for k in SEM_SERIES if f"results/per_rotation/{k}" in f}


def peek(path) -> dict[str, Any] | None:
    """The few things a sweep's resume check needs from a complete archive, read cheaply: ``scenario``
    (TOML text), ``model``, ``model_version`` (of the model that computed it; None if the archive
    stores none), ``summary`` (numbers), ``per_rotation`` (``I_dec``, ``I_acc`` and those of the others of
    :data:`SEM_SERIES` it has: the arrays :func:`bearingsim.stats.summary_standard_errors` reads), ``wall_time_s``,
    ``notes`` (the run's stored notes, :func:`read_notes`; None if it stores none), ``wear`` (the attributes of
    ``/results/wear``: a reduced run's wear rates; {} without them). None for a missing, unreadable,
    damaged or incomplete file (never trusted)."""
    h5py = _lazy_h5py()
    path = Path(path)
    if not path.is_file():
        return None
    try:
        with h5py.File(path, "r") as f:
            g = f.get("bearingsim")
            if g is None or _plain(g.attrs.get("complete", False)) is not True:  # a boolean True, not "false"
                return None
            text = f["scenario"][()]
            summary = group_attrs(f["results/summary"])[0]
            prov = group_attrs(f["provenance"])[0] if "provenance" in f else {}
            version = prov.get("model_version")
            per = read_sem_series(f)
            if "I_acc" not in per or not sem_series_ok(per):
                return None  # damaged: the case runs again
            return {
                "scenario": text.decode("utf-8") if isinstance(text, bytes) else str(text),
                "model": str(g.attrs["model"]),
                "model_version": int(version) if isinstance(version, (int, np.integer))
                and not isinstance(version, bool) else None,
                "summary": {k: float(v) for k, v in summary.items()
                            if isinstance(v, (int, float)) and not isinstance(v, bool)},
                "per_rotation": per,
                "wall_time_s": float(prov.get("wall_time_s", float("nan"))),
                "notes": read_notes(f, path),
                "wear": group_attrs(f["results/wear"])[0] if "results/wear" in f else {},
            }
    except (*H5_ERRORS, UserError):  # damaged, in any way h5py tells
        return None


def check_same_scenario(out: Path, scenario,
                        advice: str = "write this run elsewhere with -o, or add --force to replace it") -> None:
    """Refuse to replace the archive ``out`` when it holds a run of another resolved scenario (a
    ``--set`` on the same file writes to the same default name): one line naming the archive, the keys
    that differ, and ``advice`` (the command line's ``-o`` / ``--force``; :meth:`Result.save`'s ``force=True``).
    A rerun of the same scenario (or of one of the same model that differs only in keys the model does not read),
    an unreadable or incomplete archive (never a result) and no file at all pass."""
    import tomllib

    from bearingsim.scenario import differing_keys, resolve

    got = peek(out) if out.is_file() else None
    if got is None:
        return
    try:
        old = resolve(tomllib.loads(got["scenario"]), f"{out}:/scenario")
    except Exception:  # noqa: BLE001 - a scenario this version cannot read is not this run's
        old = None
    if old is not None and old == scenario:
        return
    keys = []
    if old is not None:
        differ = differing_keys(old.raw, scenario.raw)
        if _unread_by_both(old, scenario, [k for k, _, _ in differ]):
            return  # the same run: its scenario differs only in keys its model does not read (each run notes them)
        keys = [f"{k} {va} -> {vb}" for k, va, vb in differ]
    what = f" ({'; '.join(keys[:3])}{'; ...' if len(keys) > 3 else ''})" if keys else ""
    raise UserError(f"{out}: holds the run of a different scenario{what}; not replaced: {advice}")


def _unread_by_both(old, new, keys) -> bool:
    """Whether the scenarios ``old`` and ``new``, of one model, differ only in ``keys`` that model does not read
    (:func:`bearingsim.scenario.unused_keys`, with the reduced model's method: a multibody key given to a reduced
    run, say), so that their runs are the same run. Another reduced method is a key the reduced model reads."""
    from bearingsim.scenario import unused_keys

    return (bool(keys) and old.model == new.model
            and len(unused_keys(new.model, keys, new.reduced.method)) == len(keys))


def _check_regular(p: Path) -> None:
    """Refuse a path that is not a regular file (a FIFO would block the reader forever, a device is
    not a file to read), checked with ``stat`` before anything opens it, or a file this process may not
    read ("cannot read (Permission denied)", as a scenario file's reader says)."""
    import stat

    try:
        mode = p.stat().st_mode
    except FileNotFoundError:
        raise UserError(f"{p}: file not found") from None
    except OSError as exc:
        raise UserError(f"{p}: cannot open ({exc.strerror or exc.__class__.__name__})") from None
    if stat.S_ISDIR(mode):
        raise _directory_error(p)
    if not stat.S_ISREG(mode):
        raise UserError(f"{p}: not a regular file (a FIFO, socket or device), not an archive")
    try:  # a file without read permission is not a damaged one: say which it is
        os.close(os.open(p, os.O_RDONLY))
    except OSError as exc:
        raise UserError(f"{p}: cannot read ({exc.strerror or exc.__class__.__name__})") from None


#: the table ``bearingsim validate`` writes in its folder (:mod:`bearingsim.studies.validate`; a CSV: no format)
VALIDATE_TABLE = "fig9_idec_vs_speed.csv"


def _directory_error(p: Path) -> UserError:
    """The refusal of a folder given where an archive is read; a sweep's or a study's folder (its index
    ``sweep.h5``) is named as one, with the commands that read it and the file ``bearingsim plot`` draws its
    figures from: a study's own table (:func:`_study_tables`), else the sweep's index (of a study, that draws
    only the cases' overview)."""
    if (p / "sweep.h5").is_file():
        cases = (f"its cases' archives are in {p / 'cases'}" if (p / "cases").is_dir()
                 else "its cases kept no archives (sweep --archives all keeps them)")
        tables = _study_tables(p)
        if tables:
            drawn = ", ".join(f"'bearingsim plot {t}' draws the study's figure" for t in tables)
        elif (p / VALIDATE_TABLE).is_file():  # validate's figures come from its cases, not from a table file
            drawn = (f"'bearingsim plot {p / 'sweep.h5'}' draws its cases' overview (validate's own figures: the "
                     f"same 'bearingsim validate -o {p}' again redraws them from its cases)")
        else:
            drawn = f"'bearingsim plot {p / 'sweep.h5'}' draws its figures"
        return UserError(f"{p}: is a sweep or study folder, not an archive: 'bearingsim table {p}', 'bearingsim "
                         f"report {p}' and 'bearingsim wear {p}' read it, {drawn}; {cases}")
    return UserError(f"{p}: is a directory, not an archive")


def _study_tables(folder: Path) -> list[Path]:
    """The studies' tables in ``folder`` (``life.h5``, ``sensitivity.h5``, ...: its regular ``*.h5`` files whose
    root ``format`` is one of :data:`STUDY_TABLE_FORMATS`), by name; what :func:`bearingsim.tables.studies_of`
    finds of them, told by the format alone (this layer does not import the studies)."""
    found = []
    for f in sorted(folder.glob("*.h5")):
        if f.name == "sweep.h5" or not f.is_file():
            continue
        fmt = root_format(f)
        if fmt is not None and fmt.rstrip("0123456789. ") in STUDY_TABLE_FORMATS:
            found.append(f)
    return found


def is_scenario_file(path) -> bool:
    """True for a regular file without an HDF5 signature that is named ``.toml`` or holds a TOML table with
    an integer ``schema_version`` (a scenario saved under another name): what ``show`` resolves as a
    scenario, and what the commands that read an archive refuse with :func:`scenario_file_error`."""
    p = Path(path)
    try:
        if not p.is_file() or _has_hdf5_signature(p):
            return False
        if p.suffix.lower() == ".toml":
            return True
        import tomllib

        with open(p, "rb") as f:
            head = f.read(1 << 20)
        return isinstance(tomllib.loads(head.decode("utf-8")).get("schema_version"), int)
    except (OSError, ValueError):  # unreadable, not UTF-8 or not TOML: not a scenario file
        return False


def scenario_file_error(path) -> UserError | None:
    """The one-line refusal of a scenario file (:func:`is_scenario_file`) given where an archive is read
    (``rerun``, ``inspect``, ``plot``, ``animate``, ``compare``, ``wear``, ``report``, ``table``), naming the
    commands that read it; None for any other path."""
    if not is_scenario_file(path):
        return None
    if _is_sweep_toml(path):  # 'run' and 'show' refuse it: send to the command that reads it
        return UserError(f"{path}: is a sweep file, not an archive; 'bearingsim sweep {path}' runs it "
                         "(docs/sweeps.md)")
    return UserError(f"{path}: is a scenario file, not an archive; 'bearingsim run {path}' runs it and writes an "
                     f"archive, 'bearingsim show {path}' prints it resolved")


def _is_sweep_toml(path) -> bool:
    """A TOML file with a sweep file's mark (``scenario``, no ``schema_version``: sweeps.spec.is_sweep_file)."""
    import tomllib

    try:
        with open(path, "rb") as f:
            raw = tomllib.loads(f.read(1 << 20).decode("utf-8"))
    except (OSError, ValueError):
        return False
    return "schema_version" not in raw and "scenario" in raw


#: what each of bearingsim's own files that is not a run archive is, by its root ``format`` attribute less
#: its version (the sweep index and map, the studies' tables)
OWN_FILES = {"bearingsim sweep index": "a sweep's index", "bearingsim sweep map": "a sweep's map",
             "bearingsim crosscheck index": "a cross-check's table",
             "bearingsim sensitivity index": "a sensitivity study's table",
             "bearingsim uncertainty index": "an uncertainty study's table", "bearingsim life": "a life study's table"}
#: the studies' tables among them ('bearingsim plot' draws each study's figure from its table)
STUDY_TABLE_FORMATS = ("bearingsim crosscheck index", "bearingsim sensitivity index", "bearingsim uncertainty index",
                       "bearingsim life")


def _own_file_error(p: Path, fmt) -> UserError | None:
    """The one-line refusal of one of bearingsim's own files that is not a run archive (a sweep's
    ``sweep.h5`` or ``map.h5``, a study's table: root attribute ``format``) given where a run's archive
    is read, naming the commands that read it; None for any other file."""
    fmt = _plain(fmt) if fmt is not None else None
    if not isinstance(fmt, str) or not fmt.startswith("bearingsim "):
        return None
    kind = fmt.rstrip("0123456789. ")
    what = OWN_FILES.get(kind, f"a {kind} file")
    return UserError(f"{p}: {what} written by bearingsim, not a run archive; 'bearingsim inspect {p}' says what "
                     f"it holds, 'bearingsim table {p.parent}' prints its folder's table")


def own_file_target_error(p: Path) -> UserError | None:
    """The one-line refusal of one of bearingsim's own files that is not a run archive (a sweep's index or
    map, a study's table: :data:`OWN_FILES`) at a path a run's archive is to be written to, saying what it
    is (the output layer's "exists and is not a bearingsim archive" would call it a user's); None for any
    other file."""
    err = _own_file_error(Path(p), root_format(p))
    if err is None:
        return None
    return UserError(f"{str(err).split(';')[0]}; not replaced by a run's archive (choose another path)")


def own_table_error(p: Path, command: str = "table") -> UserError | None:
    """The one-line refusal of a CSV table a sweep or study wrote (``sweep.csv``, ``crosscheck.csv``, ...:
    :data:`bearingsim.outputs.FOLDER_FILES`, told by its name and first bytes) given where an archive is
    read, naming the command that reads its folder (``table``, or ``report``); None for any other file."""
    p = Path(p)
    head = outputs.FOLDER_FILES.get(p.name)
    if head is None or not p.name.endswith(".csv"):
        return None
    try:
        with open(p, "rb") as f:
            if f.read(len(head)) != head:
                return None
    except OSError:
        return None
    does = "reports on its folder" if command == "report" else "prints its folder's tables"
    return UserError(f"{p}: a table bearingsim wrote (CSV), not an archive; 'bearingsim {command} {p.parent}' {does}")


def open_archive(path: str | Path):
    """Open a complete bearingsim archive read-only, or raise a one-line :class:`UserError`."""
    h5py = _lazy_h5py()
    p = Path(path)
    if not p.exists():
        raise UserError(f"{p}: file not found")
    if p.is_dir():
        raise _directory_error(p)
    _check_regular(p)
    try:
        ok = h5py.is_hdf5(p)
    except OSError:
        ok = False
    if not ok:
        raise scenario_file_error(p) or own_table_error(p) or UserError(
            f"{p}: not an HDF5 file (truncated, or not a bearingsim archive)")
    try:
        f = h5py.File(p, "r")
    except OSError as exc:
        raise UserError(f"{p}: damaged or truncated file, HDF5 cannot open it ({exc})") from None
    kind = "HDF5 file"  # until its /bearingsim group is read: a damaged file of another kind is not called an archive
    try:
        g = f["bearingsim"] if "bearingsim" in f else None  # not f.get: it takes a damaged root group for none
        kind = "archive" if g is not None else kind
        if g is None or "format_version" not in g.attrs:
            raise _own_file_error(p, f.attrs.get("format")) or UserError(
                f"{p}: HDF5 file but not a bearingsim archive (no /bearingsim group)")
        complete = _plain(g.attrs.get("complete", False))
        if not isinstance(complete, bool):
            raise _damaged(p, f"/bearingsim@complete is {outputs.printable(repr(complete))[:40]}, not a boolean")
        if not complete:
            raise UserError(f"{p}: incomplete bearingsim archive (the run did not finish)")
        major = str(_plain(g.attrs["format_version"])).split(".")[0]
        if major not in READABLE_MAJORS:
            raise UserError(f"{p}: archive format {g.attrs['format_version']} not readable by this bearingsim")
    except UserError:
        f.close()
        raise
    except Exception as exc:  # damaged metadata
        f.close()
        raise _damaged(p, f"{exc.__class__.__name__}: {exc}", kind) from None
    return f


def unreadable_error(path) -> UserError | None:
    """The one-line error of a regular file at ``path`` that this process may not read ("cannot read
    (Permission denied)"), or that has HDF5's signature but whose root HDF5 cannot read (damaged or
    truncated); None for any other path (missing, a folder, a file that is not HDF5 or reads). What a
    command that picks its input by what a file holds says of one it cannot tell (``bearingsim report``)."""
    p = Path(path)
    try:
        if not p.is_file():
            return None
        _check_regular(p)
        if not _has_hdf5_signature(p):
            return None
        with _lazy_h5py().File(p, "r") as f, reading(p, "HDF5 file"):
            dict(f.attrs), list(f)
    except UserError as exc:
        return exc
    except OSError as exc:
        return UserError(f"{p}: damaged or truncated file, HDF5 cannot open it ({exc})")
    return None


def _notes_lines(notes: list[str] | None) -> list[str]:
    """The "notes:" part of :func:`describe`: each stored note on a line of its own, ``notes: none`` for a
    run without a note, and what an archive that stores no notes is."""
    if notes is None:
        return ["notes: not stored in this archive (no /bearingsim/notes; 'bearingsim report' checks the "
                "archive again)"]
    if not notes:
        return ["notes: none"]
    return ["notes:", *(f"  {n}" for n in run_notes(notes))]


def _error_lines(f, model) -> list[str]:
    """The "standard errors" line of :func:`describe`: the batch-means errors over the recorded rotations of the
    mean impulses, the first impact speed, the cage slip and the load zone's half angle
    (:func:`bearingsim.stats.summary_standard_errors`, as ``bearingsim table`` gives them), for a whole-bearing archive; none for the reduced model's, whose rotations repeat one
    pass, nor for per-rotation arrays that are not the ``[rotations, pockets]`` numbers of a result."""
    from bearingsim.stats import SEM_UNITS, SUMMARY_SEM_OF, summary_standard_errors

    per = read_sem_series(f) if _plain(model) != "reduced" else {}
    if "I_acc" not in per or not sem_series_ok({k: per.get(k) for k in ("I_dec", "I_acc")}):
        return []  # a damaged archive is still listed (``bearingsim.load`` names what is wrong with it)
    per = {k: a for k, a in per.items() if sem_series_ok({"I_dec": per["I_dec"], k: a})}  # and a damaged one left out
    se = summary_standard_errors(per, _plain(model))
    mean_of = {v: k for k, v in SUMMARY_SEM_OF.items()}
    text = ", ".join(f"{mean_of[k]} \u00b1 {v:.2g}" + ("" if SEM_UNITS[k] == "1" else f" {SEM_UNITS[k]}")
                     for k, v in se.items() if v == v)
    if not text:
        return ["standard errors: none (1 recorded rotation gives no scatter)"]
    return [f"standard errors (batch means over {len(per['I_dec'])} recorded rotations): {text}"]


def _attribute_group_lines(f) -> list[str]:
    """The numbers an archive stores as attributes of a group under ``/results`` other than the summary (the
    reduced model's operating point, pass and wear rates): the group, its description, and each number with
    its unit."""
    lines = []
    for name, grp in f["results"].items() if "results" in f else ():
        if name == "summary" or not hasattr(grp, "keys") or ATTRS_JSON not in grp.attrs:
            continue
        values, units = group_attrs(grp)
        said = _plain(grp.attrs["description"]) if "description" in grp.attrs else ""
        lines.append(f"/results/{name}:" + (f" {said}" if said else ""))
        lines += [_number_line(k, values[k], units.get(k, "")).rstrip() for k in sorted(values)]
    return lines


def _number_line(key: str, value, unit: str) -> str:
    """One stored number of ``describe``'s listing: its name, its value (floats to 6 digits) and its unit."""
    shown = f"{value:.6g}" if isinstance(value, (float, np.floating)) else str(value)
    return f"  {key:32s} {shown} {unit}"


def describe(path: str | Path) -> str:
    """Human-readable listing of an archive: header, provenance, summary, then every dataset."""
    f = open_archive(path)
    lines: list[str] = []
    try:
        g = f["bearingsim"]
        lines.append(f"{path}: bearingsim archive, format {g.attrs['format_version']}, model {g.attrs['model']}, "
                     f"scenario {g.attrs['scenario_name']!s}")
        if "provenance" in f:
            pv = group_attrs(f["provenance"])[0]
            keys = ["bearingsim_version", "git_commit", "created_utc", "wall_time_s"]
            lines.append("provenance: " + ", ".join(f"{k}={pv[k]}" for k in keys if k in pv))
            extra = [k for k in pv if k not in keys and not k.startswith("version_") and k not in ("platform", "command")]
            if extra:
                lines.append("run: " + ", ".join(f"{k}={pv[k]}" for k in extra))
        if "results/summary" in f:
            lines.append("summary:")
            sa, su = group_attrs(f["results/summary"])
            lines += [_number_line(k, sa[k], su.get(k, "")) for k in sorted(sa)]
            lines += _error_lines(f, g.attrs["model"])
        lines += _attribute_group_lines(f)
        lines += _notes_lines(read_notes(f, path))
        lines.append("datasets:")

        def visit(name, obj):
            if hasattr(obj, "shape") and name not in ("scenario", NOTES):
                unit = obj.attrs.get("unit", "")
                lines.append(f"  /{name:52s} {str(obj.shape):14s} {obj.dtype!s:8s} {unit}")

        f.visititems(visit)
    except (KeyError, TypeError, ValueError) as exc:  # attributes missing or malformed
        raise UserError(f"{path}: damaged archive (missing or malformed attribute {exc})") from None
    except (RuntimeError, OSError) as exc:  # a B-tree or heap damaged (h5py's errors: :data:`H5_ERRORS`)
        raise _damaged(path, f"{exc.__class__.__name__}: {exc}") from None
    finally:
        f.close()
    return outputs.printable("\n".join(lines))  # attributes may carry terminal escape sequences
