"""``bearingsim sweep``: run a sweep from the command line and say what it wrote (docs/sweeps.md);
called by :func:`bearingsim.cli.main`."""
from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

from bearingsim.cli_common import output_path
from bearingsim.errors import UserError
from bearingsim.wording import counted

#: rows of the table printed at the end of a sweep ('bearingsim table DIR' prints them all)
TABLE_ROWS = 40


def run_sweep_cli(target, params: list[str], sets: list[str], outdir, *, jobs: int | None = None,
                  scheduler: str | None = None, figures: bool = True, quiet: bool = False,
                  force: bool = False, progress: bool | None = None, archives: str = "auto") -> int:
    """``bearingsim sweep``: run, print what was written and the table of the cases (unless ``quiet``)
    and return the exit code. ``progress``: the bar on stderr (default: when stderr is a terminal);
    ``archives``: which cases keep an archive (:func:`run_sweep`).

    0: every case done, stale (run again) or cached; 1: some case failed (named on stderr); 130/143/129: interrupted by
    SIGINT/SIGTERM/SIGHUP (finished cases and the index are kept; run again to resume).
    """
    from bearingsim.cli_common import with_notes
    from bearingsim.sweeps.engines import DaskEngine, LocalEngine
    from bearingsim.sweeps.run import run_sweep
    from bearingsim.sweeps.spec import spec_from_args

    spec = spec_from_args(target, params, sets)
    if not quiet:  # keys that change nothing in the base scenario's model (unless the model is swept too)
        from bearingsim.scenario import given_keys, load_scenario, unread_note

        keys = given_keys(spec.scenario, spec.sets) + spec.keys
        base = load_scenario(spec.scenario, spec.sets)
        method = None if "reduced.method" in spec.keys else base.reduced.method  # swept: some cases use the step
        note = None if "model" in spec.keys else unread_note(base, keys, method, varied=spec.keys)
        if note:
            print(f"bearingsim: note: {note}", file=sys.stderr)
    jobs = jobs if jobs is not None else (os.cpu_count() or 1)
    if jobs < 1:  # in the words of every other command's -j (studies.make_engine)
        raise UserError(f"-j {jobs}: give at least 1 worker process")
    engine = DaskEngine(scheduler) if scheduler is not None else LocalEngine(jobs)
    out = run_sweep(spec, outdir, engine=engine, figures=figures, force=force, archives=archives,
                    progress=progress if progress is not None else (not quiet and sys.stderr.isatty()))
    n = len(out.rows)
    counts = out.counts()
    if out.interrupted is not None:
        print(f"bearingsim: sweep interrupted ({signal.Signals(out.interrupted).name}): {counts}, "
              f"{out.count('pending')} not run, of {n}; index {out.h5}; run the same command again to resume",
              file=sys.stderr)
        return 128 + out.interrupted
    try:
        if not quiet:
            print(f"wrote {out.csv}")
            print(f"wrote {out.h5}")
            if out.map is not None:
                print(f"wrote {out.map}")
            for p in out.figures:
                print(f"wrote {p}")
            for line in out.figure_notes:
                print(f"bearingsim: note: {line}", file=sys.stderr)
            from bearingsim import tables

            print(tables.format_table(tables.table_of_index(out.h5), max_rows=TABLE_ROWS))
            print(f"{counted(n, 'case')}: {counts} ({out.wall_s:.1f} s){with_notes(out.rows, 'case', out.outdir)}")
    except KeyboardInterrupt as exc:  # the cases, index and figures are written: the command line says so
        exc.resume_note = (f"{counted(n, 'case')} indexed in {out.h5}, the table not all printed "
                           f"('bearingsim table {out.outdir}' prints it)")
        raise
    if out.failed:
        names = ", ".join(f"{r['case']} ({', '.join(f'{k}={v}' for k, v in r['values'].items())})"
                          for r in out.failed[:10])
        more = f" and {len(out.failed) - 10} more" if len(out.failed) > 10 else ""
        print(f"bearingsim: {len(out.failed)} of {counted(n, 'case')} failed: {names}{more} (errors in {out.csv})",
              file=sys.stderr)
        return 1
    return 0


def add_commands(sub) -> None:
    """Register ``sweep`` on the subparsers ``sub`` of :func:`bearingsim.cli.build_parser`."""
    s = sub.add_parser("sweep", help="what-if sweep: resumable, failures recorded, local pool or dask cluster")
    s.add_argument("scenario", help="scenario TOML (with --param) or sweep file (docs/sweeps.md)")
    s.add_argument("--param", action="append", default=[], metavar="KEY=V1,V2,...|KEY=START:STOP:NUM",
                   help="key and the values to sweep, as a list (values as TOML; commas inside [ ], { } or "
                        "quotes do not split) or as a range START:STOP:NUM of NUM evenly spaced numbers, both "
                        "ends included, e.g. operating.inner_ring_speed_rpm=500:6000:12 (repeatable: the grid "
                        "is the product)")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario key in every case (repeatable)")
    s.add_argument("-o", "--output", type=output_path, default="outputs/sweep",
                   help="sweep folder (index, map, cases/, figures; default outputs/sweep)")
    s.add_argument("--archives", choices=("none", "all"), default=None,
                   help="per-case archives in DIR/cases/: 'all' or 'none' (default: the multibody cases only; "
                        "every case's numbers are in the index sweep.h5 and, for a product grid, map.h5)")
    s.add_argument("-j", "--jobs", type=int, default=None, help="local worker processes (default: one per core; at most one per case)")
    s.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on an existing dask.distributed cluster, e.g. tcp://127.0.0.1:8786")
    s.add_argument("--no-plots", action="store_true", help="index only, no figures")
    s.add_argument("--force", action="store_true",
                   help="replace another sweep or study in the output folder (default: refused; the same command resumes)")
    s.add_argument("-q", "--quiet", action="store_true", help="no progress bar, no table, nothing printed on success")
    s.set_defaults(func=_cmd_sweep)


def _cmd_sweep(args) -> int:
    from bearingsim.cli_common import progress_wanted

    return run_sweep_cli(args.scenario, args.param, args.set, Path(args.output), jobs=args.jobs,
                         scheduler=args.scheduler, figures=not args.no_plots, force=args.force, quiet=args.quiet,
                         progress=progress_wanted(args), archives=args.archives or "auto")
