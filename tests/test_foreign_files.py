"""Files that are not bearingsim's (issue 30): a run, ``plot``, a sweep or a cross-check never writes
through a symbolic link, never replaces a user's file or folder, and writes whole files or none.
The command-line cases of a run are in ``tests/test_reliability.py`` (``out-figure-*``)."""
from __future__ import annotations

from pathlib import Path

import pytest

from .conftest import SCENARIOS
from .test_cli import bearingsim as cli

PAPER = SCENARIOS / "paper_3000rpm.toml"


def _plant_link(folder: Path, name: str, outside: Path) -> Path:
    """``folder/name`` a symbolic link to a user's file ``outside`` (outside ``folder``)."""
    outside.write_text("notes\n")
    link = folder / name
    link.symlink_to(outside)
    return link


def _one_line_refusal(res, *words):
    assert res.returncode == 2, (res.returncode, res.stderr)
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    for w in words:
        assert w in lines[0], lines[0]


def test_run_leaves_a_linked_figure_and_its_target_alone(tmp_path):
    """The issue's case: ``o_pass.png`` a link to ``../victim.txt``; the run is refused before it
    starts, the link and its target are unchanged, no archive is written."""
    out = tmp_path / "out"
    out.mkdir()
    link = _plant_link(out, "o_pass.png", tmp_path / "victim.txt")
    res = cli("run", PAPER, "-o", out / "o.h5")
    _one_line_refusal(res, "o_pass.png", "symbolic link")
    assert link.is_symlink() and Path(link.readlink()) == tmp_path / "victim.txt"
    assert (tmp_path / "victim.txt").read_text() == "notes\n"
    assert sorted(p.name for p in out.iterdir()) == ["o_pass.png"]


@pytest.mark.parametrize("kind", ["symlink", "text", "fifo"])
def test_plot_refuses_a_figure_path_it_did_not_write(tmp_path, kind):
    """``plot`` checks every figure path before drawing: a link, a user's file or a FIFO is kept."""
    import os

    res = cli("run", PAPER, "-o", tmp_path / "a.h5", "--no-plots", "-q")
    assert res.returncode == 0, res.stderr
    fig = tmp_path / "a_pass.png"
    if kind == "symlink":
        _plant_link(tmp_path, "a_pass.png", tmp_path.parent / f"{tmp_path.name}-victim.txt")
    elif kind == "text":
        fig.write_text("my notes\n")
    else:
        os.mkfifo(fig)
    res = cli("plot", tmp_path / "a.h5")
    _one_line_refusal(res, "a_pass.png", "not replaced")
    if kind == "symlink":
        assert fig.is_symlink() and fig.resolve().read_text() == "notes\n"
        fig.resolve().unlink()
    elif kind == "text":
        assert fig.read_text() == "my notes\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.h5", "a_pass.png"]


def test_plot_replaces_its_own_figures(tmp_path):
    res = cli("run", PAPER, "-o", tmp_path / "a.h5", "-q")
    assert res.returncode == 0, res.stderr
    before = (tmp_path / "a_pass.png").stat().st_ino
    res = cli("plot", tmp_path / "a.h5")
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "a_pass.png").stat().st_ino != before  # a new file renamed over the old one
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.h5", "a_pass.png"]


def test_a_figure_is_written_whole_or_not_at_all(tmp_path):
    """A figure whose drawing fails half-way (here after 100 bytes, as a full disk or a signal would)
    leaves the previous file as it was and no temporary file."""
    from bearingsim.plotting import plt, save_figure

    path = tmp_path / "f.png"
    save_figure(plt.figure(), path)
    old = path.read_bytes()
    fig = plt.figure()

    def failing_savefig(target, **kw):
        if hasattr(target, "write"):
            target.write(b"\x89PNG" + b"x" * 96)
        else:
            Path(target).write_bytes(b"\x89PNG" + b"x" * 96)
        raise KeyboardInterrupt

    fig.savefig = failing_savefig
    with pytest.raises(KeyboardInterrupt):
        save_figure(fig, path)
    assert path.read_bytes() == old
    assert [p.name for p in tmp_path.iterdir()] == ["f.png"]
