"""``bearingsim`` command: thin subcommands over the Python API.

User errors (bad scenario, key, path, archive) print one line and exit 2, with no traceback; a run
that goes numerically unstable exits 3 and writes no archive.
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
from pathlib import Path

from bearingsim import __version__
from bearingsim.errors import SimulationUnstable, UserError


def _cmd_run(args) -> int:
    from bearingsim.scenario import check_run_request, load_scenario
    from bearingsim.simulation import run_scenario

    scenario = load_scenario(args.scenario, args.set)
    check_run_request(scenario)
    progress = not args.quiet and sys.stderr.isatty()
    out = run_scenario(scenario, args.output, figures=not args.no_plots, progress=progress)
    if not args.quiet:
        summary = out.result.summary
        print(f"wrote {out.archive}")
        for png in out.figures:
            print(f"wrote {png}")
        for key in ("I_dec_mean_Ns", "I_acc_mean_Ns", "first_impact_speed_m_s", "cage_slip",
                    "load_zone_half_angle_deg"):
            if key in summary:
                print(f"  {key:28s} {summary[key]:.6g}")
    return 0


def _cmd_inspect(args) -> int:
    from bearingsim.archive import describe

    print(describe(args.archive))
    return 0


def _cmd_validate(args) -> int:
    from bearingsim.reduced.studies import save_fig9

    paths = save_fig9(Path(args.output))
    for p in paths:
        print(f"wrote {p}")
    return 0


def _cmd_bench(args) -> int:
    from bearingsim.bench import run_bench

    run_bench(Path(args.output), quick=args.quick)
    return 0


def _cmd_sweep(args) -> int:
    from bearingsim.sweep import run_sweep

    run_sweep(args.scenario, args.param, args.set, Path(args.output), jobs=args.jobs, figures=not args.no_plots)
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="bearingsim", description="Roller/cage dynamics and cage-wear impulse.")
    p.add_argument("--version", action="version", version=f"bearingsim {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    r = sub.add_parser("run", help="run a scenario file and write an HDF5 archive and figures")
    r.add_argument("scenario", help="scenario TOML file")
    r.add_argument("-o", "--output", help="archive path (default outputs/<name>.h5)")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario key, e.g. operating.inner_ring_speed_rpm=3000 (repeatable)")
    r.add_argument("--no-plots", action="store_true", help="write the archive only")
    r.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    r.set_defaults(func=_cmd_run)

    i = sub.add_parser("inspect", help="print what an archive holds")
    i.add_argument("archive")
    i.set_defaults(func=_cmd_inspect)

    v = sub.add_parser("validate", help="Fig. 9 analog: reduced-model I_dec against speed (table and PNG)")
    v.add_argument("-o", "--output", default="outputs/validate", help="output folder")
    v.set_defaults(func=_cmd_validate)

    b = sub.add_parser("bench", help="speed against error of every solver (CSV, table, plot)")
    b.add_argument("--quick", action="store_true", help="short version (a few minutes)")
    b.add_argument("-o", "--output", default="outputs/bench", help="output folder")
    b.set_defaults(func=_cmd_bench)

    s = sub.add_parser("sweep", help="what-if sweep over one or more scenario keys")
    s.add_argument("scenario")
    s.add_argument("--param", action="append", required=True, metavar="KEY=V1,V2,...",
                   help="key and the values to sweep (repeatable: the grid is the product)")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    s.add_argument("-o", "--output", default="outputs/sweep", help="output folder")
    s.add_argument("-j", "--jobs", type=int, default=1, help="parallel processes")
    s.add_argument("--no-plots", action="store_true")
    s.set_defaults(func=_cmd_sweep)
    return p


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like SIGINT's KeyboardInterrupt so that every clean-up path (temporary archive
    removed, output lock released) runs the same way."""


def _raise_terminated(signum, frame):
    raise Terminated()


def _one_line(exc: BaseException) -> str:
    from bearingsim.outputs import printable

    return printable(str(exc), keep_newlines=False)


def main(argv: list[str] | None = None) -> int:
    """Run one ``bearingsim`` command; return its exit code.

    Exit codes: 0 success, 2 bad input or an unwritable output (one line on stderr), 3 an unstable or
    unphysical run (no archive), 130 SIGINT, 143 SIGTERM (no archive, no temporary file).
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    previous = None
    try:
        previous = signal.signal(signal.SIGTERM, _raise_terminated)
    except ValueError:  # not the main thread (main() called from a library): leave SIGTERM alone
        pass
    try:
        return args.func(args)
    except UserError as exc:
        line = f"bearingsim: error: {_one_line(exc)}"
        fd = getattr(exc, "stderr_fd", None)
        if fd is not None:  # failed archive write: HDF5 cannot be torn down cleanly (outputs.ArchiveWriteError)
            sys.stdout.flush()
            os.write(fd, (line + "\n").encode())
            os._exit(exc.exit_code)
        print(line, file=sys.stderr)
        return exc.exit_code
    except SimulationUnstable as exc:
        print(f"bearingsim: unstable run, no archive written: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    except Terminated:
        print("bearingsim: terminated (SIGTERM), no archive written", file=sys.stderr)
        return 128 + signal.SIGTERM
    except KeyboardInterrupt:
        print("bearingsim: interrupted, no archive written", file=sys.stderr)
        return 130
    except OSError as exc:  # a file the command reads or writes (validate/bench output folders, ...)
        where = exc.filename or "bearingsim"
        print(f"bearingsim: error: {_one_line(where)}: {_one_line(exc.strerror or exc)}", file=sys.stderr)
        return 2
    except MemoryError:
        print("bearingsim: error: out of memory; run fewer numerics.rotations or a longer numerics.output_rate_hz "
              "interval", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`: stop quietly
        sys.stderr.close()
        return 0
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
