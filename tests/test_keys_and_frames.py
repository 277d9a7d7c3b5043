"""Issue 28, items 9 and 10: results as DataFrames and Datasets (with units), the sweep index as a
DataFrame; the resolved scenario before a run (``show SCENARIO.toml``, ``run --dry-run``), every key
with unit, bounds, default and source (``bearingsim keys``), "did you mean" on an unknown key."""
from __future__ import annotations

import json
import re
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import bearingsim
from bearingsim.errors import UserError
from bearingsim.scenario import flatten, load_scenario

from .conftest import SCENARIOS
from .test_cli import assert_user_error, bearingsim as cli

PAPER = SCENARIOS / "paper_3000rpm.toml"


_flat = flatten  # dotted keys of a nested table


# --- did you mean -----------------------------------------------------------------------------------

@pytest.mark.parametrize("setting, hint", [
    ("operating.inner_ring_sped_rpm=3000", "did you mean operating.inner_ring_speed_rpm?"),
    ("numerics.rotation=3", "did you mean numerics.rotations?"),
    ("bearing.inner_ring_speed_rpm=3000", "did you mean operating.inner_ring_speed_rpm?"),  # wrong section
    ("operatin.radial_load_N=900", "did you mean operating?"),
])
def test_unknown_key_in_set_gets_the_closest_key(tmp_path, setting, hint):
    res = cli("run", PAPER, "--set", setting, "-o", tmp_path / "r.h5")
    assert_user_error(res, setting.split("=")[0].split(".")[0], "unknown key", hint)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("key, hint", [
    ("bearing.clearance", " (did you mean bearing.pocket_clearance_mm, bearing.radial_clearance_mm or "
                          "bearing.cage_land_clearance_mm?)"),
    ("contact.friction", " (did you mean contact.cage_friction or contact.land_friction?)"),
    ("operating.load", " (did you mean operating.radial_load_N?)"),
    ("operating.speed", " (did you mean operating.inner_ring_speed_rpm?)"),
    ("lubrication.drag", " (did you mean lubrication.drag_coefficient?)"),
    ("bearing.rollers", " (did you mean bearing.roller_count, bearing.roller_diameter_mm, bearing.roller_length_mm "
                        "or bearing.roller_mass_kg?)"),
    ("bearing.friction", " (did you mean contact.cage_friction or contact.land_friction?)"),  # wrong section
    # at the top level, the section left out: the keys of any section that hold the words (none was named, or
    # difflib's section "lubrication" for "friction")
    ("friction", " (did you mean contact.cage_friction or contact.land_friction?)"),
    ("clearance", " (did you mean bearing.pocket_clearance_mm, bearing.radial_clearance_mm or "
                  "bearing.cage_land_clearance_mm?)"),
    ("speed", " (did you mean operating.inner_ring_speed_rpm?)"),
    ("operatin", " (did you mean operating?)"),  # a misspelt section as before
    # misspellings as before
    ("numerics.rotation", " (did you mean numerics.rotations?)"),
    ("operating.inner_ring_sped_rpm", " (did you mean operating.inner_ring_speed_rpm?)"),
    ("bearing.no_such_key", ""),
])
def test_unknown_key_named_by_a_word_gets_every_key_that_holds_it(key, hint):
    """A key named by a word of the keys' names got difflib's one closest key, which was often the wrong one
    (`bearing.clearance` -> bearing.radial_clearance_mm, the pocket clearance being what a clearance study
    means; `contact.friction` -> contact.land_friction, not the roller-cage friction), or none (`operating.load`,
    `operating.speed`, `lubrication.drag`). Every key that holds the words is named."""
    from bearingsim.scenario import did_you_mean, known_keys

    assert did_you_mean(key) == hint
    named = hint.removeprefix(" (did you mean ").removesuffix("?)").replace(" or ", ", ").split(", ")
    assert not hint or set(named) <= set(known_keys())


def test_unknown_key_with_a_word_no_keys_name_holds_gets_the_keys_it_enters_through():
    """`--set bearing.cage_material=...` said "did you mean bearing.cage_inertia_kgm2?" (difflib's closest); a word
    `bearingsim keys` answers (material, viscosity) gets the keys it enters through, as `bearingsim keys WORD`."""
    from bearingsim.errors import UserError
    from bearingsim.wording import KEY_TOPICS

    with pytest.raises(UserError) as err:
        load_scenario(PAPER, ["bearing.cage_material=1"])
    message = str(err.value)
    assert message.endswith("bearing.cage_material: unknown key ('material' is in no key's name: "
                            f"{KEY_TOPICS['material'][1]}: bearing.cage_mass_kg, bearing.cage_inertia_kgm2, "
                            "contact.restitution, contact.cage_friction, contact.land_friction, "
                            "wear.wear_coefficient and wear.hardness_Pa)"), message
    assert "cage_inertia_kgm2?" not in message and "\n" not in message


