"""Sweep figures drawn from a sweep index (issue 28, defect 4): every sweep draws something meaningful
or says in one line why not; heat maps of sampled cells only; I_dec and I_acc apart; the sweep's title.

The indexes are written directly (:func:`bearingsim.sweeps.index.write_index`): nothing is simulated."""
import json
import math

import numpy as np

import pytest

from bearingsim.sweeps.index import write_index
from bearingsim.sweeps.plot import plot_sweep_index

from .conftest import SCENARIOS
from .test_cli import assert_user_error, bearingsim

SPEED = "operating.inner_ring_speed_rpm"
GUIDE = "bearing.cage_guidance"
CLEAR = "bearing.pocket_clearance_mm"


def _index(folder, points, keys, *, grid=None, grid_rows=None, mode="product", failed=(), results=True,
           sem=lambda i: 1e-4):
    """An index of ``points``; case i's I_dec is 5 + i mN s, I_acc 2 + i / 2, their standard errors
    ``sem(i)`` and half of it [N s] (NaN: none, as a run of one recorded rotation has)."""
    rows = []
    for i, values in enumerate(points):
        ok = results and i not in failed
        rows.append({"case": f"c{i}", "values": values, "status": "done" if ok else "failed", "error": "",
                     "archive": "", "wall_s": 0.1,
                     "summary": {"I_dec_mean_Ns": 0.005 + 0.001 * i, "I_dec_sem_Ns": sem(i),
                                 "I_acc_mean_Ns": 0.002 + 0.0005 * i, "I_acc_sem_Ns": 0.5 * sem(i)} if ok else {}})
    grid = keys if grid is None else grid
    meta = {"mode": mode, "grid": json.dumps(grid), "grid_rows": len(points) if grid_rows is None else grid_rows,
            "scenario": "scenarios/paper_3000rpm.toml"}
    write_index(folder, rows, keys, meta)
    return folder / "sweep.h5"


@pytest.fixture
def figures(monkeypatch):
    """The matplotlib figures the sweep plot saves, by file name (captured before they are closed)."""
    import bearingsim.plotting as plotting

    seen = {}
    real = plotting.save_figure

    def capture(fig, path, **kw):
        seen[path.name] = {"title": fig._suptitle.get_text() if fig._suptitle else "",
                           "axes": [{"title": ax.get_title(), "ylabel": ax.get_ylabel(), "xlabel": ax.get_xlabel(),
                                     "xlim": ax.get_xlim(),
                                     "ylim": ax.get_ylim(),
                                     "xticks": [t.get_text() for t in ax.get_xticklabels()],
                                     "yticks": [t.get_text() for t in ax.get_yticklabels()],
                                     "texts": [t.get_text() for t in ax.texts],
                                     "colours": {tuple(line.get_color()) if not isinstance(line.get_color(), str)
                                                 else line.get_color() for line in ax.lines}}
                                    for ax in fig.axes if ax.get_label() != "<colorbar>"]}
        return real(fig, path, **kw)

    monkeypatch.setattr(plotting, "save_figure", capture)
    return seen


@pytest.fixture
def drawn(monkeypatch):
    """The matplotlib figures the sweep plot saves, by file name, whole (their artists)."""
    import bearingsim.plotting as plotting

    seen = {}
    real = plotting.save_figure

    def keep(fig, path, **kw):
        seen[path.name] = fig
        return real(fig, path, **kw)

    monkeypatch.setattr(plotting, "save_figure", keep)
    return seen


def _bars(ax) -> list:
    """The error bars an axes draws: the segments of its errorbar containers (one of length 0 included:
    its caps show; a NaN error leaves none)."""
    return [seg for c in ax.containers if hasattr(c, "has_yerr") or hasattr(c, "has_xerr")
            for col in c.lines[2] for seg in col.get_segments() if len(seg)]


def _open_markers(ax) -> list:
    """(x, y) of the markers drawn open (white face): the values without a standard error."""
    return [(float(x), float(y)) for line in ax.lines if line.get_markerfacecolor() in ("white", "w", (1, 1, 1, 1))
            for x, y in zip(line.get_xdata(), line.get_ydata())]


