"""`bearingsim bench`: speed against error of every solver, in one run, on this machine.

Writes to the output folder:

* ``bench.csv``: one row per solver setting with at least ``model, method, scene, dt_s, wall_s,
  rel_error`` (wall time of one no-load pass for the reduced model, of one cage rotation for the
  multibody model; ``rel_error`` = error of the mean I_dec against the row's reference, ``rel_error_I_acc``
  that of the mean I_acc, and for the
  multibody model's chaotic full scene ``ref_sem_rel`` = that reference run's standard error, relative);
* ``bench.png``: wall time against error, log-log;
* ``bench_meta.json``: machine, package versions, date, command, and the long-run check;
* ``bench.md``: the same table as markdown (what docs/bench.md shows).

Times are medians of repeats, measured in the same process one after the other, so ratios between
rows are meaningful even on a noisy machine; absolute times are not.

The reduced model's reference is the event solver itself; the event row's own error is measured
against an event solve with tighter tolerances (Chebyshev tail 2e-15, Zeno height 1e-9 s). Euler's
convergence onto it (first order) independently confirms it.
"""
from __future__ import annotations

import csv
import datetime as _dt
import functools
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REDUCED_SPEEDS = (500, 2000, 6000)
EULER_DTS = (1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7)
COLUMNS = ("model", "method", "scene", "rpm", "dt_s", "wall_s", "rel_error", "I_dec_Ns", "unit_of_work", "repeats",
           "notes")


def _median_time(fn, repeats: int):
    times = []
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def reduced_rows(quick: bool) -> list[dict]:
    """Event and euler at 500, 2000 and 6000 rpm (the paper's conditions, 970 N, φ = 23.5°)."""
    from bearingsim.parameters import Parameters
    from bearingsim.reduced.core import PassInputs
    from bearingsim.reduced.euler import max_stable_dt, solve_euler
    from bearingsim.reduced.event import solve_event
    from bearingsim.studies.fig9 import paper_scenario

    rows = []
    for rpm in REDUCED_SPEEDS:
        inp = PassInputs.from_parameters(Parameters.from_scenario(paper_scenario(rpm)))
        solve_event(inp, trace_points=0)  # compile / load the cache outside the timing
        solve_euler(inp, 1e-4, trace_points=0)
        ref = solve_event(inp, trace_points=0)
        tight = solve_event(inp, trace_points=0, cheb_tol=2e-15, zeno_height=1e-9)
        wall, sol = _median_time(lambda: solve_event(inp, trace_points=0), 7 if quick else 21)
        rows.append(dict(model="reduced", method="event", scene="single_pocket", rpm=rpm, dt_s=float("nan"),
                         wall_s=wall, **_index_errors(sol, tight), I_dec_Ns=sol.I_dec,
                         unit_of_work="no-load pass", repeats=7 if quick else 21,
                         notes="error against tighter event tolerances", impacts=len(sol.impacts["theta"]),
                         **_closed_form_cost(inp, 50_000 if quick else 200_000)))
        dtmax = max_stable_dt(inp)
        for dt in EULER_DTS:
            if dt > dtmax:
                continue
            reps = 3 if dt >= 1e-6 or not quick else 1
            wall, sol = _median_time(lambda: solve_euler(inp, dt, trace_points=0), reps)
            rows.append(dict(model="reduced", method="euler", scene="single_pocket", rpm=rpm, dt_s=dt, wall_s=wall,
                             **_index_errors(sol, ref), I_dec_Ns=sol.I_dec, unit_of_work="no-load pass",
                             repeats=reps, notes="error against event"))
    return rows


