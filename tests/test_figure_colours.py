"""What a reader of the report figures sees of the two pocket faces: the reduced model's pass figure draws
both impulses, I_acc and the front face in the house colour FRONT and I_dec and the rear face in REAR in every
figure, and the series a figure compares differ in more than hue (lightness, hatch, marker or line style).
The colours are read from the artists of the returned Figure."""
import numpy as np
import pytest
from matplotlib.colors import to_rgb

import bearingsim
from bearingsim.plotting import FRONT, REAR

from .conftest import SCENARIOS


def luminance(colour) -> float:
    """0.2126 R + 0.7152 G + 0.0722 B of the sRGB values (what a greyscale print keeps of a colour)."""
    r, g, b = to_rgb(colour)
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def same(colour, house) -> bool:
    return np.allclose(to_rgb(colour), to_rgb(house))


def test_house_colours_differ_in_lightness():
    assert abs(luminance(FRONT) - luminance(REAR)) >= 0.15


def _line(ax, label):
    lines = [ln for ln in ax.get_lines() if ln.get_label().startswith(label)]
    assert len(lines) == 1, [ln.get_label() for ln in ax.get_lines()]
    return lines[0]


@pytest.mark.parametrize("rpm, method", [(500, "event"), (500, "euler"), (3000, "event")])
def test_reduced_pass_figure_draws_cumulative_I_acc_and_I_dec(rpm, method):
    """The bottom panel draws the cumulative I_dec (REAR) and I_acc (FRONT), ending at the run's summary values;
    the title gives both, and says an I_acc of 0 (it drew and named I_dec alone: at 500 rpm I_acc is 2/3 of it)."""
    sc = bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml",
                                  set={"operating.inner_ring_speed_rpm": rpm, "reduced.method": method})
    r = bearingsim.run(sc, dt=1e-6 if method == "euler" else None)
    fig = r.plot_pass()
    top, bottom = fig.axes[0], fig.axes[2]
    s = r.summary
    dec, acc = _line(bottom, "$I_{dec}$"), _line(bottom, "$I_{acc}$")
    assert same(dec.get_color(), REAR) and same(acc.get_color(), FRONT)
    assert dec.get_ydata()[-1] * 1e-3 == pytest.approx(s["I_dec_mean_Ns"], rel=1e-12, abs=0)
    assert acc.get_ydata()[-1] * 1e-3 == pytest.approx(s["I_acc_mean_Ns"], rel=1e-12, abs=1e-15)
    legend = [t.get_text() for t in bottom.get_legend().get_texts()]
    assert "$I_{dec}$ (rear face)" in legend and any(t.startswith("$I_{acc}$ (front face)") for t in legend)
    assert same(_line(top, "rear face").get_color(), REAR) and same(_line(top, "front face").get_color(), FRONT)
    title = top.get_title()
    if rpm == 500:
        assert s["I_acc_mean_Ns"] > 0.5 * s["I_dec_mean_Ns"]
        assert f"$I_{{acc}}$ = {s['I_acc_mean_Ns'] * 1e3:.3f} mN s" in title
    else:
        assert s["I_acc_mean_Ns"] == 0.0
        assert "$I_{acc}$ = 0: no front-face impact" in title
    assert f"$I_{{dec}}$ = {s['I_dec_mean_Ns'] * 1e3:.3f} mN s" in title


def test_reduced_pass_figure_of_an_archive_without_cumulative_I_acc(tmp_path):
    """An archive written before the trace recorded I_acc reads and draws: I_dec, I_acc in the title, and the
    legend says its curve is not recorded there (not I_acc = 0)."""
    import h5py

    path = tmp_path / "old.h5"
    r = bearingsim.run(bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml",
                                                set={"operating.inner_ring_speed_rpm": 500}))
    r.save(path)
    with h5py.File(path, "r+") as f:
        del f["results/trace/I_acc_cumulative"]
    fig = bearingsim.load(path).plot_pass()
    assert same(_line(fig.axes[2], "$I_{dec}$").get_color(), REAR)
    assert "$I_{acc}$ = 8.742 mN s" in fig.axes[0].get_title()
    legend = [t.get_text() for t in fig.axes[2].get_legend().get_texts()]
    assert any(t.startswith("$I_{acc}$: not recorded\nin this archive") for t in legend), legend


# --- the two faces in their house colours, in every figure that draws them --------------------------------
def _face_of(label: str) -> str | None:
    """Which face an artist's label names: I_acc, F_acc, front face -> FRONT; I_dec, F_dec, rear face -> REAR."""
    if any(w in label for w in ("I_{acc}", "F_{acc}", "front face")):
        return FRONT
    if any(w in label for w in ("I_{dec}", "F_{dec}", "rear face")):
        return REAR
    return None


