"""Numerical stability on the hard cases of scenarios/hard/ (issue 4), each at reduced length.

Every file must either finish with finite, physically bounded results, or refuse at the start with a
UserError (exit code 2) whose message says what to change. Files whose name contains
``dt_too_large`` must refuse; every other file must finish. Bounds checked, and why they must hold:

* reduced model: the roller never leaves its pocket (0 <= l_r <= s, to 1e-12 m: the event solver
  resolves contacts exactly); Newton's second law over the pass closes (m v_end = m ∫a dt + I_dec -
  I_acc, to 1e-9 of the impulses); no approach speed exceeds ∫|a| dt over the pass (impacts multiply
  the relative speed by -e and resting sets it to 0, so only the applied forces can raise it: a
  larger speed is energy from nowhere);
* multibody model: no NaN, no roller deeper than 1 % of the pocket clearance in a cage face, and the
  cage speed bounded by the inner ring's (it is driven by rollers that roll on the inner ring); a cage
  on the outer land stays within half the land clearance plus the land contact's 1 % overlap bound.
"""
import math
import re

import numpy as np
import pytest
from scipy.integrate import quad

from bearingsim.errors import UserError
from bearingsim.scenario import load_scenario
from bearingsim.simulation import run_scenario

from .conftest import SCENARIOS, si
from .test_cli import assert_user_error, bearingsim

HARD = sorted((SCENARIOS / "hard").glob("*.toml"))
# one recorded rotation; a multibody run needs one warm-up rotation before it (refused without: biased
# means, bearingsim.scenario.check_run_request), and the bounds below hold over the whole run, warm-up included
REDUCED_LENGTH = ["numerics.rotations=1", "numerics.warmup_rotations=1"]


def test_hard_cases_cover_the_issue():
    """The hard cases issue 4 names are all present."""
    names = {p.stem for p in HARD}
    for needed in ("150rpm", "20000rpm", "restitution_0", "restitution_0.99", "clearance_0.02mm",
                   "clearance_1mm", "load_0", "load_20kN", "drag_0", "drag_0.2", "reverse", "dt_too_large"):
        assert any(n.endswith(needed) or f"_{needed}" in n for n in names), needed
    for needed in ("rollers_3", "rollers_30"):  # roller count only exists in the multibody model
        assert f"multibody_{needed}" in names, needed


@pytest.mark.slow
@pytest.mark.parametrize("path", HARD, ids=[p.stem for p in HARD])
def test_hard_case(path, tmp_path):
    sc = load_scenario(path, REDUCED_LENGTH)
    out = tmp_path / "h.h5"
    if "dt_too_large" in path.stem:
        with pytest.raises(UserError, match=r"numerics\.dt_s.*(at most|steps up to)"):
            run_scenario(sc, out, figures=False)
        assert not out.exists() and list(tmp_path.iterdir()) == []
        return
    res = run_scenario(sc, out, figures=False)
    assert out.exists()
    summary = res.result.summary
    assert all(np.isfinite(v) or k.startswith("first_impact") for k, v in summary.items()), summary
    if sc.model == "reduced":
        _check_reduced(res.result)
    else:
        _check_multibody(res.result, sc)


def _check_reduced(result):
    inp, sol = result.inputs, result.solution
    s = inp.pocket_clearance
    assert np.all(np.isfinite(sol.trace["l_r"])) and np.all(np.isfinite(sol.trace["dl_r_dt"]))
    tol = 1e-12 if sol.method == "event" else 1e-9
    assert sol.trace["l_r"].min() >= -tol and sol.trace["l_r"].max() <= s + tol
    supply, _ = quad(lambda th: abs(float(inp.acceleration(th))) / inp.omega_c, inp.theta_start, inp.theta_end,
                     limit=400)
    integral, _ = quad(lambda th: float(inp.acceleration(th)) / inp.omega_c, inp.theta_start, inp.theta_end,
                       epsabs=1e-13 * supply, epsrel=1e-12, limit=400)
    scale = max(sol.I_dec, sol.I_acc, inp.mass * supply)
    balance = inp.mass * sol.v_end - (inp.mass * integral + sol.I_dec - sol.I_acc)
    tol_balance = 1e-9 if sol.method == "event" else 1e-3  # euler: O(dt) discretisation error
    assert abs(balance) <= tol_balance * scale, balance / scale
    speeds = sol.impacts["approach_speed"]
    assert speeds.size == 0 or speeds.max() <= supply * (1 + 1e-9)


