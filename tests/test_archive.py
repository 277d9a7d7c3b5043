"""Archive format: atomic write, units on physical datasets, provenance, and clear errors on bad files."""
import os
import re
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from bearingsim import archive
from bearingsim.archive import Spool, describe, open_archive
from bearingsim.errors import UserError
from bearingsim.scenario import resolve
from .forked_cli import pythonpath as _path


def _result(scenario):
    from bearingsim.datatypes import AttrGroup, NamedArray
    from bearingsim.reduced import ReducedResult

    res = ReducedResult(scenario, {"results/per_rotation/I_dec": NamedArray(np.ones((3, 2)), "N s")},
                 {"results/summary": AttrGroup({"I_dec_mean_Ns": 1.0}, {"I_dec_mean_Ns": "N s"})},
                 provenance={"dt_s": 1e-6, "wall_time_s": 0.5})
    return res


def _write(path, scenario, fail=False):
    with Spool(path) as spool:
        ts = spool.timeseries("cage_angular_speed", (), unit="rad/s")
        for k in range(10000):  # more than one buffered block: streamed, not held
            ts.append(k, k * 1e-6, 100.0 + k)
        if fail:
            raise RuntimeError("simulated crash mid-run")
        archive.write(_result(scenario), path, spool)


def test_complete_archive_has_header_scenario_provenance_units(tmp_path, base_reduced):
    sc = resolve(base_reduced)
    path = tmp_path / "a.h5"
    _write(path, sc)
    with open_archive(path) as f:
        assert f["h5md/creator"].attrs["name"] == "bearingsim"
        assert f["bearingsim"].attrs["complete"]
        assert "pocket_clearance_mm = 0.2" in f["scenario"][()].decode()
        prov = archive.group_attrs(f["provenance"])[0]
        for key in ("bearingsim_version", "git_commit", "created_utc", "wall_time_s", "version_numpy",
                    "version_pymunk", "version_h5py", "dt_s"):
            assert key in prov, key
        ts = f["observables/cage_angular_speed"]
        assert ts["value"].shape == (10000,) and ts["value"][-1] == 100.0 + 9999
        assert ts["value"].attrs["unit"] == "rad/s" and ts["time"].attrs["unit"] == "s"
        assert f["results/per_rotation/I_dec"].attrs["unit"] == "N s"
    # docs/archive.md: "Every dataset under /results and /observables has a unit attribute (1 for
    # dimensionless or counts)": the H5MD step counter too (it had none)
    with open_archive(path) as f:
        missing = []
        f.visititems(lambda name, obj: missing.append(name) if isinstance(obj, h5py.Dataset) and name.startswith(
            ("results/", "observables/")) and "unit" not in obj.attrs else None)
        assert missing == [], missing
        assert f["observables/cage_angular_speed/step"].attrs["unit"] == "1"
    # The stored scenario reproduces the run's inputs exactly.
    import tomllib

    with open_archive(path) as f:
        again = resolve(tomllib.loads(f["scenario"][()].decode()))
    assert again.raw == sc.raw
    text = describe(path)
    assert "I_dec_mean_Ns" in text and "/results/per_rotation/I_dec" in text


def test_the_h5md_header_names_an_author_from_the_environment_only(tmp_path, base_reduced, monkeypatch):
    """H5MD 1.1 requires /h5md/author with a name beside /h5md/creator; the header claimed 1.1 without it.
    The name is $BEARINGSIM_AUTHOR, else "unknown" (never the host's login name)."""
    sc = resolve(base_reduced)
    monkeypatch.delenv("BEARINGSIM_AUTHOR", raising=False)
    archive.write(_result(sc), tmp_path / "a.h5")
    monkeypatch.setenv("BEARINGSIM_AUTHOR", "  ")
    archive.write(_result(sc), tmp_path / "b.h5")
    monkeypatch.setenv("BEARINGSIM_AUTHOR", "A. Tester")
    archive.write(_result(sc), tmp_path / "c.h5")
    names = []
    for name in ("a.h5", "b.h5", "c.h5"):
        with open_archive(tmp_path / name) as f:
            assert list(f["h5md"].attrs["version"]) == [1, 1] and f["h5md/creator"].attrs["name"] == "bearingsim"
            names.append(f["h5md/author"].attrs["name"])
    assert names == ["unknown", "unknown", "A. Tester"]


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
        Spool(blocker / "sub" / "a.h5")


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


