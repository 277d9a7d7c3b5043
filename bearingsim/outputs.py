"""Output-path policy: where a run may write, and who may write there at once.

Rules, each a one-line :class:`bearingsim.errors.UserError` (exit 2) before any work:

* a default output name (``outputs/<name>.h5``) never leaves the output folder;
* an archive path ends in ``.h5`` / ``.hdf5`` (so ``-o my.toml`` or ``-o notes.txt`` is refused);
* the target is never the input scenario file;
* an existing target that is not a bearingsim archive is not replaced, nor a symbolic link at the
  archive path, whatever it points to (a link is the user's, as at a figure path);
* every PNG, GIF and MP4 bearingsim writes carries its mark (:data:`MARK`: a PNG's ``Software`` text,
  a GIF's comment, an MP4's comment tag), and only a file with the mark is replaced: a figure path of the
  run (``<stem>_<name>.png``) that is a symbolic link, a directory or a file without the mark (a user's
  picture) is refused before the run (:func:`check_replaceable`); figures, tables and archives are written
  to a temporary name and renamed over the target (:func:`atomic_file`), never through a link;
* once a run's archive is written, the figures at its stem of any model that the run does not draw
  (:func:`remove_figures`: only regular PNG files so named that carry the mark) are removed, being the
  replaced archive's;
* one writer per target: an exclusive ``fcntl`` lock on ``.<name>.lock`` beside the target (an empty
  regular file, opened with ``O_NOFOLLOW``: a link or a user's file there is refused), held from
  the start of the run until its archive and figures are written, then removed; a second run to the
  same target is refused, not interleaved (a run killed by SIGKILL leaves the empty lock file, which
  the next run takes over: the lock dies with its process);
* temporary archives ``.<name>.tmp-<pid>`` whose process is gone (a run killed by SIGKILL or a power
  cut; a killed process not yet reaped, a zombie, counts as gone) are removed on the next run into that
  folder, whichever model it runs, with a note on stderr.
"""
from __future__ import annotations

import contextlib
import errno
import fcntl
import functools
import logging
import os
import re
import stat
import sys
from pathlib import Path

from bearingsim.errors import UserError

ARCHIVE_SUFFIXES = (".h5", ".hdf5")
# ArchiveWriter's temporary name, ".<name>.h5.tmp-<pid>"; only such files that are empty or start with
# the HDF5 signature are removed, so another program's temporary file is never touched.
_TMP_RE = re.compile(r"^\..+\.(?:h5|hdf5)\.tmp-(\d+)$")
_FOLDER_TMP_RE = re.compile(r"^\.(.+)\.tmp-(\d+)$")  # the temporary of any file: (its name, the pid)
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def default_output(name: str, root: str | Path = "outputs") -> Path:
    """``root/<name>.h5``, refusing a name that would resolve outside ``root``.

    Parameters
    ----------
    name : scenario name (already checked by the scenario schema to be a plain file name)
    root : output folder
    """
    root = Path(root)
    out = root / f"{name}.h5"
    if out.resolve().parent != root.resolve():
        raise UserError(f"name: {name!r} is not a plain file name (it would write outside {root}/)")
    return out


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def temporary_name(path: Path) -> Path:
    """The name a file is written under before its rename to ``path`` (hidden, with this process's id,
    so that :func:`clean_stale_temporaries` can tell a dead writer's from a live one's)."""
    return path.with_name(f".{path.name}.tmp-{os.getpid()}")


def discard_temporary(tmp: Path) -> None:
    """Remove the temporary file ``tmp`` if it is there. Its folder removed, or replaced by a file, while it was
    written (a sweep's ``cases/``) means it is not: that ``NotADirectoryError`` was raised over the write's own
    error and recorded raw as a sweep case's failure."""
    with contextlib.suppress(FileNotFoundError, NotADirectoryError):
        os.unlink(tmp)


def create_new(path: Path, readable: bool = False) -> int:
    """Open ``path`` for writing (and reading, with ``readable``) as a new file, never through a symbolic
    link (``O_EXCL|O_NOFOLLOW``); a leftover of this process's id (a symbolic link planted there included)
    is removed first."""
    flags = ((os.O_RDWR if readable else os.O_WRONLY) | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
             | getattr(os, "O_CLOEXEC", 0))
    try:
        return os.open(path, flags, 0o644)
    except FileExistsError:
        os.unlink(path)  # removes a link itself, never its target
        return os.open(path, flags, 0o644)


