"""Land-guided cages (issue 12): ``bearing.cage_guidance``, ``bearing.cage_land_clearance_mm``,
``contact.land_friction``. Each test says why its check must hold.

Short runs (1 warm-up + 3 cage rotations at 3000 and 6000 rpm, 970 N), shared through module fixtures.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from bearingsim.errors import UserError
from bearingsim.multibody.core import LAND_OVERLAP_FRACTION, land_params, land_reference_force
from bearingsim.scenario import load_scenario
from bearingsim.simulation import run as simulate
from tests.conftest import SCENARIOS, si
from tests.test_cli import assert_user_error, bearingsim

BASE = SCENARIOS / "multibody_3000rpm.toml"


def _scenario(guidance, rpm=3000, rotations=3, warmup=1, extra=()):
    return load_scenario(BASE, [f"bearing.cage_guidance={guidance}", f"operating.inner_ring_speed_rpm={rpm}",
                                f"numerics.rotations={rotations}", f"numerics.warmup_rotations={warmup}", *extra])


@pytest.fixture(scope="module")
def outer_3000():
    return simulate(_scenario("outer_land"))


@pytest.fixture(scope="module")
def inner_3000():
    return simulate(_scenario("inner_land"))


@pytest.fixture(scope="module")
def outer_6000_frictionless():
    return simulate(_scenario("outer_land", rpm=6000, extra=["contact.land_friction=0"]))


def _half_clearance(res):
    return 0.5 * res.parameters.bearing.cage_land_clearance


# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["outer_3000", "outer_6000_frictionless"])
def test_outer_land_holds_the_cage_within_half_the_clearance(name, request):
    """The outer ring is fixed and centred on the bearing axis: the cage centre can leave the axis by
    c_L/2 plus the land contact's overlap, which the penalty stiffness keeps below 1 % of c_L/2 under
    the reference force (W + centrifugal loads + cage weight). The roller-guided cage of the same
    bearing goes to 0.195 mm at 3000 rpm (measured), beyond c_L/2 = 0.15 mm: the land is in contact."""
    res = request.getfixturevalue(name)
    half = _half_clearance(res)
    s = res.summary
    assert s["land_overlap_max_m"] <= LAND_OVERLAP_FRACTION * half, s["land_overlap_max_m"]
    assert s["land_overlap_max_m"] > 0.0  # the land did carry the cage
    assert s["cage_orbit_max_m"] <= half * (1.0 + LAND_OVERLAP_FRACTION), s["cage_orbit_max_m"]
    assert np.all(res.per_rotation["land_normal"] > 0.0)


@pytest.mark.slow
def test_inner_land_holds_the_cage_about_the_inner_ring(inner_3000):
    """On an inner land the cage is guided by the inner ring, whose centre moves with the load
    (~44 um down): the cage centre stays within c_L/2 (+ 1 % overlap bound) of the ring centre, so
    within that plus the ring's largest offset of the bearing axis."""
    res = inner_3000
    half = _half_clearance(res)
    assert res.summary["land_overlap_max_m"] <= LAND_OVERLAP_FRACTION * half
    cage = res.series["cage_centre"]
    ring = res.series["inner_ring_centre"]
    offset = np.hypot(cage.value[:, 0] - ring.value[:, 0], cage.value[:, 1] - ring.value[:, 1])
    assert offset.max() <= half * (1.0 + LAND_OVERLAP_FRACTION), offset.max()
    ring_max = np.hypot(ring.value[:, 0], ring.value[:, 1]).max()
    assert res.summary["cage_orbit_max_m"] <= half * (1.0 + LAND_OVERLAP_FRACTION) + ring_max


