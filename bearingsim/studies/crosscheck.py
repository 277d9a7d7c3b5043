"""The cross-check ladder (``bearingsim crosscheck``): the paper's reduced model against the whole bearing,
one assumption at a time.

Five rungs at each speed; each drops one assumption of the paper's model and keeps the others:

1. ``reduced``: the reduced event model (one pocket, cage at the epicyclic speed, rollers leave the load
   zone at the front of their pockets, no inner ring), built from the multibody scenario: the same
   bearing, operating point, contact, lubrication and ``reduced.load_zone_half_angle_deg``;
2. ``reduced_equivalent``: the same assumptions in pymunk, every pocket;
3. ``kinematic_cage``: rollers driven by their raceway contacts (Hertz, traction, inner ring: the load
   zone emerges); the cage still centred and turning at the epicyclic speed, prescribed;
4. ``centred_cage``: the cage turns freely under its contact torques; its centre held on the axis;
5. ``full``: the cage free in the plane, guided as the scenario says: the very run ``bearingsim run``
   makes of the scenario at that speed (and with ``--rotations``, that many rotations).

Numbers per rung: the mean impulses per pocket and cage rotation over all pockets (SI), their standard
error from batch means (:func:`bearingsim.stats.impulse_standard_errors`) of the pocket-mean series over
rotations (rotations of a chaotic scene are correlated), the mean first rear-impact speed and the cage
slip. ``change_from_previous`` is the change of ``I_dec_mean_Ns`` from the rung before, so the changes
add up to full minus reduced exactly.

The rungs are the cases of a study (:class:`CrossCheck`) run on the sweep engine
(:func:`bearingsim.studies.run_studies`): in parallel on local processes or a dask cluster; a rung that
fails is kept in the table with empty numbers and its error (``status``/``error`` in the index), the
other rungs go on; an interrupted or failed cross-check run again reuses every finished rung's archive.

Outputs in ``DIR``: ``crosscheck.csv``, ``crosscheck.h5`` (the same table as an index, one dataset per
column, ``archive`` naming each rung's archive, ``status`` and ``error`` each rung's outcome),
``crosscheck.png`` (drawn from the index: :func:`plot_crosscheck`), ``cases/<hash>.h5`` (the rungs'
ordinary archives) and ``sweep.csv``/``sweep.h5`` (the engine's index of the cases).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from bearingsim.errors import UserError
from bearingsim.stats import BATCHES, critical_ses, sem_batches, significant
from bearingsim.studies.engine import Study, case_of, load_result

INDEX_FORMAT = "bearingsim crosscheck index 1"
DEFAULT_SPEEDS_RPM = (1000.0, 3000.0, 6000.0)
DEFAULT_ROTATIONS = 10

#: warm-up rotations of rung 3 at least (the kinematic_cage scene is periodic once settled, and with one warm-up
#: its first recorded rotation is still its start: 11.589 against 12.555 mN s at 3000 rpm, 9.771 against 10.069
#: at 6000, the whole of its batch-means error; with two every recorded rotation is the same)
KINEMATIC_WARMUP_ROTATIONS = 2


def warmup_text(warmup: int) -> str:
    """The rungs' warm-up rotations as the command's first line gives them: the scenario's ``warmup``, and rung 3's
    where :data:`KINEMATIC_WARMUP_ROTATIONS` raises it ("1 warm-up (rung 3: 2)", as docs/crosscheck.md says)."""
    from bearingsim.wording import counted

    text = counted(int(warmup), "warm-up")
    return text + (f" (rung 3: {KINEMATIC_WARMUP_ROTATIONS})" if warmup < KINEMATIC_WARMUP_ROTATIONS else "")


#: (rung, scene, the assumption of the paper's model this rung drops; ``{raceways}``: :func:`rungs` names them)
RUNGS = (
    (1, "reduced", "none: the paper's reduced model (one pocket; cage at the epicyclic speed)"),
    (2, "reduced_equivalent", "one pocket: every pocket in the plane (pymunk)"),
    (3, "kinematic_cage", "rollers carried through the load zone: raceway contacts ({raceways}; traction; inner ring)"),
    (4, "centred_cage", "cage speed prescribed: the cage turns under its contact torques"),
    (5, "full", "cage centre on the axis: the cage free in the plane"),
)


def rungs(raceway_contact: str = "hertz") -> list[tuple[int, str, str]]:
    """:data:`RUNGS` with the raceway contacts of a scenario's ``multibody.raceway_contact`` named."""
    raceways = {"hertz": "Hertz", "rigid": "rigid raceways"}[raceway_contact]
    return [(rung, scene, relaxed.format(raceways=raceways)) for rung, scene, relaxed in RUNGS]


