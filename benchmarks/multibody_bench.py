"""Benchmark cases of the multi-pocket model (for ``bearingsim bench``).

Two kinds of rows, ``wall_s`` always per simulated cage rotation (median of repeats; warm-up rotation
included in the count), beside ``pymunk_step_s``, the time spent in pymunk's own step (``cpSpaceStep``,
timed around each call inside the compiled loop) per rotation in the same run; ``wall_s -
pymunk_step_s`` is the rest of the step (force kernel, recording, batched copies, set-up):

* ``scene = full``: the full scene at 1000, 3000 and 6000 rpm over dt; ``rel_error`` is the error of
  the mean I_dec against a small-dt reference run of the same speed and length. The full scene is
  chaotic (pocket-to-pocket scatter of I_dec ~30 %), so over a few rotations this error holds
  statistical scatter (trajectories separate) as well as the dt error: it bounds the dt error from
  above, it does not measure it;
* ``scene = full_rigid_raceways``: the full scene with ``multibody.raceway_contact = "rigid"`` at its
  automatic step, error against the same Hertz reference (so it holds the chaotic scatter too;
  ``bearingsim bench --fast-scene`` compares the two scenes over 40 rotations with standard errors);
* ``scene = full_dynamic_ring``: the full scene with ``multibody.inner_ring = "dynamic"`` (the ring
  integrated with the rotor's mass, what ``auto`` chooses where fewer than two rollers would carry the
  load) at its automatic step, error against the same reference (quasi-static ring);
* ``scene = reduced_equivalent``: deterministic, at 3000 rpm over dt; ``rel_error`` against the exact
  event solution of the reduced model, whose assumptions this scene makes;
* ``scene = full_polyline_N``: the geometric error. The full scene at 3000 rpm at its automatic step with
  each arc pocket face drawn as a circumscribed polyline of N = 3, 5, 9, 17, 33 segments, against the
  exact faces over the same rotations (``rel_error``; ``sem_rel``: the exact run's standard error of the
  mean I_dec from its rotation-to-rotation scatter, relative, the scale below which a difference is not
  resolved); and the cost of the exact faces against the 3-segment polyline at 1000 and 6000 rpm, Hertz
  (4 us) and rigid raceways, repeats interleaved (``cost_ratio`` on the exact rows).

Every ``full`` row is computed on the exact faces (the default scene); its dt rows are the exact faces'
own time-step convergence.
"""
from __future__ import annotations

import math
import statistics

from bearingsim.multibody import simulate
from bearingsim.errors import SimulationUnstable
from bearingsim.multibody.core import PenetrationExceeded, choose_dt
from bearingsim.parameters import Parameters
from bearingsim.scenario import resolve

GOAL_S_PER_ROTATION = 0.2  # the goal: full scene at 6000 rpm
GOAL_ERROR = 0.01


def reference_scenario(rpm: float, rotations: int, warmup: int, scene: str = "full", load: float = 970.0,
                       phi="auto", source: str = "<bench>", raceway_contact: str = "hertz", pocket_face_segments: int = 0,
                       inner_ring: str = "auto"):
    """The reference bearing (NU214) in the multibody model at one speed and load; ``phi`` is the
    reduced-equivalent scene's load-zone half angle [deg] or "auto"."""
    doc = {
        "schema_version": 1,
        "name": f"multibody_{scene}_{rpm:g}rpm_{load:g}N",
        "model": "multibody",
        "bearing": {"preset": "NU214-Suzuki2023"},
        "operating": {"inner_ring_speed_rpm": float(rpm), "radial_load_N": float(load)},
        "multibody": {"scene": scene, "raceway_contact": raceway_contact, "pocket_face_segments": pocket_face_segments,
                      "inner_ring": inner_ring},
        "numerics": {"rotations": rotations, "warmup_rotations": warmup},
        "reduced": {"load_zone_half_angle_deg": phi},
    }
    return resolve(doc, source=source)


