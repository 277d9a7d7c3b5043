"""Discretization errors of published whole-bearing numbers that no other benchmark measures.

    python -m benchmarks.discretization psi     # wear profile: 16 / 32 / 64 / 128 bins of psi (wear-test scene)
    python -m benchmarks.discretization theta   # load-zone contact extent, F_dec onset: 180 / 360 / 720 / 1440 bins of theta
    python -m benchmarks.discretization dt      # I_dec at the automatic step and half of it (the change, not the error)
    python -m benchmarks.discretization order   # I_dec at the step and 3 halvings: observed order, extrapolated error
    python -m benchmarks.discretization order --bins=500 --raceways=hertz --halvings=4 --warmup=2 --rotations=4
    python -m benchmarks.discretization rig     # the rig's flat pocket 0 over the reduced model: s.e. and dt / 2 (docs/validation.md)
    python -m benchmarks.discretization whatif  # docs/whatif.md's I_dec with standard errors, without rotation 1, at dt / 2
    python -m benchmarks.discretization life    # the life study to depth = 0.1 mm (fast scene) with 16 / 32 / 64 bins of psi
    python -m benchmarks.discretization stages  # the same life study in 5 / 10 / 20 stages

``--bins=32,64`` chooses the bin counts, ``--set=KEY=VALUE`` (repeatable) overrides a scenario key, e.g.
``--set=numerics.dt_s=2e-6`` or ``--set=numerics.warmup_rotations=41`` (the next 40 rotations).

The bins are recording only: the trajectory, and every summary number that is not binned, is the same bit
for bit at every bin count (each table prints I_dec to show it), so a difference between rows is the
binning error alone. The bin counts are the model's constants (``multibody.recorder.FACE_BINS`` = 32,
``multibody.core.THETA_BINS`` = 360); this script changes them for its own runs only.

``psi``: ``scenarios/wear_test_6000rpm.toml`` (Hertz raceways, 1 warm-up + 40 rotations, 922 N) worn for
1.6e5 inner-ring rotations at k = 6e-4, H = 1.5 GPa, the numbers docs/wear.md quotes (Fig. 13, Fig. 14,
Table 3). ``theta``: ``scenarios/multibody_3000rpm.toml`` with the fixtures' settings of
``benchmarks/whole_bearing.py checks`` (1 warm-up + 20 rotations, phi = 23.5 deg), the numbers
docs/multibody.md's check table quotes.

Each study is several whole-bearing runs of 1 warm-up + 10 to 40 rotations, minutes or more; it prints
markdown tables and writes nothing (``life`` keeps its studies in temporary folders, removed after).
"""
from __future__ import annotations

import argparse
from pathlib import Path


SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


def _run(name, sets):
    import bearingsim
    from bearingsim.scenario import load_scenario

    return bearingsim.run(load_scenario(SCENARIOS / f"{name}.toml", list(sets)))


def dt(rpms=(1000, 3000, 6000), sets=(), raceways=("hertz", "rigid"), rotations=40):
    """The change of the mean I_dec over 1 warm-up + ``rotations`` from the automatic step to half of it, each
    with its batch-means standard error (``bearingsim.stats``). The full scene is chaotic: the two runs are two
    trajectories, so their difference is the step's effect plus statistical scatter, judged against the
    combined standard error. It is not the step's error: for the first-order scheme the change is about half
    of it, less where the convergence is slower (``order`` measures the error from three halvings)."""
    import math

    from bearingsim.stats import batch_sem, pocket_means

    print("| rpm | raceways | dt [us] | I_dec [mN s] ± s.e. | dt / 2: I_dec ± s.e. | difference | in combined s.e. |")
    print("|---|---|---|---|---|---|---|")
    for raceway in raceways:
        for rpm in rpms:
            base = ["numerics.warmup_rotations=1", f"numerics.rotations={rotations}",
                    f"multibody.raceway_contact={raceway}", *sets]
            a = _run(f"multibody_{rpm}rpm", base)
            step = a.provenance["dt_s"]
            b = _run(f"multibody_{rpm}rpm", [*base, f"numerics.dt_s={step / 2!r}"])
            ia, ib = a.summary["I_dec_mean_Ns"], b.summary["I_dec_mean_Ns"]
            sa, sb = (batch_sem(pocket_means(r.per_rotation["I_dec"])) for r in (a, b))
            diff = (ia - ib) / ib
            print(f"| {rpm} | {raceway} | {step * 1e6:.1f} | {ia * 1e3:.3f} ± {sa * 1e3:.3f} | {ib * 1e3:.3f} ± "
                  f"{sb * 1e3:.3f} | {diff:+.2%} | {(ia - ib) / math.hypot(sa, sb):+.2f} |", flush=True)


