"""Which unknowns matter: the normalised sensitivity of the headline numbers to every ranged key
(``bearingsim sensitivity``).

For each key, two runs: the key at x (1 - step) and at x (1 + step), each held within the key's
plausible range (:func:`perturbed_values`), everything else as the scenario says (the same start, the
same warm-up and recorded rotations). From each run's archive, the headline
numbers y and their standard errors (:func:`headline_numbers`); then per key and number

    S = (ln y+ - ln y-) / (ln x+ - ln x-)          (d ln y / d ln x: +1 means y grows as x)

for the mean impulses ``I_dec``, ``I_acc`` and the cage's mean eccentricity, and
``(y+ - y-) / (ln x+ - ln x-)`` (d y / d ln x) for the cage slip, a signed number near zero whose
logarithm has no meaning. ``over_range`` = S ln(high / low): the change of ln y (or of y) across the key's plausible range, if
it were linear there: what ranks the keys (a key with a wide range matters more than its S says).
The standard error of S comes from the rotation-to-rotation scatter of each
run (batch means, :func:`bearingsim.studies.batch_sem`): SE(ln y) = SE(y) / y, the two runs taken as
independent (a chaotic scene forgets its start within the warm-up), so
SE(S) = sqrt(SE(ln y+)^2 + SE(ln y-)^2) / |ln x+ - ln x-|.

The reduced model repeats one no-load pass every rotation: its sensitivities have no scatter (SE 0)
and it has neither cage slip nor eccentricity (only ``I_dec`` and ``I_acc`` rows). Its I_dec jumps where the
number of impacts of a pass changes, so a difference across a step may be no local slope: each key also
runs at half the step, and ``sensitivity_half_step`` is S from those runs (NaN for the whole bearing, and
where the key's range clips the half step onto the full step's values: :func:`step_notes`).

Outputs in ``DIR``: ``sensitivity.csv`` (:data:`CSV_COLUMNS`), ``sensitivity.h5`` (the same table as an
index, with each run's archive, status and error), ``sensitivity.png`` (tornado chart), ``cases/``
(every run's ordinary archive) and ``sweep.{csv,h5}`` (the engine's index).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from bearingsim.errors import UserError
from bearingsim.scenario import unread_because  # why a key's paired runs would be identical
from bearingsim.studies.engine import Study, batch_sem, case_of, load_result
from bearingsim.wording import given_by

INDEX_FORMAT = "bearingsim sensitivity index 1"
DEFAULT_STEP = 0.10

#: headline numbers: (name, unit, what the sensitivity is: "log" d ln y / d ln x, "lin" d y / d ln x)
QUANTITIES = (("I_dec", "N s", "log"), ("I_acc", "N s", "log"), ("cage_slip", "1", "lin"),
              ("cage_eccentricity", "m", "log"))
REDUCED_QUANTITIES = ("I_dec", "I_acc")

COLUMNS = ("key", "quantity", "measure", "x", "x_minus", "x_plus", "y_minus", "y_minus_se", "y_plus", "y_plus_se",
           "sensitivity", "sensitivity_se", "over_range", "sensitivity_half_step")
#: the columns of ``sensitivity.csv``: the table's and the half step's values (``sensitivity.h5`` also has them);
#: its header starts with :data:`COLUMNS`, which marks the file as the study's
CSV_COLUMNS = (*COLUMNS, "x_minus_half", "x_plus_half")
UNITS = {"measure": "", "sensitivity": "1 (log) or y's unit (lin)", "sensitivity_se": "as sensitivity",
         "over_range": "as sensitivity", "sensitivity_half_step": "as sensitivity",
         **{c: "the key's unit" for c in ("x", "x_minus", "x_plus", "x_minus_half", "x_plus_half")},
         **{c: "the quantity's SI unit (I_dec, I_acc: N s; cage_slip: 1; cage_eccentricity: m)"
            for c in ("y_minus", "y_minus_se", "y_plus", "y_plus_se")}}
#: the paired runs' sides: at the step, and, for a deterministic model (the reduced one: no standard error
#: to show what the step does), at half of it: S there beside S says whether the difference is a local slope
SIDES = ("-", "+")
HALF_SIDES = ("-/2", "+/2")

def parse_step(text) -> float:
    """``"10%"`` or ``"0.1"`` -> 0.1; a one-line UserError naming ``--step`` unless 0 < step < 1."""
    raw = str(text).strip()
    try:
        step = float(raw[:-1]) / 100.0 if raw.endswith("%") else float(raw)
    except ValueError:
        raise UserError(f"--step {text!r}: give a relative step such as 10% or 0.1") from None
    if not (math.isfinite(step) and 0.0 < step < 1.0):
        hint = ""
        if not raw.endswith("%") and 1.0 <= abs(step) < 100.0:  # per cent without its sign: --step 10
            hint = f"; did you mean --step {raw.lstrip('-+')}%?"
        elif -1.0 < step < 0.0:  # --step=-10%: the runs are at x (1 - step) and x (1 + step) already
            hint = "; a step is taken both ways, give it positive"
        raise UserError(f"--step {text!r}: the relative step must be above 0 and below 100 % (runs at x (1 - step) "
                        f"and x (1 + step)){hint}")
    return step


def step_text(step) -> str:
    """The relative step as a percentage, as given (0.1 -> "10%", 0.001 -> "0.1%", 0.125 -> "12.5%"): a whole
    percent would show 0.1 % as "0%"."""
    return f"{float(step) * 100.0:g}%"


def runs_text(step, half: bool, keys: int, runs: int | None = None) -> str:
    """The keys and their runs, as the headers say them: "5 keys x 2 runs at x (1 ± 10%) within each key's
    range", for a study that ran half steps too (the reduced model) "5 keys x 4 runs at x (1 ± 10%) and
    x (1 ± 5%) within ...". ``runs``, the study's distinct runs, when fewer (a half step clipped to its key's
    range onto the full step's values runs nothing new): "5 keys, 16 runs at ... (not 4 a key: ...)"."""
    from bearingsim.wording import counted

    per = 4 if half else 2
    at = (f"at x (1 ± {step_text(step)})" + (f" and x (1 ± {step_text(float(step) / 2)})" if half else "")
          + " within each key's range")
    if runs is None or int(runs) == keys * per:
        return f"{counted(keys, 'key')} x {per} runs {at}"
    return (f"{counted(keys, 'key')}, {counted(int(runs), 'run')} {at} (not {per} a key: a half step the range "
            f"clips onto the full step's values is no new run)")


