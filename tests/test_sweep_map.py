"""A product sweep's cases as one labelled dataset (issue 29, item 2): ``map.h5`` holds the index's
numbers as arrays over the axes, readable by xarray without bearingsim; reduced-model cases keep no
archive unless asked (``--archives all``), and a sweep resumes from its index rows, trusting a row
only when its model version is the current one."""
import math
import os
import signal

import h5py
import numpy as np
import pytest

import bearingsim
from bearingsim.model_versions import MODEL_VERSIONS
from bearingsim.scenario import load_scenario
from bearingsim.simulation import run as simulate
from bearingsim.sweeps import LocalEngine, SweepSpec, read_index, read_map, run_sweep
from bearingsim.sweeps.worker import keeps_archive

from .conftest import SCENARIOS
from .test_cli import assert_user_error, bearingsim as cli

BASE = SCENARIOS / "paper_3000rpm.toml"
SPEED = "operating.inner_ring_speed_rpm"
DRAG = "lubrication.drag_coefficient"
GUIDE = "bearing.cage_guidance"


def _same(a, b):
    """Equal arrays, NaN in the same places (bit for bit: float64 in both files)."""
    np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


def test_map_holds_the_index_numbers_over_the_axes(tmp_path):
    """Without drag and gravity a run has no rear-face impact, which only the finished run shows: a failed
    cell, NaN in every quantity. Every other cell is the single run's number, bit for bit, and the index's
    number at that case."""
    spec = SweepSpec(scenario=BASE, sets=["operating.gravity=false"], axes=[(SPEED, [1000, 2000, 3000]),
                                                                            (DRAG, [0.02, 0.0])])
    out = run_sweep(spec, tmp_path, engine=LocalEngine(2), figures=False, progress=False)
    assert out.map == tmp_path / "map.h5"
    assert not (tmp_path / "cases").exists() and all(r["archive"] == "" for r in out.rows)  # no reduced archive
    m = read_map(tmp_path)
    assert m.dims == [SPEED, DRAG] and m.shape == (3, 2)
    _same(m.coords[SPEED], [1000.0, 2000.0, 3000.0])
    _same(m.coords[DRAG], [0.02, 0.0])
    cols, meta = read_index(tmp_path / "sweep.h5")
    summary = [c for c in meta["columns"] if c not in ("case", SPEED, DRAG, "status", "error", "archive", "notes")]
    assert {"I_dec_mean_Ns", "I_acc_mean_Ns", "I_dec_sem_Ns", "first_impact_speed_m_s", "wall_s",
            "model_version"} <= set(summary)
    for k in summary:
        assert m[k].shape == (3, 2) and m[k].dtype == np.float64
        _same(m[k].ravel(), cols[k])
    _same(m["status"].ravel(), [str(s) for s in cols["status"]])
    _same(m["case"].ravel(), [str(c) for c in cols["case"]])
    assert list(m["status"][:, 1]) == ["failed"] * 3 and list(m["status"][:, 0]) == ["done"] * 3
    assert np.isnan(m["I_dec_mean_Ns"][:, 1]).all() and np.isnan(m["model_version"][:, 1]).all()
    assert (m["model_version"][:, 0] == MODEL_VERSIONS["reduced"]).all()
    for i, rpm in enumerate((1000, 2000, 3000)):
        run = simulate(load_scenario(BASE, ["operating.gravity=false", f"{SPEED}={rpm}", f"{DRAG}=0.02"])).summary
        assert m["I_dec_mean_Ns"][i, 0] == run["I_dec_mean_Ns"] and m["I_acc_mean_Ns"][i, 0] == run["I_acc_mean_Ns"]
    assert m.units[SPEED] == "rpm" and m.units[DRAG] == "N^0.754 (s/m)^0.648" and m.units["I_dec_mean_Ns"] == "N s"
    assert m.units["first_impact_speed_m_s"] == "m/s" and m.long_names[SPEED] == "inner ring speed"
    assert m.attrs["bearingsim_version"] == bearingsim.__version__
    assert m.attrs["scenario"] == load_scenario(BASE, ["operating.gravity=false"]).to_toml()


def test_xarray_reads_the_map_with_text_axes(tmp_path):
    """xarray opens ``map.h5`` with its own netCDF reader (h5netcdf): dims named after the axes,
    coordinates the swept values (a text key as strings), the same numbers and units as
    :func:`read_map`; ``SweepMap.to_xarray()`` builds the same Dataset."""
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000]), (GUIDE, ["rollers", "outer_land", "inner_land"])])
    run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    m = read_map(tmp_path / "map.h5")
    with xr.open_dataset(tmp_path / "map.h5", engine="h5netcdf") as ds:
        assert list(ds.dims) == [SPEED, GUIDE] and ds["I_dec_mean_Ns"].dims == (SPEED, GUIDE)
        _same(ds[SPEED].values, [1000.0, 2000.0])
        assert list(ds[GUIDE].values) == ["rollers", "outer_land", "inner_land"]
        assert ds["I_dec_mean_Ns"].attrs["units"] == "N s" and ds[SPEED].attrs["units"] == "rpm"
        assert "units" not in ds[GUIDE].attrs and ds.attrs["scenario"] == m.attrs["scenario"]
        for k, v in m.data.items():
            _same(ds[k].values, v)
        mine = m.to_xarray()
        assert list(mine.dims) == list(ds.dims) and set(mine.data_vars) == set(ds.data_vars)
        for k in ds.variables:
            _same(mine[k].values, ds[k].values)
            assert mine[k].attrs == ds[k].attrs
    # the reduced model does not use the cage guidance: one value per speed, whatever the guidance
    assert (m["I_dec_mean_Ns"] == m["I_dec_mean_Ns"][:, :1]).all()


