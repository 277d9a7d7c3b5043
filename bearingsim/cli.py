"""``bearingsim`` command: thin subcommands over the Python API.

User errors (bad scenario, key, path, archive) print one line and exit 2, with no traceback; a run
that goes numerically unstable exits 3 and writes no archive.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from bearingsim import __version__
from bearingsim.errors import SimulationUnstable, UserError


def _cmd_run(args) -> int:
    from bearingsim.scenario import load_scenario
    from bearingsim.simulation import run_scenario

    scenario = load_scenario(args.scenario, args.set)
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
    if args.sweep:
        from bearingsim.sweeps.bench import run_sweep_bench

        run_sweep_bench(Path(args.output))
        return 0
    from bearingsim.bench import run_bench

    run_bench(Path(args.output), quick=args.quick)
    return 0


def _cmd_sweep(args) -> int:
    from bearingsim.sweeps import run_sweep_cli

    return run_sweep_cli(args.scenario, args.param, args.set, Path(args.output), jobs=args.jobs,
                         scheduler=args.scheduler, figures=not args.no_plots)


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
    b.add_argument("--sweep", action="store_true",
                   help="scaling of a small multibody sweep on 1 and 2 workers, local pool and dask LocalCluster")
    b.add_argument("-o", "--output", default="outputs/bench", help="output folder")
    b.set_defaults(func=_cmd_bench)

    s = sub.add_parser("sweep", help="what-if sweep: resumable, failures recorded, local pool or dask cluster")
    s.add_argument("scenario", help="scenario TOML (with --param) or sweep file (README: Sweeps)")
    s.add_argument("--param", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="key and the values to sweep (repeatable: the grid is the product)")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario key in every case (repeatable)")
    s.add_argument("-o", "--output", default="outputs/sweep", help="sweep folder (index, cases/, figures)")
    s.add_argument("-j", "--jobs", type=int, default=None, help="local worker processes (default: one per core)")
    s.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on an existing dask.distributed cluster, e.g. tcp://127.0.0.1:8786")
    s.add_argument("--no-plots", action="store_true", help="index only, no figures")
    s.set_defaults(func=_cmd_sweep)
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except UserError as exc:
        print(f"bearingsim: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except SimulationUnstable as exc:
        print(f"bearingsim: unstable run, no archive written: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("bearingsim: interrupted, no archive written", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`: stop quietly
        sys.stderr.close()
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