#: keys every run reads that move none of the headline numbers (:data:`QUANTITIES`): Archard's k and H scale
#: the wear outputs alone (worn volumes and depths k W / H of the sliding work W, which they do not change)
WEAR_SCALE_KEYS = {"wear.wear_coefficient": "Archard's wear coefficient k", "wear.hardness_Pa": "the cage's hardness H"}


def unmeasured_because(scenario, key: str) -> str | None:
    """Why varying ``key`` moves none of the numbers the sensitivity and uncertainty studies measure, or
    None: the scenario's run does not read it (:func:`bearingsim.scenario.unread_because`), or it only
    scales the wear outputs (:data:`WEAR_SCALE_KEYS`). The phrase names the scenario where its settings decide."""
    why = unread_because(scenario, key)
    if why is not None:
        return f"{scenario.source}: {why}, so varying it changes no run"
    if key in WEAR_SCALE_KEYS:
        return (f"{WEAR_SCALE_KEYS[key]} only scales the wear outputs (worn volumes and depths are proportional to "
                f"k and 1/H), so varying it changes no I_dec, I_acc, cage slip or eccentricity, the numbers the "
                f"study measures")
    return None


def default_keys(scenario) -> list[str]:
    """Every ranged key the scenario's model reads for its headline numbers (not the wear keys, which only
    scale the wear outputs: :func:`unmeasured_because`): the land keys only with a land-guided cage, the
    reduced model without the cage's mass, inertia, diameters, frictions and the multibody keys, and
    without the radial clearance when its load zone is given."""
    from bearingsim.ranges import ranged_keys

    return [k for k in ranged_keys(scenario) if unmeasured_because(scenario, k) is None]


