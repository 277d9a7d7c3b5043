"""Shared test helpers. Paths are absolute so tests run from any folder.

The suite runs on pytest-xdist (``-n auto --dist loadfile`` in pyproject.toml): each test file on one
worker, so a module's fixtures are computed once. No test bounds a wall time (a busy machine makes
every run slower), so tests need no turns of their own.
"""
import contextlib
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"


@pytest.fixture
def base_reduced() -> dict:
    """A minimal reduced-model scenario dictionary on the reference bearing."""
    return {
        "schema_version": 1,
        "name": "t",
        "model": "reduced",
        "bearing": {"preset": "NU214-Suzuki2023"},
        "operating": {"inner_ring_speed_rpm": 3000.0, "radial_load_N": 970.0},
        "reduced": {"load_zone_half_angle_deg": 23.5},
        "numerics": {"rotations": 1},
    }


def archive_summary_table() -> tuple[str, dict[str, str]]:
    """docs/archive.md's table of the summary attributes: (its text, {name: unit} of every name in a row's
    first cell)."""
    import re

    text = (ROOT / "docs" / "archive.md").read_text()
    table = text[text.index("### Summary attributes"):text.index("## Sign conventions")]
    units = {}
    for line in table.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 3:
            units.update((name, cells[1]) for name in re.findall(r"`([a-zA-Z_]+)`", cells[0]))
    return table, units


def si(scenario):
    """The SI parameters of a resolved scenario (what the models take)."""
    from bearingsim.parameters import Parameters

    return Parameters.from_scenario(scenario)


def _default_signals():  # pragma: no cover - runs in the child between fork and exec
    import signal

    # a suite started from a background job inherits SIGINT ignored, and Python keeps an ignored SIGINT:
    # the child must see the signals the tests send it as a terminal user's process would
    # (and one started under nohup, SIGHUP ignored)
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)


@contextlib.contextmanager
def started(cmd, **kw):
    """``subprocess.Popen(cmd, **kw)`` with SIGINT, SIGTERM and SIGHUP at their defaults in the child, ended
    (killed and reaped, its pipes closed) whatever happens in the ``with`` block."""
    proc = subprocess.Popen([str(c) for c in cmd], preexec_fn=_default_signals, **kw)
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
        for stream in (proc.stdin, proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()
        proc.wait()


# --- pytest-xdist: how many workers ---------------------------------------------------------------------
#: most workers ``-n auto`` starts: each worker loads numba's compiled kernels (and compiles them on a
#: fresh checkout) and has its own server of forked command lines (tests/forked_cli.py), and many tests
#: start process pools of their own, so more workers add memory and start-up rather than speed
MAX_WORKERS = 4


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """``-n auto``: the CPUs this process may run on (its affinity, which a container or ``taskset``
    limits, unlike the machine's core count), at most :data:`MAX_WORKERS`; on one CPU no workers (the
    tests run in this process). ``PYTEST_XDIST_AUTO_NUM_WORKERS`` still decides when set."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None  # xdist's own hook reads it
    n = min(len(os.sched_getaffinity(0)), MAX_WORKERS)
    return n if n > 1 else 0


#: module fixtures that run a study, a ladder of runs or a long run (seconds each): a test that takes one is no test of
#: "about a second or less", whatever its own call takes, so it is left out of the quick subset with them
SLOW_FIXTURES = {"ladder", "folders", "full_3000", "full_3000_reverse"}


def pytest_collection_modifyitems(items):
    """Mark ``slow`` every test that takes a fixture of :data:`SLOW_FIXTURES`."""
    for item in items:
        if SLOW_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.slow)

