"""``bearingsim`` command: thin subcommands over the Python API.

User errors (bad scenario, key, path, archive) print one line and exit 2, with no traceback; a run
that goes numerically unstable exits 3 and writes no archive.
"""
from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
from pathlib import Path

from bearingsim import __version__, outputs
from bearingsim.cli_common import Parser, given_once, output_path, progress_wanted, report_study, say, with_notes
from bearingsim.errors import SimulationUnstable, UserError
from bearingsim.wording import counted


def _print_summary(result) -> None:
    """The headline numbers of a finished run, by their SI keys, and beside each in the units ``bearingsim
    table`` shows (:func:`bearingsim.tables.headline`)."""
    from bearingsim.tables import headline

    for key, v, err, words in headline(result):
        text = f"  {key:28s} {v:.6g}"
        if err is not None and err == err and err > 0.0:
            text += f" \u00b1 {err:.2g}"
        print(text + (f"  ({words})" if words else ""))


def _cmd_run(args) -> int:
    from bearingsim.scenario import given_key_notes, given_keys, load_scenario, with_overrides
    from bearingsim.simulation import check_run, check_step_possible, run_scenario

    scenario = load_scenario(args.scenario, args.set)
    try:
        check_run(scenario)  # what the run would refuse before its first step: the dry run refuses it too
    except UserError as exc:  # a value a --set gave is not the file's
        raise with_overrides(exc, scenario.source, args.set) from None
    if args.check_step:
        check_step_possible(scenario)
    if not args.quiet:  # the keys given that have no effect on the run, or not the one asked, noted by the dry run too
        for note in given_key_notes(scenario, given_keys(args.scenario, args.set)):
            print(f"bearingsim: note: {note}", file=sys.stderr)
    if args.dry_run:
        return _dry_run(scenario, args)
    progress = not args.quiet and sys.stderr.isatty()
    out = run_scenario(scenario, args.output, figures=not args.no_plots, progress=progress, notes=not args.quiet,
                       force=args.force, check_step=args.check_step)
    args.written, args.finished = out.archive, True  # from here neither stdout's error nor a signal is "no archive"
    if not args.quiet:
        print(f"wrote {out.archive}")
        for png in out.figures:
            print(f"wrote {png}")
        _print_summary(out.result)
    return 0


def _describe_index(path) -> tuple[str, str | None] | None:
    """(description, scenario TOML or None) of bearingsim's own index files (``sweep.h5``, ``map.h5``,
    ``crosscheck.h5``, the study tables); None for any other file."""
    import json

    from bearingsim import archive
    from bearingsim.studies import crosscheck
    from bearingsim.sweeps.index import INDEX_FORMAT, read_index

    if archive.is_table_file(path, INDEX_FORMAT):
        cols, meta = read_index(path)
        n, total = meta["grid_rows"], len(cols["case"])
        lines = [f"sweep mode {meta.get('mode', '?')}; base scenario {meta.get('scenario') or '(none)'}",
                 "swept keys: " + (", ".join(meta["axes"]) or "(none)"),
                 f"grid of {', '.join(meta['grid']) or '(no axes)'}: {counted(n, 'case')}; extra cases: {total - n}",
                 "each case's archive: the 'archive' column (relative to this folder; empty for a case run "
                 "without one); 'bearingsim show' of a case archive gives its scenario"]
        toml = meta.get("scenario_toml") or None
        if toml:
            lines.append(f"the base scenario resolved, with the sweep's --set: 'bearingsim show {path}'")
        return archive.describe_table(path, "bearingsim sweep index (one row per case)", cols,
                                      meta["columns"], lines, noun="case"), toml
    from bearingsim.sweeps.grid import MAP_FORMAT, describe_map, read_map

    if archive.is_grid_file(path, MAP_FORMAT):
        return describe_map(path), read_map(path).attrs.get("scenario")
    if archive.is_table_file(path, crosscheck.INDEX_FORMAT):
        cols, meta = archive.read_table_file(path, crosscheck.INDEX_FORMAT)
        columns = json.loads(meta["columns"])
        lines = [f"scenario {meta.get('scenario_name', '?')} (its TOML: 'bearingsim show {path}')",
                 "speeds [rpm]: " + ", ".join(f"{v:g}" for v in sorted(set(cols["rpm"].tolist())))]
        return archive.describe_table(path, "bearingsim cross-check table (one row per rung and speed)", cols,
                                      columns, lines), meta.get("scenario")
    return _describe_study_table(path)


#: the files inspect and show read (an archive, then the index files of :func:`_describe_index`)
_INDEX_KINDS = ("a run archive, a sweep's sweep.h5 or map.h5, crosscheck.h5, sensitivity.h5, uncertainty.h5 "
                "or life.h5")


def _describe_study_table(path) -> tuple[str, str | None] | None:
    """The sensitivity, uncertainty and life tables (``sensitivity.h5``, ``uncertainty.h5``, ``life.h5``):
    what each is, its columns, and the scenario it was made from."""
    import json

    from bearingsim import archive
    from bearingsim.studies import life, sensitivity, uncertainty

    kinds = ((sensitivity.INDEX_FORMAT, "bearingsim sensitivity table (one row per key and quantity)", "row"),
             (uncertainty.INDEX_FORMAT, "bearingsim uncertainty table (Sobol indices, one row per key and quantity)",
              "row"),
             (life.LIFE_FORMAT, "bearingsim life history (one row per stage)", "stage"))
    for fmt, what, noun in kinds:
        if archive.is_table_file(path, fmt):
            cols, meta = archive.read_table_file(path, fmt)
            columns = json.loads(meta["columns"]) if "columns" in meta else list(cols)
            name = meta.get("scenario_name")
            if name is None and meta.get("scenario"):
                import tomllib

                name = tomllib.loads(meta["scenario"]).get("name")
            lines = [f"scenario {name or '?'} (its TOML: 'bearingsim show {path}')"]
            shown = ("step", "samples", "runs", "seed", "limit", "stages", "rotations", "left_out")
            lines += [f"{k}: {meta[k]}" + (" recorded cage rotations per stage" if k == "rotations" else "")
                      for k in shown if k in meta]
            if fmt == life.LIFE_FORMAT:
                lines += _life_lines(meta)
            return archive.describe_table(path, what, cols, columns, lines, noun=noun), meta.get("scenario")
    return None


def _life_lines(meta: dict) -> list[str]:
    """What a life history's attributes say beside its limit and counts: the wear mapping its stages ran
    with (the one a resume must give; a history without one is a uniform study's) and, when the cage bar
    wore through before the limit, that."""
    from bearingsim.studies import life

    mapping = meta.get("mapping")
    text = (f"mapping: {mapping} ({life.MAPPINGS[mapping]})" if mapping in life.MAPPINGS else
            f"mapping: {mapping}" if mapping else "mapping: uniform (none recorded: written before the shape mapping)")
    lines = [text]
    if meta.get("worn_through"):
        lines.append(f"ended before the limit, the cage bar worn through: {meta['worn_through']}")
    return lines


