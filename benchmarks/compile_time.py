"""What compiling the kernels costs: a model's first run from an empty kernel cache.

    python -m benchmarks.compile_time [SCENARIO ...]

runs each scenario (default: ``scenarios/paper_3000rpm.toml`` and ``scenarios/multibody_6000rpm.toml``)
for one recorded rotation in a fresh process whose numba cache (``NUMBA_CACHE_DIR``) is a new empty
folder, and prints the first run's wall time and the functions numba compiled, longest first, each
with its compile time including what it compiled inside it (numba's ``numba:compile`` events). A
process that finds the kernels in the cache loads them instead (about a second). Each scenario takes
about half a minute to a minute (README: 31.4 s for the main job's on 2 quiet cores); the caches are temporary
folders, removed after each run, and nothing else is written.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile

CHILD = r"""
import sys, time
from numba.core import event as ev
rec = ev.RecordingListener()
ev.register("numba:compile", rec)
import bearingsim
sc = bearingsim.load_scenario(sys.argv[1], set={"numerics.rotations": 1})
t0 = time.perf_counter()
bearingsim.run(sc)
print(f"first run {time.perf_counter() - t0:.1f} s")
starts, spans = {}, []
for ts, e in rec.buffer:
    d = e.data.get("dispatcher")
    key = (f"{d.py_func.__module__}.{d.py_func.__qualname__}" if d else "?", str(e.data.get("args")))
    if e.is_start:
        starts[key] = ts
    else:
        spans.append((ts - starts.get(key, ts), key[0]))
for s, name in sorted(spans, reverse=True)[:int(sys.argv[2])]:
    print(f"  {s:7.2f} s  {name}")
"""


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.compile_time", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenarios", nargs="*", metavar="SCENARIO", help="scenario files (default: the two above)")
    return ap


def main(argv=None) -> None:
    files = parser().parse_args(argv).scenarios or ["scenarios/paper_3000rpm.toml", "scenarios/multibody_6000rpm.toml"]
    for f in files:
        with tempfile.TemporaryDirectory(prefix="bearingsim-numba-cache-") as cache:
            print(f"{f} (empty kernel cache):", flush=True)
            subprocess.run([sys.executable, "-c", CHILD, f, "8"], check=True,
                           env={**os.environ, "NUMBA_CACHE_DIR": cache})


if __name__ == "__main__":
    main()