def test_the_provenance_carries_the_units_of_its_times(tmp_path, base_reduced):
    """docs/archive.md: an attribute group stores units_json for the values that have a unit; /provenance
    had none, so a reader of dt_s or wall_time_s with h5py alone got no unit. Its times are in seconds."""
    import bearingsim

    path = bearingsim.run(resolve(base_reduced)).save(tmp_path / "r.h5")
    with h5py.File(path, "r") as f:
        values, units = archive.group_attrs(f["provenance"])
    timed = [k for k, v in values.items() if k.endswith("_s") and isinstance(v, float)]
    assert "wall_time_s" in timed and {k: units.get(k) for k in timed} == {k: "s" for k in timed}
    assert "bearingsim_version" not in units and "git_commit" not in units


def test_a_fresh_result_has_the_provenance_it_reads_back_with_but_the_time_written(tmp_path, base_reduced):
    """docs/architecture.md: a fresh result and one read back have the same content. The versions, commit,
    platform and command were added only when the archive was written (13 keys missing from a fresh
    result); only ``created_utc``, the time the archive was written, is the archive's. A second save keeps
    the facts and the time of the first."""
    import bearingsim

    r = bearingsim.run(resolve(base_reduced))
    back = bearingsim.load(r.save(tmp_path / "r.h5"))
    assert set(back.provenance) - set(r.provenance) == {"created_utc"} and set(r.provenance) <= set(back.provenance)
    assert repr({k: back.provenance[k] for k in r.provenance}) == repr(r.provenance)  # dt_s is nan here
    for key in ("bearingsim_version", "git_commit", "platform", "command", "version_numpy", "model_version"):
        assert key in r.provenance, key
    again = bearingsim.load(back.save(tmp_path / "again.h5"))
    assert repr(again.provenance) == repr(back.provenance)


def test_save_makes_its_folders_replaces_an_archive_and_refuses_any_other_file(tmp_path, base_reduced):
    """Result.save as its docstring says: missing folders are made; a bearingsim archive at the path is
    replaced (by this result's: one of another scenario with force=True); a file that is not one is refused
    with one line and left as it was."""
    import bearingsim

    r = bearingsim.run(resolve(base_reduced))
    path = tmp_path / "a" / "b" / "r.h5"
    assert r.save(path) == path and bearingsim.load(path).summary == r.summary
    other = bearingsim.run(resolve({**base_reduced, "name": "other"}))
    with pytest.raises(UserError, match="holds the run of a different scenario"):
        other.save(path)
    other.save(path, force=True)
    assert bearingsim.load(path).scenario.name == "other"
    mine = tmp_path / "mine.h5"
    mine.write_text("my notes\n")
    with pytest.raises(UserError, match=r"exists and is not a bearingsim archive; not replaced \(remove it or "
                                        r"choose another path\)$"):  # the API has no -o
        r.save(mine)
    assert mine.read_text() == "my notes\n"
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a", "b", "mine.h5", "r.h5"]


def test_save_refuses_a_symbolic_link_as_figures_do(tmp_path, base_reduced):
    """``Result.save("link.h5")``, a link to an archive, replaced the link with a regular file, where a
    figure path that is a link is refused: a link at the archive path (to an archive, or to nothing) is
    refused in one line naming it, and the link and its target are left as they were."""
    import bearingsim

    r = bearingsim.run(resolve(base_reduced))
    real = r.save(tmp_path / "real.h5")
    before = real.read_bytes()
    link, dangling = tmp_path / "link.h5", tmp_path / "dangling.h5"
    link.symlink_to(real)
    dangling.symlink_to(tmp_path / "nowhere.h5")
    for target in (link, dangling):
        with pytest.raises(UserError, match="archive path is a symbolic link; not replaced") as err:
            r.save(target)
        assert str(err.value).startswith(f"{target}: ") and "\n" not in str(err.value) and target.is_symlink()
    assert real.read_bytes() == before and not (tmp_path / "nowhere.h5").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dangling.h5", "link.h5", "real.h5"]


@pytest.mark.skipif(not (Path("/proc/self").is_dir() and sys.platform.startswith("linux")),
                    reason="needs Linux's /proc, where no file can be created whoever asks")