def _halvings(rpm, raceway, sets, halvings, rotations, warmup=1):
    """Mean I_dec over ``warmup`` + ``rotations`` without the first recorded rotation (the warm-up's trace,
    docs/statistics.md) at the automatic step and ``halvings`` halvings of it: ``[(dt, mean, s.e., CPU s per
    simulated rotation)]``, the CPU time of this process (``time.process_time``: the wall time of a host that runs
    other work too is not the run's); a first run of one rotation before them leaves the kernels' compilation out."""
    import time

    from bearingsim.stats import batch_sem, pocket_means

    name = f"multibody_{rpm}rpm" if (SCENARIOS / f"multibody_{rpm}rpm.toml").exists() else "multibody_3000rpm"
    base = [f"operating.inner_ring_speed_rpm={rpm}", f"multibody.raceway_contact={raceway}", *sets]
    _run(name, [*base, "numerics.warmup_rotations=1", "numerics.rotations=1"])
    base += [f"numerics.warmup_rotations={warmup}", f"numerics.rotations={rotations}"]
    rows, step = [], None
    for k in range(halvings + 1):
        t0 = time.process_time()
        r = _run(name, base if step is None else [*base, f"numerics.dt_s={step / 2 ** k!r}"])
        cpu = (time.process_time() - t0) / (rotations + 1)
        step = step or r.provenance["dt_s"]
        x = pocket_means(r.per_rotation["I_dec"])[1:]
        rows.append((r.provenance["dt_s"], float(x.mean()), batch_sem(x), cpu))
    return rows


def _order(m, s, k):
    """The observed order of convergence from the means ``m`` (standard errors ``s``) at steps k, k + 1, k + 2,
    each half the one before: log2 of the ratio of the two changes, with its standard error (delta method, the
    three runs independent); NaN where the changes differ in sign."""
    import math

    d1, d2 = m[k] - m[k + 1], m[k + 1] - m[k + 2]
    if d1 * d2 <= 0:
        return float("nan"), float("nan")
    g = (1 / d1, -1 / d1 - 1 / d2, 1 / d2)
    return math.log2(d1 / d2), math.sqrt(sum((gi * s[k + i]) ** 2 for i, gi in enumerate(g))) / math.log(2)


def order(rpms=(500, 1000), sets=(), raceways=("hertz", "rigid"), halvings=3, rotations=20, warmup=1):
    """The step's error of the mean I_dec, measured: ``warmup`` + ``rotations`` (the first recorded rotation
    dropped) at the automatic step and ``halvings`` halvings of it (3, 1 warm-up and 20 rotations unless given). Each row gives the change from the step before with its
    standard error (batch means, the runs independent), the observed order from each three successive steps
    (``_order``), and the offset from the first-order Richardson extrapolation of the two finest steps,
    2 I(dt / 8) - I(dt / 4) (the scheme converges at about first order, docs/fast_scene.md). With both raceways,
    the rigid rows also give their offset from the Hertz extrapolation, and the last column is the CPU time per
    simulated rotation, warm-up included (``_halvings``)."""
    import math

    print("| rpm | raceways | dt [us] | I_dec ± s.e. [mN s] | change from the step before | observed order "
          "| off the extrapolation | off Hertz extrapolated | CPU s per rotation |")
    print("|---|---|---|---|---|---|---|---|---|")
    for rpm in rpms:
        hertz = None
        for raceway in raceways:
            rows = _halvings(rpm, raceway, sets, halvings, rotations, warmup)
            m, s = [r[1] for r in rows], [r[2] for r in rows]
            ext, se_ext = 2 * m[-1] - m[-2], math.hypot(2 * s[-1], s[-2])
            hertz = (ext, se_ext) if raceway == "hertz" else hertz
            for k, (step, mk, sk, cpu) in enumerate(rows):
                change = (f"{mk / m[k - 1] - 1:+.2%} ± {math.hypot(sk, s[k - 1]) / m[k - 1]:.2%}" if k else "")
                p, sp = _order(m, s, k - 2) if k >= 2 else (math.nan, math.nan)
                off = f"{mk / ext - 1:+.2%} ± {math.hypot(sk, se_ext) / ext:.2%}"
                vs = (f"{mk / hertz[0] - 1:+.2%} ± {math.hypot(sk, hertz[1]) / hertz[0]:.2%}"
                      if raceway != "hertz" and hertz else "")
                print(f"| {rpm} | {raceway} | {step * 1e6:.2f} | {mk * 1e3:.3f} ± {sk * 1e3:.3f} | {change} | "
                      f"{'' if math.isnan(p) else f'{p:.2f} ± {sp:.2f}'} | {off} | {vs} | {cpu:.3f} |", flush=True)
            print(f"| {rpm} | {raceway} | extrapolated | {ext * 1e3:.3f} ± {se_ext * 1e3:.3f} | | | | | |", flush=True)


