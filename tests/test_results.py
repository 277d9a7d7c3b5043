"""Results as objects: a result travels between processes as it is (pickle), as a scenario does."""
import multiprocessing
import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import bearingsim
from bearingsim.compare import compare_results

from .conftest import SCENARIOS


def _short_scenarios():
    """Two one-rotation reduced-model cases (about a second each)."""
    sc = bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml", set={"numerics.rotations": 1})
    return [sc, sc.replace(**{"operating.inner_ring_speed_rpm": 1000.0})]


def _same(a, b) -> None:
    assert type(a) is type(b)
    assert a.scenario == b.scenario
    assert compare_results(a, b).identical
    assert a.data.keys() == b.data.keys()
    for k, v in a.data.items():
        assert np.array_equal(v.data, b.data[k].data) and v.unit == b.data[k].unit, k
    assert a.groups == b.groups


def test_result_pickles_and_round_trips_equal(tmp_path):
    sc = _short_scenarios()[0]
    r = bearingsim.run(sc)
    _same(pickle.loads(pickle.dumps(r)), r)
    loaded = bearingsim.load(r.save(tmp_path / "r.h5"))  # a result read from an archive too
    back = pickle.loads(pickle.dumps(loaded))
    _same(back, loaded)
    assert repr(back.provenance) == repr(loaded.provenance)  # dt_s may be nan (not equal to itself)


@pytest.mark.slow
def test_run_maps_over_a_process_pool():
    """``ProcessPoolExecutor().map(bearingsim.run, scenarios)`` on the public API (spawned workers: the
    scenarios go out and the results come back through pickle alone)."""
    scenarios = _short_scenarios()
    ex = ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn"))
    try:
        results = list(ex.map(bearingsim.run, scenarios, timeout=300))
    except BaseException:
        for proc in list((ex._processes or {}).values()):  # a stuck worker is ended, whatever happened
            proc.kill()
        raise
    finally:
        ex.shutdown(wait=True, cancel_futures=True)
    assert [r.scenario for r in results] == scenarios
    for r, sc in zip(results, scenarios):
        _same(r, bearingsim.run(sc))  # what a run in this process gives, bit for bit


def test_a_title_in_a_script_the_font_lacks_gives_no_warnings(tmp_path):
    """Issue 30, Low: a scenario named in CJK printed matplotlib's "Glyph ... missing from font(s)"
    warning for every character and layout pass. The figure is written (the missing glyphs drawn as
    boxes) without them. A private-use character stands for a glyph no font has."""
    import warnings

    from bearingsim.plotting import subplots, save_figure

    fig, ax = subplots()
    ax.set_title("name \ue000\ue001")
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        save_figure(fig, tmp_path / "f.png")
    assert [str(w.message) for w in seen if "Glyph" in str(w.message)] == []
    assert (tmp_path / "f.png").read_bytes().startswith(b"\x89PNG")


_BACKEND_SCRIPT = """
import sys
import matplotlib
matplotlib.use("svg")  # a backend the user chose (a notebook's inline one, a GUI's)
import bearingsim
r = bearingsim.run(bearingsim.load_scenario(PAPER))
names = sorted(r.figures())
written = r.save_figures(STEM)
print(matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules, len(names) == len(written) > 0)
"""