def test_an_archive_in_a_folder_that_takes_no_file_is_refused_in_words_that_are_true(base_reduced):
    """``r.save("/proc/x.h5")`` and ``bearingsim run ... -o /proc/x.h5`` said "/proc/x.h5: output is not writable
    (No such file or directory)": as if the output had to exist to be written. Both say the same true line, the
    folder that takes no file named, the OS's reason in brackets; the run's --dry-run too; and a folder that cannot
    be made is "cannot create output folder", from both. The command exits 2; nothing is written."""
    import re

    import bearingsim

    from .conftest import SCENARIOS
    from .test_cli import assert_user_error, bearingsim as cli

    r = bearingsim.run(resolve(base_reduced))
    for out, line in (("/proc/x.h5", r"/proc/x\.h5: cannot write archive: no file can be created in /proc \([^()]+\)"),
                      ("/proc/none/x.h5", r"/proc/none/x\.h5: cannot create output folder \([^()]+\)")):
        with pytest.raises(UserError) as info:
            r.save(out)
        assert re.fullmatch(line, str(info.value)), str(info.value)
        for dry in ((), ("--dry-run",)):
            res = cli("run", SCENARIOS / "paper_3000rpm.toml", "--no-plots", "-o", out, *dry)  # refused before it runs
            assert_user_error(res, str(info.value))
            assert res.stderr == f"bearingsim: error: {info.value}\n"
    assert not Path("/proc/x.h5").exists() and not Path("/proc/none").exists()


def test_a_refused_save_leaves_no_folder_behind(tmp_path, tmp_path_factory, base_reduced):
    """Result.save made the missing folders of its path before checking the path's name, so a refused
    ``a/b/x.txt`` left ``a/b`` behind; a refusal writes nothing (as the command line's does). A folder that
    cannot be made (its parent not writable) is refused in one line and leaves nothing either."""
    import bearingsim

    r = bearingsim.run(resolve(base_reduced))
    for target in (tmp_path / "a" / "b" / "x.txt", tmp_path / "c" / "deep" / "x"):
        with pytest.raises(UserError, match="archive path must end in .h5 or .hdf5"):
            r.save(target)
    assert list(tmp_path.iterdir()) == []
    # A folder the user may not write into: root writes anywhere (CAP_DAC_OVERRIDE), and the suite runs as
    # root in CI, so there the save runs in a child under setpriv without the override capabilities
    # (test_damaged_files._obeying_file_modes), where the kernel's own refusal is what is tested.
    import subprocess
    import sys

    from . import forked_cli
    from .test_damaged_files import _obeying_file_modes

    prefix = _obeying_file_modes()
    if prefix is None:
        pytest.skip("root, and no setpriv to obey file modes: the locked-folder refusal is not checked here")
    source = r.save(tmp_path_factory.mktemp("source") / "r.h5")
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    code = ("import bearingsim, sys\ntry:\n    bearingsim.load(sys.argv[1]).save(sys.argv[2])\n"
            "except bearingsim.UserError as e:\n    print(e)\n    sys.exit(3)\n")
    try:
        res = subprocess.run([*prefix, sys.executable, "-c", code, str(source), str(locked / "new" / "x.h5")],
                             capture_output=True, text=True, env=forked_cli.environment(), timeout=300)
    finally:
        locked.chmod(0o700)
    assert res.returncode == 3, (res.returncode, res.stdout, res.stderr)
    assert res.stdout == f"{locked / 'new' / 'x.h5'}: cannot create output folder (Permission denied)\n"
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["locked"]


@pytest.mark.slow
def test_read_gives_back_the_written_result(tmp_path, base_reduced):
    """write(result) then read(path): same class, scenario, summary, arrays, units and time series."""
    import bearingsim

    sc = resolve(base_reduced)
    r = bearingsim.run(sc)
    path = r.save(tmp_path / "r.h5")
    back = bearingsim.load(path)
    assert type(back) is type(r) and back.scenario.raw == sc.raw
    assert back.summary == r.summary
    for k, v in r.data.items():
        assert np.array_equal(back.data[k].data, v.data), k
        assert back.data[k].unit == v.unit, k
    assert back.impacts["face"].tolist() == r.impacts["face"].tolist()
    assert back.provenance["solver"] == "reduced/event"
    assert back.provenance["version_pymunk"] != "not installed"


def test_memory_series_are_written_and_read_back(tmp_path, base_reduced):
    from bearingsim.datatypes import Series

    from bearingsim.results import Result

    class Bare(Result):  # _result's arrays are not a reduced run's layout, which a ReducedResult checks on read
        model = "reduced"

    res = _result(resolve(base_reduced))
    res.series["x"] = Series(np.arange(5), np.arange(5) * 1e-3, np.ones((5, 2)), "m", "a test series")
    back = archive.read(archive.write(res, tmp_path / "s.h5"), Bare)
    s = back.series["x"]
    assert s.unit == "m" and s.value.shape == (5, 2) and np.array_equal(s.step, np.arange(5))


