"""``bearingsim sensitivity`` and ``bearingsim uncertainty``: their parsers and commands,
kept beside :mod:`bearingsim.cli`, which adds them with :func:`add_parsers`."""
from __future__ import annotations

import time
from pathlib import Path

from bearingsim.cli_common import output_path, with_notes
from bearingsim.errors import UserError
from bearingsim.wording import counted


def _keys(text):
    if text is None:
        return None
    keys = [k.strip() for k in text.split(",") if k.strip()]
    if not keys:
        raise UserError(f"--keys {text!r}: give dotted keys separated by commas, e.g. bearing.pocket_clearance_mm")
    return keys


def _scenario(args):
    """The scenario a study command is given (an archive refused with a hint)."""
    from bearingsim.scenario import load_scenario

    return load_scenario(args.scenario, args.set)


def _run(study, args):
    """Run ``study`` into ``-o`` on the engine of ``-j``/``--scheduler``: (its outcome, wall time [s])."""
    from bearingsim.studies import make_engine, run_studies

    engine = make_engine(args.jobs, args.scheduler)
    t0 = time.perf_counter()
    outcome = run_studies([study], Path(args.output), engine=engine, force=args.force,
                          progress=False if args.quiet else None)
    return outcome, time.perf_counter() - t0


def _cmd_sensitivity(args) -> int:
    from bearingsim.cli_common import report_study
    from bearingsim.studies.sensitivity import Sensitivity, format_table, parse_step, runs_text

    step = parse_step(args.step)
    study = Sensitivity(_scenario(args), _keys(args.keys), step)  # bad keys refused before any run
    outcome, wall = _run(study, args)
    if outcome.interrupted is None and not args.quiet:
        print(f"sensitivity of {args.scenario}: {runs_text(step, study.half, len(study.keys), study.run_count)}, "
              f"{wall:.1f} s")
        for k, why in study.left_out:
            print(f"left out: {k}: {why}; give it a nonzero value to vary it")
        print(format_table(study.rows))
        for name in ("sensitivity.csv", "sensitivity.h5", "sensitivity.png"):
            print(f"wrote {Path(args.output) / name}")
        print(f"runs: {outcome.counts()}; archives in {Path(args.output) / 'cases'}"
              f"{with_notes(outcome.sweep.rows, 'run', Path(args.output) / 'sweep.h5')}")
    return report_study(outcome, "sensitivity")


def _cmd_uncertainty(args) -> int:
    from bearingsim.cli_common import report_study
    from bearingsim.studies.uncertainty import Uncertainty, format_table

    study = Uncertainty(_scenario(args), args.samples, args.seed, _keys(args.keys))
    outcome, wall = _run(study, args)
    if outcome.interrupted is None and not args.quiet:
        print(f"uncertainty of {args.scenario}: {counted(len(study.keys), 'key')}, N = {args.samples} "
              f"({counted(study.runs, 'run')}), "
              f"seed {args.seed}, {wall:.1f} s")
        print(format_table(study.spreads, study.indices))
        for name in ("uncertainty.csv", "uncertainty_spread.csv", "uncertainty.h5", "uncertainty.png"):
            print(f"wrote {Path(args.output) / name}")
        print(f"runs: {outcome.counts()}; archives in {Path(args.output) / 'cases'}"
              f"{with_notes(outcome.sweep.rows, 'run', Path(args.output) / 'sweep.h5')}")
    return report_study(outcome, "uncertainty")


def _common(p, default_out):
    p.add_argument("scenario", help="scenario TOML (either model) whose keys carry ranges (its preset's or its own)")
    p.add_argument("--keys", metavar="K1,K2,...", help="dotted keys to vary (default: every ranged key the model reads)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a scenario key (repeatable)")
    p.add_argument("-o", "--output", type=output_path, default=default_out, help=f"output folder (default {default_out})")
    p.add_argument("-j", "--jobs", type=int, default=None, help="local worker processes (default: one per core; at most one per case)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run on an existing dask.distributed cluster")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no table (failures still said)")
    p.add_argument("--force", action="store_true",
                   help="replace another sweep or study in the output folder (default: refused; the same command resumes)")


def add_parsers(sub) -> None:
    """Add ``sensitivity`` and ``uncertainty`` to the ``bearingsim`` subcommands."""
    s = sub.add_parser("sensitivity", help="d ln y / d ln x of I_dec, I_acc, cage slip and eccentricity for every "
                                           "ranged key (docs/sensitivity.md; run again to resume)")
    _common(s, "outputs/sensitivity")
    s.add_argument("--step", default="10%",
                   help="relative step, e.g. 10%% or 0.1 (default 10%%; held within each key's range)")
    s.set_defaults(func=_cmd_sensitivity)
    u = sub.add_parser("uncertainty", help="every ranged key sampled over its range: median, 5-95 %% interval and "
                                           "Sobol indices (docs/sensitivity.md; run again to resume)")
    _common(u, "outputs/uncertainty")
    u.add_argument("--samples", type=int, required=True, help="base sample N (N (keys + 2) runs, 2N for one key; a power of 2 is best)")
    u.add_argument("--seed", type=int, default=0, help="seed of the Sobol' scrambling and the bootstrap (default 0)")
    u.set_defaults(func=_cmd_uncertainty)
