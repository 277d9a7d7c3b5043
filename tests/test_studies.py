"""Studies on one engine (issue 29, item 1): the cross-check, the rig and Fig. 9 run their cases on the
sweep engine; a failing rung is kept and reported, an interrupted study resumes from its archives, and
the tables are the numbers the studies gave before they moved onto the engine."""
from __future__ import annotations

import csv
import math
import os
import signal

import numpy as np
import pytest

import bearingsim
from bearingsim.scenario import load_scenario
from bearingsim.studies import crosscheck as cc
from bearingsim.sweeps.engines import LocalEngine

from .conftest import SCENARIOS

REFERENCE = SCENARIOS / "multibody_3000rpm.toml"
RPM = 6000.0  # the cheapest speed of the ladder: one rotation of every rung takes about a second


def _archives(out):
    return {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in (out / "cases").glob("*.h5")}


@pytest.mark.slow
def test_a_failing_rung_is_kept_and_the_rerun_runs_only_it(tmp_path, monkeypatch):
    """Rung 3 given an impossible time step (1 ms, far above the bearing's stable step) fails at run
    time: the other four rungs' numbers are in the table, rung 3 has empty numbers, its status and
    error, and so has the change after it; the failure is reported, nothing raised. Run again without
    the override, the four finished rungs come from their archives (the files untouched) and only
    rung 3 runs."""
    scenario = load_scenario(REFERENCE)
    real = cc.rung_scenarios

    def broken(sc, rpm, rotations=None):
        return [(r, s, why, x.replace(**{"numerics.dt_s": 1e-3}) if s == "kinematic_cage" else x)
                for r, s, why, x in real(sc, rpm, rotations)]

    monkeypatch.setattr(cc, "rung_scenarios", broken)
    said = []
    rows, outcome = cc.run_crosscheck(scenario, tmp_path, (RPM,), 1, jobs=1, progress=False, log=said.append)
    assert outcome.interrupted is None
    assert [r["rung"] for r in rows] == [1, 2, 3, 4, 5]
    assert [r["status"] for r in rows] == ["done", "done", "failed", "done", "done"]
    assert "numerics.dt_s" in rows[2]["error"] and rows[2]["archive"] == ""
    assert len(said) == 1 and "numerics.dt_s" in said[0] and "kinematic_cage" in said[0]
    assert [r["values"]["rung"] for r in outcome.failed] == [3]
    for r in rows[:2] + rows[3:]:
        assert math.isfinite(r["I_dec_mean_Ns"])
        assert bearingsim.load(tmp_path / r["archive"]).summary["I_dec_mean_Ns"] == r["I_dec_mean_Ns"]
    assert math.isnan(rows[2]["I_dec_mean_Ns"])
    assert math.isnan(rows[2]["change_from_previous"]) and math.isnan(rows[3]["change_from_previous"])
    assert rows[4]["change_from_previous"] == rows[4]["I_dec_mean_Ns"] - rows[3]["I_dec_mean_Ns"]
    with open(tmp_path / "crosscheck.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert table[2]["I_dec_mean_Ns"] == "" and table[3]["I_dec_mean_Ns"] != ""
    stored, _ = cc.read_table(tmp_path / "crosscheck.h5")
    assert [r["status"] for r in stored] == ["done", "done", "failed", "done", "done"]
    assert "numerics.dt_s" in stored[2]["error"]
    assert any("failed rungs: 3 kinematic_cage" in line for line in cc.verdicts(rows))

    before = _archives(tmp_path)
    assert len(before) == 4
    monkeypatch.setattr(cc, "rung_scenarios", real)
    again, outcome = cc.run_crosscheck(scenario, tmp_path, (RPM,), 1, jobs=1, progress=False, log=said.append)
    assert [r["status"] for r in again] == ["cached", "cached", "done", "cached", "cached"]
    assert outcome.count("cached") == 4 and outcome.count("done") == 1 and not outcome.failed
    after = _archives(tmp_path)
    assert {k: v for k, v in after.items() if k in before} == before  # reused, not written again
    for a, b in zip(rows, again):
        if a["rung"] != 3:
            assert a["I_dec_mean_Ns"] == b["I_dec_mean_Ns"] and a["I_acc_mean_Ns"] == b["I_acc_mean_Ns"]
    assert all(math.isfinite(r["change_from_previous"]) for r in again[1:])


class _InterruptedAfterFirstCase(LocalEngine):
    """A local engine that receives SIGINT right after the first finished case is handed over: an
    interruption at a known point, whatever the machine's speed."""

    def run(self, batches, cases_dir, *args):
        for records in super().run(batches, cases_dir, *args):
            yield records
            os.kill(os.getpid(), signal.SIGINT)


@pytest.mark.slow
def test_an_interrupted_crosscheck_resumes_from_the_finished_rungs(tmp_path):
    """SIGINT after the first rung: the cross-check stops (no table), the finished rung's archive and
    the case index stay. The same cross-check again takes that archive as it is (cached, the file
    untouched) and runs the four others; the CLI then reports the counts."""
    scenario = load_scenario(REFERENCE)
    rows, outcome = cc.run_crosscheck(scenario, tmp_path, (RPM,), 1, engine=_InterruptedAfterFirstCase(1),
                                      progress=False)
    assert outcome.interrupted == signal.SIGINT and rows == []
    assert outcome.count("done") == 1 and outcome.count("pending") == 4
    assert not (tmp_path / "crosscheck.csv").exists() and (tmp_path / "sweep.csv").exists()
    kept = _archives(tmp_path)
    assert len(kept) == 1

    from bearingsim.cli import main

    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["crosscheck", str(REFERENCE), "--speeds", f"{RPM:g}", "--rotations", "1", "-j", "1",
                   "-o", str(tmp_path)])
    assert rc == 0
    assert "rungs: 4 done, 1 cached, 0 failed" in buf.getvalue()
    assert {k: v for k, v in _archives(tmp_path).items() if k in kept} == kept
    table, _ = cc.read_table(tmp_path / "crosscheck.h5")
    assert sorted(r["status"] for r in table) == ["cached", "done", "done", "done", "done"]
    assert all(math.isfinite(r["I_dec_mean_Ns"]) for r in table)


