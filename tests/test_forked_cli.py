"""The tests' command lines in forked processes (:mod:`tests.forked_cli`) end as in a fresh interpreter.

Each command line below runs twice, in two sibling folders that start with the same files: once in a
fork of the server, once as ``python -m bearingsim`` in a fresh interpreter. The exit status, standard
output and standard error must be the same text, and the folders must hold the same files afterwards
(archives and tables compared by their numbers: they also store when a run was written and how long it
took, which ``inspect`` prints; the comparison leaves those out). The commands cover
what the suite's command lines do: a refusal (exit 2), a run that writes an archive and prints its
summary, a run whose figures are drawn, reading an archive back, a comparison that finds a difference
(exit 1), and a sweep whose cases run in a process pool started by the command.
"""
from __future__ import annotations

import csv
import re
import shutil
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from . import forked_cli
from .conftest import SCENARIOS

PAPER = SCENARIOS / "paper_3000rpm.toml"

COMMANDS = [
    ["run", "bad.toml"],
    ["run", "paper.toml", "-o", "a.h5", "--no-plots"],
    ["run", "paper.toml", "-o", "figs/b.h5", "--set", "operating.inner_ring_speed_rpm=1000"],
    ["inspect", "a.h5"],
    ["compare", "a.h5", "figs/b.h5"],
    ["sweep", "paper.toml", "--param", "operating.inner_ring_speed_rpm=1000,2000", "--archives", "all", "-o", "sw",
     "-j", "2", "-q"],
    ["--version"],
]


def _steady(text: str) -> str:
    """What a command printed, without the times an archive records of its run (``inspect``)."""
    return re.sub(r"(created_utc|wall_time_s|solver_wall_s)=[^,\n]*", r"\1=...", text)


def _numbers(path) -> dict:
    """Every dataset of an HDF5 file, by name, but a run's wall time: numbers as their bytes, strings as
    a list."""
    found = {}

    def take(name, obj):
        if isinstance(obj, h5py.Dataset) and "wall_s" not in name:
            data = np.asarray(obj[()])
            found[name] = data.tolist() if data.dtype == object else (data.dtype.str, data.tobytes())

    with h5py.File(path, "r") as f:
        f.visititems(take)
    return found


def _table(path) -> list:
    """A CSV table's rows without its wall-time column."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    keep = [i for i, name in enumerate(rows[0]) if name != "wall_s"]
    return [[row[i] for i in keep] for row in rows]


def _files(folder) -> dict:
    """The folder's files by relative name: archives by their numbers, other files by their bytes except
    figures (drawn by the same code; their names are compared)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            name = p.relative_to(folder).as_posix()
            out[name] = {".h5": _numbers, ".csv": _table, ".png": lambda p: None}.get(p.suffix, Path.read_bytes)(p)
    return out


@pytest.mark.skipif(not forked_cli.FORK, reason="BEARINGSIM_TEST_FORK=0: every command line in a fresh interpreter")
@pytest.mark.slow
def test_a_forked_command_line_ends_as_a_fresh_interpreter_s(tmp_path):
    folders = {}
    for how in ("fork", "fresh"):
        d = tmp_path / how
        d.mkdir()
        shutil.copy(PAPER, d / "paper.toml")
        (d / "bad.toml").write_text(PAPER.read_text().replace('name = "paper_3000rpm"', 'nme = "x"'))
        folders[how] = d
    codes = set()
    for args in COMMANDS:
        forked = forked_cli.run(args, cwd=folders["fork"])
        fresh = forked_cli.run(args, cwd=folders["fresh"], fresh_interpreter=True)
        assert (forked.args[0], fresh.args[0]) == (forked_cli.FORKED, sys.executable)
        assert ((forked.returncode, _steady(forked.stdout), forked.stderr)
                == (fresh.returncode, _steady(fresh.stdout), fresh.stderr)), args
        codes.add(fresh.returncode)
    assert codes == {0, 1, 2}  # success, a difference found, a refusal
    written = _files(folders["fork"])
    assert {"a.h5", "figs/b.h5", "sw/sweep.h5"} <= set(written) and any(n.endswith(".png") for n in written)
    assert written == _files(folders["fresh"])


@pytest.mark.skipif(not forked_cli.FORK, reason="BEARINGSIM_TEST_FORK=0: every command line in a fresh interpreter")
@pytest.mark.slow
def test_a_changed_environment_gets_a_server_started_in_it(tmp_path, monkeypatch):
    """A fresh interpreter inherits the test process's environment as it is at the call; so does a fork,
    from a server started again once the environment changed."""
    assert forked_cli.run(["--version"], cwd=tmp_path).returncode == 0
    first = forked_cli._server.proc.pid
    monkeypatch.setenv("BEARINGSIM_TEST_PROBE", "1")
    res = forked_cli.run(["--version"], cwd=tmp_path)
    assert (res.returncode, res.args[0]) == (0, forked_cli.FORKED)
    assert forked_cli._server.proc.pid != first and forked_cli._server.env["BEARINGSIM_TEST_PROBE"] == "1"
