"""Which unknowns dominate I_dec of the reference bearing, and how wide the answer is (docs/sensitivity.md,
"What dominates, for the reference bearing"; the intervals of docs/whatif.md).

    python benchmarks/sensitivity_finding.py                  # everything, then the tables
    python benchmarks/sensitivity_finding.py --part seeds     # only the two-seed check

The whole bearing: ``scenarios/multibody_<rpm>rpm.toml`` at 1000, 3000 and 6000 rpm, roller-guided and
outer-land-guided (``bearing.cage_guidance``), on the fast scene (``multibody.raceway_contact = "rigid"``,
within 3 % of the Hertz scene, docs/fast_scene.md), 1 warm-up + ``--rotations`` recorded rotations. The
reduced model: ``scenarios/paper_<rpm>rpm.toml`` under the same ranges (the ranged keys it reads). Each
configuration runs ``bearingsim.sensitivity`` (10 % step) and ``bearingsim.uncertainty`` (seed 0) into
its own folder under ``--out``; a second run of the same command reuses every archive (the sweep engine
resumes) and only prints the tables. Markdown tables on stdout.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import bearingsim
from bearingsim.ranges import ranged_keys
from bearingsim.scenario import load_scenario

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
SPEEDS = (1000, 3000, 6000)
GUIDANCE = {"rollers": "roller", "outer_land": "outer land"}
SEED_CHECK = (6000, "rollers")  # the configuration run with a second seed


def whole_bearing(rpm, guidance, rotations):
    return load_scenario(SCENARIOS / f"multibody_{rpm}rpm.toml",
                         ["multibody.raceway_contact=rigid", f"numerics.rotations={rotations}",
                          f"bearing.cage_guidance={guidance}"])


def configurations(rotations):
    """[(label, scenario)]: the six whole-bearing configurations, then the reduced model at each speed."""
    out = [(f"{rpm} {GUIDANCE[g]}", whole_bearing(rpm, g, rotations)) for rpm in SPEEDS for g in GUIDANCE]
    return out + [(f"{rpm} reduced", load_scenario(SCENARIOS / f"paper_{rpm}rpm.toml")) for rpm in SPEEDS]


def folder(out, label):
    return Path(out) / label.replace(" ", "_")


def _timed(what, fn):
    t0 = time.perf_counter()
    r = fn()
    print(f"{what}: {r.outcome.counts()}, {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
    return r


def _se_ci(row, name):
    """Standard error of an index from its 95 % bootstrap interval (half its width / 1.96)."""
    return (row[f"{name}_high"] - row[f"{name}_low"]) / (2 * 1.96)


def sensitivity_table(sens, configs):
    """Change of ln I_dec across each key's range (S ln(high/low)) ± its standard error, per configuration."""
    labels = [lab for lab, _ in configs if lab in sens]
    keys = list(dict.fromkeys(r["key"] for lab in labels for r in sens[lab].table))
    print("\nChange of ln I_dec across each key's plausible range, S ln(high/low) ± SE (10 % step; reduced: SE 0)\n")
    print("| key | range | " + " | ".join(labels) + " |")
    print("|---|---|" + "---|" * len(labels))
    ranges = ranged_keys(configs[0][1])
    for k in keys:
        cells = []
        for lab in labels:
            row = next((r for r in sens[lab].table if r["key"] == k and r["quantity"] == "I_dec"), None)
            if row is None:
                cells.append("–")
                continue
            lo, hi, _ = ranges[k]
            cells.append(f"{row['over_range']:+.2f} ± {row['sensitivity_se'] * math.log(hi / lo):.2f}")
        lo, hi, _ = ranges[k]
        print(f"| {k} | {lo:g} – {hi:g} | " + " | ".join(cells) + " |")


def spread_table(unc):
    print("\nI_dec over the plausible ranges (all keys at once, uniform): median and 5–95 % interval [mN s]\n")
    print("| configuration | keys | N | runs | I_dec median | 5–95 % | width / median | I_acc median (5–95 %) | cage slip 5–95 % |")
    print("|---|---|---|---|---|---|---|---|---|")
    for lab, u in unc.items():
        sp = {s["quantity"]: s for s in u.spread}
        d, a = sp["I_dec"], sp["I_acc"]
        slip = sp.get("cage_slip")
        slip_txt = f"{slip['p05'] * 100:+.3f} .. {slip['p95'] * 100:+.3f} %" if slip else "–"
        print(f"| {lab} | {len(u.keys)} | {u.samples} | {u.samples * (len(u.keys) + 2)} | {d['median'] * 1e3:.2f} | "
              f"{d['p05'] * 1e3:.2f} – {d['p95'] * 1e3:.2f} | {(d['p95'] - d['p05']) / d['median']:.0%} | "
              f"{a['median'] * 1e3:.2f} ({a['p05'] * 1e3:.2f} – {a['p95'] * 1e3:.2f}) | {slip_txt} |")