COLUMNS = ("rpm", "rung", "scene", "relaxed", "I_dec_mean_Ns", "I_dec_sem_Ns", "I_acc_mean_Ns", "I_acc_sem_Ns",
           "first_impact_speed_m_s", "cage_slip", "change_from_previous")
UNITS = {"rpm": "rpm", "rung": "1", "I_dec_mean_Ns": "N s", "I_dec_sem_Ns": "N s", "I_acc_mean_Ns": "N s",
         "I_acc_sem_Ns": "N s", "first_impact_speed_m_s": "m/s", "cage_slip": "1", "change_from_previous": "N s"}


def parse_speeds(text: str) -> tuple[float, ...]:
    """``"1000,3000,6000"`` -> speeds [rpm]; a one-line UserError naming ``--speeds`` and its form otherwise
    (a sweep's range START:STOP:NUM is not one: the refusal says so)."""
    try:
        speeds = tuple(float(v) for v in text.split(","))
    except ValueError:
        form = ("--speeds takes a list, not a range START:STOP:NUM as --param does: " if ":" in text else "")
        raise UserError(f"--speeds {text!r}: {form}give inner-ring speeds in rpm separated by commas, e.g. "
                        f"1000,3000,6000") from None
    if not speeds or not all(math.isfinite(v) and v > 0 for v in speeds):
        raise UserError(f"--speeds {text!r}: every speed must be a positive number of rpm")
    if len(set(speeds)) != len(speeds):
        raise UserError(f"--speeds {text!r}: a speed is given twice")
    return speeds


def rung_scenarios(scenario, rpm: float, rotations: int | None = None) -> list[tuple[int, str, str, object]]:
    """The five rungs' scenarios at ``rpm``: ``[(rung, scene, relaxed, Scenario), ...]``.

    Parameters
    ----------
    scenario : resolved multibody scenario whose ``multibody.scene`` is ``"full"`` (rung 5 is that
        scenario itself).
    rpm : inner-ring speed [rpm] (``operating.inner_ring_speed_rpm``).
    rotations : recorded cage rotations (``numerics.rotations``); None keeps the scenario's.

    Raises
    ------
    UserError
        A reduced-model scenario (the ladder needs the whole bearing; give its multibody scenario), or
        a multibody scenario whose scene is not ``full``.
    """
    if scenario.model != "multibody":
        raise UserError(f"{scenario.source}: model = {scenario.model!r}: the cross-check climbs from the reduced model "
                        f"to the whole bearing; give a scenario with model = \"multibody\" and scene = \"full\" (it builds "
                        f"the reduced rung from it)")
    if scenario.multibody.scene != "full":
        raise UserError(f"{scenario.source}: multibody.scene = {scenario.multibody.scene!r}: the cross-check's last rung "
                        f"is the scenario itself and must be the full scene; set multibody.scene = \"full\"")
    over = {"operating.inner_ring_speed_rpm": float(rpm)}
    if rotations is not None:
        over["numerics.rotations"] = int(rotations)
    full = scenario.replace(**over)
    out = []
    for rung, scene, relaxed in rungs(scenario.multibody.raceway_contact):
        if scene == "full":
            sc = full
        elif scene == "reduced":
            sc = full.replace(model="reduced")
        elif scene == "kinematic_cage":
            sc = full.replace(**{"multibody.scene": scene, "numerics.warmup_rotations": max(
                KINEMATIC_WARMUP_ROTATIONS, full.numerics.warmup_rotations)})
        else:
            sc = full.replace(**{"multibody.scene": scene})
        out.append((rung, scene, relaxed, sc))
    return out


