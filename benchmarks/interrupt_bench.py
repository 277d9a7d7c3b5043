"""How long a large sweep takes to stop on a signal: ``python -m benchmarks.interrupt_bench [--tries N]``.

Each try starts ``bearingsim sweep scenarios/sweeps/map_speed_clearance.toml -j 2 --no-plots -q`` (the
100 x 100 reduced-model map) in a fresh folder, waits until the sweep has written its index ``sweep.h5``
(its workers are then running cases), waits a further 1-3 s (seeded, so the same tries land at the same
moments of the sweep as nearly as the machine allows; the map takes ~10 s on 2 cores), sends the signal
to the sweep process and measures the time until it has exited. Prints one row per try (seconds, exit
code, the sweep's last line on stderr; its whole stderr when the exit code is not 128 + the signal) and
the minimum, median and maximum of the tries the signal interrupted. docs/sweeps.md says a sweep exits
"within a second or so".
"""
from __future__ import annotations

import argparse
import random
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SWEEP = ROOT / "scenarios" / "sweeps" / "map_speed_clearance.toml"


def one_try(wait_s: float, signum: int, folder: Path) -> tuple[float, int, list[str]]:
    """(seconds from the signal to the sweep's exit, its exit code, its stderr lines)."""
    out = folder / "s"
    with open(folder / "err", "w+") as err:
        proc = subprocess.Popen([sys.executable, "-m", "bearingsim", "sweep", str(SWEEP), "-o", str(out), "-j", "2",
                                 "--no-plots", "-q"], stdout=subprocess.DEVNULL, stderr=err, cwd=ROOT)
        start = time.monotonic()
        while not (out / "sweep.h5").is_file():
            if proc.poll() is not None or time.monotonic() - start > 300:
                proc.kill()
                raise SystemExit(f"the sweep ended or stalled before it wrote {out / 'sweep.h5'}")
            time.sleep(0.05)
        time.sleep(wait_s)
        t0 = time.monotonic()
        proc.send_signal(signum)
        code = proc.wait()
        took = time.monotonic() - t0
        err.seek(0)
        lines = [line.rstrip() for line in err if line.strip()]
    return took, code, lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.interrupt_bench", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tries", type=int, default=10)
    ap.add_argument("--signal", choices=("INT", "TERM"), default="INT")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    rng = random.Random(args.seed)
    signum = getattr(signal, f"SIG{args.signal}")
    times = []
    print(f"{'try':>3}  {'s to exit':>9}  {'exit':>4}  last line")
    for i in range(1, args.tries + 1):
        with tempfile.TemporaryDirectory(prefix="bearingsim-interrupt-") as d:
            took, code, lines = one_try(1.0 + 2.0 * rng.random(), signum, Path(d))
        print(f"{i:>3}  {took:9.2f}  {code:>4}  {(lines[-1] if lines else '')[:110]}", flush=True)
        if code == 128 + signum:
            times.append(took)
        else:  # finished before the signal (0), or a defect: all it said
            print("\n".join(f"       | {line}" for line in lines))
    if times:
        print(f"SIG{args.signal}, {len(times)} of {args.tries} tries interrupted: min {min(times):.2f} s, "
              f"median {statistics.median(times):.2f} s, max {max(times):.2f} s")
    return 0 if len(times) == args.tries else 1


if __name__ == "__main__":
    raise SystemExit(main())
