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


@pytest.mark.slow
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


@pytest.mark.slow
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


@pytest.mark.slow
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
    from bearingsim.plotting import figure, save_figure

    path = tmp_path / "f.png"
    save_figure(figure(), path)
    old = path.read_bytes()
    fig = figure()

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


def _users_png(path: Path) -> bytes:
    """A user's picture at ``path``: a PNG that matplotlib drew outside bearingsim (a PNG's signature, its
    chunks, a ``Software`` text of matplotlib's own), not one bearingsim wrote. Returns its bytes."""
    from bearingsim.plotting import figure

    fig = figure()
    fig.add_subplot().plot([0, 1], [1, 0])
    fig.savefig(path, format="png")
    return path.read_bytes()


def test_a_users_png_at_a_figure_path_is_refused_in_one_line_and_kept(tmp_path):
    """A figure path holding a user's PNG (any PNG passed the signature check and was replaced): refused,
    one line naming the file and saying bearingsim did not write it, kept; a figure bearingsim drew
    carries its mark and is replaced."""
    from bearingsim.errors import UserError
    from bearingsim.outputs import MARK, check_target, is_own_png
    from bearingsim.plotting import figure, save_figure

    mine = tmp_path / "o_pass.png"
    data = _users_png(mine)
    import bearingsim

    result = bearingsim.run(bearingsim.load_scenario(PAPER))
    calls = (lambda: save_figure(figure(), mine), lambda: check_target(tmp_path / "o.h5", figures=["pass"]),
             lambda: result.save_figures(tmp_path / "o"))  # the API's too: worded for it and -o alike
    for call in calls:
        with pytest.raises(UserError) as err:
            call()
        assert str(err.value) == (f"{mine}: figure path is a file without bearingsim's mark (not written by it, "
                                  "or by a version before its files carried it); not replaced (remove it or choose "
                                  "another path)")
    assert mine.read_bytes() == data and sorted(p.name for p in tmp_path.iterdir()) == ["o_pass.png"]
    own = save_figure(figure(), tmp_path / "own.png")
    assert is_own_png(own) and not is_own_png(mine) and f"Software\x00{MARK}".encode() in own.read_bytes()
    assert save_figure(figure(dpi=50), own) == own and is_own_png(own)  # its own figure: replaced


def test_figures_removed_are_only_those_bearingsim_drew(tmp_path):
    """``remove_figures`` (a new run's archive over another model's) and ``remove_folder_files`` (``--force``
    over another sweep or study) remove a figure bearingsim drew, never a user's PNG of that name."""
    from bearingsim.outputs import remove_figures, remove_folder_files
    from bearingsim.plotting import figure, save_figure

    save_figure(figure(), tmp_path / "X_forces.png")
    save_figure(figure(), tmp_path / "sweep_I.png")
    kept = {name: _users_png(tmp_path / name) for name in ("X_wear.png", "life.png", "sweep_map.png")}
    assert remove_figures(tmp_path / "X", ["forces", "wear"]) == [tmp_path / "X_forces.png"]
    assert remove_folder_files(tmp_path) == [tmp_path / "sweep_I.png"]
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == kept


# --- lock files (item 5) -------------------------------------------------------------------------
@pytest.mark.slow
def test_run_lock_file_is_never_followed(tmp_path):
    """A planted ``.o.h5.lock`` link is refused (was: followed, creating its target outside the folder)."""
    out = tmp_path / "out"
    out.mkdir()
    target = tmp_path / "created-outside"
    (out / ".o.h5.lock").symlink_to(target)
    res = cli("run", PAPER, "-o", out / "o.h5", "--no-plots")
    _one_line_refusal(res, ".o.h5.lock", "symbolic link")
    assert not target.exists() and (out / ".o.h5.lock").is_symlink()
    assert sorted(p.name for p in out.iterdir()) == [".o.h5.lock"]


@pytest.mark.slow
def test_run_lock_file_that_is_a_users_file_is_kept(tmp_path):
    """A non-empty ``.o.h5.lock`` is not bearingsim's (its lock files are empty): refused and kept
    (was: taken as the lock and deleted when the run ended)."""
    (tmp_path / ".o.h5.lock").write_text("my notes\n")
    res = cli("run", PAPER, "-o", tmp_path / "o.h5", "--no-plots")
    _one_line_refusal(res, ".o.h5.lock", "not empty")
    assert (tmp_path / ".o.h5.lock").read_text() == "my notes\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [".o.h5.lock"]


# --- sweep and cross-check folders (item 5) ------------------------------------------------------
def _sweep(out):
    return cli("sweep", PAPER, "--param", "contact.restitution=0.5,0.6", "-o", out, "-j", "1")


@pytest.mark.slow
def test_sweep_lock_link_does_not_truncate_its_target(tmp_path):
    out = tmp_path / "sw"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    _plant_link(out, ".sweep.lock", victim)
    res = _sweep(out)
    _one_line_refusal(res, ".sweep.lock", "symbolic link")
    assert victim.read_text() == "notes\n"
    assert sorted(p.name for p in out.iterdir()) == [".sweep.lock"]


@pytest.mark.parametrize("command", ["sweep", "run"])
def test_a_lock_file_that_is_a_folder_is_named_as_the_lock_file(tmp_path, command):
    """A folder at ``DIR/.sweep.lock`` (or a run's ``.o.h5.lock``) was said as 'DIR: output is not writable (Is a
    directory)', naming neither the lock file nor what is in the way: now one line naming it, and it is kept."""
    out = tmp_path / "sw"
    lock = out / (".sweep.lock" if command == "sweep" else ".o.h5.lock")
    lock.mkdir(parents=True)
    res = _sweep(out) if command == "sweep" else cli("run", PAPER, "-o", out / "o.h5", "--no-plots")
    _one_line_refusal(res, str(lock), "is a folder")
    assert "not writable" not in res.stderr and lock.is_dir()


