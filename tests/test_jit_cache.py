"""The numba disk cache of a kernel that inlines a kernel from another file follows edits of that file
(bearingsim._jit.drop_stale_caches; numba itself checks only the cached function's own file)."""
from __future__ import annotations

import subprocess
import sys
import textwrap

import numba
import pytest

#: these tests are of numba's compiled kernels and their cache: with NUMBA_DISABLE_JIT in the environment
#: nothing is compiled and there is nothing to test
pytestmark = pytest.mark.skipif(bool(numba.config.DISABLE_JIT), reason="NUMBA_DISABLE_JIT is set: nothing compiles")

DEP = """
from numba import njit

@njit(cache=True)
def value():
    return {v}
"""

USER = """
import dep
from numba import njit
from bearingsim._jit import drop_stale_caches

@njit(cache=True)
def call():
    return dep.value()

drop_stale_caches(__name__, (dep,))
"""


def _run(tmp_path, v):
    (tmp_path / "dep.py").write_text(textwrap.dedent(DEP.format(v=v)))
    user = tmp_path / "user.py"
    if not user.exists():  # only the dependency is edited
        user.write_text(textwrap.dedent(USER))
    out = subprocess.run([sys.executable, "-c", "import user; print(user.call())"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return int(out.stdout.strip())


@pytest.mark.slow
def test_guard_recompiles_after_an_edit_of_the_dependency(tmp_path):
    """Without the drop_stale_caches line the second run returns 1 with numba 0.68 (the cached caller keeps
    the old kernel; seen when this test was written): the guard is what makes it 2."""
    assert _run(tmp_path, 1) == 1
    assert _run(tmp_path, 2) == 2
    assert _run(tmp_path, 2) == 2


def test_the_first_compile_of_a_package_function_calls_once_and_a_compiled_one_never():
    """bearingsim._jit.on_first_compile listens to numba's "numba:compile" event, which numba fires after
    a cache miss only: a fresh dispatcher of a bearingsim function (no cache) calls it once, with its
    module, however many functions compile after it; a function of another package, and a dispatcher
    already compiled, call nothing."""
    import numba

    from bearingsim import _jit, laws

    seen = []
    with _jit.on_first_compile(seen.append):
        numba.njit(lambda x: x + 1.0)(1.0)  # this test module's: not bearingsim's
        assert seen == []
        f = numba.njit(laws.palmgren_load)
        g = numba.njit(laws.oil_film_drag_scalar)
        assert f(3.0e9, 1e-5) == laws.palmgren_load(3.0e9, 1e-5)
        g(1e-3, 100.0, 5.0)
        f(3.0e9, 2e-5)
    assert seen == ["bearingsim.laws"]
    with _jit.on_first_compile(seen.append):
        f(3.0e9, 3e-5)  # compiled for these types: nothing to compile
    numba.njit(laws.palmgren_load)(3.0e9, 1e-5)  # after the block: nothing listens
    assert seen == ["bearingsim.laws"]


def test_the_compile_note_names_the_model_and_only_where_a_progress_bar_would_show(monkeypatch):
    """The line bearingsim.cli prints as a model's kernels start to compile names the model; it is shown
    for the commands that run a model, on a terminal, without -q, and not for a dry run (which compiles
    nothing and imports no numba)."""
    import argparse
    import contextlib
    import io

    from bearingsim import cli

    out = io.StringIO()
    monkeypatch.setattr(sys, "stderr", out)
    cli._say_compiling("bearingsim.multibody.chipmunk")
    cli._say_compiling("bearingsim.reduced.event")
    lines = out.getvalue().split("\n")  # each a line of its own, from the line's start (\r)
    assert lines[0].startswith("\rbearingsim: note: compiling the multibody model's kernels for this machine")
    assert lines[1].startswith("\rbearingsim: note: compiling the reduced model's kernels for this machine")
    assert lines[2:] == [""]

    class Tty(io.StringIO):
        def isatty(self):
            return True

    def ns(**kw):
        return argparse.Namespace(**{"command": "run", "quiet": False, "dry_run": False, **kw})

    monkeypatch.setattr(sys, "stderr", Tty())
    assert not isinstance(cli._compile_note(ns()), contextlib.nullcontext)
    for args in (ns(quiet=True), ns(dry_run=True), ns(command="inspect")):
        assert isinstance(cli._compile_note(args), contextlib.nullcontext), args
    monkeypatch.setattr(sys, "stderr", io.StringIO())  # not a terminal: a log, a test's capture
    assert isinstance(cli._compile_note(ns()), contextlib.nullcontext)


def _on_a_terminal(cmd, env, cwd):
    """Run ``cmd`` with its stderr on a pseudo-terminal; its exit code and what it wrote there."""
    import os
    import pty
    import select

    master, slave = pty.openpty()
    proc = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=slave)
    os.close(slave)
    got = b""
    while True:
        ready, _, _ = select.select([master], [], [], 1.0)
        if ready:
            try:
                chunk = os.read(master, 4096)
            except OSError:  # the child closed its end
                chunk = b""
            if not chunk and proc.poll() is not None:
                break
            got += chunk
        elif proc.poll() is not None:
            break
    os.close(master)
    return proc.wait(timeout=600), got.decode(errors="replace")


@pytest.mark.slow
def test_a_first_run_on_a_terminal_says_it_compiles_and_the_next_run_does_not(tmp_path):
    """From an empty numba cache (NUMBA_CACHE_DIR), `bearingsim run` of the reduced model on a terminal
    says once that it compiles the reduced model's kernels; the same run again loads them from the
    cache and says nothing of it."""
    import os
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    cmd = [sys.executable, "-m", "bearingsim", "run", str(root / "scenarios" / "paper_3000rpm.toml"),
           "--no-plots", "-o", str(tmp_path / "a.h5")]
    code, first = _on_a_terminal(cmd, env, tmp_path)
    assert code == 0, first
    assert first.count("compiling the reduced model's kernels for this machine") == 1, first
    code, second = _on_a_terminal(cmd, env, tmp_path)
    assert code == 0, second
    assert "compiling" not in second, second


@pytest.mark.slow
def test_a_sweeps_workers_say_once_between_them_that_they_compile(tmp_path):
    """From an empty numba cache, `bearingsim sweep -j 2` on a terminal: its two forked workers each compile
    the reduced model's kernels (the sweep process runs no model), and the note is said once, by the first
    of them to start (each worker said it, one line per worker, before the flag was shared)."""
    import os
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    cmd = [sys.executable, "-m", "bearingsim", "sweep", str(root / "scenarios" / "paper_3000rpm.toml"),
           "--param", "operating.inner_ring_speed_rpm=1000,2000,3000,4000", "-j", "2", "--no-plots",
           "-o", str(tmp_path / "sw")]
    code, said = _on_a_terminal(cmd, env, tmp_path)
    assert code == 0, said
    assert said.count("compiling the reduced model's kernels for this machine") == 1, said
    assert len(list((tmp_path / "cache").rglob("*.nbi"))) > 0  # the workers did compile into the empty cache


def test_without_shared_semaphores_the_note_flag_is_the_process_own(monkeypatch):
    """Where multiprocessing cannot make a shared value (no /dev/shm: OSError), the flag of
    on_first_compile is a flag of this process: the note is still said once in it."""
    import multiprocessing

    import numba

    from bearingsim import _jit, laws

    def no_shm(*a, **kw):
        raise OSError("sem_open: function not implemented")

    monkeypatch.setattr(multiprocessing, "Value", no_shm)
    flag = _jit._shared_flag()
    with flag.get_lock():
        assert flag.value is False
    seen = []
    with _jit.on_first_compile(seen.append):
        numba.njit(laws.palmgren_load)(3.0e9, 1e-5)
        numba.njit(laws.oil_film_drag_scalar)(1e-3, 100.0, 5.0)
    assert seen == ["bearingsim.laws"]
