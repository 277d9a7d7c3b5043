"""One self-contained HTML report of a run archive, a sweep folder or a study folder (cross-check,
validate, sensitivity, uncertainty, life): ``bearingsim report PATH -o report.html``,
``bearingsim.report(path, out)``.

The page gathers what the other commands print and draw, read from the files alone: the figures
(the same figure functions as ``bearingsim plot``, the sweeps' and the studies', embedded as PNG data
URIs), the animation of an archive that holds the bodies' motion (:mod:`bearingsim.animation`, when
installed), the tables (with the standard errors and marks of ``bearingsim table``), the plausibility
checks, the scenario as TOML and the provenance, under a table of contents. Nothing is fetched when
it is read: it works offline and prints to PDF from the browser (print styles: one section after
another, no figure split across pages). The page is a Jinja2 template shipped with the package
(``bearingsim/templates/report.html.j2``), every value autoescaped; ``docs/report.md``.

The same inputs give the same bytes (no clock in the page: the run's own time is in its provenance).
"""
from __future__ import annotations

import base64
import math
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bearingsim.errors import UserError, check_path
from bearingsim.wording import counted, listed, run_notes

#: the first bytes of every report bearingsim writes: what ``-o`` may replace
SIGNATURE = b"<!DOCTYPE html>\n<!-- bearingsim report"
SUFFIXES = (".html", ".htm")
#: most rows of a table in the page (a 10 000-case sweep: 'bearingsim table' prints them all)
MAX_ROWS = 200
#: the formats of the embedded animation and how the page shows them
ANIMATIONS = {"gif": ("image/gif", "img"), "mp4": ("video/mp4", "video")}
KINDS = ("run", "sweep", "crosscheck", "validate", "sensitivity", "uncertainty", "life", "studies")


@dataclass
class Section:
    """One section of the page: an anchor ``id``, a title and its blocks (dicts with a ``kind``: text,
    list, table, figure, animation, checks, pre; see the template)."""

    id: str
    title: str
    blocks: list[dict] = field(default_factory=list)


# --- what PATH is -------------------------------------------------------------------------------
def kind_of(path) -> tuple[str, Path]:
    """``(kind, file)`` of ``path``: a run archive (``"run"``, the archive) or a folder (or its table
    file) of a study (life, cross-check, sensitivity, uncertainty, validate:
    :func:`bearingsim.tables.study_of`) or of a sweep (the kind and its table file; a study folder also
    holds the sweep index of its cases, reported as a sweep when given as ``DIR/sweep.h5``); a one-line
    UserError for anything else."""
    from bearingsim import archive, tables
    from bearingsim.sweeps.index import INDEX_FORMAT

    p = Path(path)
    if not p.exists():
        raise UserError(f"{p}: file or folder not found")
    if p.is_file() and archive.is_archive(p):
        return "run", p
    found = tables.study_of(p)
    if found is not None:
        return found
    index = p / "sweep.h5" if p.is_dir() else p
    if index.name == "sweep.h5" and index.is_file() and archive.is_table_file(index, INDEX_FORMAT):
        return "sweep", index
    if not p.is_dir():  # a file: what is wrong with it, as the commands that read an archive say
        raise (archive.scenario_file_error(p) or archive.own_table_error(p, "report") or archive.unreadable_error(p)
               or _not_an_archive(p))
    candidates = [p / n for n in ("sweep.h5", *(name for _, name in tables.STUDY_TABLES))]
    raise next((e for e in map(archive.unreadable_error, candidates) if e is not None), None) or UserError(
        f"{p}: not a bearingsim archive, nor a sweep, cross-check, validate, sensitivity, uncertainty or life folder "
        f"(no sweep.h5, crosscheck.h5, fig9_idec_vs_speed.csv, sensitivity.h5, uncertainty.h5 or life.h5 in it)")


def _not_an_archive(p: Path) -> UserError:
    """Why the file ``p`` is not a run archive (truncated, not HDF5, another program's HDF5, incomplete:
    :func:`bearingsim.archive.open_archive`'s one line), where it is neither a study's nor a sweep's table."""
    from bearingsim import archive

    try:
        archive.open_archive(p).close()
    except UserError as exc:
        return exc
    return UserError(f"{p}: not a bearingsim archive, nor a sweep's or a study's table")


# --- the report ---------------------------------------------------------------------------------
def report(path, out=None, *, animation: str | None = "gif") -> Path:
    """Write the report of ``path`` (a run archive, or a sweep or study folder) to ``out`` (``.html``;
    None: :func:`default_output`, beside ``path``), atomically; return ``out``. ``animation``: the format
    of an archive's embedded animation, ``"gif"`` (an image: every browser, printed as its frame) or
    ``"mp4"`` (a video, smaller), None for none. One-line UserError for a PATH that is none of these and
    for an output that cannot be written."""
    from bearingsim import tables
    from bearingsim.outputs import atomic_file, exclusive_output

    if animation is not None and animation not in ANIMATIONS:
        raise UserError(f"animation {animation!r}: give one of {', '.join(ANIMATIONS)} or None")
    check_path(path, "path", "an archive, a sweep or a study folder")
    if out is not None:
        check_path(out, "out", "the report (.html)")
    out = check_output(default_output(path) if out is None else out, path)
    with exclusive_output(out, "report"):  # one command writes it: a second is refused, not silently replaced
        kind, file = kind_of(path)
        found = tables.studies_of(path) if kind != "run" else []
        if len(found) > 1:  # a folder of several studies (run_studies of a cross-check and Fig. 9): every one
            kind = "studies"
            title, sections = _studies_sections(found)
        else:
            title, sections = _sections(kind, file, animation)
        html = render(title, str(path), kind, sections)
        try:
            with atomic_file(out) as fh:
                fh.write(html.encode("utf-8"))
        except OSError as exc:
            raise UserError(f"{out}: cannot write the report ({exc.strerror or exc})") from None
    return out