@contextlib.contextmanager
def atomic_file(path: str | Path):
    """``with atomic_file(path) as fh: fh.write(...)``: the one way bearingsim writes a whole file.

    The data goes to a new temporary file in the same folder (:func:`temporary_name`), which replaces
    ``path`` by ``os.replace`` only when the block ends without an error: a reader never sees a partial
    file, and a symbolic link at ``path`` is replaced, never written through. On any error (a signal
    included) the temporary file is removed and ``path`` is untouched; an ``OSError`` of the temporary
    file (a full disk) is raised as one of ``path`` (its ``filename``).
    """
    path = Path(path)
    tmp = temporary_name(path)
    try:
        fd = create_new(tmp)
    except OSError as exc:
        raise _naming(exc, path) from None
    renaming = False
    try:
        with os.fdopen(fd, "wb") as fh:
            yield fh
        renaming = True
        os.replace(tmp, path)
        note_written(path)
    except BaseException as exc:
        if renaming and not os.path.lexists(tmp):  # renamed, then a signal's exception: the file is complete
            note_written(path)
            raise
        discard_temporary(tmp)
        if isinstance(exc, OSError) and exc.errno is not None and (
                exc.filename is None or str(exc.filename) == str(tmp)):  # a write, or the rename, of the temporary
            raise _naming(exc, path) from None
        raise


def _naming(exc: OSError, path: Path) -> OSError:
    """``exc`` (a write to the temporary file, its creation or its rename) as the same error of ``path``, the
    file the user asked for: a full disk while a sweep's index is written names ``sweep.csv``, never the
    temporary name nor, with no name at all, standard output (:func:`bearingsim.cli.main`)."""
    return OSError(exc.errno, exc.strerror or os.strerror(exc.errno), str(path))


#: while the command line records them (:func:`recording_files`): the files written so far, renamed into place
#: complete (absolute path -> the path as given), what an interrupted command says it leaves
_recorded: dict[str, str] | None = None


@contextlib.contextmanager
def recording_files(ledger: dict[str, str]):
    """Within it, every file bearingsim writes whole (:func:`atomic_file`, an archive's rename) is noted in
    ``ledger`` once it is complete, also when a signal's exception comes right after its rename (the
    command line: ``bearingsim: interrupted once its files were written ...``). Called by the command line
    only; a library call records nothing."""
    global _recorded
    previous, _recorded = _recorded, ledger
    try:
        yield ledger
    finally:
        _recorded = previous


def note_written(path) -> None:
    """Note ``path`` as complete where files are recorded (:func:`recording_files`); else nothing."""
    if _recorded is not None:
        _recorded.setdefault(os.path.abspath(path), str(path))


def write_atomic_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through :func:`atomic_file` (never a partial file)."""
    with atomic_file(path) as fh:
        fh.write(data)


def csv_bytes(header, rows) -> bytes:
    """A CSV table (``header``, then ``rows`` of already formatted cells) as UTF-8 bytes, in the one dialect
    of every table bearingsim writes: Python's csv default, RFC 4180 (``\r\n`` line ends), as ``sweep.csv``."""
    import csv
    import io

    buf = io.StringIO(newline="")
    w = csv.writer(buf)
    w.writerow(header)
    w.writerows(rows)
    return buf.getvalue().encode("utf-8")


def write_csv(path: str | Path, header, rows) -> Path:
    """Write a CSV table (:func:`csv_bytes`) through :func:`atomic_file`, so a reader never sees half a
    table; return the path."""
    path = Path(path)
    write_atomic_bytes(path, csv_bytes(header, rows))
    return path


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: the mark of every PNG, GIF and MP4 bearingsim writes (no time, no host: the same figure is the same bytes):
#: a PNG's ``Software`` text chunk (:data:`PNG_METADATA`), a GIF's comment, an MP4's ``comment`` tag. Only a
#: file that carries it is replaced or removed (:func:`is_own_png`, :func:`is_own_gif`, :func:`is_own_mp4`).
MARK = "bearingsim"
#: what ``savefig(metadata=...)`` writes into every PNG bearingsim draws
PNG_METADATA = {"Software": MARK}
_MARK_BYTES = MARK.encode("ascii")
#: the MP4 atom ffmpeg writes for ``-metadata comment=MARK`` (``moov/udta/meta/ilst/\xa9cmt``, its ``data``: UTF-8)
_MP4_COMMENT = ((24 + len(_MARK_BYTES)).to_bytes(4, "big") + b"\xa9cmt" + (16 + len(_MARK_BYTES)).to_bytes(4, "big")
                + b"data" + b"\x00\x00\x00\x01" + b"\x00\x00\x00\x00" + _MARK_BYTES)