def rung_numbers(result, reduced: bool) -> dict:
    """The table's numbers of one rung's result (SI).

    The standard errors are :func:`bearingsim.stats.impulse_standard_errors` (batch means over rotations
    of the pocket-mean impulses: the same numbers ``bearingsim sweep`` and ``bearingsim table`` give for
    the rung's archive); the reduced model repeats one no-load pass every rotation, so its scatter is
    zero by construction, and its cage turns at the epicyclic speed by assumption (cage slip 0).
    """
    from bearingsim.stats import impulse_standard_errors

    s = result.summary
    se = impulse_standard_errors(result.per_rotation["I_dec"], result.per_rotation["I_acc"],
                                 "reduced" if reduced else result.scenario.model)
    return {
        "I_dec_mean_Ns": float(s["I_dec_mean_Ns"]), "I_dec_sem_Ns": se["I_dec_sem_Ns"],
        "I_acc_mean_Ns": float(s["I_acc_mean_Ns"]), "I_acc_sem_Ns": se["I_acc_sem_Ns"],
        "first_impact_speed_m_s": float(s["first_impact_speed_m_s"]),
        "cage_slip": 0.0 if reduced else float(s["cage_slip"]),
    }


def add_changes(rows: list[dict]) -> list[dict]:
    """Fill ``change_from_previous`` (I_dec, N s) within each speed, rungs in order; NaN for rung 1."""
    rows = sorted(rows, key=lambda r: (r["rpm"], r["rung"]))
    prev = {}
    for r in rows:
        p = prev.get(r["rpm"])
        r["change_from_previous"] = math.nan if p is None else r["I_dec_mean_Ns"] - p["I_dec_mean_Ns"]
        prev[r["rpm"]] = r
    return rows


NUMBERS = ("I_dec_mean_Ns", "I_dec_sem_Ns", "I_acc_mean_Ns", "I_acc_sem_Ns", "first_impact_speed_m_s", "cage_slip")


class CrossCheck(Study):
    """The ladder as a study: five rungs at each speed (:func:`rung_scenarios`); its table is
    ``crosscheck.csv``/``crosscheck.h5`` and its figure ``crosscheck.png``.

    Parameters
    ----------
    scenario : resolved multibody scenario, full scene.
    speeds : inner-ring speeds [rpm].
    rotations : recorded cage rotations of every rung (None: the scenario's ``numerics.rotations``).
    """

    name = "crosscheck"

    def __init__(self, scenario, speeds=DEFAULT_SPEEDS_RPM, rotations: int | None = DEFAULT_ROTATIONS):
        from bearingsim import archive
        from bearingsim.outputs import is_own_png

        # the table keeps the scenario with the rungs' recorded rotations ('bearingsim show crosscheck.h5')
        self.scenario = scenario if rotations is None else scenario.replace(**{"numerics.rotations": int(rotations)})
        self.rungs = {}  # case hash -> (rpm, rung, scene, relaxed)
        cases = []
        for rpm in speeds:
            for rung, scene, relaxed, sc in rung_scenarios(scenario, rpm, rotations):
                c = case_of(sc, {"rpm": float(rpm), "rung": rung, "scene": scene})
                self.rungs[c.hash] = (float(rpm), rung, scene, relaxed)
                cases.append(c)
        # the longest runs first (low speed, multibody) so that the workers finish together
        cases.sort(key=lambda c: (c.values["scene"] == "reduced", c.values["rpm"], -c.values["rung"]))
        self.cases = cases
        self.outputs = [("crosscheck.csv", ",".join(COLUMNS).encode(), "cross-check table"),
                        ("crosscheck.h5", lambda p: archive.is_table_file(p, INDEX_FORMAT), "cross-check table"),
                        ("crosscheck.png", is_own_png, "figure")]
        self.rows: list[dict] = []

    def finish(self, outdir, records) -> list[Path]:
        """The table from the rungs' archives (a failed rung: NaN numbers, its status and error),
        written with its figure."""
        rows = []
        for c in self.cases:
            rec = records[c.hash]
            rpm, rung, scene, relaxed = self.rungs[c.hash]
            result = load_result(outdir, rec)
            numbers = (rung_numbers(result, scene == "reduced") if result is not None
                       else dict.fromkeys(NUMBERS, math.nan))
            rows.append({"rpm": rpm, "rung": rung, "scene": scene, "relaxed": relaxed,
                         "archive": rec["archive"], "wall_s": float(rec["wall_s"]),
                         "status": rec["status"], "error": rec["error"], **numbers})
        self.rows = add_changes(rows)
        paths = write_table(outdir, self.rows, self.scenario)
        return [*paths, *plot_crosscheck(outdir / "crosscheck.h5", outdir)]


