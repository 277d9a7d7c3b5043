"""Resources (issue 30, item 6): nothing waits forever on a FIFO given as an input file."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from .conftest import SCENARIOS, started

PAPER = SCENARIOS / "paper_3000rpm.toml"
HANG_TIMEOUT_S = 120  # ends a hang; a refusal takes the time of an import


@pytest.mark.parametrize("args, what", [
    (["run", "{fifo}", "-o", "{tmp}/o.h5"], "scenario file"),
    (["sweep", "{fifo}", "--param", "contact.restitution=0.5,0.6", "-o", "{tmp}/sw"], "scenario file"),
    (["crosscheck", "{fifo}", "--speeds", "3000", "-o", "{tmp}/cc"], "scenario file"),
    (["show", "{fifo}"], "archive"),
    (["inspect", "{fifo}"], "archive"),
    (["plot", "{fifo}"], "archive"),
    (["compare", "{fifo}", "{fifo}"], "archive"),
    (["rerun", "{fifo}"], "archive"),
], ids=lambda v: v[0] if isinstance(v, list) else None)
@pytest.mark.slow
def test_a_fifo_is_refused_not_waited_on(tmp_path, args, what):
    """Was: ``bearingsim run FIFO`` hung forever (opening a FIFO blocks until a writer comes). Now every
    input path is checked to be a regular file before it is opened: exit 2, one line. (The timeout only
    ends a hang; a run that is refused takes the time of an import.)"""
    fifo = tmp_path / "in.toml"
    os.mkfifo(fifo)
    cmd = [sys.executable, "-m", "bearingsim", *(a.format(fifo=fifo, tmp=tmp_path) for a in args)]
    with started(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
        try:
            out, err = proc.communicate(timeout=HANG_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{args[0]} waits on a FIFO")
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert proc.returncode == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert "in.toml" in lines[0] and "not a regular file" in lines[0] and what in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.toml"]


@pytest.mark.slow
@pytest.mark.parametrize("call", ["load_scenario", "load"])
def test_the_api_refuses_a_fifo_too(tmp_path, call):
    """``bearingsim.load_scenario`` and ``bearingsim.load`` of a FIFO: a UserError (run in a child, so
    that a hang ends with the test)."""
    fifo = tmp_path / "in.toml"
    os.mkfifo(fifo)
    code = (f"import bearingsim\ntry:\n    bearingsim.{call}({str(fifo)!r})\n"
            f"except bearingsim.UserError as e:\n    print('UserError', e)")
    with started([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
        try:
            out, err = proc.communicate(timeout=HANG_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            pytest.fail(f"bearingsim.{call} waits on a FIFO")
    assert out.startswith("UserError") and "not a regular file" in out, (out, err)


def _sweep_file(tmp_path, axes: str):
    path = tmp_path / "big.toml"
    path.write_text(f'scenario = "{PAPER}"\n[axes]\n{axes}\n')
    return path


@pytest.mark.slow
def test_a_sweep_range_of_a_trillion_values_is_refused_at_once(tmp_path):
    """Was: ``num = 1000000000000`` accepted (then numpy's linspace ran out of memory, with advice
    about numerics.rotations)."""
    from .test_cli import assert_user_error, bearingsim as cli

    path = _sweep_file(tmp_path, '"operating.inner_ring_speed_rpm" = { start = 500, stop = 6000, num = 1000000000000 }')
    assert_user_error(cli("sweep", path, "-o", tmp_path / "sw"), "big.toml", "num = 1000000000000", "100000")
    assert not (tmp_path / "sw").exists()


def test_a_sweep_of_too_many_cases_is_refused_before_any_is_built(tmp_path):
    """4 million cases of two ranges, 120000 of two --param axes: refused before a case is resolved
    (was: every case resolved, then a MemoryError)."""
    from bearingsim.errors import UserError
    from bearingsim.sweeps.spec import resolve_cases, spec_from_args

    path = _sweep_file(tmp_path, '"operating.inner_ring_speed_rpm" = { start = 500, stop = 6000, num = 2000 }\n'
                                 '"bearing.pocket_clearance_mm" = { start = 0.05, stop = 0.5, num = 2000 }')
    with pytest.raises(UserError, match="4000000 cases"):
        resolve_cases(spec_from_args(path, [], []))
    speeds = ",".join(str(500 + i) for i in range(400))
    restitutions = ",".join(str(0.1 + i / 1000) for i in range(300))
    spec = spec_from_args(PAPER, [f"operating.inner_ring_speed_rpm={speeds}", f"contact.restitution={restitutions}"], [])
    with pytest.raises(UserError, match="120000 cases .* more than the 100000"):
        resolve_cases(spec)


@pytest.fixture(scope="module")
def archive_with_unread_data(tmp_path_factory):
    """A reduced-model archive with datasets no command but ``bearingsim.load`` needs: a time series
    and an extra results array (in the issue, 2 GB of zeros in 2.2 MB cost ``show`` 2.2 GB and 11 s)."""
    import h5py
    import numpy as np

    import bearingsim

    path = tmp_path_factory.mktemp("unread") / "a.h5"
    bearingsim.run(bearingsim.load_scenario(PAPER)).save(path)
    with h5py.File(path, "r+") as f:
        kw = dict(compression="gzip", chunks=(4096,))
        g = f.create_group("observables/zeros")
        for name in ("step", "time", "value"):
            g.create_dataset(name, data=np.zeros(100_000), **kw)
        f.create_dataset("results/zeros", data=np.zeros(100_000), **kw)
    return path


# every read of an archive gives its result the run's notes (a few lines of text, /bearingsim/notes)
@pytest.mark.parametrize("command, reads", [
    ("show", {"/scenario", "/bearingsim/notes"}),
    ("plot", {"/scenario", "/bearingsim/notes", "/results/trace/theta_deg", "/results/trace/l_r",
              "/results/trace/dl_r_dt", "/results/trace/I_dec_cumulative", "/results/trace/I_acc_cumulative"}),
])
def test_archive_commands_read_only_the_datasets_they_need(archive_with_unread_data, tmp_path, monkeypatch,
                                                           capsys, command, reads):
    """Every dataset a command reads is recorded (``h5py.Dataset.__getitem__``): ``show`` reads the
    scenario and the run's notes alone, ``plot`` what its figure draws; neither decompresses the time series,
    the impact table or an array it does not use. (``compare`` and ``rerun`` judge every number a run computed,
    so they read every dataset: tests/test_archive_tools.py.)"""
    import h5py

    from bearingsim.cli import main

    read = set()
    real = h5py.Dataset.__getitem__

    def recording(self, key):
        read.add(self.name)
        return real(self, key)

    monkeypatch.setattr(h5py.Dataset, "__getitem__", recording)
    path = archive_with_unread_data
    args = {"compare": [path, path], "plot": [path, "-o", tmp_path]}.get(command, [path])
    assert main([command, *map(str, args)]) == 0, capsys.readouterr().err
    assert read == reads
