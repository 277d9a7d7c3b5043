"""The cross-check ladder (issue 13): ``bearingsim crosscheck`` and the scenes it climbs through.

One command run (3000 rpm, 2 warm-up + 4 rotations, 2 processes, ~10 s once compiled) feeds the tests;
each rung's archive is read back to check that its scene holds what it claims.
"""
from __future__ import annotations

import csv
import math
import signal
from pathlib import Path

import h5py
import numpy as np
import pytest

import bearingsim
from bearingsim.studies import crosscheck as cc
from bearingsim.cli import main
from bearingsim.compare import compare_results
from bearingsim.scenario import load_scenario, parse_toml_text
from .forked_cli import pythonpath as _path

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
REFERENCE = SCENARIOS / "multibody_3000rpm.toml"
RPM = 3000.0
#: the fast scene, where what a test checks is not the whole bearing's numbers (docs/fast_scene.md)
RIGID = ("--set", "multibody.raceway_contact=rigid")
ROTATIONS = 2
WARMUP = 2  # not the scenario file's 1: the header says the warm-up the rungs ran


@pytest.fixture(scope="module")
def ladder(tmp_path_factory):
    """The command, run once: (output folder, exit code, stdout lines)."""
    import contextlib
    import io

    out = tmp_path_factory.mktemp("crosscheck")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["crosscheck", str(REFERENCE), "--speeds", f"{RPM:g}", "--set", f"numerics.rotations={ROTATIONS}",
                   "--set", f"numerics.warmup_rotations={WARMUP}", "-o", str(out)])
    return out, rc, buf.getvalue().splitlines()