def _row(scene, rpm, dt, runs, total_rot, ref_idec, ref_what, ref_iacc=None):
    """One row; ``rel_error_I_acc`` (the other wear index's error) where ``ref_iacc`` is given."""
    wall = statistics.median(r.provenance["solver_wall_s"] for r in runs)
    pm = statistics.median(r.provenance["pymunk_step_s"] for r in runs)
    idec = runs[0].summary["I_dec_mean_Ns"]
    row = {
        "model": "multibody", "method": "pymunk", "scene": scene, "rpm": rpm, "dt_s": dt,
        "wall_s": wall / total_rot, "pymunk_step_s": pm / total_rot, "unit_of_work": "cage rotation",
        "run_wall_s": wall, "I_dec_Ns": idec,
        "rel_error": float("nan") if ref_what == "itself" else abs(idec - ref_idec) / ref_idec,
        "reference": ref_what, "rotations": total_rot, "steps": int(runs[0].summary["steps"]), "repeats": len(runs),
    }
    if ref_iacc is not None:
        iacc = runs[0].summary["I_acc_mean_Ns"]
        row["I_acc_Ns"] = iacc
        d_acc = abs(iacc - ref_iacc)
        rel_acc = d_acc / abs(ref_iacc) if ref_iacc else (0.0 if d_acc == 0.0 else math.inf)  # I_acc may be 0
        row["rel_error_I_acc"] = float("nan") if ref_what == "itself" else rel_acc
    return row


def _own_sem(result) -> dict:
    """A run's own standard error of its mean I_dec (relative) and the batch means it rests on."""
    from bearingsim.stats import pocket_means, sem_batches

    return {"sem_rel": ref_sem_rel(result), "batches": sem_batches(len(pocket_means(result.per_rotation["I_dec"])))}


def ref_sem_rel(result) -> float:
    """The standard error of a reference run's mean I_dec, relative: batch means over its recorded rotations
    (``bearingsim.stats``, the estimator every command uses, docs/statistics.md). A ``rel_error`` against that
    run below about twice this is not resolved: the full scene is chaotic, so two runs at different steps are
    two trajectories."""
    from bearingsim.stats import batch_sem, pocket_means

    mean = result.summary["I_dec_mean_Ns"]
    return batch_sem(pocket_means(result.per_rotation["I_dec"])) / mean


def _failed_row(scene, rpm, dt, total_rot, why) -> dict:
    """A row for a step at which the run was stopped (overlap or stability bound): no time, no error."""
    nan = float("nan")
    return {"model": "multibody", "method": "pymunk", "scene": scene, "rpm": rpm, "dt_s": dt, "wall_s": nan,
            "pymunk_step_s": nan, "unit_of_work": "cage rotation", "run_wall_s": nan, "I_dec_Ns": nan,
            "rel_error": nan, "reference": "", "rotations": total_rot, "steps": 0, "repeats": 0,
            "notes": f"stopped: {why}"}


#: The full scene's other solvers, each a row per speed at its automatic step against the full scene's
#: dt = 1 us reference (Hertz raceways; at 970 N and 16 rollers ``inner_ring = "auto"`` is the quasi-static
#: ring): rigid raceways (docs/fast_scene.md) and the dynamic inner ring (docs/stability.md), which
#: ``auto`` chooses with few rollers or light loads.
FULL_VARIANTS = (("full_rigid_raceways", {"raceway_contact": "rigid"}),
                 ("full_dynamic_ring", {"inner_ring": "dynamic"}))


