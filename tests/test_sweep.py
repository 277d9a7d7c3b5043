"""What-if sweeps (issue 15): validation before running, content-hash archives, the index, resume,
failures, interruption by signals, the local pool and a real dask LocalCluster, figures."""
import csv
import math
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest

from bearingsim.errors import SimulationUnstable
from bearingsim.simulation import run as simulate
from bearingsim.scenario import load_scenario
from bearingsim.sweeps import LocalEngine, SweepSpec, case_hash, read_index, resolve_cases, run_sweep
from bearingsim.sweeps.plot import axis_label, plot_sweep_index
from bearingsim.cli_sweep import run_sweep_cli
from bearingsim.sweeps.run import make_batches
from bearingsim.sweeps.spec import Case, load_sweep_file, scenario_from_toml
from bearingsim.stats import impulse_standard_errors as standard_errors

from .conftest import ROOT, SCENARIOS, started
from .test_cli import assert_user_error, bearingsim
from .forked_cli import pythonpath as _path

BASE = SCENARIOS / "paper_3000rpm.toml"
SPEED = "operating.inner_ring_speed_rpm"


def _rows(folder):
    with open(folder / "sweep.csv") as fh:
        return list(csv.DictReader(fh))


@pytest.mark.slow
def test_sweep_table_matches_single_runs(tmp_path):
    res = bearingsim("sweep", BASE, "--param", f"{SPEED}=500,6000", "--param", "lubrication.drag_coefficient=0.01,0.03",
                     "-o", tmp_path, "-j", "2", "--archives", "all")
    assert res.returncode == 0, res.stderr
    rows = _rows(tmp_path)
    assert len(rows) == 4
    assert (tmp_path / "sweep_map.png").exists()  # two axes: a heat map
    for row in rows:
        assert row["status"] == "done" and row["error"] == ""
        sc = load_scenario(BASE, [f"{SPEED}={row[SPEED]}", f"lubrication.drag_coefficient={row['lubrication.drag_coefficient']}"])
        assert float(row["I_dec_mean_Ns"]) == pytest.approx(simulate(sc).summary["I_dec_mean_Ns"], rel=1e-12, abs=0)
        # the archive is named by the hash of the scenario it stores
        with h5py.File(tmp_path / row["archive"], "r") as f:
            stored = f["scenario"][()].decode()
            assert bool(f["bearingsim"].attrs["complete"])
        assert row["archive"] == f"cases/{case_hash(stored)}.h5" == f"cases/{row['case']}.h5"
    cols, meta = read_index(tmp_path / "sweep.h5")
    assert meta["axes"] == [SPEED, "lubrication.drag_coefficient"]
    assert list(cols["status"]) == ["done"] * 4
    np.testing.assert_array_equal(cols[SPEED], [500.0, 500.0, 6000.0, 6000.0])


@pytest.mark.slow
def test_sweep_with_a_bad_point_runs_nothing(tmp_path):
    res = bearingsim("sweep", BASE, "--param", "contact.restitution=0.5,1.5", "-o", tmp_path)
    assert_user_error(res, "contact.restitution")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, key", [
    (["--param", f"{SPEED}=500,1000", "--param", f"{SPEED}=2000"], SPEED),
    (["--param", f"{SPEED}=500,1000", "--set", f"{SPEED}=2000"], SPEED),
    (["--param", "bearing.no_such_key=1,2"], "bearing.no_such_key"),
])
@pytest.mark.slow
def test_key_twice_or_unknown_is_refused_before_running(tmp_path, args, key):
    res = bearingsim("sweep", BASE, *args, "-o", tmp_path / "out")
    assert_user_error(res, key)
    assert not (tmp_path / "out").exists()


def test_set_on_the_command_line_overrides_the_sweep_files_set():
    """`--set` adds to a sweep file as it adds to a scenario file: a key the file's [set] also gives takes the
    command line's value (it was refused, 'numerics.rotations: given twice', so a shipped sweep could not be
    shortened without copying it); the same key twice on the command line is still refused."""
    from bearingsim.errors import UserError
    from bearingsim.sweeps.spec import spec_from_args

    path = SCENARIOS / "sweeps" / "multibody_speed.toml"  # [set] numerics.rotations = 10
    cases = resolve_cases(spec_from_args(path, [], ["numerics.rotations=2"]))
    assert len(cases) == 5 and {scenario_from_toml(c.toml).numerics.rotations for c in cases} == {2}
    assert {scenario_from_toml(c.toml).numerics.rotations for c in resolve_cases(spec_from_args(path, [], []))} == {10}
    with pytest.raises(UserError, match="numerics.rotations"):
        resolve_cases(spec_from_args(path, [], ["numerics.rotations=2", "numerics.rotations=3"]))


@pytest.mark.parametrize("params, sets, named", [
    (["bearing.pocket_clearance_mm=0.2,0.3"], ["numerics.warmup_rotations=0"], "with numerics.warmup_rotations=0: "),
    (["bearing.pocket_clearance_mm=0.2,5"], [], "with bearing.pocket_clearance_mm=5: "),
    (["bearing.roller_count=16,17"], ["bearing.pocket_clearance_mm=4.2"],
     "with bearing.pocket_clearance_mm=4.2 and bearing.roller_count=17: "),
])
def test_a_sweeps_refusal_names_the_overrides_and_the_case_value_it_is_about(params, sets, named):
    """A sweep's refusal of a case names the --set values and the case's --param value it is about as `run --set`
    does ("FILE with KEY=VALUE: ..."); it blamed the scenario file for them ("FILE: KEY: ...")."""
    from bearingsim.errors import UserError
    from bearingsim.sweeps.spec import spec_from_args

    path = SCENARIOS / "multibody_3000rpm.toml"
    with pytest.raises(UserError) as err:
        resolve_cases(spec_from_args(path, params, sets))
    assert str(err.value).startswith(f"{path} {named}"), str(err.value)
    assert "(sweep case " in str(err.value)


@pytest.mark.parametrize("params, sets, named", [
    (["operating.inner_ring_speed_rpm=300,3000"], ["multibody.raceway_contact=rigid"],
     "with multibody.raceway_contact=rigid and operating.inner_ring_speed_rpm=300: "),
    (["bearing.pocket_clearance_mm=0.2,0.3"], ["numerics.dt_s=1"], "with numerics.dt_s=1: numerics.dt_s"),
])
def test_a_case_the_run_would_refuse_at_its_start_is_refused_before_any_case_runs(params, sets, named):
    """The model's own start checks (rigid raceways below their speed floor, a step far above the stable one)
    were made only when a case ran: the other cases ran and the case failed. The sweep refuses it before any
    case runs, as `bearingsim run` and its dry run do, naming the case and the overrides it is about."""
    from bearingsim.errors import UserError
    from bearingsim.sweeps.spec import spec_from_args

    path = SCENARIOS / "multibody_3000rpm.toml"
    with pytest.raises(UserError) as err:
        resolve_cases(spec_from_args(path, params, sets))
    assert str(err.value).startswith(f"{path} {named}") and "(sweep case " in str(err.value), str(err.value)


@pytest.mark.slow
@pytest.mark.parametrize("spec_or_cases", ["spec", "cases"])
def test_the_pool_has_no_more_workers_than_the_sweep_has_cases(tmp_path, spec_or_cases):
    """`-j 1000` for a sweep of two cases started a thousand worker processes (the trial's machine ran out
    of memory); the local pool is as large as -j asks or as the sweep has cases, whichever is fewer, both
    when the reduced model's workers are warmed up from the sweep's description and when cases are given."""
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [500.0, 600.0])])
    engine = LocalEngine(16)  # not more: were the pool as large as -j, this test would start that many processes
    out = run_sweep(spec if spec_or_cases == "spec" else resolve_cases(spec), tmp_path, engine=engine,
                    figures=False, progress=False)
    assert [r["status"] for r in out.rows] == ["done", "done"]
    assert (engine.jobs, engine.workers) == (16, 2)


@pytest.mark.slow
def test_sweep_file_zip_and_extra_cases(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(f"""scenario = "{BASE}"
mode = "zip"
[set]
"contact.restitution" = 0.7
[axes]
"{SPEED}" = [500, 1000, 2000]
lubrication.drag_coefficient = [0.01, 0.02, 0.03]
[[cases]]
"{SPEED}" = 6000
"bearing.pocket_clearance_mm" = 0.3
""")
    spec = load_sweep_file(f)
    cases = resolve_cases(spec)
    assert [c.values for c in cases] == [
        {SPEED: 500, "lubrication.drag_coefficient": 0.01}, {SPEED: 1000, "lubrication.drag_coefficient": 0.02},
        {SPEED: 2000, "lubrication.drag_coefficient": 0.03}, {SPEED: 6000, "bearing.pocket_clearance_mm": 0.3}]
    assert spec.keys == [SPEED, "lubrication.drag_coefficient", "bearing.pocket_clearance_mm"]
    sc = scenario_from_toml(cases[3].toml)
    assert sc.contact.restitution == 0.7 and sc.bearing.pocket_clearance_mm == 0.3
    # a worker rebuilds exactly the scenario that was hashed, or resume could never find a case
    assert all(scenario_from_toml(c.toml).to_toml() == c.toml for c in cases)

    f.write_text(f.read_text().replace("[0.01, 0.02, 0.03]", "[0.01, 0.02]"))
    res = bearingsim("sweep", f, "-o", tmp_path / "out")
    assert_user_error(res, "zip", "lubrication.drag_coefficient: 2")
    f.write_text(f.read_text().replace('"contact.restitution" = 0.7', f'"{SPEED}" = 100'))
    assert_user_error(bearingsim("sweep", f, "-o", tmp_path / "out"), SPEED, "both")
    f.write_text(f'scenario = "{BASE}"\naxis = 1\n')
    assert_user_error(bearingsim("sweep", f, "-o", tmp_path / "out"), "axis", "unknown key")
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_a_swept_key_a_case_does_not_set_shows_the_value_it_ran_at(tmp_path):
    """The shipped zip-and-extras sweep: its two [[cases]] set the speed and one other key, not the drag
    coefficient, and the zipped cases set neither the restitution nor the direction. Those cells were
    NaN (or empty) in the printed table and the index, although every case ran at a value: its resolved
    scenario's, the base scenario's here. Now the table, sweep.csv and sweep.h5 show that value."""
    f = SCENARIOS / "sweeps" / "speed_zip_and_extras.toml"
    res = bearingsim("sweep", f, "-o", tmp_path, "-j", "1", "--no-plots")
    assert res.returncode == 0, res.stderr
    base = load_scenario(BASE)
    drag, e, way = base.lubrication.drag_coefficient, base.contact.restitution, base.operating.direction
    cols, meta = read_index(tmp_path / "sweep.h5")
    assert meta["axes"] == [SPEED, "lubrication.drag_coefficient", "contact.restitution", "operating.direction"]
    np.testing.assert_array_equal(cols["lubrication.drag_coefficient"], [0.01, 0.015, 0.02, 0.03, drag, drag])
    np.testing.assert_array_equal(cols["contact.restitution"], [e, e, e, e, 0.6, e])
    assert list(cols["operating.direction"]) == [way] * 5 + ["reverse"]
    rows = _rows(tmp_path)
    assert [float(r["lubrication.drag_coefficient"]) for r in rows[4:]] == [drag, drag]
    assert [r["operating.direction"] for r in rows] == [way] * 5 + ["reverse"]
    lines = res.stdout.splitlines()
    (i,) = [k for k, ln in enumerate(lines) if ln.startswith(SPEED)]
    table = [ln.split() for ln in lines[i + 1:i + 7]]
    assert [t[:4] for t in table[4:]] == [["3000", f"{drag:g}", "0.6", way], ["3000", f"{drag:g}", f"{e:g}", "reverse"]]
    assert "nan" not in res.stdout


@pytest.mark.slow
def test_shipped_sweep_files_resolve():
    files = sorted((SCENARIOS / "sweeps").glob("*.toml"))
    assert len(files) >= 3
    n = {f.name: len(resolve_cases(load_sweep_file(f))) for f in files}
    assert n["map_speed_clearance.toml"] == 10_000 and n["speed_zip_and_extras.toml"] == 6


def test_same_scenario_twice_is_refused():
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [500, 500.0])])
    with pytest.raises(Exception, match="same scenario"):
        resolve_cases(spec)