def sobol_table(unc, configs):
    labels = [lab for lab, _ in configs if lab in unc]
    keys = list(dict.fromkeys(r["key"] for lab in labels for r in unc[lab].table))
    print("\nShare of the variance of I_dec: total Sobol index ST [95 % bootstrap interval]\n")
    print("| key | " + " | ".join(labels) + " |")
    print("|---|" + "---|" * len(labels))
    for k in keys:
        cells = []
        for lab in labels:
            row = next((r for r in unc[lab].table if r["key"] == k and r["quantity"] == "I_dec"), None)
            cells.append("–" if row is None else f"{row['ST']:.2f} [{row['ST_low']:.2f}, {row['ST_high']:.2f}]")
        print(f"| {k} | " + " | ".join(cells) + " |")
    sums = [sum(r["S1"] for r in unc[lab].table if r["quantity"] == "I_dec") for lab in labels]
    print("| sum of first-order S1 | " + " | ".join(f"{s:.2f}" for s in sums) + " |")


def seed_table(a, b):
    """Seed 0 against seed 1: each index's difference against 1.96 sqrt(SE_a^2 + SE_b^2)."""
    print(f"\nTwo seeds, {SEED_CHECK[0]} rpm {GUIDANCE[SEED_CHECK[1]]}-guided, N = {a.samples}: I_dec's indices; "
          "agree = |difference| <= 1.96 sqrt(SE0^2 + SE1^2), SE from each 95 % interval\n")
    print("| key | S1 seed 0 | S1 seed 1 | agree | ST seed 0 | ST seed 1 | agree |")
    print("|---|---|---|---|---|---|---|")
    n_ok = n = 0
    for ra in (r for r in a.table if r["quantity"] == "I_dec"):
        rb = next(r for r in b.table if r["key"] == ra["key"] and r["quantity"] == "I_dec")
        cells = []
        for name in ("S1", "ST"):
            ok = abs(ra[name] - rb[name]) <= 1.96 * math.hypot(_se_ci(ra, name), _se_ci(rb, name))
            n_ok, n = n_ok + ok, n + 1
            cells += [f"{ra[name]:.2f} [{ra[name + '_low']:.2f}, {ra[name + '_high']:.2f}]",
                      f"{rb[name]:.2f} [{rb[name + '_low']:.2f}, {rb[name + '_high']:.2f}]", "yes" if ok else "**no**"]
        print(f"| {ra['key']} | " + " | ".join(cells) + " |")
    print(f"\n{n_ok} of {n} indices agree.")
    for u, seed in ((a, 0), (b, 1)):
        d = next(s for s in u.spread if s["quantity"] == "I_dec")
        print(f"seed {seed}: I_dec median {d['median'] * 1e3:.2f} mN s, 5–95 % {d['p05'] * 1e3:.2f} – {d['p95'] * 1e3:.2f}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="outputs/sensitivity_finding", help="folder of every study's folder")
    p.add_argument("--rotations", type=int, default=10, help="recorded rotations of the whole bearing (after 1 warm-up)")
    p.add_argument("--samples", type=int, default=16, help="uncertainty base sample N of the whole bearing")
    p.add_argument("--reduced-samples", type=int, default=64, help="uncertainty base sample N of the reduced model")
    p.add_argument("--part", choices=("all", "sensitivity", "uncertainty", "seeds"), default="all")
    p.add_argument("-j", "--jobs", type=int, default=2)
    args = p.parse_args(argv)
    configs = configurations(args.rotations)
    sens, unc = {}, {}
    if args.part in ("all", "sensitivity"):
        for lab, sc in configs:
            sens[lab] = _timed(f"sensitivity {lab}", lambda: bearingsim.sensitivity(
                sc, folder(args.out, lab) / "sensitivity", jobs=args.jobs))
        sensitivity_table(sens, configs)
    if args.part in ("all", "uncertainty"):
        for lab, sc in configs:
            n = args.reduced_samples if sc.model == "reduced" else args.samples
            unc[lab] = _timed(f"uncertainty {lab}", lambda: bearingsim.uncertainty(
                sc, n, folder(args.out, lab) / "uncertainty", seed=0, jobs=args.jobs))
        spread_table(unc)
        sobol_table(unc, configs)
    if args.part in ("all", "seeds"):
        lab = f"{SEED_CHECK[0]} {GUIDANCE[SEED_CHECK[1]]}"
        sc = dict(configs)[lab]
        runs = [_timed(f"uncertainty {lab} seed {seed}", lambda: bearingsim.uncertainty(
            sc, args.samples, folder(args.out, lab) / ("uncertainty" if seed == 0 else f"uncertainty_seed{seed}"),
            seed=seed, jobs=args.jobs)) for seed in (0, 1)]
        seed_table(*runs)


if __name__ == "__main__":
    main()