def test_a_study_whose_every_case_failed_writes_no_table_and_says_so(tmp_path, monkeypatch, capsys):
    """Every rung of a cross-check failed (each case's archive met a full disk): no crosscheck.csv, .h5 or
    .png of empty numbers as if done, no table printed, one line naming the failures and where they are
    kept, exit 1; the case index lists every rung failed with its error. It wrote the three files with
    empty number columns, printed them and "wrote ..." lines."""
    from bearingsim.cli import main
    from bearingsim.sweeps import worker

    def full_disk(case_hash, *args, **kwargs):  # in the forked worker: what a case on a full disk records
        return {"hash": case_hash, "status": "failed", "wall_s": 0.0, "summary": {},
                "error": f"cases/{case_hash}.h5: cannot write archive (No space left on device); nothing was written"}

    monkeypatch.setattr(worker, "run_case", full_disk)
    out = tmp_path / "cc"
    rc = main(["crosscheck", str(REFERENCE), "--speeds", f"{RPM:g}", "--rotations", "1", "-j", "1", "-o", str(out)])
    captured = capsys.readouterr()
    said = [line for line in captured.err.splitlines() if not line.startswith("bearingsim: note:")]
    assert rc == 1
    assert len(said) == 6 and all(line.startswith("failed: case ") for line in said[:5])  # one line each, then:
    assert said[-1].startswith("bearingsim: error: crosscheck: all 5 cases failed, the first (rpm=6000.0, rung=")
    assert said[-1].count("cannot write archive (No space left on device)") == 1
    assert said[-1].endswith(f"no table or figure written (the errors are in {out / 'sweep.csv'}; the same command "
                             "runs them again)")
    assert "wrote" not in captured.out and "crosscheck.csv" not in captured.out
    assert not [p.name for p in out.iterdir() if p.name.startswith("crosscheck")]
    with open(out / "sweep.csv", newline="") as fh:
        index = list(csv.DictReader(fh))
    assert [r["status"] for r in index] == ["failed"] * 5
    assert all("No space left on device" in r["error"] for r in index)