def test_batches_group_cheap_cases_only():
    red = [Case(f"r{i}", {}, "t", "reduced") for i in range(40)]
    mb = [Case(f"m{i}", {}, "t", "multibody") for i in range(3)]
    batches = make_batches(red + mb, workers=2)
    sizes = sorted(len(b) for b in batches)
    assert sizes == [1, 1, 1] + [5] * 8  # 40 reduced cases in 4 batches per worker, multibody alone
    assert sorted(h for b in batches for h, _ in b) == sorted(c.hash for c in red + mb)


def test_last_batches_of_a_large_sweep_shrink():
    red = [Case(f"r{i}", {}, "t", "reduced") for i in range(10_000)]
    sizes = [len(b) for b in make_batches(red, workers=2)]
    assert max(sizes) == 200 and sizes[:40] == [200] * 40  # full batches first
    assert sizes[-6:-1] == sorted(sizes[-6:-1], reverse=True) and max(sizes[-6:]) <= 15  # a short tail
    assert [h for b in make_batches(red, workers=2) for h, _ in b] == [c.hash for c in red]


def test_standard_error_is_over_rotations_of_pocket_means():
    # two rotations of two pockets: rotation means 2 and 4 -> sample std sqrt(2), over sqrt(2) -> 1
    se = standard_errors(np.array([[1.0, 3.0], [3.0, 5.0]]), np.zeros((2, 2)))
    assert se["I_dec_sem_Ns"] == pytest.approx(1.0) and se["I_acc_sem_Ns"] == 0.0
    assert math.isnan(standard_errors(np.ones((1, 4)), np.ones((1, 4)))["I_dec_sem_Ns"])


def test_resume_runs_only_what_is_missing(tmp_path):
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000, 3000, 4000])])
    first = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert [r["status"] for r in first.rows] == ["done"] * 4
    cases = tmp_path / "cases"
    kept = cases / f"{first.rows[0]['case']}.h5"
    mtime = kept.stat().st_mtime_ns
    (cases / f"{first.rows[1]['case']}.h5").unlink()  # lost
    data = (cases / f"{first.rows[2]['case']}.h5").read_bytes()
    (cases / f"{first.rows[2]['case']}.h5").write_bytes(data[: len(data) // 2])  # truncated
    with h5py.File(cases / f"{first.rows[3]['case']}.h5", "a") as f:  # complete flag not set: a partial file
        f["bearingsim"].attrs["complete"] = False
    (cases / f".{first.rows[1]['case']}.h5.tmp-99999").write_bytes(data)  # a dead worker's temporary file

    # the truncated file: HDF5 cannot open it, so nothing tells it is bearingsim's (an archive is written through a
    # temporary file and renamed complete): refused, not removed, until the user removes it
    truncated = cases / f"{first.rows[2]['case']}.h5"
    index = (tmp_path / "sweep.h5").read_bytes()
    from bearingsim.errors import UserError

    with pytest.raises(UserError, match=f"{truncated}: archive of the case {SPEED}=3000 of {tmp_path} is not known to "
                                        f"be bearingsim's: damaged or truncated file"):
        run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert truncated.read_bytes() == data[: len(data) // 2] and (tmp_path / "sweep.h5").read_bytes() == index
    truncated.unlink()
    again = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert [r["status"] for r in again.rows] == ["cached", "done", "done", "done"]
    assert kept.stat().st_mtime_ns == mtime
    assert not list(cases.glob(".*"))
    for a, b in zip(first.rows, again.rows):
        assert a["summary"]["I_dec_mean_Ns"] == b["summary"]["I_dec_mean_Ns"]
    assert [r["status"] for r in _rows(tmp_path)] == ["cached", "done", "done", "done"]


def _set_provenance(path, **changes):
    """Rewrite an archive's provenance as an older bearingsim would have written it (None: key absent)."""
    import json

    with h5py.File(path, "a") as f:
        g = f["provenance"]
        prov = json.loads(g.attrs["attrs_json"])
        for k, v in changes.items():
            if v is None:
                prov.pop(k, None)
            else:
                prov[k] = v
        g.attrs["attrs_json"] = json.dumps(prov, sort_keys=True)


def test_resume_reruns_archives_of_another_model_version(tmp_path):
    """A case is ``cached`` only when its archive was computed by the same version of the model
    (``bearingsim.model_versions``); an archive of the same scenario from another version, or from a
    bearingsim that stored none, is ``stale``: run again, replaced, and the index says so."""
    from bearingsim.archive import peek
    from bearingsim.model_versions import MODEL_VERSIONS

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000, 3000])])
    first = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    cases = tmp_path / "cases"
    archives = [cases / f"{r['case']}.h5" for r in first.rows]
    assert [peek(a)["model_version"] for a in archives] == [MODEL_VERSIONS["reduced"]] * 3
    _set_provenance(archives[1], model_version=MODEL_VERSIONS["reduced"] + 1)  # another model's numbers
    _set_provenance(archives[2], model_version=None)  # written before models had a version
    kept = archives[0].stat().st_mtime_ns

    again = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert [r["status"] for r in again.rows] == ["cached", "stale", "stale"]
    assert again.count("stale") == 2
    # the count says what was done, not what to do: the stale cases ran already (it read "run again")
    assert again.counts() == "0 done, 1 cached, 0 failed, 2 stale (another model version's: computed again)"
    assert archives[0].stat().st_mtime_ns == kept
    assert [peek(a)["model_version"] for a in archives] == [MODEL_VERSIONS["reduced"]] * 3  # replaced
    for a, b in zip(first.rows, again.rows):
        assert a["summary"]["I_dec_mean_Ns"] == b["summary"]["I_dec_mean_Ns"]
    assert [r["status"] for r in _rows(tmp_path)] == ["cached", "stale", "stale"]
    index, _ = read_index(tmp_path / "sweep.h5")
    assert [str(s) for s in index["status"]] == ["cached", "stale", "stale"]
    third = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert [r["status"] for r in third.rows] == ["cached"] * 3


class _FakeTime:
    """A stand-in for the ``time`` module of :mod:`bearingsim.sweeps.run`: its clocks (``perf_counter``,
    ``monotonic``) read ``now``, which moves only when the test moves it; anything else is the real module's."""

    def __init__(self):
        self.now = 1000.0

    def perf_counter(self) -> float:
        return self.now

    monotonic = perf_counter

    def __getattr__(self, name):
        return getattr(time, name)


def test_sweep_wall_time_covers_its_cases(tmp_path, monkeypatch):
    """``SweepOutcome.wall_s`` is the sweep's wall time from call to return: on a clock of the test's that
    moves only by the set-up's time (resolving the cases, SETUP_S) and, as each batch's records come in, by
    the cases' own times (measured in the worker), it is all the time that passed in the call, so on one
    worker at least the sum of the cases' own times (a timer reused for the index rewrites once made it the
    time since the last rewrite; the index is rewritten after every batch here). No real-time bound."""
    import bearingsim.sweeps.run as sweep_run

    setup_s = 7.0
    clock = _FakeTime()
    resolve = sweep_run._resolve

    def slow_resolve(*args, **kwargs):  # the call's own set-up, inside its wall time
        clock.now += setup_s
        return resolve(*args, **kwargs)

    class CaseTimedEngine(LocalEngine):
        def run(self, *args, **kwargs):
            for records in super().run(*args, **kwargs):
                clock.now += sum(r["wall_s"] for r in records)
                yield records

    monkeypatch.setattr(sweep_run, "time", clock)
    monkeypatch.setattr(sweep_run, "_resolve", slow_resolve)
    monkeypatch.setattr(sweep_run, "INDEX_EVERY_S", 0.0)
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000, 3000])])
    before = clock.now
    out = run_sweep(spec, tmp_path, engine=CaseTimedEngine(1), figures=False, progress=False)
    cases_s = sum(r["wall_s"] for r in out.rows)
    assert [r["status"] for r in out.rows] == ["done"] * 3 and cases_s > 0.0
    assert clock.now - before == pytest.approx(setup_s + cases_s, rel=1e-12)  # the clock moved as meant
    assert out.wall_s == pytest.approx(clock.now - before, rel=1e-12)  # all of the call's time
    assert out.wall_s >= cases_s


@pytest.mark.slow
def test_failed_case_is_recorded_and_the_others_go_on(tmp_path):
    # without drag and gravity nothing moves the roller off its front face: the run has no rear-face impact,
    # which only the finished run shows (plausibility.check refuses it)
    res = bearingsim("sweep", BASE, "--set", "operating.gravity=false", "--param",
                     "lubrication.drag_coefficient=0.02,0,0.03", "-o", tmp_path, "-j", "2")
    assert res.returncode == 1, res.stderr
    assert "Traceback" not in res.stderr
    rows = _rows(tmp_path)
    assert [r["status"] for r in rows] == ["done", "failed", "done"]
    assert "lubrication.drag_coefficient = 0" in rows[1]["error"] and "\n" not in rows[1]["error"]
    assert rows[1]["archive"] == ""
    assert rows[1]["case"] in res.stderr.splitlines()[-1] and "1 of 3 cases failed" in res.stderr
    assert not (tmp_path / "cases" / f"{rows[1]['case']}.h5").exists()


@pytest.mark.slow  # over 2 s (quick subset under a minute)
def test_failure_of_any_kind_is_one_line(tmp_path, monkeypatch, capsys):
    # forked pool workers inherit the patch: a case at 2000 rpm raises as an unstable run would
    import bearingsim.simulation as simulation

    real = simulation.run

    def flaky(scenario, *a, **kw):
        if scenario.operating.inner_ring_speed_rpm == 2000:
            raise SimulationUnstable("energy blow-up at t = 0.1 s; try a smaller dt")
        if scenario.operating.inner_ring_speed_rpm == 3000:
            raise ZeroDivisionError("float division by zero")
        return real(scenario, *a, **kw)

    monkeypatch.setattr(simulation, "run", flaky)  # what every case runs through, in memory or streamed
    code = run_sweep_cli(BASE, [f"{SPEED}=1000,2000,3000"], [], tmp_path, jobs=2, figures=False, quiet=True)
    assert code == 1
    rows = _rows(tmp_path)
    assert [r["status"] for r in rows] == ["done", "failed", "failed"]
    assert rows[1]["error"] == "energy blow-up at t = 0.1 s; try a smaller dt"
    assert rows[2]["error"] == "ZeroDivisionError: float division by zero"
    err = capsys.readouterr().err
    assert "2 of 3 cases failed" in err and f"{SPEED}=2000" in err and "Traceback" not in err


def _descendants(pid):
    import psutil

    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def _running(procs) -> list:
    """Those of ``procs`` (psutil processes) still running: neither gone nor a zombie (ended, not yet reaped)."""
    import psutil

    alive = []
    for p in procs:
        try:
            if p.is_running() and p.status() != psutil.STATUS_ZOMBIE:
                alive.append(p)
        except psutil.NoSuchProcess:
            pass
    return alive


#: the sweep of the signal test: the first case quick (euler at 50 ns: a few hundredths of a second), the seven
#: others 33 times as many steps each (1.50-1.56 ns: over a second each here). The case queued second starts
#: with the quick one and the third when it ends, so both are far from their end when the quick one is indexed
#: and the signal comes, on a machine of any speed; and short enough that a worker let finish its case after
#: the signal writes it before the sweep's stop kills it (engines.STOP_WAIT_S, 3 s)
SIGNAL_DTS = ("5e-08", *(f"{1.5 + i / 100:.2f}e-09" for i in range(7)))
#: the sweep process: ``bearingsim sweep`` with the index rewritten after every batch (as in
#: test_sweep_wall_time_covers_its_cases), so that the quick case's row says done as soon as its record is in
SWEEP_EVERY_BATCH = ("import sys; import bearingsim.sweeps.run as r; r.INDEX_EVERY_S = 0.0; "
                     "from bearingsim.cli import main; sys.exit(main(sys.argv[1:]))")