def test_dry_run_with_no_plots_does_not_promise_figures(tmp_path):
    """`run --dry-run --no-plots` said the run would write the archive 'and its figures beside it'."""
    res = cli("run", PAPER, "--dry-run", "--no-plots", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "would write outputs/paper_3000rpm.h5 (no figures: --no-plots)" in res.stdout
    assert "and its figures" not in res.stdout
    res = cli("run", PAPER, "--dry-run", cwd=tmp_path)
    assert "would write outputs/paper_3000rpm.h5 (and its figures beside it)" in res.stdout
    assert list(tmp_path.iterdir()) == []


def test_unknown_key_in_a_file_gets_the_closest_key_and_nonsense_gets_none(tmp_path):
    from bearingsim.errors import UserError

    f = tmp_path / "s.toml"
    f.write_text(PAPER.read_text() + "\n[wear]\nwear_coefficent = 1e-4\n")
    with pytest.raises(UserError, match=r"wear\.wear_coefficent: unknown key \(did you mean wear\.wear_coefficient\?\)"):
        load_scenario(f)
    with pytest.raises(UserError) as exc:
        load_scenario(PAPER, ["bearing.no_such_key=1"])
    assert str(exc.value).endswith("bearing.no_such_key: unknown key")


@pytest.mark.parametrize("section", ["bearing", "operating"])
def test_a_misspelt_section_is_named_rather_than_the_keys_it_leaves_missing(tmp_path, section):
    """A misspelt table leaves its keys unset: the misspelling is the error to name (one error is told,
    the one that explains the others)."""
    from bearingsim.errors import UserError

    text = PAPER.read_text()
    assert f"\n[{section}]\n" in text
    f = tmp_path / "s.toml"
    f.write_text(text.replace(f"\n[{section}]\n", f"\n[{section[:3] + section[4:]}]\n"))
    with pytest.raises(UserError, match=rf"s\.toml: {section[:3] + section[4:]}: unknown key \(did you mean {section}\?\)"):
        load_scenario(f)


# --- keys ---------------------------------------------------------------------------------------------

def test_keys_lists_every_key_a_resolved_scenario_has_with_unit_bounds_default_source():
    from bearingsim.keys import list_keys

    keys = {k.key: k for k in list_keys()}
    resolved = _flat(tomllib.loads(load_scenario(SCENARIOS / "multibody_3000rpm.toml").to_toml()))
    resolved = {"ranges" if k.startswith("ranges.") else k for k in resolved}  # one entry: the ranges table
    assert set(resolved) <= set(keys), set(resolved) - set(keys)
    assert keys["bearing.pocket_clearance_mm"].plausible == "0.16..0.24"  # the preset's range, shown
    rc = keys["bearing.roller_count"]
    assert (rc.kind, rc.default) == ("int >= 3", "16") and rc.source.startswith("preset NU214-Suzuki2023: paper")
    d = keys["bearing.roller_diameter_mm"]
    assert d.unit == "mm" and d.kind == "float > 0" and "reconstructed" in d.source and "13 g" in d.why
    assert keys["contact.restitution"].kind == "float >= 0, <= 1"
    assert keys["multibody.raceway_contact"].kind == '"hertz" | "rigid"'
    assert keys["numerics.rotations"].default == "5" and keys["numerics.rotations"].source == "package default"
    assert keys["multibody.scene"].unused_by == ("reduced",)


def test_keys_why_gives_the_presets_reason_and_range_for_a_package_default():
    """A key whose value is a package default that the preset documents (``[source.wear.wear_coefficient]``,
    with a reason and a range) shows them: ``keys KEY --why``, to which a run's out-of-range note points,
    showed the table row alone."""
    from bearingsim.keys import format_keys, list_keys
    from bearingsim.scenario import load_preset

    src = load_preset("NU214-Suzuki2023")["source"]
    keys = {k.key: k for k in list_keys()}
    k = keys["wear.wear_coefficient"]
    assert k.source.startswith("package default") and k.plausible == "3e-07..0.0001"
    assert k.why == src["wear"]["wear_coefficient"]["reason"]
    assert keys["contact.cage_friction"].why == src["contact"]["cage_friction"]["range_reason"]  # no reason: the range's
    text = format_keys(list(keys.values()), "wear.wear_coefficient", why=True)
    assert "plausible 3e-07..0.0001" in text and "Rabinowicz, 'The Wear Coefficient" in text
    # the hardness, a package default too, has its reason: `keys wear.hardness_Pa --why` printed the row alone
    assert keys["wear.hardness_Pa"].why == src["wear"]["hardness_Pa"]["reason"] and "HV 150" in keys["wear.hardness_Pa"].why
    text = format_keys(list(keys.values()), "wear.hardness_Pa", why=True)
    assert len(text.splitlines()) == 3 and "high-strength brass" in text.splitlines()[2], text


@pytest.mark.parametrize("key", ["wear.wear_coefficient", "wear.hardness_Pa"])
def test_keys_gives_the_bounds_a_scenario_enforces_on_a_wear_key(key):
    """`bearingsim keys wear` said `float >= 0` for the wear coefficient and `float > 0` for the hardness,
    where a scenario refuses k above scenario.MAX_WEAR_COEFFICIENT and a hardness outside
    scenario.HARDNESS_RANGE_PA: the bounds keys gives are accepted, values beyond them refused."""
    import re

    from bearingsim.keys import list_keys

    kind = {k.key: k for k in list_keys()}[key].kind
    m = re.fullmatch(r"float >= ([0-9.e+-]+), <= ([0-9.e+-]+)", kind)
    assert m, kind
    lo, hi = float(m[1]), float(m[2])
    for value, ok in ((lo, True), (hi, True), (hi * 1.01, False), (lo * 0.99 if lo else -1e-9, False)):
        try:
            load_scenario(SCENARIOS / "wear_test_6000rpm.toml", values={key: value})
        except UserError:
            assert not ok, (key, value)
        else:
            assert ok, (key, value)


def test_keys_bounds_come_from_the_scenarios_limits(monkeypatch):
    """The keys table gives the limits of scenario._check_limits from its constants, those with other keys
    too (total rotations, dm*n, roller density, radial clearance, drag, static load rating), so a changed
    limit changes the table."""
    from bearingsim import scenario
    from bearingsim.keys import list_keys

    monkeypatch.setattr(scenario, "MAX_WEAR_COEFFICIENT", 0.05)
    monkeypatch.setattr(scenario, "HARDNESS_RANGE_PA", (2.0e7, 1.0e11))
    monkeypatch.setattr(scenario, "MAX_ROTATIONS", 777)
    monkeypatch.setattr(scenario, "MAX_DM_N_MM_RPM", 3.5e6)
    monkeypatch.setattr(scenario, "ROLLER_DENSITY_RANGE_KG_M3", (600.0, 19_000.0))
    monkeypatch.setattr(scenario, "MAX_RADIAL_CLEARANCE_TO_ROLLER", 0.04)
    monkeypatch.setattr(scenario, "MAX_DRAG_TO_LOAD", 0.5)
    monkeypatch.setattr(scenario, "ISO76_C0_FACTOR", 43.0)
    kinds = {k.key: k.kind for k in list_keys()}
    assert kinds["wear.wear_coefficient"] == "float >= 0, <= 0.05"
    assert kinds["wear.hardness_Pa"] == "float >= 2e+07, <= 1e+11"
    # the reduced model runs no warm-up: the total counts numerics.warmup_rotations for the multibody model only
    assert kinds["numerics.rotations"] == "int >= 1, <= 777, multibody: + numerics.warmup_rotations <= 777"
    assert kinds["numerics.warmup_rotations"].endswith(", multibody: + numerics.rotations <= 777")
    assert "(dm*n) <= 3.5e+06 mm rpm" in kinds["operating.inner_ring_speed_rpm"]
    assert "in [600, 19000] kg/m^3" in kinds["bearing.roller_mass_kg"]
    assert kinds["bearing.radial_clearance_mm"] == "float >= 0, <= 0.04 x bearing.roller_diameter_mm"
    assert "<= 0.5 x the least roller load" in kinds["lubrication.drag_coefficient"]
    assert "<= C0r = 43 " in kinds["operating.radial_load_N"]
    assert "bearing.cage_mass_kg" in kinds["bearing.cage_inertia_kgm2"]
    assert "2 x bearing.roller_count samples per cage rotation" in kinds["numerics.output_rate_hz"]


@pytest.mark.parametrize("scenario", ["multibody_3000rpm.toml", "paper_3000rpm.toml"])
def test_keys_gives_the_lower_bound_of_an_integer_key_that_a_run_enforces(scenario):
    """`bearingsim keys roller_count` said `int >= 1` where 1 and 2 rollers are refused ("at least 3
    rollers"), and `keys warmup_rotations` `int >= 0` where a multibody run refuses 0: the least value
    keys gives for an integer key runs, one less is refused."""
    import re

    from bearingsim.errors import UserError
    from bearingsim.keys import list_keys
    from bearingsim.scenario import check_run_request

    def runs(key, value):
        try:
            check_run_request(load_scenario(SCENARIOS / scenario, values={key: value}))
        except UserError:
            return False
        return True

    model = "multibody" if scenario.startswith("multibody") else "reduced"
    bounds = {}
    for k in list_keys():
        m = re.match(r"int >= (\d+)(?:, >= (\d+) to run the (\w+) model)?", k.kind)
        if m and model not in k.unused_by:
            bounds[k.key] = int(m[2]) if m[2] and m[3] == model else int(m[1])
    assert bounds["bearing.roller_count"] == 3 and bounds.get("numerics.warmup_rotations") == \
        (1 if model == "multibody" else None)  # the reduced model does not read it
    for key, least in bounds.items():
        assert runs(key, least) and not runs(key, least - 1), (key, least)


@pytest.mark.slow
def test_keys_command(tmp_path):
    res = cli("keys", "numerics.")
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert lines[0].split()[:2] == ["key", "unit"] and len(lines) == 5  # header + the 4 numerics keys
    assert any(ln.startswith("numerics.output_rate_hz") and " Hz " in ln and "20000.0" in ln for ln in lines)
    why = cli("keys", "pocket_clearance", "--why")
    assert why.returncode == 0 and "Table 4" in why.stdout  # the reasoning behind the preset's value
    assert_user_error(cli("keys", "no_such_thing"), "no_such_thing", "viscosity")
    assert_user_error(cli("keys", "--preset", "nope"), "--preset", "nope")


def test_keys_gives_the_unit_of_eq_2s_drag_coefficient():
    """Eq. (2), F_o = c N^0.246 V^0.648 with F_o and N in N and V in m/s (Suzuki et al. 2023, docs/physics.md):
    c's unit is N^(1 - 0.246) (s/m)^0.648, not the blank of a dimensionless key (checked by its exponents)."""
    from bearingsim.keys import KEY_UNITS, list_keys

    info = next(k for k in list_keys() if k.key == "lubrication.drag_coefficient")
    assert info.unit == KEY_UNITS[info.key] == f"N^{1 - 0.246:g} (s/m)^{0.648:g}"


@pytest.mark.parametrize("word, keys", [("viscosity", {"lubrication.drag_coefficient"}),
                                        ("grease", {"lubrication.drag_coefficient", "multibody.traction_mu_max",
                                                    "multibody.traction_slip_ref"}),
                                        ("Oil", {"lubrication.drag_coefficient", "multibody.traction_mu_max",
                                                 "multibody.traction_slip_ref"}),
                                        ("material", {"bearing.cage_mass_kg", "bearing.cage_inertia_kgm2",
                                                      "contact.restitution", "contact.cage_friction",
                                                      "contact.land_friction", "wear.wear_coefficient",
                                                      "wear.hardness_Pa"})])
def test_keys_answers_a_word_no_keys_name_holds_with_the_keys_it_enters_through(word, keys):
    """``bearingsim keys viscosity`` was refused ("no scenario key contains it"); an engineer's word for what a
    key carries gets the keys it enters through (each a real key), and a line saying how."""
    from bearingsim.keys import format_keys, list_keys

    all_keys = {k.key for k in list_keys()}
    assert keys <= all_keys
    text = format_keys(list_keys(), word)
    lines = text.splitlines()
    assert lines[0].startswith(f"{word!r} is in no key's name: ") and "docs/whatif.md" in lines[0]
    assert lines[1].split()[:2] == ["key", "unit"]
    assert {ln.split()[0] for ln in lines[2:]} == keys
    assert format_keys(list_keys(), "no_such_thing") == ""


@pytest.mark.parametrize("words, keys", [("roller count", ["bearing.roller_count"]),
                                         ("pocket clearance", ["bearing.pocket_clearance_mm"]),
                                         ("Cage Mass", ["bearing.cage_mass_kg"]),
                                         ("rollers", ["bearing.roller_count", "bearing.roller_diameter_mm",
                                                      "bearing.roller_length_mm", "bearing.roller_mass_kg"])])
def test_keys_finds_a_key_by_the_words_of_its_name(words, keys):
    """`bearingsim keys "roller count"` (or `rollers`, `"pocket clearance"`) was refused: "no scenario key contains
    it", the key being bearing.roller_count. A text no key contains gets the keys whose names hold its words
    (singular, any case); a text whose words no key holds is still refused (empty table)."""
    from bearingsim.keys import format_keys, list_keys

    lines = format_keys(list_keys(), words).splitlines()
    assert lines[0].split()[:2] == ["key", "unit"]
    assert [ln.split()[0] for ln in lines[1:]] == keys
    assert format_keys(list_keys(), "roller colour") == ""


# --- the resolved scenario before a run ------------------------------------------------------------------

@pytest.mark.slow
def test_show_of_a_scenario_file_is_the_resolved_scenario(tmp_path):
    res = cli("show", PAPER, "--set", "bearing.roller_count=14")
    assert res.returncode == 0, res.stderr
    shown = tomllib.loads(res.stdout)
    assert shown["bearing"]["roller_count"] == 14 and shown["bearing"]["cage_guidance"] == "rollers"
    assert "# differs from the preset: 14 rollers" in res.stdout
    again = tmp_path / "again.toml"
    again.write_text(res.stdout)
    assert load_scenario(again).to_toml() == load_scenario(PAPER, ["bearing.roller_count=14"]).to_toml()
    assert_user_error(cli("show", PAPER, "--set", "bearing.roler_count=14"), "did you mean bearing.roller_count?")


@pytest.mark.slow
def test_run_dry_run_runs_and_writes_nothing(tmp_path):
    res = cli("run", PAPER, "--dry-run", "--set", "operating.inner_ring_speed_rpm=500", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert tomllib.loads(res.stdout)["operating"]["inner_ring_speed_rpm"] == 500.0
    assert "would write outputs/paper_3000rpm.h5" in res.stdout and "nothing was run" in res.stdout
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
@pytest.mark.parametrize("name", ["multibody_dt_too_large", "reduced_euler_dt_too_large"])
def test_run_dry_run_refuses_the_time_step_the_run_refuses(tmp_path, name):
    """A given numerics.dt_s far above the stable step (multibody) or above the euler method's bound is
    refused by the run before its first step; the dry run, which says what the run would do, refuses it
    with the same line (it passed, exit 0)."""
    path = SCENARIOS / "hard" / f"{name}.toml"
    dry = cli("run", path, "--dry-run", cwd=tmp_path)
    real = cli("run", path, "--no-plots", "-o", tmp_path / "a.h5")
    assert_user_error(dry, "numerics.dt_s")
    assert dry.stderr == real.stderr
    assert list(tmp_path.iterdir()) == []


def test_run_dry_run_refuses_a_pocket_too_tight_for_the_assembled_bearing(tmp_path):
    """Rollers that overlap their pocket faces as assembled (pocket clearance 5 um against a radial play
    of 80 um: tests/test_multibody.py) are refused by the run before its first step and by the dry run with
    the same line, naming the file and the clearance (the dry run passed, exit 0, and the run refused it
    in its first step, exit 3)."""
    setting = "bearing.pocket_clearance_mm=0.005"
    path = SCENARIOS / "multibody_3000rpm.toml"
    dry = cli("run", path, "--set", setting, "--dry-run", cwd=tmp_path)
    real = cli("run", path, "--set", setting, "--no-plots", "-o", tmp_path / "a.h5")
    assert_user_error(dry, str(path), "bearing.pocket_clearance_mm = 0.005 is too small", "overlap a pocket face")
    assert dry.stderr == real.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
@pytest.mark.parametrize("case", ["a file in the folder's place", "a folder that takes no file",
                                  "an archive of another scenario"])
def test_run_dry_run_refuses_the_output_the_run_refuses(tmp_path, case):
    """What the run refuses of its output before its first step (the target, a folder that cannot be made
    or takes no file, an archive of another scenario at the target) the dry run refuses with the same line
    (it said 'would write' and exited 0); it writes nothing, and with --force it passes where the run would."""
    sets = ["--set", "numerics.rotations=1"]
    if case == "a file in the folder's place":
        (tmp_path / "f").write_text("a user's file")
        out = tmp_path / "f" / "sub" / "a.h5"
    elif case == "a folder that takes no file":
        if not (Path("/proc/self").is_dir() and sys.platform.startswith("linux")):
            pytest.skip("needs Linux's /proc, where no file can be created whoever asks")
        out = Path("/proc/a.h5")
    else:
        out = tmp_path / "a.h5"
        assert cli("run", PAPER, *sets, "--no-plots", "-q", "-o", out).returncode == 0
        sets += ["--set", "operating.inner_ring_speed_rpm=2000"]
    before = sorted(tmp_path.rglob("*"))
    dry = cli("run", PAPER, *sets, "--dry-run", "--no-plots", "-o", out, cwd=tmp_path)
    assert sorted(tmp_path.rglob("*")) == before
    real = cli("run", PAPER, *sets, "--no-plots", "-o", out, cwd=tmp_path)
    assert_user_error(dry, str(out.parent))  # the archive, or its folder that cannot be made
    assert dry.stderr == real.stderr
    if case == "an archive of another scenario":
        assert "--force" in dry.stderr
        forced = cli("run", PAPER, *sets, "--dry-run", "--no-plots", "--force", "-o", out, cwd=tmp_path)
        assert forced.returncode == 0 and f"would write {out}" in forced.stdout, forced.stderr


@pytest.mark.slow
def test_run_dry_run_gives_the_notes_the_run_gives(tmp_path):
    """The dry run says what the run would do, its notes included: here the time step, which the
    event-driven method does not use, and the cage guidance, which the reduced model does not use."""
    sets = ["--set", 'reduced.method="event"', "--set", "numerics.dt_s=1e-6", "--set", "bearing.cage_guidance=outer_land",
            "--set", "numerics.rotations=1"]
    dry = cli("run", PAPER, "--dry-run", *sets, cwd=tmp_path)
    real = cli("run", PAPER, *sets, "--no-plots", "-o", tmp_path / "a.h5")
    assert dry.returncode == 0 and real.returncode == 0, (dry.stderr, real.stderr)

    def notes(res):
        return [line for line in res.stderr.splitlines() if "note" in line]

    assert notes(dry) == notes(real)
    assert len(notes(dry)) == 1 and "numerics.dt_s" in notes(dry)[0] and "bearing.cage_guidance" in notes(dry)[0]


def test_an_archive_given_as_a_scenario_is_refused_with_the_commands_that_read_it(tmp_path):
    """Through the Python API as on the command line, and whatever the archive's size (a scenario file
    is refused above 1 MiB: an archive is told apart first)."""
    import h5py

    from bearingsim.errors import UserError

    path = tmp_path / "big.h5"
    with h5py.File(path, "w") as f:
        f["x"] = np.zeros(300_000)  # 2.4 MB
    with pytest.raises(UserError, match=r"big\.h5: is an HDF5 file, not a scenario file.*'bearingsim rerun .*big\.h5' runs"):
        load_scenario(path)


def test_a_study_table_given_as_a_scenario_gets_advice_that_works_for_it(tmp_path, capsys):
    """A sweep's index given where a scenario belongs was told to 'bearingsim rerun' it, which refuses a table
    ("not a bearingsim archive"): the line names 'bearingsim inspect', which says what any of bearingsim's
    files is, and says rerun is for a run's archive."""
    from bearingsim.cli import main

    assert main(["sweep", str(PAPER), "--param", "operating.inner_ring_speed_rpm=1000,2000", "-q", "--no-plots",
                 "-o", str(tmp_path)]) == 0
    index = tmp_path / "sweep.h5"
    assert main(["run", str(index)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"'bearingsim inspect {index}' says what it is" in err[0], err
    assert "runs a run's archive again" in err[0]
    assert main(["inspect", str(index)]) == 0 and "sweep index" in capsys.readouterr().out


# --- DataFrames and Datasets --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def multibody_result():
    """Rigid raceways (the fast scene), 1 warm-up + 2 rotations at 3000 rpm."""
    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml",
                       ["numerics.rotations=2", 'multibody.raceway_contact="rigid"'])
    return bearingsim.run(sc)


def test_per_rotation_and_impacts_frames_hold_the_arrays_with_units(multibody_result):
    r = multibody_result
    per = r.to_dataframe("per_rotation")
    dec = r.per_rotation["I_dec"]
    assert per.shape[0] == dec.size and per.index.names == ["rotation", "pocket"]
    assert per.loc[(1, 5), "I_dec"] == dec[1, 5] and per.attrs["units"]["I_dec"] == "N s"
    assert per["I_dec"].mean() == pytest.approx(r.summary["I_dec_mean_Ns"], rel=1e-12, abs=0)
    imp = r.to_dataframe("impacts")
    assert len(imp) == len(r.impacts["time_s"]) > 0 and imp.attrs["units"]["approach_speed_m_s"] == "m/s"
    assert set(imp["face"]) <= {"rear", "front"}
    named = r.to_dataframe("per_rotation", units_in_names=True)
    assert "I_dec [N s]" in named.columns


def test_a_number_per_rotation_stands_in_each_pocket_row_and_is_a_rotation_variable():
    """The per-rotation arrays of the cage, one number per rotation (where it rests; a land-guided cage's
    land impulses), beside the [rotation, pocket] ones: the DataFrame repeats a rotation's number in each of
    its pockets' rows, and the Dataset gives it the dimension rotation alone. Before, a land-guided result's
    frames failed ("Length of values (2) does not match length of index (32)")."""
    r = bearingsim.run(load_scenario(SCENARIOS / "multibody_3000rpm.toml", [
        "bearing.cage_guidance=outer_land", "multibody.raceway_contact=rigid", "numerics.rotations=2"]))
    per = r.to_dataframe("per_rotation")
    land = np.asarray(r.per_rotation["land_normal"])
    assert land.shape == (2,) and per.shape[0] == 2 * 16
    assert (per.loc[1, "land_normal"].to_numpy() == land[1]).all()
    assert per.loc[(0, 7), "I_dec"] == r.per_rotation["I_dec"][0, 7]
    assert (per.loc[0, "cage_rest_angle"].to_numpy() == r.per_rotation["cage_rest_angle"][0]).all()
    ds = r.to_xarray()
    assert ds["land_normal"].dims == ("rotation",) and ds["cage_rest_angle"].dims == ("rotation",)
    assert ds["I_dec"].dims == ("rotation", "pocket") and ds["cage_rest_angle"].attrs["units"] == "deg"


def test_every_summary_number_has_the_unit_the_archive_page_gives(multibody_result, tmp_path):
    """`bearingsim inspect` showed the summary number `pockets` without a unit (and `to_dataframe("summary")`
    had none for it), where docs/archive.md gives `1` as for `steps`: every number carries its unit,
    in the result and in the archive written from it."""
    from .conftest import archive_summary_table

    documented = archive_summary_table()[1]
    path = multibody_result.save(tmp_path / "m.h5")
    for r in (multibody_result, bearingsim.load(path)):
        numbers = [k for k, v in r.summary.items() if not isinstance(v, str)]
        assert {k: r.summary_units.get(k) for k in numbers} == {k: documented[k] for k in numbers}


def test_the_archive_page_says_where_the_summary_text_scene_is(multibody_result, tmp_path):
    """docs/archive.md lists `scene` (text) among the summary attributes, and it is one, in the archive's
    `/results/summary` and in the result's group of it; but `'scene' in r.summary` is False, fresh or read
    back: `Result.summary` is the numbers (its docstring, SUMMARY_NUMBERS, the frames). The page said
    nothing of it; it says where the text is, and what it says holds."""
    from .conftest import archive_summary_table

    table, units = archive_summary_table()
    assert [k for k, u in units.items() if u == "text"] == ["scene"]
    assert '`r.summary` holds the numbers' in table and 'r.groups["results/summary"].attrs["scene"]' in table
    for r in (multibody_result, bearingsim.load(multibody_result.save(tmp_path / "m.h5"))):
        assert "scene" not in r.summary and all(isinstance(v, float) for v in r.summary.values())
        assert r.groups["results/summary"].attrs["scene"] == r.scenario.multibody.scene == "full"


def test_observables_frame_and_dataset(multibody_result):
    r = multibody_result
    obs = r.to_dataframe("observables")
    speed = r.series["cage_angular_speed"]
    assert obs.index.name == "time_s" and np.array_equal(obs["cage_angular_speed"].to_numpy(), speed.value)
    assert obs.attrs["units"]["cage_centre_x"] == "m" and np.array_equal(obs["cage_centre_y"], r.series["cage_centre"].value[:, 1])
    ds = r.to_xarray()
    assert ds["I_dec"].dims == ("rotation", "pocket") and ds["I_dec"].attrs["units"] == "N s"
    assert ds["impact_theta_deg"].attrs["units"] == "deg" and ds["time"].attrs["units"] == "s"
    assert ds.attrs["I_dec_mean_Ns"] == r.summary["I_dec_mean_Ns"] and ds.attrs["units_I_dec_mean_Ns"] == "N s"
    assert load_scenario_text(ds.attrs["scenario_toml"]) == r.scenario.to_toml()
    assert r.to_dataframe("summary").loc[r.scenario.name, "cage_slip"] == r.summary["cage_slip"]


@pytest.mark.parametrize("scenario, sets", [
    ("paper_3000rpm.toml", []),
    ("multibody_3000rpm.toml", ["numerics.rotations=1"]),
])
def test_a_result_read_back_gives_the_same_frames_columns_in_order(tmp_path, scenario, sets):
    """docs/dataframes.md: a fresh result and one read from its archive give the same frames. The reader
    built its dicts in the order HDF5 lists a group (by name): every frame of a result read back had its
    columns in another order (the impacts `approach_speed_m_s, face, ...` for `time_s, theta_deg, ...`;
    the summary and time series in the run's order against by name), and saving a result read back wrote
    `/results/impacts@columns` in alphabetical order."""
    import h5py
    import pandas as pd

    r = bearingsim.run(load_scenario(SCENARIOS / scenario, sets))
    path = r.save(tmp_path / "r.h5")
    back = bearingsim.load(path)
    for what in ("per_rotation", "impacts", "observables", "summary"):
        pd.testing.assert_frame_equal(r.to_dataframe(what), back.to_dataframe(what), obj=what)
    assert list(back.data) == list(r.data)
    again = back.save(tmp_path / "again.h5")
    with h5py.File(path, "r") as f, h5py.File(again, "r") as g:
        written = f["results/impacts"].attrs["columns"].tolist()
        assert written[:2] == ["time_s", "theta_deg"] and g["results/impacts"].attrs["columns"].tolist() == written


def load_scenario_text(text):
    from bearingsim.sweeps.spec import scenario_from_toml

    return scenario_from_toml(text).to_toml()


def test_sweep_index_as_a_dataframe(tmp_path):
    from bearingsim.sweeps import index_dataframe
    from bearingsim.sweeps.index import write_index

    rows = [{"case": f"c{i}", "values": {"operating.inner_ring_speed_rpm": s}, "status": "done", "error": "",
             "archive": f"cases/c{i}.h5", "wall_s": 0.1, "summary": {"I_dec_mean_Ns": 0.005 * (i + 1), "I_dec_sem_Ns": 0.0}}
            for i, s in enumerate((1000.0, 3000.0))]
    write_index(tmp_path, rows, ["operating.inner_ring_speed_rpm"],
                {"mode": "product", "grid": json.dumps(["operating.inner_ring_speed_rpm"]), "grid_rows": 2, "scenario": "x"})
    df = index_dataframe(tmp_path)
    assert list(df.index) == ["c0", "c1"] and df.loc["c1", "I_dec_mean_Ns"] == 0.01
    assert df.loc["c0", "operating.inner_ring_speed_rpm"] == 1000.0 and df.loc["c0", "status"] == "done"
    assert df.attrs["units"]["operating.inner_ring_speed_rpm"] == "rpm" and df.attrs["axes"] == ["operating.inner_ring_speed_rpm"]


def test_without_pandas_a_one_line_hint_names_the_extra(monkeypatch, multibody_result):
    from bearingsim.frames import MissingExtra

    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas now raises ImportError
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(MissingExtra, match=r"needs pandas.*bearingsim\[frames\]"):
        multibody_result.to_dataframe()
    with pytest.raises(MissingExtra, match=r"needs xarray.*bearingsim\[frames\]"):
        multibody_result.to_xarray()


def test_an_installed_extra_that_fails_to_import_is_not_called_missing(monkeypatch):
    """A module of the user's named like one xarray imports (a ``glob.py`` beside the script) made
    ``to_xarray`` say "xarray, which is not installed" and dropped the real error; only a missing module
    is a missing extra, any other failure of its import is raised as it is."""
    import importlib

    from bearingsim import frames

    def broken(name, *a, **k):
        if name == "xarray":
            raise ModuleNotFoundError("No module named 'glob.escape'; 'glob' is not a package", name="glob.escape")
        return importlib.import_module(name, *a, **k)

    monkeypatch.setattr(importlib, "import_module", broken)
    with pytest.raises(ModuleNotFoundError, match="glob") as caught:
        frames.need("xarray", "Result.to_xarray")
    assert not isinstance(caught.value, frames.MissingExtra)


@pytest.mark.parametrize("what", ["everything", 3, None])
def test_a_frame_that_is_not_there_is_a_user_error(multibody_result, what):
    """A bad argument from the caller is a bearingsim.UserError (docs/usage.md), naming what to give: an unknown
    frame raised a plain ValueError."""
    from bearingsim.errors import UserError

    with pytest.raises(UserError, match=r"give one of per_rotation, impacts, observables, summary"):
        multibody_result.to_dataframe(what)


def test_keys_why_says_what_resting_contact_counts():
    """`bearingsim keys resting --why` printed the row alone and docs/usage.md named the key without saying what it
    does, though it moves I_dec from 5.44 to 1.10 mN s at e = 0 (scenarios/paper_3000rpm.toml): it counts Eq. (9)'s
    resting-contact impulse; false counts impacts only, as the paper's previous model (docs/physics.md)."""
    from bearingsim.keys import format_keys, list_keys

    res = cli("keys", "resting", "--why")
    lines = res.stdout.splitlines()
    assert res.returncode == 0 and len(lines) == 3 and lines[1].startswith("reduced.resting_contact"), res.stdout
    assert "Eq. (9)" in lines[2] and "previous model" in lines[2], lines
    assert "Eq. (9)" in {k.key: k for k in list_keys()}["reduced.resting_contact"].source
    assert format_keys(list_keys(), "reduced.resting_contact", why=True).splitlines()[2] == lines[2]
    usage = (SCENARIOS.parent / "docs" / "usage.md").read_text()
    assert "`reduced.resting_contact` (`true`, default) counts" in usage, "usage.md: the key without what it does"


def test_keys_shows_1_for_a_dimensionless_number_and_says_what_the_wear_coefficient_is(capsys):
    """`bearingsim keys` left the unit blank for dimensionless keys (wear.wear_coefficient, contact.restitution,
    numerics.rotations ...), which archives write as 1, and said nowhere that the wear coefficient is Archard's
    dimensionless k = k' H: a data sheet's specific wear rate k' = 1e-15 m^3/(N m) given as k reads the wear
    about 1e9 times low, without a word. The table gives 1 for such a number (none for a text or a switch), the
    row and its --why line say what k is, and a run's note of k = 1e-15, below its plausible range, says why."""
    from bearingsim.cli import main

    for key in ("wear.wear_coefficient", "contact.restitution", "contact.cage_friction",
                "multibody.traction_mu_max", "numerics.rotations"):
        assert main(["keys", key]) == 0
        row = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith(key + " "))
        assert row.split()[1] == "1", row
    assert main(["keys", "multibody.raceway_contact"]) == 0
    row = capsys.readouterr().out.splitlines()[1]
    assert row.split()[1] == '"hertz"', row  # a text key: no unit
    assert main(["keys", "wear.wear_coefficient", "--why"]) == 0
    out = capsys.readouterr().out
    assert "Archard's dimensionless k = k' H" in out.splitlines()[1]
    assert "k is Archard's dimensionless wear coefficient" in out and "1e9 times low" in out
    plausible = re.search(r"plausible ([0-9.e+-]+)\.\.([0-9.e+-]+)", out)
    assert not float(plausible.group(1)) <= 1e-15 <= float(plausible.group(2))
    assert main(["run", str(SCENARIOS / "wear_test_6000rpm.toml"), "--dry-run",
                 "--set", "wear.wear_coefficient=1e-15"]) == 0
    err = capsys.readouterr().err
    assert re.search(r"wear\.wear_coefficient = 1e-15 \(plausible [^)]*k is Archard's dimensionless coefficient, "
                     r"k = k' H: a specific wear rate k' in m\^3/\(N m\) given as k reads the wear about 1e9 "
                     r"times low\)", err), err
