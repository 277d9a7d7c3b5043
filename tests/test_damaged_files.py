"""Damaged, truncated and unreadable files: every reader of an archive or of a sweep's or study's table says
what is wrong in one line naming the file (a :class:`bearingsim.UserError`, exit 2), never a traceback of
h5py's errors, nor "cannot write to standard output" of an error reading a file.

A file is damaged as a disk or a copy damages it: bytes overwritten with seeded random ones, starting at an
HDF5 structure's signature (a B-tree ``TREE``, a local heap ``HEAP``, a symbol table node ``SNOD``, a global
heap collection ``GCOL``); each test checks that h5py itself fails on the file so damaged."""
from __future__ import annotations

import re
import shutil

import h5py
import numpy as np
import pytest

import bearingsim
from bearingsim import archive

from .conftest import SCENARIOS
from .test_cli import ARCHIVE_READERS, assert_user_error, bearingsim as cli
from .test_index_files import _sweep_index

STRUCTURES = rb"TREE|HEAP|SNOD"  # B-trees, local heaps and symbol table nodes: the groups' structure


def _overwrite(path, offset: int, size: int = 4096, seed: int = 20261206) -> None:
    """``size`` bytes of ``path`` from ``offset`` replaced by seeded random ones (the same on every run)."""
    data = bytearray(path.read_bytes())
    noise = np.random.default_rng(seed).integers(0, 256, size, dtype=np.uint8).tobytes()
    data[offset:offset + size] = noise[:len(data) - offset]
    path.write_bytes(bytes(data))


def _structures(path, after: float = 0.1) -> list[int]:
    """Offsets of the group structures' signatures in ``path`` at or after ``after`` of its length."""
    data = path.read_bytes()
    return [m.start() for m in re.finditer(STRUCTURES, data) if m.start() >= after * len(data)]


def _h5py_fails(path) -> bool:
    """h5py raises on visiting every object of ``path`` and reading its attributes and data."""
    def visit(name, obj):
        dict(obj.attrs)
        if isinstance(obj, h5py.Dataset):
            obj[()]

    try:
        with h5py.File(path, "r") as f:
            f.visititems(visit)
    except (RuntimeError, OSError, KeyError, ValueError):
        return True
    return False