def _cmd_inspect(args) -> int:
    from bearingsim.archive import describe

    folder = _folder_listing(Path(args.archive))
    if folder is not None:
        print(folder)
        return 0
    index = _describe_index(args.archive)
    print(index[0] if index is not None else describe(args.archive))
    return 0


def _folder_listing(p: Path) -> str | None:
    """``inspect`` of a sweep's or a study's folder (one holding ``sweep.h5``): each of its study tables and
    its case index, as ``inspect`` of each file lists it, one after the other; None for anything else (a
    folder that holds no sweep is refused by the archive reader, naming what it is)."""
    from bearingsim.archive import unreadable_error
    from bearingsim.tables import studies_of

    if not (p.is_dir() and (p / "sweep.h5").is_file()):
        return None
    studies = studies_of(p)
    files = [f for _, f in studies if f.suffix != ".csv"] + [f for f in (p / "sweep.h5", p / "map.h5") if f.is_file()]
    listed = [_csv_study_text(kind, p) for kind, f in studies if f.suffix == ".csv"]  # ([names], text)
    for f in files:
        described = _describe_index(f)
        if described is None:  # what is wrong with it, as inspect of the file says (a sweep's own file is not foreign)
            raise unreadable_error(f) or UserError(f"{f}: not a bearingsim sweep index, though a sweep writes one by "
                                                   f"that name into its folder")
        listed.append(([f.name], described[0]))
    names = [n for shown, _ in listed for n in shown]
    head = f"{p}: a sweep or study folder; " + ("its file" if len(names) == 1 else "its files") + " below: " + \
        ", ".join(names)
    return "\n\n".join([head, *(text for _, text in listed)])


def _csv_study_text(kind: str, folder: Path) -> tuple[list[str], str]:
    """What ``inspect`` of a study folder says of the study whose tables are CSV (``validate``): (its tables'
    names, a text naming them and the command that prints them, :func:`bearingsim.tables.study_text`)."""
    from bearingsim.studies.validate import own_tables
    from bearingsim.tables import STUDY_NAMES

    names = own_tables(folder)
    return names, (f"{folder}: bearingsim {STUDY_NAMES[kind]} tables (CSV, one row per speed): {', '.join(names)}\n"
                   f"'bearingsim table {folder}' prints them; its cases: sweep.h5 below")


def _is_scenario_file(path) -> bool:
    """``show``'s argument is a scenario to resolve: a regular ``.toml`` file, or one holding a scenario's
    TOML, that is not HDF5 (an archive is read as one whatever its name; a FIFO or a missing file goes to
    the archive reader's refusal): :func:`bearingsim.archive.is_scenario_file`."""
    from bearingsim.archive import is_scenario_file

    return is_scenario_file(path)


def _write_toml(text: str) -> None:
    """A TOML text to stdout as UTF-8 whatever the locale (a C locale: ASCII)."""
    buffer = getattr(sys.stdout, "buffer", None)
    if buffer is None:  # a text stream without bytes underneath (main() called with stdout replaced)
        sys.stdout.write(text)
        return
    sys.stdout.flush()
    buffer.write(text.encode("utf-8"))


def _resolved_text(scenario, out=None, figures=True) -> str:
    """The resolved scenario as TOML, with what differs from its preset (and the archive a run would
    write, with its figures unless ``--no-plots``) as comments above it."""
    from bearingsim.scenario import differences_from_preset

    head = [f"# resolved from {scenario.source}: every key, defaults < preset < file < --set"]
    diffs = differences_from_preset(scenario)
    head.append("# differs from the preset: " + (", ".join(diffs) if diffs else "nothing"))
    if out is not None:
        also = "and its figures beside it" if figures else "no figures: --no-plots"
        head.append(f"# 'bearingsim run' would write {out} ({also}); nothing was run")
    return "\n".join(head) + "\n" + scenario.to_toml()


def _dry_run(scenario, args) -> int:
    """``run --dry-run``: the resolved scenario and the archive it would write, its output refused as the run
    would refuse it; nothing run or written."""
    from bearingsim.scenario import out_of_range_note
    from bearingsim.simulation import check_output

    out = check_output(scenario, args.output, figures=not args.no_plots, force=args.force)
    note = None if args.quiet else out_of_range_note(scenario)  # the run's note of it, given before any step
    if note:
        print(note, file=sys.stderr)
    _write_toml(_resolved_text(scenario, out, figures=not args.no_plots))
    return 0


def _cmd_show(args) -> int:
    from bearingsim.simulation import SCENARIO_ONLY, load as read

    if _is_scenario_file(args.archive):
        from bearingsim.scenario import load_scenario

        _write_toml(_resolved_text(load_scenario(args.archive, args.set)))
        return 0
    if args.set:
        raise UserError(f"show {args.archive}: --set applies to a scenario file (.toml), not to an archive")
    index = _describe_index(args.archive)
    if index is not None:  # an index file: the scenario it stores as runnable TOML (a sweep.h5: its base scenario
        # with the sweep's --set); of one that stores none (a sweep of given cases), what it is as TOML comments
        idx_text, toml = index
        text = toml if toml else "".join(f"# {line}\n" for line in idx_text.splitlines())
    else:
        text = read(args.archive, only=SCENARIO_ONLY).scenario.to_toml()
    _write_toml(text)
    return 0


def _cmd_plot(args) -> int:
    from bearingsim.archive import check_writable_dir
    from bearingsim.simulation import load as read

    path = Path(args.archive)
    from bearingsim import archive
    from bearingsim.sweeps.index import INDEX_FORMAT

    from bearingsim.studies import crosscheck

    tell = say(args)
    if archive.is_table_file(path, crosscheck.INDEX_FORMAT):  # a cross-check's index: its figure
        folder = check_writable_dir(args.output) if args.output else path.parent
        for png in crosscheck.plot_crosscheck(path, folder):
            tell(f"wrote {png}")
        return 0
    drawer = _study_table_drawer(path)
    if drawer is not None:  # sensitivity.h5, uncertainty.h5, life.h5: the study's figure from its table alone
        folder = check_writable_dir(args.output) if args.output else path.parent
        for png in drawer(path, folder):
            tell(f"wrote {png}")
        return 0
    from bearingsim.sweeps.grid import MAP_FORMAT

    if archive.is_grid_file(path, MAP_FORMAT):  # its figures are drawn from the sweep's index beside it
        raise UserError(f"{path}: a sweep's map (map.h5), not a run archive; the sweep's figures are drawn from "
                        f"its index: bearingsim plot {path.parent / 'sweep.h5'}")
    if archive.is_table_file(path, INDEX_FORMAT):  # a sweep's index: its figures
        from bearingsim.sweeps import plot_sweep_index

        folder = check_writable_dir(args.output) if args.output else path.parent
        notes: list[str] = []
        written = plot_sweep_index(path, folder, notes=notes)
        for png in written:
            tell(f"wrote {png}")
        if not written:  # nothing drawn: say why, in one line, and fail
            raise UserError(f"{path}: no figure written: " + "; ".join(notes))
        for line in notes:
            tell(f"bearingsim: note: {line}", file=sys.stderr)
        return 0
    from bearingsim.simulation import model_module

    result = read(path, only=model_module(archive.model_of(path)).RESULT.FIGURE_DATA)
    folder = check_writable_dir(args.output) if args.output else path.parent
    for png in result.save_figures(folder / path.stem):
        tell(f"wrote {png}")
    return 0


