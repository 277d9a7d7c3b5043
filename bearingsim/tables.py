"""Tables for the terminal: summary numbers of several runs side by side, with units, standard errors
and significance marks (``bearingsim table``, ``bearingsim compare A B C ...``, the end of
``bearingsim sweep``); and a study folder's own table (:func:`study_of`, :func:`study_text`).

A table has one row per run (an archive, or a case of a sweep's or study's index ``sweep.h5``), label
columns (the file, the swept keys or the scenario keys that differ) and number columns (summary
numbers). ``I_dec_mean_Ns`` and ``I_acc_mean_Ns`` carry their standard error, the one estimator of
:mod:`bearingsim.stats` (batch means over rotations), and a mark:

    ``*`` when |x - x_ref| > t sqrt(SE² + SE_ref²), x_ref the first row with a number

(t: Student's 97.5 % quantile of the Welch-Satterthwaite degrees of freedom of the two standard errors,
each from its number of batch means less one: 2.31 for two runs of 5 or more rotations, 2.78 against an
exact reference (SE 0); so 5 % of differences of equal true means are marked), and more than round-off,
1e-9 of the larger (:func:`bearingsim.stats.significant`, the one rule); no mark where the difference is
within that, and none where a standard error is missing (fewer than 2 rotations: NaN) so the difference
cannot be judged. Impulses are shown in mN s; every other column in
the unit its key names.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bearingsim.errors import UserError
from bearingsim.wording import by_kind, counted, distinct_texts, note_kind, shown_as
from bearingsim.stats import (BATCHES, ROUND_OFF_REL, SEM_UNITS, SIGNIFICANCE_LEVEL, SUMMARY_SEM_OF, sem_batches,
                              significant, with_error)

#: the rule of the marks (:func:`bearingsim.stats.significant`), printed under a table
RULE = (f"* : |x - x_ref| > t sqrt(SE^2 + SE_ref^2) and > {ROUND_OFF_REL:g} max(|x|, |x_ref|) (round-off), "
        f"x_ref the first row with a number (named below), t Student's {0.5 + SIGNIFICANCE_LEVEL / 2:.1%} quantile of the "
        "Welch-Satterthwaite degrees of freedom (each SE: batch means over rotations, batches - 1; "
        "docs/statistics.md); no mark: within that, or no SE to judge by")
#: the line above the key of a table's ``[k]`` marks, the runs' notes (:attr:`Table.footnotes`)
NOTES_HEAD = ("notes: the runs' notes (of a run that is plausible but not clean, docs/reliability.md; of a step check "
              "asked for, docs/multibody.md):")
#: the note above a table of archives of both models
MIXED_MODELS = ("rows of both models: the reduced model's '± 0' is its exactness (every rotation repeats its one "
                "pass), not a measured error, and a mark against a whole-bearing row is the difference of the models, "
                "which 'bearingsim crosscheck' takes apart assumption by assumption (docs/crosscheck.md)")
#: the line under the rule of the marks of a table whose rows are all of the reduced model
REDUCED_EXACT = ("reduced model: each case is one exact pass, repeated in every rotation, so its '± 0' is no "
                 "measured error and a mark is any difference beyond round-off")
#: number columns shown by default, those present
DEFAULT_COLUMNS = ("I_dec_mean_Ns", "I_acc_mean_Ns", "first_impact_speed_m_s", "cage_slip", "cage_rest_angle_deg",
                   "load_zone_half_angle_deg", "wear_front_mean_m3_h", "wear_rear_mean_m3_h")
#: summary keys with a standard error (the key of the error)
SEM_OF = {**SUMMARY_SEM_OF, "wear_front_mean_m3_h": "wear_front_sem_m3_h", "wear_rear_mean_m3_h": "wear_rear_sem_m3_h"}

#: the summary keys a finished run is read by first (``bearingsim run`` prints them, the report heads its summary)
HEADLINE_KEYS = ("I_dec_mean_Ns", "I_acc_mean_Ns", "first_impact_speed_m_s", "cage_slip", "load_zone_half_angle_deg",
                 "land_normal_impulse_mean_Ns")


def headline(result) -> list[tuple[str, float, float | None, str]]:
    """The headline numbers of a run (:data:`HEADLINE_KEYS` that it has): ``(key, value, standard error or None,
    words)``, the words in the units the tables show (:func:`shown_as`): the mean impulses per pocket and cage
    rotation in mN s with their standard errors (:func:`bearingsim.stats.result_standard_errors`: batch means
    over the recorded rotations; the reduced model's are exact, every rotation repeating one pass), the first
    impact speed, the cage slip in per cent and the load zone's half angle with theirs; ``""`` for a number shown
    as stored."""
    from bearingsim.stats import result_standard_errors

    summary, units = result.summary, result.summary_units
    se = result_standard_errors(result)
    rotations = len(result.per_rotation["I_dec"])
    rows = []
    for key in HEADLINE_KEYS:
        if key not in summary:
            continue
        v, err = summary[key], se.get(SEM_OF.get(key, ""))
        scale, unit = shown_as(key, units.get(key, "1"))
        words = ""
        if err is None:  # no standard error: an archive of an earlier version, a cage turned at its epicyclic speed
            words = f"{v * scale:.4g} {unit}" if key == "cage_slip" else ""
        else:
            per = f"{unit} per pocket and cage rotation" if key.endswith("_Ns") else unit
            if err == 0.0:
                words = f"{v * scale:.5g} {per}"
            elif err != err and v != v and key == "first_impact_speed_m_s":  # no first impact recorded at all
                words = "none recorded"
            elif err != err:  # NaN: one recorded rotation gives no scatter
                words = f"{v * scale:.5g} {per}; no standard error from {counted(rotations, 'recorded rotation')}"
            else:
                words = (f"{with_error(v * scale, err * scale)} {per}; standard error, batch means over {rotations} "
                         f"recorded rotations")
        rows.append((key, v, err, words))
    return rows


@dataclass
class Table:
    """Rows of runs: ``labels[name]`` (text per row), ``numbers[key]`` (float per row, SI),
    ``units[key]``; ``notes`` are lines printed above the table; ``footnotes`` (row -> text) are printed
    under it for the rows shown, each marked in the row's label column ``notes`` (``[1]``, ``[2]``, ...);
    ``batches`` (per row) the number of batch means its standard errors came from (their degrees of freedom
    plus one, :func:`bearingsim.stats.sem_batches`; None: :data:`bearingsim.stats.BATCHES` each); ``exact``:
    every row is of the reduced model (:data:`REDUCED_EXACT` is printed with the rule of the marks)."""

    label_names: list[str]
    labels: dict[str, list[str]]
    numbers: dict[str, np.ndarray]
    units: dict[str, str]
    notes: list[str] = field(default_factory=list)
    footnotes: dict[int, str] = field(default_factory=dict)
    batches: list[int] | None = None
    exact: bool = False

    def __len__(self) -> int:
        return len(next(iter(self.labels.values()))) if self.labels else 0


def table_of_index(path) -> Table:
    """The table of a sweep's or study's index (``DIR/sweep.h5`` or the file): one row per case,
    labelled by its swept keys (and its status where it is not done or cached)."""
    from bearingsim.sweeps.index import FIXED, index_batches, notes_of, read_index, unit_of

    cols, meta = read_index(path)
    n = len(cols["case"])
    axes = [k for k in meta["axes"] if k in cols]
    status = [str(s) for s in cols["status"]]
    names = list(axes)
    labels = {k: distinct_texts(list(cols[k])) for k in axes}
    if any(s not in ("done", "cached") for s in status):
        names.append("status")
        labels["status"] = status
    if not names:
        names, labels = ["case"], {"case": [str(c) for c in cols["case"]]}
    numbers = {k: np.asarray(cols[k], float) for k in meta["columns"] if k not in ("case", *FIXED, *axes)
               and np.asarray(cols[k]).dtype.kind == "f"}
    notes = [f"{path}: {counted(n, 'case')}" + (f" of a sweep of {meta['scenario']}" if meta.get("scenario") else "")]
    footnotes = _run_notes([notes_of(c) for c in cols.get("notes", [""] * n)], names, labels)
    return Table(names, labels, numbers, {k: unit_of(k) for k in numbers}, notes, footnotes,
                 index_batches(cols, meta, n), exact=_index_models(cols, meta) == {"reduced"})


def _index_models(cols: dict, meta: dict) -> set:
    """The models of an index's rows: the swept ``model`` column's, else the base scenario's (an empty set when
    neither says)."""
    import tomllib

    if "model" in cols:
        return {str(m) for m in cols["model"]}
    try:
        model = tomllib.loads(meta.get("scenario_toml") or "").get("model")
    except tomllib.TOMLDecodeError:
        return set()
    return {model} if model else set()


def _run_notes(found: list[list[str]], names: list[str], labels: dict) -> dict[int, str]:
    """The runs' notes (``found``, a list per row: an index's ``notes`` column, an archive's
    ``/bearingsim/notes``) as footnotes, each row with notes marked ``[k]`` in a label column ``notes`` added
    to ``names`` and ``labels`` (none when no row has notes). Rows with notes of the same kind share one mark,
    whose footnote is keyed by the first of them (a study's stages or cases often carry one note alike, or notes
    that differ in their numbers only, :func:`bearingsim.wording.note_kind`: then the first row's words, saying so)."""
    rows = [i for i, lines in enumerate(found) if lines]
    if not rows:
        return {}
    texts = ["; ".join(found[i]) for i in rows]
    kinds = by_kind(texts)  # the notes' kind -> (the first noted row, how many, whether their numbers differ)
    number = {kind: k for k, kind in enumerate(kinds, 1)}
    names.append("notes")
    labels["notes"] = [f"[{number[note_kind('; '.join(lines))]}]" if lines else "" for lines in found]
    return {rows[j]: f"[{number[kind]}] {texts[j]}" + (
        f" (the numbers of the first row marked [{number[kind]}]; the others differ in theirs)" if differ else "")
        for kind, (j, _, differ) in kinds.items()}


def table_of_archives(paths) -> Table:
    """The table of run archives, one row each: labelled by the file and the scenario keys that
    differ between them (:func:`archive_labels`: at most 4 as columns; the others listed in ``notes``), and its notes' mark
    (:func:`_run_notes`); the standard errors computed from each archive's per-rotation impulses
    (:func:`bearingsim.stats.result_standard_errors`)."""
    from bearingsim.simulation import TABLED, load
    from bearingsim.stats import result_standard_errors
    from bearingsim.wording import run_notes

    results = [load(p, only=TABLED) for p in paths]
    labels, differ = archive_labels(paths, [r.scenario.raw for r in results])
    names = list(labels)
    keys = list(dict.fromkeys(k for r in results for k, v in r.summary.items() if _is_number(v)))
    numbers, units = {}, {}
    for k in keys:
        numbers[k] = np.array([float(r.summary.get(k, math.nan)) for r in results])
        units[k] = next((r.summary_units.get(k) for r in results if k in r.summary_units), "1")
    errors = [result_standard_errors(r) for r in results]
    # those of stats.summary_standard_errors (an archive's summary has no wear rates: a sweep's index does)
    for k in dict.fromkeys(k for e in errors for k in e):
        numbers[k] = np.array([e.get(k, math.nan) for e in errors])
        units[k] = SEM_UNITS[k]
    notes = []
    rest = [k for k in differ if k not in labels and k != "name"]
    if rest:
        notes.append("scenario keys that also differ: " + ", ".join(rest))
    if not differ and len(results) > 1:
        notes.append("scenarios: identical")
    models = {getattr(r.scenario, "model", None) for r in results}
    if "reduced" in models and len(models) > 1:
        notes.append(MIXED_MODELS)
    footnotes = _run_notes([run_notes(r.notes) for r in results], names, labels)  # worded as an index's
    batches = [sem_batches(np.shape(r.per_rotation["I_dec"])[0]) for r in results]
    return Table(names, labels, numbers, units, notes, footnotes, batches, exact=models == {"reduced"})


#: the most scenario keys that differ a table of archives shows as label columns (the others in a note)
SHOWN_KEYS = 4


def archive_labels(paths, scenarios) -> tuple[dict[str, list[str]], list[str]]:
    """The label columns of a table of archives (``bearingsim table``, ``bearingsim wear``), a row per path:
    ``archive`` (:func:`distinguishing_labels`) and the first :data:`SHOWN_KEYS` scenario keys that differ
    between the raw scenario tables ``scenarios`` (``name`` aside), their values as the tables write them
    (:func:`distinct_texts`, ``(unset)`` where a scenario lacks the key); and every key that differs."""
    from bearingsim.scenario import differing_keys

    rows = differing_keys(*scenarios)
    labels = {"archive": distinguishing_labels(paths)}
    for row in [row for row in rows if row[0] != "name"][:SHOWN_KEYS]:
        labels[row[0]] = distinct_texts(list(row[1:]))
    return labels, [row[0] for row in rows]


def distinguishing_labels(paths) -> list[str]:
    """A label per path: its file name where that is unique among ``paths``, else the shortest ending of
    the path (``cases/<hash>.h5``, ``run1/cases/<hash>.h5``) that no other path shares, so two files of
    one name in different folders get different labels. The same file given twice keeps one label."""
    import os

    parts = [Path(os.path.abspath(p)).parts for p in paths]  # the folders as given, links not followed
    labels = []
    for i, mine in enumerate(parts):
        others = [q for q in parts if q != mine]
        k = next((k for k in range(1, len(mine) + 1) if all(q[-k:] != mine[-k:] for q in others)), len(mine))
        labels.append(str(Path(*mine[-k:])) if k < len(mine) else str(Path(*mine)))
    return labels


def _is_number(v) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


#: a study's table files, the most specific first: a study folder also holds the case index of its cases
#: (``sweep.h5``), which a study's table is about; (kind, file name)
STUDY_TABLES = (("life", "life.h5"), ("crosscheck", "crosscheck.h5"), ("sensitivity", "sensitivity.h5"),
                ("uncertainty", "uncertainty.h5"), ("validate", "fig9_idec_vs_speed.csv"))
#: what each kind of study is called in messages
STUDY_NAMES = {"life": "life study", "crosscheck": "cross-check", "sensitivity": "sensitivity study",
               "uncertainty": "uncertainty study", "validate": "validate"}


def _is_study_table(kind: str, path: Path) -> bool:
    from bearingsim import archive

    if kind == "validate":
        from bearingsim.studies.validate import is_validate_table

        return is_validate_table(path)
    from bearingsim.studies import crosscheck, life, sensitivity, uncertainty

    fmt = {"life": life.LIFE_FORMAT, "crosscheck": crosscheck.INDEX_FORMAT, "sensitivity": sensitivity.INDEX_FORMAT,
           "uncertainty": uncertainty.INDEX_FORMAT}[kind]
    return archive.is_table_file(path, fmt)


def studies_of(path) -> list[tuple[str, Path]]:
    """``(kind, table file)`` of every study whose table a folder holds (life, cross-check, sensitivity,
    uncertainty, validate), in the order of :data:`STUDY_TABLES` (one folder may hold several:
    :func:`bearingsim.studies.run_studies` of a cross-check and the Fig. 9 study), or of a table file
    itself; empty for anything else (a sweep folder, a case index, an archive)."""
    p = Path(path)
    if not p.exists():
        return []
    folder = p if p.is_dir() else p.parent
    return [(kind, folder / name) for kind, name in STUDY_TABLES
            if (p.is_dir() or p.name == name) and _is_study_table(kind, folder / name)]


def study_of(path) -> tuple[str, Path] | None:
    """The first of :func:`studies_of` (the most specific study table of a folder), or None."""
    found = studies_of(path)
    return found[0] if found else None


def study_text(kind: str, file: Path) -> str:
    """A study's own table for the terminal, as its command prints it at its end, under one line naming
    the file and the study (``kind`` and ``file`` as :func:`study_of` gives them)."""
    import json
    import tomllib

    from bearingsim.studies import crosscheck, life, sensitivity, uncertainty

    if kind == "validate":
        from bearingsim.studies.validate import format_tables, read_validate

        return (f"{file.parent}: validate: the reduced model's Fig. 9 analog and the rig scene against it "
                f"(docs/validation.md)\n" + format_tables(read_validate(file.parent)))
    if kind == "crosscheck":
        rows, meta = crosscheck.read_table(file)
        speeds = len({r["rpm"] for r in rows})
        return "\n".join([f"{file}: cross-check of {meta.get('scenario_name', '?')}: {counted(speeds, 'speed')} x "
                          f"{len(crosscheck.RUNGS)} rungs; impulses per pocket and cage rotation, mean over all pockets ± "
                          "batch-means standard error", crosscheck.format_table(rows),
                          *crosscheck.verdicts(rows, crosscheck.table_rotations(meta))])
    if kind == "sensitivity":
        rows, meta = sensitivity.read_table(file)
        keys = len(dict.fromkeys(r["key"] for r in rows))
        runs = sensitivity.runs_text(meta.get("step", 0), sensitivity.ran_half_steps(rows), keys, meta.get("runs"))
        head = [f"{file}: sensitivity of {meta.get('scenario_name', '?')}: {runs}"]
        if meta.get("left_out"):
            head.append(f"left out: {meta['left_out']}")
        return "\n".join([*head, sensitivity.format_table(rows)])
    if kind == "uncertainty":
        rows, spreads, meta = uncertainty.read_table(file)
        keys = len(json.loads(meta.get("keys", "[]")))
        return (f"{file}: uncertainty of {meta.get('scenario_name', '?')}: {counted(keys, 'key')}, N = "
                f"{meta.get('samples', '?')} ({counted(int(meta.get('runs', 0)), 'run')}), seed {meta.get('seed', '?')}\n"
                + uncertainty.format_table(spreads, rows))
    cols, attrs = life.read_life(file)
    name = tomllib.loads(attrs["scenario"]).get("name", "?") if attrs.get("scenario") else "?"
    return life.format_history(cols, f"{file}: life of {name} to {attrs.get('limit', '?')}", attrs)


def format_paths(paths, columns=None) -> str:
    """What ``bearingsim table PATHS`` prints: for a study folder or its table file, the study's own table
    (:func:`study_text`; ``columns`` refused: its columns are its own), of a folder holding several studies'
    tables each of them, in the order of :func:`studies_of`, under a line naming them; else the summary
    table of a sweep folder or index, or of run archives (:func:`table_of`, :func:`format_table`)."""
    paths = [Path(paths)] if isinstance(paths, (str, Path)) else [Path(p) for p in paths]
    found = studies_of(paths[0]) if len(paths) == 1 else []
    if not found:
        return format_table(table_of(paths), columns=columns)
    folder = found[0][1].parent
    if columns:
        what = (f"{found[0][1]} is a {STUDY_NAMES[found[0][0]]}'s table, whose columns are its own" if len(found) == 1
                else f"{folder} holds {len(found)} studies' tables, whose columns are their own: {_named(found)}")
        raise UserError(f"--columns: {what}; give {folder / 'sweep.h5'} for its cases' summary numbers")
    texts = [study_text(kind, file) for kind, file in found]
    if len(found) == 1:
        return texts[0]
    head = (f"{folder}: {len(found)} studies' tables, each below: {_named(found)}; "
            f"'bearingsim table {folder / 'FILE'}' prints one")
    return "\n\n".join([head, *texts])


def _named(found) -> str:
    """``cross-check (crosscheck.h5), validate (fig9_idec_vs_speed.csv)``"""
    return ", ".join(f"{STUDY_NAMES[kind]} ({file.name})" for kind, file in found)


def table_of(paths) -> Table:
    """The summary table of ``paths``: one folder or index file (a sweep's or study's ``sweep.h5``: one
    row per case; of a study folder, the case index, which ``bearingsim table`` prints only for
    ``DIR/sweep.h5``: :func:`format_paths`), or run archives (one-line UserError otherwise)."""
    from bearingsim import archive
    from bearingsim.sweeps.index import INDEX_FORMAT

    paths = [Path(paths)] if isinstance(paths, (str, Path)) else [Path(p) for p in paths]
    if len(paths) == 1 and paths[0].is_dir():
        index = paths[0] / "sweep.h5"
        if not index.is_file():
            raise UserError(f"{paths[0]}: holds no sweep.h5 (not a sweep or study folder); give the folder of a "
                            f"sweep or of a study ({', '.join(STUDY_NAMES.values())}), or archives")
        return table_of_index(index)
    indexes = [p for p in paths if archive.is_table_file(p, INDEX_FORMAT)]
    if indexes and len(paths) == 1:
        return table_of_index(paths[0])
    if indexes:
        raise UserError(f"{indexes[0]}: a sweep index among archives; give one folder or index, or archives only")
    for p in paths:
        if p.is_dir():
            raise UserError(f"{p}: a folder among files; give one folder, or archives")
    return table_of_archives(paths)


def _bare(key: str) -> str:
    """A key without its unit suffix (``I_dec_mean_Ns`` -> ``I_dec_mean``)."""
    from bearingsim.sweeps.index import UNITS

    for suffix, _ in UNITS:
        if key.endswith(suffix):
            return key[: -len(suffix)]
    return key


def column_cells(table: Table, key: str) -> tuple[str, list[str]]:
    """Header and cells of number column ``key`` (with its standard error and marks when it has one,
    against the first row that has a number)."""
    unit = table.units.get(key, "1")
    scale, shown = shown_as(key, unit)
    head = _bare(key) + ("" if shown == "1" else f" [{shown}]")
    x = table.numbers[key]
    finite = np.flatnonzero(np.isfinite(x))
    ref = int(finite[0]) if finite.size else None
    se = table.numbers.get(SEM_OF.get(key, ""), None)
    batches = table.batches or [BATCHES] * len(x)
    cells = []
    for i, v in enumerate(x):
        if not math.isfinite(v):
            cells.append("-")
            continue
        if se is not None:
            e = se[i]
            text = with_error(v * scale, e * scale)
            mark = None if ref is None or i == ref else significant(v, e, x[ref], se[ref], batches[i], batches[ref])
            text += " *" if mark else "  "
        else:
            text = f"{v * scale:.4g}"
        cells.append(text)
    return head, cells


def column_keys(table: Table) -> list[str]:
    """The number columns ``columns`` of :func:`format_table` (``--columns``) may name, in the table's order:
    every summary number of its runs, the standard errors (``I_dec_sem_Ns``, ``I_acc_sem_Ns``,
    ``first_impact_speed_sem_m_s``, ``cage_slip_sem``, ``load_zone_half_angle_sem_deg``) included; the one list its
    refusal of another name prints."""
    return list(table.numbers)


def shown_key(table: Table, name: str) -> str:
    """The summary key of column ``name`` as ``--columns`` gives it: the key itself (``I_dec_mean_Ns``), or the
    name the table's header shows for it, without its unit (``I_dec_mean``, ``cage_rest_angle``,
    ``wear_rear_mean``), when exactly one of the table's numbers has that name; any other name as given."""
    if name in table.numbers:
        return name
    keys = [k for k in table.numbers if _bare(k) == name]
    return keys[0] if len(keys) == 1 else name


def format_table(table: Table, columns=None, max_rows: int | None = None) -> str:
    """The table as aligned text: label columns left-aligned, number columns right-aligned, the rule
    of the marks below it when a column has standard errors. ``columns``: summary keys to show
    (default: :data:`DEFAULT_COLUMNS` present); ``max_rows``: at most this many rows (then a line
    saying how many are left out)."""
    if columns:
        accepted = column_keys(table)
        columns = [shown_key(table, k) for k in columns]
        missing = [k for k in columns if k not in accepted]
        if missing:
            raise UserError(f"--columns: {', '.join(missing)}: not a number of these runs (they have: "
                            f"{', '.join(accepted)})")
    keys = list(columns) if columns else [k for k in DEFAULT_COLUMNS if k in table.numbers]
    n = len(table)
    heads = [*table.label_names]
    cols = [table.labels[k] for k in table.label_names]
    for key in keys:
        head, cells = column_cells(table, key)
        heads.append(head)
        cols.append(cells)
    shown = n if max_rows is None else min(n, max_rows)
    widths = [max([len(h)] + [len(c) for c in col[:shown]]) for h, col in zip(heads, cols)]
    nlab = len(table.label_names)

    def line(cells):
        return "  ".join(c.ljust(w) if j < nlab else c.rjust(w) for j, (c, w) in enumerate(zip(cells, widths))).rstrip()

    out = [*table.notes, line(heads)]
    out += [line([col[i] for col in cols]) for i in range(shown)]
    if shown < n:
        out.append(f"... {n - shown} more rows ('bearingsim table' prints them all)")
    noted = [text for i, text in sorted(table.footnotes.items()) if i < shown]
    if noted:
        out.append(NOTES_HEAD)
        out += noted
    if any(k in SEM_OF for k in keys):
        out += [RULE, *([REDUCED_EXACT] if table.exact else []), reference_line(table, [k for k in keys if k in SEM_OF])]
    return "\n".join(out)


def reference_line(table: Table, keys: list[str]) -> str:
    """The line under a table naming its row x_ref of each of ``keys`` (the columns with standard errors):
    the first row with a number, the first archive given (the rows keep the order given) or the index's
    first case: ``x_ref: the row c.h5 (the first archive given)``."""
    names = [k for k in table.label_names if k not in ("notes", "status")]
    refs: dict[int, list[str]] = {}
    for key in keys:
        finite = np.flatnonzero(np.isfinite(table.numbers[key]))
        if finite.size:
            refs.setdefault(int(finite[0]), []).append(_bare(key))
    if not refs:
        return "x_ref: none (no row has a number)"
    archives = names[:1] == ["archive"]

    def row(i):
        if archives:
            return table.labels["archive"][i] + (" (the first archive given)" if i == 0 else "")
        return ", ".join(f"{k} = {table.labels[k][i]}" for k in names) + (" (the first case)" if i == 0 else "")

    if len(refs) == 1:
        return f"x_ref: the row {row(next(iter(refs)))}"
    return "x_ref: " + "; ".join(f"of {', '.join(ks)}, the row {row(i)}" for i, ks in refs.items())