#: most bytes of an MP4's ``moov`` box read to find the mark (a long animation's is well under 1 MB)
_MAX_MOOV = 64 << 20


def _open_regular(path):
    """``path`` opened for reading, never through a symbolic link nor blocking on a FIFO."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    return open(fd, "rb")


def is_own_png(path) -> bool:
    """True when ``path`` is a PNG file bearingsim drew: a ``tEXt`` chunk ``Software`` = :data:`MARK` before
    its image data. False for any other file, or one that cannot be read."""
    try:
        with _open_regular(path) as fh:
            if fh.read(8) != PNG_SIGNATURE:
                return False
            while True:
                head = fh.read(8)
                if len(head) < 8 or head[4:] in (b"IDAT", b"IEND"):
                    return False
                size = int.from_bytes(head[:4], "big")
                if head[4:] == b"tEXt" and size == len(b"Software\x00") + len(_MARK_BYTES):
                    if fh.read(size) == b"Software\x00" + _MARK_BYTES:
                        return True
                    fh.seek(4, os.SEEK_CUR)
                else:
                    fh.seek(size + 4, os.SEEK_CUR)
    except OSError:
        return False


def is_own_gif(path) -> bool:
    """True when ``path`` is a GIF file bearingsim wrote: a comment extension :data:`MARK` before its first
    image. False for any other file, or one that cannot be read."""
    try:
        with _open_regular(path) as fh:
            head = fh.read(13)
            if len(head) < 13 or head[:4] != b"GIF8":
                return False
            if head[10] & 0x80:  # the global colour table
                fh.seek(3 << ((head[10] & 7) + 1), os.SEEK_CUR)
            while (block := fh.read(2))[:1] == b"\x21":  # extensions, up to the first image (0x2c)
                data = b""
                while size := fh.read(1):
                    if size == b"\x00":
                        break
                    data += fh.read(size[0])
                if block[1:] == b"\xfe" and data == _MARK_BYTES:
                    return True
            return False
    except (OSError, IndexError):
        return False


def is_own_mp4(path) -> bool:
    """True when ``path`` is an MP4 file bearingsim wrote: it starts with an ``ftyp`` box and its ``moov`` box
    holds the comment :data:`MARK`. False for any other file, or one that cannot be read."""
    try:
        with _open_regular(path) as fh:
            first = True
            while len(head := fh.read(8)) == 8:
                size, kind = int.from_bytes(head[:4], "big"), head[4:]
                if first and kind != b"ftyp":
                    return False
                first = False
                body = 8
                if size == 1:  # a 64-bit size follows
                    size, body = int.from_bytes(fh.read(8), "big"), 16
                if kind == b"moov":
                    return size <= _MAX_MOOV and _MP4_COMMENT in fh.read(size - body)
                if size < body:  # 0: to the end of the file; or not an MP4
                    return False
                fh.seek(size - body, os.SEEK_CUR)
            return False
    except OSError:
        return False


def check_replaceable(path: str | Path, signature, what: str) -> Path:
    """Refuse (one-line :class:`UserError`) to replace ``path`` unless it is absent or a regular file
    bearingsim wrote there (a PNG with its :data:`MARK` for a figure, its own index for ``sweep.csv``). A
    symbolic link, a directory, a FIFO or any other file (a user's picture, a figure without the mark) is
    the user's: not replaced, not followed. Returns ``path``.

    Parameters
    ----------
    path : file bearingsim is about to write
    signature : bytes the files it writes there start with, or ``signature(path) -> bool`` for a
        regular file (:func:`is_own_png`, :func:`is_own_gif`, :func:`is_own_mp4`, or e.g.
        :func:`bearingsim.archive.is_table_file` of the right format)
    what : what the file is, for the message ("figure", "sweep index")
    """
    p = Path(path)
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        return p
    except OSError as exc:
        raise UserError(f"{p}: cannot check the {what} path ({exc.strerror or exc})") from None
    if stat.S_ISLNK(st.st_mode):
        kind = "a symbolic link"
    elif stat.S_ISDIR(st.st_mode):
        kind = "a directory"
    elif not stat.S_ISREG(st.st_mode):
        kind = "not a regular file"
    else:
        try:
            with _open_regular(p) as fh:
                head = b"" if callable(signature) else fh.read(len(signature))
        except OSError as exc:
            raise UserError(f"{p}: cannot read the existing {what} ({exc.strerror or exc}); not replaced") from None
        if signature(p) if callable(signature) else head == signature:
            return p
        kind = "a file not written by bearingsim"
        if signature in (is_own_png, is_own_gif, is_own_mp4):  # files of a bearingsim before the mark have none
            kind = "a file without bearingsim's mark (not written by it, or by a version before its files carried it)"
    raise UserError(f"{p}: {what} path is {kind}; not replaced (remove it or choose another path)")


def check_target(path: str | Path, inputs: list[str | Path] = (), is_archive=None, figures: bool = True,
                 own_file_error=None) -> Path:
    """Check that a run may write its archive at ``path`` (rules in the module docstring).

    Parameters
    ----------
    path : archive path
    inputs : files the run reads (the scenario file); the target may not be one of them
    is_archive : ``is_archive(path) -> bool``, what may be replaced (:func:`bearingsim.archive.is_archive`);
        None: the file signature of HDF5
    figures : names of the figures the run also writes beside the archive (``<stem>_<name>.png``): each
        must be absent or a figure bearingsim drew (:func:`check_replaceable`, :func:`is_own_png`); True: only
        check that no ``<stem>_*.png`` is a folder; False or empty: no figures
    own_file_error : ``own_file_error(path) -> UserError | None``, the refusal of a file bearingsim wrote that is
        not an archive (:func:`bearingsim.archive.own_file_target_error`: a sweep's index, named as one); None:
        any file that is not an archive is refused as not one

    Returns
    -------
    Path
        ``path`` as a :class:`~pathlib.Path`.
    """
    p = Path(path)
    if "\x00" in str(p):
        raise UserError(f"{str(p)!r}: output path contains a NUL byte")
    if p.is_symlink():  # the user's, as a linked figure is (check_replaceable): neither replaced nor followed
        raise UserError(f"{p}: archive path is a symbolic link; not replaced (remove it or choose another path)")
    for src in inputs:
        if src and _same_file(p, Path(src)):
            raise UserError(f"{p}: output path is the input scenario file; choose another -o")
    check_folder_can_be_made(p, "archive")  # a file where the archive's folder should be
    if p.is_dir():
        raise UserError(f"{p}: output path is a directory")
    if p.suffix.lower() not in ARCHIVE_SUFFIXES:
        raise UserError(f"{p}: archive path must end in .h5 or .hdf5 (got {p.suffix or 'no suffix'!r})")
    if is_archive is None:
        def is_archive(q):
            with open(q, "rb") as fh:
                return fh.read(8) == _HDF5_SIGNATURE
    if p.exists() and not is_archive(p):
        raise (own_file_error(p) if own_file_error else None) or UserError(
            f"{p}: exists and is not a bearingsim archive; not replaced (remove it or choose another path)")
    stem = p.with_suffix("")
    if figures is True and p.parent.is_dir():
        for fig in p.parent.glob(f"{_glob_escape(stem.name)}_*.png"):
            if fig.is_dir():
                raise UserError(f"{fig}: figure path is a directory")
    elif figures:
        for name in figures:
            check_replaceable(figure_path(stem, name), is_own_png, "figure")
    return p


def check_folder_path(folder: str | Path, what: str = "output folder") -> Path:
    """Refuse (one-line :class:`UserError`) a ``folder`` to write into that, or the nearest of its
    parents that exists, is not a folder (a file in the way): it could never be made. Every command
    that writes into a folder says it in these words, ``{folder}: cannot create the {what} ({file} is
    not a folder)``, or ``(it is a file)`` when ``folder`` itself is the file in the way. Nothing is
    created here; ``what`` names the folder ("output folder", "report's folder"). Returns ``folder`` as a
    :class:`~pathlib.Path`."""
    folder = Path(folder)
    existing = next((p for p in (folder, *folder.parents) if p.exists()), None)
    if existing is not None and not existing.is_dir():
        if existing != folder:
            raise UserError(f"{folder}: cannot create the {what} ({existing} is not a folder)")
        kind = "a file" if existing.is_file() else "not a folder"
        raise UserError(f"{folder}: cannot create the {what} (it is {kind})")
    return folder


def check_folder_can_be_made(out: Path, what: str) -> None:
    """Refuse (one-line :class:`UserError`, :func:`check_folder_path`) an output file ``out`` whose
    folder, or the nearest of its parents that exists, is not a folder (a file in the way). Nothing is
    created here; ``what`` names the output ("report", "animation", "archive")."""
    check_folder_path(Path(out).parent, f"{what}'s folder")


#: every file a sweep or a study writes into its folder beside ``cases/`` (the sweep's index, map and figures;
#: each study's table and figures: tests/test_studies.py checks that every study's outputs are listed), with
#: the first bytes bearingsim writes it with (a CSV's header, a PNG's or HDF5's signature; a PNG also carries
#: :data:`MARK`): what ``--force`` removes of another sweep or study in the folder (:func:`remove_folder_files`)
FOLDER_FILES = {
    "sweep.csv": b"case,", "sweep.h5": _HDF5_SIGNATURE, "map.h5": _HDF5_SIGNATURE,
    "sweep_I.png": PNG_SIGNATURE, "sweep_map.png": PNG_SIGNATURE, "sweep_cases.png": PNG_SIGNATURE,
    "crosscheck.csv": b"rpm,rung,", "crosscheck.h5": _HDF5_SIGNATURE, "crosscheck.png": PNG_SIGNATURE,
    "fig9_idec_vs_speed.csv": b"speed_rpm,", "fig9_idec_vs_speed.png": PNG_SIGNATURE,
    "rig_idec_vs_speed.csv": b"rpm,rotations,", "rig_idec_vs_speed.png": PNG_SIGNATURE,
    "rig_pocket0_forces.png": PNG_SIGNATURE,
    "sensitivity.csv": b"key,quantity,", "sensitivity.h5": _HDF5_SIGNATURE, "sensitivity.png": PNG_SIGNATURE,
    "uncertainty.csv": b"quantity,key,", "uncertainty_spread.csv": b"quantity,median,",
    "uncertainty.h5": _HDF5_SIGNATURE, "uncertainty.png": PNG_SIGNATURE,
    "life.h5": _HDF5_SIGNATURE, "life.png": PNG_SIGNATURE,
}


def remove_folder_files(folder: str | Path) -> list[Path]:
    """Remove from ``folder`` the files a sweep or study writes there (:data:`FOLDER_FILES`) that start as
    bearingsim writes them, a figure only with its :data:`MARK` (never a link, a folder, a user's picture or
    a file of another content): what ``--force`` does to the sweep or study it replaces, so that no table or
    figure of it is left to be read as the new one's. Returns the files removed."""
    return [Path(folder) / name for name, head in FOLDER_FILES.items()
            if _remove_if_own(Path(folder) / name, is_own_png if head == PNG_SIGNATURE else head)]


def no_file_in(folder: str | Path, exc: OSError) -> str:
    """``no file can be created in FOLDER (why)``: what a refusal says of a folder that exists but takes no new
    file (no permission, a read-only file system, /proc), the OS's reason in brackets. (It said "output is not
    writable (No such file or directory)", which read as if the output had to exist.)"""
    return f"no file can be created in {folder} ({exc.strerror or exc})"


def cannot_write_archive(path: str | Path, exc: OSError) -> UserError:
    """The one line for an archive ``path`` whose folder exists but takes no new file (:func:`no_file_in`), the
    same from ``Result.save``, ``bearingsim run -o`` and its ``--dry-run``."""
    return UserError(f"{path}: cannot write archive: {no_file_in(Path(path).parent, exc)}")


def cannot_create_folder(path: str | Path, exc: OSError) -> UserError:
    """The one line for an archive ``path`` whose missing folder cannot be made (``Result.save``, ``bearingsim
    run -o`` and its ``--dry-run`` alike)."""
    return UserError(f"{path}: cannot create output folder ({exc.strerror or exc})")


def check_writable(path: str | Path) -> None:
    """Refuse, in the line a run would give (:meth:`OutputLock.acquire`), an output ``path`` whose folder
    could not be made or would take no new file, without writing anything: the nearest folder of it that
    exists is probed with an unnamed temporary file, gone when closed (``run --dry-run``)."""
    import tempfile

    path = Path(path)
    existing = next((p for p in (path.parent, *path.parent.parents) if p.exists()), None)
    if existing is None:
        return
    try:
        if not existing.is_dir():
            raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR))
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as exc:
        raise (cannot_write_archive(path, exc) if existing == path.parent
               else cannot_create_folder(path, exc)) from None