# Computed at commit 2e9b5c4 (before the studies moved onto the engine), with
# bearingsim.reduced.studies.fig9_table(), numbers printed with repr (the reduced model's numbers have
# not moved since).
FIG9_AT_2E9B5C4 = {
    "speed_rpm": [500.0, 750.0, 1000.0, 1500.0, 2000.0, 3000.0, 4000.0, 5000.0, 6000.0],
    "I_dec_c0.01_Ns": [0.011817955077465213, 0.008312956172646617, 0.006578007907950572, 0.00497125847390182,
                       0.004206586324025872, 0.0035256228105165696, 0.003125623564406289, 0.0031766311373143817,
                       0.0031765845505256985],
    "I_dec_c0.02_Ns": [0.012885341390878656, 0.009486037567340662, 0.007832783677204178, 0.006304848714071719,
                       0.005549834752222626, 0.005280209299758883, 0.005751033240934162, 0.005337738307837762,
                       0.005747669652105256],
    "I_dec_c0.03_Ns": [0.013973924291281508, 0.010701143741814259, 0.009152620536543145, 0.008262257163220406,
                       0.007725904618515982, 0.008267922442827261, 0.008448005962176283, 0.008641295924524976,
                       0.008392487073122621],
    "I_dec_previous_c0.02_Ns": [0.002721000111101033, 0.003428471764733687, 0.004039388800608723,
                                0.004946386314805308, 0.0051917221680597946, 0.005575019430990997,
                                0.0059850238146818835, 0.005968633447537131, 0.00547370883070177],
}
def test_fig9_study_gives_the_table_of_before(tmp_path):
    """Every number of the Fig. 9 table, bit for bit, as computed before the study ran on the engine;
    and the same study run again is all cached."""
    from bearingsim.studies.fig9 import fig9_table

    table = fig9_table(outdir=tmp_path, jobs=2)
    assert list(table) == list(FIG9_AT_2E9B5C4)
    for k, v in FIG9_AT_2E9B5C4.items():
        assert table[k].tolist() == v, k
    assert (tmp_path / "fig9_idec_vs_speed.csv").is_file()
    with open(tmp_path / "sweep.csv", newline="") as fh:
        assert {r["status"] for r in csv.DictReader(fh)} == {"done"}
    assert fig9_table(outdir=tmp_path)["I_dec_c0.02_Ns"].tolist() == FIG9_AT_2E9B5C4["I_dec_c0.02_Ns"]
    with open(tmp_path / "sweep.csv", newline="") as fh:
        assert {r["status"] for r in csv.DictReader(fh)} == {"cached"}


@pytest.mark.slow
def test_rig_study_gives_the_row_of_a_direct_run(tmp_path):
    """The rig study's row at 4000 rpm (2 rotations), through the engine (case archives written by worker
    processes, read back), is bit for bit the row made from a direct run of the same two scenarios in this
    process: every number and array. (At 2e9b5c4, before the studies moved onto the engine, the row was
    checked against the old code's the same way; the multibody numbers have moved since with the exact
    pocket faces, so the reference is computed here rather than stored.)"""
    import bearingsim
    from bearingsim.studies.fig9 import paper_scenario
    from bearingsim.studies.rig import rig_row, rig_scenario, rig_table

    (row,) = rig_table(speeds=(4000,), rotations=2, jobs=1, outdir=tmp_path)
    direct = rig_row(4000.0, 2, bearingsim.run(rig_scenario(4000.0, 2)),
                     float(bearingsim.run(paper_scenario(4000.0, 0.02, False)).summary["I_dec_mean_Ns"]))
    assert list(row) == list(direct)
    for k, v in direct.items():
        if isinstance(v, np.ndarray):
            assert np.asarray(row[k]).tobytes() == v.tobytes(), k
        else:
            assert row[k] == v, k
    assert (tmp_path / "rig_idec_vs_speed.csv").is_file() and (tmp_path / "rig_pocket0_forces.png").is_file()


