"""``bearingsim wear`` and ``bearingsim life``: the wear subcommands (docs/wear.md), registered by
:func:`bearingsim.cli.build_parser` through :func:`add_commands`."""
from __future__ import annotations

import sys
from pathlib import Path

from bearingsim.cli_common import output_path
from bearingsim.errors import UserError


def _wear_of(path: Path, args):
    """(result, :class:`bearingsim.wear.WearReport`) of the archive ``path`` after the running time ``args``
    gives; every refusal one line naming the archive or the option."""
    from bearingsim import wear
    from bearingsim.cli_common import options_named
    from bearingsim.simulation import load

    result = load(path)  # a missing file, a folder, a scenario file, a foreign file: one line saying which
    if result.model != "multibody":
        raise UserError(f"{path}: a {result.model}-model archive has no wear profile; the multibody model records it")
    try:
        with options_named("hours", "rotations"):  # refusals of the archive and the running time
            return result, wear.wear_report(result, hours=args.hours, rotations=args.rotations)
    except UserError as exc:  # one about the archive (no wear profile, its scenario's k of 0) names the archive
        if not str(exc).startswith("--"):  # the running time's refusals name their option (options_named)
            raise UserError(f"{path}: {exc}") from None
        raise


def _cmd_wear(args) -> int:
    from bearingsim import wear
    from bearingsim.archive import check_writable_dir
    from bearingsim.cli_common import say
    from bearingsim.outputs import check_replaceable, figure_path, is_own_png
    from bearingsim.plotting import save_figure

    paths = [Path(a) for a in args.archive]
    folder = _sweep_folder(paths)
    if folder is not None:  # a sweep's folder: the wear of its cases, a row each (no figures)
        say(args)(_sweep_wear(folder, args))
        return 0
    seen = {}
    for path in paths:  # one archive twice would be one row twice, its figures drawn twice onto each other
        first = seen.setdefault(path.resolve(), path)
        if first is not path:
            raise UserError(f"{path}: given twice ({first} and {path} are one file); give each archive once")
    done = [_wear_of(path, args) for path in paths]  # every archive checked before anything is written
    figures = {"wear_profile": wear.plot_wear_profile, "wear_volume": wear.plot_wear_volume}
    pngs = []
    if not args.no_plots:  # the figures' folders and paths checked before anything is printed
        folder = check_writable_dir(args.output) if args.output else None
        for path in paths:
            pngs.append({name: check_replaceable(figure_path((folder or path.parent) / path.stem, name), is_own_png,
                                                 "figure") for name in figures})
        seen = [p for named in pngs for p in named.values()]
        if len(set(seen)) < len(seen):
            raise UserError(f"{args.output}: archives of one file name would draw their figures onto each other "
                            f"there; give no -o (each archive's figures beside it), or --no-plots")
    tell = say(args)
    if len(paths) == 1:
        tell(f"{paths[0]}: " + wear.format_report(done[0][1]))
    else:
        tell(_comparison(paths, done))
    args.expected = [png for named in pngs for png in named.values()]  # an interrupt's line says which are complete
    for (result, rep), named in zip(done, pngs):
        for name, png in named.items():
            tell(f"wrote {save_figure(figures[name](rep, result.title()), png)}")
    return 0


def _comparison(paths, done) -> str:
    """The table of several archives' wear (:func:`bearingsim.wear.format_comparison`), labelled as
    ``bearingsim table`` labels archives (:func:`bearingsim.tables.archive_labels`: the file and the values of
    the scenario keys that differ), those keys named above it."""
    from bearingsim import wear
    from bearingsim.tables import archive_labels

    labels, differ = archive_labels(paths, [result.scenario.raw for result, _ in done])
    differ = [k for k in differ if k != "name"]
    notes = [f"wear of {len(paths)} archives, each after the running time at its own speed; scenario keys that "
             f"differ: {_keys_as_columns(labels, differ)}"]
    return wear.format_comparison(labels, [rep for _, rep in done], notes)


def _keys_as_columns(labels: dict, differ: list[str]) -> str:
    """The keys that differ, named, and how many of them the table's label columns ``labels`` show (the first
    column names the archive or case; :func:`bearingsim.tables.archive_labels`)."""
    named = ", ".join(differ) if differ else "none"
    if len(labels) == 1:
        return named
    return named + (" (as columns)" if len(labels) > len(differ) else f" (the first {len(labels) - 1} as columns)")


def _sweep_folder(paths: list[Path]) -> Path | None:
    """The sweep (or study) folder of the one path given, the folder or its index ``sweep.h5``; None otherwise."""
    from bearingsim import archive
    from bearingsim.sweeps.index import INDEX_FORMAT

    if len(paths) != 1:
        return None
    path = paths[0]
    if path.is_dir() and (path / "sweep.h5").is_file():
        return path
    return path.parent if path.is_file() and archive.is_table_file(path, INDEX_FORMAT) else None