@pytest.mark.slow
def test_a_missing_standard_error_is_no_bar_and_is_said(tmp_path, drawn):
    """A sweep of one recorded rotation per case has no standard error (the table: ``18.41 ± n/a``); the
    line figure drew it as an error bar of 0 (``np.nan_to_num``) under "error bars: ±1 standard error".
    Now such a point has no bar, an open marker, and the panel's title counts it."""
    speeds = (1000.0, 2000.0, 3000.0)
    h5 = _index(tmp_path, [{SPEED: s} for s in speeds], [SPEED], sem=lambda i: 1e-4 if i == 1 else math.nan)
    plot_sweep_index(h5, tmp_path / "f")
    for ax, sem, ends in zip(drawn["sweep_I.png"].axes, (0.1, 0.05), ((5.0, 7.0), (2.0, 3.0))):
        (bar,) = _bars(ax)  # the middle point's only: ± 0.1 mN s (I_acc: ± 0.05)
        assert np.allclose(np.ptp(bar, axis=0), [0.0, 2 * sem])
        np.testing.assert_allclose(sorted(_open_markers(ax)), [(1000.0, ends[0]), (3000.0, ends[1])], rtol=1e-12)
        assert " ".join(ax.get_title().split()).endswith(
            "(error bars: ±1 standard error; open markers: none (n/a), 2 of 3 points)")  # its words (wrapped)
    (tmp_path / "one").mkdir(), (tmp_path / "all").mkdir()
    h5 = _index(tmp_path / "one", [{SPEED: s} for s in speeds], [SPEED], sem=lambda i: math.nan)
    plot_sweep_index(h5, tmp_path / "g")
    for ax in drawn["sweep_I.png"].axes:
        assert _bars(ax) == [] and len(_open_markers(ax)) == 3
        assert ax.get_title().endswith("(no error bars: no point has a standard error (n/a))")
    h5 = _index(tmp_path / "all", [{SPEED: s} for s in speeds], [SPEED])  # every point has one: unchanged
    plot_sweep_index(h5, tmp_path / "h")
    for ax in drawn["sweep_I.png"].axes:
        assert len(_bars(ax)) == 3 and _open_markers(ax) == []
        assert ax.get_title().endswith("(error bars: ±1 standard error)")


def test_a_case_without_a_standard_error_is_a_hatched_bar_without_an_error_bar(tmp_path, drawn):
    """The per-case chart drew a missing standard error as an error bar of 0 too."""
    points = [{SPEED: 1000.0}, {SPEED: 2000.0, "contact.restitution": 0.6}]
    h5 = _index(tmp_path, points, [SPEED, "contact.restitution"], grid=[], grid_rows=0,
                sem=lambda i: math.nan if i == 1 else 1e-4)
    plot_sweep_index(h5, tmp_path / "f")
    for ax in drawn["sweep_cases.png"].axes:
        (bar,) = _bars(ax)
        assert np.allclose(bar[:, 1], 0.0)  # case 0's, on its row
        assert [p.get_hatch() for p in ax.patches] == [None, "//"]
        assert ax.get_title().endswith("(error bars: ±1 standard error; hatched: none (n/a), 1 of 2 bars)")


def test_a_text_key_is_a_categorical_axis(tmp_path, figures, drawn):
    """Text values are categories along the axis, by rank, drawn as markers: a line between them (it was drawn
    for 3 or more) says the values between are in between, and there is nothing between rollers and outer_land."""
    h5 = _index(tmp_path, [{GUIDE: g} for g in ("rollers", "outer_land", "inner_land")], [GUIDE])
    notes = []
    out = plot_sweep_index(h5, tmp_path / "f", notes=notes)
    assert [p.name for p in out] == ["sweep_I.png"] and notes == []
    panels = figures["sweep_I.png"]["axes"]
    assert [a["xticks"] for a in panels] == [["rollers", "outer_land", "inner_land"]] * 2
    for ax in drawn["sweep_I.png"].axes:
        data = [line for line in ax.lines if len(line.get_xdata()) == 3]
        assert data and all(line.get_linestyle() in ("None", "none", "") for line in data), ax.get_ylabel()