@pytest.mark.parametrize("name", ["outer_3000", "inner_3000"])
def test_cage_angular_momentum_balance_closes_with_the_land_torque(name, request):
    """The cage's angular momentum changes by the torque impulses of the roller contacts plus the land
    friction torque: the balance closes within 1 % of the drive moment sum(I_acc) r_p (as the
    roller-guided test). The land torque is not negligible in it (> 5 % of the drive moment), so the
    balance would not close without it."""
    res = request.getfixturevalue(name)
    s = res.summary
    assert abs(s["torque_balance_residual"]) < 0.01, s["torque_balance_residual"]
    drive = res.per_rotation["I_acc"].sum() * res.parameters.bearing.pitch_radius
    assert abs(s["land_torque_impulse_Nms"]) > 0.05 * drive, (s["land_torque_impulse_Nms"], drive)


def test_land_friction_direction_and_coulomb_ratio(outer_3000, inner_3000):
    """The cage rim slides forward over the fixed outer ring (friction brakes the cage) and backward
    over the faster inner ring (friction drives it). The rim slides at metres per second, far above the
    1 mm/s regularisation of the friction direction, so the friction impulse is mu times the normal
    impulse (to 1e-6) and the torque impulse is R_land times the friction impulse."""
    for res, sense in ((outer_3000, -1.0), (inner_3000, 1.0)):
        p = res.parameters
        sign = p.operating.sign
        mu = p.contact.land_friction
        pr = res.per_rotation
        assert np.all(sense * sign * pr["land_torque"] > 0.0), pr["land_torque"]
        np.testing.assert_allclose(pr["land_friction"], mu * pr["land_normal"], rtol=1e-6)
        np.testing.assert_allclose(np.abs(pr["land_torque"]), p.bearing.cage_land_radius * pr["land_friction"],
                                   rtol=1e-6)


def test_frictionless_land_gives_no_torque(outer_6000_frictionless):
    """contact.land_friction = 0: the land pushes only along the line through the cage centre, which
    has no moment about it: the land torque and friction impulses are exactly zero, the normal not."""
    res = outer_6000_frictionless
    assert res.summary["land_torque_impulse_Nms"] == 0.0
    assert np.all(res.per_rotation["land_friction"] == 0.0)
    assert np.all(res.per_rotation["land_torque"] == 0.0)
    assert res.summary["land_normal_impulse_mean_Ns"] > 0.0
    assert abs(res.summary["torque_balance_residual"]) < 0.01


def test_roller_guided_path_ignores_the_land_keys():
    """With cage_guidance = "rollers" nothing of the land enters the run: changing the land clearance
    and friction leaves every summary number and per-rotation array bit for bit the same, and the
    result has no land entries. (Checked by hand too: `bearingsim run scenarios/multibody_3000rpm.toml`
    gives the same summary and results as before the land was added, `bearingsim compare`.)"""
    short = ["numerics.rotations=1", "numerics.warmup_rotations=1"]
    a = simulate(load_scenario(BASE, short))
    b = simulate(load_scenario(BASE, [*short, "bearing.cage_land_clearance_mm=0.05", "contact.land_friction=0.7"]))
    assert a.summary == b.summary
    assert not any(k.startswith("land") for k in a.summary)
    assert set(a.per_rotation) == set(b.per_rotation) and "land_normal" not in a.per_rotation
    for k in a.per_rotation:
        np.testing.assert_array_equal(a.per_rotation[k], b.per_rotation[k])


def test_land_stiffness_keeps_the_overlap_bound_under_the_reference_force():
    """k F_ref: the penalty's overlap under the reference force is 1 % of c_L/2 by construction, and
    its explicit stability limit 2 sqrt(m_cage / k) is far above the time step (symplectic Euler)."""
    sc = _scenario("outer_land", rpm=6000)
    p = si(sc)
    land = land_params(p, active=True)
    assert land_reference_force(p) / land.stiffness == pytest.approx(LAND_OVERLAP_FRACTION * land.half_clearance)
    from bearingsim.multibody.core import choose_dt

    dt, _, _ = choose_dt(p)
    assert 2.0 * math.sqrt(p.bearing.cage_mass / land.stiffness) > 5.0 * dt


# --- keys ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("value", ["0", "0.0", "-0.1"])
def test_zero_or_negative_land_clearance_refused(value):
    with pytest.raises(UserError, match=r"bearing\.cage_land_clearance_mm: must be > 0 mm"):
        _scenario("outer_land", extra=[f"bearing.cage_land_clearance_mm={value}"])