def default_output(path) -> Path:
    """Where the report of ``path`` goes by default: beside it, named after it (``outputs/run.h5`` ->
    ``outputs/run.html``, the folder ``outputs/sweep`` -> ``outputs/sweep.html``)."""
    p = Path(path)
    if p.name in ("", ".", ".."):  # "." or "..": the folder's own name
        p = p.resolve()
    return p.with_suffix(".html") if p.is_file() else p.with_name(p.name + ".html")


def check_output(out, source=None) -> Path:
    """Refuse, in one line, an output that is not an ``.html`` path bearingsim may write: a folder, a
    link, a file that is not a report bearingsim wrote, the input itself, below a file. Nothing is
    created here: :func:`report` creates the missing folders when the page is ready."""
    from bearingsim.outputs import check_folder_can_be_made, check_replaceable

    out = Path(out)
    if out.suffix.lower() not in SUFFIXES:
        raise UserError(f"{out}: report path must end in .html or .htm (got {out.suffix or 'no suffix'!r})")
    if source is not None and out.exists() and Path(source).exists() and out.resolve() == Path(source).resolve():
        raise UserError(f"{out}: the report path is the input; choose another -o")
    check_folder_can_be_made(out, "report")
    check_replaceable(out, SIGNATURE, "report")
    return out


def breakable(name: str):
    """A column's name, escaped, where a line may break after each ``_`` and ``.`` (``<wbr>``): a key's name
    (``bearing.cage_guidance``, ``load_zone_half_angle [deg]``) is one word to the browser, so a table of many
    such columns ran past the page's edge and hid its last columns."""
    from markupsafe import Markup, escape

    return Markup(str(escape(name)).replace("_", "_<wbr>").replace(".", ".<wbr>"))


def render(title: str, source: str, kind: str, sections: list[Section]) -> str:
    """The page (text) of ``sections`` from the package's template, every value autoescaped."""
    import jinja2

    from bearingsim._version import __version__

    env = jinja2.Environment(loader=jinja2.PackageLoader("bearingsim", "templates"), autoescape=True,
                             undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True,
                             keep_trailing_newline=True)
    env.filters["breakable"] = breakable
    return env.get_template("report.html.j2").render(title=title, source=source, kind=kind, sections=sections,
                                                     version=__version__)


def _sections(kind: str, file: Path, animation) -> tuple[str, list[Section]]:
    if kind == "run":
        return _run_sections(file, animation)
    title, sections, scenario = _builders()[kind](file)  # scenario: the folder's scenario as TOML, or its blocks
    sections += _folder_sections(file.parent, scenario)
    return title, sections


def _builders() -> dict:
    return {"sweep": _sweep_sections, "crosscheck": _crosscheck_sections, "validate": _validate_sections,
            "sensitivity": _sensitivity_sections, "uncertainty": _uncertainty_sections, "life": _life_sections}


def _studies_sections(found) -> tuple[str, list[Section]]:
    """A folder holding several studies' tables (``found``: :func:`bearingsim.tables.studies_of`): each
    study's sections in that order (anchors and figure titles named after the study), then the folder's
    cases and checks, each study's scenario and the provenance of its first case."""
    from bearingsim.tables import STUDY_NAMES

    folder = found[0][1].parent
    titles, sections, scenarios = [], [], []
    for kind, file in found:
        title, own, scenario = _builders()[kind](file)
        titles.append(title)
        for s in own:
            s.id = f"{kind}-{s.id}"
            s.title = s.title if s.id != f"{kind}-figures" else f"Figures: {own[0].title}"
        sections += own
        blocks = scenario if isinstance(scenario, list) else _scenario_blocks(scenario, file)
        scenarios.append(Section(f"{kind}-scenario", f"Scenario: {own[0].title}", blocks))
    intro = {"kind": "text", "text": f"{folder} holds {len(found)} studies' tables, each shown here: "
                                     + ", ".join(f"{STUDY_NAMES[k]} ({f.name})" for k, f in found) + "."}
    sections[0].blocks.insert(0, intro)
    return "; ".join(titles), sections + _folder_sections(folder, None, scenarios=scenarios)


# --- blocks -------------------------------------------------------------------------------------
def _data_uri(data: bytes, mime: str) -> str:
    return f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"


def figure_block(fig, caption: str) -> dict:
    """A matplotlib figure as an embedded PNG."""
    from bearingsim.plotting import figure_png

    return {"kind": "figure", "src": _data_uri(figure_png(fig), "image/png"), "caption": caption}