def missing_folders(folder: Path) -> list[Path]:
    """``folder`` and those of its parents that do not exist yet, deepest first."""
    missing = []
    for p in (folder, *folder.parents):
        if p.exists() or p.is_symlink():
            break
        missing.append(p)
    return missing


def remove_empty(folders: list[Path]) -> None:
    """Remove ``folders`` (deepest first) while they are empty: never a file, never a folder someone
    has put something into meanwhile."""
    for p in folders:
        try:
            os.rmdir(p)
        except OSError:
            return


def figure_path(stem: str | Path, name: str) -> Path:
    """Where a run's figure ``name`` goes: ``<stem>_<name>.png``."""
    return Path(f"{stem}_{name}.png")


def remove_figures(stem: str | Path, names) -> list[Path]:
    """Remove the figures ``<stem>_<name>.png`` of ``names`` that are regular PNG files with bearingsim's
    :data:`MARK` (what :func:`check_replaceable` would let bearingsim replace); a link, a folder or any
    other file (a user's picture) is left alone, and so is a file that cannot be removed. Returns the paths
    removed."""
    paths = [figure_path(stem, name) for name in names]
    return [p for p in paths if _remove_if_own(p, is_own_png)]


def _remove_if_own(path: Path, own) -> bool:
    """Remove ``path`` if it is a regular file (not a link: never followed) as bearingsim writes it: its
    first bytes are ``own`` (bytes), or ``own(path)`` is true (:func:`is_own_png`); anything else, or a
    file that cannot be removed, is left. True if removed."""
    try:
        if not stat.S_ISREG(os.lstat(path).st_mode):
            return False
        with _open_regular(path) as fh:
            if not (own(path) if callable(own) else fh.read(len(own)) == own):
                return False
        path.unlink()
    except OSError:
        return False
    return True