@pytest.mark.slow
def test_zero_land_clearance_is_one_line_from_the_cli(tmp_path):
    res = bearingsim("run", BASE, "--set", "bearing.cage_guidance=outer_land", "--set",
                     "bearing.cage_land_clearance_mm=0", "-o", tmp_path / "x.h5")
    assert_user_error(res, "bearing.cage_land_clearance_mm", "> 0 mm")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("setting, match", [
    ("contact.land_friction=-0.1", r"contact\.land_friction"),
    ("bearing.cage_guidance=ring", r"bearing\.cage_guidance"),
    ("bearing.cage_land_clearance_mm=10", r"bearing\.cage_land_clearance_mm: the outer land bore"),
    ("bearing.cage_outer_diameter_mm=95", r"bearing\.cage_outer_diameter_mm: the cage"),
])
def test_bad_land_keys_refused(setting, match):
    with pytest.raises(UserError, match=match):
        _scenario("outer_land", extra=[setting])


@pytest.mark.parametrize("clearance", ["0.01", "0.05"])
def test_an_inner_land_the_assembled_ring_already_overlaps_is_refused_before_the_run(clearance, tmp_path):
    """The inner ring starts at its quasi-static displacement (43.9 um below the axis at 970 N: P_d/2 = 40 um plus
    the raceways' approach) and the cage centred on the axis, so an inner land with c_L/2 below that offset starts
    inside the cage rim, a penalty force of up to 77 times its reference force that no step removes. Was: exit 0,
    a note of an "impact on the land" of 770 % (74 %) of c_L/2, and at c_L = 0.01 mm (6000 rpm) a cage at 2.2
    times its epicyclic speed, I_dec 2.2 N s per pocket and rotation. Refused now, by the run and its dry run,
    naming the key and the least clearance it accepts; that clearance, and any outer land, start clear."""
    from bearingsim.simulation import check_run

    sc = _scenario("inner_land", extra=[f"bearing.cage_land_clearance_mm={clearance}"])
    with pytest.raises(UserError, match=r"bearing\.cage_land_clearance_mm = .*inner ring as assembled") as err:
        check_run(sc)
    least = re.search(r"at least ([0-9.]+) mm", str(err.value))
    assert least and 0.08 < float(least.group(1)) < 0.1, str(err.value)
    with pytest.raises(UserError, match=r"bearing\.cage_land_clearance_mm"):
        simulate(sc)
    check_run(_scenario("inner_land", extra=[f"bearing.cage_land_clearance_mm={least.group(1)}"]))
    check_run(_scenario("outer_land", extra=[f"bearing.cage_land_clearance_mm={clearance}"]))
    res = bearingsim("run", BASE, "--set", "bearing.cage_guidance=inner_land", "--set",
                     f"bearing.cage_land_clearance_mm={clearance}", "--dry-run", "-o", tmp_path / "x.h5")
    assert_user_error(res, "bearing.cage_land_clearance_mm", "at least")
    assert list(tmp_path.iterdir()) == []


def test_inner_land_must_clear_the_inner_raceway():
    with pytest.raises(UserError, match=r"bearing\.cage_land_clearance_mm: the inner land"):
        _scenario("inner_land", extra=["bearing.cage_land_clearance_mm=7"])


def test_all_flat_pockets_need_a_land():
    """Flat faces push only along the direction of rotation: with roller guidance nothing would hold
    the cage radially (refused); with a land the land does (accepted)."""
    with pytest.raises(UserError, match=r"multibody\.pocket_shape.*cage_guidance"):
        _scenario("rollers", extra=["multibody.pocket_shape=flat"])
    sc = _scenario("outer_land", extra=["multibody.pocket_shape=flat"])
    assert si(sc).multibody.flat_pockets == tuple(range(16))


