"""Wear profile bookkeeping, Archard's law on it, and the life study (docs/wear.md)."""
from __future__ import annotations

import math
import os
import re
import shutil
import signal
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bearingsim import laws
from bearingsim.errors import UserError
from bearingsim.multibody import forces as fk
from bearingsim.multibody import recorder as rk
from bearingsim.multibody.scene import pocket_angles
from bearingsim.reduced.core import FACE_FRONT, FACE_REAR
from bearingsim.scenario import load_scenario

from .conftest import SCENARIOS

N = 4
IDS = np.array([10, 11, 12, 13, 20], dtype=np.uint64)
RP = 0.04875  # pocket centres' radius [m]
R = 0.0066  # pocket circle radius [m]
LO, HI = math.radians(-32.9), math.radians(26.2)


def _record(arbiters, vx=0.1):
    """record_step with the wear profile on; arbiters (impulse on the roller, normal roller -> cage,
    cage contact point), roller 0 (pocket 0 at the bottom: e_t = +x, e_r = -y) sliding at vx."""
    arb_f = np.zeros(rk.ARB_F * len(arbiters))
    arb_i = np.zeros(rk.ARB_I * len(arbiters), dtype=np.uint64)
    for k, (jimp, nrm, pc) in enumerate(arbiters):
        arb_f[k * rk.ARB_F:(k + 1) * rk.ARB_F] = [*jimp, *nrm, *pc, *pc, 0.0]
        arb_i[k * rk.ARB_I:(k + 1) * rk.ARB_I] = [10, 20, 1]
    cfg = rk.RecorderConfig(sign=1.0, roller_count=N, warmup_rotations=0.0, rotations=1, theta_bins=360,
                            impact_speed_threshold=0.01, pocket_centre_radius=RP, psi_lo=LO, psi_hi=HI)
    acc = rk.accumulators(1, N, 360, 16)
    st = np.zeros((N + 1, 6))
    st[0, 0:2] = (0.0, -RP)
    st[0, 4] = vx  # roller 0 moving at vx along y
    order = np.argsort(IDS)
    rk.record_step(arb_f, arb_i, len(arbiters), IDS[order], order.astype(np.int64), st, st.copy(), 1e-3, 1e-6, cfg,
                   pocket_angles(N, 1), np.mod(-2.0 * math.pi * np.arange(N) / N, 2.0 * math.pi),
                   np.zeros(N, dtype=fk.DIAG), acc, 0, np.zeros(N, dtype=np.bool_))
    return acc


def _contact(face_sign, psi_deg, jn):
    """A contact on pocket 0's front (face_sign +1) or rear (-1) face at psi, normal impulse jn on the cage."""
    psi = math.radians(psi_deg)
    n = (face_sign * math.cos(psi), -math.sin(psi))  # d / |d| = cos psi (+-e_t) + sin psi e_r, e_r = -y
    pc = (R * n[0], -RP + R * n[1])
    return (-jn * n[0], -jn * n[1]), n, pc


def _bin(psi_deg):
    return int(math.floor((math.radians(psi_deg) - LO) / (HI - LO) * rk.FACE_BINS))


def test_profile_bins_each_contact_at_its_psi_and_sums_the_normal_impulse():
    """Contacts at psi = -30, 0, +20 deg on the front face and their mirror images on the rear face land
    in the bins of their psi, and the profile's impulse per face is the face's recorded normal
    impulse (the same additions in another grouping: 1e-18 N s on 1e-4)."""
    js = (1e-4, 2e-4, 3e-4)
    arbs = [_contact(s, p, j) for s in (1, -1) for p, j in zip((-30.0, 0.0, 20.0), js)]
    acc = _record(arbs)
    for face in (FACE_FRONT, FACE_REAR):
        got = acc.prof[0, face]["impulse"]
        want = np.zeros(rk.FACE_BINS)
        for p, j in zip((-30.0, 0.0, 20.0), js):
            want[_bin(p)] += j
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-18)
        assert acc.prof[0, face]["hits"].sum() == 3.0
    assert acc.prof[0, FACE_FRONT]["impulse"].sum() == pytest.approx(acc.win[0, 0]["Jn_front"], abs=1e-18)
    assert acc.prof[0, FACE_REAR]["impulse"].sum() == pytest.approx(acc.win[0, 0]["Jn_rear"], abs=1e-18)
    # mirror-symmetric contacts (front and rear at the same psi) give the same profile on both faces
    np.testing.assert_array_equal(acc.prof[0, FACE_FRONT], acc.prof[0, FACE_REAR])
    assert np.all(acc.prof[1:] ["impulse"] == 0.0)


def test_contacts_past_the_faces_ends_count_in_the_end_bins():
    """A contact at the arc's end or beyond it (a roller on the face's edge) counts in the end bin."""
    acc = _record([_contact(1, -40.0, 1e-4), _contact(1, 30.0, 2e-4), _contact(-1, 26.2, 3e-4)])
    # (the impulse's normal component of a vector built from cos and sin: 1e-18 on 1e-4)
    assert acc.prof[0, FACE_FRONT]["impulse"][0] == pytest.approx(1e-4, abs=1e-18)
    assert acc.prof[0, FACE_FRONT]["impulse"][-1] == pytest.approx(2e-4, abs=1e-18)
    assert acc.prof[0, FACE_REAR]["impulse"][-1] == pytest.approx(3e-4, abs=1e-18)
    assert acc.prof[0]["hits"].sum() == 3.0


# --- a short whole-bearing run (fast scene, 6000 rpm, 1 warm-up + 2 rotations: ~2 s) ------------------------
@pytest.fixture(scope="module")
def fast_run(tmp_path_factory):
    from bearingsim.simulation import load, run_scenario

    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["numerics.rotations=2", "multibody.raceway_contact=rigid"])
    path = tmp_path_factory.mktemp("wear") / "w.h5"
    run_scenario(sc, path, figures=False, notes=False)
    return load(path), path


def test_profile_impulse_and_work_equal_the_recorded_totals(fast_run):
    """Conservation of the bookkeeping over a whole run: each pocket face's profile sums to its recorded
    normal impulse and sliding work over the recorded rotations (same additions regrouped: 1e-12)."""
    res, _ = fast_run
    for f in ("front", "rear"):
        np.testing.assert_allclose(res.get(f"wear/profile_impulse_{f}").sum(axis=0),
                                   res.per_rotation[f"Jn_{f}"].sum(axis=0), rtol=1e-12)
        np.testing.assert_allclose(res.get(f"wear/profile_work_{f}").sum(axis=0),
                                   res.per_rotation[f"slide_work_{f}"].sum(axis=0), rtol=1e-12)
        assert res.data[f"results/wear/profile_work_{f}"].unit == "J"
    assert res.get("wear/profile_impulse_front").sum() > 0.0


def test_archard_volume_is_k_W_over_H(fast_run):
    """The worn volume of a face after N inner-ring rotations is k W / H with W the recorded sliding work
    scaled to the cage rotations of N (cage speed / inner-ring speed, measured); the depth profile
    integrates back to it over the bins' face area."""
    res, _ = fast_run
    rep = res.wear_report(rotations=1.6e5)
    p = res.parameters
    cage_rot = 1.6e5 * res.summary["cage_speed_mean_rad_s"] / p.operating.omega_i
    w = res.per_rotation["slide_work_rear"].sum(axis=0) / res.per_rotation["I_dec"].shape[0] * cage_rot
    np.testing.assert_allclose(rep.volume_rear, p.wear.wear_coefficient * w / p.wear.hardness, rtol=1e-12)
    np.testing.assert_allclose(rep.depth_rear.sum(axis=0) * rep.bin_area, rep.volume_rear, rtol=1e-12)
    assert rep.hours == pytest.approx(1.6e5 / 6000 / 60, rel=1e-12, abs=0)
    # abs=0: pytest.approx adds an absolute 1e-12 by default, 50 times this volume, and would pass any value
    assert laws.archard_volume_from_work(1e-5, 3.0, 1.5e9) == pytest.approx(2e-14, rel=1e-15, abs=0.0)


def test_a_face_bins_area_is_the_arc_the_rollers_hit_times_the_roller_length(fast_run):
    """A worn depth is a bin's worn volume over the bin's area, and the Archard test above checks the depths
    against that same area, so it held for any area (a pocket radius of r_r + s in the area passed the wear
    tests). The area is pinned here to the face the rollers collide with: the arc of the scene the run builds
    (its pocket radius R = r_r + s/2 and extent), times the roller length, split into the profile's bins."""
    from bearingsim.multibody.scene import build_scene
    from bearingsim.wear import face_area

    res, _ = fast_run
    p = res.parameters
    sc = build_scene(p.bearing, p.operating, p.contact.restitution, p.contact.cage_friction,
                     extent=p.multibody.pocket_face_extent, n_seg=0, kinematic_cage=False, spin_free=True)
    lo, hi = sc.extent
    rep = res.wear_report(rotations=1.6e5)
    bins = rep.depth_rear.shape[0]
    assert rep.bin_area == pytest.approx(sc.pocket_radius * (hi - lo) / bins * p.bearing.roller_length, rel=1e-12, abs=0)
    assert rep.bin_area == face_area(p, bins) and sc.pocket_radius == pytest.approx(
        p.bearing.roller_radius + 0.5 * p.bearing.pocket_clearance, rel=1e-15, abs=0)


def test_the_papers_wear_index_takes_the_normal_impulse_and_agrees_with_the_sliding_work(fast_run):
    """Eq. 16 writes Archard's sliding work as W L_s = integral F_c dL_s ~ I_c r_r omega_r, F_c the contact force:
    on the whole bearing's arc faces that is the normal impulse J_n, whose circumferential component (I_acc,
    I_dec) is smaller by the faces' obliquity. The paper's index (``/results/wear/paper_index_*``) is
    k J_n r_r omega_r / H per pocket; with the circumferential impulse it read the rear faces 15 % below their
    sliding work on the wear test and turned the front / rear order over. Against the sliding work, face by
    face and pocket by pocket, within 3 %: the roller's surface slides over its face at about r_r omega_r
    (Eq. 12's spin relative to the cage), off by the roller's spin slip and its translation in the pocket
    (measured: 1.3-1.5 % over all pockets, at most 2.3 % in one)."""
    res, _ = fast_run
    p = res.parameters
    k, h = p.wear.wear_coefficient, p.wear.hardness
    for face in ("front", "rear"):
        jn = res.per_rotation[f"Jn_{face}"].mean(axis=0)
        index = res.get(f"wear/paper_index_{face}")
        np.testing.assert_allclose(index, k * jn * p.bearing.roller_radius * p.operating.omega_r / h, rtol=1e-12)
        np.testing.assert_allclose(index / res.get(f"wear/sliding_work_{face}"), 1.0, atol=0.03)


def test_wear_profile_figure_shows_the_deepest_point_of_either_face(fast_run):
    """The Fig. 13 analog shares its depth axis between the faces; its limit was fixed by the front face
    alone (set before the rear face was drawn), so the rear face's bore end, the deepest point of the
    wear test (2492 um mean against the front's 1841 um, docs/wear.md), ran off the top of the figure.
    Both faces' largest depth now lies within the axis; the two x labels do not overlap."""
    res, _ = fast_run
    rep = res.wear_report(rotations=1.6e5)
    fig = res.plot_wear_profile(rotations=1.6e5)
    deepest = max(rep.depth_front.max(), rep.depth_rear.max()) * 1e6
    for ax in fig.axes[:2]:
        bottom, top = ax.get_ylim()
        assert bottom == 0.0 and top >= deepest, (top, deepest)
    fig.canvas.draw()
    boxes = [ax.xaxis.label.get_window_extent() for ax in fig.axes[:2]]
    assert boxes[0].x1 < boxes[1].x0, "the faces' x labels overlap"


def test_archive_without_profile_reads_and_wear_says_why(fast_run, tmp_path, capsys):
    """An archive written before the profile existed (its datasets removed) still reads; the wear report
    refuses it in one line, and ``bearingsim wear`` names the archive in it (it said 'this archive' alone:
    of several archives, not which), writing nothing."""
    import h5py
    import shutil

    from bearingsim.simulation import load

    _, path = fast_run
    old = tmp_path / "old.h5"
    shutil.copy(path, old)
    with h5py.File(old, "a") as f:
        for k in list(f["results/wear"]):
            if k.startswith("profile_"):
                del f[f"results/wear/{k}"]
    res = load(old)
    assert "results/wear/profile_work_front" not in res.data
    with pytest.raises(UserError, match="no wear profile"):
        res.wear_report(hours=1.0)
    from bearingsim.cli import main

    code = main(["wear", str(path), str(old), "--hours", "1", "-o", str(tmp_path / "figs")])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and err.startswith(f"bearingsim: error: {old}: this archive has no wear profile"), err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "figs").exists()


@pytest.mark.parametrize("kw", [{"hours": -1.0}, {"rotations": 0.0}, {}, {"hours": 1.0, "rotations": 2.0},
                                {"hours": float("nan")}, {"rotations": 1e300}, {"hours": 1.0001e6}])
def test_bad_running_time_is_refused(fast_run, kw):
    with pytest.raises(UserError):
        fast_run[0].wear_report(**kw)


def test_running_time_up_to_its_bound_gives_finite_numbers(fast_run):
    """Realistic running times and the bound itself (wear.MAX_RUNNING_HOURS, 1e6 h) are reported, every
    number finite; just beyond it, in hours or in the same inner-ring rotations, refused naming the option."""
    from bearingsim.wear import MAX_RUNNING_HOURS

    res = fast_run[0]
    for hours in (0.44, 100.0, MAX_RUNNING_HOURS):
        rep = res.wear_report(hours=hours)
        assert rep.hours == pytest.approx(hours, rel=1e-12, abs=0)
        assert all(math.isfinite(x) for x in (rep.max_depth, rep.cov("front"), rep.cov("rear")))
    rotations = MAX_RUNNING_HOURS * 3600 * res.parameters.operating.omega_i / (2 * math.pi)  # at 6000 rpm: 3.6e11
    assert res.wear_report(rotations=rotations * 0.999).hours == pytest.approx(0.999 * MAX_RUNNING_HOURS, rel=1e-12)
    for kw, name in (({"hours": MAX_RUNNING_HOURS * 1.001}, "hours"),
                     ({"rotations": rotations * 1.001}, "rotations")):  # the API names its keywords
        with pytest.raises(UserError, match=f"^{name} .*: more than 1000000 h of running"):
            res.wear_report(**kw)
    with pytest.raises(UserError, match=r"^hours 1000000\.4: more than 1000000 h of running \(360000000000 inner"):
        res.wear_report(hours=1000000.4)  # just over the bound: both numbers in full (it said "hours 1e+06: more
        # than 1e+06 h")
    for kw in ({"hours": 10**400}, {"rotations": 10**400}):  # an integer no float holds: an OverflowError before
        with pytest.raises(UserError, match=f"^{next(iter(kw))} above 1e308: more than 1000000 h of running"):
            res.wear_report(**kw)
    with pytest.raises(UserError, match="^hours 'x': must be a positive number$"):  # it said "--hours x"
        res.wear_report(hours="x")
    with pytest.raises(UserError, match="^give the running time as hours or as inner-ring rotations"):
        res.wear_report()


def test_an_infinite_running_time_is_refused_as_beyond_the_bound_not_as_no_positive_number(fast_run):
    """`bearingsim wear M --hours inf` (and `wear_report(rotations=math.inf)`) said "--hours inf: must be a positive
    number", which infinity is. It is refused as the time beyond the bound it is, naming it; NaN and what is not
    above 0 keep their line."""
    import argparse

    from bearingsim.cli_wear import _check_time
    from bearingsim.errors import UserError

    res = fast_run[0]
    for kw, name in (({"hours": math.inf}, "hours"), ({"rotations": math.inf}, "rotations"),
                     ({"hours": np.float64(np.inf)}, "hours")):
        with pytest.raises(UserError, match=f"^{name} inf: more than 1000000 h of running "):
            res.wear_report(**kw)
    for value in (math.nan, -math.inf, 0.0):
        with pytest.raises(UserError, match=f"^hours {value!r}: must be a positive number$"):
            res.wear_report(hours=value)
    with pytest.raises(UserError, match="^--hours inf: more than 1000000 h of running, 114 years"):
        _check_time(argparse.Namespace(hours=math.inf, rotations=None))  # a sweep's wear, before any case is read
    _check_time(argparse.Namespace(hours=None, rotations=math.inf))  # rotations: each case's bound, at its speed