def run_crosscheck(scenario, outdir, speeds=DEFAULT_SPEEDS_RPM, rotations: int | None = DEFAULT_ROTATIONS,
                   jobs: int = 2, *, engine=None, progress: bool | None = None, log=None, force: bool = False):
    """Run every rung at every speed on the sweep engine (``jobs`` local processes, or ``engine``),
    write the rung archives, the CSV, the index and the figure into ``outdir``.

    Archives already in ``outdir`` from an earlier run of the same rungs (same scenario, same model
    version) are reused; a rung that fails is kept in the table (NaN numbers, its error).

    Parameters
    ----------
    scenario : resolved multibody scenario, full scene (:func:`rung_scenarios`).
    outdir : output folder (created).
    speeds : inner-ring speeds [rpm].
    rotations : recorded cage rotations of every rung (None: the scenario's ``numerics.rotations``).
    jobs : local worker processes (ignored when ``engine`` is given).
    force : replace another study or sweep in ``outdir`` (default: refused).

    Returns
    -------
    (rows, outcome)
        The table's rows sorted by speed and rung (empty if interrupted) and the
        :class:`bearingsim.studies.StudiesOutcome` (counts, failed cases, interruption).
    """
    from bearingsim.studies.engine import make_engine, run_studies

    if engine is None:
        engine = make_engine(jobs)
    study = CrossCheck(scenario, speeds, rotations)
    outcome = run_studies([study], outdir, engine=engine, progress=progress, log=log, force=force)
    return study.rows, outcome


def write_table(outdir, rows: list[dict], scenario) -> tuple[Path, Path]:
    """Write ``crosscheck.csv`` (exactly :data:`COLUMNS`; a failed rung's numbers empty) and
    ``crosscheck.h5`` (the same columns and ``archive``, ``wall_s``, ``status``, ``error``, as an index
    table; :func:`bearingsim.archive.write_table_file`) atomically."""
    from bearingsim import archive
    from bearingsim.outputs import write_atomic_bytes
    from bearingsim.studies.engine import table_columns, table_csv

    outdir = Path(outdir)
    csv_path = outdir / "crosscheck.csv"
    write_atomic_bytes(csv_path, table_csv(rows, COLUMNS))
    columns = (*COLUMNS, "archive", "wall_s", "status", "error")
    cols = table_columns(rows, columns)
    units = {**UNITS, "wall_s": "s"}
    attrs = {"format": INDEX_FORMAT, "columns": json.dumps(columns), "scenario": scenario.to_toml(),
             "scenario_name": scenario.name}
    h5_path = archive.write_table_file(outdir / "crosscheck.h5", cols, units, attrs)
    return csv_path, h5_path


def table_rotations(meta: dict) -> int | None:
    """The rungs' recorded rotations of a table's root attributes (``meta`` of :func:`read_table`: the
    scenario it keeps has them), or None when it names none."""
    import tomllib

    try:
        return int(tomllib.loads(meta.get("scenario") or "")["numerics"]["rotations"])
    except (KeyError, TypeError, ValueError, tomllib.TOMLDecodeError):
        return None


def read_table(path) -> tuple[list[dict], dict]:
    """Read ``crosscheck.h5``: (rows as dicts, root attributes). One-line UserError if it is not one."""
    from bearingsim import archive

    cols, meta = archive.read_table_file(path, INDEX_FORMAT)
    names = json.loads(meta["columns"])
    n = len(cols[names[0]])
    rows = []
    for i in range(n):
        row = {}
        for c in names:
            v = cols[c][i]
            row[c] = v if isinstance(v, str) else float(v)
        row["rung"] = int(row["rung"])
        rows.append(row)
    return rows, meta


def plot_crosscheck(index_path, outdir) -> list[Path]:
    """Draw ``crosscheck.png`` from the index alone (:func:`plot_ladder`)."""
    from bearingsim.plotting import save_figure

    rows, meta = read_table(index_path)
    return [save_figure(plot_ladder(rows, meta), Path(outdir) / "crosscheck.png")]