def _check_multibody(result, sc):
    s = si(sc).bearing.pocket_clearance
    assert np.all(np.isfinite(result.per_rotation["I_dec"])) and np.all(result.per_rotation["I_dec"] >= 0)
    assert result.summary["max_penetration_all_m"] <= 0.01 * s, result.summary["max_penetration_all_m"]
    assert abs(result.summary["cage_speed_mean_rad_s"]) <= si(sc).operating.omega_i
    if sc.bearing.cage_guidance == "outer_land":  # the fixed outer land holds the cage centre (tests/test_land.py)
        from bearingsim.multibody.core import LAND_OVERLAP_FRACTION

        half = 0.5 * si(sc).bearing.cage_land_clearance
        assert result.summary["land_overlap_max_m"] <= LAND_OVERLAP_FRACTION * half
        assert result.summary["cage_orbit_max_m"] <= half * (1.0 + LAND_OVERLAP_FRACTION)


@pytest.mark.slow
def test_dt_too_large_exits_2_from_the_cli(tmp_path):
    """The refusal reaches the user as one line with the largest allowed dt, exit code 2, no archive."""
    res = bearingsim("run", SCENARIOS / "hard" / "reduced_euler_dt_too_large.toml", "-o", tmp_path / "x.h5")
    assert_user_error(res, "numerics.dt_s", "at most")
    assert list(tmp_path.iterdir()) == []


def test_zero_restitution_and_tight_pocket_end_at_rest_with_the_drag_impulse():
    """Cross-check of two hard cases against a closed form: when the roller ends the pass resting on the
    rear face (e = 0, or a 0.02 mm pocket), momentum balance makes I_dec - I_acc equal to the whole
    braking impulse m ∫ (g sin θ + F_o/m) dt of the pass, whatever happened on the way."""
    for name in ("reduced_restitution_0", "reduced_clearance_0.02mm"):
        sc = load_scenario(SCENARIOS / "hard" / f"{name}.toml", REDUCED_LENGTH)
        from bearingsim.simulation import run as simulate

        r = simulate(sc)
        inp = r.inputs
        assert r.solution.v_end == 0.0 and r.solution.l_end == 0.0
        braking, _ = quad(lambda th: -float(inp.acceleration(th)) / inp.omega_c, inp.theta_start, inp.theta_end,
                          epsabs=0.0, epsrel=1e-12, limit=400)
        assert r.solution.I_dec - r.solution.I_acc == pytest.approx(inp.mass * braking, rel=1e-9)
        assert math.isfinite(r.summary["first_impact_speed_m_s"])


