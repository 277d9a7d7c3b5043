"""Archive format: atomic write, units on physical datasets, provenance, and clear errors on bad files."""
import h5py
import numpy as np
import pytest

from bearingsim.archive import ArchiveWriter, describe, open_archive
from bearingsim.errors import UserError
from bearingsim.scenario import resolve


def _write(path, scenario, fail=False):
    with ArchiveWriter(path, scenario, {"dt_s": 1e-6}) as aw:
        aw.write_array("results/per_rotation/I_dec", np.ones((3, 2)), unit="N s")
        aw.set_attrs("results/summary", {"I_dec_mean_Ns": 1.0}, units={"I_dec_mean_Ns": "N s"})
        ts = aw.timeseries("cage_angular_speed", (), unit="rad/s")
        for k in range(10000):  # more than one buffered block: streamed, not held
            ts.append(k, k * 1e-6, 100.0 + k)
        if fail:
            raise RuntimeError("simulated crash mid-run")


def test_complete_archive_has_header_scenario_provenance_units(tmp_path, base_reduced):
    sc = resolve(base_reduced)
    path = tmp_path / "a.h5"
    _write(path, sc)
    with open_archive(path) as f:
        assert f["h5md/creator"].attrs["name"] == "bearingsim"
        assert f["bearingsim"].attrs["complete"]
        assert "pocket_clearance_mm = 0.2" in f["scenario"][()].decode()
        prov = f["provenance"].attrs
        for key in ("bearingsim_version", "git_commit", "created_utc", "wall_time_s", "version_numpy",
                    "version_pymunk", "version_h5py", "dt_s"):
            assert key in prov, key
        ts = f["observables/cage_angular_speed"]
        assert ts["value"].shape == (10000,) and ts["value"][-1] == 100.0 + 9999
        assert ts["value"].attrs["unit"] == "rad/s" and ts["time"].attrs["unit"] == "s"
        assert f["results/per_rotation/I_dec"].attrs["unit"] == "N s"
    # The stored scenario reproduces the run's inputs exactly.
    import tomllib

    with open_archive(path) as f:
        again = resolve(tomllib.loads(f["scenario"][()].decode()))
    assert again.raw == sc.raw
    text = describe(path)
    assert "I_dec_mean_Ns" in text and "/results/per_rotation/I_dec" in text


def test_crash_leaves_no_archive_and_keeps_previous_file(tmp_path, base_reduced):
    sc = resolve(base_reduced)
    path = tmp_path / "a.h5"
    _write(path, sc)
    before = path.read_bytes()
    with pytest.raises(RuntimeError):
        _write(path, sc, fail=True)
    assert path.read_bytes() == before  # nothing lost
    assert [p.name for p in tmp_path.iterdir()] == ["a.h5"]  # no temporary left behind


def test_unwritable_output_is_a_user_error_before_running(tmp_path, base_reduced):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(UserError, match="file"):
        ArchiveWriter(blocker / "sub" / "a.h5", resolve(base_reduced))


def test_foreign_truncated_and_incomplete_files_are_refused(tmp_path, base_reduced):
    text = tmp_path / "t.h5"
    text.write_text("not hdf5")
    with pytest.raises(UserError, match="not an HDF5 file"):
        open_archive(text)
    foreign = tmp_path / "f.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = 1
    with pytest.raises(UserError, match="not a bearingsim archive"):
        open_archive(foreign)
    good = tmp_path / "g.h5"
    _write(good, resolve(base_reduced))
    cut = tmp_path / "cut.h5"
    cut.write_bytes(good.read_bytes()[:2000])
    with pytest.raises(UserError):
        open_archive(cut)
    incomplete = tmp_path / "i.h5"
    incomplete.write_bytes(good.read_bytes())
    with h5py.File(incomplete, "r+") as f:
        f["bearingsim"].attrs["complete"] = False
    with pytest.raises(UserError, match="incomplete"):
        open_archive(incomplete)
    with pytest.raises(UserError, match="not found"):
        open_archive(tmp_path / "missing.h5")