def rig(rpms=(2000, 2500, 3000, 3500, 4000), sets=()):
    """docs/validation.md's and docs/geometry.md's rig rows: pocket 0's mean I_dec over the reduced model's,
    with the batch-means standard error of pocket 0's per-rotation series, at the automatic step and at half
    of it (``scenarios/rig_3000rpm.toml`` and ``paper_3000rpm.toml`` at each speed, which differ from the
    other speeds' files in the speed alone; 1 warm-up + 20 rotations, as ``bearingsim validate``)."""
    from bearingsim.stats import batch_sem

    print("| rpm | reduced [mN s] | dt [us] | pocket 0 [mN s] ± s.e. | ratio ± s.e. | dt / 2: pocket 0 ± s.e. | ratio ± s.e. |")
    print("|---|---|---|---|---|---|---|")
    for rpm in rpms:
        speed = [f"operating.inner_ring_speed_rpm={rpm}", *sets]
        red = _run("paper_3000rpm", speed).summary["I_dec_mean_Ns"]
        a = _run("rig_3000rpm", speed)
        step = a.provenance["dt_s"]
        b = _run("rig_3000rpm", [*speed, f"numerics.dt_s={step / 2!r}"])
        cells = []
        for r in (a, b):
            x = r.per_rotation["I_dec"][:, 0]
            m, se = float(x.mean()), batch_sem(x)
            cells.append(f"{m * 1e3:.2f} ± {se * 1e3:.2f} | {m / red:.3f} ± {se / red:.3f}")
        print(f"| {rpm} | {red * 1e3:.2f} | {step * 1e6:.1f} | {cells[0]} | {cells[1]} |", flush=True)


def whatif(rpms=(3000, 6000), sets=()):
    """docs/whatif.md's whole-bearing rows (1 warm-up + 20 rotations, Hertz raceways): mean I_dec with its
    batch-means standard error, the mean without the first recorded rotation (the warm-up's trace,
    docs/statistics.md), and the mean at half the step with its standard error."""
    from bearingsim.stats import batch_sem, pocket_means

    print("| rpm | cage | I_dec ± s.e. [mN s] | without rotation 1 | dt / 2: I_dec ± s.e. |")
    print("|---|---|---|---|---|")
    for rpm in rpms:
        for guidance in ("rollers", "outer_land", "inner_land"):
            base = ["numerics.rotations=20", f"bearing.cage_guidance={guidance}", *sets]
            a = _run(f"multibody_{rpm}rpm", base)
            b = _run(f"multibody_{rpm}rpm", [*base, f"numerics.dt_s={a.provenance['dt_s'] / 2!r}"])
            xa, xb = (pocket_means(r.per_rotation["I_dec"]) for r in (a, b))
            print(f"| {rpm} | {guidance} | {xa.mean() * 1e3:.2f} ± {batch_sem(xa) * 1e3:.2f} | {xa[1:].mean() * 1e3:.2f} | "
                  f"{xb.mean() * 1e3:.2f} ± {batch_sem(xb) * 1e3:.2f} |", flush=True)


def _life_of(sets, limit: str, stages: int, mapping: str = "shape") -> tuple[dict, str]:
    """docs/wear.md's rigid life study (``wear_test_6000rpm``, k = 6e-4, stages of 1 warm-up + 10 rotations) in a
    temporary folder: its history's columns, and what wore through the cage bar before the limit ("" if none).
    A stage that fails raises its UserError."""
    import tempfile

    from bearingsim.scenario import load_scenario
    from bearingsim.studies.life import parse_limit, read_life, run_life

    sc = load_scenario(SCENARIOS / "wear_test_6000rpm.toml",
                       ["multibody.raceway_contact=rigid", "wear.wear_coefficient=6e-4", *sets])
    with tempfile.TemporaryDirectory() as d:
        c = run_life(sc, d, parse_limit(limit), stages=stages, rotations=10, mapping=mapping)
        return c, read_life(f"{d}/life.h5")[1].get("worn_through") or ""