@pytest.mark.slow
def test_extra_cases_get_a_per_case_chart(tmp_path, figures):
    points = [{SPEED: 1000.0}, {SPEED: 2000.0}, {SPEED: 3000.0, "contact.restitution": 0.6}]
    h5 = _index(tmp_path, points, [SPEED, "contact.restitution"], grid=[SPEED], grid_rows=2)
    out = plot_sweep_index(h5, tmp_path / "f")
    assert [p.name for p in out] == ["sweep_I.png", "sweep_cases.png"]
    labels = figures["sweep_cases.png"]["axes"][0]["yticks"]
    assert labels[2] == "inner ring speed = 3000, restitution = 0.6" and len(labels) == 3
    # a sweep of extra cases alone
    h5 = _index(tmp_path, points, [SPEED, "contact.restitution"], grid=[], grid_rows=0)
    assert [p.name for p in plot_sweep_index(h5, tmp_path / "g")] == ["sweep_cases.png"]


def test_heat_map_cells_are_the_sampled_values_only(tmp_path, figures):
    xs, ys = (1000.0, 2000.0, 6000.0), (0.1, 0.2)  # unequal steps: cells equal, centred on the ticks
    points = [{SPEED: s, CLEAR: c} for s in xs for c in ys]
    h5 = _index(tmp_path, points, [SPEED, CLEAR], failed=(1,))
    assert [p.name for p in plot_sweep_index(h5, tmp_path / "f")] == ["sweep_map.png"]
    panels = figures["sweep_map.png"]["axes"]
    assert [a["title"].split(":")[0] for a in panels] == ["$I_{dec}$", "$I_{acc}$"]  # apart, own scales
    for a in panels:
        assert a["xticks"] == ["1000", "2000", "6000"] and a["yticks"] == ["0.1", "0.2"]
        assert a["xlim"] == (-0.5, 2.5) and a["ylim"] == (-0.5, 1.5)  # no edge beyond a sampled value
        assert len(a["texts"]) == 6 and "–" in a["texts"]  # every cell's value written; the failed one a gap
    assert set(panels[0]["texts"]) == {"5", "–", "7", "8", "9", "10"}  # mN s, case i: 5 + i
    assert set(panels[1]["texts"]) == {"2", "–", "3", "3.5", "4", "4.5"}  # case i: 2 + i / 2


@pytest.mark.slow
def test_a_maps_title_says_how_large_a_difference_its_standard_errors_leave_unresolved(tmp_path, figures):
    """A map has no error bars: a 2 x 2 multibody map of 3 rotations coloured I_acc 17.8-18.2 mN s with
    no word of its cells' standard errors of 0.52-1.1 mN s (the colours were noise). The title gives the
    largest standard error X and the difference the tables' test resolves for any two cells,
    t sqrt(2) X with t Student's 97.5 % quantile at the fewest batch means less one (here 5 each, an index
    without a rotations column: t = 2.776 at 4 degrees of freedom, test_a_maps_threshold_is_the_tables_test),
    and the colours' span when it is smaller; a cell without one (n/a) is starred; the reduced model's
    exact maps say so; a map of one rotation per case that it has none."""
    points = [{SPEED: s, CLEAR: c} for s in (1000.0, 2000.0, 6000.0) for c in (0.1, 0.2)]
    folders = iter(range(10))

    def titles(sem):
        (tmp_path / (d := f"i{next(folders)}")).mkdir()
        plot_sweep_index(_index(tmp_path / d, points, [SPEED, CLEAR], sem=sem), tmp_path / d / "f")
        return [a["title"] for a in figures["sweep_map.png"]["axes"]], figures["sweep_map.png"]["axes"]

    # I_dec 5-10 mN s with standard errors 0.1-0.6 (case 2: none); I_acc 2-4.5 with half of them
    got, panels = titles(lambda i: math.nan if i == 2 else 1e-4 * (i + 1))
    test = "(5+ batch means):\nthe tables' test resolves every difference\nabove 2.78 × √2 × "
    starred = "\n*: 1 of 6 cells without one (n/a)"
    assert got == [f"$I_{{dec}}$: standard errors up to 0.6 mN s {test}0.6 = 2.4 mN s{starred}",
                   f"$I_{{acc}}$: standard errors up to 0.3 mN s {test}0.3 = 1.2 mN s{starred}"]
    assert [t for t in panels[0]["texts"] if t.endswith("*")] == ["7*"]  # case 2's value, starred
    got, _ = titles(lambda i: 3e-3)  # standard errors of 3 mN s over colours spanning 5
    assert got[0] == f"$I_{{dec}}$: standard errors up to 3 mN s {test}3 = 12 mN s\n(the colours span 5 mN s)"
    got, panels = titles(lambda i: 0.0)  # the reduced model
    assert got == [f"{sym} (exact: the reduced model has no standard error)" for sym in ("$I_{dec}$", "$I_{acc}$")]
    got, panels = titles(lambda i: math.nan)  # one recorded rotation per case
    assert got == [f"{sym} (no cell has a standard error (n/a))" for sym in ("$I_{dec}$", "$I_{acc}$")]
    assert not any(t.endswith("*") for a in panels for t in a["texts"])  # all without: the title says it


