"""What a ``bearingsim`` process imports before it does anything: building the parser, reading and
validating a scenario and listing its keys load none of the heavy packages (numba, scipy, dask, ...);
the commands that need them import them when they run (docs/architecture.md, "Imports")."""
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from .forked_cli import pythonpath as _path

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"

#: packages no parser, scenario or key listing needs (the numerical kernels, optimisers, the cluster,
#: figures, archives)
HEAVY = ("numba", "llvmlite", "scipy", "dask", "distributed", "matplotlib", "h5py", "pymunk", "pandas", "xarray")

PROBE = textwrap.dedent("""
    import json, sys
    HEAVY = set(json.loads(sys.argv[1]))

    def loaded():
        return sorted({m.split(".")[0] for m in sys.modules} & HEAVY)

    seen = {}
    from bearingsim import cli
    parser = cli.build_parser()
    for argv in (["keys", "pocket"], ["run", sys.argv[2], "--dry-run"], ["sweep", sys.argv[2], "--param", "a=1,2"],
                 ["sensitivity", sys.argv[2]], ["wear", "x.h5", "--hours", "1"], ["life", sys.argv[2], "--limit", "depth=0.1mm"],
                 ["animate", "x.h5", "-o", "x.gif"]):
        parser.parse_args(argv)
    seen["parser"] = loaded()
    if sys.argv[4] == "parser":
        print(json.dumps(seen))
        raise SystemExit
    from bearingsim.archive import is_archive
    from bearingsim.scenario import check_run_request, load_scenario
    assert not is_archive(sys.argv[2])
    check_run_request(load_scenario(sys.argv[2], ["numerics.rotations=2"]))
    seen["scenario"] = loaded()
    from bearingsim.keys import format_keys, list_keys
    assert "pocket_clearance_mm" in format_keys(list_keys(), "pocket")
    seen["keys"] = loaded()
    check_run_request(load_scenario(sys.argv[3], ["numerics.rotations=2"]))
    seen["multibody scenario"] = loaded()
    print(json.dumps(seen))
""")


def _probe(stop):
    """What the probe saw loaded after each step, up to ``stop`` ("parser" or "all")."""
    env = {**os.environ, "PYTHONPATH": _path()}
    out = subprocess.run([sys.executable, "-c", PROBE, json.dumps(HEAVY), str(SCENARIOS / "paper_3000rpm.toml"),
                          str(SCENARIOS / "multibody_3000rpm.toml"), stop], capture_output=True, text=True, env=env,
                         cwd=ROOT, timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_the_parser_imports_no_heavy_package():
    """Before the parser was built without the command implementations and laws.py without numba, the
    parser alone loaded numba and scipy (through the sweep runner and the scenario reader)."""
    assert _probe("parser") == {"parser": []}


@pytest.mark.slow
def test_parser_scenario_and_keys_import_no_heavy_package():
    """The parser, a reduced scenario read and checked for a run, the key list: nothing heavy. The one
    heavy package a scenario's validation may need is scipy, called (not imported at import time) for the
    quasi-static load zone of a load-zone angle left "auto" (laws.quasi_static_load_zone: brentq), as
    the multibody scenario leaves it; the reduced one gives its angle."""
    assert _probe("all") == {"parser": [], "scenario": [], "keys": [], "multibody scenario": ["scipy"]}