def check_keys(scenario, keys, *, relative: bool = True, left_out: list | None = None,
               origin: str = "--keys") -> list[str]:
    """``keys`` (None: :func:`default_keys`) checked: each must have a range (one-line UserError
    naming it otherwise) and, with ``relative`` (the sensitivity study's steps x (1 -+ step)), a nonzero
    numeric value. A default key whose value is 0 is left out (a relative step cannot move it), named with
    why in ``left_out``; one given in ``keys`` is refused. The uncertainty study samples the ranges
    themselves (``relative=False``): a key's own value does not matter there. ``keys`` may be one text, of one
    key or of several separated by commas as ``--keys`` takes them. ``origin``: what gave ``keys``,
    as the refusals name it (``--keys`` of the command line, ``keys`` of the Python API's argument)."""
    from bearingsim.ranges import ranged_keys, value_of

    have = ranged_keys(scenario)
    given = keys is not None
    if isinstance(keys, str):  # one key, or several as --keys takes them ("a.b,c.d"): not its characters
        keys = [k.strip() for k in keys.split(",") if k.strip()]
    keys = default_keys(scenario) if keys is None else list(dict.fromkeys(keys))
    if not keys:
        raise UserError(f"{scenario.source}: no key has a range ([ranges.<section>.<key>] or the preset's); "
                        f"nothing to vary")
    kept = []
    for k in keys:
        if given:
            _check_given_key(scenario, k, origin)
        if k not in have:
            raise UserError(f"{given_by(origin, k)}: no range for this key in {scenario.source} or its preset (give "
                            f"[ranges.{k}] range = [low, high] and reason)")
        x = value_of(scenario, k)
        if relative and (not isinstance(x, (int, float)) or isinstance(x, bool) or x == 0):
            if given:
                raise UserError(f"{given_by(origin, k)}: its value ({x!r}) has no relative step; give the key a "
                                f"nonzero number")
            if left_out is not None:
                left_out.append((k, f"its value is {x!r}: a relative step x (1 ± step) cannot move it"))
            continue
        kept.append(k)
    if not kept:
        raise UserError(f"{scenario.source}: every ranged key is 0 ({', '.join(keys)}): a relative step cannot "
                        f"move them; give them nonzero values ('bearingsim uncertainty' samples their ranges)")
    return kept


def _check_given_key(scenario, key: str, origin: str = "--keys") -> None:
    """A one-line UserError naming ``key`` (given to ``origin``: ``--keys``, or the API's ``keys``) when no
    scenario has it (with the closest accepted key) or varying it moves no number the study measures
    (:func:`unmeasured_because`)."""
    from bearingsim.scenario import did_you_mean, known_keys

    named = given_by(origin, key)
    known = known_keys()
    if key not in known:
        raise UserError(f"{named}: unknown key{did_you_mean(key)}")
    if any(k.startswith(key + ".") for k in known):
        raise UserError(f"{named}: a section, not a key (give its keys, e.g. {key}.<key>)")
    if "." not in key:  # name, model, schema_version: the scenario's own settings, none a number to vary
        raise UserError(f"{named}: a top-level setting of the scenario, not a number of the bearing or its "
                        f"operation; give a key of a section (e.g. contact.restitution)")
    why = unmeasured_because(scenario, key)
    if why is not None:
        raise UserError(f"{named}: {why}; leave it out")
    from bearingsim.ranges import key_kind

    kind = key_kind(scenario, key)
    if kind != "float":
        what = "a list of numbers" if kind == "list" else "a count or a choice"
        raise UserError(f"{named}: not a continuous number ({what}): it has no range or derivative; "
                        f"sweep its values instead (bearingsim sweep --param {key}=A,B,...)")


def perturbed_values(scenario, key: str, step: float) -> tuple[float, float]:
    """(x-, x+) of ``key``: x (1 - step) and x (1 + step), each held within the key's plausible range
    when x lies in it (a 10 % step of the pitch diameter would leave the bearing; its range is
    +-0.5 mm): a side clipped to x itself makes the difference one-sided."""
    from bearingsim.ranges import ranged_keys, value_of

    x = float(value_of(scenario, key))
    lo, hi, _ = ranged_keys(scenario)[key]
    xm, xp = x * (1.0 - step), x * (1.0 + step)
    if x < 0.0:
        xm, xp = xp, xm
    if lo <= x <= hi:
        xm, xp = max(xm, lo), min(xp, hi)
    if not xm < xp:
        raise UserError(f"sensitivity: {key}: its range [{lo:g}, {hi:g}] leaves no room around {x:g} to vary it")
    return xm, xp


def perturbed_scenarios(scenario, keys, step: float) -> list[tuple[str, str, float, object]]:
    """``[(key, "-" or "+", value, Scenario), ...]``: each key at its two values (:func:`perturbed_values`),
    the scenario otherwise unchanged. A value the scenario refuses is a one-line UserError naming the key."""
    out = []
    for k in keys:
        for side, v in zip("-+", perturbed_values(scenario, k, step)):
            try:
                sc = scenario.replace(**{k: v})
            except UserError as exc:
                raise UserError(f"sensitivity: {k} = {v:g} (the {side} side) is refused: {exc}") from None
            out.append((k, side, v, sc))
    return out