def test_a_maps_threshold_is_the_tables_test(tmp_path, figures):
    """A 2 x 2 map of 2 rotations per case said "differences below 2√2 × 0.36 = 1 mN s may be noise" while
    `bearingsim table` did not resolve a difference of 2.74 mN s between cells of 0.36 and 0.14 mN s (its
    rule, docs/statistics.md: Student's t of the Welch-Satterthwaite degrees of freedom of the two errors,
    from 2 batch means each: t = 7.5). The title's threshold is now one the tables' test
    (stats.significant) resolves for every pair of cells: any difference above it, between the map's cells
    here and between any two standard errors up to the map's largest of at least its fewest batch means
    (a bound, not an estimate: exact, no tolerance)."""
    import re

    from bearingsim.stats import significant

    load, sems = "operating.radial_load_N", (0.14e-3, 0.29e-3, 0.36e-3, 0.07e-3)  # I_dec 5, 6, 7, 8 mN s
    points = [{SPEED: s, load: f, "numerics.rotations": 2.0} for s in (4000.0, 6000.0) for f in (900.0, 1000.0)]
    meta_grid = [SPEED, load]
    plot_sweep_index(_index(tmp_path, points, [SPEED, load, "numerics.rotations"], grid=meta_grid,
                            sem=lambda i: sems[i]), tmp_path / "f")
    title = figures["sweep_map.png"]["axes"][0]["title"]
    above = float(re.search(r"= ([0-9.]+) mN s", title).group(1))
    for i in range(4):
        for j in range(i):  # the map's pairs: a difference above the title's is resolved (here 2 and 3 mN s)
            diff = abs(i - j)
            assert diff <= above or significant(5 + i, sems[i] * 1e3, 5 + j, sems[j] * 1e3, 2, 2), (i, j)
    assert "2+ batch means" in title and "the tables' test resolves every difference" in title
    top = max(sems) * 1e3
    for se in np.linspace(0.0, top, 11):  # any two cells of standard errors up to the map's largest
        for b0, b1 in ((2, 2), (2, 5), (5, 40)):
            assert significant(10 + above * 1.0001, top, 10.0, se, b0, b1)


@pytest.mark.slow
def test_a_large_map_is_a_page_with_every_kth_value_labelled(tmp_path, figures):
    """The 100 x 100 map of scenarios/sweeps/map_speed_clearance.toml: the figure stays within the bounds
    of sweeps.plot (9 x 13 in, 1080 x 1555 px at 120 dpi, its panels one above the other; it grew with the
    axes to 29160 x 5700 px, and was 2520 x 1440 px with the panels side by side),
    at most 20 labelled ticks per axis, every 5th value, and no values written in cells of 0.09 in."""
    from PIL import Image

    xs = [500.0 + 55.0 * i for i in range(100)]
    ys = [round(0.05 + 0.005 * j, 4) for j in range(100)]
    h5 = _index(tmp_path, [{SPEED: s, CLEAR: c} for s in xs for c in ys], [SPEED, CLEAR])
    (png,) = plot_sweep_index(h5, tmp_path / "f")
    with Image.open(png) as im:
        assert im.size == (1080, 1555)
    for a in figures["sweep_map.png"]["axes"]:
        assert a["xticks"] == [f"{v:g}" for v in xs[::5]] and a["yticks"] == [f"{v:g}" for v in ys[::5]]
        assert a["xlim"] == (-0.5, 99.5) and a["ylim"] == (-0.5, 99.5) and a["texts"] == []


def test_i_dec_and_i_acc_in_separate_panels(tmp_path, figures):
    h5 = _index(tmp_path, [{SPEED: s} for s in (1000.0, 2000.0)], [SPEED])
    plot_sweep_index(h5, tmp_path / "f")
    panels = figures["sweep_I.png"]["axes"]
    assert len(panels) == 2 and "I_{dec}" in panels[0]["ylabel"] and "I_{acc}" in panels[1]["ylabel"]