class _InterruptedAfterFirstBatch(LocalEngine):
    """A local engine that receives SIGINT right after the first finished batch is handed over."""

    def run(self, batches, cases_dir, *args):
        for records in super().run(batches, cases_dir, *args):
            yield records
            os.kill(os.getpid(), signal.SIGINT)


def test_interrupted_sweep_without_archives_resumes_only_missing_cases(tmp_path):
    """Four cases on one worker go in batches of one; SIGINT after the first: one row done, three
    pending (NaN in the map). Run again, the done row is taken from the index (``cached``, its wall
    time the first run's: it did not run again) and only the three others run."""
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000, 3000, 4000])])
    first = run_sweep(spec, tmp_path, engine=_InterruptedAfterFirstBatch(1), figures=False, progress=False)
    assert first.interrupted == signal.SIGINT
    assert [r["status"] for r in first.rows] == ["done", "pending", "pending", "pending"]
    m = read_map(tmp_path)
    assert list(m["status"]) == ["done", "pending", "pending", "pending"]
    assert math.isfinite(m["I_dec_mean_Ns"][0]) and np.isnan(m["I_dec_mean_Ns"][1:]).all()

    again = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert [r["status"] for r in again.rows] == ["cached", "done", "done", "done"]
    assert again.rows[0]["wall_s"] == first.rows[0]["wall_s"]
    assert again.rows[0]["summary"]["I_dec_mean_Ns"] == first.rows[0]["summary"]["I_dec_mean_Ns"]
    assert again.rows[0]["model_version"] == MODEL_VERSIONS["reduced"]
    assert not (tmp_path / "cases").exists()
    _same(read_map(tmp_path)["I_dec_mean_Ns"], read_index(tmp_path / "sweep.h5")[0]["I_dec_mean_Ns"])


def test_rows_of_another_model_version_are_stale(tmp_path, monkeypatch):
    """A row whose numbers another model version computed (or an index that recorded none) is not
    trusted: the case runs again and its row says ``stale``; the numbers are the same (the model did
    not change here), and a third run takes every row."""
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000, 3000])])
    first = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    with h5py.File(tmp_path / "sweep.h5", "a") as f:
        v = f["index/model_version"][()]
        v[1], v[2] = MODEL_VERSIONS["reduced"] + 1, np.nan  # another version's row; a row without one
        f["index/model_version"][...] = v
    again = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert [r["status"] for r in again.rows] == ["cached", "stale", "stale"]
    assert list(read_map(tmp_path)["status"]) == ["cached", "stale", "stale"]
    for a, b in zip(first.rows, again.rows):
        assert a["summary"]["I_dec_mean_Ns"] == b["summary"]["I_dec_mean_Ns"]
    third = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert [r["status"] for r in third.rows] == ["cached"] * 3
    # the model's version bumped (as a change that moves numbers does): no row is trusted
    monkeypatch.setitem(MODEL_VERSIONS, "reduced", MODEL_VERSIONS["reduced"] + 1)
    fourth = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert [r["status"] for r in fourth.rows] == ["stale"] * 3


def test_archives_all_writes_every_archive_with_the_same_numbers(tmp_path):
    res = cli("sweep", BASE, "--param", f"{SPEED}=1000,2000", "-o", tmp_path / "all", "--archives", "all",
              "-j", "1", "--no-plots")
    assert res.returncode == 0, res.stderr
    assert "map.h5" in res.stdout
    res = cli("sweep", BASE, "--param", f"{SPEED}=1000,2000", "-o", tmp_path / "none", "-j", "1", "--no-plots", "-q")
    assert res.returncode == 0, res.stderr
    assert not (tmp_path / "none" / "cases").exists()
    kept, _ = read_index(tmp_path / "all" / "sweep.h5")
    bare, _ = read_index(tmp_path / "none" / "sweep.h5")
    assert list(kept["archive"]) == [f"cases/{h}.h5" for h in kept["case"]] and list(bare["archive"]) == ["", ""]
    for i, h in enumerate(kept["case"]):
        assert bearingsim.load(tmp_path / "all" / "cases" / f"{h}.h5").summary["I_dec_mean_Ns"] == kept["I_dec_mean_Ns"][i]
    _same(read_map(tmp_path / "all")["I_dec_mean_Ns"], read_map(tmp_path / "none")["I_dec_mean_Ns"])
    # a folder swept with archives resumes without them from its archives, and the other way round
    again = run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])]), tmp_path / "all",
                      engine=LocalEngine(1), figures=False, progress=False)
    assert [(r["status"], r["archive"]) for r in again.rows] == [("cached", f"cases/{h}.h5") for h in kept["case"]]
    assert keeps_archive("multibody", "auto") and not keeps_archive("reduced", "auto")
    assert keeps_archive("reduced", "all") and not keeps_archive("multibody", "none")