def plot_ladder(rows: list[dict], meta: dict):
    """I_dec and I_acc against the rung, one line per speed, error bars ± 1 standard error (batch means);
    a rung without one (n/a: fewer than 2 recorded rotations) an open marker, no bar, counted in the title
    (:func:`bearingsim.plotting.error_title`). I_dec in the house colour of the rear face, I_acc in the front
    face's; the speeds differ in marker and line style."""
    from bearingsim.plotting import (FRONT, LINE_STYLES, REAR, error_title, legend_outside, mark_without_error,
                                     subplots)

    speeds = sorted({r["rpm"] for r in rows})
    labels = {r["rung"]: f"{r['rung']} {r['scene']}" for r in rows}
    fig, axes = subplots(2, 1, figsize=(9, 6.5), sharex=True)
    for k, rpm in enumerate(speeds):
        rs = sorted((r for r in rows if r["rpm"] == rpm), key=lambda r: r["rung"])
        x = np.array([r["rung"] for r in rs]) + (k - 0.5 * (len(speeds) - 1)) * 0.06
        marker, ls = LINE_STYLES[k % len(LINE_STYLES)]
        for ax, q, colour in zip(axes, ("I_dec", "I_acc"), (REAR, FRONT)):
            y, err = (np.array([r[f"{q}_{c}_Ns"] * 1e3 for r in rs], dtype=float) for c in ("mean", "sem"))
            ax.errorbar(x, y, yerr=err, marker=marker, ls=ls, ms=5, capsize=3, color=colour, label=f"{rpm:g} rpm")
            mark_without_error(ax, x, y, err, colour, marker, ms=5)
    axes[0].set_ylabel("$I_{dec}$ per pocket and\ncage rotation [mN s]")
    axes[1].set_ylabel("$I_{acc}$ per pocket and\ncage rotation [mN s]")
    for ax in axes:
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3)
    ticks = sorted(labels)
    axes[1].set_xticks(ticks)
    axes[1].set_xticklabels([labels[t] for t in ticks], rotation=15)
    axes[1].set_xlabel("rung of the cross-check (each drops one assumption of the paper's model)")
    drawn = [r for r in rows if math.isfinite(r["I_dec_mean_Ns"])]
    errors = error_title([r["I_dec_sem_Ns"] for r in drawn] + [r["I_acc_sem_Ns"] for r in drawn],
                         bars="± 1 standard error (batch means over rotations)")
    errors = (errors.removeprefix("error bars: ") if errors.startswith("error bars: ")
              else f"({errors})" if errors else "")
    axes[0].set_title(f"{ladder_title(meta, speeds)}: mean over all pockets {errors}", fontsize=9)
    legend_outside(axes[0], title="inner ring speed")
    return fig


def ladder_title(meta: dict, speeds) -> str:
    """``Cross-check at 1000, 3000, 6000 rpm of multibody_3000rpm's other settings``: the speeds that ran, and
    the base scenario as what the rest comes from (its own speed ran only if it is one of ``speeds``)."""
    at = f" at {', '.join(f'{float(v):g}' for v in sorted(speeds))} rpm" if len(speeds) else ""
    return f"Cross-check{at} of {meta.get('scenario_name', '?')}'s other settings"


