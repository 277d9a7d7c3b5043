"""How wide is the answer: every ranged key sampled over its range (``bearingsim uncertainty``).

Design (Saltelli 2010): a scrambled Sobol' sequence (``scipy.stats.qmc.Sobol``, seeded) of N points in
2k dimensions (k ranged keys) gives two independent quasi-random matrices A and B (N x k, uniform over
the box of the ranges: the keys are taken independent and uniform within their plausible ranges, the
least informative assumption a range allows); AB_i is A with column i from B. The model runs N (k + 2)
times. For each headline number y:

* median and 5-95 % interval over the 2N independent points of A and B;
* first-order Sobol index, Saltelli (2010) Eq. (b): S_i = mean(f(B) (f(AB_i) - f(A))) / V, with f
  centred on its mean over A and B (same expectation, much smaller scatter when mean(f) >> std(f));
* total index, Jansen (1999): ST_i = mean((f(A) - f(AB_i))^2) / (2 V);

V the variance of f over A and B. Both estimators are the ones Saltelli et al. (2010, Comput. Phys.
Commun. 181:259, Table 2) recommend. 95 % confidence intervals by bootstrap over the N rows (seeded).
A row with a failed run is dropped from A, B and every AB_i (rows are independent draws).

:func:`design` and :func:`sobol_indices` are the whole method; the study only runs the cases between
them (the Ishigami test goes through the same two functions).
"""
from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np

from bearingsim.errors import UserError
from bearingsim.studies.engine import Study, case_of, summary_of

INDEX_FORMAT = "bearingsim uncertainty index 1"
#: the largest --seed: the table stores it as a 64-bit signed integer (numpy's generator takes any)
MAX_SEED = 2**63 - 1
BOOTSTRAP = 1000
CONFIDENCE = 0.95
QUANTITIES = (("I_dec", "I_dec_mean_Ns", "N s"), ("I_acc", "I_acc_mean_Ns", "N s"), ("cage_slip", "cage_slip", "1"))
COLUMNS = ("quantity", "key", "S1", "S1_low", "S1_high", "ST", "ST_low", "ST_high")
SPREAD_COLUMNS = ("quantity", "median", "p05", "p95", "mean", "std", "runs_used")