def bench_cases(quick: bool) -> list[dict]:
    """Run the benchmark and return one dict per (scene, rpm, dt) row (see module docstring)."""
    from bearingsim.reduced.core import PassInputs
    from bearingsim.reduced.event import solve_event

    if quick:
        plan = {1000: 1, 3000: 1, 6000: 2}  # recorded rotations (after 1 warm-up)
        dts = [6e-6, 4e-6]
        dt_ref = 2e-6
        repeats = 1
    else:
        plan = {1000: 2, 3000: 5, 6000: 10}
        dts = [6e-6, 4e-6, 3e-6, 2e-6]
        dt_ref = 1e-6
        repeats = 3
    rows = []
    simulate(Parameters.from_scenario(reference_scenario(6000, 1, 0)))  # load the compiled kernels once (not timed in any row)
    simulate(Parameters.from_scenario(reference_scenario(6000, 1, 0, raceway_contact="rigid")))
    for rpm, nrot in plan.items():
        sc = Parameters.from_scenario(reference_scenario(rpm, nrot, 1))
        total_rot = nrot + 1
        ref = simulate(sc, dt=dt_ref)
        ref_idec, ref_iacc = ref.summary["I_dec_mean_Ns"], ref.summary["I_acc_mean_Ns"]
        ref_own = _own_sem(ref)
        ref_stats = {"ref_sem_rel": ref_own["sem_rel"], "ref_batches": ref_own["batches"]}
        for dt in dts:
            try:
                runs = [simulate(sc, dt=dt) for _ in range(repeats)]
            except (SimulationUnstable, PenetrationExceeded) as exc:  # a step too long for this scene: a finding
                rows.append(_failed_row("full", rpm, dt, total_rot, str(exc)))
                continue
            rows.append({**_row("full", rpm, dt, runs, total_rot, ref_idec, f"full scene at dt = {dt_ref:g} s",
                                ref_iacc), **ref_stats, **_own_sem(runs[0])})
        rows.append({**_row("full", rpm, dt_ref, [ref], total_rot, ref_idec, "itself", ref_iacc), **ref_stats,
                     **ref_own})
        # the other solvers of the full scene at their automatic step, against the same reference
        for scene, options in FULL_VARIANTS:
            var = Parameters.from_scenario(reference_scenario(rpm, nrot, 1, **options))
            runs = [simulate(var) for _ in range(repeats)]
            rows.append({**_row(scene, rpm, runs[0].provenance["dt_s"], runs, total_rot, ref_idec,
                                f"full scene (Hertz raceways, quasi-static ring) at dt = {dt_ref:g} s", ref_iacc),
                         **ref_stats, **_own_sem(runs[0])})
    # deterministic scene against the exact reduced solution
    sc = Parameters.from_scenario(reference_scenario(3000, 1, 1, scene="reduced_equivalent", phi=23.5))
    event = solve_event(PassInputs.from_parameters(sc))
    exact = event.I_dec
    _, _, lim = choose_dt(sc)
    for f in (0.5, 0.25, 0.125) if quick else (1.0, 0.5, 0.25, 0.125, 0.0625):
        runs = [simulate(sc, dt=f * lim) for _ in range(repeats)]
        rows.append(_row("reduced_equivalent", 3000, f * lim, runs, 2, exact, "reduced event model (exact)",
                         event.I_acc))
    return rows + geometry_cases(quick)


GEOMETRY_SEGMENTS = (3, 5, 9, 17, 33)
GOAL_COST_RATIO = 1.2  # exact faces against the 3-segment polyline, per cage rotation


def idec_sem(result) -> float:
    """Standard error [N s] of a run's mean I_dec: the batch-means error of the per-rotation means over the
    pockets (:func:`bearingsim.stats.batch_sem`, the one every table of the package gives; docs/statistics.md)."""
    from bearingsim.stats import batch_sem, pocket_means

    return batch_sem(pocket_means(result.get("per_rotation/I_dec")))


def geometry_cases(quick: bool) -> list[dict]:
    """The geometric error of polyline pocket faces against the exact faces, and the exact faces' cost."""
    rows = []
    nrot = 2 if quick else 10
    exact = simulate(Parameters.from_scenario(reference_scenario(3000, nrot, 1)))
    ref = exact.summary["I_dec_mean_Ns"]
    sem = idec_sem(exact) / ref
    ref_sem = ref_sem_rel(exact)
    row = _row("full", 3000, exact.provenance["dt_s"], [exact], nrot + 1, ref, "itself")
    rows.append({**row, "notes": "exact faces (geometric reference)", "sem_rel": sem, "ref_sem_rel": ref_sem})
    for n_seg in GEOMETRY_SEGMENTS:
        run = simulate(Parameters.from_scenario(reference_scenario(3000, nrot, 1, pocket_face_segments=n_seg)))
        row = _row(f"full_polyline_{n_seg}", 3000, run.provenance["dt_s"], [run], nrot + 1, ref,
                   f"exact faces, same dt and {nrot + 1} rotations")
        rows.append({**row, "sem_rel": sem, "ref_sem_rel": ref_sem, "signed_error": (row["I_dec_Ns"] - ref) / ref})
    repeats = COST_REPEATS_QUICK if quick else COST_REPEATS
    cost_rot = 1 if quick else 2
    for raceway in ("hertz", "rigid"):
        for rpm in (1000, 6000):
            dt = 4e-6 if raceway == "hertz" else None
            runs = {0: [], 3: []}
            for _ in range(repeats):  # interleaved: the machine's load drifts
                for n_seg in (0, 3):
                    p = Parameters.from_scenario(reference_scenario(rpm, cost_rot, 1, raceway_contact=raceway,
                                                                    pocket_face_segments=n_seg))
                    runs[n_seg].append(simulate(p, dt=dt))
            walls = {k: [r.provenance["solver_wall_s"] for r in v] for k, v in runs.items()}
            cost = cost_verdict(walls[0], walls[3])
            scene = "full" if raceway == "hertz" else "full_rigid_raceways"
            for n_seg, v in runs.items():
                r = _row(scene if n_seg == 0 else f"{scene}_polyline_3", rpm, v[0].provenance["dt_s"], v, cost_rot + 1,
                         runs[0][0].summary["I_dec_mean_Ns"], "itself" if n_seg == 0 else "exact faces, same run")
                if n_seg == 0:
                    r.update(cost_ratio=cost["ratio"], cost_ratio_low=cost["low"], cost_ratio_high=cost["high"],
                             cost_verdict=cost["verdict"])
                else:
                    r["cost_ratio"] = float("nan")
                r["notes"] = "cost of the exact faces against the 3-segment polyline"
                rows.append(r)
    return rows


