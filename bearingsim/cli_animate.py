"""``bearingsim animate``: an MP4 or GIF of a multibody run's stored motion (docs/animation.md), registered
by :func:`bearingsim.cli.build_parser` through :func:`add_commands`."""
from __future__ import annotations

import math
import sys

from bearingsim.cli_common import output_path
from bearingsim.errors import UserError


def parse_rotations(text: str) -> tuple[float, float]:
    """``"a:b"`` -> (a, b): recorded cage rotations, a < b (one-line UserError otherwise)."""
    parts = str(text).split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = float(parts[0]), float(parts[1])
    except ValueError:
        raise UserError(f"--rotations: expected a:b, two recorded cage rotations (e.g. 38:40), got {text!r}") from None
    if not (math.isfinite(a) and math.isfinite(b) and a < b):
        raise UserError(f"--rotations {text}: expected a < b")
    return a, b


def _cmd_animate(args) -> int:
    from bearingsim import animation
    from bearingsim.cli_common import options_named
    from bearingsim.simulation import animate as render
    from bearingsim.sweeps.run import _progress as progress_bar  # the bar of sweep, crosscheck and validate

    rotations = parse_rotations(args.rotations) if args.rotations is not None else None
    animation.check_number(args.fps, "--fps", 1.0, animation.MAX_FPS)  # named as the user gave them
    if args.exaggerate is not None:
        animation.check_number(args.exaggerate, "--exaggerate", 1.0, animation.MAX_EXAGGERATION)
    enabled = not args.quiet and sys.stderr.isatty()
    bar = None

    def progress(done, total):
        nonlocal bar
        if bar is None:
            bar = progress_bar(total, enabled, 0, "frames", unit="frame")
        if bar is not None:
            bar.update(done - bar.n)

    try:
        with options_named("rotations", "fps", "exaggerate"):
            out = render(args.archive, args.output, rotations=rotations, exaggerate=args.exaggerate, fps=args.fps,
                         progress=progress)
    finally:
        if bar is not None:
            bar.close()
    if not args.quiet:
        print(f"wrote {out}")
    return 0


def add_commands(sub) -> None:
    a = sub.add_parser("animate", help="an MP4 or GIF of a multibody run's stored motion: rollers in their pockets, "
                                       "cage, face forces, impacts (docs/animation.md)")
    a.add_argument("archive", help="run archive (.h5) with motion (output.motion_rotations > 0 when it ran)")
    a.add_argument("-o", "--output", type=output_path, required=True, help="animation file, .mp4 (H.264) or .gif")
    a.add_argument("--rotations", metavar="A:B", help="recorded cage rotations to show (default: all stored)")
    a.add_argument("--exaggerate", type=float, metavar="K",
                   help="draw the clearances K times their size (default: automatic, stated on the frame; at most "
                        "what the bearing's drawing holds, 22.8 for the NU214: docs/animation.md)")
    a.add_argument("--fps", type=float, default=30.0, help="frames per second of video (default 30; each cage "
                                                           "rotation takes 4 s of video)")
    a.add_argument("-q", "--quiet", action="store_true", help="no progress bar and nothing printed on success")
    a.set_defaults(func=_cmd_animate)
