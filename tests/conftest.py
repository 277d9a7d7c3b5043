"""Shared test helpers. Paths are absolute so tests run from any folder."""
import contextlib
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


def si(scenario):
    """The SI parameters of a resolved scenario (what the models take)."""
    from bearingsim.parameters import Parameters

    return Parameters.from_scenario(scenario)


def _default_signals():  # pragma: no cover - runs in the child between fork and exec
    import signal

    # a suite started from a background job inherits SIGINT ignored, and Python keeps an ignored SIGINT:
    # the child must see the signals the tests send it as a terminal user's process would
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_DFL)


@contextlib.contextmanager
def started(cmd, **kw):
    """``subprocess.Popen(cmd, **kw)`` with SIGINT and SIGTERM at their defaults in the child, ended
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