def test_wear_report_takes_numpy_numbers_and_refuses_what_a_scenario_refuses(fast_run):
    """`wear_report(rotations=np.int64(100000))` was refused as "must be a positive number" (np.float64 was
    taken); `wear_coefficient=-1` gave a max depth of -0.0 and `hardness=0` NaN with a divide-by-zero warning.
    Numpy numbers are taken; k and H outside the scenario's bounds are refused in one line naming the argument."""
    import warnings

    from bearingsim.scenario import HARDNESS_RANGE_PA, MAX_WEAR_COEFFICIENT
    from bearingsim.wear import wear_report

    res = fast_run[0]
    base = res.wear_report(rotations=1e5)
    for kw in ({"rotations": np.int64(100000)}, {"rotations": np.float32(1e5)}, {"hours": np.int32(1)}):
        rep = res.wear_report(**kw)
        assert math.isfinite(rep.max_depth) and rep.max_depth > 0.0, kw
    assert res.wear_report(rotations=np.int64(100000)).max_depth == base.max_depth
    k, h = res.parameters.wear.wear_coefficient, res.parameters.wear.hardness
    rep = wear_report(res, rotations=1e5, wear_coefficient=np.float64(2 * k), hardness=np.int64(int(h)))
    assert rep.max_depth == pytest.approx(2 * base.max_depth, rel=1e-12, abs=0)
    lo, hi = HARDNESS_RANGE_PA
    bad = [("wear_coefficient", -1), ("wear_coefficient", 0.0), ("wear_coefficient", 2 * MAX_WEAR_COEFFICIENT),
           ("wear_coefficient", float("nan")), ("wear_coefficient", "1e-6"), ("wear_coefficient", True),
           ("hardness", 0), ("hardness", -1.5e9), ("hardness", lo / 2), ("hardness", hi * 2), ("hardness", np.inf)]
    for name, value in bad:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no RuntimeWarning on the way to the refusal
            with pytest.raises(UserError, match=f"^{name} {re.escape(repr(value))}: must be ") as err:
                wear_report(res, rotations=1e5, **{name: value})
        assert "\n" not in str(err.value)
    for value in (True, np.bool_(True)):
        with pytest.raises(UserError, match="^rotations .*: must be a positive number$"):
            res.wear_report(rotations=value)


@pytest.mark.parametrize("option, value", [("--rotations", "1e300"), ("--hours", "1e300"), ("--hours", "2e6"),
                                           ("--hours", "1000000.4")])
def test_wear_cli_refuses_an_absurd_running_time_in_one_line(fast_run, capsys, option, value):
    """`bearingsim wear M --rotations 1e300` exited 0 with an overflow warning, a coefficient of variation
    of inf and depths of 1e296 um: a running time beyond 1e6 h (wear.MAX_RUNNING_HOURS) is refused in one
    line naming the option, before anything is printed."""
    from bearingsim.cli import main

    code = main(["wear", str(fast_run[1]), option, value, "--no-plots"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "", (code, out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"bearingsim: error: {option} ") and "1000000 h" in lines[0], err
    assert f" {repr(float(value)).removesuffix('.0')}: " in lines[0], err  # as given, not rounded to the bound


def test_wear_cli_checks_its_output_before_printing(fast_run, tmp_path, capsys):
    """An output that cannot take the figures (-o a plain file; a figure path that is a folder) is refused
    in one line before the report is printed or a figure written (it printed the whole table, then
    refused)."""
    from bearingsim.cli import main

    archive = fast_run[1]
    afile = tmp_path / "afile"
    afile.write_text("mine")
    code = main(["wear", str(archive), "--hours", "1", "-o", str(afile)])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (code, out, err)
    assert f"{afile}: cannot create the output folder (it is a file)\n" in err and afile.read_text() == "mine"
    figs = tmp_path / "figs"
    (figs / f"{archive.stem}_wear_volume.png").mkdir(parents=True)
    code = main(["wear", str(archive), "--hours", "1", "-o", str(figs)])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (code, out, err)
    assert "wear_volume.png: figure path is a directory" in err
    assert [p.name for p in figs.iterdir()] == [f"{archive.stem}_wear_volume.png"]  # no figure written


@pytest.mark.slow
def test_wear_of_several_archives_is_one_table_of_their_volumes_with_errors(fast_run, tmp_path, capsys):
    """An engineer comparing cage materials compared impulses only (``table``): ``bearingsim wear A B --hours T``
    gives each archive's wear in a row, with the same numbers as ``wear_report`` of each (its k and H from its
    own scenario; the volume mean over pockets and its batch-means error), and the scenario keys that differ.
    Archives of one file name would draw their figures onto each other in one -o folder: refused, nothing drawn;
    a reduced-model archive among them is refused naming it."""
    import shutil

    from bearingsim import wear
    from bearingsim.cli import main
    from bearingsim.simulation import load, run_scenario
    from bearingsim.stats import with_error

    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["numerics.rotations=2", "multibody.raceway_contact=rigid",
                                                                   "wear.wear_coefficient=1e-5", "wear.hardness_Pa=1.2e8"])
    other = tmp_path / "polymer.h5"
    run_scenario(sc, other, figures=False, notes=False)
    code = main(["wear", str(fast_run[1]), str(other), "--hours", "10", "--no-plots"])
    out, err = capsys.readouterr()
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0].endswith("scenario keys that differ: wear.hardness_Pa, wear.wear_coefficient (as columns)")
    # each row labelled by the values of the keys that differ, as bearingsim table labels it (was: the file alone)
    assert lines[1].split()[:4] == ["archive", "wear.hardness_Pa", "wear.wear_coefficient", "hours"], lines[1]
    for path, row in zip((fast_run[1], other), lines[2:4]):
        rep = wear.wear_report(load(path), hours=10)
        cells = re.split(r"\s{2,}", row.strip())
        assert cells[0] == path.name and cells[4] == f"{rep.wear_coefficient:g}"
        assert cells[1:3] == [f"{rep.hardness:g}", f"{rep.wear_coefficient:g}"], cells
        for cell, face in zip(cells[6:8], ("front", "rear")):
            v = (rep.volume_front if face == "front" else rep.volume_rear).mean()
            assert cell == with_error(v * 1e9, rep.volume_sem(face) * 1e9)  # as bearingsim table shows a value
        assert cells[9] == "2"
    twin = tmp_path / "twin"
    twin.mkdir()
    shutil.copy(other, twin / fast_run[1].name)
    code = main(["wear", str(fast_run[1]), str(twin / fast_run[1].name), "--hours", "1", "-o", str(tmp_path / "f")])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and "would draw their figures onto each other" in err
    assert not list((tmp_path / "f").glob("*.png"))
    code = main(["wear", str(fast_run[1]), str(fast_run[1]), "--hours", "1"])  # one archive twice: one row twice
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and f"{fast_run[1]}: given twice" in err and "None" not in err, err
    red = tmp_path / "red.h5"
    run_scenario(load_scenario(str(SCENARIOS / "paper_3000rpm.toml")), red, figures=False, notes=False)
    code = main(["wear", str(fast_run[1]), str(red), "--hours", "1", "--no-plots"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and f"{red}: a reduced-model archive has no wear profile" in err


# --- life ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("text", ["depth=0.1", "depth=-1mm", "width=1mm", "volume=2mm", "depth=xmm", ""])
def test_bad_limit_is_refused(text):
    from bearingsim.studies.life import parse_limit

    with pytest.raises(UserError, match="--limit"):
        parse_limit(text)


@pytest.mark.parametrize("text", ["depth=1e400mm", "clearance=1e999um", "volume=1e400mm3"])
def test_an_infinite_limit_is_not_called_negative(text):
    """``--limit depth=1e400mm`` (infinite) said "must be positive"."""
    from bearingsim.studies.life import parse_limit

    with pytest.raises(UserError, match=r": must be a finite positive number$"):
        parse_limit(text)


def test_limit_parsing():
    from bearingsim.studies.life import parse_limit

    assert parse_limit("depth=0.1mm").value == pytest.approx(1e-4, rel=1e-6, abs=0)
    assert parse_limit("clearance=300um").value == pytest.approx(3e-4, rel=1e-6, abs=0)
    assert parse_limit("volume=2mm3").value == pytest.approx(2e-9, rel=1e-6, abs=0)


@pytest.mark.parametrize("text, words", [
    ("clearance=0x", "give a finite factor above 1 before the x"),
    ("clearance=1x", "give a finite factor above 1 before the x"),
    ("clearance=-2x", "give a finite factor above 1 before the x"),
    ("clearance=x", "give a finite factor above 1 before the x"),
    ("clearance=nanx", "give a finite factor above 1 before the x"),
    ("depth=2x", "a relative limit (<f>x) is for the clearance only; give depth=<x>mm or clearance=<f>x"),
    ("clearance=2y", "the unit of clearance is one of mm, um or <f>x"),
])
def test_a_bad_relative_clearance_limit_is_refused_in_one_line(tmp_path, monkeypatch, capsys, text, words):
    """`--limit clearance=<f>x` (the clearance f times its value at the start) takes a finite f above 1; any
    other is refused in one line naming --limit, exit 2, no folder made (it was told the unit of clearance is
    mm or um)."""
    from bearingsim.cli import main

    monkeypatch.chdir(tmp_path)
    code = main(["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", text])
    err = capsys.readouterr().err
    assert code == 2 and f"--limit {text!r}: {words}" in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_a_relative_clearance_limit_is_the_start_clearance_times_its_factor():
    """`clearance=2x` is twice the effective clearance at the study's start: the scenario's s (0.2 mm: the very
    number clearance=0.4mm is), or with worn faces of its own s plus the worst pocket's front and rear mean worn
    depth; the study shows what was asked and the value it means here (the history's `limit`)."""
    from bearingsim.studies.life import LifeStudy, parse_limit

    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["multibody.raceway_contact=rigid"])
    lim = parse_limit("clearance=2x")
    assert lim.factor == 2.0 and lim.shown == "clearance=2x"
    study = LifeStudy(sc, lim, stages=2, rotations=1)
    assert study.limit.value == parse_limit("clearance=0.4mm").value
    assert study.limit.shown == study.attrs()["limit"] == "clearance=2x (0.4 mm)"
    assert not study.limit.same_as(parse_limit("clearance=0.4mm")) and study.limit.same_as(parse_limit("clearance=2.0x"))
    worn = load_scenario(str(Path(__file__).parent / "data" / "worn_stage05_rigid.toml"))
    study = LifeStudy(worn, parse_limit("clearance=1.5x"), stages=2, rotations=1)
    assert study.start_value > worn.bearing.pocket_clearance_mm * 1e-3
    assert study.limit.value == 1.5 * study.start_value
    assert study.attrs()["limit"] == f"clearance=1.5x ({study.limit.value * 1e3:.6g} mm)"


@pytest.mark.slow
def test_a_relative_clearance_limit_is_its_absolute_value_and_says_so(tmp_path, capsys):
    """`--limit clearance=2x` on s = 0.2 mm gives the stage history of `clearance=0.4mm` bit for bit (the same
    criterion); the command's table, `bearingsim table`, life.h5's `limit`, the figure's title and the report
    show `clearance=2x (0.4 mm)`. A folder of the absolute limit is not resumed as the relative one, nor the
    other way round (the same value, another criterion: their clearances would compare otherwise); the
    relative one again resumes its own folder."""
    import bearingsim
    from bearingsim.cli import main
    from bearingsim.studies.life import parse_limit, plot_life, read_life, run_life

    cmd = ["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--stages", "2", "--rotations", "1", "-q",
           "--set", "multibody.raceway_contact=rigid"]
    assert main([*cmd, "--limit", "clearance=2x", "-o", str(tmp_path / "rel")]) == 0
    printed = capsys.readouterr().out
    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["multibody.raceway_contact=rigid"])
    run_life(sc, tmp_path / "abs", parse_limit("clearance=0.4mm"), stages=2, rotations=1)
    (a_cols, a_attrs), (r_cols, r_attrs) = read_life(tmp_path / "abs"), read_life(tmp_path / "rel")
    assert a_cols.keys() == r_cols.keys()
    for k in a_cols:
        np.testing.assert_array_equal(r_cols[k], a_cols[k], err_msg=k)
    assert r_cols["clearance_end_mm"][-1] == pytest.approx(0.4, rel=1e-9)
    assert a_attrs["limit"] == "clearance=0.4mm" and r_attrs["limit"] == "clearance=2x (0.4 mm)"
    assert printed.splitlines()[0].startswith(f"life of {SCENARIOS / 'wear_test_6000rpm.toml'} to clearance=2x (0.4 mm): ")
    assert main(["table", str(tmp_path / "rel")]) == 0
    assert "life of wear_test_6000rpm to clearance=2x (0.4 mm): " in capsys.readouterr().out
    assert plot_life(r_cols, r_attrs)._suptitle.get_text().startswith("life to clearance=2x (0.4 mm): ")
    assert "Life of wear_test_6000rpm to clearance=2x (0.4 mm)" in bearingsim.report(
        tmp_path / "rel", tmp_path / "rel.html", animation=None).read_text()
    for folder, given, held, again in (
            ("abs", "clearance=2x", "clearance=0.4mm; this one: --limit clearance=2x (0.4 mm)", "clearance=0.4mm"),
            ("rel", "clearance=0.4mm", "clearance=2x (0.4 mm); this one: --limit clearance=0.4mm", "clearance=2x")):
        assert main([*cmd, "--limit", given, "-o", str(tmp_path / folder)]) == 2
        err = capsys.readouterr().err
        assert (f"holds a life study of another limit ({held}); give --limit {again} to resume it, another folder, or "
                f"--force to replace it") in err, err
        assert len(err.strip().splitlines()) == 1
    assert main([*cmd, "--limit", "clearance=2.0x", "-o", str(tmp_path / "rel")]) == 0
    assert read_life(tmp_path / "rel")[0]["reused"].tolist() == [1, 1]


def _stage_path(folder, j: int):
    """Where stage ``j``'s archive of a life study's folder is, as the folder's case index says."""
    from bearingsim.sweeps.index import read_index

    cols, _ = read_index(folder / "sweep.h5")
    (k,) = np.flatnonzero(cols["stage"] == j)
    return folder / str(cols["archive"][k])


def _stage(folder, j: int):
    """Stage ``j``'s result, read from its archive."""
    from bearingsim.simulation import load

    return load(_stage_path(folder, j))