def _study_table_drawer(path):
    """``draw(table, folder) -> [png]`` for a study's table file (``sensitivity.h5``, ``uncertainty.h5``,
    ``life.h5``): the figure the study drew, from the table alone; None for any other file."""
    from bearingsim import archive
    from bearingsim.studies import life, sensitivity, uncertainty

    def draw_life(table, folder):
        from bearingsim.plotting import save_figure

        return [save_figure(life.plot_life(*life.read_life(table)), Path(folder) / "life.png")]

    for fmt, draw in ((sensitivity.INDEX_FORMAT, sensitivity.plot_sensitivity),
                      (uncertainty.INDEX_FORMAT, uncertainty.plot_uncertainty), (life.LIFE_FORMAT, draw_life)):
        if archive.is_table_file(path, fmt):
            return draw
    return None


def _cmd_rerun(args) -> int:
    from bearingsim.simulation import load as read
    from bearingsim.compare import compare_results
    from bearingsim.plausibility import STEP_CHECK_HEAD
    from bearingsim.simulation import COMPARED, run, run_scenario

    if args.force and not args.output:  # it was accepted and did nothing: a rerun without -o writes nothing
        raise UserError(f"rerun {args.archive}: --force applies with -o (it replaces an archive of another "
                        "scenario there); without -o the rerun writes nothing")
    old = read(args.archive, only=COMPARED)
    progress = not args.quiet and sys.stderr.isatty()
    check_step = any(n.startswith(STEP_CHECK_HEAD) for n in old.notes)  # the check the archive holds, repeated
    if args.output:  # the path of `run`: target checks, output lock, stale temporaries of dead runs cleaned
        run_scenario(old.scenario, args.output, figures=False, progress=progress, notes=not args.quiet,
                     force=args.force, check_step=check_step)
        args.written, args.finished = Path(args.output), True  # its one file: a signal now is not "no archive"
        new = read(args.output, only=COMPARED)  # as written: its time series went to the file, not the result
    else:
        new = run(old.scenario, progress=progress, check_step=check_step)
        for note in new.notes if not args.quiet else ():  # the rerun's notes, as `run` prints them
            print(note, file=sys.stderr)
    c = compare_results(old, new)  # the versions: the rerun's provenance holds this code's (simulation.run)
    args.status = 0 if c.identical else 1  # the verdict, kept if the reader of stdout goes early (main)
    if args.output and not args.quiet:
        print(f"wrote {args.output}")
    if c.identical:
        say(args)(f"{args.archive}: rerun is bit-identical ({len(c.summary)} summary numbers, "
                   f"{c.arrays_compared} arrays and other numbers)")
        for line in c.unrecorded_lines():
            say(args)(line)
        return 0
    print(f"{args.archive}: rerun differs")
    print(c.summary_table())
    for line in c.difference_lines():
        print(line)
    for line in c.version_lines("archive", "now"):
        print(line)
    return args.status


def _cmd_compare(args) -> int:
    from bearingsim.simulation import COMPARED, load as read
    from bearingsim.compare import compare_results

    if len(args.archives) < 2:
        raise UserError("compare: give at least two archives")
    if len(args.archives) > 2:
        return _compare_many(args.archives, args)
    args.a, args.b = args.archives
    a, b = read(args.a, only=COMPARED), read(args.b, only=COMPARED)
    c = compare_results(a, b)
    args.status = 0 if c.identical else 1  # the verdict, kept if the reader of stdout goes early (main)
    if c.scenario_keys:
        print("scenario keys that differ (A -> B):")
        for k, va, vb in c.scenario_keys:
            print(f"  {k}: {va!r} -> {vb!r}")
    else:
        print("scenarios: identical")
    print(c.summary_table())
    for line in c.difference_lines() + c.version_lines() if not c.identical else c.unrecorded_lines():
        print(line)
    print(f"results: identical ({len(c.summary)} summary numbers, {c.arrays_compared} arrays and other numbers, "
          "bit for bit)" if c.identical else "results: differ")
    return args.status


def _compare_many(paths, args) -> int:
    """``compare`` of three or more archives: the scenario keys that differ, then the summary table
    with standard errors and significance marks against the first (:mod:`bearingsim.tables`); exit 0
    when every archive's results are bit-identical to the first's, else 1."""
    from bearingsim import tables
    from bearingsim.compare import compare_results
    from bearingsim.scenario import differing_keys
    from bearingsim.simulation import COMPARED, load as read

    results = [read(p, only=COMPARED) for p in paths]
    differ = [Path(p).name for p, r in zip(paths[1:], results[1:]) if not compare_results(results[0], r).identical]
    args.status = 1 if differ else 0  # the verdict, kept if the reader of stdout goes early (main)
    keys = differing_keys(*(r.scenario.raw for r in results))
    if keys:  # identical scenarios: the table's header says so
        print("scenario keys that differ (archive 1, 2, ...):")
        for k, *values in keys:
            print(f"  {k}: " + ", ".join(map(repr, values)))
    print(tables.format_table(tables.table_of_archives(paths)))
    print("results: identical" if not differ else f"results: differ from {Path(paths[0]).name}: {', '.join(differ)}")
    return args.status


def _cmd_table(args) -> int:
    """``bearingsim table DIR|FILES...``: summary numbers side by side, or a study's own table
    (:mod:`bearingsim.tables`)."""
    from bearingsim import tables

    columns = [c.strip() for c in args.columns.split(",") if c.strip()] if args.columns else None
    print(tables.format_paths(args.paths, columns=columns))
    return 0


def _cmd_keys(args) -> int:
    """``bearingsim keys``: every scenario key with unit, bounds, default and source (:mod:`bearingsim.keys`)."""
    from bearingsim.keys import format_keys, list_keys
    from bearingsim.scenario import available_presets
    from bearingsim.wording import KEY_TOPICS

    if args.preset not in available_presets():
        raise UserError(f"--preset {args.preset!r}: unknown preset (available: {', '.join(available_presets())})")
    text = format_keys(list_keys(args.preset), args.pattern, why=args.why)
    if not text:
        raise UserError(f"keys {args.pattern!r}: no scenario key contains it ('bearingsim keys' lists them all; "
                        f"words a key's name does not hold: {', '.join(KEY_TOPICS)})")
    print(text)
    return 0