@pytest.mark.slow
def test_run_that_goes_unstable_midway_is_stopped_and_not_written(tmp_path):
    """A dt between the Hertz limit 2/omega_n and the refusal threshold (2x) is accepted at the start but
    the raceway contacts blow up (explicit normal force beyond its stability limit). The run must stop
    with one clear line (exit code 3) that names the key to change, and write no archive."""
    from bearingsim.multibody.core import choose_dt

    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml")
    _, _, limit = choose_dt(si(sc))
    out = tmp_path / "u.h5"
    res = bearingsim("run", SCENARIOS / "multibody_3000rpm.toml", "--set", f"numerics.dt_s={1.5 * limit!r}",
                     "--set", "numerics.rotations=1", "-o", out, "--no-plots")
    assert res.returncode == 3, res.stderr
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    assert "numerics.dt_s" in lines[0] and "unstable" in lines[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_cage_that_escapes_its_pockets_is_stopped_and_not_written(tmp_path):
    """Only the rollers guide the cage in this model. With pocket faces of +-10 deg the cage centre
    wanders past the radial reach of the face arcs (R sin A = 1.15 mm) and, unchecked, flew 90 mm off
    the axis with an I_acc 40 times the default's; the run must stop (exit 3) naming the key, no archive."""
    out = tmp_path / "c.h5"
    res = bearingsim("run", SCENARIOS / "multibody_3000rpm.toml", "--set", "multibody.pocket_face_half_angle_deg=10",
                     "--set", "numerics.rotations=3", "-o", out, "--no-plots")
    assert res.returncode == 3, res.stderr
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "multibody.pocket_face_half_angle_deg = 10; the cage wall allows up to" in lines[0], res.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_a_cage_that_escapes_faces_already_at_the_wall_is_told_what_holds_it(tmp_path):
    """A 2 mm pocket clearance (ten times the reference's) lets the roller-guided cage leave the reach of
    faces that already span the cage wall: the run stops (exit 3, no archive) naming the pocket clearance and
    the ring land, and does not advise widening the faces, which the wall does not allow (it did: the
    newcomer's trial was then refused 'at most 21.8' for the half angle it was told to widen)."""
    res = bearingsim("run", SCENARIOS / "multibody_3000rpm.toml", "--set", "bearing.pocket_clearance_mm=2",
                     "--set", "multibody.raceway_contact=rigid", "--set", "numerics.rotations=2",
                     "-o", tmp_path / "c.h5", "--no-plots")
    assert res.returncode == 3, res.stderr
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, res.stderr
    assert ("the faces already span the cage wall (multibody.pocket_face_half_angle_deg = 'auto'): give a smaller "
            "pocket clearance (bearing.pocket_clearance_mm = 2 mm) or guide the cage on a ring land") in lines[0]
    assert "widen" not in lines[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_automatic_dt_restart_is_recorded():
    """The 0.02 mm pocket at 20000 rpm needs a shorter step than the automatic estimate (an approach
    overlaps the 20 um clearance's face by 0.47 um at the automatic step, more than twice the
    1 % bound; at 3000 rpm the exact pocket faces keep it within the bound): the run restarts at a step
    scaled to the measured overlap, ends within the 1 % bound, and the archive's dt_choice says how the
    first step was chosen and why it was shortened."""
    from bearingsim.simulation import run as simulate

    sc = load_scenario(SCENARIOS / "hard" / "multibody_clearance_0.02mm.toml",
                       [*REDUCED_LENGTH, "operating.inner_ring_speed_rpm=20000"])
    r = simulate(sc)
    how = r.provenance["dt_choice"]
    assert how.startswith("auto:") and "restarted at dt" in how, how
    assert r.summary["max_penetration_all_m"] <= 0.01 * si(sc).bearing.pocket_clearance


def test_a_given_step_too_small_to_finish_is_refused_before_the_run():
    """A given ``numerics.dt_s`` far below the automatic step (a mistyped exponent, 1e-12 s for 1e-6 s) was
    accepted by the dry run and ran for hours; one needing more than ``MAX_STEPS_PER_ROTATION`` steps per
    nominal cage rotation (2 pi / omega_c, Eq. 5's cage speed) is refused in one line naming the key and the
    smallest step it takes, which itself is accepted: the bound is the stated one, not a round-off away. The API's
    ``dt=`` is refused as its other bad steps are ("run(): dt: ..."), not as the scenario file's value."""
    import bearingsim as api
    from bearingsim.multibody import core

    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml")
    p = sc.parameters
    smallest = 2.0 * math.pi / p.operating.omega_c / core.MAX_STEPS_PER_ROTATION
    with pytest.raises(UserError, match=r"needs 1(\.0\d)?e\+07 steps per cage rotation, more than 1e\+07"):
        core.choose_dt(p, 0.999 * smallest)
    assert core.choose_dt(p, 1.001 * smallest)[0] == 1.001 * smallest
    res = bearingsim("run", SCENARIOS / "multibody_3000rpm.toml", "--set", "numerics.dt_s=1e-12", "--dry-run")
    assert res.returncode == 2 and res.stderr.count("\n") == 1 and "Traceback" not in res.stderr, res.stderr
    assert "with numerics.dt_s=1e-12: numerics.dt_s: 1e-12 s needs" in res.stderr, res.stderr
    suggested = float(re.search(r"use at least (\S+) s", res.stderr).group(1))  # 3 digits, rounded up: accepted
    assert smallest <= suggested <= 1.01 * smallest and core.choose_dt(p, suggested)[0] == suggested, res.stderr
    with pytest.raises(UserError, match=r"^run\(\): dt: 1e-12 s needs .* \(or leave the step to the automatic "
                                        r"choice\)$"):
        api.run(sc, dt=1e-12)


def test_the_automatic_step_at_a_crawl_is_refused_before_the_run_naming_the_speed():
    """The automatic step is ~4 us at any speed (the stiffest contact and the impacts set it), so at 1 rpm the
    main job's 41 rotations would take 1.41e9 steps (hours) with no word but a progress bar, where a given
    ``numerics.dt_s`` needing more than ``MAX_STEPS_PER_ROTATION`` steps per cage rotation is refused. The
    automatic step is refused at the same bound, in one line naming operating.inner_ring_speed_rpm, the
    rotations' steps and the least speed it runs at, which is accepted (just below it is not); the dry run
    says the same. No shipped scenario is refused."""
    from bearingsim.multibody import core
    from bearingsim.simulation import check_run

    main = SCENARIOS / "multibody_6000rpm.toml"
    res = bearingsim("run", main, "--set", "operating.inner_ring_speed_rpm=1", "--dry-run")
    assert_user_error(res, "with operating.inner_ring_speed_rpm=1: operating.inner_ring_speed_rpm: at 1 rpm",
                      "3.43e+07 steps of the automatic", "numerics.rotations", "1.41e+09 steps")
    least = float(re.search(r"run at (\S+) rpm or more", res.stderr).group(1))
    check_run(load_scenario(main, [f"operating.inner_ring_speed_rpm={least}"]))
    with pytest.raises(UserError, match="operating.inner_ring_speed_rpm: at 3.43 rpm"):
        check_run(load_scenario(main, [f"operating.inner_ring_speed_rpm={least - 0.01:.3g}"]))
    p = load_scenario(main, ["operating.inner_ring_speed_rpm=1"]).parameters
    with pytest.raises(UserError, match=r"^operating.inner_ring_speed_rpm: at 1 rpm"):
        core.choose_dt(p)
    for f in [*sorted(SCENARIOS.glob("*.toml")), *HARD]:
        try:
            sc = load_scenario(f)
        except UserError:
            continue  # a hard file refused as it is
        if sc.model == "multibody":
            try:
                check_run(sc)
            except UserError as exc:
                assert "steps of the automatic" not in str(exc), (f, str(exc))


def test_the_far_above_refusal_quotes_the_scenes_own_automatic_step():
    """A given step far above the stable one is refused naming the automatic step to fall back on; in the
    kinematic-cage scene, whose automatic step is the Hertz step / KINEMATIC_DT_DIVISOR, it quoted the full
    scene's (4.03e-06 s where the scene takes 5.04e-07 s at 3000 rpm). The largest step it takes reads as
    accepted, not as safe: steps between the automatic one and it may blow up (1.5e-05 s at 6000 rpm does);
    the rigid raceways' refusal of a step far above the land's limit named no automatic step at all."""
    from bearingsim.multibody import core

    for scene in ("full", "kinematic_cage", "rigid"):
        sets = [f"multibody.scene={scene}"] if scene != "rigid" else [
            "multibody.raceway_contact=rigid", "bearing.cage_guidance=outer_land"]
        p = load_scenario(SCENARIOS / "multibody_3000rpm.toml", sets).parameters
        automatic, _, limit = core.choose_dt(p)
        with pytest.raises(UserError) as err:
            core.choose_dt(p, 1e-3)
        assert str(err.value).endswith(
            f"steps up to {2 * limit:.3g} s are accepted, but only the automatic {automatic:.3g} s is shown "
            f"stable (leave the step to the automatic choice)"), (scene, str(err.value))


@pytest.mark.parametrize("dt", [1.5e-5, 1e-5, 8e-6])
def test_a_given_step_that_blows_up_is_told_the_automatic_step(dt):
    """A given step between the automatic one and the refusal's bound that blows up (6000 rpm: 1.5e-5 and 1e-5 s
    overlap a face, 8e-6 s blows the raceway approach up within 1e-4 s) names the scene's automatic step, as the
    refusal before the run does. It named a bound computed from the approach speed of the state that had already
    diverged (39 m/s: "use numerics.dt_s <= 2.04e-08 s", 200 times below the automatic step) or "a smaller
    numerics.dt_s than 8e-06 s". Said of the argument for the API's dt, of the key for numerics.dt_s."""
    import bearingsim as api
    from bearingsim.errors import SimulationUnstable
    from bearingsim.multibody import core

    sc = load_scenario(SCENARIOS / "multibody_6000rpm.toml", ["numerics.rotations=1"])
    automatic = core.choose_dt(sc.parameters)[0]
    with pytest.raises(SimulationUnstable) as err:
        api.run(sc, dt=dt)
    msg = str(err.value)
    assert msg.endswith(f"the given step dt = {dt:.3g} s (run()'s dt argument) is {dt / automatic:.3g} times the "
                        f"automatic {automatic:.3g} s: give a smaller dt, or none"), msg
    with pytest.raises(SimulationUnstable) as err:
        api.run(sc.replace(**{"numerics.dt_s": dt}))
    msg = str(err.value)
    assert msg.endswith(f"the given step numerics.dt_s = {dt:.3g} s is {dt / automatic:.3g} times the automatic "
                        f"{automatic:.3g} s: remove numerics.dt_s or set a smaller one"), msg


def test_a_ring_on_one_roller_held_quasi_static_is_refused_before_it_runs():
    """docs/stability.md, The inner ring: a massless ring resting on one roller (600 N at 6000 rpm, 16 rollers:
    laws.loaded_rollers_with_one_at_centre gives 1) has no stable sideways equilibrium and jumps between
    supports. Its force balance converges, so no count of failed solves stops it; at 300 N and 500 rpm
    (1 rotation) such a ring gives I_dec 47.3 mN s against the dynamic ring's 52.4 (-10 %), in 12 times the
    time. Held quasi-static by the scenario, it is refused before any step, with one line naming the key and
    the dynamic ring, not a smaller step."""
    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml", [
        "multibody.inner_ring=quasi_static", "operating.radial_load_N=600", "operating.inner_ring_speed_rpm=6000",
        "numerics.rotations=1"])
    with pytest.raises(UserError) as err:
        run_scenario(sc)
    msg = str(err.value)
    assert msg.startswith('multibody.inner_ring = "quasi_static": the quasi-static inner ring rests on one roller '
                          'here (1 loaded'), msg
    assert 'set multibody.inner_ring = "dynamic"' in msg and "\n" not in msg, msg
    assert "a smaller numerics.dt_s does not help" in msg, msg