@pytest.mark.slow
@pytest.mark.parametrize("mapping", ["uniform", "shape"])
def test_life_stages_are_monotone_reach_the_limit_and_resume(tmp_path, capsys, mapping):
    """Three stages of the fast scene (1 rotation each) to a pocket clearance of 0.203 mm: the effective
    clearance grows stage by stage, the running time grows, the last stage ends at the limit; each stage
    runs with the wear of the stages before it (uniform: at the grown pocket clearance; shape: with the
    worn depth on each face); the same command again reuses every stage's archive and gives the same
    history bit for bit."""
    from bearingsim.studies.life import HISTORY_TABLE, parse_limit, run_life

    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["multibody.raceway_contact=rigid"])
    lim = parse_limit("clearance=0.203mm")
    cols = run_life(sc, tmp_path, lim, stages=3, rotations=1, mapping=mapping)
    assert np.all(np.diff(cols["clearance_start_mm"]) > 0) and np.all(np.diff(cols["hours_end"]) > 0)
    assert np.all(cols["stage_rotations"] > 0)
    assert cols["clearance_end_mm"][-1] == pytest.approx(0.203, rel=1e-9)
    assert np.all(cols["reused"] == 0)
    assert _stage(tmp_path, 0).scenario.wear.worn_depth_front_um is None
    if mapping == "uniform":  # stage j runs at the clearance stages 0..j-1 left (rounded to 1e-9 mm)
        for j in (1, 2):
            stage = _stage(tmp_path, j).scenario
            assert stage.wear.worn_depth_front_um is None
            assert stage.bearing.pocket_clearance_mm == pytest.approx(cols["clearance_end_mm"][j - 1], abs=1e-9)
    else:  # stage j runs with the depth accumulated by stages 0..j-1 on each face, per pocket and bin of
        # psi (rounded to 1e-6 um in its scenario), at the given pocket clearance
        for j in (1, 2):
            stage = _stage(tmp_path, j).scenario
            assert stage.bearing.pocket_clearance_mm == sc.bearing.pocket_clearance_mm
            # the history's clearance is the effective one, which its header says (it was "s [mm]", read
            # as the scenario's s, which these stages keep at 0.2 mm)
            assert cols["clearance_start_mm"][j] > stage.bearing.pocket_clearance_mm
            assert ("clearance_start_mm", "s_eff [mm]") in [c[:2] for c in HISTORY_TABLE]
            for f in ("front", "rear"):
                np.testing.assert_allclose(np.array(getattr(stage.wear, f"worn_depth_{f}_um")).T,
                                           cols[f"worn_depth_{f}_um"][j - 1], rtol=0, atol=5e-7)
    assert np.all(np.diff(cols["worn_depth_rear_um"], axis=0) >= 0) and cols["worn_depth_rear_um"][-1].max() > 0
    assert cols["max_depth_um"][-1] == pytest.approx(max(cols["worn_depth_front_um"][-1].max(),
                                                         cols["worn_depth_rear_um"][-1].max()), rel=1e-12)
    again = run_life(sc, tmp_path, lim, stages=3, rotations=1, mapping=mapping)
    assert np.all(again["reused"] == 1)
    for k in cols:
        if k != "reused":
            np.testing.assert_array_equal(again[k], cols[k])
    with pytest.raises(UserError, match=r"another limit \(clearance=0.203mm; this one: --limit clearance=0.204mm\); "
                                        "give --limit clearance=0.203mm to resume it, another folder, or --force"):
        run_life(sc, tmp_path, parse_limit("clearance=0.204mm"), stages=3, rotations=1, mapping=mapping)
    other = "shape" if mapping == "uniform" else "uniform"
    with pytest.raises(UserError, match=f"another wear mapping .*this one: {other}.*give --mapping {mapping} to resume"):
        run_life(sc, tmp_path, lim, stages=3, rotations=1, mapping=other)
    from bearingsim.cli import main

    assert main(["inspect", str(tmp_path / "life.h5")]) == 0  # bearingsim's own table file: described
    text = capsys.readouterr().out
    assert "life history" in text and "wear_test_6000rpm" in text and "limit: clearance=0.203mm" in text
    assert f"(one row per stage): {len(cols['stage'])} stages" in text  # its rows are stages (it said "cases")


@pytest.mark.slow
def test_life_uniform_mapping_counts_a_worn_start_once(tmp_path):
    """The uniform mapping from a scenario with worn faces of its own (tests/data/worn_stage05_rigid.toml,
    about 5 um mean depth): every stage keeps those faces, so stage 1's pocket clearance grows by stage 0's
    wear alone (the worst pocket's mean front + rear depth). It grew by the start's depth as well, which
    then acted twice on the stage's pocket (once on its faces, once in s)."""
    from bearingsim.studies.life import parse_limit, run_life

    sc = load_scenario(str(Path(__file__).parent / "data" / "worn_stage05_rigid.toml"))
    start = {f: np.array(getattr(sc.wear, f"worn_depth_{f}_um")).T for f in ("front", "rear")}  # [bin, pocket] um
    cols = run_life(sc, tmp_path, parse_limit("clearance=0.215mm"), stages=2, rotations=1, mapping="uniform")
    stage1 = _stage(tmp_path, 1).scenario
    for f in ("front", "rear"):
        np.testing.assert_array_equal(np.array(getattr(stage1.wear, f"worn_depth_{f}_um")).T, start[f])
    grown = sum((cols[f"worn_depth_{f}_um"][0] - start[f]).mean(axis=0) for f in ("front", "rear")).max()
    assert grown > 0
    assert stage1.bearing.pocket_clearance_mm == pytest.approx(sc.bearing.pocket_clearance_mm + grown * 1e-3, abs=2e-9)
    # the history's effective clearance holds the start's depth once
    start_mean = sum(start[f].mean(axis=0) for f in ("front", "rear")).max()
    assert cols["clearance_start_mm"][0] == pytest.approx(sc.bearing.pocket_clearance_mm + start_mean * 1e-3, abs=1e-9)


@pytest.mark.slow
def test_life_from_worn_faces_steps_from_their_depth_to_the_limit(tmp_path):
    """A life study from a scenario with worn faces of its own (50 um deepest) to depth=0.1mm in 2 stages
    wears on from 50 um: 75 um after stage 0, 100 um after stage 1, every stage forwards in time. The
    stages' steps were fractions of the limit from 0 (stage 0's goal 50 um, the start's depth: a stage of
    negative rotations, worn faces of negative depth next). A limit the start reaches already is refused
    in one line, no folder made."""
    from bearingsim.studies.life import parse_limit, run_life

    sc = load_scenario(str(Path(__file__).parent / "data" / "worn_stage05_rigid.toml"))
    start = max(np.max(getattr(sc.wear, f"worn_depth_{f}_um")) for f in ("front", "rear"))
    assert start == pytest.approx(50.0, abs=1e-5)
    cols = run_life(sc, tmp_path / "life", parse_limit("depth=0.1mm"), stages=2, rotations=1)
    assert np.all(cols["stage_rotations"] > 0) and np.all(np.diff(cols["hours_end"]) > 0)
    np.testing.assert_allclose(cols["max_depth_um"], [start + 25.0, 100.0], rtol=1e-9)
    for kind in ("depth=0.04mm", "clearance=0.205mm"):
        with pytest.raises(UserError, match=f"--limit {kind}: .*own worn faces .* are there already"):
            run_life(sc, tmp_path / "refused", parse_limit(kind), stages=2, rotations=1)
    assert not (tmp_path / "refused").exists()


@pytest.mark.slow
def test_life_runs_again_a_stage_computed_by_another_model_version(tmp_path, monkeypatch):
    """A stage archive that stores the stage's scenario but was computed by another version of the model
    (bearingsim.model_versions: its numbers moved since) is run again, not reused, as a sweep's case is."""
    from bearingsim import model_versions
    from bearingsim.studies.life import parse_limit, run_life

    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["multibody.raceway_contact=rigid"])
    lim = parse_limit("clearance=0.201mm")
    assert run_life(sc, tmp_path, lim, stages=1, rotations=1, mapping="shape")["reused"].tolist() == [0]
    assert run_life(sc, tmp_path, lim, stages=1, rotations=1, mapping="shape")["reused"].tolist() == [1]
    monkeypatch.setitem(model_versions.MODEL_VERSIONS, "multibody", model_versions.MODEL_VERSIONS["multibody"] + 1)
    assert run_life(sc, tmp_path, lim, stages=1, rotations=1, mapping="shape")["reused"].tolist() == [0]


@pytest.mark.slow
def test_plot_and_table_of_a_life_history_again(tmp_path, capsys):
    """`plot life.h5` said "not a bearingsim archive": it draws life.png again from the history alone, the
    same bytes as `bearingsim life` drew. `table` of the folder printed its case index (the stages' runs,
    marked against the first) and `table life.h5` "not a bearingsim archive": both print the history as
    `bearingsim life` printed it (its first line naming the scenario by its name)."""
    from bearingsim.cli import main

    code = main(["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "depth=1mm", "--stages", "1",
                 "--rotations", "1", "--set", "multibody.raceway_contact=rigid", "-o", str(tmp_path / "l"), "-q"])
    assert code == 0, capsys.readouterr().err
    lines = capsys.readouterr().out.splitlines()
    code = main(["plot", str(tmp_path / "l" / "life.h5"), "-o", str(tmp_path / "again")])
    captured = capsys.readouterr()
    assert code == 0 and captured.err == "" and captured.out == f"wrote {tmp_path / 'again' / 'life.png'}\n"
    assert (tmp_path / "again" / "life.png").read_bytes() == (tmp_path / "l" / "life.png").read_bytes()
    history = [ln for ln in lines if not ln.startswith("wrote ")]
    assert history[0].startswith("life of ") and history[1].split()[:2] == ["stage", "s_eff"]
    for path in (tmp_path / "l", tmp_path / "l" / "life.h5"):
        assert main(["table", str(path)]) == 0
        printed = capsys.readouterr().out.splitlines()
        assert printed[0] == f"{tmp_path / 'l' / 'life.h5'}: " + history[0].replace(
            str(SCENARIOS / "wear_test_6000rpm.toml"), "wear_test_6000rpm")
        assert printed[1:] == history[1:]


@pytest.mark.slow  # a life study of 2 stages (~1.7 s)
def test_life_table_shows_a_volume_limits_quantity_and_the_stages_notes(tmp_path, capsys):
    """The life table of a volume limit gave the deepest point and its rate, not the largest face volume
    that the limit reads (life.h5 held it), and no table gave the stages' run notes (their archives hold
    them): the command and `bearingsim table DIR` give the volume and its rate, and under the table each
    distinct note once with how many stages carry it (1 recorded rotation: the warm-up cannot be judged)."""
    import bearingsim
    from bearingsim.cli import main

    cmd = ["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "volume=0.5mm3", "--stages", "2",
           "--rotations", "1", "-q", "--set", "multibody.raceway_contact=rigid", "-o", str(tmp_path)]
    assert main(cmd) == 0
    printed = capsys.readouterr().out
    assert main(["table", str(tmp_path)]) == 0
    table = capsys.readouterr().out
    from bearingsim.studies.life import read_life

    cols, _ = read_life(tmp_path / "life.h5")
    for out in (printed, table):
        lines = out.splitlines()
        head = next(i for i, ln in enumerate(lines) if ln.lstrip().startswith("stage "))
        assert "largest volume [mm3]" in lines[head] and "volume rate [mm3/h]" in lines[head]
        assert "deepest [um]" not in lines[head]
        assert lines[head + 2].split()[5] == format(float(cols["max_volume_mm3"][1]), ".4g") == "0.5"
        notes = [ln for ln in lines if ln.startswith("note (")]
        assert notes and notes[0].startswith("note (2 of 2 stages): the warm-up could not be judged"), out
        assert len(notes) == len(set(notes))
    stage_notes = {n for p in (tmp_path / "cases").glob("*.h5") for n in bearingsim.load(p).notes}
    assert len(notes) == len(stage_notes)


def test_the_stages_notes_of_one_kind_are_given_once():
    """Under the life history each distinct note was given once, so notes that differ only in their numbers (the
    warm-up note gives each stage's own rotations' I_dec) came once per stage: a 4-stage study of 3 rotations a
    stage printed 4 paragraphs that differ in a few digits. A kind of note is given once, in the words of its first
    stage, saying so; notes of other words stay apart, and a note the same in every stage reads as before."""
    from bearingsim.studies.life import stage_notes

    cols = {"stage": np.arange(4),
            "notes": ["rotations read 20.9 / 21.99 mN s", "", "rotations read 23.48 / 21.56 mN s\nk is high",
                      "rotations read 23.2 / -1e-3 mN s\nk is high"]}
    assert stage_notes(cols) == [
        "note (3 of 4 stages; the numbers of stage 0, the others differ in theirs): rotations read 20.9 / 21.99 mN s",
        "note (2 of 4 stages): k is high"]


def test_read_life_takes_the_study_folder(tmp_path):
    """read_life(DIR) on a life study's folder raised a UserError telling to pass DIR/life.h5: it reads
    DIR/life.h5, as read_life(DIR/life.h5) does; a folder without one is still refused in one line."""
    from bearingsim.studies.life import parse_limit, read_life, run_life

    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["multibody.raceway_contact=rigid"])
    run_life(sc, tmp_path / "l", parse_limit("clearance=0.201mm"), stages=1, rotations=1)
    cols, attrs = read_life(tmp_path / "l")
    file_cols, file_attrs = read_life(str(tmp_path / "l" / "life.h5"))
    assert attrs == file_attrs and attrs["limit"] == "clearance=0.201mm"
    assert cols.keys() == file_cols.keys() and cols["hours_end"].tolist() == file_cols["hours_end"].tolist()
    assert read_life(str(tmp_path / "l"))[1] == attrs
    with pytest.raises(UserError, match="life.h5"):
        read_life(tmp_path / "l" / "cases")


def test_life_cli_bad_input_is_one_line(tmp_path, capsys):
    from bearingsim.cli import main

    code = main(["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "depth=1furlong", "-o", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "--limit" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    code = main(["life", str(SCENARIOS / "paper_6000rpm.toml"), "--limit", "depth=0.1mm", "-o", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "multibody" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("scenario, extra, words", [
    ("paper_3000rpm.toml", ["--limit", "depth=0.1mm"], "multibody"),
    ("wear_test_6000rpm.toml", ["--limit", "clearance=0.1mm"], "--limit clearance=0.1mm"),
    ("wear_test_6000rpm.toml", ["--limit", "depth=0.1mm", "--stages", "0"], "--stages 0"),
    ("wear_test_6000rpm.toml", ["--limit", "depth=0.1mm", "--rotations", "0"], "--rotations 0"),
    ("wear_test_6000rpm.toml", ["--limit", "depth=0.1mm", "--set", "multibody.pocket_face_segments=8"],
     "multibody.pocket_face_segments = 8: --mapping shape (the default) feeds the worn depths back"),
], ids=["reduced-model", "clearance-below-s", "no-stages", "no-rotations", "shape-on-polylines"])
def test_refused_life_creates_no_folder(tmp_path, monkeypatch, capsys, scenario, extra, words):
    """A life study refused for its scenario or arguments exits 2 in one line and creates nothing (it left an
    empty outputs/<name>_life/; the shape mapping on polyline faces ran stage 0, then refused stage 1's
    worn faces)."""
    from bearingsim.cli import main

    monkeypatch.chdir(tmp_path)
    code = main(["life", str(SCENARIOS / scenario), *extra])
    err = capsys.readouterr().err
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, (code, err)
    assert list(tmp_path.iterdir()) == []


def test_life_uniform_mapping_takes_polyline_faces():
    """Polyline pocket faces (multibody.pocket_face_segments >= 1) are refused with the shape mapping only:
    the uniform one grows the clearance and never gives the faces a worn depth."""
    from bearingsim.studies.life import LifeStudy, parse_limit

    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["multibody.pocket_face_segments=8"])
    with pytest.raises(UserError, match="--mapping uniform"):
        LifeStudy(sc, parse_limit("depth=0.1mm"))
    assert LifeStudy(sc, parse_limit("depth=0.1mm"), mapping="uniform").mapping == "uniform"


@pytest.mark.parametrize("extra, words", [
    (["--limit", "depth=6mm"], "--limit depth=6mm: the cage bar between two pockets is 5.821 mm wide"),
    (["--limit", "depth=10000mm"], "--limit depth=10000mm: the cage bar"),
    (["--limit", "clearance=11.9mm"], "--limit clearance=11.9mm: the cage bar between two pockets is 5.821 mm wide: "
                                      "a pocket worn 11.7 mm wider, at least twice the bar's width"),
    (["--limit", "volume=1000mm3"], "--limit volume=1000mm3: the cage bar"),
    (["--limit", "depth=0.1mm", "--set", "wear.wear_coefficient=0"], "wear.wear_coefficient = 0: nothing wears"),
], ids=["depth-beyond-bar", "depth-absurd", "clearance-beyond-two-bars", "volume-beyond-bar", "no-wear"])
def test_life_refuses_a_limit_no_wear_can_reach_before_anything_runs(tmp_path, monkeypatch, capsys, extra, words):
    """A limit that a face reaches only through the cage bar between two pockets, on its face (the
    wear-test bearing: 97.5 mm pitch, 16 rollers of 13 mm, s = 0.2 mm: 97.5 sin(pi/16) - 13.2 = 5.821 mm):
    a depth, or a face's mean depth (volume), at that width or beyond, a clearance whose pocket has grown by
    twice that (its front and rear faces lie on the two bars either side of it: one face alone through its
    bar), or a wear coefficient of 0, is refused in one line before any stage runs, and nothing is created
    (a stage ran, then the next stage's scenario was refused naming wear.worn_depth_front_um, or 'no wear at
    this stage'; depth=6mm even ran to the end). A limit short of that runs, and may end where a bar wears
    through (the test above)."""
    from bearingsim.cli import main

    monkeypatch.chdir(tmp_path)
    code = main(["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--stages", "2", "--rotations", "1",
                 "--set", "multibody.raceway_contact=rigid", *extra])
    err = capsys.readouterr().err
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, (code, err)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("address", ["bogus", "inproc://x"])
def test_life_refuses_an_unusable_scheduler_before_making_its_folder(tmp_path, monkeypatch, capsys, address):
    """A --scheduler no client can use is refused in one line (exit 2) and leaves no folder, as a sweep's
    does (docs/wear.md: a study refused for its arguments creates no folder). The study engine made the
    folder and its lock file first and met the address only at its first case: the refused command left
    '-o' behind holding '.sweep.lock' alone."""
    pytest.importorskip("distributed")
    from bearingsim.cli import main

    monkeypatch.chdir(tmp_path)
    code = main(["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--stages", "1", "--rotations", "1",
                 "--limit", "depth=0.05mm", "--scheduler", address, "-o", "life"])
    err = capsys.readouterr().err
    assert code == 2 and "--scheduler" in err and len(err.strip().splitlines()) == 1, (code, err)
    assert list(tmp_path.iterdir()) == []