def design(bounds: np.ndarray, n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, AB): A and B [n, k] and AB [k, n, k] (AB[i] = A with column i from B), in the units of
    ``bounds`` [k, 2] (low, high per key). Scrambled Sobol' points, seeded: the same seed gives the same
    design. n need not be a power of 2 (the points are then less balanced)."""
    from scipy.stats import qmc

    bounds = np.asarray(bounds, float)
    k = len(bounds)
    sampler = qmc.Sobol(d=2 * k, scramble=True, seed=np.random.default_rng(seed))
    with warnings.catch_warnings():  # "balance properties ... power of 2": said in the docs
        warnings.simplefilter("ignore", UserWarning)
        u = sampler.random(n)
    x = bounds[:, 0] + u.reshape(n, 2, k) * (bounds[:, 1] - bounds[:, 0])
    a, b = x[:, 0, :].copy(), x[:, 1, :].copy()
    ab = np.repeat(a[None, :, :], k, axis=0)
    for i in range(k):
        ab[i, :, i] = b[:, i]
    return a, b, ab


def _indices(fa, fb, fab):
    # centred on the mean of A and B: the estimators' expectations are unchanged (E[f(AB_i) - f(A)] = 0)
    # and the first-order estimator's variance no longer grows with mean(f)^2 / V (an impulse's mean is
    # several times its spread)
    c = np.mean(np.concatenate([fa, fb]))
    fa, fb, fab = fa - c, fb - c, fab - c
    v = np.var(np.concatenate([fa, fb]), ddof=1)
    if not v > 0.0:  # a bootstrap resample where A and B do not vary: no shares (NaN, not +-inf)
        return np.full(len(fab), np.nan), np.full(len(fab), np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):  # a resample where nothing varies: NaN
        s1 = np.mean(fb[None, :] * (fab - fa[None, :]), axis=1) / v
        st = 0.5 * np.mean((fa[None, :] - fab) ** 2, axis=1) / v
    return s1, st


def sobol_indices(fa, fb, fab, seed: int = 0, bootstrap: int = BOOTSTRAP, confidence: float = CONFIDENCE) -> dict:
    """First-order (Saltelli 2010) and total (Jansen 1999) Sobol indices of one output.

    Parameters
    ----------
    fa, fb : [n] outputs at A and B;  fab : [k, n] outputs at AB_i.
    seed : the bootstrap's seed.

    Returns
    -------
    dict of arrays [k]: ``S1``, ``ST``, their bootstrap percentile intervals ``S1_low``/``S1_high``,
    ``ST_low``/``ST_high`` (``confidence``) and bootstrap standard errors ``S1_se``/``ST_se``.
    """
    fa, fb, fab = np.asarray(fa, float), np.asarray(fb, float), np.asarray(fab, float)
    s1, st = _indices(fa, fb, fab)
    rng = np.random.default_rng(seed)
    n = len(fa)
    boot1, boott = np.empty((bootstrap, len(s1))), np.empty((bootstrap, len(st)))
    for j in range(bootstrap):
        r = rng.integers(0, n, n)
        boot1[j], boott[j] = _indices(fa[r], fb[r], fab[:, r])
    q = [50.0 * (1.0 - confidence), 50.0 * (1.0 + confidence)]
    l1, h1 = np.nanpercentile(boot1, q, axis=0)
    lt, ht = np.nanpercentile(boott, q, axis=0)
    return {"S1": s1, "ST": st, "S1_low": l1, "S1_high": h1, "ST_low": lt, "ST_high": ht,
            "S1_se": np.nanstd(boot1, axis=0, ddof=1), "ST_se": np.nanstd(boott, axis=0, ddof=1)}


def spread(fa, fb) -> dict:
    """Median, 5 % and 95 % points, mean and standard deviation of an output over A and B."""
    y = np.concatenate([np.asarray(fa, float), np.asarray(fb, float)])
    p05, med, p95 = np.percentile(y, [5.0, 50.0, 95.0])
    return {"median": float(med), "p05": float(p05), "p95": float(p95), "mean": float(y.mean()),
            "std": float(y.std(ddof=1)), "runs_used": float(len(y))}


class Uncertainty(Study):
    """The Saltelli design of a scenario's ranged keys as cases; tables ``uncertainty.csv``
    (Sobol indices), ``uncertainty_spread.csv`` (median and interval), ``uncertainty.h5``; figure
    ``uncertainty.png``.

    Parameters
    ----------
    scenario : resolved scenario with ranges.
    samples : N, the base sample (N (k + 2) cases; ``runs``, the distinct ones, is 2N for one key, whose
        AB_0 is B).
    seed : seed of the Sobol' scrambling and the bootstrap.
    keys : dotted keys (None: every ranged key the model reads, as the sensitivity study's default).
    """

    name = "uncertainty"

    def __init__(self, scenario, samples: int, seed: int = 0, keys=None, origin: str = "--keys"):
        from bearingsim import archive
        from bearingsim.outputs import is_own_png
        from bearingsim.ranges import ranged_keys
        from bearingsim.studies.sensitivity import check_keys
        from bearingsim.sweeps.spec import MAX_SWEEP_CASES

        from bearingsim.wording import given_by

        arg = (lambda name: f"--{name}") if origin.startswith("--") else str  # the option, or the API's argument
        if not isinstance(samples, int) or isinstance(samples, bool) or samples < 2:
            raise UserError(f"{given_by(arg('samples'), repr(samples))}: give at least 2 base samples (a power of 2 "
                            f"such as 64 is best)")
        if not isinstance(seed, int) or isinstance(seed, bool) or not 0 <= seed <= MAX_SEED:
            raise UserError(f"{given_by(arg('seed'), repr(seed))}: give an integer from 0 to {MAX_SEED} (2**63 - 1, "
                            f"the largest the study's table stores)")
        self.scenario, self.samples, self.seed = scenario, samples, seed
        # the ranges are sampled: any value of the key
        self.keys = check_keys(scenario, keys, relative=False, origin=origin)
        total = samples * (len(self.keys) + 2)
        if total > MAX_SWEEP_CASES:  # counted before any case is built, as a sweep's
            raise UserError(f"{given_by(arg('samples'), str(samples))}: {total} cases ({samples} x {len(self.keys) + 2}: "
                            f"the samples A, B and one block per key) are more than the {MAX_SWEEP_CASES} a sweep or "
                            f"study may have; give at most {arg('samples')}{' ' if origin.startswith('--') else '='}"
                            f"{MAX_SWEEP_CASES // (len(self.keys) + 2)}")
        r = ranged_keys(scenario)
        self.bounds = np.array([r[k][:2] for k in self.keys])
        self.a, self.b, self.ab = design(self.bounds, samples, seed)
        self.grid = {}  # (block, row) -> case; block "A", "B" or key index i for AB_i
        blocks = [("A", self.a), ("B", self.b)] + [(i, self.ab[i]) for i in range(len(self.keys))]
        cases = []
        for block, x in blocks:
            for j in range(samples):
                c = self._case(block, j, x[j])
                self.grid[(block, j)] = c
                cases.append(c)
        self.cases = cases
        # the runs are the distinct cases (the engine runs a case once): with one key AB_0 is B, 2N runs
        self.runs = len({c.hash for c in cases})
        self.outputs = [("uncertainty.csv", ",".join(COLUMNS).encode(), "uncertainty table"),
                        ("uncertainty_spread.csv", ",".join(SPREAD_COLUMNS).encode(), "uncertainty table"),
                        ("uncertainty.h5", lambda p: archive.is_table_file(p, INDEX_FORMAT), "uncertainty table"),
                        ("uncertainty.png", is_own_png, "figure")]
        self.indices: list[dict] = []
        self.spreads: list[dict] = []

    def _case(self, block, j, x):
        values = {k: float(v) for k, v in zip(self.keys, x)}
        try:
            sc = self.scenario.replace(**values)
        except UserError as exc:
            raise UserError(f"uncertainty: sample {j} ({', '.join(f'{k}={v:g}' for k, v in values.items())}) is "
                            f"refused: {exc}; narrow the ranges so that every combination is a valid bearing") from None
        label = "A" if block == "A" else "B" if block == "B" else f"AB{block}"
        return case_of(sc, {"block": label, "sample": j})

    def outputs_of(self, outdir, records) -> dict[str, np.ndarray]:
        """``{quantity: f}`` with f [k + 2, N] (rows A, B, AB_0..AB_k-1), NaN where a run failed."""
        k, n = len(self.keys), self.samples
        quantities = [q for q in QUANTITIES if self.scenario.model == "multibody" or q[0] != "cage_slip"]
        out = {q: np.full((k + 2, n), np.nan) for q, _, _ in quantities}
        for (block, j), c in self.grid.items():
            summary = summary_of(outdir, records[c.hash])  # the summary alone: no archive loaded in full
            if summary is None:
                continue
            row = 0 if block == "A" else 1 if block == "B" else 2 + block
            for q, name, _ in quantities:
                out[q][row, j] = float(summary[name])
        return out

    def finish(self, outdir, records) -> list[Path]:
        f = self.outputs_of(outdir, records)
        self.indices, self.spreads = analyse(f, self.keys, self.seed)
        paths = write_tables(outdir, self.indices, self.spreads, self)
        return [*paths, *plot_uncertainty(outdir / "uncertainty.h5", outdir)]


def analyse(f: dict[str, np.ndarray], keys, seed: int) -> tuple[list[dict], list[dict]]:
    """Sobol indices (rows of :data:`COLUMNS`) and spreads (rows of :data:`SPREAD_COLUMNS`) of every
    output ``f[q]`` [k + 2, N]; a sample row with any NaN is left out of that output."""
    indices, spreads = [], []
    for q, y in f.items():
        ok = np.all(np.isfinite(y), axis=0)
        fa, fb, fab = y[0, ok], y[1, ok], y[2:, ok]
        spreads.append({"quantity": q, **(spread(fa, fb) if ok.sum() >= 2 else dict.fromkeys(SPREAD_COLUMNS[1:], math.nan))})
        if ok.sum() >= 2 and np.var(np.concatenate([fa, fb])) > 0:
            s = sobol_indices(fa, fb, fab, seed)
        else:  # nothing varies (or too few runs): no shares
            s = {c: np.full(len(keys), math.nan) for c in COLUMNS[2:]}
        for i, key in enumerate(keys):
            indices.append({"quantity": q, "key": key, **{c: float(s[c][i]) for c in COLUMNS[2:]}})
    return indices, spreads


def write_tables(outdir, indices, spreads, study) -> list[Path]:
    """``uncertainty.csv``, ``uncertainty_spread.csv`` and ``uncertainty.h5`` (the index table plus the
    spreads and the design in its attributes), atomically."""
    from bearingsim import archive
    from bearingsim.outputs import write_atomic_bytes
    from bearingsim.studies.engine import table_columns, table_csv

    outdir = Path(outdir)
    p1, p2 = outdir / "uncertainty.csv", outdir / "uncertainty_spread.csv"
    write_atomic_bytes(p1, table_csv(indices, COLUMNS))
    write_atomic_bytes(p2, table_csv(spreads, SPREAD_COLUMNS))
    cols = table_columns(indices, COLUMNS)
    attrs = {"format": INDEX_FORMAT, "columns": json.dumps(COLUMNS), "scenario": study.scenario.to_toml(),
             "scenario_name": study.scenario.name, "samples": study.samples, "seed": study.seed,
             "keys": json.dumps(study.keys), "bounds": json.dumps(study.bounds.tolist()),
             "spread": json.dumps(spreads), "runs": study.runs}
    p3 = archive.write_table_file(outdir / "uncertainty.h5", cols, {c: "1" for c in COLUMNS[2:]}, attrs)
    return [p1, p2, p3]


#: what a panel's title counts of the indices whose 95 % interval, as the table prints it, reaches 0: drawn faded
UNRESOLVED = "not told from 0 (95 % interval reaches 0)"
#: the colours of the first-order and total indices: a light sand and a dark green, apart in greyscale too, neither a
#: face's colour
INDEX_COLOURS = {"S1": "#DDCC77", "ST": "#117733"}
#: the shade of the shares outside 0..1
NO_SHARE = "0.92"


def plot_indices(indices, spreads, title: str = ""):
    """One panel per output: S1 and ST of every key with their confidence intervals, and the output's
    median and 5-95 % interval in the panel's title, in the unit the table prints it. An index of n/a (its
    output's variance 0 or unknown, as the table says) has no bar, "n/a" at 0; one without an interval a
    hatched bar; one whose interval reaches 0 (:func:`resolved`) a faded bar: each counted in the title. The
    shares below 0 and above 1, which no index has (the estimate's scatter), are shaded."""
    from bearingsim.plotting import subplots

    qs = list(dict.fromkeys(r["quantity"] for r in indices))
    keys = list(dict.fromkeys(r["key"] for r in indices))
    fig, axes = subplots(1, len(qs), figsize=(3.8 * len(qs) + 1.5, 0.35 * len(keys) + 2.0), squeeze=False)
    y = np.arange(len(keys))[::-1]
    said, faded = 0, 0  # most lines a panel's title says of its bars: the figure grows by them
    for ax, q in zip(axes[0], qs):
        rows = {r["key"]: r for r in indices if r["quantity"] == q}
        missing = _index_bars(ax, rows, keys, y)
        said, faded = max(said, sum(n > 0 for n in missing.values())), faded + missing[UNRESOLVED]
        ax.set_title(_spread_title(q, next(s for s in spreads if s["quantity"] == q))
                     + "".join(f"\n{w}: {n} of {2 * len(keys)} indices" for w, n in missing.items() if n), fontsize=8)
        ax.set_yticks(y)
        ax.set_yticklabels(keys if ax is axes[0][0] else [""] * len(keys), fontsize=8)
        ax.set_xlabel("Sobol index (share of the variance)")
        ax.grid(axis="x", alpha=0.3)
    shaded = [_shade_no_share(ax) for ax in axes[0]]
    _index_legend(axes[0][0], faded > 0, any(shaded))
    fig.suptitle(title, fontsize=9)
    fig.set_figheight(fig.get_figheight() + 0.3 * said + 0.2)
    fig.tight_layout()
    return fig


def _spread_title(q: str, sp: dict) -> str:
    """A panel's first two lines: the output (``$I_{dec}$``) and its median and 5-95 % interval in the unit the
    table prints (:func:`shown`: the impulses in mN s)."""
    scale, unit = shown(q)
    unit = f" {unit}" if unit else ""
    name = f"$I_{{{q[2:]}}}$" if q in ("I_dec", "I_acc") else q.replace("_", " ")
    return (f"{name}: median {sp['median'] * scale:.4g}{unit}\n5-95 %: {sp['p05'] * scale:.4g} .. "
            f"{sp['p95'] * scale:.4g}{unit}")


def resolved(low: float, high: float) -> bool:
    """Whether an index's 95 % interval, as the table prints it (3 decimals), keeps clear of 0; False also
    without one (NaN)."""
    lo, hi = round(float(low), 3), round(float(high), 3)
    return bool(lo > 0.0 or hi < 0.0) if math.isfinite(lo) and math.isfinite(hi) else False


def _shade_no_share(ax) -> bool:
    """Shade the shares below 0 and above 1 that the axis shows (no index lies there: what is, is the
    estimate's scatter); whether any."""
    lo, hi = ax.get_xlim()
    spans = [(a, b) for a, b in ((lo, 0.0), (1.0, hi)) if b > a]
    for a, b in spans:
        ax.axvspan(a, b, color=NO_SHARE, zorder=0, lw=0)
    ax.set_xlim(lo, hi)
    return bool(spans)


def _index_legend(ax, faded: bool, shaded: bool) -> None:
    """The legend of the first panel, below the axes: the two indices (:data:`INDEX_COLOURS`), and what a faded
    bar and the shading mean when the figure has them."""
    from matplotlib.legend_handler import HandlerTuple
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=c) for c in INDEX_COLOURS.values()]
    labels = ["first order", "total"]
    if faded:
        handles.append(tuple(Patch(facecolor=c, alpha=0.35) for c in INDEX_COLOURS.values()))
        labels.append("faded: 95 % interval reaches 0 (not told from 0)")
    if shaded:
        handles.append(Patch(facecolor=NO_SHARE))
        labels.append("outside 0..1: no share, the estimate's scatter")
    ax.legend(handles, labels, fontsize=8, loc="upper left", bbox_to_anchor=(0.0, -0.2), ncol=2,
              handler_map={tuple: HandlerTuple(ndivide=None, pad=0.0)})