def _sweep_wear(folder: Path, args) -> str:
    """The wear table of the sweep in ``folder`` (docs/wear.md, *A sweep's wear*): a row per case labelled by the
    values of the swept keys that differ (:func:`bearingsim.tables.archive_labels`, as ``bearingsim table`` labels
    archives), from its archive (:func:`_case_wear`), or from the index's wear rates; a case of neither named
    under the table as not available, with why."""
    from bearingsim import wear
    from bearingsim.sweeps.index import read_index
    from bearingsim.tables import archive_labels

    _check_time(args)
    cols, meta = read_index(folder / "sweep.h5")
    n = len(cols["case"])
    axes = [k for k in meta["axes"] if k in cols]
    cases = [str(c) for c in cols["case"]]
    labels, differ = archive_labels(cases, [{k: cols[k][i] for k in axes} for i in range(n)])
    labels = {("case" if k == "archive" else k): v for k, v in labels.items()}
    rows, missing, whys = [], [], []
    for i in range(n):
        values = ", ".join(f"{k} = {labels[k][i]}" for k in labels if k != "case")  # the case's swept values
        try:
            cells, why = _case_wear(folder, cols, i, args)
        except UserError as exc:  # the running time's refusal at this case's speed: which case it is
            head, _, rest = str(exc).partition(": ")
            raise UserError(f"{head}: case {cases[i]}{f' ({values})' if values else ''}: {rest}") from None
        rows.append(cells)
        whys.append(why)
        if why:
            missing.append(f"not available: case {cases[i]}{f', {values}' if values else ''}: {why}")
    if n and all(why == PER_HOUR for why in whys):  # the option, not the cases: a table of dashes says nothing
        raise UserError(f"--rotations {wear.given_time(args.rotations)}: no case of {folder} has an archive to scale by its cage "
                        f"speed (a reduced case never keeps one by default), and the index's wear rates are per hour: "
                        f"give --hours")
    notes = [f"wear of the {n} cases of the sweep {folder}, each after the running time at its own speed; swept keys "
             f"that differ: {_keys_as_columns(labels, differ)}"]
    table = wear.format_comparison(labels, rows, notes)
    rated = any(not isinstance(r, wear.WearReport) and r[3] != "-" for r in rows)  # a row of the index's rates
    return "\n".join([table, *missing, *([SWEEP_ROWS] if rated else [])])


#: the line under the wear table of a sweep's folder that says where its rows come from
SWEEP_ROWS = ("a case with a multibody archive: its wear as 'bearingsim wear ARCHIVE' computes it; a case without one "
              "(a reduced case: always, its model has no wear profile): the index's wear rates per hour "
              "(wear_*_mean_m3_h, wear_*_sem_m3_h) times the hours, '-' where they do not tell; a reduced case's "
              "wear is Archard's law on its no-load pass's impulses (Eq. 16), not on the sliding work (docs/wear.md)")


def _check_time(args) -> None:
    """Refuse a running time no case could take (:func:`bearingsim.wear.running_time`'s bounds, in hours; the
    rotations' bound depends on each case's speed), naming the option, before any case is read."""
    from bearingsim.wear import MAX_RUNNING_HOURS, given_time

    value, name = (args.hours, "--hours") if args.hours is not None else (args.rotations, "--rotations")
    if not value > 0:  # NaN fails it; an infinite time is beyond the bound (hours below, rotations a case's)
        raise UserError(f"{name} {value!r}: must be a positive number")
    if args.hours is not None and value > MAX_RUNNING_HOURS:
        raise UserError(f"--hours {given_time(value)}: more than {MAX_RUNNING_HOURS:.10g} h of running, 114 years, ten times the "
                        f"longest life a bearing is designed for; give a shorter running time")


def _case_wear(folder: Path, cols: dict, i: int, args) -> tuple:
    """(the cells of case ``i``'s row of the sweep's wear table after its labels, why it is not available or "")."""
    import math

    from bearingsim import wear
    from bearingsim.cli_common import options_named
    from bearingsim.simulation import load

    status, stored = str(cols["status"][i]), str(cols["archive"][i])
    if status not in ("done", "cached", "stale"):
        error = str(cols["error"][i]) if "error" in cols else ""
        return wear.rate_cells(None, 0.0), f"the case is {status}" + (f" ({error})" if error else "")
    path = folder / stored if stored else None
    if path is not None and path.is_file():
        try:
            result = load(path)
            if result.model == "multibody":
                with options_named("hours", "rotations"):
                    return wear.wear_report(result, hours=args.hours, rotations=args.rotations), ""
        except UserError as exc:
            if str(exc).startswith("--"):  # the running time's refusal (options_named): the command's, not the case's
                raise
            return wear.rate_cells(None, 0.0), f"{stored}: {exc}"
    rates = {k: float(cols[k][i]) for k in wear.SWEEP_RATES if k in cols}
    if not all(math.isfinite(rates.get(f"wear_{f}_{q}_m3_h", math.nan)) for f in ("front", "rear")
               for q in ("mean", "sem")):
        return wear.rate_cells(None, 0.0), ("no archive, and no wear rates in the index (one written before them: "
                                            "the same sweep command run again adds them)")
    if args.hours is None:
        return wear.rate_cells(None, 0.0), PER_HOUR
    return wear.rate_cells(rates, args.hours), ""


