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
    (At 2000-4000 rpm the ratio is 1.26-1.27, just outside the goal: docs/geometry.md.)"""
    (row,) = rig_table(speeds=(1000,), rotations=20, jobs=1)
    ratio = row["pocket0_I_dec_mean_Ns"] / row["reduced_I_dec_Ns"]
    assert 0.75 <= ratio <= 1.25, ratio
    assert row["arc_pockets_I_dec_mean_Ns"] > 2.0 * row["pocket0_I_dec_mean_Ns"]
    assert row["pocket0_I_dec_sem_Ns"] < 0.05 * row["pocket0_I_dec_mean_Ns"]


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
