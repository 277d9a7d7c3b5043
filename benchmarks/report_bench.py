"""Time of ``bearingsim report`` (docs/report.md): the whole command, as a user runs it.

``python -m benchmarks.report_bench [ARCHIVE_OR_FOLDER ...]`` (default: the main job's archive
``outputs/multibody_6000rpm.h5``, written by ``bearingsim run scenarios/multibody_6000rpm.toml``):
each input reported ``--repeats`` times (default 3) with and without the embedded animation, a table of
the wall times (each a new process: imports, reading, figures, animation, writing) and the page's size.
The goal: under 10 s for the main job's archive.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAIN = ROOT / "outputs" / "multibody_6000rpm.h5"


def time_report(path: Path, animation: str, out: Path) -> float:
    """Wall time [s] of one ``bearingsim report`` process (exit 0 required)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "bearingsim", "report", str(path), "-o", str(out), "-q",
                          "--animation", animation], capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        raise SystemExit(f"report_bench: {path}: {res.stderr.strip()}")
    return wall


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.report_bench", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="*", type=Path, default=[MAIN])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    for p in args.paths:
        if not p.exists():
            raise SystemExit(f"report_bench: {p}: not found (the main job's archive: bearingsim run "
                             f"scenarios/multibody_6000rpm.toml)")
    print(f"load average at start: {' / '.join(f'{v:.2f}' for v in os.getloadavg())}; {os.cpu_count()} cores")
    print(f"{'input':40s} {'animation':>9s} {'wall s (each run)':>26s} {'median s':>9s} {'page kB':>8s} {'animated':>8s}")
    with tempfile.TemporaryDirectory(prefix="report-bench-") as tmp:
        for p in args.paths:
            for animation in ("gif", "none"):
                out = Path(tmp) / f"{p.stem}_{animation}.html"
                walls = [time_report(p, animation, out) for _ in range(args.repeats)]
                animated = "yes" if 'id="animation"' in out.read_text() else "no"
                print(f"{str(p)[-40:]:40s} {animation:>9s} {' '.join(f'{w:.2f}' for w in walls):>26s} "
                      f"{statistics.median(walls):9.2f} {out.stat().st_size / 1e3:8.0f} "
                      f"{animated:>8s}")
    print(f"load average at end: {' / '.join(f'{v:.2f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