def _glob_escape(s: str) -> str:
    return re.sub(r"([*?\[])", r"[\1]", s)


def _pid_alive(pid: int) -> bool:
    """True while process ``pid`` may still write: it exists and is neither a zombie nor being killed.

    ``kill(pid, 0)`` alone counts a process that SIGKILL ended but no parent has reaped yet (a zombie),
    or whose SIGKILL is still being delivered, as alive; a run killed by ``timeout -s KILL`` (which kills
    its own process group, itself included) stays a zombie of the init process for a while after its
    parent is gone, and the next run into its folder, however soon it comes, takes it as dead (Linux:
    ``/proc/<pid>/status``, :func:`dying`; elsewhere ``kill`` alone)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive unless dying
        pass
    try:
        with open(f"/proc/{pid}/status", encoding="ascii", errors="replace") as fh:
            status = fh.read()
    except OSError:  # no /proc (not Linux): kill's answer; else the process has just gone, or is unreadable
        return not Path("/proc/self/status").exists() or Path(f"/proc/{pid}").exists()
    return not dying(status)


def dying(status: str) -> bool:
    """True when the text of ``/proc/<pid>/status`` is that of a process that will never run again: a
    zombie or dead (``State: Z`` / ``X``), or one with SIGKILL pending (``ShdPnd`` or ``SigPnd``)."""
    import signal

    fields = dict(line.split(":", 1) for line in status.splitlines() if ":" in line)
    if fields.get("State", "").strip()[:1] in ("Z", "X"):
        return True
    kill_bit = 1 << (signal.SIGKILL - 1)
    for name in ("ShdPnd", "SigPnd"):
        try:
            if int(fields.get(name, "0").strip(), 16) & kill_bit:
                return True
        except ValueError:
            continue
    return False


def clean_stale_temporaries(folder: str | Path, report=None, names: dict[str, bytes] | None = None) -> list[Path]:
    """Remove ``.<name>.tmp-<pid>`` files in ``folder`` whose process no longer exists.

    Parameters
    ----------
    folder : output folder
    report : callable taking one line (default: a note of the ``bearingsim.outputs`` logger, which the
        command line prints on stderr)
    names : the files whose temporaries to remove, each with the first bytes bearingsim writes it with
        (a sweep's or a study's :data:`FOLDER_FILES`); default: any archive (``.h5``, ``.hdf5``, HDF5's
        signature). A temporary that is not empty and does not start so is not bearingsim's: kept.

    Returns
    -------
    list of Path
        The files removed.
    """
    folder = Path(folder)
    report = report or logging.getLogger(__name__).info
    removed = []
    if not folder.is_dir():
        return removed
    for entry in folder.iterdir():
        m = _TMP_RE.match(entry.name) if names is None else _FOLDER_TMP_RE.match(entry.name)
        if not m or not entry.is_file() or (names is not None and (m.group(1) not in names or entry.is_symlink())):
            continue
        pid = int(m.group(m.lastindex))
        if pid == os.getpid() or _pid_alive(pid):
            continue
        head_wanted = _HDF5_SIGNATURE if names is None else names[m.group(1)]
        try:
            with open(entry, "rb") as fh:
                head = fh.read(len(head_wanted))
        except OSError:
            continue
        if head and head != head_wanted:
            continue
        try:
            entry.unlink()
        except OSError as exc:
            report(f"bearingsim: note: stale temporary file {entry} of a dead run (pid {pid}) "
                   f"could not be removed ({exc.strerror})")
            continue
        removed.append(entry)
        report(f"bearingsim: note: removed stale temporary file {entry} of a dead run (pid {pid})")
    return removed


def open_lock_file(lock_path: str | Path, guarded: str | Path, unwritable="no file can be created in it") -> int:
    """Open (creating it if needed) the lock file ``lock_path`` for ``flock``; return its descriptor.

    Never through a symbolic link (``O_NOFOLLOW``: a planted ``.sweep.lock -> ~/notes`` neither truncates
    nor creates its target) and never a file bearingsim did not make: a lock file is an empty regular
    file, anything else there is refused with one line naming it (``guarded``: what the lock protects;
    ``unwritable``: what its line says, after ``guarded: ``, of a folder that takes no file, the OS's reason
    after it in brackets; or a function of the ``OSError`` giving the exception to raise).
    """
    lock_path = Path(lock_path)
    flags = (os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
             | getattr(os, "O_NONBLOCK", 0))
    try:
        fd = os.open(lock_path, flags, 0o644)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise UserError(f"{lock_path}: lock file of {guarded} is a symbolic link; not followed "
                            "(remove it)") from None
        if exc.errno == errno.EISDIR:  # a folder there: said as the lock file's, not as an unwritable folder
            raise UserError(f"{lock_path}: lock file of {guarded} is a folder, not bearingsim's; not replaced "
                            "(remove it)") from None
        if callable(unwritable):
            raise unwritable(exc) from None
        raise UserError(f"{guarded}: {unwritable} ({exc.strerror or exc})") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode) or st.st_size > 0:
        os.close(fd)
        kind = "not a regular file" if not stat.S_ISREG(st.st_mode) else "not empty"
        raise UserError(f"{lock_path}: lock file of {guarded} is {kind}, not bearingsim's; not replaced (remove it)")
    return fd


class FolderLock:
    """One writer per folder of many outputs (a sweep's or a study's): an exclusive, non-blocking
    ``fcntl.flock`` on ``DIR/.sweep.lock`` (:func:`open_lock_file`: never a link, never a user's file).

    The lock file stays (it is empty); the lock itself dies with its process. A second writer, in this
    process or another, is refused with one line. Held across a whole study (its cases and then its
    table and figures), it is passed to :func:`bearingsim.sweeps.run_sweep` as ``lock=``.

    Parameters
    ----------
    folder : the folder the lock guards (must exist)
    """

    NAME = ".sweep.lock"

    def __init__(self, folder: str | Path):
        self.path = Path(folder) / self.NAME
        self.fh: int | None = None

    def acquire(self) -> "FolderLock":
        if self.fh is not None:  # already held by this object
            return self
        fd = open_lock_file(self.path, self.path.parent)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            raise UserError(f"{self.path.parent}: another sweep or study is writing this folder") from None
        self.fh = fd
        return self

    def release(self) -> None:
        if self.fh is not None:
            os.close(self.fh)
            self.fh = None

    @property
    def held(self) -> bool:
        return self.fh is not None

    def __enter__(self) -> "FolderLock":
        return self.acquire()

    def __exit__(self, *exc) -> bool:
        self.release()
        return False


class OutputLock:
    """Exclusive, non-blocking ``fcntl.flock`` on ``.<name>.lock`` beside an archive path.

    Released when the process exits, however it exits, so a killed run never leaves a held lock.

    Parameters
    ----------
    path : archive path the lock guards
    what : what is written there, as the refusal of a second writer names it
    """

    def __init__(self, path: str | Path, what: str = "archive"):
        p = Path(path)
        self.path, self.what = p, what
        # an archive's folder that takes no file: cannot_write_archive's line, as Result.save gives it
        self.unwritable = (functools.partial(cannot_write_archive, p) if what == "archive"
                           else f"cannot write the {what}")
        self.lock_path = p.with_name(f".{p.name}.lock")
        self._fd: int | None = None

    def acquire(self) -> "OutputLock":
        for _ in range(10):  # the holder may unlink the lock file between our open and flock: retry
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                if callable(self.unwritable):
                    raise cannot_create_folder(self.path, exc) from None
                raise UserError(f"{self.path}: {self.unwritable} ({exc.strerror or exc})") from None
            fd = open_lock_file(self.lock_path, self.path, self.unwritable)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    raise UserError(f"{self.path}: another bearingsim {'run' if self.what == 'archive' else 'command'} "
                                    f"is writing this {self.what} "
                                    f"(lock {self.lock_path.name} is held); wait for it or choose another -o") from None
                raise UserError(f"{self.path}: cannot lock output ({exc.strerror or exc})") from None
            try:
                same = os.stat(self.lock_path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                self._fd = fd
                return self
            os.close(fd)
        raise UserError(f"{self.path}: cannot lock output (lock file keeps changing)")

    def release(self) -> None:
        """Remove the lock file, then unlock: nothing is left beside the archive."""
        if self._fd is not None:
            try:
                self.lock_path.unlink()
            except OSError:
                pass
            fcntl.flock(self._fd, fcntl.LOCK_UN)
            os.close(self._fd)
            self._fd = None

    def __enter__(self) -> "OutputLock":
        return self.acquire()

    def __exit__(self, *exc) -> bool:
        self.release()
        return False


@contextlib.contextmanager
def exclusive_output(path: str | Path, what: str):
    """The block is the one writer of the file ``path`` (a ``what``: "report", "animation"): :class:`OutputLock`
    held on it, so that a second command writing the same file is refused in one line rather than replacing
    the first one's file unseen; the folders made for it are removed again if they are left empty."""
    path = Path(path)
    made = missing_folders(path.parent)
    try:
        with OutputLock(path, what):
            yield path
    finally:
        remove_empty(made)


#: True only while :func:`bearingsim.cli.main` runs a command (:func:`command_line_owns_stderr`): then
#: :func:`quiet_stderr` may point file descriptor 2 at /dev/null around HDF5 writes. A library call never
#: touches the process's file descriptors: they belong to the program that imported bearingsim.
_command_line_owns_stderr = False


@contextlib.contextmanager
def command_line_owns_stderr():
    """The block is the ``bearingsim`` command: :func:`quiet_stderr` may redirect file descriptor 2."""
    global _command_line_owns_stderr
    previous, _command_line_owns_stderr = _command_line_owns_stderr, True
    try:
        yield
    finally:
        _command_line_owns_stderr = previous


@contextlib.contextmanager
def quiet_stderr():
    """Under the command line only (:func:`command_line_owns_stderr`), send file descriptor 2 to
    /dev/null for the block: around the close of a spool's HDF5 file (:func:`close_quietly`), which
    sees no failed write (a full disk is kept from HDF5: :class:`bearingsim.archive.Spool`) but would
    print its error stack there for anything else that failed while a signal or an error is already on
    its way. Called from a library, it does nothing."""
    if not _command_line_owns_stderr:
        yield
        return
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError):  # no stderr to quieten (closed)
        yield
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    os.close(devnull)
    try:
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def close_quietly(f) -> None:
    """Close an h5py file inside :func:`quiet_stderr`."""
    with quiet_stderr():
        f.close()