@pytest.mark.slow
def test_figures_leave_the_users_matplotlib_backend_alone(tmp_path):
    """Issue 29, item 4: importing bearingsim's plotting switched matplotlib to Agg for the whole process
    (``matplotlib.use("Agg")``) and drew through pyplot. Figures are now Figure objects with their own
    Agg canvas: the user's backend stays, pyplot is not even imported, and the PNGs are written."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = str(Path(__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": root + os.pathsep + os.environ.get("PYTHONPATH", "")}
    script = _BACKEND_SCRIPT.replace("PAPER", repr(str(SCENARIOS / "paper_3000rpm.toml"))).replace(
        "STEM", repr(str(tmp_path / "r")))
    res = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300, env=env)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["svg", "False", "True"], res.stdout
    assert all(p.read_bytes().startswith(b"\x89PNG") for p in tmp_path.glob("r_*.png"))


def test_save_figures_makes_missing_folders_as_save_does(tmp_path):
    """``save_figures`` into a folder that did not exist failed with a raw FileNotFoundError naming its
    temporary file (``.stem_pass.png.tmp-<pid>``), where ``save`` makes the folders: it makes them too, and a
    folder that cannot be made (a file in the way) is one ``bearingsim.UserError`` naming it, nothing written."""
    r = bearingsim.run(_short_scenarios()[0])
    written = r.save_figures(tmp_path / "new" / "deeper" / "run")
    assert written == [tmp_path / "new" / "deeper" / f"run_{name}.png" for name in r.FIGURES]
    assert all(p.read_bytes().startswith(b"\x89PNG") for p in written)
    (tmp_path / "file").write_text("mine\n")
    with pytest.raises(bearingsim.UserError) as err:
        r.save_figures(tmp_path / "file" / "sub" / "run")
    folder, file = tmp_path / "file" / "sub", tmp_path / "file"
    assert str(err.value) == f"{folder}: cannot create the output folder ({file} is not a folder)"
    assert sorted(p.name for p in tmp_path.rglob("*")) == sorted(["new", "deeper", "file", *(p.name for p in written)])


def test_get_of_a_name_the_result_lacks_is_one_user_error_naming_what_it_has():
    """``r.get("nope")`` raised a bare ``KeyError: 'results/nope'``; a name of the caller's that is not there is
    one ``bearingsim.UserError`` line (docs/usage.md) naming it, the closest names and every array there is."""
    r = bearingsim.run(_short_scenarios()[0])
    assert np.shares_memory(r.get("trace/theta_deg"), r.data["results/trace/theta_deg"].data)  # a view of it
    for name, words in (("nope", ["get('nope'): no array results/nope in this reduced result; its arrays: "
                                  "per_rotation/{I_dec, I_acc}, impacts/{time_s, "]),
                        ("trace/theta", ["(did you mean trace/theta_deg "]),
                        (3, ["get(3): expected the name of an array under results/ (a str), got int"])):
        with pytest.raises(bearingsim.UserError) as err:
            r.get(name)
        text = str(err.value)
        assert "\n" not in text and all(w in text for w in words), text


def test_save_over_an_archive_of_another_scenario_needs_force(tmp_path):
    """``Result.save(path)`` replaced an archive of a different scenario silently, where ``bearingsim run -o``
    refuses it without ``--force``; it refuses the same way, naming the file, the keys that differ and
    ``force=True``, and writes nothing. The same scenario is replaced (saving again), and ``force=True``
    replaces the other."""
    path = tmp_path / "a.h5"
    sc = bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml")
    first = bearingsim.run(sc)
    first.save(path)
    first.save(path)  # the same scenario: replaced
    before = path.read_bytes()
    other = bearingsim.run(sc.replace(**{"operating.radial_load_N": 1500.0}))
    with pytest.raises(bearingsim.UserError) as info:
        other.save(path)
    msg = str(info.value)
    assert msg.startswith(f"{path}: holds the run of a different scenario (operating.radial_load_N 970")
    assert msg.endswith("not replaced: give another path, or save(..., force=True) to replace it"), msg
    assert path.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["a.h5"]
    other.save(path, force=True)
    assert bearingsim.load(path).scenario == other.scenario
    with pytest.raises(bearingsim.UserError, match="force: expected True or False"):
        other.save(path, force="yes")


def test_a_scenario_that_differs_only_in_keys_its_model_does_not_read_replaces_its_archive(tmp_path):
    """``bearingsim run paper_3000rpm.toml --set multibody.raceway_contact=rigid`` noted that the key has no effect
    on the reduced run, then refused to replace the archive of the file's own run as "a different scenario": the
    same run. A scenario of the same model (and reduced method) that differs only in keys the model does not read
    replaces it; one key it reads among them, or another method, is refused as before."""
    path = tmp_path / "a.h5"
    sc = bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml")
    bearingsim.run(sc).save(path)
    unread = sc.replace(**{"multibody.raceway_contact": "rigid", "multibody.scene": "centred_cage"})
    bearingsim.run(unread).save(path)  # replaced: the same run
    assert bearingsim.load(path).scenario == unread
    for other in (unread.replace(**{"operating.radial_load_N": 1500.0}), sc.replace(**{"reduced.method": "euler"})):
        with pytest.raises(bearingsim.UserError, match="holds the run of a different scenario"):
            bearingsim.run(other).save(path)
    # the reduced model's method is a key the whole bearing does not read (bearingsim.scenario.unused_keys)
    from bearingsim.archive import _unread_by_both

    mb = bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml")
    assert _unread_by_both(mb, mb.replace(**{"reduced.method": "euler"}), ["reduced.method"])
    assert not _unread_by_both(sc, sc.replace(**{"reduced.method": "euler"}), ["reduced.method"])


def _short_run_of(model: str):
    """A short scenario of ``model``: the first of :func:`_short_scenarios`, or one rotation of the 3000 rpm whole
    bearing on rigid raceways."""
    if model == "reduced":
        return _short_scenarios()[0]
    return bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml", set={
        "multibody.raceway_contact": "rigid", "numerics.rotations": 1})


@pytest.mark.parametrize("model", ["reduced", "multibody"])
def test_the_arrays_a_result_hands_out_are_read_only(tmp_path, model):
    """``a = r.per_rotation["I_dec"]; a *= 1e3`` changed the result in place: its summary no longer agreed with
    it and its archive held the changed numbers (``bearingsim rerun`` then called it different). The arrays of
    ``per_rotation``, ``impacts`` and ``get`` are read-only, of a run and of an archive read back, and computing
    from them gives new arrays; so are those the result holds (``r.data[...].data``, and the time series of
    ``r.series``, docs/dataframes.md)."""
    r = bearingsim.run(_short_run_of(model))
    before = r.summary["I_dec_mean_Ns"]
    for result in (r, bearingsim.load(r.save(tmp_path / "r.h5"))):
        arrays = [result.per_rotation["I_dec"], result.get("per_rotation/I_acc"), result.impacts["time_s"],
                  result.data["results/per_rotation/I_dec"].data]
        arrays += [a for s in result.series.values() for a in (s.step, s.time, s.value)]
        assert len(arrays) > 4 or model == "reduced"  # a multibody run keeps its bodies' motion (r.series)
        for a in arrays:
            kept = a.copy()
            with pytest.raises(ValueError, match="read-only"):
                a *= 2
            with pytest.raises(ValueError, match="read-only"):
                a[...] = 0
            assert np.array_equal(a, kept) and np.array_equal(a * 1e3, kept * 1e3)
        assert np.mean(result.per_rotation["I_dec"]) == pytest.approx(before, rel=1e-12, abs=0)
    assert bearingsim.load(tmp_path / "r.h5").summary["I_dec_mean_Ns"] == before


@pytest.mark.parametrize("model", ["reduced", "multibody"])
def test_a_pickled_result_keeps_its_arrays_read_only(model):
    """A result back from ``ProcessPoolExecutor().map(bearingsim.run, ...)`` comes through pickle, which rebuilt
    its arrays writable: ``r.data[...].data *= 2`` or ``r.series[...].value[:] = 0`` changed the result and the
    archive it saves. Unpickled, they are read-only as the run's."""
    r = bearingsim.run(_short_run_of(model))
    back = pickle.loads(pickle.dumps(r))
    arrays = [v.data for v in back.data.values() if isinstance(v.data, np.ndarray)]
    arrays += [a for s in back.series.values() for a in (s.step, s.time, s.value)]
    assert len(arrays) > 4 and (model == "reduced" or back.series)
    for a in arrays:
        with pytest.raises(ValueError, match="read-only"):
            a[...] = 0
    _same(back, r)