def _index_errors(sol, ref) -> dict:
    """Relative errors of both wear indices of a pass against a reference pass: ``rel_error`` of I_dec and
    ``rel_error_I_acc`` of I_acc (the front face's, smaller, with larger relative errors under euler). Where the
    reference's I_acc is 0 (no front-face contact: 6000 rpm) the error is 0 if the pass's is 0 too, else inf."""
    d_acc = abs(sol.I_acc - ref.I_acc)
    rel_acc = d_acc / abs(ref.I_acc) if ref.I_acc != 0.0 else (0.0 if d_acc == 0.0 else math.inf)
    return dict(rel_error=abs(sol.I_dec - ref.I_dec) / abs(ref.I_dec), rel_error_I_acc=rel_acc, I_acc_Ns=sol.I_acc)


@functools.cache
def _flight_cost_loop():
    """A compiled loop that evaluates the event solver's closed form of one flight at n angles spread
    over [th0, th1] and returns the sum of l, so that nothing is optimised away (compiled on first use,
    not cached on disk: it inlines ``bearingsim.reduced.event._flight``)."""
    from numba import njit

    from bearingsim.reduced.event import _flight

    @njit
    def loop(tab, npan, omega, g, fs, th0, th1, n):
        acc = 0.0
        for i in range(n):
            l, _, _, _, _ = _flight(tab, npan, omega, g, fs, th0 + (th1 - th0) * (i + 0.5) / n)
            acc += l
        return acc

    return loop


def closed_form_evaluator(inp):
    """``evaluate(n)``: the closed form of one flight of this pass (its own drag table) evaluated at n
    angles in one compiled call; ``evaluate(0)`` is a bare call into compiled code."""
    from bearingsim.reduced.event import (DEFAULT_ZENO_FLOOR, DEFAULT_ZENO_HEIGHT, _flight_start, drag_table,
                                          pass_constants)

    tab, npan = drag_table(inp)
    par = pass_constants(inp, DEFAULT_ZENO_HEIGHT, DEFAULT_ZENO_FLOOR)
    omega, g, th0, th1 = par.omega_c, par.gravity, par.theta_start, par.theta_end
    fs = _flight_start(tab, npan, omega, th0, par.clearance, 0.0)
    loop = _flight_cost_loop()

    def evaluate(n: int) -> float:
        return loop(tab, npan, omega, g, fs, th0, th1, n)

    evaluate(1)  # compile outside any timing
    return evaluate


def _closed_form_cost(inp, evaluations: int) -> dict:
    """``eval_s``: one evaluation of the event solver's closed form (median of 5 loops of
    ``evaluations``); ``call_s``: one call from Python into compiled code (median of 201 empty calls).
    A solver that reports each impact evaluates the motion at least once per impact and is called at
    least once, so ``call_s + impacts × eval_s`` bounds a pass of this method from below."""
    evaluate = closed_form_evaluator(inp)
    loop, _ = _median_time(lambda: evaluate(evaluations), 5)
    call, _ = _median_time(lambda: evaluate(0), 201)
    return dict(eval_s=loop / evaluations, call_s=call)


def reduced_goal(rows: list[dict]) -> list[str]:
    """The goal: event reaches <= 1e-6 for <= 1/100 of the time euler needs to reach 1e-4."""
    lines = []
    for rpm in REDUCED_SPEEDS:
        ev = [r for r in rows if r["model"] == "reduced" and r["method"] == "event" and r["rpm"] == rpm][0]
        eu = sorted((r for r in rows if r["model"] == "reduced" and r["method"] == "euler" and r["rpm"] == rpm),
                    key=lambda r: -r["dt_s"])
        need = _euler_need(eu, "rel_error")
        if need is None:
            lines.append(f"{rpm} rpm: euler does not reach 1e-4 on the dt grid; event {ev['wall_s'] * 1e3:.3f} ms "
                         f"at error {ev['rel_error']:.1e}")
            continue
        ratio = ev["wall_s"] / need["wall_s"]
        lines.append(
            f"{rpm} rpm: event {ev['wall_s'] * 1e3:.3f} ms at error {ev['rel_error']:.1e}; euler needs dt = "
            f"{need['dt_s']:.0e} s and {need['wall_s'] * 1e3:.3f} ms for 1e-4; ratio {ratio:.3g} "
            f"(goal <= 0.01: {'met' if ratio <= 0.01 and ev['rel_error'] <= 1e-6 else 'not met'})"
        )
        if "eval_s" in ev:
            budget = 0.01 * need["wall_s"]
            floor = ev["call_s"] + ev["impacts"] * ev["eval_s"]
            lines.append(
                f"  budget 1/100 x euler = {budget * 1e6:.2f} us; floor of this closed form = one call "
                f"{ev['call_s'] * 1e6:.2f} us + {ev['impacts']} impacts x one evaluation {ev['eval_s'] * 1e9:.0f} ns "
                f"= {floor * 1e6:.2f} us ({'below' if floor <= budget else 'above'} the budget)"
            )
        if "rel_error_I_acc" in ev:
            lines.append(_i_acc_line(ev, eu))
    return lines


