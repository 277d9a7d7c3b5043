"""Silent absurd results (issue 30, item 3): inputs no bearing can have are refused with one line
naming the key and the bound; a run that is not statistically steady says so in a note."""
from __future__ import annotations

import pytest

import bearingsim

from .conftest import SCENARIOS
from .test_cli import assert_user_error, bearingsim as cli

PAPER = SCENARIOS / "paper_3000rpm.toml"
MULTIBODY = SCENARIOS / "multibody_3000rpm.toml"


@pytest.mark.parametrize("setting, key", [
    ("wear.wear_coefficient=1e308", "wear.wear_coefficient"),   # was: 1e298 m^3 of wear, exit 0
    ("wear.wear_coefficient=0.5", "wear.wear_coefficient"),
    ("bearing.cage_inertia_kgm2=1e3", "bearing.cage_inertia_kgm2"),  # 0.2 kg ring of 52 mm: <= 5.4e-4
    ("bearing.cage_inertia_kgm2=6e-4", "bearing.cage_inertia_kgm2"),
    ("bearing.cage_inertia_kgm2=1e-6", "bearing.cage_inertia_kgm2"),
    ("bearing.radial_clearance_mm=50", "bearing.radial_clearance_mm"),  # larger than the 13 mm roller
    ("bearing.radial_clearance_mm=5", "bearing.radial_clearance_mm"),   # multibody ran for minutes
])
@pytest.mark.parametrize("scenario", [PAPER, MULTIBODY], ids=["reduced", "multibody"])
def test_impossible_bearing_values_are_refused(scenario, setting, key):
    with pytest.raises(bearingsim.UserError, match=key) as info:
        bearingsim.load_scenario(scenario, overrides=[setting])
    assert "\n" not in str(info.value)


@pytest.mark.slow
def test_the_refusal_is_one_line_from_the_cli(tmp_path):
    res = cli("run", PAPER, "--set", "wear.wear_coefficient=1e308", "-o", tmp_path / "o.h5")
    assert_user_error(res, "wear.wear_coefficient", "Archard")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.filterwarnings("ignore::bearingsim.UnreadKeyWarning")  # the reduced model reads no cage inertia
@pytest.mark.parametrize("setting", ["wear.wear_coefficient=1e-2", "wear.wear_coefficient=0",
                                     "bearing.cage_inertia_kgm2=5.4e-4", "bearing.radial_clearance_mm=0.6",
                                     "bearing.radial_clearance_mm=0"])
def test_values_within_the_bounds_are_accepted(setting):
    bearingsim.load_scenario(PAPER, overrides=[setting])
    bearingsim.load_scenario(MULTIBODY, overrides=[setting])


@pytest.mark.slow
def test_a_decelerating_cage_is_noted_as_not_steady():
    """Almost no traction and a strong oil drag: the cage slows through the whole run (95 -> 60 rad/s in
    one recorded rotation); was reported as one steady slip with no note."""
    sc = bearingsim.load_scenario(MULTIBODY, overrides=["multibody.traction_mu_max=1e-6",
                                                        "lubrication.drag_coefficient=0.2", "numerics.rotations=1"])
    r = bearingsim.run(sc)
    steady = [n for n in r.notes if "not statistically steady" in n]
    assert len(steady) == 1 and "numerics.warmup_rotations" in steady[0], r.notes


def test_a_steady_run_has_no_such_note():
    r = bearingsim.run(bearingsim.load_scenario(MULTIBODY, overrides=["numerics.rotations=1"]))
    assert not [n for n in r.notes if "steady" in n], r.notes


def test_a_coasting_bearing_without_radial_load_is_noted_as_not_steady():
    """At zero radial load nothing drives the rollers (the unloaded inner ring touches none), so the cage
    coasts down: in the hard case (1 warm-up + 2 rotations) its speed fell by 9.5 % of its mean, with
    I_acc / I_dec = 0.77 and a cage slip of +8.7 %, and the run gave no note, because the drift bound was
    20 % where steady runs drift by at most 0.8 % (every other scenarios/hard/multibody_* case)."""
    r = bearingsim.run(bearingsim.load_scenario(SCENARIOS / "hard" / "multibody_load_0.toml"))
    steady = [n for n in r.notes if "not statistically steady" in n]
    assert len(steady) == 1, r.notes