def _recorded_windows(result) -> list[np.ndarray] | None:
    """Indices of the cage-centre samples of each recorded rotation (None without the series).

    The run ends when the cage has turned through warm-up + recorded rotations; the recorded part is
    the last t_rec = 2 pi R / (mean cage speed) of the series, split into R windows of equal time (one
    cage rotation each, the cage speed varying by its slip of ~1e-3)."""
    s = result.series.get("cage_centre")
    rot = result.per_rotation["I_dec"].shape[0]
    w = float(result.summary.get("cage_speed_mean_rad_s", float("nan")))
    if s is None or not len(s.time) or not (w > 0.0):
        return None
    t = np.asarray(s.time, float)
    t_end = t[-1]
    edges = t_end - 2.0 * math.pi * rot / w + np.arange(rot + 1) * (2.0 * math.pi / w)
    k = np.searchsorted(t, edges)
    return [np.arange(k[i], max(k[i + 1], k[i] + 1)) for i in range(rot) if k[i] < len(t)]


def headline_numbers(result) -> dict[str, tuple[float, float]]:
    """``{quantity: (mean, standard error)}`` of one run (SI), means as the archive's summary gives
    them; standard errors from batch means (:func:`batch_sem`) of the per-rotation values.

    ``I_dec``, ``I_acc``: per pocket and cage rotation (summary means; per-rotation pocket means for
    the error). ``cage_slip``: the summary's; per-rotation slips from the ``cage_slip`` series.
    ``cage_eccentricity``: mean distance of the cage centre from the bearing axis over the recorded
    rotations (``cage_centre`` series). The reduced model: ``I_dec``, ``I_acc``, SE 0."""
    s = result.summary
    d = result.per_rotation["I_dec"].mean(axis=1)
    a = result.per_rotation["I_acc"].mean(axis=1)
    if "cage_slip" not in s:  # the reduced model: one pass repeated
        return {"I_dec": (float(s["I_dec_mean_Ns"]), 0.0), "I_acc": (float(s["I_acc_mean_Ns"]), 0.0)}
    out = {"I_dec": (float(s["I_dec_mean_Ns"]), batch_sem(d)), "I_acc": (float(s["I_acc_mean_Ns"]), batch_sem(a))}
    windows = _recorded_windows(result)
    slip_se = ecc = ecc_se = float("nan")
    if windows:
        slip = np.asarray(result.series["cage_slip"].value, float)
        slip_se = batch_sem(np.array([slip[w].mean() for w in windows]))
        c = np.asarray(result.series["cage_centre"].value, float)
        r = np.hypot(c[:, 0], c[:, 1])
        per = np.array([r[w].mean() for w in windows])
        ecc, ecc_se = float(r[np.concatenate(windows)].mean()), batch_sem(per)
    out["cage_slip"] = (float(s["cage_slip"]), slip_se)
    out["cage_eccentricity"] = (ecc, ecc_se)
    return out


def sensitivity_of(measure: str, x_minus, x_plus, y_minus, se_minus, y_plus, se_plus) -> tuple[float, float]:
    """(S, SE) of one key and one number: ``measure`` "log" (d ln y / d ln x) or "lin" (d y / d ln x)."""
    dlx = math.log(x_plus) - math.log(x_minus)
    if measure == "lin":
        return (y_plus - y_minus) / dlx, math.hypot(se_plus, se_minus) / abs(dlx)
    if not (y_minus > 0.0 and y_plus > 0.0):
        return float("nan"), float("nan")
    return ((math.log(y_plus) - math.log(y_minus)) / dlx,
            math.hypot(se_plus / y_plus, se_minus / y_minus) / abs(dlx))


def missing_note(row) -> str:
    """Why a table row's sensitivity, standard error or change over the range is not a number (NaN in
    the table: ``n/a`` where it is shown), "" when all three are numbers. A number that is 0 in both runs
    (the reduced model's I_acc where no roller hits the front face) did not change: it has no relative
    change to take the logarithm of, and the key no effect on it."""
    q, measure = row["quantity"], row["measure"]
    s, se, over = (float(row[k]) for k in ("sensitivity", "sensitivity_se", "over_range"))
    if row.get("status") == "failed":
        return "a run failed"
    if not math.isfinite(s):
        ym, yp = float(row["y_minus"]), float(row["y_plus"])
        if not (math.isfinite(ym) and math.isfinite(yp)):
            return f"no {q} in the runs"
        if measure == "log" and ym == 0.0 and yp == 0.0:
            return f"{q} is 0 in both runs: no effect, and no relative change to measure"
        if measure == "log" and min(ym, yp) <= 0.0:
            return f"{q} is 0 in one run: no relative change (ln 0)"
        return f"{q}: no sensitivity"
    notes = []
    if not math.isfinite(se):
        notes.append("no standard error from fewer than 2 rotations")
    if not math.isfinite(over):
        notes.append("the key's range starts at 0: no change over it on a log scale")
    return "; ".join(notes)