def _euler_need(eu: list[dict], key: str) -> dict | None:
    """The euler row (``eu`` by falling dt) from which on every smaller dt of the grid stays within 1e-4 in ``key``."""
    for i, r in enumerate(eu):
        if all(x[key] <= 1e-4 for x in eu[i:]):
            return r
    return None


def _i_acc_line(ev: dict, eu: list[dict]) -> str:
    """Where euler reaches 1e-4 in I_acc, the other wear index (the goal above reads I_dec)."""
    need = _euler_need(eu, "rel_error_I_acc")
    head = f"  I_acc (event error {ev['rel_error_I_acc']:.1e}): euler "
    if need is None:
        last = eu[-1] if eu else None
        if last is None:
            return head + "has no row"
        return head + (f"does not reach 1e-4 on the dt grid (dt = {last['dt_s']:.0e} s: "
                       f"{last['rel_error_I_acc']:.1e}, I_dec {last['rel_error']:.1e})")
    return head + (f"needs dt = {need['dt_s']:.0e} s and {need['wall_s'] * 1e3:.3f} ms for 1e-4 "
                   f"(I_acc {need['rel_error_I_acc']:.1e}, I_dec {need['rel_error']:.1e} there)")


def multibody_rows(quick: bool) -> list[dict]:
    from benchmarks.multibody_bench import bench_cases

    return bench_cases(quick)


#: Python lines that set ``rss`` to the peak resident memory [MiB] of the process that runs them: VmHWM of
#: /proc/self/status, the peak of this process's own address space since its exec. getrusage's ru_maxrss is
#: not: Linux carries the parent's peak over fork and exec, so a child of the bench reported the bench's
#: peak (699 MiB for 20 and for 200 rotations). ru_maxrss only where /proc is absent.
PEAK_RSS_CODE = (
    "try:\n"
    "    rss = [int(l.split()[1]) for l in open('/proc/self/status') if l.startswith('VmHWM:')][0] / 1024.0\n"
    "except (OSError, IndexError, ValueError):\n"
    "    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0\n"
)