@pytest.mark.parametrize("name, kind", [("sweep.csv", "text"), ("sweep.h5", "text"), ("sweep_I.png", "symlink"),
                                        ("sweep_map.png", "text"), ("cases", "symlink")])
@pytest.mark.slow
def test_sweep_refuses_a_folder_holding_a_users_file(tmp_path, name, kind):
    """Before any case runs: a user's file or a link at a path the sweep writes is refused and kept, and the
    folder is left as it was (the refusal came after the sweep had made its lock file, which stayed)."""
    out = tmp_path / "sw"
    out.mkdir()
    if kind == "text":
        (out / name).write_text("my notes\n")
    elif name == "cases":
        (tmp_path / "elsewhere").mkdir()
        (out / name).symlink_to(tmp_path / "elsewhere")
    else:
        _plant_link(out, name, tmp_path / "victim.txt")
    res = _sweep(out)
    _one_line_refusal(res, name, "not")
    if kind == "text":
        assert (out / name).read_text() == "my notes\n"
    elif name == "cases":
        assert list((tmp_path / "elsewhere").iterdir()) == []
    else:
        assert (tmp_path / "victim.txt").read_text() == "notes\n" and (out / name).is_symlink()
    assert sorted(p.name for p in out.iterdir()) == [name]


@pytest.mark.slow
def test_a_forced_sweep_into_a_folder_another_sweep_is_writing_removes_nothing(tmp_path):
    """``--force`` replaces another sweep's files, but never while that sweep holds the folder's lock: a forced
    sweep into a folder another was writing removed its index and case archives and only then was refused
    ("another sweep or study is writing this folder"), so the running sweep's index pointed at missing files.
    The other sweep is stood in for by its lock, held here, over a finished sweep's files."""
    from bearingsim.outputs import FolderLock

    out = tmp_path / "sw"
    assert _sweep(out).returncode == 0
    before = sorted(p.relative_to(out) for p in out.rglob("*"))
    with FolderLock(out):
        res = cli("sweep", PAPER, "--param", "contact.restitution=0.7", "--force", "-o", out, "-j", "1")
    _one_line_refusal(res, str(out), "another sweep or study is writing this folder")
    assert sorted(p.relative_to(out) for p in out.rglob("*")) == before


@pytest.mark.slow
def test_a_folder_of_cases_from_an_earlier_model_version_is_refused_with_the_way_on(tmp_path):
    """A cross-check folder written before its rung 3 changed (multibody model version 7 to 8, its warm-up and
    step) was refused to the very command that made it, telling the user that command resumes it. When every case
    not in the new sweep was computed by a model version this bearingsim does not have, the refusal says so and
    that --force computes them again; another sweep's folder keeps "the same command as before resumes it"."""
    import h5py

    out = tmp_path / "sw"
    assert _sweep(out).returncode == 0
    other = cli("sweep", PAPER, "--param", "contact.restitution=0.7", "-o", out, "-j", "1")
    _one_line_refusal(other, str(out), "(the same command as before resumes it)")
    with h5py.File(out / "sweep.h5", "r+") as f:
        f["index/model_version"][...] = 99.0  # a version no model has: computed by another bearingsim
    res = cli("sweep", PAPER, "--param", "contact.restitution=0.7", "-o", out, "-j", "1")
    _one_line_refusal(res, str(out), "computed by an earlier version of the model", "--force replaces them")
    assert "(the same command as before resumes it)" not in res.stderr


@pytest.mark.slow
def test_sweep_rewrites_its_own_files(tmp_path):
    """Its own index and figure are replaced by the next sweep into the folder (resume)."""
    out = tmp_path / "sw"
    for _ in range(2):
        res = _sweep(out)
        assert res.returncode == 0, res.stderr
    assert {"sweep.csv", "sweep.h5", "sweep_I.png", "map.h5", ".sweep.lock"} == {p.name for p in out.iterdir()}


@pytest.mark.slow
@pytest.mark.parametrize("name", ["crosscheck.csv", "crosscheck.h5", "crosscheck.png"])
def test_crosscheck_refuses_a_folder_holding_a_users_file(tmp_path, name):
    """Before any rung runs (the refusal takes no simulation time)."""
    out = tmp_path / "cc"
    out.mkdir()
    (out / name).write_text("my notes\n")
    res = cli("crosscheck", SCENARIOS / "multibody_3000rpm.toml", "--speeds", "3000", "--rotations", "1",
              "-o", out, "-j", "1")
    _one_line_refusal(res, name, "not replaced")
    assert (out / name).read_text() == "my notes\n"
    assert sorted(p.name for p in out.iterdir()) == [name]


@pytest.mark.slow
def test_validate_figure_is_never_written_through_a_link(tmp_path):
    """``validate`` (reduced Fig. 9 only) writes its figure through ``save_figure`` too."""
    out = tmp_path / "v"
    out.mkdir()
    link = _plant_link(out, "fig9_idec_vs_speed.png", tmp_path / "victim.txt")
    res = cli("validate", "--rig-rotations", "0", "-o", out)
    _one_line_refusal(res, "fig9_idec_vs_speed.png", "symbolic link")
    assert (tmp_path / "victim.txt").read_text() == "notes\n" and link.is_symlink()