#: why a case without an archive has no row for a running time given as rotations
PER_HOUR = "no archive, and the index's wear rates are per hour: give --hours"


def _cmd_life(args) -> int:
    from bearingsim.cli_common import given_once, progress_wanted, report_study
    from bearingsim.scenario import load_scenario
    from bearingsim.studies import life, make_engine, run_studies

    limit = life.parse_limit(args.limit)
    scenario = load_scenario(args.scenario, args.set)
    given_once(args.set, "numerics.rotations", f"--rotations {args.rotations}", args.rotations,
               scenario.numerics.rotations, "the stages' recorded rotations")
    study = life.LifeStudy(scenario, limit, stages=args.stages, rotations=args.rotations, mapping=args.mapping,
                           progress=None if args.quiet else (lambda line: print(line, file=sys.stderr)))
    engine = make_engine(1, args.scheduler, "--scheduler")
    folder = Path(args.output or Path("outputs") / f"{scenario.name}_life")  # created after the study's checks
    outcome = run_studies([study], folder, engine=engine, force=args.force, progress=progress_wanted(args))
    code = report_study(outcome, "life")
    if code:
        return code
    notes = (life.depth_limit_note(scenario, study.limit), life.stage_count_note(args.stages, args.mapping))
    for note in notes:  # how to read the history below
        if note and not args.quiet:
            print(f"bearingsim: note: {note}", file=sys.stderr)
    # the limit reached, or the cage bar worn through first (the end of the life all the same: exit 0)
    # the limit as asked and, a relative one, the absolute value it means here: clearance=2x (0.4 mm)
    print(life.format_history(study.columns(), f"life of {args.scenario} to {study.limit.shown}", study.attrs()))
    for path in outcome.written if not args.quiet else ():  # -q: the history alone
        print(f"wrote {path}")
    return 0


#: the default stage count of ``bearingsim life``, :data:`bearingsim.studies.life.STAGES_RESOLVED` (here as a
#: number: the parser is built without importing the study; tests/test_wear.py holds the two equal)
DEFAULT_STAGES = 20


def add_commands(sub) -> None:
    """Register ``wear`` and ``life`` on the subparsers ``sub``."""
    w = sub.add_parser("wear", help="worn depth profile and volume of every pocket face after a running time "
                                    "(from a multibody archive's wear profile)")
    w.add_argument("archive", nargs="+", help="multibody archive (.h5); several: one table of their wear, a row each; "
                                              "a sweep's folder: the wear of its cases, a row each")
    t = w.add_mutually_exclusive_group(required=True)
    t.add_argument("--hours", type=float, help="running time [h] at the archive's speed")
    t.add_argument("--rotations", type=float, help="running time as inner-ring (shaft) rotations")
    w.add_argument("-o", "--output", type=output_path, help="folder for the figures (default: the archive's)")
    w.add_argument("--no-plots", action="store_true", help="print only")
    w.add_argument("-q", "--quiet", action="store_true", help="print nothing on success (the figures only)")
    w.set_defaults(func=_cmd_wear)
    li = sub.add_parser("life", help="stages of simulate / wear the pockets / simulate again until a wear limit")
    li.add_argument("scenario", help="multibody scenario TOML file")
    li.add_argument("--limit", required=True, help="depth=<x>mm (deepest worn point: an end bin's, which depends "
                                                   "on the bins of psi, docs/wear.md), clearance=<x>mm (pocket "
                                                   "clearance), clearance=<f>x (the clearance f times its value at "
                                                   "the start: 2x, the play doubles), or volume=<x>mm3 (worn volume "
                                                   "of one face)")
    li.add_argument("--stages", type=int, default=DEFAULT_STAGES,
                    help=f"stages (default {DEFAULT_STAGES}: with the worn shape fed back fewer read the life long, "
                         f"docs/wear.md)")
    li.add_argument("--rotations", type=int, help="recorded cage rotations per stage (default: the scenario's)")
    li.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a scenario key (repeatable)")
    li.add_argument("-o", "--output", type=output_path, help="folder (default outputs/<name>_life); the same command resumes")
    li.add_argument("--scheduler", metavar="ADDRESS", help="run the stages on a dask cluster (tcp://host:8786); "
                                                          "default: one local worker process")
    li.add_argument("--force", action="store_true",
                    help="replace what the folder holds: a life study of another scenario, limit, mapping, number "
                         "of stages or rotations per stage, or another sweep or study")
    li.add_argument("--mapping", choices=("shape", "uniform"), default="shape",
                    help="how a stage's wear acts back: 'shape' (default), the worn depth added to each face where "
                         "it wore; 'uniform', every pocket's clearance grows by the worst pocket's mean worn depth "
                         "(the pockets stay arcs; docs/wear.md)")
    li.add_argument("-q", "--quiet", action="store_true", help="the history table alone: no line per stage "
                                                                "run, no notes, no 'wrote' lines")
    li.set_defaults(func=_cmd_life)