def _cmd_validate(args) -> int:
    from bearingsim.studies import make_engine, run_studies
    from bearingsim.studies.fig9 import Fig9

    studies, n = [Fig9()], args.rig_rotations
    if n < 0:
        raise UserError(f"--rig-rotations {n}: give 0 (no rig) or more recorded rotations")
    if n > 0:
        from bearingsim.studies.rig import Rig

        try:
            studies.append(Rig(rotations=n))
        except UserError as exc:  # named after the option, not the module that builds the rig's scenarios
            raise UserError(f"--rig-rotations {n}: {str(exc).removeprefix('bearingsim.studies.rig: ')}") from None
    engine = make_engine(args.jobs, args.scheduler)
    outcome = run_studies(studies, Path(args.output), engine=engine, force=args.force, progress=progress_wanted(args))
    if not args.quiet:
        _print_validate(args, studies, outcome)
    return report_study(outcome, "validate")


def _print_validate(args, studies, outcome) -> None:
    """The Fig. 9 table and its files, then the rig table and its files (what ``bearingsim table`` of the
    folder prints: :func:`bearingsim.studies.validate.format_tables`), then the cases' counts."""
    if outcome.interrupted is None:
        from bearingsim.studies.fig9 import format_table

        print(format_table(studies[0].table))
    for p in outcome.written[:2]:
        print(f"wrote {p}")
    if args.rig_rotations > 0 and outcome.interrupted is None:
        from bearingsim.studies.rig import format_table

        print(format_table(studies[1].rows, args.rig_rotations))
        for p in outcome.written[2:]:
            print(f"wrote {p}")
    if outcome.interrupted is None:
        notes = with_notes(outcome.sweep.rows, "case", Path(args.output) / "sweep.h5")
        print(f"{counted(len(outcome.sweep.rows), 'case')}: {outcome.counts()}; archives in "
              f"{Path(args.output) / 'cases'}{notes}")


def _benchmarks_root() -> Path:
    """The source checkout holding ``benchmarks/`` beside this package, put first on ``sys.path``.

    The benchmarks and goal checks are not part of the installed package: ``bearingsim bench`` runs
    from a checkout (a one-line UserError otherwise)."""
    root = Path(__file__).resolve().parents[1]
    if not (root / "benchmarks" / "__init__.py").is_file():
        raise UserError("bench: the benchmarks are not installed with bearingsim; run 'bearingsim bench' from a "
                        "source checkout of bearingsim (its benchmarks/ folder)")
    if sys.path[:1] != [str(root)]:
        sys.path.insert(0, str(root))
    return root


def _check_bench_options(args) -> None:
    """One bench at a time, and --rotations only where it is read (a --rotations of 0 is not the default)."""
    modes = [flag for flag, on in (("--map", args.map), ("--sweep", args.sweep), ("--geometry", args.geometry),
                                   ("--fast-scene", args.fast_scene)) if on]
    if len(modes) > 1 or (modes and args.quick):
        given = modes + (["--quick"] if args.quick else [])
        raise UserError(f"bench: {' and '.join(given)}: give one of --quick, --sweep, --fast-scene, --geometry "
                        "and --map (each is a bench of its own)")
    if args.rotations is None:
        return
    if not (args.geometry or args.fast_scene):
        raise UserError(f"bench: --rotations {args.rotations}: read only by --fast-scene and --geometry")
    if args.rotations < 1:
        raise UserError(f"bench: --rotations {args.rotations}: give at least 1 recorded rotation")


def _cmd_bench(args) -> int:
    from bearingsim.outputs import check_folder_path

    _benchmarks_root()
    _check_bench_options(args)
    check_folder_path(args.output)  # a file in the way: refused in the words of every other command
    if args.map:
        from benchmarks.sweep_bench import run_map_bench

        run_map_bench(Path(args.output))
        return 0
    if args.sweep:
        from benchmarks.sweep_bench import run_sweep_bench

        run_sweep_bench(Path(args.output))
        return 0
    if args.geometry:
        from benchmarks.multibody_bench import run_geometry_bench

        run_geometry_bench(Path(args.output), rotations=args.rotations or 30)
        return 0
    if args.fast_scene:
        from benchmarks.fast_scene_bench import run_fast_scene_bench

        run_fast_scene_bench(Path(args.output), rotations=args.rotations or 40)
        print((Path(args.output) / "fast_scene.md").read_text(), end="")
        print(f"wrote {Path(args.output) / 'fast_scene.csv'}, fast_scene_comparison.csv, fast_scene.md")
        return 0
    from benchmarks.bench import run_bench

    run_bench(Path(args.output), quick=args.quick)
    return 0


def _cmd_crosscheck(args) -> int:
    import time

    from bearingsim.scenario import load_scenario
    from bearingsim.studies import crosscheck as cc
    from bearingsim.studies import make_engine

    engine = make_engine(args.jobs, args.scheduler)
    scenario = load_scenario(args.scenario, args.set)
    speeds = _crosscheck_speeds(args, scenario)
    rotations = _crosscheck_rotations(args, scenario)
    cc.rung_scenarios(scenario, speeds[0], rotations)  # refuse a wrong scenario before any run
    t0 = time.perf_counter()
    rows, outcome = cc.run_crosscheck(scenario, Path(args.output), speeds, rotations, engine=engine,
                                      force=args.force, progress=progress_wanted(args))
    wall = time.perf_counter() - t0
    if outcome.interrupted is None and not args.quiet:
        where = f"dask scheduler {args.scheduler}" if args.scheduler else counted(args.jobs, "process", "processes")
        warmup = cc.warmup_text(scenario.numerics.warmup_rotations)
        print(f"cross-check of {args.scenario}: {counted(len(speeds), 'speed')} x {len(cc.RUNGS)} rungs, {warmup} + "
              f"{counted(rotations, 'rotation')} each, {where}, {wall:.1f} s; impulses per pocket and cage "
              f"rotation, mean over all pockets ± batch-means standard error")
        print(cc.format_table(rows))
        for line in cc.verdicts(rows, rotations):
            print(line)
        for name in ("crosscheck.csv", "crosscheck.h5", "crosscheck.png"):
            print(f"wrote {Path(args.output) / name}")
        notes = with_notes(outcome.sweep.rows, "rung", Path(args.output) / "sweep.h5")
        print(f"rungs: {outcome.counts()}; archives in {Path(args.output) / 'cases'}{notes}")
    return report_study(outcome, "cross-check")


def _crosscheck_speeds(args, scenario) -> tuple[float, ...]:
    """The rungs' speeds: ``--speeds``, else a ``--set operating.inner_ring_speed_rpm`` (as one speed), else
    :data:`~bearingsim.studies.crosscheck.DEFAULT_SPEEDS_RPM` (:func:`~bearingsim.cli_common.given_once`)."""
    from bearingsim.studies import crosscheck as cc

    speeds = cc.parse_speeds(args.speeds) if args.speeds is not None else None
    speeds = given_once(args.set, "operating.inner_ring_speed_rpm", f"--speeds {args.speeds}", speeds,
                        (float(scenario.operating.inner_ring_speed_rpm),), "the rungs' inner-ring speed")
    return speeds if speeds is not None else cc.DEFAULT_SPEEDS_RPM