def test_inspect_show_and_table_of_a_map_folder(tmp_path):
    """``inspect map.h5`` says what it is (axes, variables, units), ``show map.h5`` prints the base
    scenario it stores, and the index's ``model_version`` is bookkeeping, not a number of the table."""
    run_sweep(SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])]), tmp_path, engine=LocalEngine(1), figures=False,
              progress=False)
    res = cli("inspect", tmp_path / "map.h5")
    assert res.returncode == 0, res.stderr
    assert "bearingsim sweep map" in res.stdout and f"{SPEED} [rpm]: 2 values, 1000, 2000" in res.stdout
    assert any(line.split()[:1] == ["I_dec_mean_Ns"] and line.rstrip().endswith("N s") for line in res.stdout.splitlines())
    res = cli("show", tmp_path / "map.h5")
    assert res.returncode == 0 and res.stdout == load_scenario(BASE).to_toml()
    assert_user_error(cli("table", tmp_path, "--columns", "model_version"), "model_version")
    # plot of map.h5 said "not a bearingsim archive": it says what the file is and which command draws it
    res = cli("plot", tmp_path / "map.h5")
    assert_user_error(res, "map.h5", "a sweep's map", f"bearingsim plot {tmp_path / 'sweep.h5'}")
    assert not list(tmp_path.glob("*.png"))


def test_a_user_file_named_map_h5_is_not_replaced(tmp_path):
    (tmp_path / "map.h5").write_text("mine")
    res = cli("sweep", BASE, "--param", f"{SPEED}=1000,2000", "-o", tmp_path, "-j", "1", "--no-plots")
    assert_user_error(res, "map.h5")
    assert (tmp_path / "map.h5").read_text() == "mine" and not (tmp_path / "sweep.csv").exists()


def test_a_sweep_without_a_map_removes_the_map_an_earlier_sweep_left(tmp_path):
    """A product sweep, then a zip sweep with the same cases and one more into the same folder (it resumes:
    nothing of the first is missing from it): the first's map.h5 was left, of two cases, beside the new
    index of three, and read as the folder's map; a sweep that writes no map leaves none."""
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])])
    run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert (tmp_path / "map.h5").exists()
    spec = SweepSpec(scenario=BASE, mode="zip", axes=[(SPEED, [1000, 2000])], extra=[{SPEED: 6000}])
    out = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert out.map is None and [r["status"] for r in out.rows] == ["cached", "cached", "done"]
    assert not (tmp_path / "map.h5").exists()


def test_zipped_axes_and_extra_cases_are_not_a_map(tmp_path):
    spec = SweepSpec(scenario=BASE, mode="zip", axes=[(SPEED, [1000, 2000]), ("lubrication.drag_coefficient", [0.01, 0.02])])
    out = run_sweep(spec, tmp_path, engine=LocalEngine(1), figures=False, progress=False)
    assert out.map is None and not (tmp_path / "map.h5").exists() and out.count("done") == 2
    # a product grid with an extra case: the grid in the map, the extra case in the index only
    spec = SweepSpec(scenario=BASE, axes=[(SPEED, [1000, 2000])], extra=[{SPEED: 6000}])
    out = run_sweep(spec, tmp_path / "grid", engine=LocalEngine(1), figures=False, progress=False)
    m = read_map(tmp_path / "grid")
    assert m.shape == (2,) and len(out.rows) == 3
    _same(m["I_dec_mean_Ns"], [r["summary"]["I_dec_mean_Ns"] for r in out.rows[:2]])


def test_every_summary_number_gets_its_unit_and_name_from_its_suffix():
    """A sweep over land-guided cages wrote ``land_stiffness_N_m`` into map.h5 with units "m" and long_name
    "land stiffness N", and ``land_torque_impulse_Nms`` with units "1" (the index's table headed them
    "land_stiffness_N [m]" and "land_torque_impulse_Nms"): the suffix rule knew neither "_N_m" nor "_Nms".
    Every summary number of either model reads, by its suffix, the unit its model declares."""
    from bearingsim import multibody, reduced
    from bearingsim.sweeps.index import name_of, unit_of

    declared = {**reduced.SUMMARY_UNITS, **multibody.SUMMARY_UNITS, **multibody.RIGID_SUMMARY_UNITS,
                **multibody.LAND_SUMMARY_UNITS}
    assert {k: unit_of(k) for k in declared} == declared
    assert name_of("land_stiffness_N_m") == "land stiffness"
    assert name_of("land_torque_impulse_Nms") == "land torque impulse"