def long_run_check(outdir: Path, rotations: int) -> dict:
    """Run the full multibody scene at 6000 rpm for ``rotations`` and for rotations/10 in fresh processes;
    report peak memory of each, boundedness, and stationarity of per-rotation I_dec."""
    res = {}
    for n in (max(rotations // 10, 4), rotations):
        out = outdir / f"long_{n}.h5"
        code = (
            "import resource, sys, json, numpy as np\n"
            "from bearingsim.scenario import load_scenario\n"
            "from bearingsim.simulation import run_scenario\n"
            f"sc = load_scenario('{_scenarios_dir() / 'multibody_6000rpm.toml'}', "
            f"['numerics.rotations={n}', 'numerics.warmup_rotations=2'])\n"
            f"I = run_scenario(sc, '{out}', figures=False).result.per_rotation['I_dec']\n"
            f"{PEAK_RSS_CODE}"
            "print(json.dumps(dict(rss_MiB=rss, I=I.mean(axis=1).tolist(), finite=bool(np.isfinite(I).all()))))\n"
        )
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        if proc.returncode != 0:
            res[n] = dict(error=proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "failed")
            continue
        d = json.loads(proc.stdout.strip().splitlines()[-1])
        d["wall_s"] = time.perf_counter() - t0
        I = np.array(d.pop("I"))
        h = len(I) // 2
        a, b = I[:h], I[h:]
        scatter = 2.0 * math.sqrt(a.var(ddof=1) / len(a) + b.var(ddof=1) / len(b)) if len(I) >= 4 else float("nan")
        d.update(rotations=n, I_dec_first_half=float(a.mean()), I_dec_second_half=float(b.mean()),
                 two_sigma_of_difference=scatter, stationary=bool(abs(a.mean() - b.mean()) <= scatter),
                 archive_MiB=out.stat().st_size / 2**20)
        out.unlink(missing_ok=True)
        res[n] = d
    return res


def _scenarios_dir() -> Path:
    here = Path(__file__).resolve().parents[1] / "scenarios"
    return here if here.is_dir() else Path("scenarios").resolve()


def _fmt(v):
    if isinstance(v, float):
        if math.isnan(v):
            return "-"
        return f"{v:.3g}"
    return str(v)


def _markdown(rows: list[dict]) -> str:
    """The table printed and written to ``bench.md``; ``notes`` says why a row has no numbers (a run stopped
    at too long a step) or what a row measures; ``ref_sem_rel`` beside ``rel_error`` is the standard error of
    the multibody reference run's mean I_dec (batch means, relative): a full-scene error below about twice it
    is chaotic scatter, not resolved (empty where the reference is exact: the reduced model and the
    reduced-equivalent scene)."""
    cols = ("model", "method", "scene", "rpm", "dt_s", "wall_s", "pymunk_step_s", "rel_error", "ref_sem_rel",
            "rel_error_I_acc", "unit_of_work", "notes")
    out = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        out.append("| " + " | ".join(_fmt(r.get(c, "")).replace("|", "/") for c in cols) + " |")
    return "\n".join(out)


#: colours of the shaft speeds in bench.png (Okabe-Ito, told apart in greyscale by the markers and lines too)
_RPM_COLOURS = {500: "#56B4E9", 1000: "#0072B2", 2000: "#009E73", 3000: "#E69F00", 6000: "#D55E00"}
#: markers of the multibody scenes in bench.png
_SCENE_MARKERS = {"full": ("s", "full scene, exact faces (over dt)"),
                  "full_rigid_raceways": ("^", "rigid raceways, automatic dt"),
                  "full_dynamic_ring": ("D", "free inner ring, automatic dt"),
                  "reduced_equivalent": ("v", "reduced-equivalent scene (over dt)"),
                  "polyline": ("x", "faces as 3 straight segments (full, rigid)")}
#: where bench.png draws an error of zero (below round-off) on its log axis
_ZERO_ERROR = 1e-16


def _plot(rows: list[dict], path: Path) -> None:
    """bench.png: wall time against the error of mean I_dec, the reduced model (per no-load pass) and the
    multibody model (per cage rotation) in panels of their own; colour = shaft speed, marker = scene; the
    faces drawn as N segments at 3000 rpm labelled with N (their error against the exact faces)."""
    from bearingsim.plotting import save_figure, subplots

    fig, (red, mb) = subplots(1, 2, figsize=(10.0, 5.6))
    _plot_reduced(red, [r for r in rows if r["model"] == "reduced"])
    _plot_multibody(mb, [r for r in rows if r["model"] == "multibody"])
    for ax in (red, mb):
        ax.set_xlabel("relative error of mean $I_{dec}$")
        ax.grid(alpha=0.3, which="both")
    fig.suptitle("bearingsim: speed against error (medians of repeats, one core)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=130, tight=False)


def _finite(rs: list[dict]) -> tuple[np.ndarray, np.ndarray]:
    """Errors (zero drawn at :data:`_ZERO_ERROR`) and wall times of the rows that have both."""
    err = np.array([float(r["rel_error"]) for r in rs], dtype=float)
    wall = np.array([float(r["wall_s"]) for r in rs], dtype=float)
    ok = np.isfinite(err) & np.isfinite(wall)
    return np.maximum(err[ok], _ZERO_ERROR), wall[ok]


def _plot_reduced(ax, rows: list[dict]) -> None:
    for rpm in sorted({int(r["rpm"]) for r in rows}):
        colour = _RPM_COLOURS.get(rpm, "k")
        err, wall = _finite([r for r in rows if r["method"] == "euler" and int(r["rpm"]) == rpm])
        ax.loglog(err, wall, marker="o", ms=4, color=colour, label=f"euler, {rpm} rpm")
        err, wall = _finite([r for r in rows if r["method"] == "event" and int(r["rpm"]) == rpm])
        ax.loglog(err, wall, marker="*", ms=11, ls="none", color=colour, markeredgecolor="k", markeredgewidth=0.5)
    ax.plot([], [], marker="*", ms=11, ls="none", color="w", markeredgecolor="k", label="event (exact)")
    ax.axvspan(ax.get_xlim()[0], 1e-15, color="0.9", zorder=0)
    ax.text(1.3e-15, ax.get_ylim()[0], " round-off", fontsize=7, va="bottom", color="0.4")
    ax.set_ylabel("wall time per no-load pass [s]")
    ax.set_title("reduced model (single pocket)", fontsize=9)
    ax.legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.14))


def _plot_multibody(ax, rows: list[dict]) -> None:
    from matplotlib.lines import Line2D

    for row_scene, (marker, _) in _SCENE_MARKERS.items():
        for rpm in sorted({int(r["rpm"]) for r in rows}):
            rs = [r for r in rows if int(r["rpm"]) == rpm and (r["scene"] == row_scene or (
                row_scene == "polyline" and r["scene"].endswith("polyline_3")))]
            err, wall = _finite(rs)
            if len(err):
                ax.loglog(err, wall, marker=marker, ms=5, color=_RPM_COLOURS.get(rpm, "k"),
                          ls="-" if row_scene in ("full", "reduced_equivalent") and len(err) > 1 else "none")
    refined = sorted(((int(r["scene"].rsplit("_", 1)[1]), r) for r in rows
                      if r["scene"].startswith("full_polyline_") and int(r["rpm"]) == 3000), key=lambda nr: nr[0])
    err, wall = _finite([r for _, r in refined])
    if len(err):
        ax.loglog(err, wall, ls=":", color="0.3", marker=".", ms=4)
        for (n, _), e, w in zip(refined, err, wall):
            ax.annotate(f"N={n}", (e, w), textcoords="offset points", xytext=(4, 3), fontsize=6.5, color="0.3")
    ax.set_ylabel("wall time per cage rotation [s]")
    ax.set_title("multibody model (whole bearing)", fontsize=9)
    scenes = [Line2D([], [], marker=m, ls="none", color="0.3", label=text) for m, text in _SCENE_MARKERS.values()]
    scenes.append(Line2D([], [], marker=".", ls=":", color="0.3", label="faces as N segments, 3000 rpm"))
    speeds = [Line2D([], [], color=_RPM_COLOURS.get(v, "k"), lw=3, label=f"{v} rpm")
              for v in sorted({int(r["rpm"]) for r in rows})]
    # below the panel: inside, they covered points
    ax.legend(handles=scenes + speeds, fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.14))