def test_in_memory_archive_has_the_content_of_a_written_one(tmp_path, base_reduced):
    """to_bytes (the sweep worker's archive) stores what write stores: every object, value and HDF5
    type; an array-valued group value stays an attribute of its own."""
    import io

    from bearingsim.datatypes import AttrGroup

    res = _result(resolve(base_reduced))
    res.groups["results/extra"] = AttrGroup({"x": 2.0, "pair": np.array([1, 2]), "names": ["a", "b"]}, {"x": "m"})
    res.tables["results/per_rotation"] = "a table"

    def content(f):
        out = {}

        def visit(name, obj):
            for k in obj.attrs:
                if k == archive.ATTRS_JSON and name == "provenance":
                    continue  # created_utc differs
                v = obj.attrs[k]
                out[f"{name}@{k}"] = (obj.attrs.get_id(k).get_type().encode(), repr(getattr(v, "tolist", lambda: v)()))
            if isinstance(obj, h5py.Dataset):
                out[name] = (obj.id.get_type().encode(), obj.shape, obj[()].tobytes() if obj.shape else obj[()])
            else:
                out[name] = None

        visit("/", f)
        f.visititems(visit)
        return out

    with h5py.File(io.BytesIO(archive.to_bytes(res))) as f:
        mem = content(f)
        assert f["results/extra"].attrs["pair"].tolist() == [1, 2]
        assert f["results/extra"].attrs["names"].tolist() == ["a", "b"]
        assert f["results/per_rotation"].attrs["columns"].tolist() == ["I_dec"]
    with h5py.File(archive.write(res, tmp_path / "w.h5")) as f:
        assert content(f) == mem


def test_format_1_archive_still_reads_the_same(tmp_path):
    """An archive of format 1.0 (one HDF5 attribute per value, written by bearingsim at commit 0921c01:
    ``bearingsim run scenarios/paper_3000rpm.toml``, kept gzipped) reads back as the same result a run
    of that scenario gives now, and the archive tools read it."""
    import gzip
    import tomllib
    from pathlib import Path

    import bearingsim

    old = tmp_path / "old.h5"
    old.write_bytes(gzip.decompress((Path(__file__).parent / "data" / "archive_v1_0_paper_3000rpm.h5.gz").read_bytes()))
    with h5py.File(old, "r") as f:
        assert f["bearingsim"].attrs["format_version"] == "1.0" and "attrs_json" not in f["results/summary"].attrs
    back = bearingsim.load(old)
    sc = resolve(tomllib.loads(back.scenario.to_toml()))
    now = bearingsim.run(sc)
    assert back.scenario.raw == now.scenario.raw
    assert back.summary == now.summary
    added = {"results/trace/I_acc_cumulative"}  # recorded since (an optional array: its figure draws I_dec alone)
    assert set(back.data) == set(now.data) - added
    for k, v in ((k, v) for k, v in now.data.items() if k not in added):
        assert np.array_equal(back.data[k].data, v.data) and back.data[k].unit == v.unit, k
    assert set(back.groups) == set(now.groups)
    for k, g in now.groups.items():
        assert back.groups[k].attrs == g.attrs and back.groups[k].units == g.units, k
    assert back.tables == now.tables
    assert back.provenance["solver"] == "reduced/event" and back.provenance["git_commit"].startswith("0921c01")
    assert isinstance(back.provenance["solver_pieces"], int) and isinstance(back.provenance["dt_s"], float)
    # the new layout gives back the same dict, types and order included
    new = bearingsim.load(back.save(tmp_path / "new.h5"))
    assert list(new.provenance) == list(back.provenance)
    for k, v in back.provenance.items():
        if k not in ("created_utc", "command", "git_commit", "bearingsim_version") and not k.startswith("version_"):
            assert type(new.provenance[k]) is type(v) and (new.provenance[k] == v or v != v), k
    for k, g in back.groups.items():
        assert list(new.groups[k].attrs.items()) == list(g.attrs.items()), k
        assert list(new.groups[k].units.items()) == list(g.units.items()), k
    assert "I_dec_mean_Ns" in describe(old) and "git_commit=0921c01" in describe(old)
    got = archive.peek(old)
    assert got["summary"]["I_dec_mean_Ns"] == now.summary["I_dec_mean_Ns"] and got["wall_time_s"] > 0
    assert got["model_version"] is None and now.provenance["model_version"] >= 1  # a sweep reruns it (stale)