def drawn_blocks(draw, captions: dict[str, str] | None = None) -> list[dict]:
    """The PNGs a figure function writes into a folder (``draw(folder) -> [paths]``), drawn into a
    temporary folder and embedded; ``captions`` by file name."""
    captions = captions or {}
    with tempfile.TemporaryDirectory(prefix="bearingsim-report-") as tmp:
        paths = draw(Path(tmp))
        return [{"kind": "figure", "src": _data_uri(Path(p).read_bytes(), "image/png"),
                 "caption": captions.get(Path(p).name, Path(p).stem.replace("_", " "))} for p in paths]


def _cell(v, scale: float = 1.0, digits: int = 4) -> str:
    if isinstance(v, (str, np.str_)):
        return str(v)
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    return "-" if not math.isfinite(x) else f"{x * scale:.{digits}g}"


def table_block(caption: str, head: list[str], rows: list[list[str]], numeric: list[bool] | None = None,
                note: str | list[str] = "") -> dict:
    """A table: ``rows`` of text cells (at most :data:`MAX_ROWS`, then a note); ``numeric`` columns
    right-aligned; ``note``: a line under it, or lines (each its own paragraph)."""
    numeric = numeric or [False] * len(head)
    note = [note] if isinstance(note, str) else list(note)
    left = len(rows) - MAX_ROWS
    if left > 0:
        rows = rows[:MAX_ROWS]
        note.append(f"{left} more rows are not shown ('bearingsim table' prints them all).")
    return {"kind": "table", "caption": caption, "head": head, "rows": rows, "numeric": numeric, "note": note}


def _summary_table_block(table, caption: str) -> dict:
    """A :class:`bearingsim.tables.Table` with the columns ``bearingsim table`` shows, standard errors
    and significance marks included."""
    from bearingsim import tables

    keys = [k for k in tables.DEFAULT_COLUMNS if k in table.numbers]
    heads, cols = list(table.label_names), [table.labels[k] for k in table.label_names]
    for key in keys:
        head, cells = tables.column_cells(table, key)
        heads.append(head)
        cols.append([c.strip() for c in cells])
    rows = [list(r) for r in zip(*cols)] if cols else []
    rule = tables.RULE if any(k in tables.SEM_OF for k in keys) else ""
    # the table's notes as one sentence, the significance marks' key on its own line under it
    said = " ".join(n if n.endswith(".") else n + "." for n in table.notes)
    return table_block(caption, heads, rows, [False] * len(table.label_names) + [True] * len(keys), [said, rule])


def _footnote_blocks(table) -> list[dict]:
    """The key of a summary table's ``[k]`` marks (its rows' notes) as ``bearingsim table`` prints it, for
    the rows the report shows (:data:`MAX_ROWS`); none for a table without marks."""
    from bearingsim import tables

    noted = [text for i, text in sorted(table.footnotes.items()) if i < MAX_ROWS]
    return [{"kind": "text", "text": tables.NOTES_HEAD}, {"kind": "list", "items": noted}] if noted else []


# --- a run archive ------------------------------------------------------------------------------
def _run_sections(path: Path, animation) -> tuple[str, list[Section]]:
    from bearingsim.simulation import load

    result = load(path)
    sections = [Section("summary", "Summary", [{"kind": "text", "text": result.title()}, _run_headline(result),
                                               _run_summary(result)]),
                Section("figures", "Figures", _run_figures(result))]
    anim = _animation_section(path, animation)
    if anim is not None:
        sections.append(anim)
    sections += [Section("pockets", "Per pocket", [_pocket_table(result)]),
                 Section("checks", "Plausibility checks", _checks_blocks(result)),
                 Section("scenario", "Scenario", _scenario_blocks(result.scenario.to_toml(), path)),
                 Section("provenance", "Provenance", [_provenance_table(result.provenance)])]
    return f"{result.scenario.name}: {result.description()}", sections


def _run_headline(result) -> dict:
    """The run's headline numbers as ``bearingsim run`` prints them (:func:`bearingsim.tables.headline`): the
    mean impulses in mN s, the first impact speed, the cage slip in per cent and the load zone, each with its
    standard error."""
    from bearingsim.tables import headline

    units = result.summary_units
    rows = [[key, words or f"{_cell(v, digits=6)} {units.get(key, '')}".strip()] for key, v, _, words in headline(result)]
    return table_block("Headline numbers (as bearingsim run prints them)", ["quantity", "value"], rows,
                       [False, False])


def _run_summary(result) -> dict:
    from bearingsim.stats import SEM_UNITS, result_standard_errors

    units = result.summary_units
    errors = result_standard_errors(result)
    rows = [[k, _cell(v, digits=6), units.get(k, "")] for k, v in result.summary.items()]
    rows += [[k, _cell(v, digits=3), SEM_UNITS[k]] for k, v in errors.items()]
    return table_block("Summary numbers (SI; every number of /results/summary)", ["quantity", "value", "unit"],
                       rows, [False, True, False],
                       "The *_sem_* rows: standard errors of the means, batch means over rotations "
                       "(docs/statistics.md).")


def _run_figures(result) -> list[dict]:
    blocks = []
    for name in result.FIGURES:
        method = getattr(result, f"plot_{name}")
        blocks.append(figure_block(method(), figure_caption(method.__doc__, name)))
    return blocks


def figure_caption(doc: str | None, name: str) -> str:
    """A run figure's caption: the first paragraph of its ``plot_*`` method's docstring, on one line, its
    reStructuredText literals and cross-references as plain words (``x`` -> x, :data:`~a.b.C` -> C); the
    figure's name without one."""
    import inspect

    if not doc:
        return name
    text = " ".join(inspect.cleandoc(doc).split("\n\n")[0].split())
    text = re.sub(r":\w+:`~?([^`]+)`", lambda m: m.group(1).rsplit(".", 1)[-1], text)
    return text.replace("``", "")