@pytest.mark.slow
@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130), (signal.SIGHUP, 129)])
def test_signal_stops_the_sweep_and_keeps_finished_cases(tmp_path, signum, code):
    """A signal stops the sweep at once: the cases running when it comes are not finished (no row done, no
    archive: a sweep that let its workers finish them wrote theirs), the queued ones not started, the
    finished one kept, the workers ended before the sweep exits, no temporary file, one line on how to
    resume, exit 128 + signal. No wall-time bound: the cases running at the signal take far longer than
    the one finished before it, on any machine."""
    cmd = [sys.executable, "-c", SWEEP_EVERY_BATCH, "sweep", BASE, "--set", "reduced.method=euler",
           "--param", f"numerics.dt_s={','.join(SIGNAL_DTS)}", "-o", tmp_path, "-j", "2", "--no-plots",
           "--archives", "all"]
    with started(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
        deadline = time.monotonic() + 300  # a hang guard only
        while time.monotonic() < deadline and proc.poll() is None:
            if (tmp_path / "sweep.csv").exists() and any(r["status"] == "done" for r in _rows(tmp_path)):
                break
            time.sleep(0.05)
        children = _descendants(proc.pid)
        assert proc.poll() is None and len(children) >= 2, "the sweep ended before the signal"  # the pool's workers
        os.kill(proc.pid, signum)
        _, err = proc.communicate(timeout=300)  # a hang guard only
    assert proc.returncode == code, err
    assert _running(children) == []  # ended (and reaped) before the sweep process exited
    rows = _rows(tmp_path)
    assert [r["numerics.dt_s"] for r in rows] == [f"{float(dt):g}" for dt in SIGNAL_DTS]
    assert [r["status"] for r in rows] == ["done"] + ["pending"] * 7  # the two running at the signal: not done
    assert sorted(p.name for p in (tmp_path / "cases").iterdir()) == [f"{rows[0]['case']}.h5"]  # none of theirs
    with h5py.File(tmp_path / rows[0]["archive"], "r") as f:
        assert bool(f["bearingsim"].attrs["complete"])
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "1 done" in err and "7 not run" in err and err.rstrip().endswith("run the same command again to resume")


def test_a_signal_inside_a_weakref_callback_is_kept_without_a_traceback(monkeypatch):
    """A signal that lands in a weakref callback (as one did in a clean-clone CI run, traceback through
    ``weakref.py``): Python cannot propagate the handler's exception there, so it is "unraisable". The
    sweep's signal guard records the signal (``fired``, which the engines poll) and drops that exception
    instead of printing it; any other unraisable exception still reaches the previous hook, and the hook
    is restored on exit. The handler is called directly inside the callback, which is where the signal
    would have run it."""
    import weakref

    from bearingsim.sweeps.run import SweepInterrupted, _Signals

    seen = []
    monkeypatch.setattr(sys, "unraisablehook", lambda u: seen.append(type(u.exc_value)))
    hook = sys.unraisablehook

    class Thing:
        pass

    with _Signals() as sig:
        a = Thing()
        ref_a = weakref.ref(a, lambda r: sig._handler(signal.SIGTERM, None))
        del a
        b = Thing()
        ref_b = weakref.ref(b, lambda r: 1 / 0)
        del b
    assert sig.fired == signal.SIGTERM
    assert seen == [ZeroDivisionError] and SweepInterrupted not in seen
    assert sys.unraisablehook is hook and ref_a() is None and ref_b() is None


@pytest.mark.slow
def test_local_cluster_runs_the_same_cases(tmp_path):
    pytest.importorskip("distributed")
    from distributed import LocalCluster

    from bearingsim.sweeps import DaskEngine

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [500, 2000, 6000])])
    local = run_sweep(spec, tmp_path / "local", engine=LocalEngine(1), figures=False, progress=False, archives="all")
    with warnings.catch_warnings(record=True) as seen:
        # dask's own start-up and shut-down notices (a port in use, comms closing) are recorded, not
        # raised; none may come from bearingsim itself
        warnings.simplefilter("always")
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                          host="127.0.0.1") as cluster:
            out = run_sweep(spec, tmp_path / "dask", engine=DaskEngine(cluster=cluster), figures=False,
                            progress=False, archives="all")
            assert len(cluster.scheduler_info["workers"]) == 2
            assert {r["case"] for r in out.rows} == {c.hash for c in resolve_cases(spec)}
            bare = run_sweep(spec, tmp_path / "dask_bare", engine=DaskEngine(cluster=cluster), figures=False,
                             progress=False)  # reduced cases: numbers only, no archive sent back
    assert [r["archive"] for r in bare.rows] == [""] * 3 and not (tmp_path / "dask_bare" / "cases").exists()
    assert [r["summary"] for r in bare.rows] == [r["summary"] for r in out.rows]
    assert [r["status"] for r in out.rows] == ["done"] * 3
    assert [str(w.message) for w in seen if "bearingsim" in w.filename] == []
    for a, b in zip(local.rows, out.rows):
        assert a["case"] == b["case"]
        assert a["summary"]["I_dec_mean_Ns"] == b["summary"]["I_dec_mean_Ns"]
        with h5py.File(tmp_path / "dask" / b["archive"], "r") as f:  # written by the client from the bytes
            assert f["scenario"][()].decode() == scenario_from_toml(f["scenario"][()].decode()).to_toml()
            assert bool(f["bearingsim"].attrs["complete"])


@pytest.mark.slow
def test_unreachable_scheduler_is_a_user_error():
    pytest.importorskip("distributed")
    from bearingsim.errors import UserError
    from bearingsim.sweeps import DaskEngine

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(UserError, match="cannot reach a dask scheduler"):
            DaskEngine("tcp://127.0.0.1:9", timeout_s=1).start()


@pytest.mark.parametrize("address", ["foo", "tcp://127.0.0.1:notaport", "inproc://x", ""])
def test_a_scheduler_address_no_client_can_use_is_one_line(tmp_path, address):
    """A malformed, in-process or empty --scheduler address is refused in one line (exit 2), nothing
    written: the client made with it raised in its constructor and, collected, printed a traceback after
    the error (and held the command 20 s); an empty one ran the sweep on the local pool instead."""
    pytest.importorskip("distributed")
    res = bearingsim("sweep", str(BASE), "--param", f"{SPEED}=1000,2000", "--scheduler", address,
                     "-o", str(tmp_path / "sw"), "--no-plots", "-q")
    assert_user_error(res, "--scheduler", "not a dask scheduler address")
    assert not (tmp_path / "sw").exists()


def test_a_scheduler_lost_mid_sweep_stops_it_in_one_line_and_keeps_the_finished_cases(tmp_path, monkeypatch):
    """The scheduler ends while batches are queued: dask cancels every future of the client ('scheduler-
    connection-lost'). Each case of them was recorded failed with a line of its own (8800 lines for the
    100 x 100 map) and the command ended 'N cases failed'; now the sweep stops with one error, the cases of
    the batch that came back kept (done), the others pending, the index written, and no cancel is sent to
    the scheduler that is gone."""
    distributed = pytest.importorskip("distributed")
    from distributed.client import FutureCancelledError

    from bearingsim.errors import UserError
    from bearingsim.sweeps import DaskEngine
    from bearingsim.sweeps.worker import run_batch

    class Future:
        def __init__(self, key, args):
            self.key, self.args = key, args

        def result(self):
            if self.key.endswith("-0"):  # the first batch came back before the scheduler went
                return run_batch(*self.args)
            raise FutureCancelledError(self.key, "scheduler-connection-lost", "Client lost the connection.")

    class Client:
        status, loop, cancelled = "running", None, []

        def submit(self, fn, *args, key, pure):
            return Future(key, args)

        def cancel(self, futures, force=False):
            self.cancelled.append(futures)

        def close(self, timeout=None):
            pass

    monkeypatch.setattr(distributed, "as_completed", lambda futures, loop=None: iter(list(futures)))
    engine = DaskEngine("tcp://127.0.0.1:9")
    engine.client, engine.workers = Client(), 1
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000, 3000, 4000])])
    with pytest.raises(UserError, match="lost the connection to the dask scheduler"):
        run_sweep(spec, tmp_path, engine=engine, figures=False, progress=False)
    status = [str(s) for s in read_index(tmp_path / "sweep.h5")[0]["status"]]
    assert status == ["done", "pending", "pending", "pending"], status
    assert Client.cancelled == []


@pytest.mark.slow
def test_figures_from_the_index(tmp_path):
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 3000])], sets=["numerics.rotations=2"])
    out = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=True, progress=False)
    assert [p.name for p in out.figures] == ["sweep_I.png"]
    assert axis_label(SPEED) == "inner ring speed [rpm]"
    assert axis_label("bearing.pocket_clearance_mm") == "pocket clearance [mm]"
    assert axis_label("lubrication.drag_coefficient") == "drag coefficient [N^0.754 (s/m)^0.648]"  # its unit as `bearingsim keys` gives it
    # drawn again from the index alone, into another folder
    again = plot_sweep_index(tmp_path / "sweep.h5", tmp_path / "again")
    assert [p.name for p in again] == ["sweep_I.png"] and again[0].stat().st_size > 10_000


@pytest.mark.slow
def test_figures_of_an_earlier_run_of_the_folder_do_not_stay_beside_the_new_ones(tmp_path):
    """A one-axis sweep (sweep_I.png) swept again into its folder over a second axis through the base value (its
    cases cached): the folder held the new sweep_map.png and the old sweep_I.png of 2 cases beside an index of 4;
    a cross-check (or any study) run into a sweep's folder kept its sweep_I.png too. The sweep figures an earlier
    run drew are removed when a sweep starts (a user's picture of that name, without bearingsim's mark, stays)."""
    one = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])])
    run_sweep(one, tmp_path, engine=LocalEngine(1), figures=True, progress=False)
    assert (tmp_path / "sweep_I.png").is_file()
    two = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000]), ("bearing.pocket_clearance_mm", [0.2, 0.3])])
    out = run_sweep(two, tmp_path, engine=LocalEngine(1), figures=True, progress=False)
    assert out.count("cached") == 2, out.counts()
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["sweep_map.png"]
    run_sweep(two, tmp_path, engine=LocalEngine(1), figures=False, progress=False)  # --no-plots: an index alone
    assert sorted(p.name for p in tmp_path.glob("*.png")) == []
    (tmp_path / "sweep_I.png").write_bytes(b"\x89PNG\r\n\x1a\n a user's picture")
    run_sweep(two, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert (tmp_path / "sweep_I.png").read_bytes() == b"\x89PNG\r\n\x1a\n a user's picture"


def test_a_sweep_over_an_integer_key_has_whole_ticks(tmp_path, monkeypatch):
    """A roller count of 14 and 16 was drawn with ticks at 14.5 and 15.5: an integer key's axis (the schema's
    type, :func:`bearingsim.scenario.is_integer_key`) has whole ticks only; a float key's keeps matplotlib's."""
    from bearingsim import plotting

    spec = SweepSpec(scenario=BASE, axes=[("bearing.roller_count", [14, 16])], sets=["numerics.rotations=1"])
    run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    drawn = []
    monkeypatch.setattr(plotting, "save_figure", lambda fig, path, **kw: drawn.append(fig) or Path(path))
    plot_sweep_index(tmp_path / "sweep.h5", tmp_path / "figs")
    ticks = [t for ax in drawn[0].axes for t in ax.get_xticks() if 14 <= t <= 16]
    assert ticks and all(float(t).is_integer() for t in ticks), ticks
    spec = SweepSpec(scenario=BASE, axes=[("bearing.pocket_clearance_mm", [0.14, 0.16, 0.18])],
                     sets=["numerics.rotations=1"])
    run_sweep(spec, tmp_path / "f", engine=LocalEngine(1), figures=False, progress=False)
    plot_sweep_index(tmp_path / "f" / "sweep.h5", tmp_path / "figs2")
    assert not all(float(t).is_integer() for t in drawn[1].axes[0].get_xticks())


def test_a_reduced_sweeps_figure_says_it_has_no_error_bars(tmp_path, monkeypatch):
    """The reduced model's sweep figure was titled "error bars: ±1 standard error" over none (its errors are 0):
    it says the model is exact; a sweep whose cases have standard errors (here edited into the index) keeps it."""
    import h5py

    from bearingsim import plotting

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])], sets=["numerics.rotations=1"])
    run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    drawn = []
    monkeypatch.setattr(plotting, "save_figure", lambda fig, path, **kw: drawn.append(fig) or Path(path))
    plot_sweep_index(tmp_path / "sweep.h5", tmp_path / "figs")
    assert [ax.get_title() for ax in drawn[0].axes] == [
        f"{sym} (exact: the reduced model has no standard error)" for sym in ("$I_{dec}$", "$I_{acc}$")]
    with h5py.File(tmp_path / "sweep.h5", "r+") as f:
        f["index/I_dec_sem_Ns"][0] = 1e-4
    plot_sweep_index(tmp_path / "sweep.h5", tmp_path / "figs2")
    assert drawn[1].axes[0].get_title() == "$I_{dec}$ (error bars: ±1 standard error)"