def test_title_names_the_swept_keys_and_the_base_scenario_as_a_sweep_of_it(tmp_path, figures):
    """A sweep of paper_3000rpm over 1000-2000 rpm had the title's second line "paper_3000rpm: reduced model
    ...", as a run of that scenario is titled, though no case ran at 3000 rpm. The first line says "sweep of
    paper_3000rpm over" its axes; the second what the cases share, without the name."""
    points = [{SPEED: s, CLEAR: c} for s in (1000.0, 2000.0) for c in (0.1, 0.2)]
    rows = [{"case": f"c{i}", "values": v, "status": "done", "error": "", "archive": "", "wall_s": 0.1,
             "summary": {"I_dec_mean_Ns": 0.005, "I_dec_sem_Ns": 1e-4, "I_acc_mean_Ns": 0.002, "I_acc_sem_Ns": 1e-4}}
            for i, v in enumerate(points)]
    write_index(tmp_path, rows, [SPEED, CLEAR], {"mode": "product", "grid": json.dumps([SPEED, CLEAR]), "grid_rows": 4,
                                                 "scenario": "scenarios/paper_3000rpm.toml",
                                                 "context": "paper_3000rpm: reduced model (event), 970 N"})
    plot_sweep_index(tmp_path / "sweep.h5", tmp_path / "f")
    title = figures["sweep_map.png"]["title"]
    assert title == "sweep of paper_3000rpm over inner ring speed × pocket clearance (4 cases)\n" \
                    "every case: reduced model (event), 970 N", title


def test_title_says_what_the_cases_share(tmp_path, figures):
    """A sweep's figure named the swept keys only: the speed, load, model and what the base scenario and
    --set changed (here the paper scenario at 6000 rpm, pockets of 0.3 mm) were on no figure, so it could
    not go into a report. The second title line says them, leaving out the swept key's base value (the
    paper scenario's load zone, 23.5°)."""
    from bearingsim.scenario import load_scenario, sweep_context

    res = bearingsim("sweep", SCENARIOS / "paper_3000rpm.toml", "--param", "reduced.load_zone_half_angle_deg=20,30",
                     "--set", "operating.inner_ring_speed_rpm=6000", "--set", "bearing.pocket_clearance_mm=0.3",
                     "--no-plots", "-q", "-o", tmp_path / "s", "-j", "1")
    assert res.returncode == 0, res.stderr
    plot_sweep_index(tmp_path / "s" / "sweep.h5", tmp_path / "f")
    context = figures["sweep_I.png"]["title"].split("\n")[1]
    assert context == "every case: reduced model (event), 6000 rpm forward, 970 N; s = 0.3 mm"
    speed = sweep_context(load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["multibody.raceway_contact=rigid"]),
                          ["operating.inner_ring_speed_rpm"])
    assert speed == "multibody_3000rpm: multibody, full scene, forward, 970 N, 1 warm-up + 4 rotations; raceway rigid"


@pytest.mark.slow
def test_plot_says_why_and_fails_when_it_draws_nothing(tmp_path):
    h5 = _index(tmp_path, [{SPEED: s} for s in (1000.0, 2000.0)], [SPEED], results=False)
    assert plot_sweep_index(h5, tmp_path / "f", notes=(notes := [])) == [] and len(notes) == 1
    res = bearingsim("plot", h5, "-o", tmp_path / "g")
    assert_user_error(res, "no figure written", "no case has a result")


def test_too_many_lines_is_said(tmp_path):
    points = [{SPEED: s, CLEAR: c, GUIDE: g} for s in (1000.0, 2000.0) for c in (0.1, 0.2, 0.3)
              for g in ("rollers", "outer_land", "inner_land")]
    notes = []
    assert plot_sweep_index(_index(tmp_path, points, [SPEED, CLEAR, GUIDE]), tmp_path / "f", notes=notes) == []
    assert len(notes) == 1 and "9 combinations" in notes[0]