def _pocket_table(result) -> dict:
    i_dec, i_acc = (np.asarray(result.per_rotation[k], float) for k in ("I_dec", "I_acc"))
    n = i_dec.shape[0]

    def spread(x):  # one rotation has no spread to show: "-", not a standard deviation of 0
        return np.nanstd(x) if n > 1 else math.nan

    with np.errstate(invalid="ignore"):
        rows = [[str(j), _cell(np.nanmean(i_dec[:, j]), 1e3), _cell(spread(i_dec[:, j]), 1e3),
                 _cell(np.nanmean(i_acc[:, j]), 1e3), _cell(spread(i_acc[:, j]), 1e3)]
                for j in range(i_dec.shape[1])]
    return table_block(f"Impulse per cage rotation of each pocket, mean and standard deviation over "
                       f"{counted(n, 'recorded rotation')} [mN s]" + (" (one rotation: no standard deviation)" if n == 1 else ""),
                       ["pocket", "I_dec mean", "I_dec std", "I_acc mean", "I_acc std"], rows,
                       [False, True, True, True, True])


def _checks_blocks(result) -> list[dict]:
    from bearingsim import plausibility
    from bearingsim.errors import SimulationUnstable

    rows = plausibility.checks_made(result)
    blocks = [{"kind": "checks", "rows": [{"name": n, "measured": m, "passed": ok,
                                           "noted": ok is False and n in plausibility.NOTED_CHECKS}
                                          for n, m, ok in rows]}]
    try:
        again = plausibility.check(result)
        verdict = _checks_verdict(rows)
    except SimulationUnstable as exc:
        again, verdict = [], f"This archive does NOT pass the checks: {exc}"
    blocks.append({"kind": "text", "text": verdict})
    notes = list(dict.fromkeys([*result.notes, *again]))  # the run's stored notes, then those made again
    if notes:
        blocks.append({"kind": "list", "items": run_notes(notes)})
    return blocks


def _checks_verdict(rows) -> str:
    """The sentence under the checks' table of an archive that :func:`bearingsim.plausibility.check` does not
    refuse: every check passed, or which gave a note (:data:`bearingsim.plausibility.NOTED_CHECKS`: the notes
    below, the run kept) or did not pass, and which could not be made."""
    from bearingsim.plausibility import NOTED_CHECKS

    skipped = [n for n, _, ok in rows if ok is None]
    noted = [n for n, _, ok in rows if ok is False and n in NOTED_CHECKS]
    failed = [n for n, _, ok in rows if ok is False and n not in NOTED_CHECKS]
    if failed or noted:
        verdict = " ".join(part for part in [f"Did not pass: {'; '.join(failed)}." if failed else "",
                            f"Noted (a finding, not a failure): {'; '.join(noted)}." if noted else "",
                            "No check that refuses a run failed, so 'bearingsim run' kept it (docs/reliability.md); "
                            "read its numbers with the notes below. Checked again from this archive."] if part)
    else:
        verdict = (("Every check passed" if not skipped else "Every check that could be made passed")
                   + ": 'bearingsim run' writes an archive only for a run that passes the checks that refuse a run "
                   "(docs/reliability.md); checked again from this archive.")
    return verdict + (f" Not evaluated here, and no pass: {'; '.join(skipped)} (the table says why)." if skipped else "")


def _scenario_blocks(toml: str | None, where) -> list[dict]:
    if not toml:
        return [{"kind": "text", "text": f"{where} stores no scenario."}]
    return [{"kind": "text", "text": f"The resolved scenario (every key), as stored in {where}; save it as a .toml "
                                     "file to run it again."}, {"kind": "pre", "text": toml}]


def _provenance_table(prov: dict, caption: str = "How the run was made") -> dict:
    rows = [[k, str(v)] for k, v in prov.items() if not k.startswith("version_")]
    rows += [[k, str(v)] for k, v in prov.items() if k.startswith("version_")]
    return table_block(caption, ["item", "value"], rows)


#: the report's clip: the last half cage rotation of the stored motion (8 roller passes of the NU214), at
#: 15 frames per second (2 s of video, 30 frames): a page that opens quickly and a report written in seconds
#: (``bearingsim animate`` draws the whole window at 30 fps)
REPORT_CLIP_ROTATIONS = 0.5
REPORT_CLIP_FPS = 15


def _animation_section(archive, fmt: str | None = "gif") -> Section | None:
    """The archive's animation (:func:`bearingsim.simulation.animate`: the last
    :data:`REPORT_CLIP_ROTATIONS` cage rotations of its stored motion at :data:`REPORT_CLIP_FPS` frames per
    second) embedded, or None: no ``fmt``, or an archive without the bodies' motion."""
    from bearingsim import animation
    from bearingsim.simulation import animate

    if fmt is None:
        return None
    if not animation.has_motion(archive):
        return None
    mime, element = ANIMATIONS[fmt]
    with tempfile.TemporaryDirectory(prefix="bearingsim-report-") as tmp:
        made = animate(archive, Path(tmp) / f"animation.{fmt}", last=REPORT_CLIP_ROTATIONS,
                                fps=REPORT_CLIP_FPS)
        data = Path(made).read_bytes()
    block = {"kind": "animation", "element": element, "mime": mime, "src": _data_uri(data, mime),
             "caption": "The bearing in motion, from the archive's recorded poses (bearingsim animate; its frame "
                        "states the clearance exaggeration, the time and the cage slip)."}
    return Section("animation", "Animation", [block])