def test_failed_save_leaves_the_process_file_descriptors_alone(tmp_path, base_reduced, monkeypatch):
    """A full disk met by ``Result.save`` is one exception for the caller; the library never points
    file descriptor 2 elsewhere (neither while writing nor after), and no descriptor is left open."""
    import errno
    import os

    def stderr_identity():
        st = os.fstat(2)
        return st.st_dev, st.st_ino

    before = stderr_identity()
    seen = []

    def full_disk(f, result, in_memory=False):
        seen.append(stderr_identity())
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(archive, "_fill", full_disk)
    res = _result(resolve(base_reduced))
    fd_probe = os.open(os.devnull, os.O_RDONLY)  # the lowest free descriptor before the save
    os.close(fd_probe)
    with pytest.raises(UserError, match="No space left on device") as info:
        res.save(tmp_path / "a.h5")
    assert seen == [before]  # while writing
    assert stderr_identity() == before  # and after
    assert getattr(info.value, "stderr_fd", None) is None
    fd_after = os.open(os.devnull, os.O_RDONLY)
    os.close(fd_after)
    assert fd_after == fd_probe  # no descriptor kept open for a caller that never closes it
    assert list(tmp_path.iterdir()) == []


def test_a_failed_save_leaves_no_folder_it_made(tmp_path, base_reduced, monkeypatch):
    """``Result.save("new/deeper/a.h5")`` on a full disk raised its one ArchiveWriteError and removed its temporary
    file, but kept the folders ``new/deeper`` it had made for the archive ("nothing left behind", docs/usage.md),
    as ``bearingsim run`` does not. They are removed again; a folder that was there stays."""
    import errno
    import os

    from bearingsim.outputs import ArchiveWriteError

    def full_disk(f, result, in_memory=False):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(archive, "_fill", full_disk)
    res = _result(resolve(base_reduced))
    (tmp_path / "kept").mkdir()
    for target in (tmp_path / "new" / "deeper" / "a.h5", tmp_path / "kept" / "a.h5"):
        with pytest.raises(ArchiveWriteError, match="No space left on device"):
            res.save(target)
    assert [p.name for p in tmp_path.iterdir()] == ["kept"] and list((tmp_path / "kept").iterdir()) == []


_FULL_DISK_CHILD = r"""
import resource, signal, sys
from bearingsim import run
from bearingsim.outputs import ArchiveWriteError
from bearingsim.scenario import resolve

res = run(resolve({"schema_version": 1, "name": "t", "model": "reduced",
                   "bearing": {"preset": "NU214-Suzuki2023"},
                   "operating": {"inner_ring_speed_rpm": 3000.0, "radial_load_N": 970.0},
                   "reduced": {"load_zone_half_angle_deg": 23.5}, "numerics": {"rotations": 1}}))
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # writes past the limit fail with EFBIG, as on a full disk
resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
try:
    res.save(sys.argv[1])
except ArchiveWriteError as exc:
    print(f"refused: {exc}")
"""