def _index_bars(ax, rows, keys, y) -> dict[str, int]:
    """S1 and ST of ``keys`` (``rows`` by key) as bars with their intervals, and how many are faded or have
    none: ``{UNRESOLVED: bars whose interval reaches 0 (:func:`resolved`), faded; "n/a (variance 0 or
    unknown)": indices of n/a, no bar (not one of 0), "n/a" at 0; "hatched (no interval)": bars without an
    error bar (not one of 0)}``. S1 light (sand), ST dark (green): they differ in greyscale too, and neither is a
    face's colour; a hatch in black on S1, in white on ST."""
    from bearingsim.plotting import hatch_without_error

    missing = {UNRESOLVED: 0, "n/a (variance 0 or unknown)": 0, "hatched (no interval)": 0}
    for off, name, hatch_colour in ((0.18, "S1", "black"), (-0.18, "ST", "white")):
        color = INDEX_COLOURS[name]
        v = np.array([rows[k][name] for k in keys], dtype=float)
        bounds = np.array([[rows[k][f"{name}_low"] for k in keys], [rows[k][f"{name}_high"] for k in keys]],
                          dtype=float)
        err = np.abs(bounds - v)
        ok = np.isfinite(v)
        bars = ax.barh(y[ok] + off, v[ok], 0.36, xerr=err[:, ok], color=color, edgecolor=hatch_colour, linewidth=0,
                       capsize=2,
                       label="first order" if name == "S1" else "total")
        hatch_without_error(bars, np.isnan(err[:, ok]).any(axis=0))
        for bar, (lo, hi) in zip(bars.patches, bounds[:, ok].T):
            if math.isfinite(lo) and math.isfinite(hi) and not resolved(lo, hi):
                bar.set_alpha(0.35)
                missing[UNRESOLVED] += 1
        for yi in y[~ok]:
            ax.text(0.0, yi + off, f" {name} n/a", va="center", fontsize=6, color="0.3")
        missing["n/a (variance 0 or unknown)"] += int((~ok).sum())
        missing["hatched (no interval)"] += int(np.isnan(err[:, ok]).any(axis=0).sum())
    ax.set_ylim(-0.6, len(keys) - 0.4)  # the rows of bars, drawn or not (n/a alone: no data to scale to)
    if not any(len(c) for c in ax.containers if hasattr(c, "patches")):
        ax.set_xlim(-0.05, 1.05)  # no index drawn: the indices' range
    return missing


