"""Every benchmark run as ``python -m benchmarks.X`` answers ``--help`` with its usage and does nothing else,
and the argument forms the docs give still parse to the same values (parsed only: nothing runs)."""
import ast
import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from .forked_cli import pythonpath as _path

ROOT = Path(__file__).resolve().parents[1]
MAIN_ENTRY = re.compile(r'^if __name__ == "__main__":', re.M)
WITH_MAIN = sorted(p.stem for p in (ROOT / "benchmarks").glob("*.py") if MAIN_ENTRY.search(p.read_text()))


def test_the_benchmarks_with_a_main_entry_are_found():
    assert {"sweep_bench", "compile_time", "discretization", "whole_bearing", "digest"} <= set(WITH_MAIN)


@pytest.mark.slow
def test_help_prints_usage_exits_0_and_writes_nothing(tmp_path):
    cwd, tmp = tmp_path / "cwd", tmp_path / "tmp"
    cwd.mkdir()
    tmp.mkdir()
    env = {**os.environ, "PYTHONPATH": _path(), "TMPDIR": str(tmp), "PYTHONDONTWRITEBYTECODE": "1"}
    procs = {m: subprocess.Popen([sys.executable, "-m", f"benchmarks.{m}", "--help"], cwd=cwd, env=env, text=True,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE) for m in WITH_MAIN}
    failed = []
    for m, p in procs.items():
        try:
            out, err = p.communicate(timeout=300)  # a hang guard only
        except subprocess.TimeoutExpired:
            p.kill()
            p.communicate()
            failed.append(f"{m}: still running after 300 s")
            continue
        if p.returncode != 0 or not out.startswith("usage:") or err:
            failed.append(f"{m}: exit {p.returncode}, {(out + err)[-300:]!r}")
        elif _docstring(m).splitlines()[-1].strip() not in out:  # the whole docstring: runs, times, outputs
            failed.append(f"{m}: its help leaves out the end of its docstring")
    assert not failed, "\n".join(failed)
    assert not list(cwd.iterdir()) and not list(tmp.iterdir())


def _docstring(module) -> str:
    return ast.get_docstring(ast.parse((ROOT / "benchmarks" / f"{module}.py").read_text())) or ""


def _parse(module, argv):
    return vars(importlib.import_module(f"benchmarks.{module}").parser().parse_args(argv))


def test_the_documented_invocations_parse_as_before():
    """The forms docs/*.md, README.md and the modules' docstrings give, and what each meant before."""
    assert _parse("animation_bench", []) == {"archive": "outputs/multibody_6000rpm.h5"}
    assert _parse("animation_bench", ["outputs/x.h5"]) == {"archive": "outputs/x.h5"}
    assert _parse("compile_time", []) == {"scenarios": []}
    assert _parse("compile_time", ["a.toml", "b.toml"]) == {"scenarios": ["a.toml", "b.toml"]}
    assert _parse("fast_scene_step", ["6000", "3000"]) == {"rpm": [6000.0, 3000.0]}
    assert _parse("step_kernels", []) == {"rpm": []}
    assert _parse("step_kernels", ["1000", "6000"]) == {"rpm": [1000.0, 6000.0]}
    assert _parse("readme_images", []) == {"archive": None}
    assert _parse("scenario_digest", []) == {}
    assert _parse("batch_means_coverage", []) == {}
    assert _parse("warmup_check", []) == {"contacts": ["hertz", "rigid"], "warmups": [1], "rotations": [4, 5, 6, 7],
                                          "runs": 20}
    assert _parse("warmup_check", ["--contacts", "rigid", "--warmups", "3", "--rotations", "5", "7"]) == {
        "contacts": ["rigid"], "warmups": [3], "rotations": [5, 7], "runs": 20}
    assert _parse("wear_bench", []) == {"what": "cost"}
    assert _parse("wear_bench", ["life"]) == {"what": "life"}
    for table in ("whatif", "orbit", "wear", "extent", "checks", "rig"):
        assert _parse("whole_bearing", [table]) == {"table": table}
    unset = {"halvings": None, "warmup": None, "rotations": None, "raceways": None}
    for study in ("psi", "theta", "dt", "order", "rig", "whatif", "life", "stages"):
        assert _parse("discretization", [study]) == {"study": study, "bins": None, "set": [], "limit": None,
                                                     "mapping": None, **unset}
    assert _parse("discretization", ["life", "--limit=clearance=0.4mm", "--bins=32,64", "--set=numerics.dt_s=2e-6",
                                     "--set=numerics.warmup_rotations=41"]) == {
        "study": "life", "bins": (32, 64), "limit": "clearance=0.4mm", "mapping": None,
        "set": ["numerics.dt_s=2e-6", "numerics.warmup_rotations=41"], **unset}
    assert _parse("discretization", ["stages", "--bins=5,10", "--mapping=uniform"]) == {
        "study": "stages", "bins": (5, 10), "limit": None, "mapping": "uniform", "set": [], **unset}
    assert _parse("discretization", ["order", "--bins=500", "--raceways=hertz", "--halvings=4", "--warmup=2",
                                     "--rotations=4"]) == {
        "study": "order", "bins": (500,), "set": [], "limit": None, "mapping": None, "halvings": 4, "warmup": 2,
        "rotations": 4, "raceways": "hertz"}
    assert _parse("sweep_bench", []) == {"command": None}
    assert _parse("sweep_bench", ["map", "out"]) == {"command": "map", "archives": "all", "outdir": "out"}
    assert _parse("sweep_bench", ["map", "--archives", "none", "out"]) == {"command": "map", "archives": "none",
                                                                           "outdir": "out"}


