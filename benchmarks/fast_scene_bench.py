"""``bearingsim bench --fast-scene``: rigid raceways against the Hertz full scene (docs/fast_scene.md).

At each speed the reference bearing (NU214, 970 N, roller-guided cage, arc pockets) runs the full scene
twice with its automatic time step, ``multibody.raceway_contact = "hertz"`` and ``"rigid"``, over the
same number of recorded rotations (after one warm-up rotation), one after the other in this process.
Reported per speed and scene: the time step, the restarts of the automatic step (a run that met an
overlap above 1 % of s runs again from the start at a shorter step), wall time per cage rotation of the
run that was kept (solver only, warm-up rotation included in the count; the first run of the process
loads the compiled kernels before the clock starts) and of the whole call, restarts included, pymunk's
share, mean I_dec and I_acc per pocket and rotation with their standard errors
(:func:`bearingsim.stats.impulse_standard_errors`: batch means over rotations of the per-rotation means over
the pockets), load-zone half angle, cage slip, and a digest of the per-rotation impulses (the first 12
hex digits of the SHA-256 of the I_dec and I_acc arrays' bytes: two runs of the bench give the same
digests when the runs are deterministic).

The comparison rows give, for the rigid scene against the Hertz scene, the relative differences of
I_dec and I_acc, the bound they are judged against, ``max(3 %, 2 SE_diff / mean_hertz)`` with
``SE_diff = sqrt(SE_rigid^2 + SE_hertz^2)`` (the full scene is chaotic: two runs of the same scene
that differ in the last bit separate, so over a finite run two correct scenes differ by their
statistical scatter), the half-angle difference (goal 1 deg) and the slip difference (goal 0.2
percentage points), the speed-up (the kept runs' times per rotation), and the speed goal, judged on the
rigid scene's whole call (restarts included).
"""
from __future__ import annotations

import hashlib
import math
import os
import time
from pathlib import Path

from benchmarks.multibody_bench import reference_scenario
from bearingsim.outputs import write_atomic_bytes, write_csv
from bearingsim.parameters import Parameters

SPEEDS = (500, 1000, 3000, 6000)
ROTATIONS = 40
GOAL_S_PER_ROTATION = {6000: 0.02, 1000: 0.1, 500: 0.2}
GOAL_REL = 0.03
GOAL_PHI_DEG = 1.0
GOAL_SLIP = 0.002


def impulse_digest(res) -> str:
    """First 12 hex digits of the SHA-256 of the per-rotation I_dec and I_acc arrays' bytes."""
    pr = res.per_rotation
    return hashlib.sha256(pr["I_dec"].tobytes() + pr["I_acc"].tobytes()).hexdigest()[:12]


def scene_row(rpm, contact, res, total_rot, call_wall_s=math.nan):
    """One table row; ``call_wall_s`` is the wall time of the whole ``simulate`` call (restarts included)."""
    from bearingsim.stats import impulse_standard_errors

    s, p = res.summary, res.provenance
    se = impulse_standard_errors(res.per_rotation["I_dec"], res.per_rotation["I_acc"])
    return {
        "rpm": rpm, "raceway_contact": contact, "dt_s": float(p["dt_s"]), "rotations": total_rot - 1,
        "restarts": str(p.get("dt_choice", "")).count("restarted at dt"),
        "wall_s_per_rotation": float(p["solver_wall_s"]) / total_rot,
        "call_s_per_rotation": call_wall_s / total_rot,
        "pymunk_s_per_rotation": float(p["pymunk_step_s"]) / total_rot,
        "I_dec_Ns": float(s["I_dec_mean_Ns"]), "I_dec_sem_Ns": se["I_dec_sem_Ns"],
        "I_acc_Ns": float(s["I_acc_mean_Ns"]), "I_acc_sem_Ns": se["I_acc_sem_Ns"],
        "load_zone_half_angle_deg": float(s["load_zone_half_angle_deg"]), "cage_slip": float(s["cage_slip"]),
        "impulse_digest": impulse_digest(res), "dt_choice": str(p.get("dt_choice", "")),
    }