@pytest.mark.slow
def test_save_on_a_full_disk_is_one_typed_error_and_a_clean_exit(tmp_path):
    """Issue 30, item 9: writes failing past 4 KiB during ``Result.save`` (in a child process: the
    limit is per process) raise one ArchiveWriteError naming the path (not h5py's raw RuntimeError
    "Set slist enabled failed"), leave no temporary file, and the interpreter exits cleanly (it died
    of SIGSEGV at exit, after h5py's error stacks for the objects it could not free)."""
    import subprocess
    import sys

    from .conftest import ROOT, started

    out = tmp_path / "out" / "a.h5"
    with started([sys.executable, "-c", _FULL_DISK_CHILD, out], cwd=tmp_path, env={**__import__("os").environ,
                 "PYTHONPATH": _path()}, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
        stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 0, stderr[-2000:]
    assert stdout.startswith(f"refused: {out}: cannot write archive (File too large)"), stdout
    assert stderr == ""
    assert not (tmp_path / "out").exists()  # no temporary file, nor the folder the save made for the archive


_SPOOL_FULL_DISK_CHILD = r"""
import sys
import numpy as np
from bearingsim import archive
from bearingsim.datatypes import AttrGroup, NamedArray
from bearingsim.outputs import ArchiveWriteError
from bearingsim.reduced import ReducedResult
from bearingsim import load_scenario

out, how = sys.argv[1], sys.argv[2]
sc = load_scenario(sys.argv[3], set={"numerics.rotations": 2})
res = ReducedResult(sc, {"results/per_rotation/I_dec": NamedArray(np.ones((3, 2)), "N s"),
                         "results/per_rotation/I_acc": NamedArray(np.ones((3, 2)), "N s")},
                    {"results/summary": AttrGroup({"I_dec_mean_Ns": 1.0}, {"I_dec_mean_Ns": "N s"})},
                    provenance={"dt_s": 1e-6, "wall_time_s": 0.5})


def stream(sink):  # 640 kB of numbers gzip cannot shrink: a long run's time series
    ts = sink.timeseries("noise", (2,), "m")
    rng = np.random.default_rng(1)
    for i in range(40):
        ts.append(np.arange(i * 1000, (i + 1) * 1000), np.arange(1000) * 1e-5, rng.random((1000, 2)))


if how == "spool":
    try:
        with archive.Spool(out) as spool:
            stream(spool)
            archive.write(res, out, spool)
    except ArchiveWriteError as exc:
        print(f"refused: {exc}")
else:  # a multibody case of a sweep, its model's run replaced by the streaming above
    from bearingsim import simulation
    from bearingsim.sweeps import worker

    def run(scenario, progress=False, sink=None, check_step=False):
        stream(sink)
        return res

    simulation.run = run
    rec = worker.run_case("0" * 16, sc.to_toml(), archive.Path(out), archives="all")
    print(f"{rec['status']}: {rec['error']}")
"""


def _fsize_limit(limit):
    """``preexec_fn`` of a child whose writes fail past ``limit`` bytes (EFBIG, "File too large", as a full
    disk's ENOSPC; Python ignores SIGXFSZ)."""
    import resource

    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return limited


@pytest.mark.slow
@pytest.mark.parametrize("how", ["spool", "sweep case"])
@pytest.mark.parametrize("limit", [64 << 10, 400_000], ids=["while streaming", "at close"])
def test_a_full_disk_while_a_spool_streams_is_one_line_and_a_clean_exit(tmp_path, how, limit):
    """A full disk met by a streamed (multibody) archive, while its time series stream or when HDF5 closes
    its file, is one ArchiveWriteError naming the archive and the cause, in a sweep's case its failure;
    no temporary file, nothing on stderr, a clean exit. It was h5py's RuntimeError "Can't decrement id
    ref count" from close (not caught), error stacks of each HDF5 object freed, and SIGSEGV at exit."""
    import subprocess
    import sys

    from .conftest import ROOT, SCENARIOS

    out = tmp_path / "out" / "a.h5"
    out.parent.mkdir()
    child = [sys.executable, "-c", _SPOOL_FULL_DISK_CHILD, out, how, SCENARIOS / "multibody_3000rpm.toml"]
    proc = subprocess.run(child, cwd=tmp_path, env={**os.environ, "PYTHONPATH": _path()}, capture_output=True,
                          text=True, preexec_fn=_fsize_limit(limit), timeout=300)
    stdout, stderr = proc.stdout, proc.stderr
    assert proc.returncode == 0, stderr[-2000:]
    first = "refused" if how == "spool" else "failed"
    assert stdout == f"{first}: {out}: cannot write archive (File too large); nothing was written\n", stdout
    assert stderr == ""
    assert list(out.parent.iterdir()) == []


def test_the_new_per_rotation_series_missing_or_damaged(tmp_path, capsys):
    """The per-rotation cage slip and load zone (multibody model version 10) give the standard errors of those
    numbers. An archive without them (version 9) is read, tabled and listed with the other errors and an n/a for
    theirs; one whose arrays are damaged (text, or another shape) is listed with the intact errors and none for
    the damaged one, and a sweep's resume check does not trust it (archive.peek: None, so the case runs again)
    instead of stopping with a traceback."""
    import shutil

    import bearingsim
    from bearingsim.cli import main

    from .conftest import SCENARIOS

    out = tmp_path / "v10.h5"
    bearingsim.run(bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml", set={"numerics.rotations": 3})
                   ).save(out)
    assert archive.peek(out)["per_rotation"]["cage_slip"].shape == (3,)
    old, text, flat = tmp_path / "v9.h5", tmp_path / "text.h5", tmp_path / "flat.h5"
    for path in (old, text, flat):
        shutil.copy(out, path)
    with h5py.File(old, "r+") as f:
        del f["results/per_rotation/cage_slip"], f["results/per_rotation/load_zone_half_angle"]
    with h5py.File(text, "r+") as f:
        del f["results/per_rotation/cage_slip"]
        f["results/per_rotation/cage_slip"] = [b"x", b"y", b"z"]
    with h5py.File(flat, "r+") as f:
        del f["results/per_rotation/load_zone_half_angle"]
        f["results/per_rotation/load_zone_half_angle"] = np.zeros((3, 16))
    capsys.readouterr()
    assert main(["table", str(out), str(old)]) == 0
    rows = {line.split()[0]: line for line in capsys.readouterr().out.splitlines() if line.startswith("v")}
    assert "± n/a" not in rows["v10.h5"] and rows["v9.h5"].count("± n/a") == 2, rows  # slip and load zone of v9
    words = tmp_path / "words.h5"  # an older defect: a text I_dec stopped a sweep's resume with a ValueError
    shutil.copy(out, words)
    with h5py.File(words, "r+") as f:
        del f["results/per_rotation/I_dec"]
        f["results/per_rotation/I_dec"] = [b"a", b"b", b"c"]
    assert archive.peek(words) is None
    for path, damaged in ((text, "cage_slip"), (flat, "load_zone_half_angle_deg")):
        assert archive.peek(path) is None
        assert main(["inspect", str(path)]) == 0
        line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("standard errors"))
        assert "I_dec_mean_Ns \u00b1" in line and f"{damaged} \u00b1" not in line, line
    assert main(["inspect", str(old)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("standard errors"))
    assert "first_impact_speed_m_s \u00b1" in line and "cage_slip" not in line, line


def test_a_multibody_archive_of_the_version_before_where_the_cage_rests_still_reads(tmp_path, capsys):
    """Multibody model version 6 added ``cage_rest_offset_m`` and ``cage_rest_angle_deg`` to the summary
    (bearingsim.multibody.SUMMARY_ADDED) and their per-rotation arrays. An archive without them (one of
    version 5) reads, the archive tools show the angle as missing ('-'), not the archive as damaged, and a
    report's check of where the cage rests is 'not evaluated'; a value that is not a number is damaged."""
    from dataclasses import replace

    import bearingsim
    from bearingsim.cli import main
    from bearingsim.multibody import SUMMARY_ADDED

    from .conftest import SCENARIOS

    r = bearingsim.run(bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml", set={"numerics.rotations": 1}))
    assert set(SUMMARY_ADDED) <= set(r.summary) and r.summary["cage_rest_offset_m"] > 0
    group = r.groups["results/summary"]  # its values read-only: the result of version 5 is one made without them
    r.groups = {**r.groups, "results/summary": replace(
        group, attrs={k: v for k, v in group.attrs.items() if k not in SUMMARY_ADDED},
        units={k: u for k, u in group.units.items() if k not in SUMMARY_ADDED})}
    for name in ("cage_rest_angle", "cage_rest_offset"):  # and its per-rotation arrays
        del r.data[f"results/per_rotation/{name}"]
    old = r.save(tmp_path / "v5.h5")
    back = bearingsim.load(old)
    assert not set(SUMMARY_ADDED) & set(back.summary) and back.summary["I_dec_mean_Ns"] == r.summary["I_dec_mean_Ns"]
    assert "cage_rest_angle" not in back.per_rotation
    from bearingsim.plausibility import checks_made

    row = next(c for c in checks_made(back) if c[0] == "cage rests in one place")
    assert row[2] is None and row[1].startswith("not evaluated"), row
    now = bearingsim.run(r.scenario).save(tmp_path / "v6.h5")
    capsys.readouterr()
    assert main(["table", str(now), str(old)]) == 0
    lines = capsys.readouterr().out.splitlines()
    lines = lines[next(i for i, line in enumerate(lines) if line.startswith("archive ")):]  # the table's header on
    assert "cage_rest_angle [deg]" in lines[0], lines[0]
    assert lines[1].split()[0] == "v6.h5" and lines[2].split()[0] == "v5.h5", lines
    cells = [re.split(r" {2,}", line.strip()) for line in lines[:3]]  # columns: 2 spaces or more apart
    at = cells[0].index("cage_rest_angle [deg]") - len(cells[0])  # from the end: the rows' notes column may be empty
    assert cells[2][at] == "-" and cells[1][at] not in ("-", ""), lines  # its angle
    with h5py.File(old, "r+") as f:
        f["results/summary"].attrs["cage_rest_angle_deg"] = "west"
    with pytest.raises(UserError, match="cage_rest_angle_deg is 'west', not a number"):
        bearingsim.load(old)


def test_a_runs_notes_are_stored_and_read_inspected_and_reported_back(tmp_path):
    """A run's notes (plausibility.check of a kept run that is not clean) were printed by `run` and lost: the
    archive did not hold them, so `inspect`, `bearingsim.load` and `run -q` (which prints nothing) never
    showed them. They are stored as /bearingsim/notes, read back into result.notes, listed by inspect
    ("notes: none" for a run without one) and once each in a report; an archive without them reads as
    before (no notes), and inspect says it stores none."""
    import bearingsim
    from bearingsim.reports import _checks_blocks

    from .conftest import SCENARIOS
    from .test_cli import bearingsim as cli

    out = tmp_path / "z3.h5"  # 3 rollers: three notes (no load-zone angle, the warm-up not judged, where it rests)
    res = cli("run", SCENARIOS / "multibody_3000rpm.toml", "--set", "bearing.roller_count=3", "--set",
              "numerics.rotations=4", "--no-plots", "-q", "-o", out)
    assert res.returncode == 0 and res.stdout == "" and res.stderr == "", res.stderr
    with pytest.warns(bearingsim.errors.PlausibilityWarning):
        fresh = bearingsim.run(bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml", set={
            "bearing.roller_count": 3, "numerics.rotations": 4}))
    back = bearingsim.load(out)
    assert back.notes == fresh.notes and len(back.notes) == 3, back.notes
    for words in ("load_zone_half_angle_deg = 0 is no result", "the warm-up could not be judged",
                  "the cage did not rest in one place"):
        assert sum(words in n for n in back.notes) == 1, words
    with h5py.File(out, "r") as f:
        assert [v.decode() for v in f["bearingsim/notes"][()]] == back.notes
    text = describe(out)
    part = text[text.index("\nnotes:\n"):text.index("\ndatasets:")].splitlines()[2:]
    assert part == [f"  {n.removeprefix('bearingsim: note: ')}" for n in back.notes], part
    items = _checks_blocks(back)[2]["items"]
    assert items == [n.removeprefix("bearingsim: note: ") for n in back.notes], items  # none twice
    back.notes = []  # stored notes the checks cannot make again (a drift) are listed too, once
    stored = bearingsim.load(back.save(tmp_path / "none.h5"))
    assert stored.notes == [] and "\nnotes: none\n" in describe(tmp_path / "none.h5")
    stored.notes = ["bearingsim: note: not statistically steady: ..."]
    items = _checks_blocks(bearingsim.load(stored.save(tmp_path / "drift.h5")))[2]["items"]
    assert items[0] == "not statistically steady: ..." and len(items) == 4, items
    with h5py.File(out, "r+") as f:  # an archive that stores no notes
        del f["bearingsim/notes"]
    assert bearingsim.load(out).notes == [] and "\nnotes: not stored in this archive" in describe(out)