def _rows(out):
    with open(out / "crosscheck.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def _archive(out, rung):
    """The path of a rung's archive, as the index names it."""
    rows, _ = cc.read_table(out / "crosscheck.h5")
    (row,) = [r for r in rows if r["rung"] == rung and r["rpm"] == RPM]
    return out / row["archive"]


def _rung(out, rung):
    return bearingsim.load(_archive(out, rung))


@pytest.mark.slow
def test_command_succeeds_and_reports(ladder):
    """Exit 0; the table and one sentence for the speed naming the largest change and each change's
    significance."""
    out, rc, lines = ladder
    assert rc == 0
    # the header says what the rungs ran: the scenario's warm-up (it said "1 warm-up" whatever it was) and
    # the recorded rotations of `--set numerics.rotations` (which the default --rotations 10 overrode)
    assert f"{WARMUP} warm-ups + {ROTATIONS} rotations each" in lines[0], lines[0]
    sentence = [ln for ln in lines if ln.startswith(f"{RPM:g} rpm: the largest change of I_dec is at rung")]
    assert len(sentence) == 1
    assert sentence[0].count("significant") == 4  # one verdict per change (rungs 2..5)
    for name in ("crosscheck.csv", "crosscheck.h5", "crosscheck.png"):
        assert (out / name).is_file()


def test_csv_columns(ladder):
    out = ladder[0]
    with open(out / "crosscheck.csv", newline="") as fh:
        header = next(csv.reader(fh))
    assert tuple(header) == cc.COLUMNS
    rows = _rows(out)
    assert [int(r["rung"]) for r in rows] == [1, 2, 3, 4, 5]
    assert [r["scene"] for r in rows] == [s for _, s, _ in cc.RUNGS]
    assert rows[0]["change_from_previous"] == ""


def test_changes_add_up_to_full_minus_reduced(ladder):
    """The same runs: the changes telescope to full - reduced (to the rounding of four subtractions)."""
    rows = _rows(ladder[0])
    total = sum(float(r["change_from_previous"]) for r in rows[1:])
    expect = float(rows[-1]["I_dec_mean_Ns"]) - float(rows[0]["I_dec_mean_Ns"])
    assert total == pytest.approx(expect, rel=1e-12, abs=1e-18)
    for a, b in zip(rows, rows[1:]):
        assert float(b["change_from_previous"]) == float(b["I_dec_mean_Ns"]) - float(a["I_dec_mean_Ns"])


def test_rungs_1_and_2_agree(ladder):
    """Rung 2 makes the reduced model's assumptions in pymunk: same I_dec within 2 % (issue 13; the
    polyline faces and the time step leave a ~0.2 % offset, docs/bench)."""
    rows = _rows(ladder[0])
    assert float(rows[1]["I_dec_mean_Ns"]) == pytest.approx(float(rows[0]["I_dec_mean_Ns"]), rel=0.02)


def test_rung3_cage_speed_is_prescribed(ladder):
    """Kinematic cage: every recorded cage speed sample is the epicyclic speed (to rounding), the centre
    never leaves the axis, and the mean-speed slip is zero up to the run's end being quantised to one
    step (the run stops at the first step past the last rotation: |slip| <= dt / t_record)."""
    out = ladder[0]
    r = _rung(out, 3)
    p = r.parameters
    with h5py.File(_archive(out, 3), "r") as f:
        w = f["observables/cage_angular_speed/value"][()]
    assert np.allclose(w, p.operating.omega_c, rtol=1e-12, atol=0)
    assert r.summary["cage_orbit_max_m"] == 0.0
    t_rec = 2 * math.pi * ROTATIONS / p.operating.omega_c
    assert abs(r.summary["cage_slip"]) <= r.summary["dt_s"] / t_rec
    # emerged (inner ring present): 23.75 deg is the continuous quasi-static load zone of the reference bearing at
    # 970 N (laws.quasi_static_load_zone, docs/physics.md), +-3 deg the window of test_multibody's load-zone test
    assert r.summary["load_zone_half_angle_deg"] == pytest.approx(23.75, abs=3.0)


def test_rung4_cage_centre_held_and_momentum_balanced(ladder):
    """Centred cage: the pivot holds the centre (pymunk solves it with the contacts in its iterative
    velocity solver, so to the solver's tolerance; bound 1e-7 m = 5e-4 of the pocket clearance, three
    orders below the full scene's ~150 um orbit). The pivot force acts through the centre and adds no
    torque: the cage's angular momentum change balances its contact torque impulses (normal and
    friction) to the solver's closure.

    Measured on this rung as the ladder runs it (cc.rung_scenarios of the scenario with 2 warm-up + 2
    rotations at 3000 rpm, scene centred_cage, run with bearingsim.simulation.run) over 16 loads differing
    only in the last bits (operating.radial_load_N = 970 + k * 0.00000097, k = 0..15; 13 distinct
    trajectories: k = 0, 1, 2 and k = 3, 4 ran bit-identical), as fractions of the drive sum(I_acc) r_p
    (0.0084-0.0089 N m s): residual +2.28e-5 .. +2.47e-5 (std 4.9e-7); the normal contacts' torque
    impulse +4.0 .. +7.8 %, the friction's -7.2 .. -7.9 %, the momentum change -3.3 .. +0.3 %; the orbit
    4.9e-9 .. 1.2e-8 m. Bound 1e-3 (was 1 %, the full scene's): 40 times the largest closure and 40
    times below the smallest contact term, so leaving out the normal or the friction torque fails (4 %
    and more off), and leaving out the momentum change fails in 15 of the 16 runs (the 1 % in 5)."""
    r = _rung(ladder[0], 4)
    assert r.summary["cage_orbit_max_m"] < 1e-7
    assert abs(r.summary["torque_balance_residual"]) < 1e-3
    assert r.summary["cage_slip"] != 0.0  # its speed is its own


@pytest.mark.slow
def test_rung5_is_bearingsim_run_of_the_scenario(ladder):
    """The full rung is ``bearingsim run`` of the scenario at that speed and rotation count, bit for bit
    (every summary number and per-rotation array); its cage momentum balances too."""
    sc = load_scenario(REFERENCE).replace(**{"operating.inner_ring_speed_rpm": RPM, "numerics.rotations": ROTATIONS,
                                             "numerics.warmup_rotations": WARMUP})
    fresh = bearingsim.run(sc)
    stored = _rung(ladder[0], 5)
    c = compare_results(stored, fresh)
    assert c.identical, (c.summary_table(), c.arrays_differ)
    assert stored.scenario.to_toml() == sc.to_toml()
    assert abs(stored.summary["torque_balance_residual"]) < 0.01


def test_index_and_plot(ladder, tmp_path):
    """crosscheck.h5 names every rung archive (readable with bearingsim.load); ``bearingsim plot`` on the
    index draws crosscheck.png again."""
    out = ladder[0]
    rows, meta = cc.read_table(out / "crosscheck.h5")
    assert [r["rung"] for r in rows] == [1, 2, 3, 4, 5]
    stored = parse_toml_text(meta["scenario"], "crosscheck.h5")  # what `bearingsim show crosscheck.h5` prints
    assert stored["numerics"]["rotations"] == ROTATIONS and stored["numerics"]["warmup_rotations"] == WARMUP
    assert {r["status"] for r in rows} == {"done"} and {r["error"] for r in rows} == {""}
    for r in rows:
        res = bearingsim.load(out / r["archive"])
        assert res.summary["I_dec_mean_Ns"] == r["I_dec_mean_Ns"]
    assert main(["plot", str(out / "crosscheck.h5"), "-o", str(tmp_path)]) == 0
    assert (tmp_path / "crosscheck.png").stat().st_size > 10_000


def test_rung_scenarios():
    """The reduced rung keeps every section of the multibody scenario; the full rung is the scenario
    with only the speed and rotations replaced."""
    sc = load_scenario(REFERENCE)
    rungs = cc.rung_scenarios(sc, 1000, 7)
    assert [r[1] for r in rungs] == ["reduced", "reduced_equivalent", "kinematic_cage", "centred_cage", "full"]
    red, full = rungs[0][3], rungs[-1][3]
    assert red.model == "reduced" and full.model == "multibody"
    for section in ("bearing", "operating", "contact", "lubrication", "reduced", "numerics"):
        assert red.raw[section] == full.raw[section]
    expect = sc.raw
    expect["operating"]["inner_ring_speed_rpm"] = 1000.0
    expect["numerics"]["rotations"] = 7
    assert full.raw == expect
    # rung 3 warms up for two rotations at least: with the file's one its first recorded rotation is its start
    # transient (docs/crosscheck.md), every other rung keeps the scenario's warm-up
    assert sc.numerics.warmup_rotations == 1
    assert [r[3].numerics.warmup_rotations for r in rungs[1:]] == [1, cc.KINEMATIC_WARMUP_ROTATIONS, 1, 1]
    assert cc.KINEMATIC_WARMUP_ROTATIONS == 2
    # the table's stored scenario (`bearingsim show crosscheck.h5`) has the rungs' count, not the file's 4
    assert cc.CrossCheck(sc, speeds=(1000,), rotations=7).scenario.numerics.rotations == 7


@pytest.mark.parametrize("contact, named", [("hertz", "(Hertz;"), ("rigid", "(rigid raceways;")])
def test_each_rung_says_the_raceway_contacts_its_scenario_has(contact, named):
    """Rung 3's description names the raceway contacts the rungs run with: a cross-check of the fast scene
    (multibody.raceway_contact = "rigid") wrote "raceway contacts (Hertz; ...)" into its table; every rung
    but the reduced one keeps the scenario's raceway contact."""
    sc = load_scenario(REFERENCE, [f"multibody.raceway_contact={contact}"])
    rungs = cc.rung_scenarios(sc, 1000, 7)
    assert named in rungs[2][2] and "{" not in "".join(r[2] for r in rungs)
    assert all(r[3].multibody.raceway_contact == contact for r in rungs[1:])


@pytest.mark.parametrize("argv, words", [
    (["crosscheck", str(SCENARIOS / "paper_3000rpm.toml")], "model = 'reduced'"),
    (["crosscheck", str(REFERENCE), "--set", "multibody.scene=reduced_equivalent"], "multibody.scene"),
    (["crosscheck", str(REFERENCE), "--speeds", "1000,fast"], "--speeds"),
    (["crosscheck", str(REFERENCE), "--rotations", "0"], "--rotations"),
    (["crosscheck", str(REFERENCE), "--set", "numerics.rotations=0"], "numerics.rotations"),
    (["crosscheck", str(REFERENCE), "--rotations", "3", "--set", "numerics.rotations=5"], "given twice"),
    (["crosscheck", str(REFERENCE), "-j", "0"], "-j 0"),
    (["crosscheck", str(REFERENCE), "--speeds", "3000", "--set", "operating.inner_ring_speed_rpm=1000"], "given twice"),
])
def test_refusals(argv, words, capsys, tmp_path):
    """A reduced-model scenario, a non-full scene and bad options: one line on stderr, exit 2, nothing run."""
    rc = main([*argv, "-o", str(tmp_path / "cc")])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.count("\n") == 1 and words in err
    assert not (tmp_path / "cc" / "cases").exists()


@pytest.mark.parametrize("argv, speeds", [
    (["--set", "operating.inner_ring_speed_rpm=2000"], (2000.0,)),
    (["--set", "operating.inner_ring_speed_rpm=2000", "--speeds", "2000"], (2000.0,)),
    ([], cc.DEFAULT_SPEEDS_RPM),
])
def test_a_set_speed_is_the_speed_the_rungs_run_at(argv, speeds, monkeypatch, tmp_path):
    """``crosscheck --speeds 3000 --set operating.inner_ring_speed_rpm=1000`` ran the rungs at 3000 rpm and
    stored 1000 rpm as the table's scenario (the --set silently overridden). As for the rotations, a --set of
    the speed without --speeds is taken as --speeds N (and both given differently are refused, above)."""
    seen = []

    class Ran(BaseException):
        pass

    def run_crosscheck(scenario, outdir, speeds, rotations, **kw):
        seen.append(tuple(speeds))
        raise Ran

    monkeypatch.setattr(cc, "run_crosscheck", run_crosscheck)
    with pytest.raises(Ran):
        main(["crosscheck", str(REFERENCE), *argv, "-o", str(tmp_path / "cc")])
    assert seen == [speeds]


@pytest.mark.slow
@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_signal_stops_the_crosscheck_at_once_and_writes_nothing_after_it(tmp_path, signum, code):
    """Issue 30, item 4: ``crosscheck -j 2`` took 7-15 s to stop after SIGINT/SIGTERM and wrote rung
    archives after the signal. On the sweep engine the signal stops it at once: the rungs running when it
    comes are not finished (no archive, no row done; a worker let finish its rung wrote it), its worker
    processes ended before it exits, no table, no temporary file, one line on how to resume, exit 128 +
    signal. No wall-time bound: the signal comes when the first two rungs (5 full and 4 centred_cage,
    started together) have their archives, and the two then running (3 and 2) started when those ended
    and take as long as a rung of the whole bearing, so they are far from their end on a machine of any
    speed."""
    import os
    import subprocess
    import sys
    import time

    import psutil

    from .conftest import ROOT, started
    from .test_sweep import _rows, _running

    out = tmp_path / "cc"
    cmd = [sys.executable, "-m", "bearingsim", "crosscheck", REFERENCE, "--speeds", f"{RPM:g}", "--rotations",
           str(ROTATIONS), "-j", "2", "-o", out]
    env = {**os.environ, "PYTHONPATH": _path()}
    with started(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env) as proc:
        deadline = time.monotonic() + 300  # a hang guard only
        finished = set()
        while time.monotonic() < deadline and proc.poll() is None and len(finished) < 2:
            time.sleep(0.02)
            finished = {p.name for p in (out / "cases").glob("[!.]*.h5")}
        children = psutil.Process(proc.pid).children(recursive=True)
        assert proc.poll() is None and len(children) >= 2, "the cross-check ended before the signal"
        os.kill(proc.pid, signum)
        _, err = proc.communicate(timeout=300)  # a hang guard only
    assert proc.returncode == code, err
    assert _running(children) == []  # ended (and reaped) before the cross-check exited
    assert {p.name for p in (out / "cases").iterdir()} == finished  # nothing written after the signal
    rows = _rows(out)
    assert len(rows) == 5 and len(finished) == 2
    for r in rows:  # a finished rung is done or (its record not yet in at the signal) pending; the others pending
        running = f"{r['case']}.h5" not in finished
        assert r["status"] == "pending" if running else r["status"] in ("done", "pending"), r
    assert not (out / "crosscheck.csv").exists() and not (out / "crosscheck.h5").exists()
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "cross-check interrupted" in err and err.rstrip().endswith("run the same command again to resume")


@pytest.mark.slow
def test_the_closing_line_counts_the_rungs_with_notes(tmp_path, capsys):
    """A sweep's closing line counts its cases with notes; the cross-check's ("rungs: 5 done, 0 cached, 0
    failed; ...") did not: it counts the rungs with notes and names the table that lists them."""
    from bearingsim.sweeps import read_index
    from bearingsim.sweeps.index import notes_of

    out = tmp_path / "cc"
    assert main(["crosscheck", str(REFERENCE), "--speeds", f"{RPM:g}", "--set", "numerics.rotations=3", *RIGID,
                 "-o", str(out), "-j", "1"]) == 0  # 3 rotations: the whole-bearing rungs get a note (rigid: faster)
    last = capsys.readouterr().out.rstrip().splitlines()[-1]
    noted = sum(bool(notes_of(c)) for c in read_index(out / "sweep.h5")[0]["notes"])
    assert noted >= 1
    assert last.startswith("rungs: 5 done, 0 cached, 0 failed; ") and last.endswith(
        f"; {noted} rung{'s' if noted > 1 else ''} with notes ('bearingsim table {out / 'sweep.h5'}' marks them in "
        f"its notes column and lists them)"), last


def test_one_rotation_prints_no_nan_standard_error():
    """Issue 30, Low: ``crosscheck --rotations 1`` printed "not significant: 2 SE = nan" and "± nan":
    one rotation gives no batch-means error, so the change is not judged and the table says n/a."""
    nan = math.nan
    rows = [dict(rpm=3000.0, rung=k, scene=s, I_dec_mean_Ns=m, I_dec_sem_Ns=e, I_acc_mean_Ns=0.0, I_acc_sem_Ns=e,
                 first_impact_speed_m_s=0.08, cage_slip=0.0, change_from_previous=c, status="done")
             for k, s, m, e, c in ((1, "reduced", 5e-3, 0.0, nan), (2, "full", 6e-3, nan, 1e-3))]
    text = " ".join(cc.verdicts(rows)) + "\n" + cc.format_table(rows)
    assert "nan" not in text.lower(), text
    assert "not judged" in text and "n/a" in text


def test_a_rung_without_a_standard_error_is_an_open_marker_the_title_counts(tmp_path, monkeypatch):
    """crosscheck.png of one rotation (the table: "± n/a") drew its multibody rungs without bars under "mean
    over all pockets ± 1 standard error": matplotlib leaves out a NaN bar, and nothing said so. Such a rung
    now has an open marker and the title counts it; the reduced rung's exact 0 stays a bar of 0."""
    from bearingsim import plotting

    nan = math.nan
    rows = [dict(rpm=3000.0, rung=k, scene=s, relaxed="", I_dec_mean_Ns=m, I_dec_sem_Ns=e, I_acc_mean_Ns=m / 2,
                 I_acc_sem_Ns=e, first_impact_speed_m_s=0.08, cage_slip=0.0, change_from_previous=nan,
                 archive="", wall_s=1.0, status="done", error="")
            for k, s, m, e in ((1, "reduced", 5e-3, 0.0), (2, "full", 6e-3, nan), (3, "full", 7e-3, 1e-4))]
    cc.write_table(tmp_path, rows, load_scenario(SCENARIOS / "multibody_3000rpm.toml"))
    figs = []
    monkeypatch.setattr(plotting, "save_figure", lambda fig, path, **kw: figs.append(fig) or Path(path))
    cc.plot_crosscheck(tmp_path / "crosscheck.h5", tmp_path)
    dec, acc = figs[0].axes[:2]
    for ax, m in ((dec, 6.0), (acc, 3.0)):
        opened = [(float(x), float(y)) for line in ax.lines if line.get_markerfacecolor() == "white"
                  for x, y in zip(line.get_xdata(), line.get_ydata())]
        assert opened == [(2.0, pytest.approx(m))]  # rung 2's, in mN s
        segs = [seg for c in ax.containers for col in c.lines[2] for seg in col.get_segments() if len(seg)]
        assert len(segs) == 2  # rung 1's of length 0, rung 3's ± 0.1 mN s; none for rung 2
    assert dec.get_title().endswith("± 1 standard error (batch means over rotations); open markers: none (n/a), "
                                    "2 of 6 points")


def test_terminal_table_gives_cage_slip_in_per_cent_as_the_docs_do():
    """The cage slip (a fraction in crosscheck.h5/.csv) printed as 1e-2 numbers ("-4.10e-03") under a
    header without a unit, while docs/crosscheck.md quotes it in per cent; the terminal table gives it
    in per cent, in a column headed so."""
    row = dict(rpm=3000.0, rung=5, scene="full", I_dec_mean_Ns=1.4563e-2, I_dec_sem_Ns=1.53e-4,
               I_acc_mean_Ns=1.5121e-2, I_acc_sem_Ns=3.56e-4, first_impact_speed_m_s=0.0349, cage_slip=-0.0041,
               change_from_previous=8.76e-3, status="done")
    head, line = cc.format_table([row]).splitlines()
    assert "slip [%]" in head
    assert line.split()[-2:] == ["-0.41", "+8.760"], line


def test_a_slip_that_rounds_to_zero_is_printed_without_a_sign():
    """A cage slip of -1.2e-06 (a kinematic cage) printed as "-0.00" in the slip [%] column; it prints 0.00,
    and a slip that does not round to zero keeps its sign."""
    row = dict(rpm=3000.0, rung=3, scene="kinematic_cage", I_dec_mean_Ns=1.1486e-2, I_dec_sem_Ns=2.83e-4,
               I_acc_mean_Ns=0.0, I_acc_sem_Ns=0.0, first_impact_speed_m_s=0.0318, cage_slip=-1.2e-06,
               change_from_previous=6.218e-3, status="done")
    slips = [cc.format_table([{**row, "cage_slip": v}]).splitlines()[1].split()[-2]
             for v in (-1.2e-06, 4e-05, -0.0014, 0.0038)]
    assert slips == ["0.00", "0.00", "-0.14", "+0.38"], slips


def test_crosscheck_index_and_table_give_each_rung_one_standard_error(ladder):
    """Issue 28, item 5: the cross-check's table, the engine's case index in the same folder and
    ``bearingsim table`` of a rung's archive report the same standard error, bit for bit."""
    from bearingsim import tables
    from bearingsim.sweeps.index import read_index

    out, rc, _ = ladder
    rows, _ = cc.read_table(out / "crosscheck.h5")
    cols, _ = read_index(out / "sweep.h5")
    by_archive = {str(a): i for i, a in enumerate(cols["archive"])}
    for row in rows:
        i = by_archive[str(row["archive"])]
        table = tables.table_of_archives([out / row["archive"]])
        for k in ("I_dec_sem_Ns", "I_acc_sem_Ns"):
            assert row[k] == cols[k][i] == table.numbers[k][0], (row["scene"], k)
    text = tables.format_table(tables.table_of(out))
    assert "rung" in text.splitlines()[1] and text.splitlines()[-2] == tables.RULE
    assert text.splitlines()[-1].startswith("x_ref: the row ") and "(the first case)" in text.splitlines()[-1]


def test_table_of_the_folder_prints_the_ladder_and_its_verdicts(ladder, capsys):
    """``bearingsim table DIR`` of a cross-check folder printed its case index: the rungs in the order they
    ran (rung 5 first, the reduced rungs last) with every ``*`` against that first row, a meaningless
    comparison; ``table DIR/crosscheck.h5`` said "not a bearingsim archive". Both print the ladder as
    ``bearingsim crosscheck`` prints it at its end: rungs by speed, changes, one verdict per speed."""
    out, _, lines = ladder
    rows, meta = cc.read_table(out / "crosscheck.h5")
    expect = [*cc.format_table(rows).splitlines(), *cc.verdicts(rows, cc.table_rotations(meta))]
    i = lines.index(expect[0])
    assert lines[i:i + len(expect)] == expect  # what the command printed
    for path in (out, out / "crosscheck.h5"):
        assert main(["table", str(path)]) == 0
        printed = capsys.readouterr().out.splitlines()
        assert printed[0].startswith(f"{out / 'crosscheck.h5'}: cross-check of multibody_3000rpm: 1 speed x 5 rungs")
        assert printed[1:] == expect
    assert main(["table", str(out), "--columns", "I_dec_mean_Ns"]) == 2  # a study's table has its own columns
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--columns" in err and str(out / "sweep.h5") in err
    assert main(["table", str(out / "sweep.h5")]) == 0  # the case index, as before
    assert capsys.readouterr().out.splitlines()[1].split()[:3] == ["rpm", "rung", "scene"]


def test_a_verdicts_threshold_carries_its_unit():
    """"(significant: 3.18 SE = 0.00023)" gave the threshold without a unit, beside changes in mN s: it is in
    mN s, t times the difference's standard error (1e-4 and 2e-4 N s: sqrt(5) 1e-4 N s = 0.224 mN s)."""
    rows = [{"rpm": 3000.0, "rung": k, "scene": scene, "relaxed": what, "I_dec_mean_Ns": 5e-3 * (1 + k),
             "I_dec_sem_Ns": 1e-4 * (1 + k % 2), "I_acc_mean_Ns": 3e-3, "I_acc_sem_Ns": 1e-4,
             "first_impact_speed_m_s": 0.1, "cage_slip": 0.01, "archive": "", "wall_s": 1.0, "status": "done",
             "error": ""} for k, scene, what in cc.rungs()[:2]]
    (line,) = cc.verdicts(cc.add_changes(rows), rotations=10)
    t = cc.critical_ses(1e-4, 2e-4, 5, 5)
    assert f"(significant: {t:.3g} SE = {t * math.sqrt(5) * 1e-1:.2g} mN s)" in line, line


def test_a_rung_without_a_rear_face_impact_prints_n_a_as_the_docs_do():
    """The kinematic cage pushes its rollers continuously at 3000 and 6000 rpm: no rear-face impact, a first
    impact speed of NaN, which the terminal table printed as "nan" where docs/crosscheck.md has n/a."""
    row = dict(rpm=3000.0, rung=3, scene="kinematic_cage", I_dec_mean_Ns=1.2555e-2, I_dec_sem_Ns=1e-9,
               I_acc_mean_Ns=0.0, I_acc_sem_Ns=0.0, first_impact_speed_m_s=float("nan"), cage_slip=0.0,
               change_from_previous=7.287e-3, status="done")
    line = cc.format_table([row]).splitlines()[1]
    assert line.split()[-3:] == ["n/a", "0.00", "+7.287"] and "nan" not in line, line
    assert cc.format_table([{**row, "first_impact_speed_m_s": 0.0485}]).splitlines()[1].split()[-3] == "0.0485"


def test_a_failed_rung_prints_n_a_not_nan():
    """A failed rung keeps its row with no numbers (crosscheck.csv: empty fields; the report: "-"), which the
    terminal table and `bearingsim table DIR` printed as "nan ± n/a" and a slip of "+nan"
    (`bearingsim crosscheck scenarios/multibody_3000rpm.toml --set numerics.dt_s=3e-5 --speeds 6000`): they print
    n/a, and the verdict names the failed rung."""
    nan = math.nan
    rows = [dict(rpm=6000.0, rung=1, scene="reduced", I_dec_mean_Ns=5.748e-3, I_dec_sem_Ns=0.0, I_acc_mean_Ns=0.0,
                 I_acc_sem_Ns=0.0, first_impact_speed_m_s=0.1122, cage_slip=0.0, change_from_previous=nan,
                 status="done"),
            dict(rpm=6000.0, rung=2, scene="reduced_equivalent", I_dec_mean_Ns=nan, I_dec_sem_Ns=nan,
                 I_acc_mean_Ns=nan, I_acc_sem_Ns=nan, first_impact_speed_m_s=nan, cage_slip=nan,
                 change_from_previous=nan, status="failed")]
    line = cc.format_table(rows).splitlines()[2]
    assert "nan" not in line.lower(), line
    assert line.split()[3:] == ["n/a", "±", "n/a", "n/a", "±", "n/a", "n/a", "n/a"], line


def test_the_first_line_gives_rung_3s_own_warm_up():
    """The command's first line said "1 warm-up + 3 rotations each", but rung 3 warms up for
    KINEMATIC_WARMUP_ROTATIONS (2) whatever the scenario's single warm-up: it says "1 warm-up (rung 3: 2)", as
    docs/crosscheck.md does; a scenario's own warm-up of 2 or more is every rung's."""
    assert cc.KINEMATIC_WARMUP_ROTATIONS == 2
    assert cc.warmup_text(1) == "1 warm-up (rung 3: 2)"
    assert cc.warmup_text(2) == "2 warm-ups" and cc.warmup_text(3) == "3 warm-ups"
    warmups = {scene: sc.numerics.warmup_rotations for _, scene, _, sc in
               cc.rung_scenarios(load_scenario(REFERENCE), 3000.0, 3)}
    assert warmups == {"reduced": 1, "reduced_equivalent": 1, "kinematic_cage": 2, "centred_cage": 1, "full": 1}


def test_the_figures_title_names_the_speeds_it_ran(tmp_path, monkeypatch):
    """A cross-check over 1000, 3000 and 6000 rpm was titled "Cross-check of multibody_3000rpm", the base
    scenario's name, as if it had run at 3000 rpm. The title names the speeds that ran."""
    from bearingsim import plotting

    rows = [dict(rpm=rpm, rung=1, scene="reduced", relaxed="", I_dec_mean_Ns=5e-3, I_dec_sem_Ns=0.0,
                 I_acc_mean_Ns=2e-3, I_acc_sem_Ns=0.0, first_impact_speed_m_s=0.08, cage_slip=0.0,
                 change_from_previous=math.nan, archive="", wall_s=1.0, status="done", error="")
            for rpm in (1000.0, 3000.0, 6000.0)]
    cc.write_table(tmp_path, rows, load_scenario(SCENARIOS / "multibody_3000rpm.toml"))
    figs = []
    monkeypatch.setattr(plotting, "save_figure", lambda fig, path, **kw: figs.append(fig) or Path(path))
    cc.plot_crosscheck(tmp_path / "crosscheck.h5", tmp_path)
    title = figs[0].axes[0].get_title()
    assert title.startswith("Cross-check at 1000, 3000, 6000 rpm of multibody_3000rpm's other settings:"), title