def step_notes(row) -> list[str]:
    """What a row's differences are, where not the central ones they are taken for: one-sided (x+ or x- is
    x itself, the key's value at an end of its range) and a half step clipped to the key's range onto the
    full step's values (``x_minus_half``, ``x_plus_half`` of the study's index): no second slope, so its
    ``sensitivity_half_step`` is NaN rather than the full step's S shown as agreement."""
    x, xm, xp = (float(row[k]) for k in ("x", "x_minus", "x_plus"))
    notes = []
    if xp == x:
        notes.append("one-sided: x+ is x, the top of the key's range")
    elif xm == x:
        notes.append("one-sided: x- is x, the bottom of the key's range")
    hm, hp = (float(row.get(k, math.nan)) for k in ("x_minus_half", "x_plus_half"))
    if (hm, hp) == (xm, xp):
        notes.append("half step n/a: clipped to the key's range onto the full step's values")
    return notes


def row_note(row) -> str:
    """A row's notes in one line: why a number is missing (:func:`missing_note`) and :func:`step_notes`."""
    return "; ".join(n for n in (missing_note(row), *step_notes(row)) if n)


class Sensitivity(Study):
    """Paired runs of every key (:func:`perturbed_scenarios`); table ``sensitivity.{csv,h5}``, figure
    ``sensitivity.png``.

    Parameters
    ----------
    scenario : resolved scenario (either model) with ranges.
    keys : dotted keys (None: :func:`default_keys`).
    step : relative step (0.1: runs at 0.9 x and 1.1 x).
    """

    name = "sensitivity"

    def __init__(self, scenario, keys=None, step: float = DEFAULT_STEP, origin: str = "--keys"):
        from bearingsim import archive
        from bearingsim.outputs import is_own_png

        if not (isinstance(step, (int, float)) and 0.0 < step < 1.0):
            raise UserError(f"step {step!r}: the relative step must be above 0 and below 1 (0.1 = 10 %)")
        self.scenario, self.step = scenario, float(step)
        self.left_out: list[tuple[str, str]] = []  # default keys at 0, which a relative step cannot move
        self.keys = check_keys(scenario, keys, left_out=self.left_out, origin=origin)
        self.runs = {}  # (key, side) -> (value, case); no half sides where they are the full step's values
        self.half_values = {}  # key -> (x-, x+) of the half step, clipped to the key's range
        self.half = scenario.model == "reduced"  # deterministic: S at half the step too (HALF_SIDES)
        full = perturbed_scenarios(scenario, self.keys, self.step)
        half = perturbed_scenarios(scenario, self.keys, self.step / 2) if self.half else []
        for k, side, v, _ in half:
            self.half_values.setdefault(k, [None, None])[SIDES.index(side)] = v
        same = {k for k, (hm, hp) in self.half_values.items() if (hm, hp) == self._full_values(full, k)}
        cases = []
        for pairs, sides in ((full, SIDES), ([h for h in half if h[0] not in same], HALF_SIDES)):
            for k, side, v, sc in pairs:
                side = sides[SIDES.index(side)]
                c = case_of(sc, {"key": k, "side": side, "value": v})
                self.runs[(k, side)] = (v, c)
                cases.append(c)
        self.cases = cases
        self.run_count = len({c.hash for c in cases})  # a half side at the full step's value is the same run
        self.outputs = [("sensitivity.csv", ",".join(COLUMNS).encode(), "sensitivity table"),
                        ("sensitivity.h5", lambda p: archive.is_table_file(p, INDEX_FORMAT), "sensitivity table"),
                        ("sensitivity.png", is_own_png, "figure")]
        self.rows: list[dict] = []

    @staticmethod
    def _full_values(full, key) -> tuple:
        """(x-, x+) of ``key`` in :func:`perturbed_scenarios`' list ``full``."""
        return tuple(v for k, _, v, _ in full if k == key)

    def finish(self, outdir, records) -> list[Path]:
        from bearingsim.ranges import value_of

        quantities = [q for q in QUANTITIES if self.scenario.model == "multibody" or q[0] in REDUCED_QUANTITIES]
        from bearingsim.ranges import ranged_keys

        ranges = ranged_keys(self.scenario)
        rows = []
        for k in self.keys:
            lo, hi, _ = ranges[k]
            (xm, xp), (hm, hp), (rm, rp) = self._pair(outdir, records, k, SIDES)
            half = self._pair(outdir, records, k, HALF_SIDES) if (k, HALF_SIDES[0]) in self.runs else None
            hx = self.half_values.get(k, (math.nan, math.nan))
            failed = [r for r in (rm, rp, *(half[2] if half else ())) if r["status"] == "failed"]
            for q, _, measure in quantities:
                ym, sm = hm.get(q, (math.nan, math.nan))
                yp, sp = hp.get(q, (math.nan, math.nan))
                s, se = sensitivity_of(measure, xm, xp, ym, sm, yp, sp)
                s_half = math.nan
                if half:
                    (xm2, xp2), (hm2, hp2), _ = half
                    y2 = [h.get(q, (math.nan, math.nan)) for h in (hm2, hp2)]
                    s_half = sensitivity_of(measure, xm2, xp2, y2[0][0], y2[0][1], y2[1][0], y2[1][1])[0]
                rows.append({"key": k, "quantity": q, "measure": measure, "x": float(value_of(self.scenario, k)),
                             "x_minus": xm, "x_plus": xp, "y_minus": ym, "y_minus_se": sm, "y_plus": yp,
                             "y_plus_se": sp, "sensitivity": s, "sensitivity_se": se,
                             "over_range": s * math.log(hi / lo) if lo > 0 else math.nan,
                             "sensitivity_half_step": s_half, "x_minus_half": hx[0], "x_plus_half": hx[1],
                             "archive_minus": rm["archive"], "archive_plus": rp["archive"],
                             "status": "failed" if failed else "done",
                             "error": "; ".join(r["error"] for r in failed)})
        self.rows = rows
        paths = write_table(outdir, rows, self.scenario, self.step, self.left_out, self.run_count)
        return [*paths, *plot_sensitivity(outdir / "sensitivity.h5", outdir)]

    def _pair(self, outdir, records, key, sides):
        """((x-, x+), (headline numbers -, +), (records -, +)) of ``key``'s runs at ``sides``."""
        (xm, cm), (xp, cp) = self.runs[(key, sides[0])], self.runs[(key, sides[1])]
        rm, rp = records[cm.hash], records[cp.hash]
        heads = []
        for rec in (rm, rp):
            res = load_result(outdir, rec)
            heads.append(headline_numbers(res) if res is not None else {})
        return (xm, xp), tuple(heads), (rm, rp)