def read_table(path):
    """(index rows, spreads, root attributes) of ``uncertainty.h5``; one-line UserError if not one."""
    from bearingsim import archive

    cols, meta = archive.read_table_file(path, INDEX_FORMAT)
    names = json.loads(meta["columns"])
    rows = [{c: (cols[c][i] if isinstance(cols[c][i], str) else float(cols[c][i])) for c in names}
            for i in range(len(cols[names[0]]))]
    return rows, json.loads(meta["spread"]), meta


def shown(quantity: str) -> tuple[float, str]:
    """(factor, unit) in which the tables show ``quantity``, as ``bearingsim run``, ``table`` and ``crosscheck`` do
    (:func:`bearingsim.wording.shown_as`: ``I_dec``: 1e3, ``mN s``; ``cage_slip``: 100, ``%``)."""
    from bearingsim.wording import shown_as

    keys = {q: (key, unit) for q, key, unit in QUANTITIES}
    key, unit = keys.get(quantity, (quantity, "1"))
    scale, label = shown_as(key, unit)
    return scale, ("" if label == "1" else label)


def format_table(spreads: list[dict], indices: list[dict]) -> str:
    """The spreads and Sobol indices for the terminal, as ``bearingsim uncertainty`` prints them."""
    from bearingsim.wording import counted

    lines = []
    for s in spreads:
        scale, label = shown(s["quantity"])
        lines.append(f"  {s['quantity']:10s} median {s['median'] * scale:.4g}, 5-95 %: {s['p05'] * scale:.4g} .. "
                     f"{s['p95'] * scale:.4g}{' ' + label if label else ''} "
                     f"({counted(int(s['runs_used']) if s['runs_used'] == s['runs_used'] else 0, 'run')})")
    lines.append(f"{'quantity':10s} {'key':34s} {'S1 [95 % CI]':>24s} {'ST [95 % CI]':>24s}")
    for r in indices:
        if not all(math.isfinite(r[k]) for k in ("S1", "S1_low", "S1_high", "ST", "ST_low", "ST_high")):
            lines.append(f"{r['quantity']:10s} {r['key']:34s} {'n/a':>24s} {'n/a':>24s}  (its variance is 0 or unknown)")
            continue
        lines.append(f"{r['quantity']:10s} {r['key']:34s} {r['S1']:+6.3f} [{r['S1_low']:+.3f}, {r['S1_high']:+.3f}] "
                     f"{r['ST']:+6.3f} [{r['ST_low']:+.3f}, {r['ST_high']:+.3f}]")
    return "\n".join(lines)