@pytest.fixture(scope="module")
def run_archive(tmp_path_factory):
    """A complete reduced-model archive (one rotation)."""
    path = tmp_path_factory.mktemp("damaged") / "r.h5"
    bearingsim.run(bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml")).save(path)
    return path


def test_an_archive_damaged_in_any_group_structure_is_a_user_error(run_archive, tmp_path):
    """``bearingsim.load`` and ``archive.describe`` (what inspect prints) of the archive with 4 KiB overwritten at
    each B-tree, local heap or symbol table node past the first 10 % of the file: a UserError naming the file
    (they raised RuntimeError "wrong B-tree signature", "bad local heap signature", OSError "bad global heap
    collection signature"), or the archive read whole where the bytes hit nothing either reads."""
    offsets = _structures(run_archive)
    assert len(offsets) >= 8, offsets
    hit = 0
    for offset in offsets:
        path = tmp_path / f"at-{offset}.h5"
        shutil.copy(run_archive, path)
        _overwrite(path, offset)
        hit += _h5py_fails(path)
        for read in (bearingsim.load, archive.describe):
            try:
                read(path)
            except bearingsim.UserError as exc:
                assert str(exc).startswith(f"{path}: ") and "\n" not in str(exc), str(exc)
                assert "damaged" in str(exc) or "truncated" in str(exc), str(exc)
    assert hit >= len(offsets) // 2, (hit, offsets)  # the overwrites do damage what h5py reads


def _deeply_damaged(run_archive, tmp_path):
    """The archive damaged where its checks on opening pass (its scenario, summary and layout read) and
    reading every object fails: the first such group structure past 10 % of the file."""
    from bearingsim.simulation import model_module

    layout = model_module("reduced").RESULT.LAYOUT
    for offset in _structures(run_archive):
        path = tmp_path / "damaged.h5"
        shutil.copy(run_archive, path)
        _overwrite(path, offset)
        with h5py.File(path, "r") as f:
            try:
                f["scenario"][()], dict(f["results/summary"].attrs), f["bearingsim"].attrs["model"]
                if not all(isinstance(f[k], h5py.Dataset) for k in layout):
                    continue
            except (RuntimeError, OSError, KeyError, ValueError):
                continue
        with pytest.raises(RuntimeError), h5py.File(path, "r") as f:
            f.visititems(lambda name, obj: None)
        return path
    raise AssertionError("no overwrite damages the archive past its checks on opening")


@pytest.mark.parametrize("command", list(ARCHIVE_READERS))
def test_every_reader_of_a_damaged_archive_says_so_in_one_line(run_archive, tmp_path, command):
    """show (of a table: inspect), inspect, plot, rerun, wear, animate, report, table, compare: exit 2, one line
    "damaged archive (RuntimeError: ...)" naming the file, nothing written; compare too (its exit 1 means
    "different"). They exited 1 with a traceback ending RuntimeError: Iteration operator failed."""
    path = _deeply_damaged(run_archive, tmp_path)
    args = [a.format(S=path, tmp=tmp_path) for a in ARCHIVE_READERS[command]]
    if command == "compare":
        args = ["compare", path, run_archive]
    assert_user_error(cli(*args), f"{path}: damaged archive (RuntimeError: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]
    if command == "inspect":
        assert_user_error(cli("show", path), f"{path}: damaged archive")


def _damaged_sweep(tmp_path, how: str):
    folder = tmp_path / "sw"
    folder.mkdir()
    index = _sweep_index(folder)
    data = bytearray(index.read_bytes())
    if how == "GCOL":  # the global heap holding the text columns and attributes
        i = data.index(b"GCOL")
        data[i:i + 4] = b"XXXX"
        index.write_bytes(bytes(data))
    elif how == "truncated":
        index.write_bytes(bytes(data[:3000]))
    else:  # the B-tree of /index
        index.write_bytes(bytes(data))
        _overwrite(index, [m.start() for m in re.finditer(b"TREE", data)][1], size=64)
    assert _h5py_fails(index) or how == "truncated"
    return folder, index


@pytest.mark.parametrize("how", ["GCOL", "TREE", "truncated"])
@pytest.mark.parametrize("command", ["table", "inspect", "show", "plot", "report", "sweep"])
def test_a_damaged_sweep_index_is_named_as_damaged(tmp_path, how, command):
    """A sweep's ``sweep.h5`` with its global heap's signature overwritten said "cannot write to standard output
    (Can't synchronously read data (bad global heap collection signature))"; truncated, ``report DIR`` said
    "no sweep.h5 ... in it" and ``table DIR`` "sweep.h5: cannot open (OSError)"; resuming the sweep called it a
    file not written by bearingsim. Each names the file and says it is damaged (or truncated)."""
    folder, index = _damaged_sweep(tmp_path, how)
    before = index.read_bytes()
    args = {"table": ["table", folder], "inspect": ["inspect", index], "show": ["show", index],
            "plot": ["plot", index], "report": ["report", folder, "-o", tmp_path / "r.html"],
            "sweep": ["sweep", SCENARIOS / "paper_3000rpm.toml", "--param", "operating.inner_ring_speed_rpm=1000",
                      "-o", folder, "-q", "--no-plots"]}[command]
    res = cli(*args)
    assert_user_error(res, f"{index}: damaged")
    assert "standard output" not in res.stderr
    if how == "truncated":
        assert "truncated" in res.stderr
    assert index.read_bytes() == before and not (tmp_path / "r.html").exists()


def test_damaged_tables_and_maps_read_through_the_api_name_the_file(tmp_path):
    """``archive.read_table_file`` and ``read_grid_file`` of a file whose global heap is damaged: a UserError
    naming the file (OSError "bad global heap collection signature")."""
    table = archive.write_table_file(tmp_path / "t.h5", {"name": np.array(["a", "b"]), "x": np.arange(2.0)},
                                     {"x": "m"}, {"format": "bearingsim life"})
    grid = archive.write_grid_file(tmp_path / "g.h5", [("k", np.array(["a", "b"]), {})],
                                   {"v": (np.arange(2.0), {"units": "m"})}, {"format": "bearingsim sweep map 1"})
    for path, read in ((table, lambda p: archive.read_table_file(p, "bearingsim life")),
                       (grid, lambda p: archive.read_grid_file(p, "bearingsim sweep map 1"))):
        data = bytearray(path.read_bytes())
        i = data.rindex(b"GCOL")
        data[i:i + 4] = b"XXXX"
        path.write_bytes(bytes(data))
        assert _h5py_fails(path)
        with pytest.raises(bearingsim.UserError, match=re.escape(str(path)) + ": damaged"):
            read(path)


def test_an_oserror_without_an_errno_is_not_blamed_on_standard_output(capsys):
    """What reaches the command line's last handler as an OSError without a file name and without an errno is
    not the system's failure to write standard output (which has an errno): it is printed as it is."""
    from argparse import Namespace

    from bearingsim.cli import _failed

    assert _failed(OSError("Can't synchronously read data (bad global heap collection signature)"), Namespace()) == 2
    err = capsys.readouterr().err
    assert "standard output" not in err and "bad global heap collection signature" in err


def _obeying_file_modes() -> list[str] | None:
    """The prefix of a command line that obeys file modes: none for a user who is not root; for root,
    ``setpriv`` without the capabilities that override them (None where there is no setpriv)."""
    import os

    if os.geteuid() != 0:
        return []
    setpriv = shutil.which("setpriv")
    return [setpriv, "--bounding-set=-dac_override,-dac_read_search"] if setpriv else None


@pytest.mark.parametrize("command", ["show", "inspect", "plot", "table", "report", "load"])
def test_an_unreadable_archive_is_said_to_be_unreadable(run_archive, tmp_path, command):
    """An archive without read permission was "not an HDF5 file (truncated, or not a bearingsim archive)" (show,
    inspect, plot, table, ``bearingsim.load``) or "not a bearingsim archive, nor a sweep ... folder" (report):
    words that could make a user delete a good file. It is "cannot read (Permission denied)", as a scenario
    file's reader says."""
    import subprocess
    import sys

    from . import forked_cli

    prefix = _obeying_file_modes()
    if prefix is None:
        pytest.skip("root, and no setpriv to obey file modes")
    path = tmp_path / "mine.h5"
    shutil.copy(run_archive, path)
    path.chmod(0)
    code = "import bearingsim, sys\ntry:\n    bearingsim.load(sys.argv[1])\nexcept bearingsim.UserError as e:\n" \
           "    sys.exit(f'bearingsim: error: {e}')"
    args = ["-c", code, path] if command == "load" else ["-m", "bearingsim", command, path]
    if command == "report":
        args += ["-o", tmp_path / "r.html"]
    res = subprocess.run([*prefix, sys.executable, *map(str, args)], capture_output=True, text=True,
                         env=forked_cli.environment(), timeout=300)
    res.returncode = 2 if res.returncode == 1 and command == "load" else res.returncode  # sys.exit(text): 1
    assert_user_error(res, f"{path}: cannot read (Permission denied)")
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def test_a_run_to_a_sweeps_index_says_it_is_one(run_archive, tmp_path):
    """``run ... -o DIR/sweep.h5 --force`` said of bearingsim's own sweep index "exists and is not a bearingsim
    archive", as of a user's file; it says which of bearingsim's files it is, and does not replace it
    (``Result.save`` the same)."""
    index = _sweep_index(tmp_path)
    before = index.read_bytes()
    res = cli("run", SCENARIOS / "paper_3000rpm.toml", "-o", index, "--force", "--no-plots")
    assert_user_error(res, f"{index}: a sweep's index written by bearingsim, not a run archive; not replaced")
    with pytest.raises(bearingsim.UserError, match="a sweep's index written by bearingsim"):
        bearingsim.load(run_archive).save(index)
    assert index.read_bytes() == before