# --- folders ------------------------------------------------------------------------------------
def _sweep_sections(index: Path):
    from bearingsim import tables
    from bearingsim.sweeps.grid import MAP_NAME, MAP_FORMAT, read_map
    from bearingsim.sweeps.index import read_index
    from bearingsim.sweeps.plot import plot_sweep_index, sweep_title_lines
    from bearingsim import archive

    cols, meta = read_index(index)
    notes: list[str] = []
    figures = drawn_blocks(lambda d: plot_sweep_index(index, d, notes=notes), SWEEP_CAPTIONS)
    figures += [{"kind": "text", "text": n} for n in notes]
    keys = ", ".join(meta["axes"]) or "(none)"
    # the figures' two-line title: the page's title, and what the cases share, a sentence under it
    title, shared = sweep_title_lines(meta, len(cols["case"]))
    head = {"kind": "text", "text": f"Base scenario {meta.get('scenario') or '(cases only)'}; swept keys: {keys}; "
                                    f"mode {meta.get('mode', '?')}." + (f" What the cases share: {shared}." if shared else "")}
    map_path = index.parent / MAP_NAME
    toml = meta.get("scenario_toml") or None  # the base scenario resolved (a sweep of a scenario stores it)
    if toml is None and archive.is_grid_file(map_path, MAP_FORMAT):
        toml = read_map(map_path).attrs.get("scenario")
    table = tables.table_of_index(index)
    sections = [Section("table", "Cases", [head, _summary_table_block(table, "Summary numbers of every case"),
                                           *_footnote_blocks(table)]),
                Section("figures", "Figures", figures)]
    return title, sections, toml


def _crosscheck_sections(table: Path):
    from bearingsim.studies import crosscheck as cc
    from bearingsim.wording import shown_as

    rows, meta = cc.read_table(table)
    slip, slip_unit = shown_as("cage_slip", "1")
    head = ["rpm", "rung", "scene", "relaxed", "I_dec [mN s]", "I_acc [mN s]", "first impact speed [m/s]",
            f"cage slip [{slip_unit}]", "change of I_dec [mN s]"]
    cells = [[_cell(r["rpm"]), str(r["rung"]), r["scene"], r["relaxed"], _pm(r["I_dec_mean_Ns"], r["I_dec_sem_Ns"]),
              _pm(r["I_acc_mean_Ns"], r["I_acc_sem_Ns"]), _cell(r["first_impact_speed_m_s"]),
              _cell(r["cage_slip"], slip, digits=3), _cell(r["change_from_previous"], 1e3)] for r in rows]
    blocks = [table_block("Impulses per pocket and cage rotation, mean over all pockets ± batch-means standard "
                          "error; each rung drops one assumption of the paper's model (docs/crosscheck.md)", head, cells,
                          [True, True, False, False, True, True, True, True, True]),
              {"kind": "list", "items": cc.verdicts(rows, cc.table_rotations(meta))}]
    figures = drawn_blocks(lambda d: cc.plot_crosscheck(table, d), {
        "crosscheck.png": "I_dec and I_acc per pocket and cage rotation, mean over all pockets ± 1 standard error, "
                          "at each rung of the ladder and each speed"})
    sections = [Section("table", "Cross-check", blocks), Section("figures", "Figures", figures)]
    return cc.ladder_title(meta, {r["rpm"] for r in rows}), sections, meta.get("scenario")


def _pm(mean, sem) -> str:
    """``mean ± sem`` of an impulse in mN s, as ``bearingsim table`` gives it (:func:`bearingsim.tables.with_error`)."""
    from bearingsim.tables import with_error

    try:
        m, e = float(mean) * 1e3, float(sem) * 1e3
    except (TypeError, ValueError):
        return f"{mean} ± {sem}"
    return "-" if not math.isfinite(m) else with_error(m, e)


#: a sweep's figures in the page, by file name (bearingsim.sweeps.plot)
SWEEP_CAPTIONS = {
    "sweep_I.png": "I_dec and I_acc per pocket and cage rotation against the first swept key, a line for each value "
                   "of the others; error bars ± 1 standard error (batch means over rotations, where the model has "
                   "one; a point without one, n/a in the table, has an open marker and no bar)",
    "sweep_map.png": "I_dec and I_acc per pocket and cage rotation over the two swept keys, as heat maps (a blank "
                     "cell: a case that failed or did not run); each panel's title gives its cells' largest standard "
                     "error X and t √2 X, above which the tables' test resolves any difference of two cells (t: "
                     "Student's, of the fewest batch means less one; below it, the table says; a starred value: "
                     "none, n/a)",
    "sweep_cases.png": "I_dec and I_acc per pocket and cage rotation of every case, labelled by its values; error bars "
                       "± 1 standard error (batch means over rotations, where the model has one; a case without one, "
                       "n/a in the table, has a hatched bar and no error bar)",
}