def _crosscheck_rotations(args, scenario) -> int:
    """The rungs' recorded rotations: ``--rotations``, else a ``--set numerics.rotations`` (the scenario
    file's own count is for its single run), else :data:`~bearingsim.studies.crosscheck.DEFAULT_ROTATIONS`
    (:func:`~bearingsim.cli_common.given_once`)."""
    from bearingsim.studies.crosscheck import DEFAULT_ROTATIONS

    rotations = given_once(args.set, "numerics.rotations", f"--rotations {args.rotations}", args.rotations,
                           scenario.numerics.rotations, "the rungs' recorded rotations")
    rotations = DEFAULT_ROTATIONS if rotations is None else rotations
    if rotations < 1:
        raise UserError(f"--rotations {rotations}: give at least 1 recorded rotation")
    return rotations


def _cmd_report(args) -> int:
    """``bearingsim report PATH [-o FILE.html]`` (:mod:`bearingsim.reports`)."""
    from bearingsim.reports import report

    out = report(args.path, args.output, animation=None if args.animation == "none" else args.animation)
    if not args.quiet:
        print(f"wrote {out}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = Parser(prog="bearingsim", description="Roller/cage dynamics and cage-wear impulse.")
    p.add_argument("--version", action="version", version=f"bearingsim {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    _add_run_commands(sub)
    _add_study_commands(sub)
    from bearingsim import cli_sweep

    cli_sweep.add_commands(sub)  # sweep (bearingsim/cli_sweep.py)
    from bearingsim import cli_wear

    cli_wear.add_commands(sub)  # wear, life (bearingsim/cli_wear.py)
    from bearingsim import cli_animate

    cli_animate.add_commands(sub)  # animate (bearingsim/cli_animate.py)
    from bearingsim.cli_sensitivity import add_parsers as _add_sensitivity_parsers

    _add_sensitivity_parsers(sub)
    return p


def _add_run_commands(sub) -> None:
    """One run and its archive: run, inspect, show, plot, rerun, compare, table, keys."""
    r = sub.add_parser("run", help="run a scenario file and write an HDF5 archive and figures")
    r.add_argument("scenario", help="scenario TOML file")
    r.add_argument("-o", "--output", type=output_path, help="archive path (default outputs/<name>.h5)")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario key, e.g. operating.inner_ring_speed_rpm=3000 (repeatable)")
    r.add_argument("--no-plots", action="store_true", help="write the archive only")
    r.add_argument("--force", action="store_true",
                   help="replace an archive of a different scenario at the output path (default: refused)")
    r.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    r.add_argument("--dry-run", action="store_true",
                   help="print the resolved scenario (every key, as TOML) and the archive it would write, refusing what "
                        "the run would refuse before its first step; run and write nothing")
    r.add_argument("--check-step", action="store_true",
                   help="run it again at half its time step and note how much each mean impulse changes, whether "
                        "that is resolved, and the step's error it implies (about twice the change for a first-order "
                        "scheme); about twice the run's cost; the note goes into the archive")
    r.set_defaults(func=_cmd_run)

    i = sub.add_parser("inspect", help=f"print what a file holds: {_INDEX_KINDS}")
    i.add_argument("archive", help=_INDEX_KINDS)
    i.set_defaults(func=_cmd_inspect)

    sh = sub.add_parser("show", help="print the scenario stored in an archive, sweep.h5, map.h5, crosscheck.h5, "
                                     "sensitivity.h5, uncertainty.h5 or life.h5 as TOML (a runnable scenario file; of "
                                     "a sweep.h5, its base scenario with the sweep's --set; of an index that stores "
                                     "none, a sweep of given cases, what it holds as TOML comments); for a scenario "
                                     "file (.toml), the resolved scenario: every key, before any run")
    sh.add_argument("archive", help=f"{_INDEX_KINDS}, or a scenario .toml file")
    sh.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="with a scenario file: override a key, as 'run --set' does (repeatable)")
    sh.set_defaults(func=_cmd_show)

    pl = sub.add_parser("plot", help="draw every figure again from a run's archive, a sweep's sweep.h5, a "
                                     "crosscheck.h5, sensitivity.h5, uncertainty.h5 or life.h5 alone")
    pl.add_argument("archive", help="a run archive, sweep.h5, crosscheck.h5, sensitivity.h5, uncertainty.h5 or life.h5")
    pl.add_argument("-o", "--output", type=output_path, help="folder for the PNG files (default: beside the file)")
    pl.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    pl.set_defaults(func=_cmd_plot)

    rr = sub.add_parser("rerun", help="run an archive's scenario again and say whether the results are bit-identical")
    rr.add_argument("archive", help="a run archive (.h5) whose stored scenario is run again")
    rr.add_argument("-o", "--output", type=output_path, help="also write the new run's archive here")
    rr.add_argument("--force", action="store_true",
                    help="with -o: replace an archive of a different scenario there (default: refused)")
    rr.add_argument("-q", "--quiet", action="store_true",
                    help="no progress bar and nothing printed when the rerun is bit-identical (exit 0); what "
                         "differs is printed as without it (exit 1)")
    rr.set_defaults(func=_cmd_rerun)

    cp = sub.add_parser("compare", help="scenario keys and summary numbers of two or more archives side by side "
                                        "(exit 0 identical, 1 different, 2 bad file); two: bit for bit, every "
                                        "number; more: a table with standard errors and significance marks")
    cp.add_argument("archives", nargs="+", metavar="ARCHIVE", help="two or more run archives (.h5)")
    cp.set_defaults(func=_cmd_compare)

    tb = sub.add_parser("table", help="summary numbers of a sweep folder (its index sweep.h5) or of archives, as "
                                      "aligned columns with units, standard errors and significance marks; of a study "
                                      "folder (cross-check, validate, sensitivity, uncertainty, life) or its table file, "
                                      "the study's own table")
    tb.add_argument("paths", nargs="+", metavar="DIR|FILE",
                    help="one folder, sweep.h5 or study table (crosscheck.h5, sensitivity.h5, uncertainty.h5, life.h5), "
                         "or run archives, a row each in the order given: the first is the reference of the marks "
                         "(a shell's cases/*.h5 comes sorted by name)")
    tb.add_argument("--columns", metavar="KEY,...",
                    help="summary keys to show (default: I_dec_mean_Ns, I_acc_mean_Ns, first_impact_speed_m_s, "
                         "cage_slip, cage_rest_angle_deg, load_zone_half_angle_deg, wear_front_mean_m3_h, "
                         "wear_rear_mean_m3_h, those present), each by its key or the name its column shows "
                         "(I_dec_mean); not for a "
                         "study's own table")
    tb.set_defaults(func=_cmd_table)

    ks = sub.add_parser("keys", help="every scenario key with its unit, type and bounds, default and source")
    ks.add_argument("pattern", nargs="?", help="only keys containing this text, e.g. land or numerics.")
    ks.add_argument("--preset", default="NU214-Suzuki2023", help="the preset whose values are the defaults shown")
    ks.add_argument("--why", action="store_true", help="each preset value's reasoning or reference below it")
    ks.set_defaults(func=_cmd_keys)


def _add_study_commands(sub) -> None:
    """Many-case studies that are not sweeps: validate, bench, crosscheck."""
    v = sub.add_parser("validate", help="Fig. 9 analogs: reduced-model I_dec against speed, and the rig scene "
                                        "(pocket 0 flat) against it (tables and PNGs; run again to resume)")
    v.add_argument("-o", "--output", type=output_path, default="outputs/validate", help="output folder (default outputs/validate)")
    v.add_argument("--rig-rotations", type=int, default=20,
                   help="recorded rotations of each rig run (after 1 warm-up); 0 skips the rig (default 20)")
    v.add_argument("-j", "--jobs", type=int, default=2, help="local worker processes (default 2)")
    v.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the cases on an existing dask.distributed cluster, e.g. tcp://127.0.0.1:8786")
    v.add_argument("--force", action="store_true",
                   help="replace another sweep or study in the output folder (default: refused; the same command resumes)")
    v.add_argument("-q", "--quiet", action="store_true", help="no progress bar and nothing printed on success")
    v.set_defaults(func=_cmd_validate)

    b = sub.add_parser("bench", help="speed against error of every solver (CSV, table, plot); from a source "
                                     "checkout (benchmarks/)",
                       description="Speed against error of every solver (CSV, table, plot). The benchmarks are "
                                   "not installed with the package: run this from a source checkout of bearingsim "
                                   "(its benchmarks/ folder); docs/bench.md.")
    b.add_argument("--quick", action="store_true", help="short version (about 30 s on 2 quiet cores: docs/bench.md)")
    b.add_argument("--sweep", action="store_true",
                   help="scaling of a small multibody sweep on 1 and 2 workers, local pool and dask LocalCluster")
    b.add_argument("--fast-scene", action="store_true",
                   help="rigid raceways against the Hertz full scene at 500, 1000, 3000 and 6000 rpm")
    b.add_argument("--geometry", action="store_true",
                   help="pocket-face geometry: exact faces against polylines of 3 to 63 segments at 2000 and 3000 rpm "
                        "(1 warm-up + 30 rotations each, or --rotations)")
    b.add_argument("--rotations", type=int, default=None,
                   help="recorded rotations per run of --fast-scene (default 40) or --geometry (default 30)")
    b.add_argument("--map", action="store_true",
                   help="the 100 x 100 reduced-model sweep map (2 workers), map only and with --archives all: "
                        "wall time, resume, files and sizes")
    b.add_argument("-o", "--output", type=output_path, default="outputs/bench", help="output folder (default outputs/bench)")
    b.set_defaults(func=_cmd_bench)

    cc = sub.add_parser("crosscheck", help="the reduced model against the whole bearing, one assumption at a time "
                                           "(docs/crosscheck.md; run again to resume)")
    cc.add_argument("scenario", help="multibody scenario TOML, full scene")
    cc.add_argument("--speeds", help="inner-ring speeds in rpm (default 1000,3000,6000, or a --set "
                                     "operating.inner_ring_speed_rpm)")
    cc.add_argument("--rotations", type=int, default=None,
                    help="recorded cage rotations of every rung (default 10, or a --set numerics.rotations), after "
                         "the scenario's warm-up rotations")
    cc.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a scenario key (repeatable)")
    cc.add_argument("-o", "--output", type=output_path, default="outputs/crosscheck",
                    help="output folder (default outputs/crosscheck)")
    cc.add_argument("-j", "--jobs", type=int, default=2, help="local worker processes (default 2)")
    cc.add_argument("--scheduler", metavar="ADDRESS",
                    help="run the rungs on an existing dask.distributed cluster, e.g. tcp://127.0.0.1:8786")
    cc.add_argument("--force", action="store_true",
                   help="replace another sweep or study in the output folder (default: refused; the same command resumes)")
    cc.add_argument("-q", "--quiet", action="store_true", help="no progress bar, no table, nothing printed on success")
    cc.set_defaults(func=_cmd_crosscheck)
    rp = sub.add_parser("report", help="one self-contained HTML page of a run archive, a sweep folder or a study "
                                       "folder: figures, animation, tables, checks, scenario, provenance (docs/report.md)")
    rp.add_argument("path", help="run archive, or sweep, cross-check, validate, sensitivity, uncertainty or life folder")
    rp.add_argument("-o", "--output", type=output_path, help="the HTML file to write (default: beside PATH, named after it: "
                                           "outputs/run.h5 -> outputs/run.html, outputs/sweep -> outputs/sweep.html)")
    rp.add_argument("--animation", choices=("gif", "mp4", "none"), default="gif",
                    help="embed an archive's animation as a GIF image (default), an MP4 video, or not at all")
    rp.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    rp.set_defaults(func=_cmd_report)


class Terminated(KeyboardInterrupt):
    """SIGTERM, or SIGHUP (a terminal that went away: ``signum`` says which), raised like SIGINT's
    KeyboardInterrupt so that every clean-up path (temporary archive removed, output lock released) runs the
    same way."""

    def __init__(self, signum: int = signal.SIGTERM):
        super().__init__()
        self.signum = signum


def _raise_terminated(signum, frame):
    raise Terminated(signum)


#: the signals the command line ends a command on by :class:`Terminated` (SIGINT raises Python's own
#: KeyboardInterrupt); SIGHUP only when the process did not start with it ignored (``nohup`` asks a command to
#: outlive its terminal)
TERMINATING = (signal.SIGTERM, signal.SIGHUP)


def _stop_words(exc: KeyboardInterrupt) -> str:
    """How the one line of an interrupted command names its signal."""
    if not isinstance(exc, Terminated):
        return "interrupted"
    return "hung up (SIGHUP)" if exc.signum == signal.SIGHUP else "terminated (SIGTERM)"


def _stop_code(exc: KeyboardInterrupt) -> int:
    """128 + the signal's number: 130 SIGINT, 143 SIGTERM, 129 SIGHUP."""
    return 128 + (exc.signum if isinstance(exc, Terminated) else signal.SIGINT)


def _own_terminating_signals() -> dict:
    """Install :func:`_raise_terminated` for :data:`TERMINATING` (a SIGHUP ignored at start stays ignored);
    the handlers they had, to put back. Outside the main thread (main() called from a library): none."""
    previous = {}
    for s in TERMINATING:
        try:
            if s == signal.SIGHUP and signal.getsignal(s) == signal.SIG_IGN:
                continue
            previous[s] = signal.signal(s, _raise_terminated)
        except ValueError:  # not the main thread: leave the process's signals alone
            break
    return previous


#: delay before a signal whose exception could not be raised is set pending again [s] (callbacks
#: such as weakref callbacks take microseconds; the signal tests allow a second to stop)
REDELIVER_AFTER_S = 0.02


@contextlib.contextmanager
def _interrupts_redelivered():
    """Deliver again a SIGINT, SIGTERM or SIGHUP whose exception Python could not raise.

    A signal's handler runs wherever the main thread is. If that is a weakref callback or a
    ``__del__``, Python cannot propagate its ``KeyboardInterrupt`` (or :class:`Terminated`): the
    exception is "unraisable", printed with a traceback, and the command would go on as if no signal had
    come (one possible cause of a test's 200-rotation run not stopping within 30 s of SIGINT, seen once on
    a busy machine). While the command runs,
    ``sys.unraisablehook`` hands such an exception's signal back to the main thread: a helper thread
    sets it pending (``_thread.interrupt_main``) ``REDELIVER_AFTER_S`` later, when the main thread has
    left the callback (the hook runs inside it, and a signal set pending at once would raise into the
    hook), and the handler raises it again there; a signal that lands in a callback again comes back
    again. Every other unraisable exception goes to the previous hook. Yields the :class:`_Swallowed`
    signal: a command that fails while a signal waits there (the callback that swallowed it could not
    finish its work) ends as that signal (:func:`main` takes it, and it is not delivered again)."""
    import _thread
    import threading
    import time

    previous = sys.unraisablehook
    swallowed = _Swallowed()

    def deliver(signum):
        time.sleep(REDELIVER_AFTER_S)
        with swallowed.lock:  # unless taken meanwhile by the command's failure (see main)
            if swallowed.signum == signum:
                swallowed.signum = None
                _thread.interrupt_main(signum)

    def hook(unraisable):
        exc = unraisable.exc_value
        if isinstance(exc, KeyboardInterrupt):
            signum = exc.signum if isinstance(exc, Terminated) else signal.SIGINT
            with swallowed.lock:
                swallowed.signum = signum
            threading.Thread(target=deliver, args=(signum,), daemon=True).start()
        else:
            previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield swallowed
    finally:
        sys.unraisablehook = previous


class _Swallowed:
    """A signal whose exception a callback swallowed, while it waits to be delivered again
    (:func:`_interrupts_redelivered`): ``signum``, or None."""

    def __init__(self):
        import threading

        self.lock = threading.Lock()
        self.signum = None

    def take(self):
        """The waiting signal, or None; it will not be delivered again."""
        with self.lock:
            signum, self.signum = self.signum, None
        return signum


def _one_line(exc: BaseException) -> str:
    from bearingsim.outputs import printable

    return printable(str(exc), keep_newlines=False)


def _stdout_to_devnull() -> None:
    """Point file descriptor 1 at /dev/null: what is still buffered for a reader that has gone (a pipe
    into ``head``) is dropped at exit instead of failing there with "Exception ignored ... BrokenPipeError"."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


def _stdout_lost(exc: OSError, written) -> None:
    """Standard output failed (``> /dev/full``) after the command wrote its archive: exit 2 means "no
    archive", so say on stderr that the archive is complete and keep the command's exit code."""
    _stdout_to_devnull()
    with contextlib.suppress(OSError, ValueError):
        print(f"bearingsim: cannot write to standard output ({_one_line(exc.strerror or exc)}); the archive "
              f"{written} is complete", file=sys.stderr)


class _NoteHandler(logging.Handler):
    """The library's notes (``logging`` records of the ``bearingsim`` loggers) on the command line's
    stderr, one line each as the library words them; the stream is looked up at each note (a test's
    captured stderr, a reconfigured one)."""

    def emit(self, record):
        try:
            print(self.format(record), file=sys.stderr)
        except Exception:  # noqa: BLE001 - a note must never end a command
            self.handleError(record)


@contextlib.contextmanager
def _notes_on_stderr():
    """While a command runs, the ``bearingsim`` loggers' notes go to stderr (and not on to the root
    logger); afterwards the loggers are as they were (main() called from a program leaves no handler)."""
    log = logging.getLogger("bearingsim")
    handler, before = _NoteHandler(), (log.level, log.propagate)
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    log.propagate = False
    try:
        yield
    finally:
        log.removeHandler(handler)
        log.setLevel(before[0])
        log.propagate = before[1]


#: the commands that run a model, whose first run on a machine compiles its kernels
_MODEL_COMMANDS = ("run", "rerun", "sweep", "crosscheck", "validate", "bench", "sensitivity", "uncertainty", "life")


def _compile_note(args):
    """Where a progress bar would be shown (a terminal, no -q) and the command runs a model: one line
    as numba starts to compile a kernel it has no cached copy of, so that the first run's tens of
    seconds of compiling are not silent."""
    if args.command not in _MODEL_COMMANDS or getattr(args, "dry_run", False) or not progress_wanted(args):
        return contextlib.nullcontext()
    from bearingsim import _jit

    return _jit.on_first_compile(_say_compiling)


def _say_compiling(module: str) -> None:
    model = next((m for m in ("multibody", "reduced") if f".{m}." in f"{module}."), None)
    what = f"the {model} model's kernels" if model else "bearingsim's compiled kernels"
    # \r and erase-to-end: the line replaces a progress bar already drawn, which draws itself again below
    print(f"\rbearingsim: note: compiling {what} for this machine, once: tens of seconds (later runs load "
          f"them from numba's cache)\033[K", file=sys.stderr)


def program() -> int:
    """The ``bearingsim`` program (its console script, ``python -m bearingsim``): :func:`main` of the process's
    arguments, which then ends with the code returned."""
    return main(exiting=True)


def main(argv: list[str] | None = None, *, exiting: bool = False) -> int:
    """Run one ``bearingsim`` command; return its exit code.

    Exit codes: 0 success, 2 bad input or an unwritable output (one line on stderr), 3 an unstable or
    unphysical run (no archive), 130 SIGINT, 143 SIGTERM, 129 SIGHUP (the line says what is complete: nothing, the
    archive, or every file once all were written); 0 also when
    the reader of the output goes away early (``bearingsim inspect x.h5 | head -1``), with nothing said,
    except for ``compare`` and ``rerun``, whose exit code is their verdict (0 identical, 1 differ) and
    stays so (``args.status``, set before they print). ``exiting``: the process ends when it returns
    (:func:`program`): once the exit code is decided SIGINT, SIGTERM and SIGHUP are ignored, not restored, so that
    a signal in its last moments neither ends it silently nor contradicts the line it printed.
    """
    args = build_parser().parse_args(argv)
    args.files_written = {}  # the files complete so far (outputs.recording_files), for an interrupted command's line
    previous = _own_terminating_signals()
    errors = {}
    for name in ("stdout", "stderr"):  # a C locale's ASCII stdout: a non-ASCII name is escaped, not a traceback
        stream = getattr(sys, name)
        with contextlib.suppress(AttributeError, ValueError, OSError):
            errors[name] = stream.errors
            stream.reconfigure(errors="backslashreplace")
    try:
        with (_interrupts_redelivered() as swallowed, outputs.command_line_owns_stderr(), _notes_on_stderr(),
              outputs.recording_files(args.files_written), _compile_note(args)):
            return _run_command(args, swallowed)
    except (OSError, UserError, SimulationUnstable, KeyboardInterrupt, MemoryError) as exc:
        if exiting:  # the outcome is decided: its line is not cut short
            _ignore_signals()
        return _failed(exc, args)
    finally:
        if exiting:
            _ignore_signals()
        else:
            for s, handler in previous.items():
                signal.signal(s, handler)
        for name, err in errors.items():
            with contextlib.suppress(AttributeError, ValueError, OSError):
                getattr(sys, name).reconfigure(errors=err)


def _ignore_signals() -> None:
    """SIGINT, SIGTERM and SIGHUP ignored from now on (the process ends with its exit code decided); a signal
    whose handler runs meanwhile (it came just before) changes nothing."""
    for _ in range(3):
        try:
            for s in (signal.SIGINT, *TERMINATING):
                signal.signal(s, signal.SIG_IGN)
            return
        except KeyboardInterrupt:  # a handler run between two of them: set them again
            continue
        except ValueError:  # not the main thread
            return


def _run_command(args, swallowed: _Swallowed) -> int:
    """The command's own function, then its output flushed (a reader gone early shows here, not in the
    interpreter's last flush)."""
    try:
        code = args.func(args)
        args.finished = True  # every file it writes is written (a signal from here on says so: _interrupted)
    except Exception as exc:
        signum = swallowed.take()
        if signum is None:
            raise
        # the signal came first, and its exception was swallowed in a callback that then could not
        # do its work (numba's compiler, called back from LLVM, left without the object it was
        # handed: "no compiled object yet"); the command failed of that: the signal ends it
        raise (KeyboardInterrupt() if signum == signal.SIGINT else Terminated(signum)) from exc
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        raise
    except OSError as exc:
        if getattr(args, "written", None) is None:
            raise
        _stdout_lost(exc, args.written)
    return code


def _failed(exc: BaseException, args) -> int:
    """The one line a failed command prints on stderr, and its exit code (:func:`main`'s list)."""
    if isinstance(exc, BrokenPipeError):  # output piped into e.g. `head`, which stopped reading: stop quietly
        _stdout_to_devnull()
        return getattr(args, "status", 0)  # compare and rerun: their verdict, decided before they print
    if isinstance(exc, UserError):
        print(f"bearingsim: error: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    if isinstance(exc, SimulationUnstable):
        print(f"bearingsim: unstable run, no archive written: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    if isinstance(exc, KeyboardInterrupt):  # SIGINT, or SIGTERM or SIGHUP (Terminated)
        return _interrupted(exc, args)
    if isinstance(exc, MemoryError):
        print("bearingsim: error: out of memory; run fewer numerics.rotations or a longer numerics.output_rate_hz "
              "interval", file=sys.stderr)
        return 2
    # OSError: a file the command reads or writes (validate/bench output folders, ...); one without an errno is
    # not the system's (h5py's of a damaged file, which bearingsim.archive names: never blamed on stdout)
    stdout = exc.filename is None and exc.errno is not None
    if getattr(args, "written", None) is not None and stdout:  # stdout, after the archive
        _stdout_lost(exc, args.written)
        return 0
    if exc.filename is None and exc.errno is None:
        print(f"bearingsim: error: {_one_line(exc)}", file=sys.stderr)
    elif exc.filename is None:  # standard output: the files bearingsim writes go through outputs, which names them
        print(f"bearingsim: error: cannot write to standard output ({_one_line(exc.strerror or exc)})",
              file=sys.stderr)
    else:
        print(f"bearingsim: error: {_one_line(exc.filename)}: {_one_line(exc.strerror or exc)}", file=sys.stderr)
    return 2


#: what an interrupted command has not written, by command ("no archive written" for the others)
_NOT_WRITTEN = {"animate": "no animation written", "report": "no report written",
                "plot": "its figures not all written", "wear": "its figures not all written", "life": "no stage run",
                "sweep": "before any case of the sweep ran (cases an earlier run kept are kept; the same command "
                         "runs it)"}
_NOT_WRITTEN.update({c: f"before any case of the {c} study ran (cases an earlier run kept are kept; the same command "
                        f"runs it)" for c in ("sensitivity", "uncertainty", "crosscheck", "validate")})


#: the commands whose cases run on the sweep engine, indexed in their folder's sweep.h5
_STUDY_COMMANDS = ("sweep", "sensitivity", "uncertainty", "crosscheck", "validate", "life")


#: the commands that write one file: once it is complete, all is written
_ONE_FILE = ("animate", "report")


def _interrupted(exc: KeyboardInterrupt, args) -> int:
    """SIGINT, SIGTERM or SIGHUP: what was kept, in one line (none when the terminal it would go to has gone);
    exit 130, 143 or 129."""
    with contextlib.suppress(OSError):
        _say_interrupted(exc, args)
    return _stop_code(exc)


def _say_interrupted(exc: KeyboardInterrupt, args) -> None:
    what = _stop_words(exc)
    written = getattr(exc, "archive_written", None) or getattr(args, "written", None)  # the archive is complete
    done = getattr(args, "files_written", {})  # the files complete (outputs.recording_files)
    # what a study kept, its cases done (studies.run_studies), or the case index a sweep or study wrote
    kept = getattr(exc, "resume_note", None) or _index_written(args, done)
    expected = (getattr(args, "expected", None) or ([written, *getattr(exc, "figures_expected", ())] if written else ())
                or (list(done) if getattr(args, "command", None) in _ONE_FILE else ()))
    if done and (getattr(args, "finished", False)
                 or (expected and all(os.path.abspath(p) in done for p in expected))):
        names = list(done.values())
        shown = ", ".join(names[:6]) + (f" and {len(names) - 6} more" if len(names) > 6 else "")
        print(f"bearingsim: {what} once its files were written: {shown} {'is' if len(names) == 1 else 'are'} "
              f"complete", file=sys.stderr)
    elif written is not None:
        print(f"bearingsim: {what} while drawing figures: the archive {written} is complete; figures not "
              f"all written ('bearingsim plot {written}' draws them)", file=sys.stderr)
    elif kept is not None:  # worded as the other studies' (cli_common.report_study)
        name = signal.Signals(_stop_code(exc) - 128).name
        print(f"bearingsim: {args.command} interrupted ({name}): {kept}; run the same command again to resume",
              file=sys.stderr)
    else:
        print(f"bearingsim: {what}, {_NOT_WRITTEN.get(getattr(args, 'command', None), 'no archive written')}",
              file=sys.stderr)


def _index_written(args, done: dict) -> str | None:
    """What a sweep or study that wrote its case index (``DIR/sweep.h5``) this time kept, when a signal ends it
    out of the sweep's own handlers: after its cases ran and their index was written, before the command
    returned (its lock released, its table printed). Said as "before any case of the sweep ran" before; None
    for another command or when no index was written (the signal came before the cases)."""
    if getattr(args, "command", None) not in _STUDY_COMMANDS:
        return None
    index = next((path for path in done if os.path.basename(path) == "sweep.h5"), None)
    if index is None:
        return None
    beside = [os.path.basename(p) for p in done  # the folder's other files (a study's tables, a sweep's map)
              if os.path.dirname(p) == os.path.dirname(index) and os.path.basename(p) not in ("sweep.h5", "sweep.csv")]
    also = f", and {', '.join(beside)} {'is' if len(beside) == 1 else 'are'} complete" if beside else ""
    return (f"its case index {done[index]} is written, with every case that ran ('bearingsim table {done[index]}' "
            f"prints them){also}")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(program())