COST_REPEATS, COST_REPEATS_QUICK = 5, 3  # interleaved pairs (exact, polyline) of the cost rows
COST_MIN_PAIRS = 3  # fewer pairs give no spread: the cost goal is then not resolved


def cost_verdict(exact_walls, poly_walls, goal: float = GOAL_COST_RATIO) -> dict:
    """The exact faces' cost against the 3-segment polyline from interleaved repeats (pair i ran one after the
    other): ``ratio`` the ratio of the minima (the least disturbed run of each), ``low``/``high`` the least
    and largest ratio of a pair, the spread the machine's load gives. "met" when even the largest pair ratio
    is within ``goal``, "not met" when even the least exceeds it, else (the spread straddles the goal, or
    fewer than :data:`COST_MIN_PAIRS` pairs) "not resolved"."""
    pairs = [a / b for a, b in zip(exact_walls, poly_walls)]
    ratio = min(exact_walls) / min(poly_walls)
    low, high = min(pairs), max(pairs)
    if len(pairs) < COST_MIN_PAIRS:
        verdict = "not resolved"
    else:
        verdict = "met" if high <= goal else "not met" if low > goal else "not resolved"
    return {"ratio": ratio, "low": low, "high": high, "pairs": len(pairs), "verdict": verdict}


def error_verdict(error: float, sem_rel: float, ref_sem_rel: float, batches: int, ref_batches: int,
                  goal: float = GOAL_ERROR) -> dict:
    """Whether a chaotic run's ``error`` (|relative difference| of mean I_dec from its reference) is within
    ``goal``, given both runs' relative standard errors (each from its batch means; both runs scatter): the
    standard error of the difference ``se = hypot(sem_rel, ref_sem_rel)``, t the two-sided 95 % Student
    quantile of its Welch-Satterthwaite degrees of freedom (:func:`bearingsim.stats.critical_ses`, the
    package's one significance rule), bounds ``error -/+ t se``. "met" when the upper bound is within the goal,
    "not met" when the lower bound exceeds it, else "not resolved" (also when a standard error is missing or
    rests on one batch)."""
    from bearingsim.stats import critical_ses

    se = math.hypot(sem_rel, ref_sem_rel)
    t = critical_ses(sem_rel, ref_sem_rel, batches, ref_batches) if math.isfinite(se) else math.nan
    lo, hi = error - t * se, error + t * se
    verdict = "met" if hi <= goal else "not met" if lo > goal else "not resolved"  # NaN bounds: not resolved
    return {"verdict": verdict, "se_diff": se, "t": t, "low": lo, "high": hi}


def _verdict_text(r: dict, v: dict) -> str:
    """The numbers :func:`error_verdict` decided on, in words."""
    text = f"I_dec error {r['rel_error']:.2%}"
    if not math.isfinite(v["se_diff"]):
        return text + ", no standard error (fewer than 2 recorded rotations in a run)"
    text += (f", standard error of the difference {v['se_diff']:.2%} (this run {r['sem_rel']:.2%}, "
             f"reference {r['ref_sem_rel']:.2%}, batch means {r['batches']} and {r['ref_batches']})")
    if not math.isfinite(v["t"]):
        return text + ", one batch mean: no degrees of freedom"
    return text + f", 95 % bounds (Student t = {v['t']:.2f}) {max(v['low'], 0.0):.2%} to {v['high']:.2%}"