def _faces_drawn(ax) -> list[tuple[str, str, tuple]]:
    """(label, its face's house colour, the colour drawn) of every labelled line, error-bar series and bar series
    of ``ax`` that names a face."""
    from matplotlib.colors import to_rgb

    out = []
    for line in ax.get_lines():
        if _face_of(line.get_label()):
            out.append((line.get_label(), _face_of(line.get_label()), to_rgb(line.get_color())))
    for c in ax.containers:
        label = c.get_label() or ""
        if not _face_of(label):
            continue
        if hasattr(c, "patches"):
            out += [(label, _face_of(label), to_rgb(p.get_facecolor())) for p in c.patches]
        else:  # an error-bar series: its markers and its bars
            out.append((label, _face_of(label), to_rgb(c.lines[0].get_color())))
            out += [(label, _face_of(label), to_rgb(col.get_color()[0])) for col in c.lines[2]]
    return out


def _assert_house_colours(fig, least: int):
    drawn = [d for ax in fig.axes for d in _faces_drawn(ax)]
    assert len({label for label, _, _ in drawn}) >= least, drawn
    wrong = [(label, colour) for label, house, colour in drawn if not np.allclose(colour, to_rgb(house))]
    assert not wrong, wrong


@pytest.fixture(scope="module")
def multibody_run():
    import warnings

    sc = bearingsim.load_scenario(SCENARIOS / "wear_test_6000rpm.toml",
                                  set={"numerics.rotations": 2, "multibody.raceway_contact": "rigid"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a short run's note on its warm-up: its figures' colours are the same
        return bearingsim.run(sc)


@pytest.mark.parametrize("name, least", [("forces", 4), ("impulses", 2), ("wear", 4), ("wear_volume", 2)])
def test_multibody_figures_draw_each_face_in_its_house_colour(multibody_run, name, least):
    """_impulses.png drew I_acc blue and I_dec orange, _forces.png F_dec red, _wear.png the rear face orange and
    red, _wear_volume.png the rear face red: each face now has one colour in every figure."""
    fig = getattr(multibody_run, f"plot_{name}")()
    _assert_house_colours(fig, least)


def test_wear_profile_draws_each_face_in_its_house_colour(multibody_run):
    fig = multibody_run.plot_wear_profile(hours=1.0)
    for ax, house in zip(fig.axes, (FRONT, REAR)):
        assert ax.get_title().startswith("front" if house == FRONT else "rear")
        assert [to_rgb(line.get_color()) for line in ax.get_lines() if line.get_label() == "mean over pockets"] == [
            to_rgb(house)]
        assert all(np.allclose(c.get_facecolor()[0][:3], to_rgb(house)) for c in ax.collections)


def test_the_wear_figure_hatches_the_sliding_work_and_keeps_each_face_one_colour(multibody_run):
    """_wear.png's four series had three of one grey (front impulse, front and rear sliding work); the two laws
    of a face are now its colour, the sliding work hatched, and the faces differ in lightness."""
    (ax,) = multibody_run.plot_wear().axes
    series = {c.get_label(): c.patches for c in ax.containers if hasattr(c, "patches")}
    assert len(series) == 4
    for label, patches in series.items():
        assert all(bool(p.get_hatch()) == ("sliding work" in label) for p in patches), label
    front = [luminance(p.get_facecolor()) for lab, ps in series.items() if lab.startswith("front") for p in ps]
    rear = [luminance(p.get_facecolor()) for lab, ps in series.items() if lab.startswith("rear") for p in ps]
    assert min(abs(f - r) for f in set(front) for r in set(rear)) >= 0.15


def test_rig_pocket0_forces_draw_each_face_in_its_house_colour(tmp_path, monkeypatch):
    from pathlib import Path

    from bearingsim import plotting
    from bearingsim.studies.rig import save_rig

    theta = np.linspace(0.0, 360.0, 8)
    rows = [{"rpm": rpm, "rotations": 2.0, "pocket0_I_dec_mean_Ns": 8e-3, "pocket0_I_dec_std_Ns": 1e-3,
             "pocket0_I_dec_sem_Ns": 1e-3, "pocket0_I_acc_mean_Ns": 1e-3, "arc_pockets_I_dec_mean_Ns": 0.03,
             "arc_pockets_I_dec_std_Ns": 2e-3, "reduced_I_dec_Ns": 7e-3, "theta_deg": theta,
             "F_acc_pocket0": np.ones(8), "F_dec_pocket0": np.ones(8), "load_zone_half_angle_deg": 23.5}
            for rpm in (1000.0, 2000.0)]
    figs = []
    monkeypatch.setattr(plotting, "save_figure", lambda fig, path, **kw: figs.append(fig) or Path(path))
    save_rig(tmp_path, rows)
    _assert_house_colours(figs[1], 2)


def test_sweep_figures_draw_I_dec_and_I_acc_in_their_house_colours(tmp_path, monkeypatch):
    """sweep_I.png drew both panels blue, sweep_cases.png I_dec blue and I_acc orange."""
    from pathlib import Path

    from bearingsim import plotting
    from bearingsim.sweeps.plot import plot_sweep_index

    from .test_sweep_figures import SPEED, _index

    figs = {}
    monkeypatch.setattr(plotting, "save_figure", lambda fig, path, **kw: figs.setdefault(Path(path).name, fig)
                        or Path(path))
    points = [{SPEED: 1000.0}, {SPEED: 2000.0}, {SPEED: 3000.0, "contact.restitution": 0.6}]
    plot_sweep_index(_index(tmp_path, points, [SPEED, "contact.restitution"], grid=[SPEED], grid_rows=2),
                     tmp_path / "f")
    assert sorted(figs) == ["sweep_I.png", "sweep_cases.png"]
    for name, fig in figs.items():
        for ax, house in zip(fig.axes, (REAR, FRONT)):  # I_dec left, I_acc right
            drawn = [p.get_facecolor() for p in ax.patches] or [line.get_color() for line in ax.get_lines()]
            assert drawn and all(same(c, house) for c in drawn), (name, ax.get_title(), drawn)


# --- series a figure compares differ in more than hue -------------------------------------------------------
def _distinct(a: dict, b: dict) -> bool:
    """Two series' styles (colour, marker, linestyle, hatch) tell apart in greyscale: luminance 0.15 apart, or
    another marker, line style or hatch."""
    return (abs(luminance(a["colour"]) - luminance(b["colour"])) >= 0.15
            or any(a.get(k) != b.get(k) for k in ("marker", "linestyle", "hatch")))


def test_crosscheck_speeds_differ_in_greyscale_and_each_panel_has_its_face_colour():
    """crosscheck.png drew 1000 rpm blue and 6000 rpm green, the same grey, marker and line; now each speed has
    its own marker and line style, I_dec drawn in REAR and I_acc in FRONT."""
    import itertools
    import math

    from bearingsim.studies import crosscheck as cc

    rows = [dict(rpm=rpm, rung=k, scene=s, I_dec_mean_Ns=5e-3 * k, I_dec_sem_Ns=1e-4, I_acc_mean_Ns=2e-3 * k,
                 I_acc_sem_Ns=1e-4, change_from_previous=math.nan)
            for rpm in (1000.0, 3000.0, 6000.0) for k, s in ((1, "reduced"), (2, "full"))]
    fig = cc.plot_ladder(rows, {"scenario_name": "t"})
    for ax, house in zip(fig.axes[:2], (REAR, FRONT)):
        series = {c.get_label(): {"colour": c.lines[0].get_color(), "marker": c.lines[0].get_marker(),
                                  "linestyle": c.lines[0].get_linestyle()} for c in ax.containers}
        assert sorted(series) == ["1000 rpm", "3000 rpm", "6000 rpm"]
        assert all(same(s["colour"], house) for s in series.values())
        for a, b in itertools.combinations(series, 2):
            assert _distinct(series[a], series[b]), (a, b, series)


def test_uncertainty_first_order_and_total_differ_in_lightness():
    """uncertainty.png drew S1 blue and ST red, the same grey (the hatch marks a bar without an interval)."""
    from bearingsim.studies.uncertainty import plot_indices

    rows = [{"quantity": "I_dec", "key": k, **{f"{n}{end}": 0.4 + d for n in ("S1", "ST")
                                               for end, d in (("", 0.0), ("_low", -0.1), ("_high", 0.1))}}
            for k in ("contact.restitution", "lubrication.drag_coefficient")]
    (ax,) = plot_indices(rows, [{"quantity": "I_dec", "median": 0.018, "p05": 0.017, "p95": 0.019}]).axes
    colours = {c.get_label(): {p.get_facecolor() for p in c.patches} for c in ax.containers if hasattr(c, "patches")}
    assert sorted(colours) == ["first order", "total"] and all(len(v) == 1 for v in colours.values())
    (s1,), (st,) = colours["first order"], colours["total"]
    assert abs(luminance(s1) - luminance(st)) >= 0.15


def test_wear_volume_faces_differ_in_lightness(multibody_run):
    """_wear_volume.png drew the front face blue and the rear red, the same grey."""
    (ax,) = multibody_run.plot_wear_volume(hours=1.0).axes
    colours = [{p.get_facecolor() for p in c.patches} for c in ax.containers if hasattr(c, "patches")]
    assert len(colours) == 2 and all(len(v) == 1 for v in colours)
    assert abs(luminance(colours[0].pop()) - luminance(colours[1].pop())) >= 0.15