def verdicts(rows: list[dict], rotations: int | None = None) -> list[str]:
    """One sentence per speed: the rung whose I_dec change is largest, and each change against t standard
    errors of the difference, sqrt(sem_a^2 + sem_b^2), by the tables' rule (:func:`bearingsim.stats.significant`:
    t Student's 97.5 % quantile of the Welch-Satterthwaite degrees of freedom, each rung's standard error from
    :func:`bearingsim.stats.sem_batches` of ``rotations`` batch means, None: :data:`bearingsim.stats.BATCHES`;
    round-off is no change). A change next to a failed rung (NaN) is not judged; the failed rungs are named."""
    nb = BATCHES if rotations is None else sem_batches(rotations)
    out = []
    for rpm in sorted({r["rpm"] for r in rows}):
        rs = sorted((r for r in rows if r["rpm"] == rpm), key=lambda r: r["rung"])
        parts = []
        for a, b in zip(rs, rs[1:]):
            d = b["I_dec_mean_Ns"] - a["I_dec_mean_Ns"]
            if math.isnan(d):
                continue
            se = math.hypot(a["I_dec_sem_Ns"], b["I_dec_sem_Ns"])
            mark = significant(b["I_dec_mean_Ns"], b["I_dec_sem_Ns"], a["I_dec_mean_Ns"], a["I_dec_sem_Ns"], nb, nb)
            if mark is None:  # a rung of fewer than 2 recorded rotations has no batch-means error
                sig = "not judged: no standard error from fewer than 2 rotations"
            else:
                t = critical_ses(a["I_dec_sem_Ns"], b["I_dec_sem_Ns"], nb, nb)
                sig = ("significant" if mark else "not significant") + f": {t:.3g} SE = {t * se * 1e3:.2g} mN s"
            parts.append(f"rung {b['rung']} {b['scene']} {d * 1e3:+.2f} mN s ({sig})")
        failed = [f"{r['rung']} {r['scene']}" for r in rs if r.get("status", "done") == "failed"]
        changes = [r for r in rs[1:] if not math.isnan(r["change_from_previous"])]
        if not changes:
            out.append(f"{rpm:g} rpm: no change of I_dec to compare (failed rungs: {', '.join(failed)}).")
            continue
        big = max(changes, key=lambda r: abs(r["change_from_previous"]))
        total = rs[-1]["I_dec_mean_Ns"] - rs[0]["I_dec_mean_Ns"]
        total_text = "n/a" if math.isnan(total) else f"{total * 1e3:+.2f} mN s"
        line = (f"{rpm:g} rpm: the largest change of I_dec is at rung {big['rung']} {big['scene']} "
                f"({big['change_from_previous'] * 1e3:+.2f} mN s; full - reduced = {total_text}); " + "; ".join(parts))
        if failed:
            line += f"; failed rungs: {', '.join(failed)}"
        out.append(line + ".")
    return out


def format_table(rows: list[dict]) -> str:
    """The table for the terminal (impulses in mN s, cage slip in per cent as in docs/crosscheck.md)."""
    head = (f"{'rpm':>6s} {'rung':>4s} {'scene':18s} {'I_dec [mN s]':>16s} {'I_acc [mN s]':>16s} "
            f"{'v1 [m/s]':>9s} {'slip [%]':>9s} {'change [mN s]':>13s}")
    lines = [head]
    for r in rows:
        ch = "" if math.isnan(r["change_from_previous"]) else f"{r['change_from_previous'] * 1e3:+.3f}"
        def sem(v):  # NaN: fewer than 2 rotations, no standard error
            return f"{'n/a':>6s}" if math.isnan(v) else f"{v * 1e3:6.3f}"

        def mean(v):  # NaN: a failed rung, no number (the verdict names it)
            return f"{'n/a':>7s}" if math.isnan(v) else f"{v * 1e3:7.3f}"

        lines.append(f"{r['rpm']:6g} {r['rung']:4d} {r['scene']:18s} "
                     f"{mean(r['I_dec_mean_Ns'])} ± {sem(r['I_dec_sem_Ns'])} "
                     f"{mean(r['I_acc_mean_Ns'])} ± {sem(r['I_acc_sem_Ns'])} "
                     f"{_first_impact(r['first_impact_speed_m_s'])} {_percent(r['cage_slip']):>9s} {ch:>13s}")
    return "\n".join(lines)


def _first_impact(v: float) -> str:
    """The first rear-face impact's speed [m/s], or n/a where a rung's rollers met no rear face at speed (the
    kinematic cage pushes them continuously), as docs/crosscheck.md prints it."""
    return f"{'n/a':>9s}" if math.isnan(v) else f"{v:9.4f}"


def _percent(fraction: float) -> str:
    """A fraction in per cent with its sign and 2 decimals ("+0.38", "-0.14"); one that rounds to zero is
    "0.00", with no sign (a slip of -1.2e-06 is not "-0.00"); "n/a" for NaN (a failed rung)."""
    if math.isnan(fraction):
        return "n/a"
    text = f"{fraction * 100:+.2f}"
    return "0.00" if float(text) == 0.0 else text
