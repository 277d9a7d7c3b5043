"""Animation speed (the goal: 2 cage rotations at 6000 rpm at 30 fps in under 30 s).

``python -m benchmarks.animation_bench [ARCHIVE]`` (from the checkout's root): animates the default window
(the last 2 recorded rotations) of ``ARCHIVE`` (default ``outputs/multibody_6000rpm.h5``, the archive
``bearingsim run scenarios/multibody_6000rpm.toml`` writes) at 30 fps into a temporary folder, as MP4 and
as GIF, each in a new process (``bearingsim animate -q``, so the time includes Python's start, the
imports and reading the archive, as a user sees it), and prints frames, wall time, the time per frame
and the file's size. The machine's load average is printed beside it: the frames are drawn in one
process and encoded in another (ffmpeg), so on a busy machine the time grows. It takes about 25 s
on 2 cores (docs/animation.md) and writes only into that temporary folder, which it removes.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FPS = 30


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.animation_bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("archive", nargs="?", default="outputs/multibody_6000rpm.h5",
                    help="the archive to animate (default: %(default)s)")
    return ap


def main(argv=None) -> int:
    archive = Path(parser().parse_args(argv).archive)
    if not archive.is_file():
        print(f"{archive}: not found; run 'bearingsim run scenarios/multibody_6000rpm.toml' first", file=sys.stderr)
        return 2
    from bearingsim import animation
    from bearingsim.simulation import load

    res = load(archive, only=("observables",))
    motion = animation._Motion(res)
    a, b = motion.window(None, archive)
    frames = max(1, int(round((b - a) * animation.SECONDS_PER_ROTATION * FPS)))
    print(f"{archive}: recorded rotations {a:.3f} .. {b:.3f}, {frames} frames at {FPS} fps; "
          f"load average {os.getloadavg()[0]:.2f}")
    print(f"{'format':6s} {'frames':>6s} {'wall [s]':>9s} {'per frame [ms]':>15s} {'size [MB]':>10s}")
    with tempfile.TemporaryDirectory() as tmp:
        for suffix in (".mp4", ".gif"):
            out = Path(tmp) / f"a{suffix}"
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "bearingsim", "animate", str(archive), "-o", str(out), "-q",
                            "--fps", str(FPS)], check=True)
            wall = time.perf_counter() - t0
            print(f"{suffix[1:]:6s} {frames:6d} {wall:9.1f} {1e3 * wall / frames:15.0f} "
                  f"{out.stat().st_size / 1e6:10.2f}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