def test_defaults():
    """Roller guidance is the default (the paper's cage); the preset's land values are marked
    reconstructed with a reason."""
    from bearingsim.scenario import load_preset

    sc = load_scenario(BASE)
    assert sc.bearing.cage_guidance == "rollers"
    preset = load_preset("NU214-Suzuki2023")
    for key in ("cage_land_clearance_mm", "cage_outer_diameter_mm", "cage_inner_diameter_mm"):
        src = preset["source"]["bearing"][key]
        assert src["kind"] == "reconstructed" and src["reason"]


def test_land_overlap_beyond_the_design_bound_is_noted():
    """The penalty stiffness keeps the overlap below LAND_OVERLAP_FRACTION of c_L/2 under the steady reference
    force only; an impact on the land goes further (measured, docs/stability.md: 3.37 um = 2.2 % of c_L/2 on an
    inner land at 20000 rpm, reverse, where the quasi-static ring's centre jumped into the cage at 1.07 m/s).
    A run beyond the bound says so in a note naming the overlap and the bound; at the bound, no note."""
    from bearingsim import plausibility as pl
    from tests.test_reliability import _FakeResult, _mb_scenario

    sc = _mb_scenario("bearing.cage_guidance=inner_land")
    half = 0.5 * si(sc).bearing.cage_land_clearance
    assert pl.check(_FakeResult(sc, land_overlap_max_m=LAND_OVERLAP_FRACTION * half)) == []
    notes = pl.check(_FakeResult(sc, land_overlap_max_m=3.37e-6))
    assert len(notes) == 1, notes
    assert "3.37 um" in notes[0] and "2.2 %" in notes[0] and "1 %" in notes[0], notes[0]
    assert "multibody.inner_ring" in notes[0]  # the quasi-static ring's jumps: the dynamic ring has none
    outer = _mb_scenario("bearing.cage_guidance=outer_land")
    notes = pl.check(_FakeResult(outer, land_overlap_max_m=3.37e-6))
    assert len(notes) == 1 and "multibody.inner_ring" not in notes[0], notes


def test_a_land_guided_cage_that_never_touches_its_land_is_noted():
    """An outer-land-guided cage with a land clearance of 0.5 mm (within the preset's plausible 0.2-0.5 mm) never
    reaches its land at 970 N: its rollers hold it about 200 um off the axis, inside the 250 um the land leaves, and
    the run's numbers were the roller-guided cage's bit for bit, with no word that the guidance asked for had no
    effect. Such a run says so in a note naming the land clearance; a cage that touches its land gets none."""
    from bearingsim import plausibility as pl
    from tests.test_reliability import _FakeResult, _mb_scenario

    far = simulate(_scenario("outer_land", rpm=6000, extra=["bearing.cage_land_clearance_mm=0.5"]))
    rollers = simulate(_scenario("rollers", rpm=6000))
    assert far.summary["land_normal_impulse_mean_Ns"] == 0.0
    assert far.summary["I_dec_mean_Ns"] == rollers.summary["I_dec_mean_Ns"]  # the land never acted
    noted = [n for n in far.notes if "never touched its outer land" in n]
    assert len(noted) == 1, far.notes
    assert "(250 um, bearing.cage_land_clearance_mm = 0.5)" in noted[0] and "roller-guided" in noted[0], noted[0]
    assert not any("never touched" in n for n in rollers.notes)
    sc = _mb_scenario("bearing.cage_guidance=inner_land")
    assert any("never touched its inner land" in n
               for n in pl.check(_FakeResult(sc, land_normal_impulse_mean_Ns=0.0, cage_rest_offset_m=1.9e-4)))
    assert pl.check(_FakeResult(sc, land_normal_impulse_mean_Ns=0.13, cage_rest_offset_m=1.5e-4)) == []
    assert pl.check(_FakeResult(_mb_scenario(), land_normal_impulse_mean_Ns=0.0)) == []  # roller-guided: no land


def test_the_land_guided_runs_here_touch_their_land(outer_3000, inner_3000):
    assert not any("never touched" in n for r in (outer_3000, inner_3000) for n in r.notes)