def plot_uncertainty(index_path, outdir) -> list[Path]:
    """Draw ``uncertainty.png`` from the index alone."""
    from bearingsim.plotting import save_figure

    rows, spreads, meta = read_table(index_path)
    fig = plot_indices(rows, spreads, f"Uncertainty of {meta.get('scenario_name', '?')}: {meta['samples']} base samples "
                                      f"({meta['runs']} runs), seed {meta['seed']}; bars: {CONFIDENCE:.0%} bootstrap intervals")
    return [save_figure(fig, Path(outdir) / "uncertainty.png")]


class UncertaintyResult:
    """What :func:`bearingsim.uncertainty` returns: ``table`` (Sobol indices, rows of :data:`COLUMNS`),
    ``spread`` (median, 5 and 95 % points of each output), ``outcome`` and :meth:`plot_indices`."""

    def __init__(self, study: Uncertainty, outcome):
        self.table, self.spread, self.outcome = study.indices, study.spreads, outcome
        self.scenario, self.samples, self.seed, self.keys = study.scenario, study.samples, study.seed, study.keys

    def plot_indices(self):
        """First-order and total Sobol indices with their intervals (a matplotlib figure)."""
        return plot_indices(self.table, self.spread, f"Uncertainty of {self.scenario.name}: N = {self.samples}, "
                                                     f"seed {self.seed}")

    def __repr__(self) -> str:
        return f"UncertaintyResult({len(self.keys)} keys, N = {self.samples}, {self.outcome.counts()})"


def run_uncertainty(scenario, outdir=None, samples: int = 64, seed: int = 0, keys=None, *, jobs: int = 1,
                    engine=None, progress: bool | None = False, log=None, force: bool = False) -> UncertaintyResult:
    """Run the design's cases on the sweep engine into ``outdir`` (None: a temporary folder) and return
    the indices and spreads (archives in ``outdir`` reused; failed rows left out, counted in ``runs_used``)."""
    from bearingsim.studies.sensitivity import run_study

    study = Uncertainty(scenario, samples, seed, keys, origin="keys")
    return UncertaintyResult(study, run_study(study, outdir, jobs=jobs, engine=engine, progress=progress, log=log,
                                              force=force))