@pytest.mark.parametrize("module, argv", [("discretization", []), ("discretization", ["nope"]),
                                          ("wear_bench", ["x"]), ("whole_bearing", []), ("sweep_bench", ["x"]),
                                          ("fast_scene_step", ["--help-me"]), ("step_kernels", ["abc"])])
def test_a_bad_argument_is_a_usage_error(module, argv, capsys):
    with pytest.raises(SystemExit) as exc:
        _parse(module, argv)
    assert exc.value.code == 2 and "error:" in capsys.readouterr().err


def test_a_limit_for_a_study_that_does_not_read_it_is_refused(capsys):
    """``discretization dt --limit=...`` ran the time-step study and dropped the limit without a word: only
    the life study reads it, any other refuses it as a usage error (exit 2) before running anything."""
    from benchmarks import discretization

    with pytest.raises(SystemExit) as exc:
        discretization.main(["dt", "--limit=depth=1mm"])
    assert exc.value.code == 2 and "--limit: only the life and stages studies read it (not dt)" in capsys.readouterr().err


def test_the_order_study_s_options_are_refused_by_the_other_studies(capsys):
    """``--halvings``, ``--warmup``, ``--rotations`` and ``--raceways`` set the order study's runs; another study
    given one refuses it as a usage error (exit 2) before running anything, as ``--limit``."""
    from benchmarks import discretization

    for option in ("--halvings=4", "--warmup=2", "--rotations=4", "--raceways=hertz"):
        with pytest.raises(SystemExit) as exc:
            discretization.main(["dt", option])
        key = option.split("=")[0]
        assert exc.value.code == 2 and f"{key}: only the order study reads it (not dt)" in capsys.readouterr().err


def test_the_observed_order_of_the_step_study_is_that_of_the_means_it_is_given():
    """``discretization order`` publishes the observed order of convergence, log2 of the ratio of two successive
    changes at steps halved each time (Richardson extrapolation; Roache, Verification and Validation in
    Computational Science and Engineering, 1998): means I0 + C dt^p give exactly p (to round-off, 1e-9), for
    p = 1 and 2; changes of opposite sign have no order (NaN); its standard error is the delta method's over
    three independent means, checked against the partial derivatives taken by finite differences (1e-6)."""
    import math

    from benchmarks.discretization import _order

    for p in (1.0, 2.0):
        m = [27.9 - 0.3 * (4e-6 / 2 ** k * 1e6) ** p for k in range(4)]
        assert abs(_order(m, [0.0] * 4, 0)[0] - p) < 1e-9 and abs(_order(m, [0.0] * 4, 1)[0] - p) < 1e-9
    assert math.isnan(_order([1.0, 1.1, 1.0], [0.01] * 3, 0)[0])
    m, s = [27.580, 27.705, 27.804], [0.004, 0.014, 0.003]
    h = 1e-7
    grad = [(_order([x + h * (i == j) for j, x in enumerate(m)], s, 0)[0] - _order(m, s, 0)[0]) / h for i in range(3)]
    expected = math.sqrt(sum((g * e) ** 2 for g, e in zip(grad, s)))
    assert abs(_order(m, s, 0)[1] - expected) < 1e-6 * max(expected, 1.0)