def plot_table(table: Path, path: Path) -> None:
    """Draw bench.png from a bench.md table (the one docs/bench.md shows): the same rows, no run."""
    lines = [ln for ln in Path(table).read_text().splitlines() if ln.startswith("| ")]
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    rows = [dict(zip(head, (c.strip() for c in ln.strip("|").split("|")))) for ln in lines[1:] if head[0] != ln[2:7]]
    for r in rows:
        for key in ("rel_error", "wall_s"):
            r[key] = float(r[key]) if r[key] not in ("", "-") else float("nan")
    _plot([r for r in rows if r.get("model") in ("reduced", "multibody")], path)
    print(f"wrote {path} ({len(rows)} rows of {table})")


def machine_info() -> dict:
    from bearingsim.archive import package_versions

    info = dict(date_utc=_dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
                platform=platform.platform(), processor=platform.processor() or platform.machine(),
                cpu_count=os.cpu_count(), python=sys.version.split()[0], command=" ".join(sys.argv))
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    info["cpu"] = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    info["versions"] = package_versions()
    return info


def run_bench(outdir: Path, quick: bool = False, include_multibody: bool = True) -> list[dict]:
    """Run the benchmark and write its files to ``outdir`` (see the module docstring)."""
    from bearingsim.archive import check_writable_dir

    outdir = check_writable_dir(outdir)
    t0 = time.perf_counter()
    print("reduced model: event and euler at 500, 2000, 6000 rpm ...", flush=True)
    rows = reduced_rows(quick)
    meta = machine_info()
    meta["quick"] = quick
    meta["reduced_goal"] = reduced_goal(rows)
    if include_multibody:
        print("multibody model: full and reduced-equivalent scenes over dt ...", flush=True)
        try:
            mrows = multibody_rows(quick)
            rows += mrows
            from benchmarks.multibody_bench import goal_lines

            meta["multibody_goal"] = goal_lines(mrows)
        except ImportError as exc:  # pragma: no cover - reported, not hidden
            meta["multibody_error"] = f"multibody benchmark unavailable: {exc}"
        if not quick:
            print("long run: 200 cage rotations of the full scene at 6000 rpm ...", flush=True)
            meta["long_run"] = long_run_check(outdir, 200)
    meta["bench_wall_s"] = time.perf_counter() - t0
    with open(outdir / "bench.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(COLUMNS) + sorted({k for r in rows for k in r} - set(COLUMNS)))
        w.writeheader()
        for r in rows:
            w.writerow(r)
    (outdir / "bench.md").write_text(_markdown(rows) + "\n")
    (outdir / "bench_meta.json").write_text(json.dumps(meta, indent=2, default=str) + "\n")
    _plot(rows, outdir / "bench.png")
    print(_markdown(rows))
    print()
    for line in meta["reduced_goal"]:
        print(line)
    if "multibody_error" in meta:
        print(meta["multibody_error"])
    for line in meta.get("multibody_goal", []):
        print(line)
    if "long_run" in meta:
        print("long run:", json.dumps(meta["long_run"], default=str))
    print(f"machine: {meta.get('cpu', meta['processor'])}, {meta['cpu_count']} cores, {meta['platform']}")
    print(f"wrote {outdir / 'bench.csv'}, bench.md, bench.png, bench_meta.json ({meta['bench_wall_s']:.0f} s)")
    return rows


def main(argv=None) -> None:
    """``python -m benchmarks.bench --plot TABLE.md OUT.png``: bench.png drawn from a bench.md table (the bench
    itself runs as ``bearingsim bench``)."""
    import argparse

    ap = argparse.ArgumentParser(prog="python -m benchmarks.bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plot", nargs=2, metavar=("TABLE.md", "OUT.png"), required=True,
                    help="draw bench.png from a bench.md table (docs/bench.md), nothing run; the bench itself: "
                         "bearingsim bench")
    args = ap.parse_args(argv)
    plot_table(Path(args.plot[0]), Path(args.plot[1]))


if __name__ == "__main__":
    main()
