"""What-if sweeps: every grid point is validated before any runs, and each point equals a single run."""
import csv

import pytest

from bearingsim.simulation import run as simulate
from bearingsim.scenario import load_scenario

from .conftest import SCENARIOS
from .test_cli import assert_user_error, bearingsim


def test_sweep_table_matches_single_runs(tmp_path):
    res = bearingsim("sweep", SCENARIOS / "paper_3000rpm.toml", "--param",
                     "operating.inner_ring_speed_rpm=500,6000", "--param", "lubrication.drag_coefficient=0.01,0.03",
                     "-o", tmp_path, "-j", "2")
    assert res.returncode == 0, res.stderr
    with open(tmp_path / "sweep.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 4
    assert (tmp_path / "sweep.png").exists()
    for row in rows:
        sc = load_scenario(SCENARIOS / "paper_3000rpm.toml", [
            f"operating.inner_ring_speed_rpm={row['operating.inner_ring_speed_rpm']}",
            f"lubrication.drag_coefficient={row['lubrication.drag_coefficient']}"])
        assert float(row["I_dec_mean_Ns"]) == pytest.approx(simulate(sc).summary["I_dec_mean_Ns"], rel=1e-12)


def test_sweep_with_a_bad_point_runs_nothing(tmp_path):
    res = bearingsim("sweep", SCENARIOS / "paper_3000rpm.toml", "--param", "contact.restitution=0.5,1.5",
                     "-o", tmp_path)
    assert_user_error(res, "contact.restitution")
    assert list(tmp_path.iterdir()) == []