def goal_lines(rows: list[dict]) -> list[str]:
    """The speed goal (full scene at 6000 rpm), the geometric error of polyline faces and the exact faces'
    cost, read off the rows."""
    lines = geometry_lines(rows)
    full = [r for r in rows if r["scene"] == "full" and r["rpm"] == 6000 and "cost_ratio" not in r]
    if not full:
        return lines
    judged = {id(r): error_verdict(r["rel_error"], r.get("sem_rel", math.nan), r.get("ref_sem_rel", math.nan),
                                   r.get("batches", 0), r.get("ref_batches", 0))
              for r in full if r["rel_error"] == r["rel_error"]}  # not the reference row, not a stopped run
    fast = [r for r in full if id(r) in judged and r["wall_s"] <= GOAL_S_PER_ROTATION]
    for verdict in ("met", "not resolved", "not met"):
        cands = [r for r in fast if judged[id(r)]["verdict"] == verdict]
        if cands:
            break
    best = min(cands, key=lambda r: r["wall_s"]) if fast else None
    for r in sorted(full, key=lambda r: -r["dt_s"]):
        if not r["wall_s"] == r["wall_s"]:  # a run stopped at too long a step: its reason, no numbers
            lines.append(f"6000 rpm full scene, dt = {r['dt_s']:.1e} s: {r.get('notes') or 'no result'}")
            continue
        py = r["wall_s"] - r["pymunk_step_s"]
        lines.append(f"6000 rpm full scene, dt = {r['dt_s']:.1e} s: {r['wall_s']:.3f} s per cage rotation, of which "
                     f"pymunk Space.step {r['pymunk_step_s']:.3f} s (rest of the step / pymunk = "
                     f"{py / r['pymunk_step_s']:.2f}), I_dec error {r['rel_error']:.1e}"
                     + (f", I_acc error {r['rel_error_I_acc']:.1e}" if "rel_error_I_acc" in r else ""))
    goal = f"goal (<= {GOAL_S_PER_ROTATION} s per rotation within {GOAL_ERROR:.0%} of the smallest step)"
    if best is None:
        lines.append(f"{goal}: no step ran within {GOAL_S_PER_ROTATION} s per rotation -> not met")
        return lines
    v = judged[id(best)]
    ratio = (best["wall_s"] - best["pymunk_step_s"]) / best["pymunk_step_s"]
    lines.append(f"{goal}: {best['wall_s']:.3f} s at dt = {best['dt_s']:.1e} s, {_verdict_text(best, v)} "
                 f"-> {v['verdict']}; goal (rest of the step, i.e. the 'Python side', <= pymunk "
                 f"step): {ratio:.2f} -> {'met' if ratio <= 1.0 else 'not met'}")
    return lines


def geometry_lines(rows: list[dict]) -> list[str]:
    """The polyline faces' I_dec error against the exact faces, and the exact faces' cost ratio."""
    lines = []
    for r in rows:
        if r["scene"].startswith("full_polyline_") and "signed_error" in r:  # (not the cost rows)
            n_seg = r["scene"].rsplit("_", 1)[1]
            lines.append(f"3000 rpm, {n_seg:>2} segments per face: I_dec {r['I_dec_Ns'] * 1e3:.2f} mN s, "
                         f"{r['signed_error']:+.1%} off the exact faces' (their standard error {r['sem_rel']:.1%}), "
                         f"{r['wall_s']:.3f} s per rotation")
    for r in rows:
        if r.get("cost_ratio", float("nan")) == r.get("cost_ratio"):
            lines.append(f"{r['rpm']} rpm {r['scene'].replace('_', ' ')}: exact faces {r['wall_s']:.3f} s per rotation, "
                         f"{r['cost_ratio']:.2f} x the 3-segment polyline (ratio of the minima; pairs "
                         f"{r['cost_ratio_low']:.2f}-{r['cost_ratio_high']:.2f} over {r['repeats']} interleaved "
                         f"repeats; goal <= {GOAL_COST_RATIO}: {r['cost_verdict']})")
    return lines