#: validate's figures in the page, by file name
VALIDATE_CAPTIONS = {
    "fig9_idec_vs_speed.png": "fig9_idec_vs_speed.png: the reduced model's I_dec per cage rotation against speed for "
                              "three drag coefficients and the paper's previous model (Fig. 9 analog)",
    "rig_idec_vs_speed.png": "rig_idec_vs_speed.png: the rig scene's flat pocket 0 and its 15 arc pockets against the "
                             "reduced model, mean ± std over rotations",
    "rig_pocket0_forces.png": "rig_pocket0_forces.png: the mean circumferential force on pocket 0's faces against θ at "
                              "each speed (Fig. 5 analog)",
}


def _validate_sections(table: Path):
    """A validate folder: its Fig. 9 table and rig table, the figures the studies drew there (embedded as
    they are), and a rig case's scenario (every case has its own)."""
    from bearingsim.studies import validate

    got = validate.read_validate(table.parent)
    speeds = counted(len(got.fig9["speed_rpm"]), "speed")
    blocks = [{"kind": "text", "text": f"bearingsim validate: the reduced model's Fig. 9 analog ({speeds}) and the "
                                       "paper's measurement rig as a whole-bearing scene against it "
                                       "(docs/validation.md)."}, _fig9_block(got.fig9)]
    if got.rig is not None:
        blocks.append(_rig_block(got.rig, got.rig_rotations))
    else:
        blocks.append({"kind": "text", "text": "No rig table in this folder (validate --rig-rotations 0, or no rig "
                                               "speed finished)."})
    figures = [{"kind": "figure", "src": _data_uri(p.read_bytes(), "image/png"),
                "caption": VALIDATE_CAPTIONS.get(p.name, p.name)} for p in got.figures]
    sections = [Section("table", "Validation", blocks), Section("figures", "Figures", figures)]
    rig = f" and the rig scene ({counted(len(got.rig), 'speed')})" if got.rig else ""
    return f"Validation against the paper: Fig. 9 analog{rig}", sections, _validate_scenario(table.parent)


def _fig9_block(table: dict) -> dict:
    from bearingsim.studies.fig9 import column_label

    cols = [c for c in table if c != "speed_rpm"]
    rows = [[_cell(n), *(_cell(table[c][i], 1e3) for c in cols)] for i, n in enumerate(table["speed_rpm"])]
    return table_block("Fig. 9 analog: the reduced model's I_dec per cage rotation [mN s] (NU214, 970 N, φ = 23.5°; "
                       "previous: the paper's previous model, no gravity, no resting contact)",
                       ["rpm", *(column_label(c) for c in cols)], rows, [True] * (len(cols) + 1),
                       "-: a failed case.")


def _rig_block(rows: list[dict], rotations: int) -> dict:
    cells = [[_cell(r["rpm"]), _cell(r["pocket0_I_dec_mean_Ns"], 1e3),
              _cell(r["pocket0_I_dec_std_Ns"], 1e3, 2) if math.isfinite(r["pocket0_I_dec_std_Ns"]) else "n/a",
              _cell(r["reduced_I_dec_Ns"], 1e3), _cell(r["pocket0_I_dec_mean_Ns"] / r["reduced_I_dec_Ns"], digits=3),
              _cell(r["arc_pockets_I_dec_mean_Ns"], 1e3)] for r in rows]
    return table_block(f"The rig scene (pocket 0 flat; 1 warm-up + {counted(rotations, 'rotation')}) against the "
                       "reduced model", ["rpm", "pocket 0 I_dec [mN s]", "std over rotations [mN s]",
                                         "reduced model [mN s]", "ratio", "arc pockets [mN s]"], cells,
                       [True] * 6, "std n/a: one recorded rotation has no scatter.")


def _validate_scenario(folder: Path) -> list[dict]:
    """The Scenario section's blocks of a validate folder: every case has its own scenario; shown is the
    first finished rig case's (else the first finished Fig. 9 case's, else the first finished case's: a
    folder may hold another study's cases too), as its archive stores it."""
    from bearingsim import archive
    from bearingsim.sweeps.index import read_index

    cols, _ = read_index(folder / "sweep.h5")
    done = [i for i, s in enumerate(cols["status"]) if str(s) in ("done", "cached", "stale") and cols["archive"][i]]
    pick = next((i for study in ("rig", "fig9") for i in done if str(cols["study"][i]) == study),
                done[0] if done else None)
    got = archive.peek(folder / str(cols["archive"][pick])) if pick is not None else None
    if got is None:
        return _scenario_blocks(None, folder)
    where = f"{cols['archive'][pick]} ({cols['study'][pick]} case at {float(cols['rpm'][pick]):g} rpm)"
    return [{"kind": "text", "text": f"Every case has its own scenario ('bearingsim show DIR/cases/<hash>.h5'). This is "
                                    f"the resolved scenario of {where}; save it as a .toml file to run it again."},
            {"kind": "pre", "text": got["scenario"]}]