def _end(c: dict, worn: str) -> str:
    """The start of a row whose life ended where a cage bar wore through, before its limit."""
    return f"not reached: the cage bar wears through first, in stage {c['stage'][-1]} ({worn}); " if worn else ""


def life(bins=(16, 32, 64), sets=(), limit="depth=0.1mm"):
    """docs/wear.md's life study to the deepest point's limit, ``depth=0.1mm`` (or ``--limit=clearance=0.4mm``),
    with the worn shape fed back (the default), on the fast scene (``--set multibody.raceway_contact=rigid``,
    k = 6e-4, 10 stages of 1 warm-up + 10 rotations), its wear profile recorded and fed back in other bin counts.
    The stages run in a worker process forked from this one, which carries the changed bin count."""
    from bearingsim.errors import UserError
    from bearingsim.multibody import recorder

    saved = recorder.accumulators.__defaults__, recorder.FACE_BINS
    print("| bins of psi | inner-ring rotations to the limit | hours | fastest point's depth rate, first / last stage "
          "[mm/h] | I_dec, first / last stage [mN s] |")
    print("|---|---|---|---|---|")
    try:
        for nb in bins:
            recorder.accumulators.__defaults__, recorder.FACE_BINS = (nb,), nb
            try:
                c, worn = _life_of(sets, limit, 10)
            except UserError as exc:  # a stage that failed: a finding
                print(f"| {nb} | {exc} | | | |", flush=True)
                continue
            rate = c["max_depth_rate_um_per_h"]
            print(f"| {nb} | {_end(c, worn)}{c['rotations_end'][-1]:.0f} | {c['hours_end'][-1]:.4g} | "
                  f"{rate[0] / 1e3:.2f} / {rate[-1] / 1e3:.2f} | {c['I_dec_mean_mNs'][0]:.2f} / "
                  f"{c['I_dec_mean_mNs'][-1]:.2f} |", flush=True)
    finally:
        recorder.accumulators.__defaults__, recorder.FACE_BINS = saved


def stages(counts=(5, 10, 20), sets=(), limit="depth=0.1mm", mapping="shape"):
    """docs/wear.md's life study (the fast scene, ``--set multibody.raceway_contact=rigid``, k = 6e-4, stages of
    1 warm-up + 10 rotations, the worn shape fed back, or ``--mapping=uniform``) with 5 / 10 / 20 stages
    (``--bins`` gives the counts): a life is the wear integrated stage by stage, each stage at the wear rate its
    run measured, so the stage count is a discretization of that integral; the table shows how the life moves
    with it."""
    from bearingsim.errors import UserError

    print(f"| stages | rotations to the limit ({limit}, {mapping} mapping) | hours | change from the previous row | "
          "I_dec, first / last stage [mN s] |")
    print("|---|---|---|---|---|")
    before = None
    for n in counts:
        try:
            c, worn = _life_of(sets, limit, n, mapping)
        except UserError as exc:  # a stage that failed: a finding
            print(f"| {n} | {exc} | | | |", flush=True)
            continue
        end = float(c["rotations_end"][-1])
        change = f"{end / before - 1:+.1%}" if before else ""
        before = end
        print(f"| {n} | {_end(c, worn)}{end:.0f} | {c['hours_end'][-1]:.4g} | {change} | "
              f"{c['I_dec_mean_mNs'][0]:.2f} / {c['I_dec_mean_mNs'][-1]:.2f} |", flush=True)


