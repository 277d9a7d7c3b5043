"""Shared test helpers. Paths are absolute so tests run from any folder."""
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"


@pytest.fixture
def base_reduced() -> dict:
    """A minimal reduced-model scenario dictionary on the reference bearing."""
    return {
        "schema_version": 1,
        "name": "t",
        "model": "reduced",
        "bearing": {"preset": "NU214-Suzuki2023"},
        "operating": {"inner_ring_speed_rpm": 3000.0, "radial_load_N": 970.0},
        "reduced": {"load_zone_half_angle_deg": 23.5},
        "numerics": {"rotations": 1},
    }


def si(scenario):
    """The SI parameters of a resolved scenario (what the models take)."""
    from bearingsim.parameters import Parameters

    return Parameters.from_scenario(scenario)
