"""The benchmark's read-off of issue 2's goal (pure bookkeeping on given rows; no timing here)."""
from pathlib import Path

import pytest

from benchmarks.bench import reduced_goal


def _rows(rpm, event_wall, euler):
    rows = [dict(model="reduced", method="event", rpm=rpm, wall_s=event_wall, rel_error=1e-15, impacts=10,
                 eval_s=2e-7, call_s=1e-6)]
    rows += [dict(model="reduced", method="euler", rpm=rpm, dt_s=dt, wall_s=w, rel_error=err) for dt, w, err in euler]
    return rows


def test_goal_uses_the_dt_from_which_euler_stays_within_1e_4():
    # euler dips below 1e-4 at 3e-5 by luck, rises again at 1e-5, and stays below from 3e-6 on:
    # the time it "needs" is that of 3e-6 (2 ms), not of the lucky 3e-5 (0.3 ms).
    euler = [(1e-4, 1e-4, 3e-3), (3e-5, 3e-4, 5e-5), (1e-5, 1e-3, 2e-4), (3e-6, 2e-3, 8e-5), (1e-6, 6e-3, 2e-5)]
    rows = []
    for rpm in (500, 2000, 6000):
        rows += _rows(rpm, 1.5e-5, euler)
    lines = reduced_goal(rows)
    first = lines[0]
    assert "dt = 3e-06 s and 2.000 ms" in first
    assert "ratio 0.0075" in first and "goal <= 0.01: met" in first
    # floor = call 1 us + 10 impacts x 0.2 us = 3 us; budget = 20 us
    assert "= 3.00 us (below the budget)" in lines[1]


def test_goal_not_met_and_floor_above_budget():
    euler = [(1e-4, 1e-4, 5e-5), (3e-5, 3e-4, 2e-5)]
    rows = []
    for rpm in (500, 2000, 6000):
        rows += _rows(rpm, 2e-5, euler)
    lines = reduced_goal(rows)
    assert "ratio 0.2" in lines[0] and "not met" in lines[0]
    # budget = 1 us < floor 3 us
    assert "budget 1/100 x euler = 1.00 us" in lines[1] and "(above the budget)" in lines[1]


def test_euler_never_within_1e_4_is_reported():
    rows = []
    for rpm in (500, 2000, 6000):
        rows += _rows(rpm, 2e-5, [(1e-4, 1e-4, 5e-3), (3e-5, 3e-4, 2e-3)])
    assert "euler does not reach 1e-4" in reduced_goal(rows)[0]


