"""The paper's measurement rig as a scene (issue 12): pocket 0 flat, the rest of the cage as built."""
import pytest

from bearingsim.studies.rig import batch_sem, rig_scenario, rig_table
from bearingsim.scenario import load_scenario

from .conftest import SCENARIOS


@pytest.mark.parametrize("rpm", [500, 1000, 2000, 3000, 4000])
def test_rig_scenario_files_are_the_rig_scene(rpm):
    """scenarios/rig_<rpm>rpm.toml resolve to the same scenario as the study's rig_scenario."""
    assert load_scenario(SCENARIOS / f"rig_{rpm}rpm.toml").raw == rig_scenario(float(rpm)).raw


@pytest.mark.slow
def test_flat_rig_pocket_against_the_reduced_model_at_1000_rpm():
    """Goal of issue 12 (paper Fig. 9: the reduced model agreed with the measured pocket): pocket 0's mean
    I_dec per rotation within +-25 % of the reduced model's. Measured on the exact pocket faces
    (bearingsim validate, 1 warm-up + 20 rotations): 8.86 mN s against 7.83 (ratio 1.13); the arc pockets
    of the same cage see 29.1 mN s. The run is deterministic, so the tolerance is the goal, not scatter.
    (At 2000-4000 rpm the ratio is 1.26-1.27, just outside the goal: docs/geometry.md.)

    The verdict must not be one that the statistical error of pocket 0's mean could reverse: the ratio's
    95 % interval, t = 2.776 (Student, 4 degrees of freedom: 5 batch means, docs/statistics.md) times the
    batch-means standard error over the reduced model's exact value, lies inside the window. Measured: sem
    1.28e-3 mN s (0.015 % of the mean), interval +-4.5e-4 in the ratio; it would leave the window only for
    a sem above 3.8 % of the mean. (This replaces "sem < 5 % of the mean", a bound with no reason stated,
    which allowed an interval of +-0.16 around 1.13, across the window's edge.)

    The arc pockets see more than twice pocket 0's impulse: docs/validation.md's claim that the cage's own
    pockets, not the rig's flat one, are where the contact impulse is (2.2-3.8 times over the rig's speeds,
    2.17 the least, at 4000 rpm; hence 2). Measured at 1000 rpm: 3.28 times. Its scatter: the arc pockets'
    std over pocket-rotations is 6.2 mN s; even with only the 15 pockets as independent samples the error
    of their mean is 6.2 / sqrt(15) = 1.6 mN s, 0.18 in the ratio, so 2 lies 7 such errors below 3.28."""
    (row,) = rig_table(speeds=(1000,), rotations=20, jobs=1)
    ratio = row["pocket0_I_dec_mean_Ns"] / row["reduced_I_dec_Ns"]
    assert 0.75 <= ratio <= 1.25, ratio
    half_width = 2.776 * row["pocket0_I_dec_sem_Ns"] / row["reduced_I_dec_Ns"]
    assert 0.75 <= ratio - half_width and ratio + half_width <= 1.25, (ratio, half_width)
    assert row["arc_pockets_I_dec_mean_Ns"] > 2.0 * row["pocket0_I_dec_mean_Ns"]


def test_batch_sem_of_independent_samples():
    """For independent samples the batch-means error estimates std / sqrt(n): a sample sd of 5 batch means
    (4 degrees of freedom) has the mean c4(5) sigma, c4(5) = 0.9400, and a relative sd of 0.34, so the mean
    of 2000 estimates lies within 3 % (about 4 of its standard deviations, 0.76 %) of c4 / sqrt(n) (a window
    of 40 % held for an sd of ddof 0, 11 % low, and a sqrt(b - 1), 12 % high); for a constant series it is 0."""
    import numpy as np

    rng = np.random.default_rng(1)
    est = [batch_sem(rng.normal(size=400)) for _ in range(2000)]
    assert np.mean(est) == pytest.approx(0.9400 / np.sqrt(400), rel=0.03)
    assert batch_sem(np.ones(20)) == 0.0


def test_a_pocket_std_of_na_is_an_open_marker_the_legend_names(tmp_path, monkeypatch):
    """rig_idec_vs_speed.png of one rotation (the table: "± n/a (std)") drew pocket 0 without bars under the
    label "mean ± std over rotations": matplotlib leaves out a NaN bar, and nothing said so. Such a point
    now has an open marker and the label says the std is n/a (here at 1 of 2 speeds)."""
    import math
    from pathlib import Path

    import numpy as np

    from bearingsim import plotting
    from bearingsim.studies.rig import save_rig

    theta = np.linspace(0.0, 360.0, 8)
    rows = [{"rpm": rpm, "rotations": 1.0, "pocket0_I_dec_mean_Ns": 8e-3, "pocket0_I_dec_std_Ns": std,
             "pocket0_I_dec_sem_Ns": math.nan, "pocket0_I_acc_mean_Ns": 1e-3, "arc_pockets_I_dec_mean_Ns": 0.03,
             "arc_pockets_I_dec_std_Ns": 2e-3, "reduced_I_dec_Ns": 7e-3, "theta_deg": theta,
             "F_acc_pocket0": np.zeros(8), "F_dec_pocket0": np.zeros(8), "load_zone_half_angle_deg": 23.5}
            for rpm, std in ((1000.0, math.nan), (2000.0, 5e-4))]
    figs = []
    monkeypatch.setattr(plotting, "save_figure", lambda fig, path, **kw: figs.append(fig) or Path(path))
    save_rig(tmp_path, rows)
    (ax,) = figs[0].axes
    opened = [(float(x), float(y)) for line in ax.lines if line.get_markerfacecolor() == "white"
              for x, y in zip(line.get_xdata(), line.get_ydata())]
    assert opened == [(1000.0, pytest.approx(8.0))]  # pocket 0 at 1000 rpm, in mN s
    labels = ax.get_legend_handles_labels()[1]
    assert "rig scene, flat pocket 0: mean ± std over rotations (open marker: std n/a, 1 of 2 speeds)" in labels
    assert "rig scene, the 15 arc pockets: mean ± std" in labels  # its std is over pockets too: a number