@pytest.mark.parametrize("model", ["reduced", "multibody"])
def test_the_groups_a_result_hands_out_are_read_only(tmp_path, model):
    """``r.summary`` was a fresh dict, but ``r.groups["results/summary"].attrs`` was the dict it is read from:
    ``attrs["I_dec_mean_Ns"] = 99.0`` changed the summary and the archive ``save()`` wrote. The values and units
    of every group are read-only (a TypeError saying so), of a run, of an archive read back and of a result back
    through pickle (which still pickles), as its arrays are; ``dict(...)`` of them is a copy to change."""
    r = bearingsim.run(_short_run_of(model))
    summary, units = r.summary, r.summary_units
    path = tmp_path / "r.h5"
    for result in (r, bearingsim.load(r.save(path)), pickle.loads(pickle.dumps(r))):
        assert result.groups.keys() == r.groups.keys() and "results/summary" in result.groups
        for name, group in result.groups.items():
            for values in (group.attrs, group.units):
                key = next(iter(values), "x")
                with pytest.raises(TypeError, match="read-only"):
                    values[key] = 99.0
                with pytest.raises(TypeError):
                    del values[key]
                assert not any(hasattr(values, m) for m in ("update", "pop", "setdefault", "clear", "popitem"))
            assert group.attrs == r.groups[name].attrs and group.units == r.groups[name].units, name
        copy = dict(result.groups["results/summary"].attrs)
        copy["I_dec_mean_Ns"] = 99.0  # a copy changes; the result does not
        assert result.summary == summary and result.summary_units == units
        assert pickle.loads(pickle.dumps(result)).summary == summary
    assert bearingsim.load(path).summary == summary