def psi(bins=(16, 32, 64, 128), sets=()):
    from bearingsim import wear
    from bearingsim.multibody import recorder

    defaults = recorder.accumulators.__defaults__
    print("| bins of psi | bin width [deg] | I_dec [mN s] | front bore / middle / rim [um] | rear bore / middle / rim [um] "
          "| deepest [um] | mean depth front + rear, worst pocket [mm] | front/rear volume | CV front / rear |")
    print("|---|---|---|---|---|---|---|---|---|")
    try:
        for nb in bins:
            recorder.accumulators.__defaults__ = (nb,)
            r = _run("wear_test_6000rpm", ["wear.wear_coefficient=6e-4", "wear.hardness_Pa=1.5e9", *sets])
            rep = wear.wear_report(r, rotations=1.6e5)
            ends = {f: wear.shape_of(rep.psi_deg, (rep.depth_front if f == "front" else rep.depth_rear).mean(axis=1))
                    for f in ("front", "rear")}
            width = (rep.psi_deg[1] - rep.psi_deg[0])
            play = (rep.mean_depth("front") + rep.mean_depth("rear")).max()
            ratio = rep.volume_front / rep.volume_rear
            e = {f: " / ".join(f"{ends[f][k] * 1e6:.0f}" for k in ("bore", "middle", "rim")) for f in ends}
            print(f"| {nb} | {width:.2f} | {r.summary['I_dec_mean_Ns'] * 1e3:.4f} | {e['front']} | {e['rear']} | "
                  f"{rep.max_depth * 1e6:.0f} | {play * 1e3:.4f} | {ratio.min():.2f}–{ratio.max():.2f} "
                  f"(mean {ratio.mean():.3f}) | {rep.cov('front'):.3f} / {rep.cov('rear'):.3f} |", flush=True)
    finally:
        recorder.accumulators.__defaults__ = defaults


def theta(bins=(180, 360, 720, 1440), sets=()):
    import bearingsim.multibody as mb
    from bearingsim.multibody import core

    from benchmarks.whole_bearing import where_forces_act

    saved = core.THETA_BINS, mb.THETA_BINS
    print("| bins of theta | I_dec [mN s] | half angle from ring displacement [deg] | contact extent [deg] | F_dec onset [deg] "
          "| drive within phi + 15 deg |")
    print("|---|---|---|---|---|---|")
    try:
        for nb in bins:
            core.THETA_BINS = mb.THETA_BINS = nb
            r = _run("multibody_3000rpm", ["reduced.load_zone_half_angle_deg=23.5", "numerics.warmup_rotations=1",
                                           "numerics.rotations=20", *sets])
            s = r.summary
            drive, onset, _, _ = where_forces_act(r)
            print(f"| {nb} | {s['I_dec_mean_Ns'] * 1e3:.4f} | {s['load_zone_half_angle_deg']:.2f} | "
                  f"{s['load_zone_contact_half_angle_deg']:.2f} | {onset:.2f} | {drive:.1%} |", flush=True)
    finally:
        core.THETA_BINS, mb.THETA_BINS = saved


def _bins(text: str) -> tuple[int, ...]:
    return tuple(int(b) for b in text.split(","))


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.discretization", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study", choices=("psi", "theta", "dt", "order", "rig", "whatif", "life", "stages"))
    ap.add_argument("--bins", type=_bins, help="bin counts, e.g. 32,64 (psi, theta, life); the speeds of dt, order, "
                                               "rig, whatif; the stage counts of stages")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="scenario override (repeatable)")
    ap.add_argument("--limit", help="life and stages only: the life study's limit (default depth=0.1mm)")
    ap.add_argument("--mapping", choices=("shape", "uniform"), help="stages only: how the wear acts back (default shape)")
    ap.add_argument("--halvings", type=int, help="order only: halvings of the automatic step (default 3)")
    ap.add_argument("--warmup", type=int, help="order only: warm-up rotations (default 1)")
    ap.add_argument("--rotations", type=int, help="order only: recorded rotations, the first dropped (default 20)")
    ap.add_argument("--raceways", choices=("hertz", "rigid", "both"), help="order only: which raceway contacts "
                                                                          "(default both)")
    return ap


#: the options only some studies read, and those studies
READ_BY = {"limit": ("life", "stages"), "mapping": ("stages",), "halvings": ("order",), "warmup": ("order",),
           "rotations": ("order",), "raceways": ("order",)}


def main(argv=None) -> None:
    ap = parser()
    a = ap.parse_args(argv)
    extra = {}
    for key, studies in READ_BY.items():  # an option only some studies read: refused by the others
        if getattr(a, key) is not None:
            if a.study not in studies:
                names = " and ".join(studies)
                ap.error(f"--{key}: only the {names} {'study reads' if len(studies) == 1 else 'studies read'} it "
                         f"(not {a.study})")
            extra[key] = getattr(a, key)
    given = [a.bins] if a.bins else []
    study = {"psi": psi, "theta": theta, "life": life, "stages": stages, "whatif": whatif, "rig": rig, "dt": dt,
             "order": order}[a.study]
    if extra.get("raceways"):
        extra["raceways"] = ("hertz", "rigid") if extra["raceways"] == "both" else (extra["raceways"],)
    study(*given, sets=a.set, **extra)


if __name__ == "__main__":
    main()