def test_a_title_states_no_rotation_count_the_sweep_varies():
    """A sweep over ``numerics.rotations=1,2,3`` was titled "... 1 warm-up + 40 rotations", the base
    scenario's count, which no case ran. A swept count (recorded or warm-up rotations) is left out of the
    title; the other one stays."""
    from bearingsim.scenario import load_scenario, sweep_context

    base = load_scenario(SCENARIOS / "multibody_6000rpm.toml", ["multibody.raceway_contact=rigid"])
    rotations = sweep_context(base, ["numerics.rotations"])
    assert "rotations" not in rotations.replace("warm-up rotation", "") and "1 warm-up rotation" in rotations
    warmup = sweep_context(base, ["numerics.warmup_rotations"])
    assert "warm-up" not in warmup and f"{base.numerics.rotations} rotations" in warmup
    both = sweep_context(base, ["numerics.rotations", "numerics.warmup_rotations"])
    assert "rotation" not in both and "warm-up" not in both


def test_an_exact_model_draws_no_error_bars_of_0(tmp_path, drawn):
    """The reduced model's standard errors are 0: the line figure and the per-case chart drew error bars of
    length 0 (their caps, a tick across every marker) under "exact: the reduced model has no standard
    error". Now a value of standard error 0 has no error bar (nor an open marker: it is exact), as the
    tornado has none for an exact model."""
    speeds = (1000.0, 2000.0, 3000.0)
    plot_sweep_index(_index(tmp_path, [{SPEED: s} for s in speeds], [SPEED], sem=lambda i: 0.0), tmp_path / "f")
    for ax in drawn["sweep_I.png"].axes:
        assert _bars(ax) == [] and _open_markers(ax) == [] and ax.get_title().endswith("(exact: the reduced "
                                                                                       "model has no standard error)")
    (tmp_path / "c").mkdir()
    points = [{SPEED: 1000.0}, {SPEED: 2000.0, "contact.restitution": 0.6}]
    h5 = _index(tmp_path / "c", points, [SPEED, "contact.restitution"], grid=[], grid_rows=0, sem=lambda i: 0.0)
    plot_sweep_index(h5, tmp_path / "g")
    for ax in drawn["sweep_cases.png"].axes:
        assert _bars(ax) == [] and [p.get_hatch() for p in ax.patches] == [None, None]


def _title_inside(fig) -> list[bool]:
    """Whether each panel's title, as drawn, lies within the figure and clear of the other panels' titles
    (its renderer's bounding boxes, px)."""
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    edge, boxes = fig.bbox, [ax.title.get_window_extent(renderer) for ax in fig.axes]
    return [edge.x0 <= b.x0 and b.x1 <= edge.x1 and b.y1 <= edge.y1
            and not any(b.overlaps(o) for o in boxes if o is not b) for b in boxes]


@pytest.mark.slow
def test_a_long_panel_title_is_wrapped_within_the_figure(tmp_path, drawn):
    """A sweep over numerics.rotations=1,2,3 titled its I_acc panel "... open markers: none (n/a), 1 of 3
    poin", cut off at the figure's right edge (sweep_I.png, 1200 px), and the per-case chart's titles ran
    into each other and past the edge. Titles are now wrapped to their panel's width: with 12 of 100 points
    (12 of 60 cases) without a standard error every title lies within the figure, its words all there."""
    sem = lambda i: math.nan if i % 8 == 0 and i < 96 else 1e-4  # noqa: E731  (12 of 100: i = 0, 8, ..., 88)
    plot_sweep_index(_index(tmp_path, [{SPEED: 100.0 * (i + 1)} for i in range(100)], [SPEED], sem=sem),
                     tmp_path / "f")
    fig = drawn["sweep_I.png"]
    assert _title_inside(fig) == [True, True]
    assert " ".join(fig.axes[1].get_title().split()).endswith("open markers: none (n/a), 12 of 100 points)")
    (tmp_path / "c").mkdir()
    points = [{SPEED: 100.0 * (i + 1), "contact.restitution": 0.6} for i in range(60)]
    plot_sweep_index(_index(tmp_path / "c", points, [SPEED, "contact.restitution"], grid=[], grid_rows=0,
                            sem=lambda i: math.nan if i % 5 == 0 else 1e-4), tmp_path / "g")  # 12 of 60
    fig = drawn["sweep_cases.png"]
    assert _title_inside(fig) == [True, True]
    assert " ".join(fig.axes[1].get_title().split()).endswith("hatched: none (n/a), 12 of 60 bars)")