def test_second_sweep_into_the_same_folder_is_refused(tmp_path):
    import psutil

    from bearingsim.errors import UserError
    from bearingsim.outputs import FolderLock

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000])])
    before = {p.pid for p in psutil.Process().children(recursive=True)}  # e.g. multiprocessing's resource tracker
    with FolderLock(tmp_path):  # another sweep holds the folder
        with pytest.raises(UserError, match="another sweep or study is writing"):
            run_sweep(spec, tmp_path, engine=LocalEngine(2), figures=False, progress=False)
    assert {p.pid for p in psutil.Process().children(recursive=True)} - before == set()  # its pool is gone
    assert run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False).count("done") == 1


@pytest.mark.parametrize("what", ["text", "hdf5", "link"])
def test_a_users_file_at_a_case_archives_name_is_refused_not_removed(tmp_path, what):
    """The resume removed any file at a case archive's name ``cases/<hash>.h5`` that was not the case's current
    archive (a user's file put there, another program's HDF5 file, a symbolic link) and wrote the case's archive
    in its place. Only bearingsim's own archive is replaced now (a stale one, of another model version, as
    before); anything else is refused in one line naming it, before any case runs, the file and the folder's
    index as they were; removed by the user, the sweep resumes."""
    from bearingsim.errors import UserError

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000, 3000])])
    first = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    stale, mine = (tmp_path / "cases" / f"{r['case']}.h5" for r in first.rows[1:])
    _set_provenance(stale, model_version=None)  # bearingsim's, of a model version before versions were stored
    mine.unlink()
    if what == "text":
        mine.write_bytes(b"my notes")
    elif what == "hdf5":
        with h5py.File(mine, "w") as f:
            f["data"] = np.arange(3.0)
    else:
        (tmp_path / "elsewhere.h5").write_bytes(b"my notes")
        mine.symlink_to(tmp_path / "elsewhere.h5")
    held = mine.read_bytes()
    index = (tmp_path / "sweep.h5").read_bytes()
    kind = {"text": "a file, not bearingsim's (not an archive bearingsim wrote)",
            "hdf5": "a file, not bearingsim's (not an archive bearingsim wrote)",
            "link": "a symbolic link, not bearingsim's"}[what]
    with pytest.raises(UserError) as exc:
        run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert str(exc.value) == (f"{mine}: archive of the case {SPEED}=3000 of {tmp_path} is {kind}; not replaced "
                              f"(remove it)")
    assert mine.read_bytes() == held and mine.is_symlink() == (what == "link")
    assert (tmp_path / "sweep.h5").read_bytes() == index
    mine.unlink()
    again = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert [r["status"] for r in again.rows] == ["cached", "stale", "done"]
    assert (tmp_path / "elsewhere.h5").exists() == (what == "link")


def test_a_users_file_in_cases_is_not_another_sweeps_case(tmp_path):
    """A file of the user's in DIR/cases/ (notes.h5, not an archive named by a case's hash) was counted as a
    case of another sweep: the same sweep's resume was refused, and --force removed the file. Now it is
    neither; another sweep's archive there still refuses a sweep without --force and goes with it."""
    from bearingsim.errors import UserError

    first = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])])
    run_sweep(first, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    (tmp_path / "cases" / "notes.h5").write_bytes(b"mine")
    again = run_sweep(first, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert again.count("cached") == 2
    other = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 3000])])
    with pytest.raises(UserError, match="holds another sweep"):
        run_sweep(other, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    run_sweep(other, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all", force=True)
    assert (tmp_path / "cases" / "notes.h5").read_bytes() == b"mine"
    assert sorted(p.name for p in (tmp_path / "cases").iterdir()) == sorted(
        ["notes.h5"] + [str(a).split("/")[-1] for a in read_index(tmp_path / "sweep.h5")[0]["archive"]])


def test_a_users_hdf5_file_named_like_a_case_archive_is_no_case_and_force_keeps_it(tmp_path):
    """A user's HDF5 file in DIR/cases/ named as a case archive is (16 hex digits, not one of the sweep's cases)
    was counted as a case of another sweep: the same sweep's resume was refused, and --force removed the file.
    Only bearingsim's archives are other sweeps' cases: the resume takes its cases beside it, another sweep's
    archive still refuses a sweep without --force, and --force removes that archive and keeps the user's file."""
    from bearingsim.errors import UserError

    first = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])])
    run_sweep(first, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    mine = tmp_path / "cases" / "0123456789abcdef.h5"
    with h5py.File(mine, "w") as f:
        f["data"] = np.arange(3.0)
    held = mine.read_bytes()
    again = run_sweep(first, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert again.count("cached") == 2
    other = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 3000])])
    with pytest.raises(UserError, match=r"holds another sweep or study \(1 case of its 2 is not in this one\)"):
        run_sweep(other, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    run_sweep(other, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all", force=True)
    assert mine.read_bytes() == held
    assert sorted(p.name for p in (tmp_path / "cases").iterdir()) == sorted(
        [mine.name] + [str(a).split("/")[-1] for a in read_index(tmp_path / "sweep.h5")[0]["archive"]])


def test_a_sweep_refused_for_an_edited_scenario_file_names_the_keys_not_the_same_command(tmp_path):
    """The same command line run again after its scenario file was edited (every case's hash moved) was refused
    with '(the same command as before resumes it)': the command just run. The refusal now names the base
    scenario's keys that differ from the one the folder's index stores (old -> new)."""
    from bearingsim.errors import UserError

    scenario = tmp_path / "s.toml"
    scenario.write_text(BASE.read_text())
    spec = SweepSpec(scenario=scenario, axes=[(SPEED, [1000, 2000])])
    run_sweep(spec, tmp_path / "out", engine=LocalEngine(1), figures=False, progress=False)
    scenario.write_text(BASE.read_text().replace("radial_load_N = 970", "radial_load_N = 900"))
    with pytest.raises(UserError) as err:
        run_sweep(spec, tmp_path / "out", engine=LocalEngine(1), figures=False, progress=False)
    text = str(err.value)
    assert "holds another sweep" in text and "operating.radial_load_N 970.0 -> 900.0" in text, text
    assert "the same command as before resumes it" not in text, text
    # another sweep of the same base scenario keeps the old hint
    with pytest.raises(UserError, match=r"\(the same command as before resumes it\)"):
        run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, [3000])]), tmp_path / "out", engine=LocalEngine(1),
                  figures=False, progress=False)


def test_temporary_files_a_killed_sweep_left_are_removed_by_the_next(tmp_path):
    """A sweep killed by SIGKILL while it wrote its index leaves '.sweep.h5.tmp-<pid>' (seen after
    'kill -9' of the 100 x 100 map): the next sweep into the folder, which removed its workers' ones in
    cases/, left it for ever. Now it goes (and the CSV's); a live writer's and another program's stay."""
    from .test_reliability import _dead_pid

    dead = _dead_pid()
    (tmp_path / f".sweep.h5.tmp-{dead}").write_bytes(b"\x89HDF\r\n\x1a\n half an index")
    (tmp_path / f".sweep.csv.tmp-{dead}").write_bytes(b"case,operating")
    kept = {f".sweep.h5.tmp-{os.getppid()}": b"\x89HDF\r\n\x1a\n a live writer's",
            f".notes.txt.tmp-{dead}": b"mine", f".map.h5.tmp-{dead}": b"not HDF5"}
    for name, data in kept.items():
        (tmp_path / name).write_bytes(data)
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])])
    run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert {p.name for p in tmp_path.iterdir() if ".tmp-" in p.name} == set(kept)


def test_an_interrupted_sweep_run_again_with_fewer_values_is_not_refused_for_cases_it_never_ran(tmp_path):
    """A sweep interrupted before some cases ran leaves them 'pending' in its index (set here as SIGINT
    leaves them); the same sweep with those values dropped was refused ('holds another sweep or study (2 of
    its 4 cases are not in this one)') though they left no result, as a failed case, exempt, leaves none."""
    from bearingsim.errors import UserError

    run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000, 3000, 4000])]), tmp_path, engine=LocalEngine(1),
              figures=False, progress=False)
    with h5py.File(tmp_path / "sweep.h5", "r+") as f:
        status = f["index/status"][()]
        status[2:] = "pending"
        f["index/status"][...] = status
    out = run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])]), tmp_path, engine=LocalEngine(1),
                    figures=False, progress=False)
    assert [r["status"] for r in out.rows] == ["cached", "cached"]
    with pytest.raises(UserError, match="holds another sweep"):  # a case with a result still refuses
        run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, [1000])]), tmp_path, engine=LocalEngine(1),
                  figures=False, progress=False)


@pytest.mark.parametrize("reaped_first", [False, True], ids=["seen-alive", "reaped-before-seen"])
def test_a_pool_worker_that_dies_mid_batch_fails_its_cases_and_the_sweep_ends(tmp_path, monkeypatch, reaped_first):
    """A local worker killed while it runs a batch (SIGKILL: by hand, the out-of-memory killer): the pool
    starts another worker but never says the batch was lost, and the sweep waited for it for ever. Now its
    cases fail, saying so, and the sweep ends (the same command runs them again). ``reaped-before-seen``: the
    sweep process first looks for dead workers only once the pool has reaped and replaced the killed one (a
    loaded machine's scheduling: the worker runs its first batch and dies on the second while the sweep
    process waits for the CPU); its status went with the pool's record of it, and the case said the worker
    ended "(gone)"."""
    import threading

    from bearingsim.sweeps import worker

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])])
    doomed = resolve_cases(spec)[1].hash
    real = worker.run_case

    def run_case(h, *args):  # in the forked worker: the doomed case kills it
        if h == doomed:
            os.kill(os.getpid(), signal.SIGKILL)
        return real(h, *args)

    monkeypatch.setattr(worker, "run_case", run_case)
    engine, out = LocalEngine(1), {}
    if reaped_first:
        engine.start(1)  # run_sweep keeps this pool
        (first,) = engine._pool._pool
        look = engine._lost_batches

        def look_once_the_pool_has_replaced_it(*args):
            deadline = time.monotonic() + 60  # a guard only: the worker dies about a second in
            while any(p is first for p in engine._pool._pool) and time.monotonic() < deadline:
                time.sleep(0.01)
            monkeypatch.setattr(engine, "_lost_batches", look)
            return look(*args)

        monkeypatch.setattr(engine, "_lost_batches", look_once_the_pool_has_replaced_it)
    thread = threading.Thread(target=lambda: out.update(sweep=run_sweep(spec, tmp_path, engine=engine, figures=False,
                                                                        progress=False)), daemon=True)
    thread.start()
    thread.join(120)  # a guard only: the sweep ends in about a second
    if thread.is_alive():
        engine.stop()
        pytest.fail("the sweep waited for ever for the batch of its dead worker")
    rows = out["sweep"].rows
    assert [r["status"] for r in rows] == ["done", "failed"], rows
    assert "the worker process running it ended (signal 9)" in rows[1]["error"]