def write_table(outdir, rows, scenario, step, left_out=(), runs=None) -> tuple[Path, Path]:
    """``sensitivity.csv`` (exactly :data:`CSV_COLUMNS`: the table and the half step's values ``x_minus_half``,
    ``x_plus_half``; a failed pair's numbers empty) and ``sensitivity.h5`` (those columns and each
    pair's archives, status and error; ``left_out``, the default keys not varied and why, in its
    ``left_out`` attribute; ``runs``, the study's distinct runs, in its ``runs`` attribute) atomically."""
    from bearingsim import archive
    from bearingsim.outputs import write_atomic_bytes
    from bearingsim.studies.engine import table_columns, table_csv

    outdir = Path(outdir)
    csv_path = outdir / "sensitivity.csv"
    write_atomic_bytes(csv_path, table_csv(rows, CSV_COLUMNS))
    columns = (*CSV_COLUMNS, "archive_minus", "archive_plus", "status", "error")
    cols = table_columns(rows, columns)
    attrs = {"format": INDEX_FORMAT, "columns": json.dumps(columns), "scenario": scenario.to_toml(),
             "scenario_name": scenario.name, "step": float(step)}
    if runs is not None:
        attrs["runs"] = int(runs)
    if left_out:
        attrs["left_out"] = "; ".join(f"{k} ({why})" for k, why in left_out)
    h5_path = archive.write_table_file(outdir / "sensitivity.h5", cols, UNITS, attrs)
    return csv_path, h5_path


def _num(v, spec: str) -> str:
    """``v`` formatted by ``spec``, or ``n/a`` (as wide) where it is not a number."""
    width = len(format(0.0, spec))
    return format(v, spec) if math.isfinite(v) else "n/a".rjust(width)


def ran_half_steps(rows) -> bool:
    """Whether the study of ``rows`` ran half steps (the reduced model): a half step's value or slope is a number."""
    return any(math.isfinite(float(r.get(k, math.nan))) for r in rows
               for k in ("sensitivity_half_step", "x_minus_half"))


#: the line under a deterministic study's table (the command's and the report's): its S has no standard error
HALF_STEP_NOTE = ("S, half step: the same slope from runs at half the step (a deterministic model has no standard "
                  "error; where the two differ, the difference is not a local slope; n/a where the key's range clips "
                  "the half step onto the full step's values: no second slope to compare)")


#: the line under a table with a cage slip's row: its S is of the slip itself, not of its logarithm
LIN_NOTE = ("cage_slip: S = d y / d ln x, y the slip as a fraction (0.001 = 0.1 %; a signed number near 0, whose "
            "logarithm has no meaning), and over range the change of y; the other rows: S = d ln y / d ln x")


