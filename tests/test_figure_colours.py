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
    assert dec.get_ydata()[-1] * 1e-3 == pytest.approx(s["I_dec_mean_Ns"], rel=1e-12)
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
    """An archive written before the trace recorded I_acc reads and draws: I_dec, and I_acc in the title."""
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