def test_the_pages_cage_bar_width_is_the_wear_test_bearings():
    """docs/wear.md gives the cage bar's width as d_p sin(pi/Z) - D - s = 5.821 mm with the wear-test
    bearing's numbers: each of them is the scenario's, and the arithmetic is laws.cage_bar_width's. The page
    gave 104 (the cage's outer diameter) for the pitch diameter, 97.5 mm, whose bar 5.821 mm is."""
    import re

    from .conftest import ROOT

    b = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml")).bearing
    text = (ROOT / "docs" / "wear.md").read_text()
    found = re.findall(r"([0-9.]+) sin\(π/(\d+)\) − ([0-9.]+) − ([0-9.]+) = ([0-9.]+) mm", text)
    assert found, "the page's cage-bar arithmetic"
    for dp, z, d, s, width in found:
        assert (float(dp), int(z), float(d), float(s)) == (b.pitch_diameter_mm, b.roller_count, b.roller_diameter_mm,
                                                           b.pocket_clearance_mm)
        assert float(width) == round(laws.cage_bar_width(float(dp), float(d), float(s), int(z)), 3)


@pytest.mark.slow
@pytest.mark.parametrize("limit, stages", [("volume=30mm3", 2), ("depth=5.8mm", 1), ("depth=5.8mm", 2),
                                           ("clearance=6.1mm", 2)])