def test_a_one_rotation_rig_row_shows_no_scatter_rather_than_zero(capsys):
    """validate --rig-rotations 1 printed "14.27 ±  0.00 (std)": the scatter of one rotation, which reads
    as an exact value. As the standard error (stats.batch_sem: NaN, tables: n/a), the row's std is NaN
    from fewer than 2 rotations and the table says n/a; from 2 rotations it is the scatter as before."""
    from types import SimpleNamespace

    from bearingsim.cli import _print_validate
    from bearingsim.studies.rig import rig_row

    def fake(per_rotation):
        d = np.asarray(per_rotation, float)
        return SimpleNamespace(per_rotation={"I_dec": d, "I_acc": d}, summary={"load_zone_half_angle_deg": 23.5},
                               get=lambda name: np.zeros((4, len(d[0]))))

    one = rig_row(3000.0, 1, fake([[0.01, 0.02, 0.03]]), 0.005)
    two = rig_row(3000.0, 2, fake([[0.01, 0.02, 0.03], [0.03, 0.02, 0.01]]), 0.005)
    assert math.isnan(one["pocket0_I_dec_std_Ns"]) and math.isnan(one["pocket0_I_dec_sem_Ns"])
    assert two["pocket0_I_dec_std_Ns"] == pytest.approx(0.01)
    args = SimpleNamespace(rig_rotations=1, output="v")
    outcome = SimpleNamespace(written=[], interrupted=None, sweep=SimpleNamespace(rows=[]), counts=lambda: "")
    fig9 = SimpleNamespace(table={"speed_rpm": np.array([500.0]), "I_dec_c0.02_Ns": np.array([0.0129])})
    _print_validate(args, [fig9, SimpleNamespace(rows=[one, two])], outcome)
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.strip().startswith("3000")]
    assert "± 0.00" not in lines[0] and "±   n/a (std)" in lines[0], lines
    assert "± 10.00 (std)" in lines[1], lines


@pytest.mark.parametrize("n, words", [("-1", "--rig-rotations -1: give 0 (no rig) or more"),
                                      ("100000", "--rig-rotations 100000: numerics.rotations: 100001 rotations")])