def _sensitivity_sections(table: Path):
    from bearingsim.studies import sensitivity as sens

    rows, meta = sens.read_table(table)
    head = ["key", "quantity", "measure", "sensitivity", "change over the key's range", "notes (n/a: why)"]

    def num(v, digits):
        return _cell(v, digits=digits) if math.isfinite(float(v)) else "n/a"

    # a deterministic study (the reduced model) ran half steps and has no standard error: S and S at half the step
    deterministic = sens.ran_half_steps(rows)

    def slope(r):  # S ± SE, or S and S at half the step (a deterministic model)
        half = float(r.get("sensitivity_half_step", math.nan))
        if deterministic:
            return num(r["sensitivity"], 3) + (f" (half step: {num(half, 3)})" if math.isfinite(half) else "")
        return f"{num(r['sensitivity'], 3)} ± {num(r['sensitivity_se'], 2)}"

    cells = [[r["key"], r["quantity"], r["measure"], slope(r), num(r["over_range"], 3), sens.row_note(r)]
             for r in rows]
    errors = "S and S at half the step" if deterministic else "± one standard error"
    blocks = [table_block(f"Normalised sensitivities (runs at x (1 ± {sens.step_text(meta.get('step', 0))})); log: "
                          f"d ln y / d ln x, lin: d y / d ln x; {errors} (docs/sensitivity.md)", head, cells,
                          [False, False, False, True, True, False], sens.HALF_STEP_NOTE if deterministic else "")]
    if meta.get("left_out"):  # default keys not varied, as the command's first lines and `bearingsim table` name them
        blocks.insert(0, {"kind": "text", "text": f"Left out of the default keys: {meta['left_out']}."})
    bars = sens.tornado_errors(rows)
    present = {r["quantity"] for r in rows}  # the chart's panels, in its order (sensitivity.plot_tornado)
    panels = [f"ln {q}" if m == "log" else f"{q} (a fraction)" for q, _, m in sens.QUANTITIES if q in present]
    drawn = listed(panels, "and") if panels else ""
    figures = drawn_blocks(lambda d: sens.plot_sensitivity(table, d), {
        "sensitivity.png": f"Tornado chart: the change of {drawn} across each key's plausible range "
                           f"(S ln(high / low), if linear), keys ordered by the change of I_dec; {bars}"})
    sections = [Section("table", "Sensitivity", blocks), Section("figures", "Figures", figures)]
    return f"Sensitivity of {meta.get('scenario_name', '?')}", sections, meta.get("scenario")


def _uncertainty_sections(table: Path):
    from bearingsim.studies import uncertainty as unc

    rows, spreads, meta = unc.read_table(table)

    def spread_row(s):  # in the unit the command prints it in (impulses in mN s)
        scale, unit = unc.shown(s["quantity"])
        return [f"{s['quantity']} [{unit}]" if unit else s["quantity"],
                *(_cell(s[c], scale) for c in ("median", "p05", "p95", "mean", "std")), _cell(s["runs_used"])]

    spread = table_block("Each output over the sampled ranges", ["quantity", "median", "5 %", "95 %", "mean", "std",
                                                                  "runs used"],
                         [spread_row(s) for s in spreads], [False] + [True] * 6)
    ci = f"{unc.CONFIDENCE:.0%}"
    index = table_block(f"Sobol indices with {ci} bootstrap intervals (docs/sensitivity.md)",
                        ["quantity", "key", "S1", f"S1 {ci}", "ST", f"ST {ci}"],
                        [[r["quantity"], r["key"], _cell(r["S1"], digits=3),
                          f"{_cell(r['S1_low'], digits=3)} .. {_cell(r['S1_high'], digits=3)}", _cell(r["ST"], digits=3),
                          f"{_cell(r['ST_low'], digits=3)} .. {_cell(r['ST_high'], digits=3)}"] for r in rows],
                        [False, False, True, True, True, True])
    figures = drawn_blocks(lambda d: unc.plot_uncertainty(table, d), {
        "uncertainty.png": f"Sobol indices of each key, first order and total, with their {ci} bootstrap intervals; "
                           "each panel's title gives its output's median and 5-95 % interval over the sampled ranges"})
    sections = [Section("table", "Uncertainty", [{"kind": "text", "text": f"{meta.get('samples')} base samples, "
                                                  f"{meta.get('runs')} runs, seed {meta.get('seed')}."}, spread, index]),
                Section("figures", "Figures", figures)]
    return f"Uncertainty of {meta.get('scenario_name', '?')}", sections, meta.get("scenario")


def _life_sections(table: Path):
    from bearingsim.studies import life

    import tomllib

    cols, attrs = life.read_life(table)
    history = life.history_table(attrs.get("limit"), cols)  # a volume limit's columns are the volume's
    head = [h for _, h, _, _ in history]
    mapping = str(attrs.get("mapping", ""))
    toml = attrs.get("scenario")
    name = tomllib.loads(toml).get("name", "?") if toml else "?"
    # the study's answer first, as `bearingsim life` and `bearingsim table` print it above the history: the
    # life and its error, or where the cage bar wears through before the limit
    blocks = [{"kind": "text", "text": life.life_headline(cols, f"Life of {name} to {attrs.get('limit', '?')}", attrs)},
              {"kind": "text", "text": f"Limit {attrs.get('limit', '?')}; mapping {mapping}"
                                       + (f": {life.MAPPINGS[mapping]}." if mapping in life.MAPPINGS else ".")}]
    stages = attrs.get("stages")
    counted_note = life.stage_count_note(int(stages), mapping) if stages is not None else None
    for note in (_life_limit_note(attrs), counted_note):  # what the command notes under its history
        if note:
            blocks.append({"kind": "text", "text": f"Note: {note}."})
    blocks.append(table_block("The life history, one row per stage, as `bearingsim table` prints it (docs/wear.md); "
                              "the worn depth over each face at each stage's end is the figure's", head,
                              life.history_rows(cols, history), [True] * len(head)))
    notes = life.depth_notes(cols, attrs) + life.stage_notes(cols)
    if notes:  # the stages' run notes, each once, as the command prints them under its history
        blocks.append({"kind": "list", "items": notes})
    figures = [figure_block(life.plot_life(cols, attrs), "Worn depth, pocket clearance and wear rate against "
                                                         "running time, stage by stage")]
    sections = [Section("table", "Life", blocks), Section("figures", "Figures", figures)]
    return f"Life of {name} to {attrs.get('limit', '?')}", sections, toml