def test_assigning_a_result_what_is_not_a_mapping_is_one_line_naming_the_attribute():
    """``r.provenance = None``, ``r.groups = None`` or ``r.series = 3`` ended in an AttributeError (``.items``)
    inside the setter, and ``r.groups = {"a": 1}`` in one of ``.attrs``: a user's mistake with a traceback that
    names no attribute. Each is a one-line :class:`bearingsim.UserError` naming the attribute (and the entry) and
    what it takes; the result is left as it was, and a mapping of the right kind is still taken."""
    r = bearingsim.run(_short_scenarios()[0])
    before = (dict(r.provenance), dict(r.groups), dict(r.series))
    cases = [("provenance", None, "Result.provenance: expected a mapping of names to values, such as a dict "
              "(got NoneType)"),
             ("groups", None, "Result.groups: expected a mapping of names to attribute groups, such as a dict "
              "(got NoneType)"),
             ("series", 3, "Result.series: expected a mapping of names to time series, such as a dict (got int)"),
             ("groups", {**r.groups, "a": 1}, "Result.groups['a']: expected a bearingsim.datatypes.AttrGroup "
              "(got int)"),
             ("series", {"x": np.zeros(3)}, "Result.series['x']: expected a bearingsim.datatypes.Series "
              "(got ndarray)")]
    for name, value, words in cases:
        with pytest.raises(bearingsim.UserError) as info:
            setattr(r, name, value)
        assert str(info.value) == words and "\n" not in str(info.value)
    assert (dict(r.provenance), dict(r.groups), dict(r.series)) == before
    r.provenance = {**r.provenance, "note": "by hand"}
    assert r.provenance["note"] == "by hand"


def test_a_value_an_archive_cannot_store_is_refused_by_save_before_anything_is_written(tmp_path):
    """``r.provenance`` was a plain dict: ``r.provenance["note"] = object()`` made ``r.save(path)`` fail with h5py's
    own TypeError (``Object dtype dtype('O') has no native HDF5 equivalent``). The provenance is read-only, as the
    rest of the result, of a run, of an archive read back and through pickle; a value an archive cannot store given
    another way (assigned to ``r.provenance`` or ``r.groups``) is refused by ``save()`` in one line naming where it
    is and its type, before anything is written: no archive, no temporary, no folder, and the archive already at
    the path kept as it was. What an archive stores (texts, numbers, arrays of them) still saves and reads back."""
    from dataclasses import replace

    r = bearingsim.run(_short_scenarios()[0])
    kept = r.save(tmp_path / "kept.h5")
    before = kept.read_bytes()
    for result in (r, pickle.loads(pickle.dumps(r)), bearingsim.load(kept)):
        assert result.provenance["solver"] == r.provenance["solver"]
        with pytest.raises(TypeError, match="read-only"):
            result.provenance["note"] = "by hand"
        with pytest.raises(TypeError, match="read-only"):
            del result.provenance["solver"]
        assert not any(hasattr(result.provenance, m) for m in ("update", "pop", "setdefault", "clear"))
    summary = r.groups["results/summary"]
    cases = [("provenance", {**r.provenance, "note": object()}, "provenance['note']", "object"),
             ("provenance", {**r.provenance, "dt_s": None}, "provenance['dt_s']", "NoneType"),
             ("groups", {**r.groups, "results/summary": replace(summary, attrs={**summary.attrs, "extra": {"a": 1}})},
              "groups['results/summary'].attrs['extra']", "dict")]
    for name, value, where, kind in cases:
        bad = pickle.loads(pickle.dumps(r))
        setattr(bad, name, value)
        for target in (tmp_path / "new" / "a.h5", kept):
            with pytest.raises(bearingsim.UserError) as info:
                bad.save(target)
            assert str(info.value) == (f"save(): {where}: expected a str, bool, int, float or an array of numbers or "
                                       f"texts, which an archive stores (got {kind})")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.h5"] and kept.read_bytes() == before
    r.provenance = {**r.provenance, "note": "by hand", "pair": np.array([1, 2]), "names": ["a", "b"]}
    back = bearingsim.load(r.save(tmp_path / "noted.h5"))
    assert back.provenance["note"] == "by hand" and list(back.provenance["pair"]) == [1, 2]
    assert list(back.provenance["names"]) == ["a", "b"] and back.summary == r.summary


