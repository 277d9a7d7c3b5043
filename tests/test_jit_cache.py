"""The numba disk cache of a kernel that inlines a kernel from another file follows edits of that file
(bearingsim._jit.drop_stale_caches; numba itself checks only the cached function's own file)."""
from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

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