def test_the_provenance_command_runs_again_as_it_was_given(monkeypatch):
    """The provenance stored ``" ".join(sys.argv)``: an argument with spaces (``--set 'operating={...}'``)
    came back as two, and ``python -m bearingsim`` was named by the path of its ``__main__.py``. It is the
    command as a shell takes it again, bearingsim's own entry point named ``bearingsim``."""
    import shlex
    import sys
    from pathlib import Path

    table = "operating={inner_ring_speed_rpm=500, radial_load_N=2000}"
    main = Path(archive.__file__).parent / "__main__.py"
    for program in (str(main), "/usr/local/bin/bearingsim"):  # python -m bearingsim; the console script
        monkeypatch.setattr(sys, "argv", [program, "run", "s.toml", "--set", table])
        command = archive.run_facts()["command"]
        assert command == f"bearingsim run s.toml --set '{table}'"
        assert shlex.split(command) == ["bearingsim", "run", "s.toml", "--set", table]
    monkeypatch.setattr(sys, "argv", ["/opt/tools/other.py", "a b"])  # another program: kept as it is
    assert archive.run_facts()["command"] == "/opt/tools/other.py 'a b'"
    with archive.given_command("bearingsim sweep x.toml"):  # a sweep case on a dask worker: the sweep's
        assert archive.run_facts()["command"] == "bearingsim sweep x.toml"
    assert archive.run_facts()["command"] == "/opt/tools/other.py 'a b'"
