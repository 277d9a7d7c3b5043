"""The wear of a sweep's cases: the rates its index carries (``wear_*_m3_h``), its table and map, and
``bearingsim wear DIR`` (docs/sweeps.md, *Wear in a sweep*; docs/wear.md, *A sweep's wear*)."""
import re
import shutil

import h5py
import numpy as np
import pytest

from bearingsim import tables, wear
from bearingsim.cli import main
from bearingsim.scenario import load_scenario
from bearingsim.simulation import load, run as simulate
from bearingsim.stats import with_error
from bearingsim.sweeps import LocalEngine, SweepSpec, read_index, read_map, run_sweep

from .conftest import ROOT, SCENARIOS

K = "wear.wear_coefficient"
CLEARANCE = "bearing.pocket_clearance_mm"
#: the multibody sweep of the tests: the wear test's scene, rigid raceways, 2 recorded rotations, two k
MB_SETS = ["numerics.rotations=2", "multibody.raceway_contact=rigid"]
#: an index the code before the wear rates wrote (a reduced sweep of paper_3000rpm.toml over the pocket clearance
#: 0.18, 0.22 mm, no archives; its impulses in the index)
OLD_INDEX = ROOT / "tests" / "data" / "sweep_index_before_wear.h5"


@pytest.fixture(scope="module")
def mb_sweep(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mb") / "sw"
    spec = SweepSpec(scenario=SCENARIOS / "wear_test_6000rpm.toml", sets=MB_SETS, axes=[(K, [5e-6, 1e-5])])
    run_sweep(spec, folder, engine=LocalEngine(1), figures=False, progress=False)
    return folder, spec


def _cells(line: str) -> list[str]:
    return re.split(r"\s{2,}", line.strip())


@pytest.mark.slow
def test_a_multibody_sweeps_index_holds_the_wear_bearingsim_wear_computes_from_each_cases_archive(mb_sweep, capsys):
    """An engineer sweeping k read impulses only: the index (sweep.h5, map.h5), its table and 'bearingsim wear DIR'
    now carry each case's worn volume per hour, bit for bit what 'bearingsim wear ARCHIVE --hours 1' computes, with
    its standard error and the worst pocket's; 'wear DIR' labels the rows by the swept values (it was refused)."""
    folder, _ = mb_sweep
    cols, meta = read_index(folder / "sweep.h5")
    assert list(cols["status"]) == ["done", "done"]
    assert meta["columns"][-6:] == list(wear.SWEEP_RATES)  # after every column an index had before them
    for i in range(2):
        rep = wear.wear_report(load(folder / str(cols["archive"][i])), hours=1.0)
        for face, v in (("front", rep.volume_front), ("rear", rep.volume_rear)):
            assert cols[f"wear_{face}_mean_m3_h"][i] == v.mean()  # the same bits
            assert cols[f"wear_{face}_sem_m3_h"][i] == rep.volume_sem(face)
            assert cols[f"wear_{face}_worst_m3_h"][i] == v.max() > v.mean()
    assert cols["wear_front_mean_m3_h"][1] == pytest.approx(2 * cols["wear_front_mean_m3_h"][0], rel=1e-12, abs=0)  # ~ k
    with h5py.File(folder / "sweep.h5", "r") as f:
        ds = f["index/wear_rear_worst_m3_h"]
        assert ds.attrs["unit"] == "m^3/h" and "most worn rear face" in ds.attrs["description"]
    m = read_map(folder)
    np.testing.assert_array_equal(m["wear_front_mean_m3_h"], cols["wear_front_mean_m3_h"])
    assert m.units["wear_front_sem_m3_h"] == "m^3/h" and "front face" in m.long_names["wear_front_mean_m3_h"]
    text = tables.format_table(tables.table_of(folder))
    head = _cells(text.splitlines()[1])
    assert head[-2:] == ["wear_front_mean [mm^3/h]", "wear_rear_mean [mm^3/h]"], head
    assert _cells(text.splitlines()[2])[-2] == with_error(cols["wear_front_mean_m3_h"][0] * 1e9,
                                                          cols["wear_front_sem_m3_h"][0] * 1e9)
    assert main(["wear", str(folder), "--hours", "10"]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert "wear of the 2 cases of the sweep" in lines[0] and lines[0].endswith(f"differ: {K} (as columns)")
    assert _cells(lines[1])[:3] == ["case", K, "hours"]
    for i, line in enumerate(lines[2:4]):
        rep = wear.wear_report(load(folder / str(cols["archive"][i])), hours=10)
        cells = _cells(line)
        assert cells[:2] == [str(cols["case"][i]), ("5e-06", "1e-05")[i]]
        assert cells[5:7] == [with_error(v.mean() * 1e9, rep.volume_sem(f) * 1e9)
                              for f, v in (("front", rep.volume_front), ("rear", rep.volume_rear))]
    assert not list(folder.glob("**/*.png"))  # a sweep's wear draws no figures


@pytest.mark.slow
def test_a_running_time_beyond_the_bound_at_a_cases_speed_names_the_case(mb_sweep, capsys):
    """'wear DIR --rotations N' bounds N by each case's speed (1e6 h of running): the refusal named the speed of
    the case it came from but not the case, which a sweep over the speed (or any key) leaves the user to guess;
    it names the case and its swept values, in one line, exit 2."""
    folder, _ = mb_sweep
    cols, _ = read_index(folder / "sweep.h5")
    assert main(["wear", str(folder), "--rotations", "1e20"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"bearingsim: error: --rotations 1e+20: case {cols['case'][0]} ({K} = 5e-06): more than "
                          "1000000 h of running (360000000000 inner-ring rotations at 6000 rpm)"), err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_a_resumed_multibody_sweep_takes_the_same_wear_from_its_archives(mb_sweep):
    """A cached case's rates are read from its archive: the same bits as the run's own."""
    folder, spec = mb_sweep
    before, _ = read_index(folder / "sweep.h5")
    run_sweep(spec, folder, engine=LocalEngine(1), figures=False, progress=False)
    after, _ = read_index(folder / "sweep.h5")
    assert list(after["status"]) == ["cached", "cached"]
    for k in (*wear.SWEEP_RATES, "I_dec_mean_Ns", "I_dec_sem_Ns", "first_impact_speed_sem_m_s"):
        np.testing.assert_array_equal(after[k], before[k])
    # the first impact speed's error is the one 'bearingsim table' computes from the case's archive
    from bearingsim.stats import result_standard_errors

    se = [result_standard_errors(load(folder / a))["first_impact_speed_sem_m_s"] for a in after["archive"]]
    assert list(after["first_impact_speed_sem_m_s"]) == se and all(np.isfinite(se))


@pytest.fixture(scope="module")
def reduced_sweep(tmp_path_factory):
    folder = tmp_path_factory.mktemp("red") / "sw"
    spec = SweepSpec(scenario=SCENARIOS / "paper_3000rpm.toml", axes=[(CLEARANCE, [0.18, 0.22])])
    run_sweep(spec, folder, engine=LocalEngine(1), figures=False, progress=False)  # no archives (auto)
    return folder


@pytest.mark.slow
def test_a_reduced_sweeps_index_holds_its_models_wear_and_wear_dir_reads_it(reduced_sweep, capsys):
    """The reduced model's wear per hour (its archive's /results/wear, Eq. 16), exact (± 0), no worst pocket;
    'wear DIR' of its cases, which keep no archive, multiplies the index's rate by the hours; with --rotations
    (the index's rates are per hour) each case is named as not available."""
    cols, _ = read_index(reduced_sweep / "sweep.h5")
    assert list(cols["archive"]) == ["", ""]
    for i, s in enumerate((0.18, 0.22)):
        w = simulate(load_scenario(SCENARIOS / "paper_3000rpm.toml", [f"{CLEARANCE}={s}"])).groups["results/wear"]
        assert cols["wear_front_mean_m3_h"][i] == w.attrs["front_per_hour_m3_h"]
        assert cols["wear_rear_mean_m3_h"][i] == w.attrs["rear_per_hour_m3_h"] > 0
        assert cols["wear_rear_sem_m3_h"][i] == 0.0
    assert "wear_front_worst_m3_h" not in cols
    spec = SweepSpec(scenario=SCENARIOS / "paper_3000rpm.toml", axes=[(CLEARANCE, [0.18, 0.22])])
    kept = reduced_sweep.parent / "kept"
    for status in ("done", "cached"):  # a case cached from its archive takes the same rates as its run
        run_sweep(spec, kept, engine=LocalEngine(1), figures=False, progress=False, archives="all")
        again, _ = read_index(kept / "sweep.h5")
        assert list(again["status"]) == [status] * 2
        for k in ("wear_front_mean_m3_h", "wear_rear_mean_m3_h", "wear_rear_sem_m3_h"):
            np.testing.assert_array_equal(again[k], cols[k])
    assert main(["wear", str(reduced_sweep), "--hours", "2"]) == 0
    out, _ = capsys.readouterr()
    lines = out.splitlines()
    for i, line in enumerate(lines[2:4]):
        cells = _cells(line)
        assert cells[1] == ("0.18", "0.22")[i]
        assert cells[5] == with_error(cols["wear_front_mean_m3_h"][i] * 2 * 1e9, 0.0)
        assert cells[-1] == "-"
    assert "Eq. 16" in lines[-1]
    # no case has an archive to scale by its cage speed: the option is refused in one line (it printed a table of
    # dashes, every case "not available", and exited 0)
    assert main(["wear", str(reduced_sweep / "sweep.h5"), "--rotations", "1e5"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1, (out, err)
    assert err.startswith("bearingsim: error: --rotations 100000: no case of ") and err.rstrip().endswith("give --hours")
    assert main(["wear", str(reduced_sweep), "--hours", "-1"]) == 2
    assert "--hours -1.0: must be a positive number" in capsys.readouterr().err


@pytest.mark.slow
def test_an_index_written_before_the_wear_rates_is_read_tabulated_and_resumed(tmp_path, capsys):
    """An index the code before these columns wrote (tests/data) reads, tabulates (no wear column) and gives 'wear
    DIR' its cases as not available; resumed, its cases (no archives) run again to get their rates, the impulses
    the same bits."""
    folder = tmp_path / "sw"
    folder.mkdir()
    shutil.copy(OLD_INDEX, folder / "sweep.h5")
    old, _ = read_index(folder / "sweep.h5")
    assert "wear_front_mean_m3_h" not in old
    text = tables.format_table(tables.table_of(folder))
    assert "I_dec_mean [mN s]" in text and "wear" not in text.splitlines()[1]
    assert main(["wear", str(folder), "--hours", "1"]) == 0
    out, _ = capsys.readouterr()
    assert out.count("no wear rates in the index") == 2
    spec = SweepSpec(scenario=SCENARIOS / "paper_3000rpm.toml", axes=[(CLEARANCE, [0.18, 0.22])])
    run_sweep(spec, folder, engine=LocalEngine(1), figures=False, progress=False)
    new, _ = read_index(folder / "sweep.h5")
    assert list(new["case"]) == list(old["case"]) and list(new["status"]) == ["done", "done"]
    for k in ("I_dec_mean_Ns", "I_acc_mean_Ns", "first_impact_speed_m_s", "load_zone_half_angle_deg"):
        np.testing.assert_array_equal(new[k], old[k])
    assert np.all(new["wear_rear_mean_m3_h"] > 0)