def format_table(rows: list[dict]) -> str:
    """The sensitivities for the terminal, as ``bearingsim sensitivity`` prints them: one row per key and
    quantity, S ± its standard error and the change over the key's range (n/a and why where missing); a
    deterministic study's (the reduced model's, :func:`ran_half_steps`) has no standard error to show, so no
    ± column, and S at half the step beside S instead."""
    half = ran_half_steps(rows)
    lines = [f"{'key':34s} {'quantity':18s} {'S':>9s}" + ("" if half else f" {'± SE':>8s}") + f" {'over range':>10s}"
             + (f" {'S, half step':>12s}" if half else "")]
    for r in rows:
        note = row_note(r)
        se = "" if half else f" {_num(r['sensitivity_se'], '8.3f')}"
        lines.append(f"{r['key']:34s} {r['quantity']:18s} {_num(r['sensitivity'], '+9.3f')}{se} "
                     f"{_num(r['over_range'], '+10.3f')}"
                     + (f" {_num(float(r.get('sensitivity_half_step', math.nan)), '+12.3f')}" if half else "")
                     + (f"  ({note})" if note else ""))
    if half:
        lines.append(HALF_STEP_NOTE)
    if any(r.get("measure") == "lin" for r in rows):
        lines.append(LIN_NOTE)
    return "\n".join(lines)


def read_table(path) -> tuple[list[dict], dict]:
    """Read ``sensitivity.h5``: (rows as dicts, root attributes); one-line UserError if it is not one."""
    from bearingsim import archive

    cols, meta = archive.read_table_file(path, INDEX_FORMAT)
    names = json.loads(meta["columns"])
    rows = [{c: (cols[c][i] if isinstance(cols[c][i], str) else float(cols[c][i])) for c in names}
            for i in range(len(cols[names[0]]))]
    return rows, meta


def plot_tornado(rows, title: str = ""):
    """A tornado chart: one panel per headline number, one bar per key: the change of ln y (of y for the
    cage slip) across the key's plausible range, ``over_range`` = S ln(high / low), ± 1 SE scaled alike;
    keys ordered by that change of ln I_dec, the largest on top. A key whose range starts at 0 has no
    such change (no bar; its label says so), nor has a failed pair or a slope of n/a (no bar, "n/a" at 0);
    its local slope S is in the table. A bar without a standard error (n/a) is hatched, its panel's title
    says how many (:func:`bearingsim.plotting.error_title`)."""
    from bearingsim.plotting import error_title, hatch_without_error, subplots

    quantities = [q for q in QUANTITIES if any(r["quantity"] == q[0] for r in rows)]
    fig, axes = subplots(1, len(quantities), figsize=(3.6 * len(quantities) + 1.5, 0.35 * len(
        {r["key"] for r in rows}) + 1.8), squeeze=False)
    order = sorted({r["key"] for r in rows if r["quantity"] == "I_dec"},
                   key=lambda k: -abs(np.nan_to_num(next(r["over_range"] for r in rows
                                                        if r["key"] == k and r["quantity"] == "I_dec"))))
    for ax, (q, unit, measure) in zip(axes[0], quantities):
        by = {r["key"]: r for r in rows if r["quantity"] == q}
        y = np.arange(len(order))[::-1]
        over = np.array([by[k]["over_range"] for k in order], dtype=float)
        se = np.array([by[k]["sensitivity_se"] * _log_range(rows, k) for k in order], dtype=float)
        ok = np.isfinite(over)  # n/a: no bar (not one of 0); a NaN error: no error bar (not one of 0)
        exact = np.all(se[ok] == 0.0)  # a deterministic model's: no error bars (not ones of 0)
        bars = ax.barh(y[ok], over[ok], xerr=None if exact else se[ok], color=np.where(over[ok] >= 0, "C3", "C0"),
                       capsize=2)
        hatch_without_error(bars, np.isnan(se[ok]))
        for yi in y[~ok]:
            ax.text(0.0, yi, " n/a", va="center", fontsize=7, color="0.3")
        ax.set_ylim(-0.6, len(order) - 0.4)  # every key's row, with a bar or not
        ax.axvline(0.0, color="0.3", lw=0.6)
        ax.set_yticks(y)
        ranged = [k if np.isfinite(next(r["over_range"] for r in rows if r["key"] == k)) else f"{k} (range from 0)"
                  for k in order]
        ax.set_yticklabels(ranged if ax is axes[0][0] else [""] * len(order), fontsize=8)
        ax.set_xlabel("change of ln y across the range" if measure == "log"
                      else "change of y across the range\n(y a fraction: 0.001 = 0.1 %)")
        errors = "" if ran_half_steps(rows) else error_title(se[ok], "bar")  # exact: the figure's title says so
        ax.set_title(q + (f"\n{errors}" if "n/a" in errors else ""), fontsize=9)
        ax.grid(axis="x", alpha=0.3)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return fig