@pytest.mark.slow  # sweeps and their figures (~1.5 s)
def test_figure_kind_follows_the_grid(tmp_path):
    from bearingsim.sweeps.index import write_index

    def rows(grid):
        out = []
        for i, values in enumerate(grid):
            failed = i == 1  # a failed case: a gap, not a zero
            out.append({"case": f"c{i}", "values": values, "status": "failed" if failed else "done", "error": "",
                        "archive": "", "wall_s": 0.1,
                        "summary": {} if failed else {"I_dec_mean_Ns": 0.005 + 0.001 * i, "I_dec_sem_Ns": 1e-4}})
        return out

    two = [{SPEED: s, "bearing.pocket_clearance_mm": c} for s in (1000, 2000) for c in (0.1, 0.2)]
    write_index(tmp_path, rows(two), list(two[0]), {"mode": "product", "grid": f'["{SPEED}", "bearing.pocket_clearance_mm"]',
                                                   "grid_rows": 4, "scenario": "x.toml"})
    assert [p.name for p in plot_sweep_index(tmp_path / "sweep.h5", tmp_path / "a")] == ["sweep_map.png"]
    text = [{SPEED: s, "operating.direction": d} for s in (1000, 2000) for d in ("forward", "reverse")]
    write_index(tmp_path, rows(text), list(text[0]), {"mode": "product", "grid": f'["{SPEED}", "operating.direction"]',
                                                     "grid_rows": 4, "scenario": "x.toml"})
    assert [p.name for p in plot_sweep_index(tmp_path / "sweep.h5", tmp_path / "b")] == ["sweep_I.png"]
    cols, meta = read_index(tmp_path / "sweep.h5")
    assert list(cols["operating.direction"]) == ["forward", "reverse"] * 2
    assert math.isnan(cols["I_dec_mean_Ns"][1]) and cols["I_dec_mean_Ns"][2] == pytest.approx(0.007)


def test_scheduler_without_dask_names_the_extra(tmp_path, monkeypatch, capsys):
    """Issue 29, item 4: dask is the optional extra ``cluster``; a command that needs it when it is
    missing says so in one line naming the extra (exit 2), not a traceback or another package name."""
    from bearingsim import cli

    monkeypatch.setitem(sys.modules, "distributed", None)  # `import distributed` raises ImportError
    code = cli.main(["sweep", str(BASE), "--param", f"{SPEED}=1000,2000", "--scheduler", "tcp://127.0.0.1:9",
                     "-o", str(tmp_path / "sw"), "--no-plots"])
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert code == 2 and len(err) == 1 and "pip install 'bearingsim[cluster]'" in err[0], (code, err)


@pytest.mark.slow
def test_stop_ends_a_pool_whose_result_queue_lock_is_held(monkeypatch):
    """A worker ended while it held the pool's result-queue lock leaves that lock taken, and
    ``Pool.terminate`` then waits forever (seen: a refused sweep whose warm-up tasks were finishing).
    Here the lock is taken as such a worker would leave it: ``stop()`` still returns, after
    ``STOP_WAIT_S``, with every worker process ended and reaped."""
    import threading

    import psutil

    from bearingsim.sweeps import engines

    monkeypatch.setattr(engines, "STOP_WAIT_S", 1.0)
    before = {p.pid for p in psutil.Process().children(recursive=True)}
    engine = LocalEngine(2)
    engine.start()
    workers = list(engine._pool._pool)
    assert engine._pool._outqueue._wlock.acquire(timeout=5)  # held for good, as by a killed worker
    stopper = threading.Thread(target=engine.stop, daemon=True)
    stopper.start()
    stopper.join(30.0)  # before the fallback: Pool.terminate never returned
    assert not stopper.is_alive()
    assert all(p.exitcode is not None for p in workers)
    assert {p.pid for p in psutil.Process().children(recursive=True)} - before == set()


def _worker_signals() -> tuple:
    """In a pool worker: (its parent-death signal, its SIGTERM handler's name, the stop signals it blocks,
    whether it ignores SIGINT and SIGHUP)."""
    import ctypes

    sig = ctypes.c_int(0)
    ctypes.CDLL(None, use_errno=True).prctl(2, ctypes.byref(sig))  # PR_GET_PDEATHSIG
    handler = signal.getsignal(signal.SIGTERM)
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, set()) & {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
    ignored = all(signal.getsignal(s) == signal.SIG_IGN for s in (signal.SIGINT, signal.SIGHUP))
    return sig.value, getattr(handler, "__name__", str(handler)), sorted(int(s) for s in blocked), ignored


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG and /proc are Linux's")
def test_a_worker_ended_by_sigterm_while_it_waits_for_a_task_leaves_the_pool_usable():
    """SIGTERM to the process group (a batch system's, `timeout`'s) reaches the workers too. A worker waits for
    its next task holding the pool's task-queue lock; ended there by the default action (or by the SIGKILL
    that a worker forked by the pool's maintenance thread got as its parent-death signal when that thread
    ended), it left the lock taken: the worker the pool started in its place waited for it for ever, and
    terminate too (a life study took 11 s to stop after SIGTERM, once it hung). A worker's SIGTERM now
    raises an exception that releases the lock and ends it with status 143, its parent-death signal is
    SIGTERM, and a worker gets the stop signals only once its handlers are in (unblocked by its initializer)."""
    import os

    engine = LocalEngine(1)
    engine.start(1)
    try:
        pool = engine._pool
        # SIGINT and SIGHUP (Ctrl-C, a terminal's hang-up) reach the whole process group: the sweep process acts
        # on them and ends the pool, so the workers ignore them
        assert pool.apply_async(_worker_signals).get(timeout=60) == (int(signal.SIGTERM), "_exit_worker", [], True)
        (first,) = pool._pool
        time.sleep(0.2)  # idle: waiting for its next task, holding the task queue's lock
        os.kill(first.pid, signal.SIGTERM)
        first.join(30)
        deadline = time.monotonic() + 30  # the pool's worker handler reaps it too: its status can lag the join
        while first.exitcode is None and time.monotonic() < deadline:
            time.sleep(0.01)
        assert first.exitcode == 143
        # the worker the pool starts in its place (forked by its maintenance thread) takes the next task
        # SIGINT and SIGHUP (Ctrl-C, a terminal's hang-up) reach the whole process group: the sweep process acts
        # on them and ends the pool, so the workers ignore them
        assert pool.apply_async(_worker_signals).get(timeout=60) == (int(signal.SIGTERM), "_exit_worker", [], True)
        assert all(p.pid != first.pid for p in pool._pool)
    finally:
        engine.stop()


def test_a_worker_that_is_ending_says_nothing_of_objects_its_stop_left_half_made(monkeypatch, capsys):
    """The exception that ends a worker on SIGTERM is raised wherever the worker was: an object it was making
    (llvmlite's OutputString, while the reduced model's warm-up compiled) was left half made, and its
    ``__del__`` printed "Exception ignored ... AttributeError" on the sweep's stderr (a stranger-machine CI run
    of the reliability case sweep-unknown-key, whose refused sweep ends its warming workers). Once a worker
    is ending its unraisable exceptions are dropped; before, they are printed as Python prints them."""
    from types import SimpleNamespace

    from bearingsim.sweeps import engines

    def unraisable():
        try:
            raise AttributeError("'OutputString' object has no attribute '_ptr'")
        except AttributeError as exc:
            return SimpleNamespace(exc_type=AttributeError, exc_value=exc, exc_traceback=exc.__traceback__,
                                   err_msg="Exception ignored in", object=None)

    from bearingsim.sweeps import worker

    printed = []
    monkeypatch.setattr(worker, "ending", False)
    engines._stop_again(unraisable(), previous=printed.append)
    assert len(printed) == 1
    monkeypatch.setattr(worker, "ending", True)
    engines._stop_again(unraisable(), previous=printed.append)
    assert len(printed) == 1
    with pytest.raises(SystemExit):
        engines._exit_worker(signal.SIGTERM, None)


def test_a_case_that_fails_while_its_worker_is_ending_ends_the_worker_and_is_not_recorded(monkeypatch):
    """The stop's exception is raised wherever a worker is, and numba's compiled code, calling back into Python
    when it lands, turns it into "SystemError: CPUDispatcher(...) returned a result with an exception set": the
    case was recorded as failed and the worker went on to wait for a task, so the sweep waited STOP_WAIT_S for
    it (Ctrl-C on a 10 000-case sweep took 11-13 s in 3 of 6 tries). Once the worker is ending, a case's
    exception ends it (exit status 143, as SIGTERM's own); before, a failing case is recorded as ever."""
    from bearingsim.sweeps import worker

    monkeypatch.setattr(worker, "ending", False)
    rec = worker.run_case("0" * 16, "this is not a scenario", None)
    assert rec["status"] == "failed" and rec["error"]
    monkeypatch.setattr(worker, "ending", True)
    with pytest.raises(worker.WorkerStop) as stop:
        worker.run_case("0" * 16, "this is not a scenario", None)
    assert stop.value.code == 128 + signal.SIGTERM


def test_a_case_run_for_a_dask_sweep_records_the_sweeps_command(tmp_path, monkeypatch):
    """A case run on a dask worker stored the worker's command line (``dask worker tcp://...``) in its
    archive's provenance, where a local pool's case stores the sweep's: the sweep's command goes with
    the batch (:func:`bearingsim.sweeps.worker.run_batch` as the dask engine calls it: no shared folder,
    the archive back as bytes)."""
    import bearingsim
    from bearingsim.sweeps import worker

    monkeypatch.setattr(sys, "argv", ["/usr/bin/dask", "worker", "tcp://127.0.0.1:8786"])
    (case,) = resolve_cases(SweepSpec(scenario=BASE, axes=[(SPEED, [1000.0])]))
    command = "bearingsim sweep scenarios/paper_3000rpm.toml --param 'operating.inner_ring_speed_rpm=1000'"
    (rec,) = worker.run_batch([(case.hash, case.toml)], None, "all", command)
    (tmp_path / "case.h5").write_bytes(rec["archive"])
    assert bearingsim.load(tmp_path / "case.h5").provenance["command"] == command


def test_an_interrupted_batch_indexes_the_cases_it_finished(tmp_path, monkeypatch):
    """A batch (up to 200 reduced cases) returns its records when all its cases have run: a sweep interrupted
    while one ran left the rows of the cases it had finished 'pending' and counted them "not run", though
    their archives were in cases/. They are indexed from their archives (the resume's check), with the numbers
    the case's own record would have given. The signal comes from the pool's worker (forked with the patched
    run_case) as soon as it has finished the batch's second case; the worker then waits to be ended."""
    import bearingsim.sweeps.run as run_module
    from bearingsim.sweeps import worker

    finish = worker.run_case
    speeds = [1000.0, 2000.0, 3000.0, 4000.0]
    second = resolve_cases(SweepSpec(scenario=BASE, axes=[(SPEED, speeds)]))[1].hash

    def run_case_then_signal(h, *args, **kwargs):
        rec = finish(h, *args, **kwargs)
        if h == second:
            os.kill(os.getppid(), signal.SIGINT)
            time.sleep(120)  # ended by the sweep's stop (SIGTERM) long before
        return rec

    monkeypatch.setattr(worker, "run_case", run_case_then_signal)
    monkeypatch.setattr(run_module, "make_batches", lambda cases, workers: [[run_module._item(c) for c in cases]])
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, speeds)])
    out = run_sweep(spec, tmp_path / "s", engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert out.interrupted == signal.SIGINT
    assert [r["status"] for r in out.rows] == ["done", "done", "pending", "pending"]
    cols, _ = read_index(tmp_path / "s" / "sweep.h5")
    assert [str(x) for x in cols["status"]] == ["done", "done", "pending", "pending"]
    assert sorted(p.name for p in (tmp_path / "s" / "cases").iterdir()) == sorted(
        f"{r['case']}.h5" for r in out.rows[:2])
    monkeypatch.undo()  # the workers of the next sweep, forked, run the cases as they are
    whole = run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, speeds[:2])]), tmp_path / "w", figures=False,
                      progress=False, archives="all")  # the same two cases, not interrupted
    for cut, ran in zip(out.rows[:2], whole.rows):
        assert cut["archive"] == ran["archive"] and cut["notes"] == ran["notes"] and cut["wall_s"] > 0
        assert cut["summary"].keys() == ran["summary"].keys()
        assert all(np.array_equal(cut["summary"][k], ran["summary"][k], equal_nan=True) for k in cut["summary"])