def test_a_zipped_axis_names_every_zipped_key_and_its_values(tmp_path, figures):
    """A zipped sweep of speed and drag coefficient labelled its x axis "inner ring speed [rpm]" alone, so a
    rise of I_dec that the drag coefficient (0.01 -> 0.03, zipped) makes read as the speed's; its title put
    "(zipped)" after the extra cases' keys ("...; cases over restitution, direction (zipped)"). The axis
    names the zipped key, a second tick row gives its values, and "(zipped)" goes with the zipped keys."""
    drag = "lubrication.drag_coefficient"
    points = [{SPEED: s, drag: c} for s, c in ((1000.0, 0.01), (2000.0, 0.015), (4000.0, 0.02), (6000.0, 0.03))]
    points.append({SPEED: 3000.0, drag: 0.02, "contact.restitution": 0.6})
    h5 = _index(tmp_path, points, [SPEED, drag, "contact.restitution"], grid=[SPEED, drag], grid_rows=4, mode="zip")
    plot_sweep_index(h5, tmp_path / "f")
    fig = figures["sweep_I.png"]
    for ax in fig["axes"]:
        assert ax["xticks"] == ["1000\n0.01", "2000\n0.015", "4000\n0.02", "6000\n0.03"], ax["xticks"]
    labels = {ax["xlabel"] for ax in fig["axes"]}
    assert labels == {"inner ring speed [rpm]\nzipped with drag coefficient [N^0.754 (s/m)^0.648]\n"
                      "(its values: the second tick row)"}, labels
    first = fig["title"].split("\n")[0]
    assert "inner ring speed, drag coefficient (zipped, 4 cases)" in first, first
    assert first.endswith("1 case over restitution"), first


def _printed_sizes(fig, width_in: float = 6.5) -> dict[str, float]:
    """Every text of ``fig`` (its titles, tick labels, axis labels, colour bar labels, cell values) and its size
    [pt] once the figure is shrunk to ``width_in`` inches (a report's text width; never enlarged)."""
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    scale = min(1.0, width_in / fig.get_size_inches()[0])
    texts = [t for t in fig.findobj(lambda a: hasattr(a, "get_fontsize") and hasattr(a, "get_text"))
             if t.get_visible() and t.get_text().strip()]
    return {t.get_text(): t.get_fontsize() * scale for t in texts}


@pytest.mark.slow  # draws a map at report width (~2 s)
def test_a_map_prints_at_a_report_width_with_rounded_ticks(tmp_path, drawn):
    """The 8 x 6 map of `--param operating.inner_ring_speed_rpm=1000:6500:8 --param
    bearing.pocket_clearance_mm=0.1:0.35:6` was 2520 x 624 px (21 x 5.2 in): at a report's 6.5 in its cell
    values (7 pt) were 2 pt, and its speeds were ticked "1785.71", "2571.43". Its panels are stacked, the
    figure at most 10 in wide, every text at least 7 pt at 6.5 in, the ticks rounded as far as the values'
    step allows (distinct values stay distinct)."""
    speeds = list(np.linspace(1000.0, 6500.0, 8))
    clear = [round(0.1 + 0.05 * j, 2) for j in range(6)]
    plot_sweep_index(_index(tmp_path, [{SPEED: s, CLEAR: c} for s in speeds for c in clear], [SPEED, CLEAR]),
                     tmp_path / "f")
    fig = drawn["sweep_map.png"]
    assert fig.get_size_inches()[0] <= 10.0, fig.get_size_inches()
    small = {t: round(pt, 2) for t, pt in _printed_sizes(fig).items() if pt < 6.95}
    assert small == {}, small
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert len(panels) == 2 and panels[0].get_position().y0 > panels[1].get_position().y1  # one above the other
    for ax in panels:
        assert [t.get_text() for t in ax.get_xticklabels()] == ["1000", "1786", "2571", "3357", "4143", "4929",
                                                                "5714", "6500"]
        assert [t.get_text() for t in ax.get_yticklabels()] == ["0.1", "0.15", "0.2", "0.25", "0.3", "0.35"]
    (tmp_path / "g").mkdir()  # close values keep the digits that tell them apart; few values, their own
    points = [{SPEED: s, CLEAR: c} for s in (1000.0, 1000.4, 1000.8) for c in (0.1, 0.35)]
    plot_sweep_index(_index(tmp_path / "g", points, [SPEED, CLEAR], failed=(1,)), tmp_path / "g" / "f")
    fig = drawn["sweep_map.png"]
    box, edge = fig._suptitle.get_window_extent(fig.canvas.get_renderer()), fig.bbox
    assert edge.x0 <= box.x0 and box.x1 <= edge.x1, fig._suptitle.get_text()  # a narrow map's title wrapped
    assert " ".join(fig._suptitle.get_text().split()).endswith("(1 cell failed or not run: blank)")
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["1000", "1000.4", "1000.8"]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["0.1", "0.35"]