def test_life_ends_where_the_cage_bar_wears_through_before_the_limit_its_stages_kept(tmp_path, capsys, limit, stages):
    """A limit whose mean depth fits the bar but whose worn edges do not (the roller-guided cage wears its
    faces' ends two orders of magnitude more per area than their middle, docs/wear.md), a depth just short
    of the bar's width, or a clearance a pocket reaches with its two faces on two bars (it was refused before
    any stage, as if they lay on one): the bar wearing through is the end of the life, the study's answer,
    when the two faces on one bar (pocket i's front face, pocket i - 1's rear face) reach its 5.821 mm
    together in one bin of psi (laws.worn_bar_depth: the check summed the deepest front and rear depths of
    any pockets and bins, which reached the bar's width sooner). It exits
    0 as a study that reaches its limit does, its history's first line saying the bar wears through first
    and when (within the stage that does it, the last one included), the stages run kept in life.h5 (the
    last one ending at that time), life.png and the table. It was a usage error (exit 2, "give a smaller
    limit") with no history: the stage run was lost. The same call again reuses the stages and ends there."""
    import re

    from bearingsim.cli import main
    from bearingsim.studies.life import parse_limit, read_life, run_life

    scenario = str(SCENARIOS / "wear_test_6000rpm.toml")
    code = main(["life", scenario, "--limit", limit, "--stages", str(stages), "--rotations", "1", "-q",
                 "--set", "multibody.raceway_contact=rigid", "-o", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 0 and err == "", (code, err)
    lines = out.splitlines()
    m = re.fullmatch(rf"life of {re.escape(scenario)} to {limit}: not reached, the cage bar wears through first, "
                     rf"after ([0-9.e+-]+) h = ([0-9.e+-]+) inner-ring rotations, in stage ([0-9]+) \(of {stages}\): "
                     r".*5\.821 mm.*", lines[0])
    assert m, lines[0]
    cols, attrs = read_life(tmp_path / "life.h5")
    last = int(m.group(3))
    assert cols["stage"].tolist() == list(range(last + 1)) and "worn_through" in attrs
    assert float(m.group(1)) == pytest.approx(cols["hours_end"][-1], rel=1e-3)
    assert float(m.group(2)) == pytest.approx(cols["rotations_end"][-1], rel=1e-3)
    assert np.all(cols["stage_rotations"] > 0)
    if limit.startswith("depth"):
        assert cols["max_depth_um"][-1] < 5800.0  # short of the limit: the bar ends the life first
    on_bar = laws.worn_bar_depth(cols["worn_depth_front_um"][-1], cols["worn_depth_rear_um"][-1])  # [bin, bar]
    bar = laws.cage_bar_width(97.5, 13.0, 0.2, 16) * 1e3
    assert on_bar.max() == pytest.approx(bar, rel=1e-6)  # the bar's width, reached at the stage's end
    i = int(np.unravel_index(np.argmax(on_bar), on_bar.shape)[1])
    assert f"pocket {i}'s front face and pocket {(i - 1) % 16}'s rear face" in lines[0]
    assert (tmp_path / "life.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [ln for ln in lines if ln.startswith("wrote ")]  # -q: the history alone
    assert main(["table", str(tmp_path)]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed == [f"{tmp_path / 'life.h5'}: " + lines[0].replace(scenario, "wear_test_6000rpm"),
                       *[ln for ln in lines[1:] if not ln.startswith("wrote ")]]  # the stages' notes too
    sc = load_scenario(scenario, ["multibody.raceway_contact=rigid"])
    again = run_life(sc, tmp_path, parse_limit(limit), stages=stages, rotations=1)
    assert again["reused"].tolist() == [1] * (last + 1)
    np.testing.assert_array_equal(again["hours_end"], cols["hours_end"])


@pytest.mark.slow
def test_life_folder_of_other_stages_or_rotations_is_refused_and_a_limit_in_other_units_resumes(tmp_path, capsys):
    """The stages and rotations per stage make another study (its stages end elsewhere): refused unless
    --force (they ran over the history silently); the same limit in other units (depth=100um for
    depth=0.1mm) is the same study and resumes from its stages."""
    from bearingsim.cli import main
    from bearingsim.studies.life import read_life

    base = ["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--set", "multibody.raceway_contact=rigid", "-q",
            "-o", str(tmp_path)]
    assert main([*base, "--limit", "depth=0.1mm", "--stages", "2", "--rotations", "1"]) == 0
    capsys.readouterr()
    for extra, words in ((["--stages", "3", "--rotations", "1"], "another number of stages (2; this one: --stages 3)"),
                         (["--stages", "2", "--rotations", "2"], "another number of rotations per stage (1; this "
                                                                 "one: --rotations 2)")):
        assert main([*base, "--limit", "depth=0.1mm", *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0] and "--force" in err[0], err
        # a folder of another stage count (one of the earlier default, 10) or rotations says how to resume it
        assert ("give --stages 2 to resume it" in err[0]) == (extra[1] == "3"), err
        assert ("give --rotations 1 to resume it" in err[0]) == (extra[3] == "2"), err
    assert main([*base, "--limit", "depth=100um", "--stages", "2", "--rotations", "1"]) == 0
    assert read_life(tmp_path / "life.h5")[0]["reused"].tolist() == [1, 1]


@pytest.mark.slow
def test_life_history_names_the_effective_clearance_and_keeps_the_scenario_its_stages_ran(tmp_path, capsys):
    """life.h5 of `--rotations 1` (the scenario file says 40): the effective clearance at each stage's start
    is the column clearance_start_mm (it was pocket_clearance_mm, the name of the scenario's key, which the
    shape mapping keeps at 0.2 mm while the column grows); its scenario ('bearingsim show life.h5') says
    rotations = 1, so that TOML run again without --rotations resumes the study (it said rotations = 40 and
    was refused: "another number of rotations per stage (1; this one: --rotations 40)"); `inspect` lists
    the wear mapping a resume depends on. A history written before (the old column name, the scenario as
    given) still reads and resumes."""
    from bearingsim import archive
    from bearingsim.cli import main
    from bearingsim.studies.life import LIFE_FORMAT, LIFE_UNITS, read_life

    scenario = str(SCENARIOS / "wear_test_6000rpm.toml")
    cmd = ["life", scenario, "--limit", "clearance=0.203mm", "--stages", "2", "--rotations", "1", "-q",
           "--set", "multibody.raceway_contact=rigid", "-o", str(tmp_path / "l")]
    assert main(cmd) == 0
    capsys.readouterr()
    history = tmp_path / "l" / "life.h5"
    raw, attrs = archive.read_table_file(history, LIFE_FORMAT)
    assert "clearance_start_mm" in raw and "pocket_clearance_mm" not in raw
    assert raw["clearance_start_mm"][0] == pytest.approx(0.2, abs=1e-12) and raw["clearance_start_mm"][1] > 0.2
    assert _stage(tmp_path / "l", 1).scenario.bearing.pocket_clearance_mm == 0.2
    assert main(["show", str(history)]) == 0
    saved = tmp_path / "saved.toml"
    saved.write_text(capsys.readouterr().out)
    assert load_scenario(str(saved)).numerics.rotations == 1
    again = ["life", str(saved), "--limit", "clearance=0.203mm", "--stages", "2", "-q", "-o", str(tmp_path / "l")]
    assert main(again) == 0, capsys.readouterr().err
    assert read_life(history)[0]["reused"].tolist() == [1, 1]
    capsys.readouterr()
    assert main(["inspect", str(history)]) == 0
    assert "\nmapping: shape (the worn depth added to each face where it wore" in capsys.readouterr().out
    # a history written before: the old column name, the scenario as given (its file's 40 rotations)
    old = {("pocket_clearance_mm" if k == "clearance_start_mm" else k): v for k, v in raw.items()}
    given = load_scenario(scenario, ["multibody.raceway_contact=rigid"]).to_toml()
    archive.write_table_file(history, old, LIFE_UNITS, {**attrs, "scenario": given})
    cols, _ = read_life(history)
    np.testing.assert_array_equal(cols["clearance_start_mm"], raw["clearance_start_mm"])
    assert main(["table", str(tmp_path / "l")]) == 0 and "s_eff [mm]" in capsys.readouterr().out
    assert main(cmd) == 0, capsys.readouterr().err
    assert read_life(history)[0]["reused"].tolist() == [1, 1]


#: case hash -> the signal its worker sends the study before it runs the case
_MARKS = None  # a JSON file: the worker processes outlive the study's rounds, so they read it at each batch
_RUN_BATCH = None  # the engine's own run_batch, while a test puts _signalling_batch in its place


def _marked() -> dict:
    """The cases marked for a worker to act on, by hash (signal number, or 0: fail)."""
    import json

    return json.loads(_MARKS.read_text()) if _MARKS is not None and _MARKS.exists() else {}


def _mark(cases, value: int) -> None:
    import json

    _MARKS.write_text(json.dumps({**_marked(), **{c.hash: value for c in cases}}))


def _wait_for_the_handler():
    for _ in range(1000):  # the handler raises here
        time.sleep(0.01)
    raise AssertionError("signal not delivered")


def _signalling_batch(items, *args, **kw):
    """The engine's run_batch (in a forked worker process, which has this module's state) sending its study
    the signal marked for one of its cases, then running them."""
    marks = _marked()
    for h, *_ in items:
        if h in marks:
            os.kill(os.getppid(), marks[h])
            time.sleep(10)  # the study ends this worker
    return _RUN_BATCH(items, *args, **kw)


@pytest.mark.slow
@pytest.mark.parametrize("when", ["between stages", "during a stage"])
@pytest.mark.parametrize("sig, code, name", [(signal.SIGINT, 130, "SIGINT"), (signal.SIGTERM, 143, "SIGTERM")])
def test_interrupted_life_says_its_stages_are_kept_and_resumes(tmp_path, monkeypatch, capsys, sig, code, name, when):
    """A signal while a life study computes its second stage from the first, or while the second stage runs
    (in the engine's worker process, which sends it to the study as a terminal's Ctrl-C reaches the whole
    process group): exit 128 + signal and one line, as every study says it, counting the finished stage
    as kept (it said "interrupted, no archive written" before the stages ran on the study engine); no
    history is written, and the same command then reuses the finished stage."""
    from bearingsim.cli import main
    from bearingsim.studies import life

    def signalled(study, cases):
        if cases and when == "between stages":
            os.kill(os.getpid(), sig)
            _wait_for_the_handler()
        _mark(cases, sig)

    _watch_stages(monkeypatch, tmp_path.with_name(tmp_path.name + "-marks.json"), _signalling_batch, signalled)
    cmd = _life_cmd(tmp_path, stages=2)
    # a suite started as a background job inherits SIGINT ignored: give this process a terminal user's handler
    # (SIGTERM's is the command line's own)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert main(cmd) == code
    finally:
        signal.signal(signal.SIGINT, previous)
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"bearingsim: life interrupted ({name}): 1 done, 0 cached, 0 failed, 1 not run, of 2 cases; run "
                   f"the same command again to resume"]
    assert list((tmp_path / "cases").iterdir()) == [_stage_path(tmp_path, 0)]
    assert not (tmp_path / "life.h5").exists()
    monkeypatch.undo()
    assert main(cmd) == 0
    assert life.read_life(tmp_path / "life.h5")[0]["reused"].tolist() == [1, 0]


@pytest.mark.slow
def test_a_signal_right_after_a_later_stages_cases_counts_them(tmp_path, monkeypatch, capsys):
    """SIGINT right after the second stage's round has run its case and written the index, before the round's
    sweep returns (the study's own handler raising in it): the line counted the round before it, "1 done, 0
    cached, 0 failed, 1 not run, of 2 cases", though the second stage was done and kept. It counts the present
    round's rows: both stages done; the same command then reuses both."""
    from bearingsim.cli import main
    from bearingsim.studies import life
    from bearingsim.sweeps import run as sweep_run

    run_cases = sweep_run._run_cases

    def then_signal(engine, cases, *args, **kw):
        interrupted = run_cases(engine, cases, *args, **kw)
        if len(cases) == 2:  # the second stage's round (with the first's case): ran, its own handlers out
            os.kill(os.getpid(), signal.SIGINT)
            _wait_for_the_handler()
        return interrupted

    monkeypatch.setattr(sweep_run, "_run_cases", then_signal)
    cmd = _life_cmd(tmp_path, stages=2)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal user's Python has it
    try:
        assert main(cmd) == 130
    finally:
        signal.signal(signal.SIGINT, previous)
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["bearingsim: life interrupted (SIGINT): 2 done, 0 cached, 0 failed, 0 not run, of 2 cases; run "
                   "the same command again to resume"]
    assert not (tmp_path / "life.h5").exists() and len(list((tmp_path / "cases").iterdir())) == 2
    monkeypatch.undo()
    assert main(cmd) == 0
    assert life.read_life(tmp_path / "life.h5")[0]["reused"].tolist() == [1, 1]


@pytest.mark.slow
def test_an_unfinished_life_study_resumes_with_its_own_options_only(tmp_path, monkeypatch, capsys):
    """A life study interrupted after its first stage, before its life.h5 is written: resumed with another
    --stages, --limit or --mapping it went on as another study over the first's stage (the folder check compared
    stage 0 alone, which these do not change), and another --rotations was refused as "another sweep or study"
    without naming --rotations. The case index records the study's options at its start (sweep.h5's root
    attribute life_study): each is refused in one line naming the option and the value that resumes the folder's
    study, the folder as it was; the same options resume it, reusing the stage."""
    from bearingsim.cli import main
    from bearingsim.studies import life

    next_cases = life.LifeStudy.next_cases

    def stopped(self, outdir, records):  # after stage 0, while the study reads its wear
        cases = next_cases(self, outdir, records)
        os.kill(os.getpid(), signal.SIGINT)
        _wait_for_the_handler()
        return cases

    def cmd(stages="1", rotations="1", limit="clearance=0.203mm", mapping="shape"):
        return ["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", limit, "--stages", stages, "--rotations",
                rotations, "--mapping", mapping, "-q", "--set", "multibody.raceway_contact=rigid", "-o", str(tmp_path)]

    monkeypatch.setattr(life.LifeStudy, "next_cases", stopped)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal user's Python has it
    try:
        assert main(cmd()) == 130
    finally:
        signal.signal(signal.SIGINT, previous)
    monkeypatch.undo()
    capsys.readouterr()
    index = tmp_path / "sweep.h5"
    before = {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert not (tmp_path / "life.h5").exists() and len(list((tmp_path / "cases").iterdir())) == 1
    for other, words in (({"stages": "2"}, "another number of stages (1; this one: --stages 2); give --stages 1 to "
                                           "resume it"),
                         ({"rotations": "2"}, "another number of rotations per stage (1; this one: --rotations 2); "
                                              "give --rotations 1 to resume it"),
                         ({"mapping": "uniform"}, "with another wear mapping (--mapping shape; this one: uniform); "
                                                  "give --mapping shape to resume it"),
                         ({"limit": "clearance=0.204mm"}, "another limit (clearance=0.203mm; this one: --limit "
                                                          "clearance=0.204mm); give --limit clearance=0.203mm to "
                                                          "resume it")):
        assert main(cmd(**other)) == 2, other
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"{index}: holds an unfinished life study " in err[0] and words in err[0], err
        assert "--force" in err[0], err
        assert {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before
    assert main(cmd(limit="clearance=203um")) == 0, capsys.readouterr().err  # the same limit in other units
    assert life.read_life(tmp_path / "life.h5")[0]["reused"].tolist() == [1]


def _watch_stages(monkeypatch, marks, batch, on_next) -> None:
    """``on_next(study, cases)`` sees each stage case a life study makes, before it runs, and the engine's
    batches go through ``batch`` (a function of this module: the forked worker finds it by name)."""
    from bearingsim.studies import life
    from bearingsim.sweeps import worker

    next_cases = life.LifeStudy.next_cases

    def watched(self, outdir, records):
        cases = next_cases(self, outdir, records)
        on_next(self, cases)
        return cases

    monkeypatch.setattr(life.LifeStudy, "next_cases", watched)
    monkeypatch.setattr(sys.modules[__name__], "_MARKS", marks)
    monkeypatch.setattr(sys.modules[__name__], "_RUN_BATCH", worker.run_batch)
    monkeypatch.setattr(worker, "run_batch", batch)


def _life_cmd(folder, stages: int) -> list[str]:
    """A life study of the fast scene, one rotation a stage, to a pocket clearance of 0.203 mm."""
    return ["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "clearance=0.203mm", "--stages", str(stages),
            "--rotations", "1", "-q", "--set", "multibody.raceway_contact=rigid", "-o", str(folder)]


def _failing_batch(items, *args, **kw):
    """The engine's run_batch (in a forked worker) failing the cases marked so, as a case whose
    run raised does."""
    marks = _marked()
    return [{"hash": h, "status": "failed", "error": "SimulationUnstable: made to fail", "wall_s": 0.0, "summary": {}}
            if h in marks else _RUN_BATCH([(h, *rest)], *args, **kw)[0] for h, *rest in items]


@pytest.mark.slow
def test_a_failed_stage_ends_the_life_study_keeping_the_stages_before_it(tmp_path, monkeypatch, capsys):
    """A stage that fails (its run raised) ends the study: exit 1, the engine's line of the failed case and
    the study's line naming the stage, its error and that the later stages were not run (each needs the one
    before); no history; the stage before it is kept, and the same command, the failure gone, reuses it."""
    from bearingsim.cli import main
    from bearingsim.studies import life

    def failing(study, cases):
        if len(study.rows) == 1:  # stage 1 fails
            _mark(cases, 0)

    _watch_stages(monkeypatch, tmp_path.with_name(tmp_path.name + "-marks.json"), _failing_batch, failing)
    cmd = _life_cmd(tmp_path, stages=3)
    assert main(cmd) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0].startswith("failed: case ") and err[0].endswith(" (stage=1): SimulationUnstable: made to fail")
    assert err[1:] == [f"bearingsim: 1 of 3 cases of the life failed (stage=1: SimulationUnstable: made to fail); the other "
                   f"cases' numbers are kept (errors in {tmp_path / 'sweep.csv'}); 1 later case not run (each needs "
                   f"the one before)"]
    assert not (tmp_path / "life.h5").exists() and list((tmp_path / "cases").iterdir()) == [_stage_path(tmp_path, 0)]
    monkeypatch.undo()
    assert main(cmd) == 0
    assert life.read_life(tmp_path / "life.h5")[0]["reused"].tolist() == [1, 0, 0]


@pytest.mark.slow
def test_life_refuses_a_folder_of_another_sweep_unless_forced(tmp_path, capsys):
    """A life study's later stages are not known before they run, so it tells its own earlier run (its first
    stage in the folder's case index) from another sweep or study itself: another is refused in one line and
    left as it was; with --force it is replaced, its case archives removed and a user's file in cases/ kept (it
    removed every cases/*.h5)."""
    from bearingsim.cli import main

    assert main(["sweep", str(SCENARIOS / "paper_3000rpm.toml"), "--param", "operating.inner_ring_speed_rpm=1000,2000",
                 "-q", "--no-plots", "--archives", "all", "-o", str(tmp_path)]) == 0
    mine = tmp_path / "cases" / "notes.h5"
    mine.write_bytes(b"mine")
    before = sorted(p.name for p in tmp_path.iterdir())
    cmd = ["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "clearance=0.201mm", "--stages", "1",
           "--rotations", "1", "-q", "--set", "multibody.raceway_contact=rigid", "-o", str(tmp_path)]
    assert main(cmd) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "holds another sweep or study" in err[0] and "--force" in err[0], err
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert main([*cmd, "--force"]) == 0
    from bearingsim.sweeps.index import read_index

    assert read_index(tmp_path / "sweep.h5")[0]["stage"].tolist() == [0]
    assert mine.read_bytes() == b"mine"
    assert [p for p in (tmp_path / "cases").iterdir() if p != mine] == [_stage_path(tmp_path, 0)]


@pytest.mark.slow
def test_a_signal_while_a_study_writes_its_table_says_its_cases_are_kept(tmp_path, monkeypatch, capsys):
    """SIGINT while a study (here a life study) writes its table and figure, its cases all done: exit 130 and
    one line saying so and that the same command finishes it (not "no archive written"); the same command
    then reuses every case and writes the history."""
    from bearingsim.cli import main
    from bearingsim.studies import life

    plot_life = life.plot_life

    def signalled(cols, attrs):
        os.kill(os.getpid(), signal.SIGINT)
        _wait_for_the_handler()

    monkeypatch.setattr(life, "plot_life", signalled)
    cmd = ["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "clearance=0.203mm", "--stages", "2",
           "--rotations", "1", "-q", "--set", "multibody.raceway_contact=rigid", "-o", str(tmp_path)]
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert main(cmd) == 130
    finally:
        signal.signal(signal.SIGINT, previous)
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"bearingsim: life interrupted (SIGINT): all 2 cases done and kept in {tmp_path}, its tables and "
                   f"figures not all written; run the same command again to resume"]
    monkeypatch.setattr(life, "plot_life", plot_life)
    assert main(cmd) == 0
    assert life.read_life(tmp_path / "life.h5")[0]["reused"].tolist() == [1, 1]
    assert (tmp_path / "life.png").is_file()


@pytest.mark.slow
def test_wear_and_life_commands_draw_their_figures_from_the_archives(tmp_path, capsys):
    """`bearingsim wear ARCHIVE` draws the Fig. 13 and Fig. 14 analogs from the archive alone (a run
    written and read back), `bearingsim life` its history figure from life.h5's columns; without
    ``--mapping`` the life study feeds the worn shape back (the default, docs/wear.md), its second stage
    running with the first stage's worn depth on the faces."""
    from bearingsim.cli import main

    archive = tmp_path / "w.h5"
    scenario = str(SCENARIOS / "wear_test_6000rpm.toml")
    assert main(["run", scenario, "-o", str(archive), "--no-plots", "-q", "--set", "numerics.rotations=2",
                 "--set", "multibody.raceway_contact=rigid"]) == 0
    assert main(["wear", str(archive), "--rotations", "1e5", "-o", str(tmp_path / "figs")]) == 0
    for name in ("w_wear_profile.png", "w_wear_volume.png"):
        assert (tmp_path / "figs" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["life", scenario, "--limit", "clearance=0.203mm", "--stages", "2", "--rotations", "1", "-q",
                 "--set", "multibody.raceway_contact=rigid", "-o", str(tmp_path / "life")]) == 0
    assert (tmp_path / "life" / "life.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    from bearingsim.studies.life import read_life

    assert read_life(tmp_path / "life" / "life.h5")[1]["mapping"] == "shape"
    stage = _stage(tmp_path / "life", 1).scenario
    assert stage.wear.worn_depth_rear_um is not None
    assert stage.bearing.pocket_clearance_mm == load_scenario(scenario).bearing.pocket_clearance_mm


@pytest.mark.parametrize("name", ["life.h5", "life.png"])
def test_life_keeps_a_users_file_in_its_folder(tmp_path, capsys, name):
    """A life.h5 or life.png bearingsim did not write is refused in one line (exit 2), kept as it was,
    and nothing is run or created."""
    from bearingsim.cli import main

    (tmp_path / name).write_text("my notes")
    code = main(["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "clearance=0.203mm",
                 "--stages", "2", "--rotations", "1", "-o", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and name in err and "not replaced" in err and len(err.strip().splitlines()) == 1
    assert (tmp_path / name).read_text() == "my notes"
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]


# --- worn faces in the scenario -------------------------------------------------------------------------
@pytest.mark.parametrize("over, words", [
    ({"wear.worn_depth_front_um": [[1.0] * 32] * 15}, "15 rows"),
    ({"wear.worn_depth_front_um": [[1.0] * 32] * 15 + [[1.0] * 31]}, "same number of bins"),
    ({"wear.worn_depth_rear_um": [[-1.0] * 32] * 16}, "negative"),
    ({"wear.worn_depth_front_um": [[3000.0] * 32] * 16, "wear.worn_depth_rear_um": [[3000.0] * 32] * 16},
     "worn through"),
    ({"wear.worn_depth_front_um": [[1.0] * 32] * 16, "multibody.pocket_face_segments": 4}, "exact arc faces"),
    ({"wear.worn_depth_front_um": [[1.0] * 32] * 16, "model": "reduced"}, "multibody"),
])
def test_bad_worn_depth_is_refused_naming_the_key(over, words):
    """A worn-depth profile that does not fit the bearing is refused in one line naming the key: a row per
    pocket (16), equal rows, no negative depth, no cage bar (5.821 mm) worn through by the two faces on it,
    exact arc faces, the multibody model."""
    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"))
    with pytest.raises(UserError, match=r"wear\.worn_depth_(front|rear)_um") as exc:
        sc.replace(**over)
    assert words in str(exc.value) and "\n" not in str(exc.value)


def test_a_worn_scenarios_cage_bar_carries_one_pockets_front_face_and_its_neighbours_rear_face():
    """The cage-bar check of worn faces sums, per bar and bin of psi, pocket i's front face and pocket
    i - 1's rear face (laws.worn_bar_depth; tests/test_geometry.py shows they face each other across the bar,
    bins of one index opposite). It summed the deepest front and the deepest rear depth of any pockets and
    bins: pocket 0's own faces, 3 mm deep each at the bore end (they lie on the two bars either side of it),
    were refused as a bar worn through, and so was pocket 1's front face with pocket 0's rear face deep at
    opposite ends of the bar (bore and rim)."""
    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"))

    def worn(front, rear):
        rows = {f: [[0.0] * 32 for _ in range(16)] for f in ("front", "rear")}
        for f, (pocket, b) in (("front", front), ("rear", rear)):
            rows[f][pocket][b] = 3000.0
        return {f"wear.worn_depth_{f}_um": rows[f] for f in rows}

    for front, rear in (((0, 0), (0, 0)), ((1, 0), (0, 31)), ((0, 0), (1, 0))):
        assert sc.replace(**worn(front, rear)).wear.worn_depth_front_um[front[0]][front[1]] == 3000.0
    with pytest.raises(UserError, match=r"wear\.worn_depth_front_um: pocket 1's front face and pocket 0's rear face, "
                                        r"either side of the cage bar between them, are worn 6 mm deep together"):
        sc.replace(**worn((1, 5), (0, 5)))
    with pytest.raises(UserError, match="pocket 0's front face and pocket 15's rear face"):
        sc.replace(**worn((0, 0), (15, 0)))


@pytest.mark.slow
def test_life_from_a_pocket_worn_deep_on_both_faces_runs_to_its_limit(tmp_path, capsys):
    """A life study from a scenario whose pocket 0 is worn 3 mm deep at the bore end of both its faces (on
    the two bars either side of it, each carrying one of them) runs to depth=3.05mm and reaches it: no bar
    is worn through. The scenario was refused (3 + 3 mm: 'the bar would be worn through')."""
    from bearingsim.cli import main
    from bearingsim.studies.life import read_life

    deep = [[3000.0] + [0.0] * 31] + [[0.0] * 32 for _ in range(15)]
    scenario = tmp_path / "deep.toml"
    text = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), ["multibody.raceway_contact=rigid"]).replace(
        **{"wear.worn_depth_front_um": deep, "wear.worn_depth_rear_um": deep}).to_toml()
    scenario.write_text(text)
    code = main(["life", str(scenario), "--limit", "depth=3.05mm", "--stages", "1", "--rotations", "1", "-q",
                 "-o", str(tmp_path / "life")])
    out, err = capsys.readouterr()
    assert code == 0 and err == "", (code, err)
    cols, attrs = read_life(tmp_path / "life" / "life.h5")
    assert "worn_through" not in attrs and "not reached" not in out
    assert cols["max_depth_um"][-1] == pytest.approx(3050.0, rel=1e-9)
    on_bar = laws.worn_bar_depth(cols["worn_depth_front_um"][-1], cols["worn_depth_rear_um"][-1])
    assert 3050.0 <= on_bar.max() < laws.cage_bar_width(97.5, 13.0, 0.2, 16) * 1e3


@pytest.mark.parametrize("make, words", [
    (lambda p: None, "file not found"),
    (lambda p: p.mkdir(), "is a directory, not an archive"),
    (lambda p: p.write_text("not hdf5"), "not an HDF5 file"),
    (lambda p: p.write_text('schema_version = 1\nname = "x"\n'), "is a scenario file, not an archive"),
])
def test_wear_cli_says_what_is_wrong_with_its_input(tmp_path, capsys, make, words):
    """`bearingsim wear missing.h5 --hours 1` said "missing.h5: not a bearingsim archive" for a file that is
    not there (and the same for a folder or a text file), where every other archive command says which:
    "file not found", "is a directory", "not an HDF5 file"."""
    from bearingsim.cli import main

    path = tmp_path / "a.h5"
    make(path)
    code = main(["wear", str(path), "--hours", "1", "--no-plots"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (code, out, err)
    assert err.startswith(f"bearingsim: error: {path}: {words}"), err


def test_a_deepest_point_at_a_faces_edge_says_it_depends_on_the_bins():
    """docs/wear.md, Discretization errors: the wear at a face's edge is a line, so an end bin's depth is its
    volume over one bin's area and doubles with each halving of the bins (1374 / 2735 / 5459 / 10911 um at
    16 / 32 / 64 / 128 bins on the wear test). The report's deepest point says so when it lies in an end bin,
    and not when it lies inside the face; a depth limit of the life study says so, the other limits not."""
    from bearingsim.scenario import load_scenario
    from bearingsim.studies.life import depth_limit_note, parse_limit
    import dataclasses

    from bearingsim.wear import WearReport, edge_caveat

    psi = np.linspace(-30.0, 25.0, 32)

    def report(depth):
        z = np.zeros((32, 2))
        return WearReport(psi, depth, z, z[0], z[0], 1.0, 1.0, 1.0, 1e-5, 1e9, 1e-8)

    edge, inside = np.zeros((32, 2)), np.zeros((32, 2))
    edge[0, 1], edge[5, 0] = 2e-3, 1e-3
    inside[0, 1], inside[5, 0] = 1e-3, 2e-3
    assert "doubles each time the bins halve" in edge_caveat(report(edge))
    assert "1.77 deg of psi wide" in edge_caveat(report(edge))  # 55 deg over 31 bin steps
    assert edge_caveat(report(inside)) == ""
    # a worn start (the scenario's own depth, given, not binned by this report): the caveat is about the wear of
    # the running time; a starting depth at an end bin, deeper than any wear, carried it before
    start = np.zeros((32, 2))
    start[0, 0] = 50e-6
    worn = WearReport(psi, inside * 1e-3, np.zeros((32, 2)), np.zeros(2), np.zeros(2), 1.0, 1.0, 1.0, 1e-5, 1e9,
                      1e-8, start_front=start, start_rear=np.zeros((32, 2)))
    assert worn.max_depth == 50e-6 and edge_caveat(worn) == ""
    assert "doubles each time the bins halve" in edge_caveat(dataclasses.replace(worn, depth_front=edge * 1e-3))
    sc = load_scenario(SCENARIOS / "wear_test_6000rpm.toml")
    assert "1.85 deg of psi wide" in depth_limit_note(sc, parse_limit("depth=0.1mm"))
    assert depth_limit_note(sc, parse_limit("clearance=0.4mm")) is None


def test_a_life_of_few_stages_with_the_shape_fed_back_is_noted_as_read_long():
    """docs/wear.md, *The life depends on the stage count* (``python -m benchmarks.discretization stages``): with
    the worn shape fed back 10 stages read the life 11-16 % long against 40, and 20 lie within 2 % of 40; with
    the uniform growth any count within 1.2 %. So a shape-mapped study of fewer than 20 stages is noted, naming
    its count and the count that resolves it; 20 and more, and the uniform mapping, are not."""
    from bearingsim.studies.life import STAGES_RESOLVED, stage_count_note

    from bearingsim.cli_wear import DEFAULT_STAGES

    assert STAGES_RESOLVED == DEFAULT_STAGES == 20  # bearingsim life's default is the resolving count
    note = stage_count_note(10, "shape")
    assert note.startswith("10 stages with the worn shape fed back") and "--stages 20 or more" in note
    assert "11-16 %" in note and "docs/wear.md" in note
    assert stage_count_note(19, "shape") is not None
    assert stage_count_note(20, "shape") is None and stage_count_note(40, "shape") is None
    assert stage_count_note(5, "uniform") is None


def test_a_life_figure_says_what_it_is_of():
    """life.png's title gave the limit and the time alone: no scenario, speed, load, k or H, although the life
    scales as H / k. Its second line names them, the mapping and the rotations per stage, from the history's
    attributes (a history without a scenario says '?')."""
    from bearingsim.studies.life import _life_subtitle

    sc = load_scenario(SCENARIOS / "wear_test_6000rpm.toml", ["wear.wear_coefficient=6e-4"])
    line = _life_subtitle({"scenario": sc.to_toml(), "mapping": "shape", "rotations": 10})
    assert line == ("wear_test_6000rpm: 6000 rpm, 922 N; Archard k = 0.0006, H = 1.5e+09 Pa (the life scales as "
                    "H / k); shape mapping, 10 recorded cage rotations per stage")
    assert _life_subtitle({}) == ("?: ?, ?; Archard k = ?, H = ? (the life scales as H / k); ? mapping, ? recorded "
                                  "cage rotations per stage")


def test_a_scenarios_wear_coefficient_of_0_is_refused_as_an_argument_of_0_is(tmp_path, capsys):
    """A run whose scenario sets wear.wear_coefficient = 0 (a scenario takes it: nothing wears) gave `bearingsim
    wear` a report of zeros with a coefficient of variation of nan, a front / rear ratio of nan .. nan, numpy's
    'All-NaN slice' warnings and the end-bin caveat on a depth of 0, exit 0; the same k given as an argument was
    refused. The scenario's k goes through the same check: one line naming the key (the command line: and the
    archive), exit 2; another k given as an argument still reports."""
    from bearingsim.cli import main
    from bearingsim.simulation import load, run_scenario
    from bearingsim.wear import wear_report

    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"),
                       ["numerics.rotations=1", "multibody.raceway_contact=rigid", "wear.wear_coefficient=0"])
    path = tmp_path / "k0.h5"
    run_scenario(sc, path, figures=False, notes=False)
    res = load(path)
    with pytest.raises(UserError, match=r"^wear\.wear_coefficient = 0 in the archive's scenario: nothing wears"):
        res.wear_report(rotations=1e5)
    assert wear_report(res, rotations=1e5, wear_coefficient=1e-5).max_depth > 0.0
    code = main(["wear", str(path), "--rotations", "1e5", "--no-plots"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "", (code, out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"bearingsim: error: {path}: wear.wear_coefficient = 0 "), err


def test_the_worn_volume_mean_gives_its_standard_error_and_the_rotations_it_extrapolates_from(fast_run):
    """The worn volume mean over pockets of a face is the mean of the recorded rotations' face totals scaled to
    the running time; the report printed it without its error. It gives the batch-means standard error
    (stats.batch_sem over rotations of the per-rotation face totals: the pockets' mean sliding work per rotation,
    scaled as the volume is) and the number of recorded rotations, in the data and in the text."""
    from bearingsim.stats import batch_sem, pocket_means, with_error
    from bearingsim.wear import format_report

    res, _ = fast_run
    rep = res.wear_report(rotations=1.6e5)
    p = res.parameters
    cage_rot = 1.6e5 * res.summary["cage_speed_mean_rad_s"] / p.operating.omega_i
    assert rep.recorded_rotations == res.per_rotation["I_dec"].shape[0] == 2
    for f, v in (("front", rep.volume_front), ("rear", rep.volume_rear)):
        work = res.per_rotation[f"slide_work_{f}"]
        expected = p.wear.wear_coefficient * batch_sem(pocket_means(work)) * cage_rot / p.wear.hardness
        assert rep.volume_sem(f) == pytest.approx(expected, rel=1e-12, abs=0) and rep.volume_sem(f) > 0.0
        np.testing.assert_allclose(rep.volume_rotations(f).mean(axis=0), v, rtol=1e-12)
        line = next(ln for ln in format_report(rep).splitlines() if ln.startswith(f"{f}: worn volume mean"))
        shown = with_error(v.mean() * 1e9, rep.volume_sem(f) * 1e9)  # as the tables show it
        assert f"mean {shown} mm^3 over pockets (standard error" in line and "2 recorded rotations" in line, line


def test_the_spread_over_pockets_is_given_beside_what_sampling_alone_gives(fast_run):
    """The coefficient of variation over pockets falls as 1/sqrt(rotations) (0.132 / 0.080 / 0.060 / 0.048 at
    4 / 10 / 20 / 40 rotations of one run; the model's pockets are identical): it is mostly the rotations'
    scatter, and it was printed alone. Beside it the report gives what identical pockets would show from that
    scatter alone (the pockets' mean batch-means standard error over their mean volume) and the rotations it
    comes from. Identical pockets drawn at random show, on the average over draws, the spread it estimates."""
    from bearingsim.stats import batch_sem
    from bearingsim.wear import WearReport, format_report

    res, _ = fast_run
    rep = res.wear_report(rotations=1.6e5)
    for f in ("front", "rear"):
        v = rep.volume_rotations(f)
        expected = np.mean([batch_sem(v[:, i]) for i in range(v.shape[1])]) / v.mean()
        assert rep.sampling_cov(f) == pytest.approx(expected, rel=1e-12, abs=0) and rep.sampling_cov(f) > 0.0
        line = next(ln for ln in format_report(rep).splitlines() if ln.startswith(f"{f}: coefficient of variation"))
        assert f"{rep.cov(f):.3f}" in line and f"identical pockets would show {rep.sampling_cov(f):.3f}" in line
        assert "2 recorded rotations" in line, line
    rng = np.random.default_rng(7)
    pairs = []
    for _ in range(200):
        draws = 1.0 + 0.2 * rng.standard_normal((40, 16))
        z = np.zeros((32, 16))
        r = WearReport(np.linspace(-30, 25, 32), z, z, draws.mean(axis=0), draws.mean(axis=0), 1.0, 1.0, 1.0, 1e-5,
                       1e9, 1e-8, draws, draws)
        pairs.append((r.cov("front"), r.sampling_cov("front")))
    cov, sampling = np.mean(pairs, axis=0)
    assert sampling == pytest.approx(cov, rel=0.1), (cov, sampling)  # both ~0.2 / sqrt(40) = 0.032
    assert math.isnan(WearReport(*([np.zeros(1)] * 5), 1.0, 1.0, 1.0, 1e-5, 1e9, 1e-8).sampling_cov("rear"))


def test_wear_says_where_its_extrapolation_goes_through_a_cage_bar(fast_run):
    """`bearingsim wear X.h5 --hours 1000` of a 6000 rpm run printed a deepest point of 7.6e4 um (76 mm)
    beside a cage bar 5.821 mm wide, silently. When the two faces on one bar (pocket i's front face, pocket
    i - 1's rear face: laws.worn_bar_depth, as the life study and a worn scenario check it) wear together as
    deep as the bar is wide in a bin of psi, the report says so in one line (bar, depth against width, the
    extrapolation past it meaningless, bearingsim life); the profile figure draws the bar's width when it lies
    within the depth axis and says the bar is worn through. A short running time says nothing of the bar."""
    from bearingsim.studies.life import _bar
    from bearingsim.wear import format_report

    res, _ = fast_run
    short, long = res.wear_report(rotations=1e3), res.wear_report(hours=1000.0)
    assert long.bar_width == _bar(res.scenario) == pytest.approx(5.821e-3, abs=1e-6)
    assert short.worn_through() is None and "cage bar" not in format_report(short)
    i, depth = long.worn_through()
    on_bar = laws.worn_bar_depth(long.depth_front, long.depth_rear)
    assert depth == on_bar.max() > long.bar_width and on_bar.max(axis=0).argmax() == i
    lines = [ln for ln in format_report(long).splitlines() if "cage bar" in ln]
    assert len(lines) == 1, lines
    assert (f"pocket {i}'s front face and pocket {(i - 1) % 16}'s rear face" in lines[0]
            and f"{depth * 1e3:.4g} mm" in lines[0] and "5.821 mm" in lines[0]
            and "linear extrapolation" in lines[0] and "bearingsim life" in lines[0]), lines[0]
    fig = res.plot_wear_profile(hours=1000.0)
    for ax in fig.axes[:2]:
        assert any(list(ln.get_ydata()) == [long.bar_width * 1e6] * 2 for ln in ax.get_lines()), ax.get_lines()
    assert "worn through" in fig._suptitle.get_text() and "starting depth" not in fig._suptitle.get_text()
    fig = res.plot_wear_profile(rotations=1e3)
    assert "worn through" not in fig._suptitle.get_text()


def test_the_wear_figure_names_the_impulse_its_archive_computed_the_index_from(fast_run, tmp_path):
    """The paper's index is computed from the normal impulse since model version 7, from its circumferential
    component before; an archive keeps its own (the dataset's description says which). The figure's legend
    followed the code, so an older archive's bars were labelled "normal impulse": it follows the archive."""
    import h5py

    from bearingsim.simulation import load

    res, path = fast_run
    labels = [t.get_text() for t in res.plot_wear().axes[0].get_legend().get_texts()]
    assert labels[0] == "front face, impulse index (Eq. 16, normal impulse)", labels
    old = tmp_path / "v6.h5"
    shutil.copy(path, old)
    with h5py.File(old, "r+") as f:  # as model version 6 described it
        for face, q in (("front", "I_acc"), ("rear", "I_dec")):
            f[f"results/wear/paper_index_{face}"].attrs["description"] = (
                f"Archard wear per cage rotation, {face} face, k {q} r_r omega_r / H (paper Eq. 16), per pocket")
    labels = [t.get_text() for t in load(old).plot_wear().axes[0].get_legend().get_texts()]
    assert labels[:2] == ["front face, impulse index (Eq. 16, circumferential impulse I_acc)",
                          "rear face, impulse index (Eq. 16, circumferential impulse I_dec)"], labels


@pytest.mark.slow  # draws the wear figures (~1.6 s)
def test_wear_figures_use_one_fixed_unit_per_quantity(fast_run, monkeypatch):
    """The run's wear figure labelled its axis [10^6 um^3 per hour] for one archive and [10^9 um^3 per hour]
    for another (an exponent chosen from the data), and matplotlib may put its own multiplier on an axis: two
    designs' figures did not compare without rescaling. Volumes are in mm^3 per hour (the text's mm^3), depths
    in um, whatever the numbers, and no axis carries a multiplier or offset."""
    res, _ = fast_run
    p = res.parameters
    get = res.get
    heights = []
    for scale in (1.0, 1000.0):  # an archive of this run's wear, and one of 1000 times more (k 1000 times larger)
        monkeypatch.setattr(res, "get", lambda name, s=scale: get(name) * s if name.startswith("wear/") else get(name))
        fig = res.plot_wear()
        ax = fig.axes[0]
        fig.canvas.draw()
        assert ax.get_ylabel() == "Archard wear volume\n[mm³ per hour]" and ax.yaxis.get_offset_text().get_text() == ""
        heights.append(np.array([b.get_height() for b in ax.patches]))
    np.testing.assert_allclose(heights[1], 1000.0 * heights[0], rtol=1e-12)
    monkeypatch.setattr(res, "get", get)
    # per hour at the run's measured cage speed, as `bearingsim wear --hours 1` (it took the nominal epicyclic
    # speed, 1 + slip times the report's: 0.4 % apart at 6000 rpm)
    np.testing.assert_allclose(heights[0][32:48], res.wear_report(hours=1.0).volume_front * 1e9, rtol=1e-12)
    per_hour = 3600.0 * res.summary["cage_speed_mean_rad_s"] / (2.0 * math.pi)  # cage rotations per hour
    np.testing.assert_allclose(heights[0][32:48], get("wear/sliding_work_front") * per_hour * 1e9, rtol=1e-12)
    for hours in (1e-3, 1e5):
        for fig in (res.plot_wear_profile(hours=hours), res.plot_wear_volume(hours=hours)):
            fig.canvas.draw()
            assert all(ax.yaxis.get_offset_text().get_text() == "" for ax in fig.axes), hours


def test_wear_counts_the_scenarios_own_worn_depth_in_the_deepest_point_and_the_cage_bar(tmp_path, capsys):
    """`bearingsim wear` of a run whose scenario starts worn 2900 um deep at the bore end of every face (the
    bar then carries 5.8 of its 5.821 mm, accepted) reported after 10 h a deepest point of 555 um and no bar
    worn through, where starting depth and new wear put 6.12 mm on one bar: the report left out the scenario's
    own worn depth, which `bearingsim life` counts. Now the deepest point, the cage bar (line, table, figure)
    count it; the volumes and per-face depths stay the wear of the running time. Exact sums (1e-15 m)."""
    from bearingsim import wear
    from bearingsim.cli import main
    from bearingsim.simulation import load, run_scenario

    start = [[2900.0] + [0.0] * 31 for _ in range(16)]
    sc = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"),
                       ["numerics.rotations=2", "multibody.raceway_contact=rigid",
                        f"wear.worn_depth_front_um={start}", f"wear.worn_depth_rear_um={start}"])
    path = tmp_path / "worn.h5"
    run_scenario(sc, path, figures=False, notes=False)
    rep = wear.wear_report(load(path), hours=10.0)
    new = max(rep.depth_front.max(), rep.depth_rear.max())
    total = np.array([rep.depth_front, rep.depth_rear])
    total[:, 0, :] += 2.9e-3
    assert rep.max_depth == pytest.approx(total.max(), abs=1e-15) and rep.max_depth > 2.9e-3
    assert 0.0 < new < 2.0e-3 and rep.max_new_depth == new  # the wear of the running time alone
    on_bar = laws.worn_bar_depth(total[0], total[1])
    assert on_bar.max() > rep.bar_width  # 5.8 mm + the bore ends' new wear on 5.821 mm
    i, depth = rep.worn_through()
    assert depth == pytest.approx(on_bar.max(), abs=1e-15) and i == int(on_bar.max(axis=0).argmax())
    text = wear.format_report(rep)
    assert "the faces start worn" in text and "deepest 2900 um" in text
    assert f"deepest point of any face: {rep.max_depth * 1e6:.4g} um, the starting depth included" in text
    assert f"pocket {i}'s front face" in text and f"{depth * 1e3:.4g} mm deep together" in text
    table = wear.format_comparison({"archive": ["worn.h5"]}, [rep])
    assert f"{rep.max_depth * 1e6:.4g}" in table and f"worn through (pocket {i})" in table
    title = load(path).plot_wear_profile(hours=10.0)._suptitle.get_text()
    assert "deepest 2900 µm, not drawn" in title and f"{depth * 1e6:.0f} µm deep, starting depth included" in title
    assert main(["wear", str(path), "--hours", "10", "--no-plots"]) == 0
    assert "cage bar worn through" in capsys.readouterr().out


def test_a_start_depth_of_other_bins_is_read_as_the_step_loop_reads_it():
    """A worn depth given in other bins than the profile's 32 is put on them as the step loop reads a
    profile: linear between its bin centres, constant in the half bins at the ends (1e-18 m: interpolation of
    a uniform or linear profile is exact to rounding)."""
    from bearingsim.wear import start_depth

    psi = np.linspace(-32.9, 26.2, 33)
    psi = 0.5 * (psi[1:] + psi[:-1])
    one = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), [f"wear.worn_depth_rear_um={[[100.0]] * 16}"])
    front, rear = start_depth(one.parameters, psi)
    assert front.shape == rear.shape == (32, 16) and np.all(front == 0.0)
    np.testing.assert_allclose(rear, 100e-6, rtol=0, atol=1e-18)
    two = load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml"), [f"wear.worn_depth_front_um={[[0.0, 200.0]] * 16}"])
    front, _ = start_depth(two.parameters, psi)
    centres = (-32.9 + 0.25 * 59.1, -32.9 + 0.75 * 59.1)
    want = np.clip((psi - centres[0]) / (centres[1] - centres[0]), 0.0, 1.0) * 200e-6
    np.testing.assert_allclose(front[:, 3], want, rtol=0, atol=1e-18)
    assert start_depth(load_scenario(str(SCENARIOS / "wear_test_6000rpm.toml")).parameters, psi) == (None, None)


def test_sliding_work_per_normal_impulse_is_the_rollers_surface_speed_relative_to_the_cage(fast_run):
    """Physics of the sliding work the wear is made of: at a roller-cage contact the roller's surface slides
    on the pocket face at its spin relative to the cage times its radius, r_r omega_r, with omega_r of the
    paper's Eq. 12 (omega_i of Eq. 10 and the epicyclic cage of Eq. 11 under it: omega_r = (1/gamma - gamma)
    omega_i / 2, gamma = r_r / r_p, laws.roller_spin_speed). So over a whole run the recorded sliding work
    sum J_n |v_slide| over the normal impulse sum J_n, per face over all pockets, is a J_n-weighted mean sliding
    speed near r_r omega_r (15.04 m/s here, the wear test's bearing at 6000 rpm). Measured 14.84 (front) and
    14.83 m/s (rear): 1.3-1.4 % slow, rotation to rotation within 0.1 %. Tolerance 3 %: the rollers spin slower
    than Eq. 12's pure rolling by their slip on the raceways (the cage's alone is 0.5 % here, and unloaded
    rollers lose speed outside the load zone), and their translation in the pocket (0.2 mm of play, contact
    speeds of a few tenths of a m/s) adds to the sliding up to ~1-2 %; 3 % is about twice the measured
    departure. The sliding speed doubled in the recorder (multibody/recorder.py, ``vslide``) passed every
    wear test and gives +97 % here."""
    res, _ = fast_run
    p = res.parameters
    r_r, r_p = p.bearing.roller_radius, p.bearing.pitch_radius
    omega_i = laws.inner_ring_angular_speed(p.operating.inner_ring_speed_rpm)  # Eq. 10
    assert omega_i == pytest.approx(p.operating.omega_i, rel=1e-12)
    surface = r_r * laws.roller_spin_speed(omega_i, r_r, r_p)  # Eq. 12
    assert surface == pytest.approx(15.04, abs=0.01)  # the wear test's bearing at 6000 rpm
    for face in ("front", "rear"):
        work, jn = res.per_rotation[f"slide_work_{face}"].sum(), res.per_rotation[f"Jn_{face}"].sum()
        assert jn > 0.0
        assert work / jn == pytest.approx(surface, rel=0.03), (face, work / jn, surface)


def test_every_count_of_rotations_says_which_body_turns(fast_run, tmp_path, capsys):
    """`numerics.rotations` and `life --rotations` count cage rotations, `wear --rotations` and the life
    history's rotations the inner ring's (2.3 times as many at 6000 rpm), and the life table's header said
    `rotations`, its progress line 'worn on for N rotations', `keys numerics.rotations` nothing and life.h5's
    datasets only the unit 1. Each now names the body: the table's `shaft rotations`, the progress line's and
    life.h5's 'inner-ring (shaft) rotations' (its datasets' description, listed by inspect), inspect's and the
    figure's 'recorded cage rotations per stage', the keys table's 'recorded cage rotations', and the wear
    comparison's 'recorded cage rotations' (the ones it extrapolates from: its header said 'cage rotations',
    which one archive's report, `wear A.h5 --hours 1000`, gives as the running time's, '7.811e+07 cage
    rotations', while the table's column held the 40 recorded)."""
    import shutil

    import h5py

    from bearingsim.cli import main

    out_dir = tmp_path / "l"
    code = main(["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "depth=1mm", "--stages", "1",
                 "--rotations", "1", "--set", "multibody.raceway_contact=rigid", "-o", str(out_dir)])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert re.search(r"worn on for [0-9.e+]+ inner-ring \(shaft\) rotations, deepest", out + err), out + err
    head = next(ln for ln in out.splitlines() if ln.lstrip().startswith("stage "))
    assert "shaft rotations" in head and " rotations " not in head.replace("shaft rotations", ""), head
    with h5py.File(out_dir / "life.h5", "r") as f:
        for name in ("stage_rotations", "rotations_end"):
            assert "inner-ring (shaft) rotations" in f["index"][name].attrs["description"]
    assert main(["inspect", str(out_dir / "life.h5")]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert "rotations: 1 recorded cage rotations per stage" in listed, listed
    assert any(ln.split()[0] == "rotations_end" and "inner-ring (shaft) rotations" in ln for ln in listed), listed
    assert main(["keys", "numerics.rotations"]) == 0
    assert "recorded cage rotations" in capsys.readouterr().out
    other = tmp_path / "again.h5"
    shutil.copy(fast_run[1], other)
    assert main(["wear", str(fast_run[1]), str(other), "--hours", "1", "--no-plots"]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = next(ln for ln in lines if ln.startswith("archive "))
    assert re.split(r"\s{2,}", head.strip())[7] == "recorded cage rotations", lines
    assert "recorded cage rotations the archive extrapolates from" in lines[-1]


def test_consecutive_stages_whose_deepest_point_wears_no_more_share_one_label():
    """`life scenarios/multibody_3000rpm.toml --set numerics.warmup_rotations=2 --rotations 10 --stages 10
    --limit clearance=0.3mm` drew "stage 2/3/4: the deepest point wears no more" once per stage, at the middle
    of each stage of 10 h on a 100 h axis, and the three labels overlapped into an unreadable blur in life.png's
    first panel. A run of consecutive such stages now gets one label, "stages 2–4: ...", over the run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from bearingsim.studies.life import _plot_depths

    # 6 stages, 2 bins, 1 pocket: bin 0 (the deepest) wears in stages 0 and 4, bin 1 alone in 1-3 and 5
    bin0 = [100.0, 100.0, 100.0, 100.0, 150.0, 150.0]
    bin1 = [0.0, 10.0, 20.0, 30.0, 30.0, 40.0]
    front = np.array([[[a], [b]] for a, b in zip(bin0, bin1)])
    cols = {"hours_end": np.arange(1.0, 7.0), "max_depth_um": np.array(bin0),
            "worn_depth_front_um": front, "worn_depth_rear_um": np.zeros_like(front)}
    fig, ax = plt.subplots()
    try:
        _plot_depths(ax, cols, {})
        labels = sorted((t.get_text(), t.xy) for t in ax.texts)
    finally:
        plt.close(fig)
    assert labels == [("stage 5: the deepest\npoint wears no more", (5.5, 150.0)),
                      ("stages 1–3: the deepest\npoint wears no more", (2.5, 100.0))], labels


def test_the_life_historys_depth_rate_is_called_the_fastest_points_not_the_deepest_points(tmp_path, capsys):
    """The life history's depth rate is the largest of any point (what drives a depth limit), which is not the
    deepest point's when another bin is deeper. The table, the figure and life.h5's description of the column
    (listed by inspect) call it the fastest point's depth rate (the table: 'depth rate, fastest point')."""
    from bearingsim.cli import main
    from bearingsim.studies.life import plot_life, read_life

    out_dir = tmp_path / "l"
    code = main(["life", str(SCENARIOS / "wear_test_6000rpm.toml"), "--limit", "depth=1mm", "--stages", "1", "-q",
                 "--rotations", "1", "--set", "multibody.raceway_contact=rigid", "-o", str(out_dir)])
    out, err = capsys.readouterr()
    assert code == 0, err
    head = next(ln for ln in out.splitlines() if ln.lstrip().startswith("stage "))
    assert "depth rate, fastest point [um/h]" in head, head
    assert main(["inspect", str(out_dir / "life.h5")]) == 0
    (line,) = [ln for ln in capsys.readouterr().out.splitlines() if ln.split()[0] == "max_depth_rate_um_per_h"]
    assert "fastest point's depth rate" in line and "not the deepest point's own rate" in line, line
    fig = plot_life(*read_life(out_dir))
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert not any("deepest point's" in lb and "rate" in lb for lb in labels), labels
    assert any(lb.startswith("fastest point's depth rate [µm/h]") for lb in labels), labels


def test_the_wear_profile_figure_marks_its_edge_bins_and_states_the_faces_interior():
    """`bearingsim wear` of 3 rotations of multibody_6000rpm for 10 h: the edge bin at psi = -32 deg (~590 um)
    set the depth axis, the middle of the face (~2 um) could not be seen, and the caveat the command prints
    (the edge's depth "doubles each time the bins halve") was not on the figure. The edge bins are hatched and
    labelled, the caveat is in the title, a second row draws the faces within their edge bins on their own
    scale, and the deepest depth within the faces is stated."""
    from bearingsim.wear import WearReport, plot_wear_profile

    psi = np.linspace(-30.0, 25.0, 32)
    front, rear = np.full((32, 2), 2e-6), np.full((32, 2), 1e-6)
    front[0], rear[-1], front[10, 1] = 590e-6, 80e-6, 4.2e-6
    fig = plot_wear_profile(WearReport(psi, front, rear, np.ones(2) * 1e-9, np.ones(2) * 1e-9, 1e3, 1.0, 1e3, 5e-6,
                                       1.5e9, 1e-8, bar_width=5.821e-3))
    title = fig._suptitle.get_text()
    assert "doubles each time the bins halve" in title and "deepest within the faces: 4.2 µm" in title, title
    top, bottom = fig.axes[:2], fig.axes[2:4]
    labels = top[1].get_legend_handles_labels()[1] + top[0].get_legend_handles_labels()[1]
    assert "edge bins: their depth depends on the bin width" in labels, labels
    assert [ax.get_title() for ax in bottom] == ["front face within its edge bins", "rear face within its edge bins"]
    assert all(top_ax.get_ylim()[1] >= 590.0 for top_ax in top)  # the whole face, edges too
    assert all(4.2 <= ax.get_ylim()[1] < 10.0 for ax in bottom)  # the interior on its own scale


def test_the_wear_volume_figure_names_its_law_and_gives_the_standard_errors_the_command_prints():
    """`bearingsim wear`'s volume figure did not say which wear law gave its volumes (the sliding work's), drew
    no error bars though the command prints a standard error of each face's mean (batch means over the recorded
    rotations), and its titles read "1e+03 h" and "3.6e+06 inner-ring rotations"; the profile figure labelled
    the cage bar's line in mm on an axis in µm. Now the law, k and H are named, each face's mean over pockets is
    drawn ± the standard error the command prints, numbers read 1000 h, 3.6 × 10⁶, 1.5 GPa, and one unit per
    quantity."""
    from bearingsim.stats import with_error
    from bearingsim.wear import WearReport, format_comparison, format_report, plot_wear_profile, plot_wear_volume

    psi = np.linspace(-30.0, 25.0, 32)
    rng = np.random.default_rng(3)
    per_rot = {f: rng.uniform(1e-9, 2e-9, (3, 4)) for f in ("front", "rear")}
    depth = np.full((32, 4), 6e-3)  # deeper than the cage bar is wide: its line is drawn
    rep = WearReport(psi, depth, depth, per_rot["front"].mean(axis=0), per_rot["rear"].mean(axis=0), 3.6e6, 1000.0,
                     1.55e6, 5e-6, 1.5e9, 1e-8, per_rot["front"], per_rot["rear"], bar_width=5.821e-3)
    fig = plot_wear_volume(rep)
    ax = fig.axes[0]
    title = ax.get_title()
    assert "Archard's law on the sliding work" in title and "H = 1.5 GPa" in title, title
    assert "1000 h" in title and "3.6 × 10⁶ inner-ring rotations" in title and "e+" not in title, title
    text = format_report(rep)
    labels = ax.get_legend_handles_labels()[1]
    for f in ("front", "rear"):
        mean, sem = rep.volume_front.mean() if f == "front" else rep.volume_rear.mean(), rep.volume_sem(f)
        # the report, the figure and a table of several archives give a mean with its error alike (with_error: the
        # legend read 37.25 ± 0.054 where the table read 37.247 ± 0.054)
        shown = with_error(mean * 1e9, sem * 1e9)
        assert f"{f}: worn volume mean {shown} mm^3 over pockets (standard error, batch means" in text
        assert f"{f} face, mean over pockets {shown} mm³ (±1 standard error)" in labels, labels
        assert shown in format_comparison({"run": ["a"]}, [rep])
    profile = plot_wear_profile(rep)
    assert "cage bar width 5821 µm" in profile.axes[0].get_legend_handles_labels()[1] + \
        profile.axes[1].get_legend_handles_labels()[1]
    assert "1000 h" in profile._suptitle.get_text() and "e+" not in profile._suptitle.get_text()


def test_the_impulse_figure_draws_the_headline_mean_and_its_standard_error(fast_run, monkeypatch):
    """The per-pocket impulse figure (`_impulses.png`) showed "mean ± std" per pocket, while the run's headline
    is the bearing's mean ± its standard error, which was not on it; of 1 recorded rotation it read "mean ± std
    over 1 cage rotations" with no bars and no word why. Now it says which spread its bars are, draws the
    headline (as the command prints it) as a line and band, and says that 1 rotation has no spread."""
    from bearingsim.results import Result
    from bearingsim.stats import result_standard_errors, with_error

    res, _ = fast_run
    se = result_standard_errors(res)
    ax = res.plot_impulses().axes[0]
    assert "bars: std over the 2 cage rotations of each pocket" in ax.get_title(), ax.get_title()
    labels = ax.get_legend_handles_labels()[1]
    for q in ("I_acc", "I_dec"):
        headline = with_error(res.summary[f"{q}_mean_Ns"] * 1e3, se[f"{q}_sem_Ns"] * 1e3)
        assert any(f"mean of the bearing {headline} mN s (±1 standard error" in lab for lab in labels), (q, labels)
    real = Result.per_rotation
    monkeypatch.setattr(Result, "per_rotation", property(lambda self: {k: v[:1] for k, v in real.fget(self).items()}))
    ax = res.plot_impulses().axes[0]
    assert "1 cage rotation: no spread" in ax.get_title() and "1 cage rotations" not in ax.get_title(), ax.get_title()
    assert any("no standard error from 1 recorded rotation" in lab for lab in ax.get_legend_handles_labels()[1])


def _life_of_a_deepest_edge_that_stops_wearing():
    """A 3-stage clearance life's history as `bearingsim life scenarios/wear_test_6000rpm.toml --limit
    clearance=0.3mm --stages 3 --rotations 2` wrote it (4 bins of psi, 2 pockets here): the rear face's bore-end
    bin of pocket 1 wears to 744.7 um in stages 0-1 and not at all in stage 2, where the next bin of pocket 0
    wears fastest (450.9 um in 4.465 h: 101 um/h), from 36.6 to 487.5 um."""
    psi = np.array([-32.0, -30.3, 0.0, 25.0])
    rear = np.zeros((3, 4, 2))
    rear[:, 0, 1] = [503.1, 744.7, 744.7]
    rear[:, 1, 0] = [10.0, 36.6, 487.5]
    front = np.zeros((3, 4, 2))
    front[:, 3, 0] = [345.4, 464.4, 547.9]
    hours = np.array([7.163, 12.81, 17.275])
    return {"stage": np.arange(3), "clearance_start_mm": np.array([0.2, 0.2333, 0.2667]),
            "stage_rotations": np.array([2.579e6, 2.035e6, 1.607e6]), "rotations_end": np.array([2.579e6, 4.614e6,
                                                                                                6.221e6]),
            "hours_end": hours, "max_depth_rate_um_per_h": np.array([503.1 / 7.163, 241.6 / 5.647, 450.9 / 4.465]),
            "max_volume_rate_mm3_per_h": np.full(3, 0.2), "max_depth_um": np.array([503.1, 744.7, 744.7]),
            "max_volume_mm3": np.array([1.7, 3.0, 4.5]), "clearance_end_mm": np.array([0.2333, 0.2667, 0.3]),
            "I_dec_mean_mNs": np.array([18.41, 22.43, 23.13]), "reused": np.zeros(3, dtype=int),
            "psi_deg": np.tile(psi, (3, 1)), "worn_depth_front_um": front, "worn_depth_rear_um": rear}


def test_the_life_history_says_the_deepest_point_stopped_wearing_where_the_fastest_point_wore_on():
    """A reviewer read life.png of the 3-stage clearance life of wear_test_6000rpm as contradicting itself: the
    deepest worn point flat at 744.7 um from 12.8 h to 17.3 h (the table's 'deepest' too) while the last stage
    wears at 101 um/h. Both are true (life.h5's profiles: the deepest point, an end bin, no longer wears in that
    stage; the fastest point is another bin, which wears 451 um, to 488 um), but neither the table nor the figure
    said so. The table notes it under the history and the figure draws each stage's fastest point's depth, whose
    slope is the rate the third panel gives, beside the deepest point."""
    from bearingsim.studies.life import format_history, plot_life

    cols = _life_of_a_deepest_edge_that_stops_wearing()
    attrs = {"limit": "clearance=0.3mm", "stages": 3, "mapping": "shape", "rotations": 2}
    text = format_history(cols, "life of x to clearance=0.3mm", attrs)
    notes = [ln for ln in text.splitlines() if ln.startswith("stage 2:")]
    assert notes == ["stage 2: the deepest point (744.7 um: rear face of pocket 1, psi -32 deg) did not wear in "
                     "this stage; the stage's depth rate, 101 um/h, is the fastest point's (rear face of pocket 0, psi "
                     "-30.3 deg), which wore 450.9 um, to 487.5 um"], text
    assert not [ln for ln in text.splitlines() if ln.startswith(("stage 0:", "stage 1:"))], text
    ax = plot_life(cols, attrs).axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    fastest = [ln for label, ln in lines.items() if label.startswith("fastest point of each stage")]
    assert len(fastest) == 1, list(lines)
    x, y = (np.asarray(a, dtype=float) for a in fastest[0].get_data())
    ends = y[np.isfinite(y)][1::2]  # a segment per stage, broken by NaN between them
    np.testing.assert_allclose(ends, [503.1, 744.7, 487.5], rtol=1e-9)  # stage 1's fastest point: the deepest
    slope = (y[-2] - y[-3]) / (x[-2] - x[-3])  # the last stage's segment, before its NaN
    assert slope == pytest.approx(cols["max_depth_rate_um_per_h"][-1], rel=1e-9)
    assert any("deepest point of any face" in label for label in lines), list(lines)


def _contrast_on_white(colour) -> float:
    """The contrast ratio of ``colour`` on white (WCAG: 3 for graphics)."""
    from matplotlib.colors import to_rgb

    lin = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in to_rgb(colour)]
    return 1.05 / (0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2] + 0.05)


@pytest.mark.parametrize("stages", [3, 20])
def test_the_life_figures_worn_faces_name_their_stages_and_show_the_first(stages):
    """life.png's worn-face panel said 'darker: later' with no colour bar or stage label, and its early stages
    were nearly invisible (the first of 20 a pale yellow-green on white, under the later ones). A colour bar
    names the stages and when each ended, and every stage's colour stands out on white (contrast 3 or more)."""
    from bearingsim.studies.life import plot_life

    cols = _life_of_a_deepest_edge_that_stops_wearing()
    if stages != 3:
        cols = {k: np.repeat(v[-1:], stages, axis=0) if k != "stage" else np.arange(stages) for k, v in cols.items()}
        cols["hours_end"] = np.linspace(1.0, 20.0, stages)
    fig = plot_life(cols, {"limit": "clearance=0.3mm", "stages": stages})
    faces = fig.axes[3]
    bars = [ax for ax in fig.axes[4:] if "stage" in ax.get_ylabel()]
    assert len(bars) == 1, [ax.get_ylabel() for ax in fig.axes]
    labels = [t.get_text() for t in bars[0].get_yticklabels()]
    assert labels[0].startswith("0") and labels[-1].startswith(str(stages - 1)), labels
    if stages == 3:
        assert labels == ["0 (to 7.16 h)", "1 (to 12.8 h)", "2 (to 17.3 h)"], labels
    colours = [ln.get_color() for ln in faces.get_lines()]
    assert min(_contrast_on_white(c) for c in colours) >= 3.0, sorted(_contrast_on_white(c) for c in colours)[:3]
    assert "darker: later" not in faces.get_title()


@pytest.mark.parametrize("after, said", [(1, "interrupted, its figures not all written"),
                                         (2, "interrupted once its files were written: {0}, {1} are complete")])
def test_a_signal_after_wear_figures_says_which_are_complete(fast_run, tmp_path, monkeypatch, capsys, after, said):
    """SIGINT as soon as wear's first or second (last) figure was written: after the last it said "its figures
    not all written" too; the line names both as complete once both are, exit 130."""
    from bearingsim import plotting
    from bearingsim.cli import main

    real, written = plotting.save_figure, []

    def then_signal(*a, **kw):
        written.append(real(*a, **kw))
        if len(written) == after:
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(1000):  # the handler raises here
                time.sleep(0.01)
            raise AssertionError("signal not delivered")
        return written[-1]

    monkeypatch.setattr(plotting, "save_figure", then_signal)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal user's Python has it
    try:
        assert main(["wear", str(fast_run[1]), "--hours", "1", "-o", str(tmp_path), "-q"]) == 130
    finally:
        signal.signal(signal.SIGINT, previous)
    assert capsys.readouterr().err.strip().splitlines() == [f"bearingsim: {said.format(*written)}"]
    assert sorted(tmp_path.iterdir()) == sorted(written)


@pytest.mark.slow
def test_life_q_prints_its_history_alone(tmp_path, capsys):
    """``life -q`` drops its line per stage and prints the history table (docs/commands.md); it printed its
    "wrote ..." lines too."""
    from bearingsim.cli import main

    assert main(_life_cmd(tmp_path, stages=2)) == 0
    captured = capsys.readouterr()
    assert captured.err == "" and captured.out.startswith("life of ")
    assert not [line for line in captured.out.splitlines() if line.startswith("wrote ")], captured.out
    assert (tmp_path / "life.h5").is_file() and (tmp_path / "life.png").is_file()


def _synthetic_rate(per_front, per_rear):
    """A wear report per rotation of the per-rotation worn volumes ``(rotations, pockets)`` of each face [m^3],
    each face's depth a flat profile of its volume over 32 bins of 1e-8 m^2."""
    from bearingsim.wear import WearReport

    bins = 32
    depth = [np.repeat(v.mean(axis=0)[None, :] / (bins * 1e-8), bins, axis=0) for v in (per_front, per_rear)]
    return WearReport(np.linspace(-30, 25, bins), depth[0], depth[1], per_front.mean(axis=0), per_rear.mean(axis=0),
                      1.0, 1e-4, 0.4, 5e-6, 1e9, 1e-8, per_front, per_rear)


def _pockets_draw(rng, rotations, true):
    """Per-rotation worn volumes of 16 pockets of true means ``true`` (each face half), scattering 35 % per
    rotation each and 10 % together (the cage's motion, shared by the pockets of a rotation)."""
    shared = 0.1 * rng.standard_normal((rotations, 1))
    return [0.5e-12 * (true + 0.35 * rng.standard_normal((rotations, 16)) + shared) for _ in range(2)]


@pytest.mark.slow
def test_the_worst_of_identical_pockets_is_told_as_their_scatter():
    """16 identical pockets (seeded normal scatter, 35 % per rotation and face, 10 % shared by a rotation's
    pockets, 300 draws each): the worst pocket as read leads the mean by 1.77 of its standard errors, 1.20 x the
    mean from 5 rotations, 1.07 x from 40, so a life that follows it reads a lead that is scatter; the history's
    pocket_worst_scatter (life.pocket_rates), what identical pockets read from the scatter alone, matches it on
    average within 2 % at 5, 10, 20 and 40 rotations, and the pockets are not taken for uneven (at most 3 of the
    1200 arrays: the test's false alarm is 0.05 %). The rates are the report's, as read."""
    from bearingsim.studies.life import pocket_rates

    rng = np.random.default_rng(11)
    read, scatter, uneven = {}, {}, 0
    for rotations in (5, 10, 20, 40):
        cols = [pocket_rates(_synthetic_rate(*_pockets_draw(rng, rotations, np.ones(16))), "clearance")[2]
                for _ in range(300)]
        read[rotations] = np.mean([c["pocket_worst_read"] for c in cols])
        scatter[rotations] = np.mean([c["pocket_worst_scatter"] for c in cols])
        uneven += sum(c["pocket_uneven"] for c in cols)
    assert uneven <= 3
    assert read[5] - read[40] > 0.1, read
    assert all(abs(scatter[r] / read[r] - 1.0) < 0.02 for r in read), (read, scatter)
    rate = _synthetic_rate(*_pockets_draw(rng, 10, np.ones(16)))
    d, v, cols = pocket_rates(rate, "clearance")
    assert np.array_equal(v, [rate.volume_front, rate.volume_rear])
    assert np.array_equal(d, [rate.depth_front, rate.depth_rear])
    assert 0.0 < cols["rate_sem_rel"] < 0.3 and math.isnan(pocket_rates(rate, "depth")[2]["rate_sem_rel"])


def test_pockets_that_really_differ_lead_beyond_their_scatter():
    """Pockets whose true means differ by 40 % (a fixed pattern, 10 rotations, seeded): the pockets' test finds
    them uneven, and the worst pocket's lead read (1.4 x and more) is far beyond the one identical pockets read
    from the scatter (about 1.15 x): the life follows a pocket that really wears fastest."""
    from bearingsim.studies.life import pocket_rates

    rng = np.random.default_rng(5)
    true = 1.0 + 0.4 * np.linspace(-1.0, 1.0, 16)
    cols = pocket_rates(_synthetic_rate(*_pockets_draw(rng, 10, true)), "clearance")[2]
    assert cols["pocket_uneven"] == 1 and cols["pocket_worst_read"] > 1.3
    assert cols["pocket_worst_read"] - 1.0 > 2.0 * (cols["pocket_worst_scatter"] - 1.0), cols


def test_a_volume_limit_carries_the_sampling_error_of_the_face_it_follows():
    """A volume limit ends when the largest face volume reaches it, so its life's error follows the face whose
    rate is largest, not the worst pocket's front + rear: here pocket 3's front face wears 2 x, and pocket 7's
    faces 1.8 x each, together more than pocket 3's (seeded, 10 rotations); the volume limit's
    ``rate_sem_rel`` is the batch-means error of pocket 3's front series over its mean, the clearance
    limit's that of pocket 7's front + rear, and a depth limit has none (a point's depth per rotation is not
    kept). The history's first line and the figure's title then name the face."""
    from bearingsim.stats import batch_sem
    from bearingsim.studies.life import format_history, plot_life, pocket_rates

    rng = np.random.default_rng(3)
    front, rear = _pockets_draw(rng, 10, np.ones(16))
    front[:, 3] *= 2.0
    front[:, 7] *= 1.8
    rear[:, 7] *= 1.8
    rate = _synthetic_rate(front, rear)
    assert (front + rear).mean(axis=0).argmax() == 7 and np.stack([front, rear]).mean(axis=1).max() == front[:, 3].mean()
    vol = pocket_rates(rate, "volume")[2]["rate_sem_rel"]
    assert vol == batch_sem(front[:, 3]) / front[:, 3].mean()
    pocket = (front + rear)[:, 7]
    assert pocket_rates(rate, "clearance")[2]["rate_sem_rel"] == batch_sem(pocket) / pocket.mean()
    assert math.isnan(pocket_rates(rate, "depth")[2]["rate_sem_rel"])
    cols = {"stage": np.array([0]), "clearance_start_mm": np.array([0.2]), "stage_rotations": np.array([3.6e6]),
            "rotations_end": np.array([3.6e6]), "hours_end": np.array([10.0]), "max_depth_rate_um_per_h": np.array([5.0]),
            "max_depth_um": np.array([50.0]), "max_volume_mm3": np.array([1.0]), "clearance_end_mm": np.array([0.21]),
            "I_dec_mean_mNs": np.array([18.0]), "reused": np.array([0]), "pocket_worst_read": np.array([1.2]),
            "pocket_worst_scatter": np.array([1.19]), "pocket_uneven": np.array([0]), "rate_sem_rel": np.array([0.05])}
    attrs = {"limit": "volume=1mm3"}
    assert "(±: the sampling error of the worst face's rates" in format_history(cols, "life", attrs).splitlines()[0]
    assert "10 ± 0.5 h" in format_history(cols, "life", attrs).splitlines()[0]
    assert "(±: the worst face's rates' sampling error)" in plot_life(cols, attrs)._suptitle.get_text()


@pytest.mark.slow
def test_the_life_is_given_with_its_sampling_error():
    """The history's first line (bearingsim life, bearingsim table) and the figure's title give a clearance
    life with its sampling error: each stage's hours times the worst pocket's relative rate error, added in
    quadrature (stages of 10 h and 20 h at 3 % and 4 %: sqrt(0.3^2 + 0.8^2) = 0.85 h), and the worst pocket's
    lead read beside the one of identical pockets; a history written before it held the columns prints as it
    did, and a depth limit's (no error: NaN) without one."""
    from bearingsim.studies.life import format_history, history_table, life_error, plot_life

    cols = {"stage": np.array([0, 1]), "clearance_start_mm": np.array([0.2, 0.3]),
            "stage_rotations": np.array([3.6e6, 7.2e6]), "rotations_end": np.array([3.6e6, 1.08e7]),
            "hours_end": np.array([10.0, 30.0]), "max_depth_rate_um_per_h": np.array([50.0, 60.0]),
            "max_depth_um": np.array([500.0, 1200.0]), "max_volume_mm3": np.array([1.0, 2.0]),
            "clearance_end_mm": np.array([0.3, 0.4]), "I_dec_mean_mNs": np.array([18.0, 25.0]),
            "reused": np.array([0, 0]), "pocket_worst_read": np.array([1.2, 1.65]),
            "pocket_worst_scatter": np.array([1.19, 1.21]), "pocket_uneven": np.array([0, 1]),
            "rate_sem_rel": np.array([0.03, 0.04])}
    assert life_error(cols) == pytest.approx(math.hypot(0.3, 0.8), rel=1e-12, abs=0)
    text = format_history(cols, "life of x to clearance=0.4mm", {"limit": "clearance=0.4mm"})
    first = text.splitlines()[0]
    assert first.startswith("life of x to clearance=0.4mm: 30 ± 0.85 h = 1.08e+07 inner-ring rotations in 2 stages "
                            "(±: the sampling error of the worst pocket's rates")  # the ± beside the hours
    assert ("read 1.2-1.65 x the pockets' mean, identical pockets 1.19-1.21 x from the scatter alone, the pockets "
            "uneven beyond it in 1 of 2 stages" in first)
    alike = cols | {"pocket_worst_scatter": np.array([1.21, 1.21])}  # one value, not a span of it to itself
    assert "identical pockets 1.21 x from" in format_history(alike, "life of x", {}).splitlines()[0]
    assert "worst/mean" in text.splitlines()[1] and " 1.650 " in text.splitlines()[3]
    # headers of words stand apart: two spaces at least between columns (one ran "worst/mean of identical pockets
    # reused" together), so splitting the header at runs of two or more spaces gives them back
    heads = [head for _, head, _, _ in history_table("clearance=0.4mm", cols)]
    assert re.split(r" {2,}", text.splitlines()[1].strip()) == heads, text.splitlines()[1]
    title = plot_life(cols, {})._suptitle.get_text()
    assert "30 ± 0.85 h, 1.08e+07 inner-ring rotations, 2 stages (±: the worst pocket's rates' sampling error)" in title
    old = {k: v for k, v in cols.items() if not k.startswith(("pocket_", "rate_sem"))}
    text = format_history(old, "life of x", {})
    assert "±" not in text and "worst/mean" not in text and text.splitlines()[0].endswith("in 2 stages")
    depth = cols | {"rate_sem_rel": np.array([math.nan, math.nan])}
    assert "±" not in format_history(depth, "life of x", {"limit": "depth=0.1mm"}).splitlines()[0]