def test_a_signal_while_the_sweep_writes_its_index_lets_it_finish_and_is_reported(tmp_path, monkeypatch):
    """A signal that landed while a sweep ended its workers or wrote its index and map (the clean-up after the
    cases) raised out of it: `bearingsim sweep` exited 1 with a traceback (1 of 6 SIGINTs of
    benchmarks.interrupt_bench). The clean-up finishes, the index holds every case, and the sweep reports
    the signal as an interruption."""
    import bearingsim.sweeps.run as run_module

    clean = run_module._clean_temporaries
    calls = []

    def clean_then_signal(cases_dir):  # the second call is the clean-up's: the signal lands there
        calls.append(cases_dir)
        if len(calls) == 2:
            os.kill(os.getpid(), signal.SIGINT)
        clean(cases_dir)

    monkeypatch.setattr(run_module, "_clean_temporaries", clean_then_signal)
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000.0, 2000.0])])
    out = run_sweep(spec, tmp_path / "s", engine=LocalEngine(1), figures=False, progress=False)
    assert len(calls) == 2 and out.interrupted == signal.SIGINT
    cols, _ = read_index(tmp_path / "s" / "sweep.h5")
    assert [str(x) for x in cols["status"]] == ["done", "done"]  # the index written to its end
    assert (tmp_path / "s" / "map.h5").is_file()


def _signal_here():
    """SIGINT to this process, returning only if its handler did not raise (it raises at a call, below)."""
    os.kill(os.getpid(), signal.SIGINT)
    for _ in range(1000):
        time.sleep(0.01)


def test_a_signal_as_the_sweep_enters_its_clean_up_is_an_interruption_not_a_traceback(tmp_path, monkeypatch):
    """SIGINT landing on the call that enters the sweep's clean-up hold (a function call is where Python runs a
    handler; `timeout -s INT 1.3 bearingsim sweep ...` resuming 1000 cached cases) raised SweepInterrupted out of
    the sweep: a traceback and exit 1. It is an interruption: the index written, the signal reported."""
    import bearingsim.sweeps.run as run_module

    for name in ("hold", "held"):  # the call that enters the hold (held: as it was before hold)
        original = getattr(run_module._Signals, name, None)
        if original is None:
            continue

        def entering(self, *args, _original=original, **kw):
            if self.fired is None:
                _signal_here()
            return _original(self, *args, **kw)

        monkeypatch.setattr(run_module._Signals, name, entering)
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000.0, 2000.0])])
    out = run_sweep(spec, tmp_path / "s", engine=LocalEngine(1), figures=False, progress=False)
    assert out.interrupted == signal.SIGINT
    cols, _ = read_index(tmp_path / "s" / "sweep.h5")
    assert [str(x) for x in cols["status"]] == ["done", "done"]


def test_a_resume_cut_short_leaves_the_folders_index_as_it_was(tmp_path, monkeypatch):
    """A resume cut short rewrote the index with the rows it had not reached yet 'pending': SIGINT during the
    resume of a finished 1000-case sweep (no archives) left 349 of them to be run again, and a folder at one case
    archive's name (an error of the resume) 7 of 12. The folder's index is left as it was: a signal ends the
    sweep as one while it starts (KeyboardInterrupt here), an error is said as before."""
    import bearingsim.sweeps.index as index_module
    from bearingsim.errors import UserError

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000.0, 2000.0, 3000.0, 4000.0])])
    run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    before = (tmp_path / "sweep.h5").read_bytes()
    trusted = index_module.trusted_row
    calls = []

    def signalled(*args, **kw):
        calls.append(1)
        if len(calls) == 2:
            _signal_here()
        return trusted(*args, **kw)

    monkeypatch.setattr(index_module, "trusted_row", signalled)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal user's Python has it
    try:
        with pytest.raises(KeyboardInterrupt):
            run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert len(calls) == 2 and (tmp_path / "sweep.h5").read_bytes() == before
    monkeypatch.setattr(index_module, "trusted_row", trusted)
    third = resolve_cases(spec)[2].hash
    (tmp_path / "cases" / f"{third}.h5").mkdir(parents=True)  # the resume cannot remove it
    with pytest.raises(UserError, match="is a folder, not bearingsim's"):  # where the case is to keep its archive
        run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False, archives="all")
    assert (tmp_path / "sweep.h5").read_bytes() == before
    (tmp_path / "cases" / f"{third}.h5").rmdir()
    out = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert [r["status"] for r in out.rows] == ["cached"] * 4


def test_a_folder_at_a_case_archives_path_is_refused_naming_it(tmp_path):
    """A folder at a case archive's path `DIR/cases/<hash>.h5` (in a new folder, or in place of a finished case's
    archive) was said as "DIR/cases/<hash>.h5: Is a directory". It is refused as the folder at the lock file's
    path is: one line naming the file and what is in the way, exit 2, before any case runs, the folder's index
    as it was and the folder kept. A case that keeps no archive (a reduced one by default) runs beside it."""
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000.0, 2000.0])])
    second = resolve_cases(spec)[1].hash
    args = ["sweep", BASE, "--param", f"{SPEED}=1000,2000", "-j", "1", "--no-plots"]
    blocker = tmp_path / "new" / "cases" / f"{second}.h5"
    blocker.mkdir(parents=True)
    res = bearingsim(*args, "--archives", "all", "-o", tmp_path / "new")
    assert_user_error(res, f"{blocker}: archive of the case {SPEED}=2000 of {tmp_path / 'new'} is a folder, not "
                           f"bearingsim's; not replaced (remove it)")
    assert blocker.is_dir() and not (tmp_path / "new" / "sweep.h5").exists()
    res = bearingsim(*args, "-o", tmp_path / "new")  # reduced cases keep no archive: not in their way
    assert res.returncode == 0 and blocker.is_dir(), res.stderr
    assert bearingsim(*args, "--archives", "all", "-o", tmp_path / "done").returncode == 0
    before = (tmp_path / "done" / "sweep.h5").read_bytes()
    blocker = tmp_path / "done" / "cases" / f"{second}.h5"  # a finished sweep's archive replaced by a folder
    blocker.unlink()
    blocker.mkdir()
    res = bearingsim(*args, "--archives", "all", "-o", tmp_path / "done")
    assert_user_error(res, f"{blocker}: archive of the case {SPEED}=2000 of {tmp_path / 'done'} is a folder")
    assert (tmp_path / "done" / "sweep.h5").read_bytes() == before and blocker.is_dir()


@pytest.mark.parametrize("model", ["reduced", "multibody"])
@pytest.mark.parametrize("blocker", ["file at cases", "folder at the archive"])
def test_a_case_whose_archive_cannot_be_written_records_a_sentence_naming_the_path(tmp_path, monkeypatch, model,
                                                                                  blocker):
    """`DIR/cases/` replaced by a file while a sweep ran: a multibody case streaming its archive recorded
    "NotADirectoryError: [Errno 20] Not a directory: 'DIR/cases/.<hash>.h5.tmp-<pid>'" as its failure (the
    temporary file's removal failed over the write's own error), a reduced one "cannot write archive (Not a
    directory)". Both record one sentence naming the archive and what is in the way; so does a folder made at
    the archive's name meanwhile ("Is a directory")."""
    from bearingsim import simulation
    from bearingsim.sweeps import worker

    sc = load_scenario(SCENARIOS / ("paper_3000rpm.toml" if model == "reduced" else "multibody_6000rpm.toml"),
                       ["numerics.rotations=1"])
    cases = tmp_path / "cases"
    cases.mkdir()
    target = cases / "0123456789abcdef.h5"
    run = simulation.run

    def run_then_block(*args, **kw):  # while the case runs (a multibody case's archive is open in cases/)
        result = run(*args, **kw)
        if blocker == "file at cases":
            for p in cases.iterdir():
                p.unlink()
            cases.rmdir()
            cases.write_text("")
        else:
            target.mkdir()
        return result

    monkeypatch.setattr(simulation, "run", run_then_block)
    rec = worker.run_case("0123456789abcdef", sc.to_toml(), target, None, "all")
    what = (f"its folder {cases} is a file now, not a folder" if blocker == "file at cases" else
            "a folder is in the way there, not bearingsim's: remove it")
    assert rec["status"] == "failed", rec
    assert rec["error"] == f"{target}: cannot write archive ({what}); nothing was written", rec["error"]
    assert (cases.is_file() if blocker == "file at cases" else [p.name for p in cases.iterdir()] == [target.name])


def test_an_index_whose_columns_differ_in_length_is_refused_in_one_line(tmp_path):
    """A sweep.h5 one of whose columns had fewer rows (cut by hand) made the sweep's resume fail with IndexError's
    traceback, after it had rewritten the index all 'pending'. It is a damaged index: refused, not replaced."""
    from bearingsim.errors import UserError

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000.0, 2000.0, 3000.0])])
    run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    with h5py.File(tmp_path / "sweep.h5", "r+") as f:
        status = f["index/status"][()]
        del f["index/status"]
        f.create_dataset("index/status", data=status[:2], dtype=h5py.string_dtype())
    before = (tmp_path / "sweep.h5").read_bytes()
    with pytest.raises(UserError, match=r"damaged sweep index \(its columns are not all of one length: status 2\)"):
        run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert (tmp_path / "sweep.h5").read_bytes() == before
    with pytest.raises(UserError, match="not all of one length"):
        read_index(tmp_path / "sweep.h5")


def test_a_worker_told_to_end_takes_no_further_case_and_waits_for_no_further_batch(monkeypatch):
    """A worker's SIGTERM whose exception was swallowed where it landed (a callback of compiled code) leaves
    the worker running its case; it then took the batch's next case, and waited for the next batch, until
    the sweep killed it after STOP_WAIT_S (a cross-check stopped by SIGTERM took 10.1 s once). A worker that is
    ending finishes the case it is in and ends (WorkerStop, exit status 143)."""
    from bearingsim.sweeps import worker

    ran = []

    def case(h, *args):  # the stop comes while the first case runs
        ran.append(h)
        worker.ending = True
        return {"hash": h, "status": "done"}

    monkeypatch.setattr(worker, "ending", False)
    monkeypatch.setattr(worker, "run_case", case)
    with pytest.raises(worker.WorkerStop) as stop:
        worker.run_batch([("a", "x"), ("b", "x")])
    assert ran == ["a"] and stop.value.code == 128 + signal.SIGTERM
    ran.clear()
    worker.ending = False  # (monkeypatch restores it)
    with pytest.raises(worker.WorkerStop):  # a one-case batch: no wait for the next one
        worker.run_batch([("c", "x")])
    assert ran == ["c"]
    with pytest.raises(worker.WorkerStop):  # already ending: no case at all
        worker.run_batch([("d", "x")])
    assert ran == ["c"]