@pytest.mark.slow
def test_a_sweep_of_one_or_two_points_draws_markers_on_impulse_axes_from_0(tmp_path, drawn):
    """A sweep at 3000 rpm alone drew its lone I_acc of 0 on an axis of -0.04..0.04 mN s (negative impulses,
    impossible), and one of 1000 and 6000 rpm joined its two points by a line, a linear trend that 6 points
    show is false (I_acc is 0 from 2700 rpm). An impulse axis starts at 0 when every value is at least 0; the
    points of fewer than 3 values along the axis are markers without a line; 3 or more are joined as before."""
    def panels(speeds, acc=None):
        (tmp_path / (d := f"s{len(speeds)}")).mkdir()
        h5 = _index(tmp_path / d, [{SPEED: s} for s in speeds], [SPEED], sem=lambda i: 0.0)
        if acc is not None:  # the recorded I_acc, as the reduced model gives it
            import h5py

            with h5py.File(h5, "r+") as f:
                f["index/I_acc_mean_Ns"][...] = acc
        plot_sweep_index(h5, tmp_path / d / "f")
        return drawn["sweep_I.png"].axes

    def joined(ax) -> bool:
        return any(line.get_linestyle() not in ("None", "none", "") and len(line.get_xdata()) > 1 for line in ax.lines)

    for ax in panels([3000.0], acc=[0.0]):
        low, high = ax.get_ylim()  # below 0 only the room of half a marker (one at 0 drawn whole): no tick there
        assert -0.05 * high < low < 0.0 < high, (ax.get_ylabel(), low, high)
        assert not any(t.get_text().startswith(("−", "-")) for t in ax.get_yticklabels() if low <= t.get_position()[1])
    for ax in panels([1000.0, 6000.0]):
        low, high = ax.get_ylim()
        assert not joined(ax) and -0.05 * high < low < 0.0
        top = max(line.get_ydata().max() for line in ax.lines if len(line.get_ydata()))
        assert top < 0.96 * high, (top, high)  # room above the highest marker: drawn whole
    for ax in panels([1000.0, 2000.0, 6000.0]):
        assert joined(ax)


def test_swept_values_that_differ_far_down_are_written_apart_in_the_table_and_the_figures(tmp_path, figures):
    """A sweep of operating.radial_load_N=970.000001,970.000002 printed "970" in both rows of its table
    (``%g``), and its line figure ticked "1e-6+9.7e2"; a 2-D sweep over such values put both values' cases
    in one cell of its map (the cells were found by the ``%g`` text). Each value is now written with the
    digits that tell it apart: in the table, the index CSV, the ticks, and the map's cells."""
    from bearingsim.tables import format_table, table_of_index

    load = "operating.radial_load_N"
    (tmp_path / "a").mkdir(), (tmp_path / "b").mkdir()
    h5 = _index(tmp_path / "a", [{load: 970.000001}, {load: 970.000002}], [load])
    table = table_of_index(h5)
    assert table.labels[load] == ["970.000001", "970.000002"]
    assert [ln.split()[0] for ln in format_table(table).splitlines()[2:4]] == ["970.000001", "970.000002"]
    assert [ln.split(",")[1] for ln in (tmp_path / "a" / "sweep.csv").read_text().splitlines()[1:]] == [
        "970.000001", "970.000002"]
    plot_sweep_index(h5, tmp_path / "fa")
    assert figures["sweep_I.png"]["axes"][0]["xticks"] == ["970.000001", "970.000002"]
    points = [{load: v, CLEAR: c} for v in (970.000001, 970.000002) for c in (0.2, 0.2000001)]
    plot_sweep_index(_index(tmp_path / "b", points, [load, CLEAR]), tmp_path / "fb")
    panel = figures["sweep_map.png"]["axes"][0]
    assert panel["xticks"] == ["970.000001", "970.000002"] and panel["yticks"] == ["0.2", "0.2000001"]
    assert len([t for t in panel["texts"] if t.strip()]) == 4, panel["texts"]