def compare(hertz: dict, rigid: dict) -> dict:
    """The comparison row of one speed (see the module docstring)."""
    out = {"rpm": hertz["rpm"], "speedup": hertz["wall_s_per_rotation"] / rigid["wall_s_per_rotation"]}
    ok = True
    for name in ("I_dec", "I_acc"):
        h, r = hertz[f"{name}_Ns"], rigid[f"{name}_Ns"]
        se = math.hypot(hertz[f"{name}_sem_Ns"], rigid[f"{name}_sem_Ns"])
        rel = (r - h) / h
        bound = max(GOAL_REL, 2.0 * se / abs(h))
        out[f"{name}_rel_diff"] = rel
        out[f"{name}_bound"] = bound
        ok &= abs(rel) <= bound
    out["phi_diff_deg"] = rigid["load_zone_half_angle_deg"] - hertz["load_zone_half_angle_deg"]
    out["slip_diff"] = rigid["cage_slip"] - hertz["cage_slip"]
    ok &= abs(out["phi_diff_deg"]) <= GOAL_PHI_DEG and abs(out["slip_diff"]) <= GOAL_SLIP
    out["agrees"] = bool(ok)
    goal = GOAL_S_PER_ROTATION.get(int(hertz["rpm"]))
    out["speed_goal_s"] = goal if goal is not None else float("nan")
    # the goal is judged on the whole call: a restarted run costs its lost part too
    out["speed_goal_met"] = (rigid["call_s_per_rotation"] <= goal) if goal is not None else None
    return out


def run_fast_scene_bench(outdir: Path, speeds=SPEEDS, rotations: int = ROTATIONS, log=print) -> tuple[list, list]:
    """Run both scenes at every speed; write ``fast_scene.csv`` and ``fast_scene.md``; return (rows, comparisons)."""
    from bearingsim.multibody import simulate

    outdir.mkdir(parents=True, exist_ok=True)
    for contact in ("hertz", "rigid"):  # load the compiled kernels (not timed)
        sc = reference_scenario(6000, 1, 0, raceway_contact=contact)
        simulate(Parameters.from_scenario(sc))
    rows, comps = [], []
    for rpm in speeds:
        pair = {}
        for contact in ("hertz", "rigid"):
            sc = reference_scenario(rpm, rotations, 1, raceway_contact=contact)
            t0 = time.perf_counter()
            res = simulate(Parameters.from_scenario(sc))
            pair[contact] = row = scene_row(rpm, contact, res, rotations + 1, time.perf_counter() - t0)
            row["load_1min"] = os.getloadavg()[0]  # the machine's load average just after the run
            log(f"{rpm:5d} rpm {contact:5s}: {time.perf_counter() - t0:6.1f} s, dt {row['dt_s']:.3g} s, "
                f"{row['wall_s_per_rotation']:.4f} s per rotation, load average {row['load_1min']:.2f}")
        rows += [pair["hertz"], pair["rigid"]]
        comps.append(compare(pair["hertz"], pair["rigid"]))
    for name, table in (("fast_scene.csv", rows), ("fast_scene_comparison.csv", comps)):
        write_csv(outdir / name, list(table[0]), [list(r.values()) for r in table])
    write_atomic_bytes(outdir / "fast_scene.md", markdown(rows, comps).encode("utf-8"))
    return rows, comps


def markdown(rows, comps) -> str:
    """The tables of docs/multibody.md (Rigid raceways) and docs/fast_scene.md."""
    lines = ["| rpm | raceways | dt [us] | restarts | s per rotation | with restarts | pymunk s | I_dec [mN s] | "
             "I_acc [mN s] | half angle [deg] | cage slip [%] | impulses digest | load |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['rpm']} | {r['raceway_contact']} | {r['dt_s'] * 1e6:.1f} | {r['restarts']} | "
                     f"{r['wall_s_per_rotation']:.4f} | {r['call_s_per_rotation']:.4f} | "
                     f"{r['pymunk_s_per_rotation']:.4f} | {r['I_dec_Ns'] * 1e3:.3f} ± {r['I_dec_sem_Ns'] * 1e3:.3f} | "
                     f"{r['I_acc_Ns'] * 1e3:.3f} ± {r['I_acc_sem_Ns'] * 1e3:.3f} | {r['load_zone_half_angle_deg']:.2f} | "
                     f"{r['cage_slip'] * 100:.3f} | {r['impulse_digest']} | {r.get('load_1min', math.nan):.2f} |")
    lines += ["", "| rpm | speed-up | I_dec diff (bound) | I_acc diff (bound) | half angle diff [deg] | slip diff [pp] | "
              "agrees | speed goal [s] | met |", "|---|---|---|---|---|---|---|---|---|"]
    for c in comps:
        met = "-" if c["speed_goal_met"] is None else ("yes" if c["speed_goal_met"] else "no")
        goal = "-" if math.isnan(c["speed_goal_s"]) else f"{c['speed_goal_s']:g}"
        lines.append(f"| {c['rpm']} | {c['speedup']:.1f} | {c['I_dec_rel_diff'] * 100:+.1f} % ({c['I_dec_bound'] * 100:.1f} %) | "
                     f"{c['I_acc_rel_diff'] * 100:+.1f} % ({c['I_acc_bound'] * 100:.1f} %) | {c['phi_diff_deg']:+.2f} | "
                     f"{c['slip_diff'] * 100:+.3f} | {'yes' if c['agrees'] else 'no'} | {goal} | {met} |")
    return "\n".join(lines) + "\n"