def test_stop_returns_once_every_worker_has_exited_though_the_pool_still_waits(monkeypatch):
    """Pool.terminate drains the task pipe once; a task handler half-way through sending a batch larger than
    the pipe then fills it again, no worker reads it, and terminate waits for the handler for ever: stop()
    waited STOP_WAIT_S, then killed. Here the pool's terminate ends the workers (SIGTERM, as Pool.terminate
    sends it) and then waits for ever; stop() returns as soon as every worker has exited (STOP_WAIT_S set far
    beyond the test's own wait, so the kill after it cannot be what ends the wait). The pool is a stand-in
    with the parts stop() uses: a real pool's internals would be left stuck by the test."""
    import multiprocessing
    import threading

    from bearingsim.sweeps import engines

    monkeypatch.setattr(engines, "STOP_WAIT_S", 3600.0)
    release = threading.Event()
    ctx = multiprocessing.get_context("fork")
    workers = [ctx.Process(target=time.sleep, args=(600,), daemon=True) for _ in range(2)]
    for p in workers:
        p.start()

    class StuckPool:  # what LocalEngine.stop uses of multiprocessing.pool.Pool
        _pool = workers

        def terminate(self):
            for p in workers:
                p.terminate()
            release.wait()  # then the task handler's join, which never returns

        def join(self):
            pass

    engine = LocalEngine(2)
    engine._pool = StuckPool()
    stopper = threading.Thread(target=engine.stop, daemon=True)
    stopper.start()
    try:
        stopper.join(120)
        assert not stopper.is_alive(), "stop() waited for the pool although every worker had exited"
        assert [p.exitcode for p in workers] == [-signal.SIGTERM] * 2  # ended by the pool's SIGTERM, not killed
    finally:
        release.set()
        for p in workers:
            p.kill()
            p.join(30)


@pytest.mark.slow
@pytest.mark.parametrize("stage", ["figures", "table"])
def test_a_signal_after_the_cases_says_they_are_indexed(tmp_path, monkeypatch, capsys, stage):
    """SIGINT while a finished sweep draws its figures or prints its table said "interrupted, no archive
    written", though every case had run and the index was written: exit 130 and one line naming the
    index and what draws or prints the rest."""
    from bearingsim import cli, tables
    from bearingsim.sweeps import plot

    def signalled(*args, **kw):
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(1000):  # the handler raises here
            time.sleep(0.01)
        raise AssertionError("signal not delivered")

    monkeypatch.setattr(plot, "plot_sweep_index", signalled) if stage == "figures" else \
        monkeypatch.setattr(tables, "format_table", signalled)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal user's Python has it
    try:
        code = cli.main(["sweep", str(BASE), "--param", f"{SPEED}=1000,2000", "-j", "1", "-o", str(tmp_path)])
    finally:
        signal.signal(signal.SIGINT, previous)
    assert code == 130
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(err) == 1 and "no archive written" not in err[0], err
    assert err[0].startswith("bearingsim: sweep interrupted (SIGINT): 2 cases indexed in "
                             f"{tmp_path / 'sweep.h5'}, "), err
    assert ("'bearingsim plot" if stage == "figures" else "'bearingsim table") in err[0]
    assert [r["status"] for r in _rows(tmp_path)] == ["done", "done"]


@pytest.mark.parametrize("stage", ["lock", "outcome", "study"])
def test_a_signal_once_the_cases_are_indexed_does_not_say_none_ran(tmp_path, monkeypatch, capsys, stage):
    """SIGINT after a sweep's cases ran and its index was written, before the command returned (its folder's
    lock released, the command reading the outcome; a study's tables written), said "interrupted, before any
    case of the sweep ran" (seen once, no data lost). It names the index written and the files complete."""
    from bearingsim import cli, cli_common, outputs
    from bearingsim.sweeps import run as run_module

    def signalled(function, before=True):
        def wrapper(*args, **kw):
            if not before:
                function(*args, **kw)
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(1000):  # the handler raises here
                time.sleep(0.01)
            raise AssertionError("signal not delivered")
        return wrapper

    if stage == "lock":  # run_sweep, the index written and the lock released, before it returns
        monkeypatch.setattr(outputs.FolderLock, "release", signalled(outputs.FolderLock.release, before=False))
    elif stage == "outcome":  # bearingsim sweep, as it reads the outcome run_sweep returned
        monkeypatch.setattr(run_module.SweepOutcome, "counts", signalled(run_module.SweepOutcome.counts))
    else:  # bearingsim sensitivity, its tables written, as it says how the study ended
        monkeypatch.setattr(cli_common, "report_study", signalled(cli_common.report_study))
    args = (["sweep", str(BASE), "--param", f"{SPEED}=1000,2000", "--no-plots"] if stage != "study" else
            ["sensitivity", str(BASE), "--keys", "contact.restitution", "-q"])
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal user's Python has it
    try:
        code = cli.main([*args, "-j", "1", "-o", str(tmp_path)])
    finally:
        signal.signal(signal.SIGINT, previous)
    assert code == 130
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    command = args[0]
    also = ", and map.h5 is complete" if stage != "study" else \
        ", and sensitivity.csv, sensitivity.h5, sensitivity.png are complete"
    assert err == [f"bearingsim: {command} interrupted (SIGINT): its case index {tmp_path / 'sweep.h5'} is written, "
                   f"with every case that ran ('bearingsim table {tmp_path / 'sweep.h5'}' prints them){also}; run "
                   f"the same command again to resume"], err
    assert all(r["status"] == "done" for r in _rows(tmp_path))


@pytest.mark.parametrize("table, got", [("{ start = 0.1, num = 3 }", "start, num"),
                                        ("{ start = 0.1, stop = 0.3, nums = 3 }", "start, stop, nums")])
def test_a_range_with_a_key_missing_or_misspelt_names_its_axis(tmp_path, table, got):
    """A sweep file's `{ start, stop, num }` with a key missing or misspelt was read as a nested table and
    refused as "axes: bearing.pocket_clearance_mm.start: must be a non-empty list ...", a key that does not
    exist; it names the axis and the range's keys."""
    from bearingsim.errors import UserError

    f = tmp_path / "s.toml"
    f.write_text(f'scenario = "{BASE}"\n[axes]\n"bearing.pocket_clearance_mm" = {table}\n')
    with pytest.raises(UserError) as err:
        load_sweep_file(f)
    assert str(err.value) == (f"{f}: axes: bearing.pocket_clearance_mm: {{ start, stop, num }} needs exactly these "
                              f"three keys (got {got})")


def test_a_range_of_one_value_between_two_ends_is_refused_and_one_at_one_end_runs(tmp_path):
    """"both ends included" cannot hold for num = 1 with start != stop: it gave the start alone, dropping
    the stop without a word (1000:6000:1 ran 1000 rpm only). It is refused, in a sweep file and on the
    command line, naming both ends; start = stop with num = 1 is the one value."""
    from bearingsim.errors import UserError
    from bearingsim.sweeps.spec import parse_param

    with pytest.raises(UserError, match=r"num = 1 is one value, and start 1000 and stop 6000 differ"):
        parse_param("operating.inner_ring_speed_rpm=1000:6000:1")
    assert parse_param("operating.inner_ring_speed_rpm=1000:1000:1") == ("operating.inner_ring_speed_rpm", [1000.0])
    assert parse_param("operating.inner_ring_speed_rpm=1000:6000:2")[1] == [1000.0, 6000.0]
    f = tmp_path / "s.toml"
    f.write_text(f'scenario = "{BASE}"\n[axes]\n"bearing.pocket_clearance_mm" = {{ start = 0.1, stop = 0.3, num = 1 }}\n')
    with pytest.raises(UserError, match=r"bearing.pocket_clearance_mm: num = 1 is one value, and start 0.1 and stop 0.3"):
        load_sweep_file(f)


def test_evenly_spaced_values_of_an_integer_key_are_ints(tmp_path):
    """START:STOP:NUM and { start, stop, num } gave floats for any key, and an integer key refuses 10.0
    ('bearing.roller_count: must be a valid integer (got 10.0)'): values that are whole numbers are ints
    for a key the schema types as an integer, so the sweep resolves; a float key keeps floats."""
    from bearingsim.sweeps.spec import parse_param, spec_from_args

    for item, values in (("bearing.roller_count=10:20:3", [10, 15, 20]), ("numerics.rotations=1:3:3", [1, 2, 3]),
                         ("multibody.pocket_face_segments=0:0:1", [0])):
        got = parse_param(item)[1]
        assert got == values and all(type(v) is int for v in got), (item, got)
    assert parse_param("bearing.pocket_clearance_mm=0.1:0.3:3")[1] == [0.1, 0.2, 0.3]
    assert all(type(v) is float for v in parse_param(f"{SPEED}=1000:6000:2")[1])
    f = tmp_path / "s.toml"
    f.write_text(f'scenario = "{BASE}"\n[set]\n"reduced.load_zone_half_angle_deg" = "auto"\n'
                 '[axes]\n"bearing.roller_count" = { start = 10, stop = 20, num = 3 }\n')
    cases = resolve_cases(load_sweep_file(f))
    assert [scenario_from_toml(c.toml).bearing.roller_count for c in cases] == [10, 15, 20]
    cases = resolve_cases(spec_from_args(BASE, ["numerics.rotations=1:3:3"], []))
    assert [c.values for c in cases] == [{"numerics.rotations": n} for n in (1, 2, 3)]


def test_evenly_spaced_values_of_an_integer_key_that_are_not_whole_are_refused(tmp_path):
    """10:20:4 of an integer key is 10, 13.33, 16.67, 20: refused before any case runs, in one line naming
    the key and the axis and saying what to give instead (a list, or a NUM that lands on whole numbers);
    exit 2 and no output folder."""
    from bearingsim.errors import UserError

    res = bearingsim("sweep", BASE, "--param", "bearing.roller_count=10:20:4", "-o", tmp_path / "out")
    assert_user_error(res, "--param 'bearing.roller_count=10:20:4': bearing.roller_count is an integer, and "
                      "10:20:4 gives 13.33, 16.67, not whole numbers; give a list (bearing.roller_count=10,13,17,20) "
                      "or a NUM that lands on whole numbers (3 or 6)")
    assert not (tmp_path / "out").exists()
    f = tmp_path / "s.toml"
    f.write_text(f'scenario = "{BASE}"\n[axes]\n"numerics.rotations" = {{ start = 1.5, stop = 3, num = 4 }}\n')
    with pytest.raises(UserError) as err:
        load_sweep_file(f)
    assert str(err.value) == (f"{f}: axes: numerics.rotations: an integer, and {{ start = 1.5, stop = 3, num = 4 }} "
                              "gives 1.5, 2.5, not whole numbers; give a list ([2, 3]), or a whole start and stop")


def test_a_sweep_files_base_scenario_is_named_without_a_detour(monkeypatch):
    """A sweep file names its base scenario relative to itself ("../paper_3000rpm.toml"); the sweep's index
    showed it as "scenarios/sweeps/../paper_3000rpm.toml". It is the same file, named the short way."""
    from bearingsim.sweeps.spec import load_sweep_file

    monkeypatch.chdir(ROOT)
    spec = load_sweep_file(Path("scenarios/sweeps/map_speed_clearance.toml"))
    assert spec.scenario == Path("scenarios/paper_3000rpm.toml") and spec.scenario.is_file()


_WARMING_WORKER = """
import sys, time
from bearingsim.sweeps import engines, worker

def slow_load(*a, **kw):  # stands for numba loading the kernels: SIGTERM lands inside it
    try:
        print("warming", flush=True)
        time.sleep(60)
    finally:
        print("unwound", file=sys.stderr, flush=True)

worker._run_in_memory = slow_load
engines._pool_worker_init()
worker.warm_up(sys.argv[1])
"""


def test_a_worker_stopped_while_it_warms_up_ends_at_once_unwinding_nothing():
    """SIGTERM ends a sweep worker by an exception raised wherever it is, so that a running case leaves no
    temporary file; a worker still warming up (loading the compiled model while the sweep resolves its
    cases) holds nothing of the sweep's, and an exception raised inside numba's loading could leave its
    objects half made: a sweep refused at resolution wrote glibc's "free(): double free detected" from
    such a worker (seen twice in 12 runs of this file under load; not reproduced on demand). Such a
    worker now ends at once, exit 143, the code it was in not unwound (its `finally` does not run)."""
    toml = load_scenario(BASE).to_toml()
    with started([sys.executable, "-c", _WARMING_WORKER, toml], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                 text=True, env={**os.environ, "PYTHONPATH": _path()}) as proc:
        assert proc.stdout.readline() == "warming\n"
        os.kill(proc.pid, signal.SIGTERM)
        _, err = proc.communicate(timeout=300)  # a hang guard only
    assert proc.returncode == 143, err
    assert "unwound" not in err and "Traceback" not in err, err