def test_an_array_of_texts_saves_and_one_too_large_for_an_attribute_is_refused_before_anything_is_written(tmp_path):
    """``check_storable`` said an array of numpy's texts (``np.array(["a", "b"])``) was not "an array of numbers or
    texts" ("(got ndarray)"), though a list of the same texts saves; and it let an array larger than an HDF5
    attribute holds through, so that ``save()`` failed mid-write with "cannot write archive (write failed)", as if
    the disk had. The array of texts is stored as the list is (read back as texts); the large array is refused in
    one line giving its size, nothing written."""
    r = bearingsim.run(_short_scenarios()[0])
    r.provenance = {**r.provenance, "names": np.array(["a", "bb"]), "grid": np.array([["x"], ["y"]])}
    back = bearingsim.load(r.save(tmp_path / "texts.h5"))
    assert list(back.provenance["names"]) == ["a", "bb"] and back.provenance["grid"].tolist() == [["x"], ["y"]]
    r.provenance = {**r.provenance, "big": np.zeros(20000)}
    with pytest.raises(bearingsim.UserError) as info:
        r.save(tmp_path / "big.h5")
    assert str(info.value) == ("save(): provenance['big']: expected a str, bool, int, float or an array of numbers or "
                               "texts of less than 64 KiB, which an archive's attribute holds (got an array of float64 "
                               "of 160000 bytes)")
    r.provenance = {**r.provenance, "big": np.array(["2020-01-01"], dtype="M8[D]")}
    with pytest.raises(bearingsim.UserError, match=r"\(got an array of datetime64\[D\]\)$"):
        r.save(tmp_path / "big.h5")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["texts.h5"]


def test_a_result_read_with_part_of_its_arrays_says_so_and_is_not_saved(tmp_path):
    """``simulation.load(path, only=...)`` reads some arrays: saving that result wrote an archive without the others
    (over its own archive, of the same scenario, without force), which every reader then called damaged; its
    frames were a StopIteration or silently empty, its figures a KeyError. Each is one line naming the array not
    read, the archive and how to read it whole; nothing is written."""
    from bearingsim import simulation

    r = bearingsim.run(_short_scenarios()[0])
    path = r.save(tmp_path / "r.h5")
    before = path.read_bytes()
    part = simulation.load(path, only=("results/per_rotation",))
    assert part.per_rotation["I_dec"].shape == r.per_rotation["I_dec"].shape  # what was read is there
    calls = [("save()", lambda: part.save(path)), ("save()", lambda: part.save(tmp_path / "other.h5")),
             ("to_dataframe('impacts')", lambda: part.to_dataframe("impacts")),
             ("get('trace/theta_deg')", lambda: part.get("trace/theta_deg")),
             ("impacts['time_s']", lambda: part.impacts["time_s"]),
             ("plot_pass()", lambda: part.plot_pass())]  # it said "no trace recorded"
    for what, call in calls:
        with pytest.raises(bearingsim.UserError) as info:
            call()
        msg = str(info.value)
        assert msg.startswith(f"{what}: this result was read from {path} without results/") and "\n" not in msg, msg
        assert msg.endswith(f"bearingsim.load({str(path)!r}) reads every array"), msg
    assert path.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]
    with pytest.raises(KeyError):  # a name the archive does not hold is what it was
        part.per_rotation["nothing"]
    whole = simulation.load(path, only=simulation.COMPARED)  # every array: a whole result
    assert whole.partial is None and whole.save(tmp_path / "again.h5").exists()


def test_a_figure_of_a_result_read_without_its_arrays_names_them(tmp_path):
    from bearingsim import simulation

    sc = bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml", set={
        "multibody.raceway_contact": "rigid", "numerics.rotations": 1, "output.motion_rotations": 0})
    path = bearingsim.run(sc).save(tmp_path / "m.h5")
    part = simulation.load(path, only=("results/impacts",))
    for name in part.FIGURES:
        with pytest.raises(bearingsim.UserError, match=f"this result was read from {path} without results/"):
            getattr(part, f"plot_{name}")()


def test_a_sink_used_again_holds_only_the_new_runs_series():
    """A ``MemorySink`` given to a second run kept the series of the first that the second did not record: a run
    with ``output.motion_rotations = 0`` came back (and saved its archive) with the first run's bodies' motion.
    Each run's result holds its own series, as with a new sink; the first result keeps its own."""
    from bearingsim.results import MemorySink

    sc = bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml", set={
        "multibody.raceway_contact": "rigid", "numerics.rotations": 1})
    without = sc.replace(**{"output.motion_rotations": 0})
    sink = MemorySink()
    first = bearingsim.run(sc, sink=sink)
    kept = {k: s.value.copy() for k, s in first.series.items()}
    second = bearingsim.run(without, sink=sink)
    assert any(k.startswith("motion_") for k in kept)
    assert sorted(second.series) == sorted(bearingsim.run(without).series)
    assert not any(k.startswith("motion_") for k in second.series)
    assert kept.keys() == first.series.keys() and all(np.array_equal(first.series[k].value, v) for k, v in kept.items())