class ArchiveWriteError(UserError):
    """The archive could not be written (full disk, I/O error); the temporary file is already removed
    and HDF5 has closed its file cleanly (the in-memory archive of :func:`bearingsim.archive.to_bytes` is
    written with plain writes; a spool's file keeps its failed writes from HDF5): the process goes on, or
    exits, as after any other :class:`UserError` (exit 2)."""


def write_error(path: str | Path, exc: OSError) -> ArchiveWriteError:
    """A one-line :class:`ArchiveWriteError` for an OS error while writing ``path``."""
    code = getattr(exc, "errno", None)
    if code is None or f"errno = {code}," not in str(exc):  # h5py puts the real errno in its message
        for c in (errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG, errno.EROFS):
            if f"errno = {c}," in str(exc):
                code = c
                break
    what = os.strerror(code) if code else "write failed"
    if code in (errno.EISDIR, errno.ENOTDIR, errno.ENOENT):
        what = _in_the_way(Path(path)) or what
    return ArchiveWriteError(f"{path}: cannot write archive ({what}); nothing was written")


def _in_the_way(path: Path) -> str | None:
    """What stands where the archive ``path`` or its folder should be, once it was checked (a folder made at
    its name, its folder replaced by a file or removed while the run wrote it), or None."""
    if path.is_dir() and not path.is_symlink():
        return "a folder is in the way there, not bearingsim's: remove it"
    folder = path.parent
    if folder.is_dir():
        return None
    if os.path.lexists(folder):
        return f"its folder {folder} is a file now, not a folder"
    return f"its folder {folder} is gone"


_CONTROL_RE = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def printable(text: str, keep_newlines: bool = True) -> str:
    """``text`` with control characters (terminal escape sequences included) shown as ``\\xNN``.

    Parameters
    ----------
    text : text read from a file or given by a user
    keep_newlines : keep ``\\n`` (multi-line listings); otherwise it is escaped too (one-line errors)
    """
    text = str(text)
    if not keep_newlines:
        text = text.replace("\n", "\\n")
    return _CONTROL_RE.sub(lambda m: f"\\x{ord(m.group()):02x}", text)