def test_bench_is_not_in_the_installed_package_and_runs_from_a_checkout(tmp_path, monkeypatch, capsys):
    """The benchmarks live in the checkout's benchmarks/ (not in the wheel: pyproject installs bearingsim*);
    `bearingsim bench` finds them beside the package, and says so in one line where they are absent."""
    from pathlib import Path

    import bearingsim
    from bearingsim import cli

    pkg = Path(bearingsim.__file__).parent
    assert not any((pkg / p).exists() for p in ("bench.py", "sweeps/bench.py", "multibody/bench.py",
                                                 "multibody/fast_bench.py", "multibody/stability.py"))
    assert (cli._benchmarks_root() / "benchmarks" / "bench.py").is_file()
    monkeypatch.setattr(cli, "__file__", str(tmp_path / "site-packages" / "bearingsim" / "cli.py"))
    assert cli.main(["bench", "--quick", "-o", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "source checkout" in err
    assert not (tmp_path / "b").exists()
    with pytest.raises(SystemExit):  # its help says so before anyone runs it
        cli.main(["bench", "--help"])
    assert "run this from a source checkout" in " ".join(capsys.readouterr().out.split())


def test_geometry_and_cost_lines_read_their_own_rows():
    """The multibody bench's goal lines: a polyline row says its signed error against the exact faces and
    their standard error; the cost rows give the exact faces' ratio against the 3-segment polyline and
    judge it against 1.2 (met at 1.1, not met at 1.3); the cost rows' own polyline twin and a row stopped
    at too long a step are not read as geometric rows."""
    from benchmarks.multibody_bench import geometry_lines, goal_lines

    nan = float("nan")
    base = dict(model="multibody", method="pymunk", dt_s=4e-6, pymunk_step_s=0.05, rel_error=nan)
    rows = [dict(base, scene="full_polyline_5", rpm=3000, I_dec_Ns=0.0183, wall_s=0.2, signed_error=0.274,
                 sem_rel=0.004),
            dict(base, scene="full", rpm=1000, I_dec_Ns=0.027, wall_s=0.55, cost_ratio=1.1, cost_ratio_low=1.05,
                 cost_ratio_high=1.15, cost_verdict="met", repeats=5),
            dict(base, scene="full_polyline_3", rpm=1000, I_dec_Ns=0.037, wall_s=0.5, cost_ratio=nan),
            dict(base, scene="full_rigid_raceways", rpm=6000, I_dec_Ns=0.018, wall_s=0.026, cost_ratio=1.3,
                 cost_ratio_low=1.25, cost_ratio_high=1.4, cost_verdict="not met", repeats=5),
            dict(base, scene="full", rpm=6000, I_dec_Ns=nan, wall_s=nan, notes="stopped: overlap")]
    lines = geometry_lines(rows)
    assert len(lines) == 3
    assert "5 segments per face" in lines[0] and "+27.4% off the exact faces'" in lines[0] and "0.4%" in lines[0]
    assert "1.10 x the 3-segment polyline" in lines[1] and "met" in lines[1] and "not met" not in lines[1]
    assert "1.30 x" in lines[2] and "not met" in lines[2]
    assert goal_lines(rows)[:3] == lines


def test_a_row_stopped_at_too_long_a_step_says_why():
    """A full-scene run stopped at too long a step (overlap or stability bound) is a row without numbers:
    the printed table and the 6000 rpm goal lines give its reason where they gave '-' and 'nan'."""
    from benchmarks.bench import _markdown
    from benchmarks.multibody_bench import _failed_row, goal_lines

    stopped = _failed_row("full", 6000, 6e-6, 3, "roller 4 overlaps the cage by 0.2 mm | step too long")
    ran = dict(stopped, wall_s=0.3, pymunk_step_s=0.1, I_dec_Ns=0.015, rel_error=0.004, dt_s=4e-6, notes="")
    table = _markdown([stopped, ran]).splitlines()
    assert "stopped: roller 4 overlaps the cage by 0.2 mm / step too long" in table[2]  # '|' kept out of the cells
    assert all(line.count("|") == table[0].count("|") for line in table)
    lines = goal_lines([stopped, ran])
    assert "6000 rpm full scene, dt = 6.0e-06 s: stopped: roller 4 overlaps the cage by 0.2 mm | step too long" in lines
    assert not any("nan" in line for line in lines)


def test_the_table_gives_the_reference_runs_standard_error_beside_the_error():
    """A full-scene row's rel_error is against a run at dt = 1 us over the same few rotations of a chaotic scene:
    the table printed and written to bench.md gives that reference's standard error (batch means over its
    rotations, the estimator of bearingsim.stats) beside it, so an error within the scatter reads as such; the
    reduced model's rows, whose reference is exact, leave the cell empty."""
    from types import SimpleNamespace

    import numpy as np

    from bearingsim.stats import batch_sem, pocket_means
    from benchmarks.bench import _markdown
    from benchmarks.multibody_bench import ref_sem_rel

    per_rot = np.array([[1.0, 1.2], [1.4, 1.0], [0.9, 1.1], [1.3, 1.5], [1.0, 0.8], [1.2, 1.2]]) * 1e-2
    ref = SimpleNamespace(summary={"I_dec_mean_Ns": float(per_rot.mean())}, per_rotation={"I_dec": per_rot})
    sem = ref_sem_rel(ref)
    assert sem == batch_sem(pocket_means(per_rot)) / per_rot.mean() and sem > 0
    full = dict(model="multibody", method="pymunk", scene="full", rpm=3000, dt_s=4e-6, wall_s=0.2, pymunk_step_s=0.08,
                rel_error=0.0133, ref_sem_rel=sem, unit_of_work="cage rotation")
    reduced = dict(model="reduced", method="euler", scene="single_pocket", rpm=500, dt_s=1e-4, wall_s=1e-4,
                   rel_error=2.7e-4, unit_of_work="no-load pass")
    table = _markdown([full, reduced]).splitlines()
    head = [c.strip() for c in table[0].strip("|").split("|")]
    col = head.index("ref_sem_rel")
    assert col == head.index("rel_error") + 1
    cells = [[c.strip() for c in line.strip("|").split("|")] for line in table[2:]]
    assert cells[0][col] == f"{sem:.3g}" and cells[1][col] == ""


def test_every_solver_of_the_full_scene_has_a_bench_row():
    """Each raceway contact law and each inner-ring model the scenario offers is a solver of its own; the bench
    times it against the full scene's reference. The dynamic inner ring (what 'auto' chooses with few rollers or
    light loads) had no row; the default row is Hertz raceways with the quasi-static ring at 970 N."""
    import typing

    from bearingsim.scenario import MultibodySection
    from benchmarks.multibody_bench import FULL_VARIANTS

    covered = {("raceway_contact", "hertz"), ("inner_ring", "quasi_static")}  # the 'full' rows
    covered |= {item for _, options in FULL_VARIANTS for item in options.items()}
    for key in ("raceway_contact", "inner_ring"):
        offered = set(typing.get_args(MultibodySection.model_fields[key].annotation)) - {"auto"}
        assert offered <= {v for k, v in covered if k == key}, key
    assert len({scene for scene, _ in FULL_VARIANTS}) == len(FULL_VARIANTS)


def test_replica_scatter_runs_with_fewer_rotations_than_its_start_window(monkeypatch, capsys):
    """``python -m benchmarks.replica_scatter --rotations N`` takes any N: the columns "rotation 1" and
    "rotations 1-5" compare with rotations 9..N, so below 9 rotations they have nothing to compare with and
    say so ("-"). With --rotations 5 the script ended in a traceback (statistics.stdev of NaN) after the
    runs. The replicas here are stand-ins (no simulation), run in this process."""
    import numpy as np

    import benchmarks.replica_scatter as rs

    class Serial:
        def __init__(self, workers):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def map(self, f, jobs):
            return map(f, jobs)

    def replica(job):
        raceway, rpm, rotations, load, dt = job
        series = 0.014 + 1e-4 * np.sin(np.arange(rotations) + load)
        return float(series.mean()), 1e-5, series, False

    monkeypatch.setattr(rs, "ProcessPoolExecutor", Serial)
    monkeypatch.setattr(rs, "_replica", replica)
    assert rs.main(["--replicas", "3", "--rotations", "5", "--case", "rigid:3000", "--jobs", "1"]) == 0
    row = capsys.readouterr().out.splitlines()[-1].split(" | ")
    assert row[0] == "| rigid" and row[9] == "-" and row[10] == "-", row
    assert rs.main(["--replicas", "3", "--rotations", "12", "--case", "rigid:3000", "--jobs", "1"]) == 0
    row = capsys.readouterr().out.splitlines()[-1].split(" | ")
    assert "±" in row[9] and "±" in row[10], row


def test_bench_refuses_options_it_would_not_read(tmp_path, monkeypatch, capsys):
    """`bench --rotations` only with --fast-scene or --geometry, at least 1 (0 ran the default 30 or 40);
    one bench at a time (--map --sweep ran the map alone, --quick --geometry ignored --quick). Refused in
    one line before any bench runs."""
    from bearingsim import cli
    from benchmarks import bench, multibody_bench

    ran = []
    monkeypatch.setattr(bench, "run_bench", lambda *a, **k: ran.append("bench"))
    monkeypatch.setattr(multibody_bench, "run_geometry_bench", lambda *a, **k: ran.append("geometry"))
    out = str(tmp_path / "b")
    for argv in (["--quick", "--rotations", "5"], ["--geometry", "--rotations", "0"],
                 ["--geometry", "--rotations", "-3"], ["--map", "--sweep"], ["--quick", "--geometry"]):
        assert cli.main(["bench", *argv, "-o", out]) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "bench: " in err, (argv, err)
    assert ran == [] and not (tmp_path / "b").exists()
    assert cli.main(["bench", "--geometry", "--rotations", "2", "-o", out]) == 0
    assert ran == ["geometry"]


def test_the_long_runs_peak_memory_is_that_of_its_own_process():
    """The long run's rss_MiB is the peak memory of the fresh process that ran it (docs/bench.md). getrusage's
    ru_maxrss of a child started by a large parent reports the parent's peak (Linux carries it over exec):
    the full bench printed 699.4 MiB for 20 and for 200 rotations, its own process's peak. A parent holding
    300 MiB here starts a child that allocates nothing: the child's peak must be far below 300 MiB."""
    import json
    import subprocess
    import sys

    import numpy as np

    from benchmarks.bench import PEAK_RSS_CODE

    held = np.ones(300 * 2**20 // 8)  # 300 MiB, touched
    code = "import resource, json\n" + PEAK_RSS_CODE + "print(json.dumps(rss))\n"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    rss = json.loads(proc.stdout.strip().splitlines()[-1])
    assert held.sum() > 0 and 1.0 < rss < 150.0, rss


def _full_6000(dt, wall, err, sem, ref_sem, batches=5, ref_batches=5):
    return dict(model="multibody", method="pymunk", scene="full", rpm=6000, dt_s=dt, wall_s=wall, pymunk_step_s=0.04,
                rel_error=err, sem_rel=sem, ref_sem_rel=ref_sem, batches=batches, ref_batches=ref_batches)


def test_the_6000_rpm_goal_is_met_only_when_the_errors_upper_bound_is_within_1_percent():
    """The full bench printed "met" for an error of 0.18 % against a reference whose standard error was 0.33 %
    (both runs scatter: the difference's is ~0.47 %, its 95 % upper bound ~1.3 %), --quick for 0.37 % against
    0.91 % over 2 recorded rotations. The goal line now says "not resolved" there, with the bounds; "met" where
    the upper bound is within 1 %, "not met" where the lower bound exceeds it."""
    from benchmarks.multibody_bench import goal_lines

    def goal(row):
        return [line for line in goal_lines([row]) if line.startswith("goal")][0]

    full = goal(_full_6000(4e-6, 0.084, 0.0018, 0.0033, 0.0033))
    assert "-> not resolved" in full and "0.18%" in full and "0.47%" in full, full
    quick = goal(_full_6000(4e-6, 0.09, 0.0037, 0.009, 0.0091, 2, 2))
    assert "-> not resolved" in quick, quick
    assert "-> met;" in goal(_full_6000(4e-6, 0.084, 0.0018, 0.001, 0.001))
    assert "-> not met;" in goal(_full_6000(4e-6, 0.084, 0.05, 0.001, 0.001))
    # the fastest step whose bound is within the goal, not the fastest step
    lines = goal_lines([_full_6000(4e-6, 0.08, 0.0018, 0.0033, 0.0033), _full_6000(3e-6, 0.12, 0.001, 0.001, 0.001)])
    assert "at dt = 3.0e-06 s" in lines[-1] and "-> met;" in lines[-1], lines[-1]


def test_error_verdict_uses_students_t_of_both_standard_errors():
    """The bound is error ± t·hypot(se, se_ref), t the 95 % two-sided Student quantile of the Welch-Satterthwaite
    degrees of freedom (4 + 4 batch-mean degrees of freedom of equal errors: 8, t = 2.306); a single batch
    mean or a missing standard error cannot be judged."""
    import math

    from benchmarks.multibody_bench import error_verdict

    v = error_verdict(0.0018, 0.0033, 0.0033, 5, 5)
    assert abs(v["t"] - 2.306) < 1e-3 and abs(v["se_diff"] - math.hypot(0.0033, 0.0033)) < 1e-15
    assert abs(v["high"] - (0.0018 + v["t"] * v["se_diff"])) < 1e-15 and v["verdict"] == "not resolved"
    assert error_verdict(0.0018, 0.001, 0.001, 5, 5)["verdict"] == "met"
    assert error_verdict(0.02, 0.001, 0.001, 5, 5)["verdict"] == "not met"
    assert error_verdict(0.0018, math.nan, 0.001, 5, 5)["verdict"] == "not resolved"
    assert error_verdict(0.0018, 0.001, 0.001, 1, 5)["verdict"] == "not resolved"


def test_reduced_rows_and_goal_give_the_error_of_i_acc_beside_i_dec(monkeypatch):
    """Euler's error of I_acc, the other wear index, is larger than of I_dec (2000 rpm, dt 3e-7: 9.2e-5 and
    3.6e-4), so "euler reaches 1e-4 at dt = 3e-7" held for I_dec only: the rows carry rel_error_I_acc, the
    table prints it and the goal lines say where euler reaches 1e-4 in I_acc (here never on the grid)."""
    from benchmarks.bench import _markdown, reduced_goal

    euler = [(1e-6, 1e-3, 2e-4, 6e-4), (3e-7, 3e-3, 9e-5, 3.6e-4), (1e-7, 1e-2, 2e-5, 1.5e-4)]
    rows = []
    for rpm in (500, 2000, 6000):
        rows += [dict(model="reduced", method="event", rpm=rpm, wall_s=1e-5, rel_error=1e-15, rel_error_I_acc=3e-15)]
        rows += [dict(model="reduced", method="euler", rpm=rpm, dt_s=dt, wall_s=w, rel_error=e, rel_error_I_acc=a)
                 for dt, w, e, a in euler]
    lines = reduced_goal(rows)
    assert "dt = 3e-07 s" in lines[0]
    assert lines[1] == "  I_acc (event error 3.0e-15): euler does not reach 1e-4 on the dt grid " \
                       "(dt = 1e-07 s: 1.5e-04, I_dec 2.0e-05)", lines[1]
    head = [c.strip() for c in _markdown(rows[:2]).splitlines()[0].strip("|").split("|")]
    assert "rel_error_I_acc" in head
    rows[2]["rel_error_I_acc"] = 9e-5
    rows[3]["rel_error_I_acc"] = 8e-5
    assert "euler needs dt = 3e-07 s and 3.000 ms for 1e-4 (I_acc 9.0e-05" in reduced_goal(rows)[1]


def test_reduced_rows_measure_the_error_of_i_acc():
    """reduced_rows' errors come from both indices of the pass (no timing asserted)."""
    from types import SimpleNamespace

    from benchmarks.bench import _index_errors

    e = _index_errors(SimpleNamespace(I_dec=1.01, I_acc=0.2 * 1.03), SimpleNamespace(I_dec=1.0, I_acc=0.2))
    assert abs(e["rel_error"] - 0.01) < 1e-12 and abs(e["rel_error_I_acc"] - 0.03) < 1e-12


def test_an_i_acc_of_zero_has_an_error_of_its_own():
    """At 6000 rpm no roller touches the front face in the event solution (I_acc = 0): the bench stopped
    with ZeroDivisionError. Both 0: error 0; a non-zero I_acc against 0: inf (no relative error is finite)."""
    import math
    from types import SimpleNamespace

    from benchmarks.bench import _index_errors

    ref = SimpleNamespace(I_dec=1.0, I_acc=0.0)
    assert _index_errors(SimpleNamespace(I_dec=1.0, I_acc=0.0), ref)["rel_error_I_acc"] == 0.0
    assert _index_errors(SimpleNamespace(I_dec=1.0, I_acc=1e-9), ref)["rel_error_I_acc"] == math.inf


def test_a_full_scene_row_gives_the_error_of_i_acc_against_its_reference():
    from types import SimpleNamespace

    from benchmarks.multibody_bench import _row

    run = SimpleNamespace(provenance={"solver_wall_s": 1.0, "pymunk_step_s": 0.5},
                          summary={"I_dec_mean_Ns": 0.0181, "I_acc_mean_Ns": 0.0042, "steps": 10})
    row = _row("full", 6000, 4e-6, [run], 3, 0.018, "full scene at dt = 1e-06 s", 0.004)
    assert abs(row["rel_error_I_acc"] - 0.05) < 1e-12 and abs(row["rel_error"] - 0.1 / 18) < 1e-12


def test_the_cost_goal_is_judged_on_the_spread_of_interleaved_repeats():
    """Exact faces against the 3-segment polyline (rigid, 1000 rpm) read 1.24 x in the full bench ("not met")
    and 1.06 x in --quick ("met") from medians of 3 and 1 repeats: the verdict flipped with the machine's load.
    It now rests on the ratio of the minima and the spread of the pairs' ratios: "not resolved" where the
    spread straddles 1.2 or fewer than 3 pairs ran."""
    from benchmarks.multibody_bench import cost_verdict

    v = cost_verdict([0.30, 0.26, 0.28], [0.25, 0.24, 0.22])  # pairs 1.20, 1.083, 1.273
    assert v["verdict"] == "not resolved" and abs(v["ratio"] - 0.26 / 0.22) < 1e-12
    assert abs(v["low"] - 0.26 / 0.24) < 1e-12 and abs(v["high"] - 0.28 / 0.22) < 1e-12
    assert cost_verdict([0.2, 0.21, 0.2], [0.2, 0.2, 0.19])["verdict"] == "met"
    assert cost_verdict([0.3, 0.31, 0.3], [0.2, 0.2, 0.19])["verdict"] == "not met"
    assert cost_verdict([0.2], [0.2])["verdict"] == "not resolved"  # one pair: no spread


def test_the_speed_against_error_plot_draws_every_measured_row_once(tmp_path, monkeypatch):
    """bench.png, drawn from the table docs/bench.md publishes (``plot_table``): every row with both an error
    and a wall time is a point, in the panel of its model (reduced: per no-load pass; multibody: per cage
    rotation), at its own (error, wall time), an error of zero at the round-off floor; the reference rows
    (no error) and the stopped row draw nothing."""
    import matplotlib.figure

    from benchmarks import bench

    saved = {}
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda fig, *a, **kw: saved.setdefault("fig", fig))
    table = Path(__file__).resolve().parents[1] / "docs" / "bench.md"
    bench.plot_table(table, tmp_path / "bench.png")
    rows = [ln.strip("|").split("|") for ln in table.read_text().splitlines() if ln.startswith("| ")]
    head = [c.strip() for c in rows[0]]
    want = {"reduced": [], "multibody": []}
    for cells in rows[1:]:
        r = dict(zip(head, (c.strip() for c in cells)))
        if r["model"] in want and r["rel_error"] not in ("", "-") and r["wall_s"] not in ("", "-"):
            want[r["model"]].append((max(float(r["rel_error"]), bench._ZERO_ERROR), float(r["wall_s"])))
    red, mb = saved["fig"].axes
    for ax, model in ((red, "reduced"), (mb, "multibody")):
        drawn = {(x, y) for line in ax.get_lines() for x, y in zip(line.get_xdata(), line.get_ydata())}
        assert want[model] and drawn == set(want[model]), model