def test_validate_refuses_a_rig_rotations_it_cannot_run(n, words, tmp_path, capsys):
    """``validate --rig-rotations -1`` ran the Fig. 9 cases and no rig (exit 0), as 0 does; a count beyond the
    limit was refused as "bearingsim.studies.rig: numerics.rotations: ...", naming a module, not the option.
    Both are refused naming --rig-rotations, before anything is written."""
    from bearingsim.cli import main

    rc = main(["validate", "--rig-rotations", n, "-o", str(tmp_path / "v")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and words in err, err
    assert not (tmp_path / "v").exists()


def test_the_validate_studys_index_gives_its_speed_and_drag_coefficient_their_units(tmp_path, capsys):
    """validate's sweep.h5 stored `rpm` and `drag` (the drag coefficient c) with unit '1', as if dimensionless:
    `rpm` is in rpm (as crosscheck.h5 has it) and `drag` in c's unit, the one `bearingsim keys
    lubrication.drag_coefficient` gives; `inspect` lists them so."""
    import h5py

    from bearingsim.cli import main

    assert main(["keys", "lubrication.drag_coefficient"]) == 0
    row = capsys.readouterr().out.splitlines()[1].split()
    c_unit = " ".join(row[1:3])
    assert c_unit == "N^0.754 (s/m)^0.648", row
    assert main(["validate", "--rig-rotations", "0", "-j", "1", "-q", "-o", str(tmp_path / "v")]) == 0
    with h5py.File(tmp_path / "v" / "sweep.h5", "r") as f:
        assert f["index/rpm"].attrs["unit"] == "rpm" and f["index/drag"].attrs["unit"] == c_unit
    capsys.readouterr()
    assert main(["inspect", str(tmp_path / "v" / "sweep.h5")]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert any(ln.split()[:3] == ["drag", "number", "[N^0.754"] for ln in listed), listed
    assert any(ln.split() == ["rpm", "number", "[rpm]"] for ln in listed), listed


@pytest.mark.slow
def test_crosscheck_on_a_dask_cluster_gives_the_local_table(tmp_path):
    """The rungs sent to a dask cluster (a LocalCluster of one worker process, ended with the block) come
    back as archives and give the very table the local pool gives."""
    pytest.importorskip("distributed")
    from distributed import LocalCluster

    from bearingsim.sweeps.engines import DaskEngine

    scenario = load_scenario(REFERENCE, ["multibody.raceway_contact=rigid"])  # the fast scene: the engine is tested
    local, _ = cc.run_crosscheck(scenario, tmp_path / "local", (RPM,), 1, jobs=1, progress=False)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0",
                      host="127.0.0.1") as cluster:
        remote, outcome = cc.run_crosscheck(scenario, tmp_path / "dask", (RPM,), 1,
                                            engine=DaskEngine(cluster=cluster), progress=False)
    assert outcome.count("done") == 5
    assert (tmp_path / "local" / "crosscheck.csv").read_bytes() == (tmp_path / "dask" / "crosscheck.csv").read_bytes()
    assert [r["archive"] for r in local] == [r["archive"] for r in remote]


def test_every_file_a_sweep_or_study_writes_into_its_folder_is_one_force_removes():
    """`--force` removes the sweep or study it replaces (bearingsim.outputs.FOLDER_FILES): a file a study
    writes that the list lacks would be left to be read as the new one's (a life study's life.h5 made
    `table` and `report` of the folder show a life study after a sweep had replaced it)."""
    import bearingsim
    from bearingsim.outputs import FOLDER_FILES
    from bearingsim.studies.crosscheck import CrossCheck
    from bearingsim.studies.fig9 import Fig9
    from bearingsim.studies.life import LifeStudy, parse_limit
    from bearingsim.studies.rig import Rig
    from bearingsim.studies.sensitivity import Sensitivity
    from bearingsim.studies.uncertainty import Uncertainty
    from bearingsim.sweeps.grid import MAP_NAME
    from bearingsim.sweeps.plot import FIGURE_NAMES

    reduced = bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml")
    multibody = bearingsim.load_scenario(SCENARIOS / "wear_test_6000rpm.toml")
    studies = [CrossCheck(bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml"), speeds=[3000], rotations=1),
               Rig(speeds=[2000], rotations=1), Fig9(), Sensitivity(reduced), Uncertainty(reduced, 2),
               LifeStudy(multibody, parse_limit("depth=0.1mm"), stages=1)]
    written = {name for s in studies for name, _, _ in s.outputs} | set(FIGURE_NAMES) | {MAP_NAME, "sweep.csv", "sweep.h5"}
    assert written <= set(FOLDER_FILES), sorted(written - set(FOLDER_FILES))
    for name, signature, _ in (o for s in studies for o in s.outputs):  # a table's header starts as listed
        if isinstance(signature, bytes):
            assert signature.startswith(FOLDER_FILES[name]), name


@pytest.mark.slow  # over 2 s (quick subset under a minute)
def test_force_removes_the_tables_and_figures_of_the_study_it_replaces(tmp_path, capsys):
    """A sweep run with --force into the folder of another study removes that study's table and figure
    (they were left: `table` and `report` of the folder then showed a life study the sweep had replaced);
    a user's file in the folder, and a file of a study's name that bearingsim did not write (a PNG without
    bearingsim's mark included), are kept."""
    import numpy as np

    from bearingsim import archive
    from bearingsim.cli import main
    from bearingsim.plotting import figure, save_figure
    from bearingsim.studies import life

    sweep = ["sweep", str(SCENARIOS / "paper_3000rpm.toml"), "-q", "--no-plots", "-o", str(tmp_path)]
    assert main([*sweep, "--param", "operating.inner_ring_speed_rpm=1000,2000"]) == 0
    cols = {"stage": np.arange(1), "I_dec_mean_mNs": np.array([14.0])}
    archive.write_table_file(tmp_path / "life.h5", cols, life.LIFE_UNITS, {"format": life.LIFE_FORMAT, "limit": "x"})
    save_figure(figure(), tmp_path / "life.png")
    users = figure()
    users.savefig(tmp_path / "crosscheck.png", format="png")  # a user's picture of a study's name: kept
    picture = (tmp_path / "crosscheck.png").read_bytes()
    (tmp_path / "crosscheck.csv").write_bytes(b"\x00\x01 not a table")  # a study's name, not bearingsim's file
    (tmp_path / "notes.txt").write_text("mine")
    capsys.readouterr()
    assert main([*sweep, "--param", "operating.inner_ring_speed_rpm=3000,4000"]) == 2  # another sweep: refused
    assert "--force" in capsys.readouterr().err and (tmp_path / "life.h5").exists()
    assert main([*sweep, "--param", "operating.inner_ring_speed_rpm=3000,4000", "--force"]) == 0
    assert not (tmp_path / "life.h5").exists() and not (tmp_path / "life.png").exists()
    assert (tmp_path / "crosscheck.csv").read_bytes() == b"\x00\x01 not a table"
    assert (tmp_path / "crosscheck.png").read_bytes() == picture
    assert (tmp_path / "notes.txt").read_text() == "mine"
    capsys.readouterr()
    assert main(["table", str(tmp_path)]) == 0
    assert "3000" in capsys.readouterr().out


def test_every_table_is_written_in_one_csv_dialect(tmp_path):
    """The studies' tables (crosscheck, sensitivity, uncertainty: engine.table_csv), validate's (Fig. 9 and
    rig: outputs.write_csv) and the sweep's index sweep.csv are written by one writer in one dialect,
    RFC 4180 line ends; the studies' tables ended their lines in '\\n', the others in '\\r\\n'."""
    import math

    from bearingsim import outputs
    from bearingsim.studies.engine import table_csv
    from bearingsim.sweeps.index import write_index

    study = table_csv([{"key": "x", "n": 2, "v": 1.5, "e": math.nan}], ["key", "n", "v", "e"])
    assert study == outputs.csv_bytes(["key", "n", "v", "e"], [["x", "2", "1.5", ""]]) == b"key,n,v,e\r\nx,2,1.5,\r\n"
    validate = outputs.write_csv(tmp_path / "t.csv", ["rpm"], [["500"]]).read_bytes()
    assert validate == b"rpm\r\n500\r\n"
    write_index(tmp_path, [{"case": "c", "status": "done", "error": "", "archive": "", "wall_s": 1.0,
                            "model_version": 1, "summary": {}}], [], {})
    lines = (tmp_path / "sweep.csv").read_bytes().split(b"\n")
    assert all(line.endswith(b"\r") for line in lines[:-1]) and lines[-1] == b""


def test_a_signal_while_the_study_engine_stops_is_an_interruption_not_a_traceback(tmp_path, monkeypatch, capsys):
    """SIGINT landing while a study's engine stopped after its last round (studies.engine._run_rounds's clean-up,
    its handler still in) raised SweepInterrupted out of the study: `bearingsim sensitivity` printed its
    traceback and exited 1. It is an interruption: exit 130, one line, the cases kept, no table; the same
    command then writes the table from them."""
    from bearingsim import cli
    from bearingsim.sweeps import engines

    stop = engines.LocalEngine.stop
    calls = []

    def stop_then_signal(self):  # the first stop is the sweep's own (its signals held), the second the study's
        stop(self)
        calls.append(1)
        if len(calls) == 2:
            signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(engines.LocalEngine, "stop", stop_then_signal)
    args = ["sensitivity", str(SCENARIOS / "paper_3000rpm.toml"), "--keys", "contact.restitution", "-j", "1", "-q",
            "-o", str(tmp_path)]
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal user's Python has it
    try:
        code = cli.main(args)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert code == 130 and len(calls) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert err == ["bearingsim: sensitivity interrupted (SIGINT): 4 done, 0 cached, 0 failed, 0 not run, of 4 cases; "
                   "run the same command again to resume"], err
    assert not (tmp_path / "sensitivity.h5").exists()
    monkeypatch.setattr(engines.LocalEngine, "stop", stop)
    assert cli.main(args) == 0 and (tmp_path / "sensitivity.h5").is_file()