def _life_limit_note(attrs: dict) -> str | None:
    """What ``bearingsim life`` notes under its history for a ``depth`` limit (the deepest point is an end
    bin's, so the rotations to it are those of the bin width: :func:`bearingsim.studies.life.depth_limit_note`),
    from the folder's limit and scenario; None for the other limits or a folder that does not say."""
    from bearingsim.errors import UserError
    from bearingsim.scenario import parse_toml_text, resolve
    from bearingsim.studies import life

    toml, text = attrs.get("scenario"), attrs.get("limit")
    if not toml or not text:
        return None
    try:
        limit = life.held_limit(str(text))
        if limit is None or limit.kind != "depth":
            return None
        return life.depth_limit_note(resolve(parse_toml_text(str(toml), "life.h5"), "life.h5"), limit)
    except UserError:
        return None


def _case_values(cols, meta) -> list[str]:
    """What each case of an index varies (its row's axes: ``key = value, ...``), as the tables of its
    folder's page name it (values written with the digits that tell them apart: :func:`distinct_texts`)."""
    from bearingsim.wording import distinct_texts

    keys = [k for k in meta.get("axes", ()) if k in cols]
    texts = {k: distinct_texts(list(cols[k])) for k in keys}

    def unset(v):  # a key the case does not set: NaN or no text (validate's rig cases: no drag, no variant)
        return (isinstance(v, float) and v != v) or (isinstance(v, str) and not v)

    return [", ".join(f"{k} = {texts[k][i]}" for k in keys if not unset(cols[k][i])) for i in range(len(cols["case"]))]


def _run_notes_blocks(cols, meta) -> list[dict]:
    """The index's run notes (its ``notes`` column: a run that is plausible but not clean,
    :func:`bearingsim.plausibility.check`): a line saying how many cases have them and a table of them."""
    from bearingsim.sweeps.index import notes_of

    values = _case_values(cols, meta)
    rows = [[str(c), values[i], note]
            for i, (c, cell) in enumerate(zip(cols["case"], cols.get("notes", ()))) for note in notes_of(cell)]
    if not rows:
        return []
    cases = len({r[0] for r in rows})
    return [{"kind": "text", "text": f"{counted(cases, 'case')} kept with notes (a run that is plausible but not "
                                     "clean; docs/reliability.md):"},
            table_block("Notes of the cases' runs", ["case", "values", "note"], rows)]


def _folder_sections(folder: Path, toml, scenarios: list[Section] | None = None) -> list[Section]:
    """The cases (status counts, failures), the scenario (``toml``: the folder's scenario as TOML text,
    or the Scenario section's blocks; ``scenarios``: sections given instead) and the provenance of a
    folder's first case archive."""
    from bearingsim import archive
    from bearingsim.sweeps.index import INDEX_FORMAT, read_index

    index = folder / "sweep.h5"
    checks: list[dict] = []
    first = None
    if archive.is_table_file(index, INDEX_FORMAT):
        cols, meta = read_index(index)
        status = [str(s) for s in cols["status"]]
        counts = ", ".join(f"{s} {status.count(s)}" for s in dict.fromkeys(status))
        values = _case_values(cols, meta)
        failed = [[str(c), values[i], e]
                  for i, (c, s, e) in enumerate(zip(cols["case"], status, cols["error"])) if s == "failed"]
        checks.append({"kind": "text", "text": f"{counted(len(status), 'case')}: {counts}. A case's archive is written only when "
                                               "its run passes the plausibility checks (docs/reliability.md); a "
                                               "failed case keeps its one-line error" +
                                               (":" if failed else ". No case failed.")})
        if failed:
            checks.append(table_block("Failed cases", ["case", "values", "error"], failed))
        checks += _run_notes_blocks(cols, meta)
        row = next((i for i, a in enumerate(cols["archive"]) if a and (folder / a).is_file()), None)
        first = folder / cols["archive"][row] if row is not None else None
        # the case named by what it varies (its index row's axes: a sweep's keys, a study's rung, speed, stage)
        label = values[row] if row is not None else ""
    if scenarios is None:
        blocks = toml if isinstance(toml, list) else _scenario_blocks(toml, folder)
        scenarios = [Section("scenario", "Scenario", blocks)]
    sections = [Section("checks", "Cases and checks", checks), *scenarios]
    if first is not None:
        from bearingsim.simulation import load

        prov = load(first, only=("results/summary",)).provenance
        sections.append(Section("provenance", "Provenance", [
            _provenance_table(prov, f"How the first case was made ({label + ': ' if label else ''}"
                                    f"{first.relative_to(folder)}; every case ran with the same code unless the "
                                    "index's model_version column says otherwise)")]))
    return sections