GOAL_GEOMETRY_ERROR = 0.03  # exact faces against the 63-segment polyline: within 3 % (or 2 standard errors)


def geometry_study(rpms=(2000, 3000), segments=(3, 5, 9, 17, 33, 63), rotations=30, warmup=1) -> list[dict]:
    """I_dec of the full scene with exact pocket faces and with polylines of ``segments`` per face, at each
    speed over the same ``warmup`` + ``rotations`` (automatic step), with standard errors and time per
    rotation. The exact row of each speed carries the goal check against the finest polyline."""
    rows = []
    for rpm in rpms:
        res = {}
        for n_seg in (0, *segments):
            r = simulate(Parameters.from_scenario(reference_scenario(rpm, rotations, warmup, pocket_face_segments=n_seg)))
            res[n_seg] = r
            print(f"  {rpm} rpm, {'exact faces' if n_seg == 0 else f'{n_seg} segments'}: "
                  f"I_dec {r.summary['I_dec_mean_Ns'] * 1e3:.3f} mN s", flush=True)
        ref = res[0].summary["I_dec_mean_Ns"]
        finest = res[max(segments)]
        for n_seg, r in res.items():
            idec = r.summary["I_dec_mean_Ns"]
            row = dict(rpm=rpm, faces="exact" if n_seg == 0 else f"polyline {n_seg}", segments=n_seg,
                       I_dec_Ns=idec, sem_Ns=idec_sem(r), rel_to_exact=(idec - ref) / ref,
                       wall_s_per_rotation=r.provenance["solver_wall_s"] / (rotations + warmup),
                       dt_s=r.provenance["dt_s"], rotations=rotations, warmup=warmup,
                       orbit_max_m=r.summary["cage_orbit_max_m"])
            if n_seg == 0:
                diff = idec - finest.summary["I_dec_mean_Ns"]
                se = math.hypot(idec_sem(r), idec_sem(finest))
                row["vs_finest"] = diff / finest.summary["I_dec_mean_Ns"]
                row["vs_finest_in_se"] = diff / se
                row["goal_met"] = abs(row["vs_finest"]) <= GOAL_GEOMETRY_ERROR or abs(diff) <= 2.0 * se
            rows.append(row)
    return rows


def run_geometry_bench(outdir, rotations: int = 30) -> list[dict]:
    """``bearingsim bench --geometry``: :func:`geometry_study` at 2000 and 3000 rpm; writes
    ``geometry.csv`` and prints the table and the goal."""
    import csv
    import io
    from pathlib import Path

    from bearingsim.archive import check_writable_dir
    from bearingsim.outputs import atomic_file

    outdir = check_writable_dir(Path(outdir))
    print(f"pocket-face geometry: exact faces against polylines, 1 warm-up + {rotations} rotations ...", flush=True)
    rows = geometry_study(rotations=rotations)
    cols = ["rpm", "faces", "segments", "I_dec_Ns", "sem_Ns", "rel_to_exact", "wall_s_per_rotation", "dt_s",
            "rotations", "warmup", "orbit_max_m", "vs_finest", "vs_finest_in_se", "goal_met"]
    text = io.StringIO()
    w = csv.DictWriter(text, fieldnames=cols)
    w.writeheader()
    for r in rows:
        w.writerow(r)
    with atomic_file(outdir / "geometry.csv") as fh:
        fh.write(text.getvalue().encode())
    print("| rpm | faces | I_dec [mN s] | s.e. [mN s] | vs exact | s per rotation |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['rpm']} | {r['faces']} | {r['I_dec_Ns'] * 1e3:.3f} | {r['sem_Ns'] * 1e3:.3f} | "
              f"{r['rel_to_exact']:+.1%} | {r['wall_s_per_rotation']:.3f} |")
    for r in rows:
        if "goal_met" in r:
            print(f"goal at {r['rpm']} rpm (exact within {GOAL_GEOMETRY_ERROR:.0%} or 2 s.e. of the finest polyline): "
                  f"{r['vs_finest']:+.2%} = {r['vs_finest_in_se']:+.2f} s.e. -> {'met' if r['goal_met'] else 'not met'}")
    print(f"wrote {outdir / 'geometry.csv'}")
    return rows