def test_a_range_of_no_values_is_refused_in_the_form_given(tmp_path):
    """`--param KEY=500:6000:0` was refused as "{ start, stop, num } needs numbers and an integer num >= 1",
    the sweep file's form, not the one typed; each form's refusal names its own."""
    from bearingsim.errors import UserError
    from bearingsim.sweeps.spec import parse_param

    with pytest.raises(UserError) as err:
        parse_param("operating.inner_ring_speed_rpm=500:6000:0")
    assert str(err.value) == ("--param 'operating.inner_ring_speed_rpm=500:6000:0': START:STOP:NUM needs an "
                              "integer NUM >= 1")
    f = tmp_path / "s.toml"
    f.write_text(f'scenario = "{BASE}"\n[axes]\n'
                 '"bearing.pocket_clearance_mm" = { start = 0.1, stop = 0.3, num = 0 }\n')
    with pytest.raises(UserError, match=r"clearance_mm: \{ start, stop, num \} needs numbers and an integer num"):
        load_sweep_file(f)


def test_a_zip_sweep_without_archives_keeps_its_resolved_scenario(tmp_path, capsys):
    """A zip sweep of reduced cases keeps no case archive and no map: its sweep.h5 held only the scenario's
    path, so `show` of it gave a description and the folder's report said "stores no scenario". The index
    now holds the base scenario resolved with the sweep's --set (rotations 2, the file's [set] says 1)."""
    from bearingsim import reports
    from bearingsim.cli import main

    target = ROOT / "scenarios" / "sweeps" / "speed_zip_and_extras.toml"
    out = tmp_path / "zip"
    assert run_sweep_cli(target, [], ["numerics.rotations=2"], out, jobs=1, figures=False, quiet=True) == 0
    assert not (out / "cases").exists() and not (out / "map.h5").exists()
    want = load_scenario(BASE, ["numerics.rotations=2"]).to_toml()
    assert read_index(out / "sweep.h5")[1]["scenario_toml"] == want
    capsys.readouterr()
    assert main(["show", str(out / "sweep.h5")]) == 0
    assert capsys.readouterr().out == want
    _, _, toml = reports._sweep_sections(out / "sweep.h5")
    assert toml == want


@pytest.mark.parametrize("archives", ["auto", "all"])
def test_a_runs_notes_are_kept_in_the_sweeps_index_table_and_report(tmp_path, capsys, archives):
    """A case run alone prints its plausibility notes; in a sweep they were dropped: no notes column, no
    word in the closing line or the table, and the report said "No case failed" alone. A pocket clearance of
    0.3 mm (plausible 0.16 to 0.24) gets a note; 0.2 mm none. The notes stay when the sweep is run again
    (cached: from the previous index, whether or not the case keeps an archive)."""
    from bearingsim import reports, tables

    out = tmp_path / "s"
    for again in (False, True):
        assert run_sweep_cli(BASE, ["bearing.pocket_clearance_mm=0.2,0.3"], [], out, jobs=1, figures=False,
                             archives=archives) == 0
        printed = capsys.readouterr().out
        cols, _ = read_index(out / "sweep.h5")
        assert list(cols["status"]) == ["cached" if again else "done"] * 2
        assert cols["notes"][0] == "" and "bearing.pocket_clearance_mm = 0.3" in cols["notes"][1], cols["notes"]
        assert "outside the range the preset's sensitivity studies sample" in cols["notes"][1] and "bearingsim: note:" not in cols["notes"][1]
        assert printed.rstrip().splitlines()[-1].endswith(f"1 case with notes ('bearingsim table {out}' marks them "
                                                          f"in its notes column and lists them)"), printed
        assert _rows(out)[1]["notes"] == cols["notes"][1]
    text = tables.format_table(tables.table_of_index(out / "sweep.h5"))
    head, first, second = text.splitlines()[1:4]
    assert "notes" in head.split() and "[1]" not in first and "[1]" in second
    assert any(line.startswith("[1] bearing.pocket_clearance_mm = 0.3") for line in text.splitlines()), text
    checks = reports._folder_sections(out, None)[0].blocks
    assert "1 case kept with notes" in checks[1]["text"]
    assert [r[2] for r in checks[2]["rows"]] == [cols["notes"][1]]


def test_a_cached_case_takes_its_notes_from_its_archive(tmp_path, capsys):
    """A case taken from its archive, with no index row to take its notes from (the index removed), keeps
    the notes its run stored in the archive (/bearingsim/notes, read by archive.peek)."""
    out = tmp_path / "s"
    args = (BASE, ["bearing.pocket_clearance_mm=0.2,0.3"], [], out)
    assert run_sweep_cli(*args, jobs=1, figures=False, archives="all") == 0
    first, _ = read_index(out / "sweep.h5")
    for name in ("sweep.h5", "sweep.csv"):
        (out / name).unlink()
    assert run_sweep_cli(*args, jobs=1, figures=False, archives="all") == 0
    capsys.readouterr()
    cols, _ = read_index(out / "sweep.h5")
    assert list(cols["status"]) == ["cached", "cached"]
    assert list(cols["notes"]) == list(first["notes"]) and "bearing.pocket_clearance_mm = 0.3" in cols["notes"][1]


def test_a_case_has_one_wall_time_done_or_cached(tmp_path):
    """A case's wall_s was the worker's time around the run and its archive's writing when done (1.5367 s)
    and the archive's own run time when cached (1.4349 s): now the run's own time, as its archive stores it."""
    from bearingsim import archive

    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])])
    done = run_sweep(spec, tmp_path, figures=False, progress=False, archives="all")
    cached = run_sweep(spec, tmp_path, figures=False, progress=False, archives="all")
    assert [r["status"] for r in done.rows] == ["done"] * 2 and [r["status"] for r in cached.rows] == ["cached"] * 2
    for a, b in zip(done.rows, cached.rows):
        assert a["wall_s"] == b["wall_s"] == archive.peek(tmp_path / a["archive"])["wall_time_s"]
    assert [float(x) for x in read_index(tmp_path / "sweep.h5")[0]["wall_s"]] == [r["wall_s"] for r in done.rows]


def test_the_sweeps_page_says_a_zip_sweep_refuses_param_as_it_does(tmp_path):
    """docs/sweeps.md said "--param and --set add to a sweep file" with no exception; a zip sweep refuses
    --param: the page quotes the refusal the command gives."""
    import re

    target = ROOT / "scenarios" / "sweeps" / "speed_zip_and_extras.toml"
    res = bearingsim("sweep", target, "--param", "contact.restitution=0.6,0.7", "-o", tmp_path / "z")
    assert_user_error(res, 'mode: --param adds a product axis; not allowed with mode = "zip"')
    page = " ".join((ROOT / "docs" / "sweeps.md").read_text().split())
    said = re.search(r"`--param` and `--set` add to a sweep file[^.]*\.[^.]*\.", page).group(0)
    assert 'a sweep file of `mode = "zip"` refuses it (`mode: --param adds a product axis; not allowed with mode = ' \
           '"zip"`)' in page and "exception" in said, said


@pytest.mark.parametrize("command", ["sweep", "sensitivity"])
def test_a_signal_before_any_case_ran_is_said_in_a_sweeps_words(tmp_path, monkeypatch, capsys, command):
    """SIGINT while a sweep or study resolved its cases said the run command's "interrupted, no archive
    written"; a sweep writes no archive of its own: it says no case of it ran and that the command runs it."""
    from bearingsim.cli import main
    from bearingsim.studies import sensitivity
    from bearingsim.sweeps import spec

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(spec, "spec_from_args", interrupted)
    monkeypatch.setattr(sensitivity, "parse_step", interrupted)
    args = ["--param", f"{SPEED}=1000,2000"] if command == "sweep" else []
    assert main([command, str(BASE), *args, "-o", str(tmp_path / "o"), "-j", "1"]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    what = "the sweep" if command == "sweep" else "the sensitivity study"
    assert err == [f"bearingsim: interrupted, before any case of {what} ran (cases an earlier run kept are kept; the "
                   f"same command runs it)"], err


def test_another_sweeps_cases_are_counted_in_good_grammar(tmp_path):
    """The refusal said "1 of its 1 case are not in this one"."""
    from bearingsim.errors import UserError

    run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, [1000])]), tmp_path, figures=False, progress=False)
    with pytest.raises(UserError) as exc:
        run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, [2000])]), tmp_path, figures=False, progress=False)
    assert "(1 case of its 1 is not in this one)" in str(exc.value), str(exc.value)


def test_the_sweeps_page_says_a_range_is_rounded_to_15_digits_as_it_is():
    """A range's values are rounded to 15 significant digits (0.05:0.5:10 gives 0.15, where the floating-point
    spacing gives 0.15000000000000002), on purpose: the page said only "NUM evenly spaced values". It says so,
    with the values it gives, and they are the ones a range gives."""
    from bearingsim.sweeps.spec import parse_param

    text = " ".join((ROOT / "docs" / "sweeps.md").read_text().split())
    assert "each rounded to 15 significant digits" in text
    assert "0.05:0.5:10 gives 0.15 and 0.35, where the floating-point spacing gives 0.15000000000000002" in text
    values = parse_param("bearing.pocket_clearance_mm=0.05:0.5:10")[1]
    assert values[2] == 0.15 and values[6] == 0.35 and np.linspace(0.05, 0.5, 10)[2] == 0.15000000000000002


@pytest.mark.slow
@pytest.mark.parametrize("limit, index", [(64, "sweep.csv"), (4096, "sweep.h5")])
def test_a_full_disk_while_the_index_is_written_names_the_index(tmp_path, limit, index):
    """Writes failing past ``limit`` bytes (``RLIMIT_FSIZE`` in the child: EFBIG, "File too large", as a full
    disk's ENOSPC) while a reduced sweep writes its index (no case archives under the default policy): one
    line naming the index file and the cause, exit 2, no temporary file. It said "cannot write to standard
    output (File too large)" (the failed write of the index's temporary file carried no file name), or, where
    h5py wrote sweep.h5 to disk, printed HDF5's error stacks and died of SIGSEGV."""
    import resource

    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    args = [sys.executable, "-m", "bearingsim", "sweep", BASE, "--param", f"{SPEED}=1000,2000",
            "--set", "numerics.rotations=2", "-j", "1", "-q"]
    warm = subprocess.run([*map(str, args), "-o", tmp_path / "warm"], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": _path()})  # compiled kernels cached: no write of them
    assert warm.returncode == 0, warm.stderr
    out = tmp_path / "sw"
    proc = subprocess.run([*map(str, args), "-o", out], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": _path()}, preexec_fn=limited)
    assert (proc.returncode, proc.stderr) == (2, f"bearingsim: error: {out / index}: File too large\n")
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [".sweep.lock"]  # no temporary


def test_a_case_label_shows_a_ranges_value_without_its_round_off():
    """A range's values carry round-off (``0.01:0.1:10`` gives 0.09000000000000001), which a failed case's message
    printed as it is ("value=0.09000000000000001"); the label shows a float to 12 significant digits, anything else
    as it is, and the base scenario's case says so."""
    import numpy as np

    from bearingsim.sweeps.spec import Case

    values = {"lubrication.drag_coefficient": float(np.linspace(0.01, 0.1, 10)[8]), "bearing.roller_count": 16,
              "bearing.cage_guidance": "outer_land", "numerics.dt_s": 4e-6}
    assert values["lubrication.drag_coefficient"] != 0.09  # the round-off is there
    assert Case("0" * 16, values, "", "multibody").label() == (
        "lubrication.drag_coefficient=0.09, bearing.roller_count=16, bearing.cage_guidance=outer_land, "
        "numerics.dt_s=4e-06")
    assert Case("0" * 16, {}, "", "reduced").label() == "(base scenario)"