def _log_range(rows, key) -> float:
    """ln(high / low) of ``key``'s range, over_range / S of a row with a slope (NaN without one)."""
    for r in rows:
        if r["key"] == key and math.isfinite(r["over_range"]) and math.isfinite(r["sensitivity"]) \
                and r["sensitivity"] != 0.0:
            return abs(r["over_range"] / r["sensitivity"])
    return math.nan


def tornado_errors(rows) -> str:
    """What the tornado's error bars are, for its title and the report's caption: none for a deterministic
    model (:func:`ran_half_steps`), none where no pair has a standard error (fewer than 2 recorded
    rotations), else ± 1 standard error."""
    if ran_half_steps(rows):
        return "no error bars: a deterministic model has no standard error (S at half the step: the table)"
    if not any(math.isfinite(float(r["sensitivity_se"])) for r in rows):
        return "no error bars: no slope has a standard error (n/a: fewer than 2 recorded rotations)"
    return "± 1 standard error (batch means over rotations)"


def plot_sensitivity(index_path, outdir) -> list[Path]:
    """Draw ``sensitivity.png`` from the index alone."""
    from bearingsim.plotting import save_figure

    rows, meta = read_table(index_path)
    errors = tornado_errors(rows)
    fig = plot_tornado(rows, f"Sensitivity of {meta.get('scenario_name', '?')}: runs at x (1 ± {step_text(meta['step'])}) "
                             "within each key's range; bars: S ln(high / low), the change across the key's plausible "
                             f"range if linear, {errors}")
    return [save_figure(fig, Path(outdir) / "sensitivity.png")]


class SensitivityResult:
    """What :func:`bearingsim.sensitivity` returns: ``table`` (rows of :data:`COLUMNS` and each pair's
    ``status``/``error``; :func:`missing_note` says why a number is NaN), ``outcome`` (the engine's
    counts), ``left_out`` (default keys not varied: ``(key, why)``) and :meth:`plot_tornado`."""

    def __init__(self, study: Sensitivity, outcome):
        self.table, self.outcome, self.step, self.keys = study.rows, outcome, study.step, study.keys
        self.scenario, self.left_out = study.scenario, study.left_out

    def plot_tornado(self):
        """The tornado chart (a matplotlib figure)."""
        return plot_tornado(self.table, f"Sensitivity of {self.scenario.name}: x (1 ± {step_text(self.step)}) within each "
                                       "key's range")

    def __repr__(self) -> str:
        return f"SensitivityResult({len(self.keys)} keys, {len(self.table)} rows, {self.outcome.counts()})"


def run_sensitivity(scenario, outdir=None, keys=None, step: float = DEFAULT_STEP, *, jobs: int = 1, engine=None,
                    progress: bool | None = False, log=None, force: bool = False) -> SensitivityResult:
    """Run the paired cases on the sweep engine into ``outdir`` (None: a temporary folder) and return
    the table. Archives already in ``outdir`` from the same cases are reused; a failed case leaves its
    key's rows with NaN numbers, its status and error."""
    study = Sensitivity(scenario, keys, step, origin="keys")
    return SensitivityResult(study, run_study(study, outdir, jobs=jobs, engine=engine, progress=progress, log=log,
                                              force=force))


def run_study(study, outdir=None, *, jobs: int = 1, engine=None, progress=False, log=None, force=False):
    """:func:`bearingsim.studies.run_studies` of one study for the Python API: in ``outdir`` or a temporary
    folder; failed cases' lines go to ``log`` (default: nowhere, the table has them); SIGINT/SIGTERM/SIGHUP
    during the cases raise KeyboardInterrupt (finished archives in ``outdir`` are kept)."""
    import signal
    import tempfile

    from bearingsim.studies.engine import make_engine, run_studies

    engine = engine or make_engine(jobs)
    log = log if log is not None else (lambda line: None)
    if outdir is None:
        with tempfile.TemporaryDirectory(prefix="bearingsim-study-") as tmp:
            out = run_studies([study], tmp, engine=engine, progress=progress, log=log, force=force)
    else:
        out = run_studies([study], outdir, engine=engine, progress=progress, log=log, force=force)
    if out.interrupted is not None:
        raise KeyboardInterrupt(signal.Signals(out.interrupted).name)
    return out
