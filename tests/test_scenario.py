"""Scenario schema v1: resolution order, preset, overrides, and one-line errors naming the key."""
import math

import pytest

import bearingsim
from bearingsim.errors import UserError
from bearingsim.scenario import given_keys, load_preset, load_scenario, parse_override, resolve

from .conftest import SCENARIOS, si


def test_preset_fills_unset_values_and_marks_reconstructions(base_reduced):
    sc = resolve(base_reduced)
    g = si(sc).bearing
    assert g.roller_count == 16
    assert g.roller_radius == pytest.approx(6.5e-3)
    assert g.pitch_radius == pytest.approx(48.75e-3)
    assert g.pocket_clearance == pytest.approx(0.20e-3, rel=1e-6, abs=0)
    preset = load_preset("NU214-Suzuki2023")
    # Every bearing value carries its source; the values the paper lost are marked reconstructed.
    for key in preset["bearing"]:
        assert key in preset["source"]["bearing"], key
    for key in ("roller_diameter_mm", "pitch_diameter_mm", "pocket_clearance_mm", "cage_mass_kg",
                "cage_inertia_kgm2", "radial_clearance_mm"):
        src = preset["source"]["bearing"][key]
        assert src["kind"] == "reconstructed" and len(src["reason"]) > 40, key


def test_scenario_value_beats_preset_and_override_beats_scenario(base_reduced):
    base_reduced["bearing"]["pocket_clearance_mm"] = 0.3
    assert si(resolve(base_reduced)).bearing.pocket_clearance == pytest.approx(0.3e-3, rel=1e-6, abs=0)
    sc = load_scenario(SCENARIOS / "paper_3000rpm.toml",
                       ["bearing.pocket_clearance_mm=0.25", "operating.direction=reverse", "model=reduced"])
    assert si(sc).bearing.pocket_clearance == pytest.approx(0.25e-3, rel=1e-6, abs=0)
    assert sc.operating.direction == "reverse"


def test_kinematics_follow_eqs_10_to_12(base_reduced):
    """Eqs. (10)-(12) of the paper: omega_c = (1-g) w_i/2, omega_r = (1/g - g) w_i/2, g = r_r/r_p."""
    op = si(resolve(base_reduced)).operating
    w_i = 2 * math.pi * 3000 / 60
    gam = 6.5 / 48.75
    assert op.omega_c == pytest.approx((1 - gam) * w_i / 2, rel=1e-12)
    assert op.omega_r == pytest.approx((1 / gam - gam) * w_i / 2, rel=1e-12)
    # Eq. (4): r_r w_r and r_o w_c are both the outer-race surface speed in pure rolling.
    assert op.rolling_velocity == pytest.approx(6.5e-3 * op.omega_r, rel=1e-12)


def test_override_values_are_toml_with_bare_words_as_strings():
    assert parse_override("operating.inner_ring_speed_rpm=3000") == ("operating.inner_ring_speed_rpm", 3000)
    assert parse_override("model=reduced") == ("model", "reduced")
    assert parse_override("operating.gravity=false") == ("operating.gravity", False)
    assert parse_override('name="a b"') == ("name", "a b")


@pytest.mark.parametrize(
    "override, key",
    [
        ("bearing.pocket_clearance_mm=-0.1", "bearing.pocket_clearance_mm"),
        ("bearing.roller_mass_kg=-1", "bearing.roller_mass_kg"),
        ("bearing.unknown_key=1", "bearing.unknown_key"),
        ("typo_section.x=1", "typo_section"),
        ("operating.inner_ring_speed_rpm=nan", "operating.inner_ring_speed_rpm"),
        ("operating.inner_ring_speed_rpm=fast", "operating.inner_ring_speed_rpm"),
        ("operating.gravity=1", "operating.gravity"),
        ("contact.restitution=1.2", "contact.restitution"),
        ("contact.restitution=-0.1", "contact.restitution"),
        ("bearing.roller_count=0", "bearing.roller_count"),
        ("bearing.roller_count=40", "bearing.roller_count"),
        ("bearing.roller_diameter_mm=120", "bearing.roller_diameter_mm"),
        ("bearing.preset=NoSuchBearing", "bearing.preset"),
        ("model=fem", "model"),
        ("reduced.method=rk4", "reduced.method"),
        ("numerics.dt_s=0", "numerics.dt_s"),
        ("schema_version=2", "schema_version"),
        ("multibody.pocket_face_half_angle_deg=0", "multibody.pocket_face_half_angle_deg"),
        ("multibody.pocket_face_half_angle_deg=90", "multibody.pocket_face_half_angle_deg"),
    ],
)
def test_bad_values_name_the_key(override, key):
    with pytest.raises(UserError) as err:
        load_scenario(SCENARIOS / "paper_3000rpm.toml", [override])
    msg = str(err.value)
    assert "\n" not in msg
    assert f": {key}:" in msg, msg


def _refusal_of(override: str) -> str:
    """The one-line refusal of the whole-bearing scenario with the ``--set`` ``override``."""
    with pytest.raises(UserError) as err:
        load_scenario(SCENARIOS / "multibody_3000rpm.toml", [override])
    return str(err.value)


@pytest.mark.parametrize("override", ["bearing=5", 'operating="fast"', "multibody=[1, 2]"])
def test_a_section_given_as_a_value_is_refused_in_the_scenarios_words(override):
    """`run --set bearing=5` said "bearing: must be a valid dictionary or instance of BearingSection": the
    name of a class inside the package. It says the section must be a table, and how to give its keys."""
    section = override.split("=")[0]
    msg = _refusal_of(override)
    assert f": {section}: must be a table of keys ([{section}] in a file, {section}.KEY=VALUE with --set)" in msg, msg
    assert "Section" not in msg and "instance" not in msg, msg


@pytest.mark.parametrize("override, alternative", [
    ("reduced.load_zone_half_angle_deg=autox", "'auto'"),
    ("multibody.pocket_face_half_angle_deg=wide", "'auto'"),
    ("multibody.inner_ring_mass_kg=heavy", "'auto'"),
    ("output.motion_start_rotation=first", "'last'"),
])
def test_a_key_that_takes_a_number_or_a_word_is_named_as_the_key(override, alternative):
    """A key typed ``float | "auto"`` refused a bad word as "reduced.load_zone_half_angle_deg.float: must be
    a valid number": a key that does not exist (pydantic's tag for the branch of the union it tried), and
    half of what the key takes. It names the key and both kinds of value."""
    key = override.split("=")[0]
    msg = _refusal_of(override)
    assert f": {key}: must be a number or {alternative} (got " in msg, msg
    assert ".float" not in msg and "\n" not in msg, msg


def test_overlapping_pockets_name_both_keys():
    # 16 pockets of 80 + 0.2 mm on a 97.5 mm pitch circle overlap (chord 2 r_p sin(pi/16) = 19.0 mm)
    with pytest.raises(UserError) as err:
        load_scenario(SCENARIOS / "paper_3000rpm.toml", ["bearing.roller_diameter_mm=80"])
    msg = str(err.value)
    assert ": bearing.roller_count:" in msg and "bearing.roller_diameter_mm" in msg and "not even 3 rollers leave such bars" in msg, msg


def test_missing_geometry_without_preset_names_the_key(base_reduced):
    del base_reduced["bearing"]["preset"]
    with pytest.raises(UserError, match=r"bearing\.roller_count: missing"):
        resolve(base_reduced)


def test_multibody_needs_three_rollers(base_reduced):
    base_reduced["model"] = "multibody"
    base_reduced["bearing"]["roller_count"] = 2
    with pytest.raises(UserError, match="bearing.roller_count"):
        resolve(base_reduced)


def test_missing_and_invalid_files(tmp_path):
    with pytest.raises(UserError, match="not found"):
        load_scenario(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("schema_version = 1\nmodel = [\n")
    with pytest.raises(UserError, match="not valid TOML"):
        load_scenario(bad)
    with pytest.raises(UserError, match=r"path: expected the path of a scenario file.*\(got int\)"):
        load_scenario(5)  # the API's wrong type: a one-line UserError too (docs/usage.md)


def test_every_shipped_scenario_validates():
    files = sorted(f for f in SCENARIOS.rglob("*.toml") if "sweeps" not in f.relative_to(SCENARIOS).parts)
    assert len(files) >= 14
    for f in files:
        load_scenario(f)


@pytest.mark.parametrize(
    "override, words",
    [
        ("multibody.flat_pockets=[16]", ["multibody.flat_pockets", "16"]),
        ("multibody.flat_pockets=[0, 0]", ["multibody.flat_pockets", "twice"]),
        ("multibody.flat_pockets=[-1]", ["multibody.flat_pockets"]),
        ("multibody.pocket_shape=flat", ["multibody.pocket_shape", "radially"]),
        ("multibody.pocket_shape=square", ["multibody.pocket_shape"]),
    ],
)
def test_pocket_shape_keys_are_validated(override, words):
    with pytest.raises(UserError) as e:
        load_scenario(SCENARIOS / "multibody_3000rpm.toml", [override])
    for w in words:
        assert w in str(e.value)


@pytest.mark.parametrize("start, length, advice", [
    (0, 50, "; shorten output.motion_rotations to 3 or less, set numerics.rotations to 50 or more, or set "
            "output.motion_start_rotation = 'last'"),
    (2, 2, "; start it at 1 or earlier, shorten output.motion_rotations to 1 or less, set numerics.rotations to 4 or "
           "more, or set output.motion_start_rotation = 'last'"),
    (5, 1, "; start it at 2 or earlier, set numerics.rotations to 6 or more, or set output.motion_start_rotation = "
           "'last'"),
    (5, 4, "; set numerics.rotations to 9 or more, or set output.motion_start_rotation = 'last'"),
])
def test_a_motion_window_after_the_run_is_refused_with_advice_that_can_be_followed(start, length, advice):
    """A window from rotation 0 longer than the run was told to "start it earlier", which it cannot: the advice
    names only what moves the window into the recorded rotations, and always the longer run that holds it (a
    window longer than the run starting after it was told nothing but 'last', after an empty list)."""
    with pytest.raises(UserError) as err:
        load_scenario(SCENARIOS / "multibody_3000rpm.toml", values={
            "numerics.rotations": 3, "output.motion_start_rotation": start, "output.motion_rotations": length})
    assert advice in str(err.value) and "earlier or set 'last'" not in str(err.value), str(err.value)


@pytest.mark.slow
def test_the_reduced_model_is_not_refused_over_a_motion_window_it_does_not_store():
    """The reduced model stores no motion and reads no [output] key: a window after its recorded rotations
    (start 0, the default 2 rotations, 1 recorded) was refused; it is the usual unread-key note instead,
    from the API and the command line's dry run alike. The multibody model still refuses it."""
    from tests.test_cli import bearingsim as cli

    path = SCENARIOS / "paper_3000rpm.toml"
    with pytest.warns(bearingsim.UnreadKeyWarning, match="output.motion_start_rotation: not used by the reduced"):
        sc = bearingsim.load_scenario(path, set={"output.motion_start_rotation": 0})
    assert sc.numerics.rotations < sc.output.motion_rotations
    res = cli("run", path, "--dry-run", "--set", "output.motion_start_rotation=0")
    assert res.returncode == 0, res.stderr
    assert "output.motion_start_rotation: not used by the reduced model" in res.stderr
    with pytest.raises(UserError, match="output.motion_start_rotation: the window 0 .. 2 ends after"):
        load_scenario(path, ["output.motion_start_rotation=0", "model=multibody"])


def test_the_total_rotations_count_a_warm_up_only_where_the_model_runs_one():
    """`keys` says numerics.warmup_rotations is not used by the reduced model, which runs no warm-up: its
    total-rotation limit (scenario.MAX_ROTATIONS) refused a reduced run over a huge warm-up. The reduced model
    gets the unread-key note and is limited by its recorded rotations alone; the multibody model counts both."""
    from bearingsim.scenario import MAX_ROTATIONS

    paper, multibody = SCENARIOS / "paper_3000rpm.toml", SCENARIOS / "multibody_3000rpm.toml"
    with pytest.warns(bearingsim.UnreadKeyWarning, match="numerics.warmup_rotations: not used by the reduced"):
        sc = bearingsim.load_scenario(paper, set={"numerics.warmup_rotations": MAX_ROTATIONS})
    assert sc.numerics.rotations + sc.numerics.warmup_rotations > MAX_ROTATIONS
    with pytest.raises(UserError) as err:  # the recorded rotations alone: no warm-up override named
        load_scenario(paper, ["numerics.rotations=100001", "numerics.warmup_rotations=3"])
    assert "with numerics.rotations=100001: numerics.rotations: 100001 rotations in all exceed" in str(err.value)
    with pytest.raises(UserError, match="numerics.warmup_rotations: 100004 rotations in all exceed"):
        load_scenario(multibody, ["numerics.warmup_rotations=100000"])


def test_the_api_warns_of_a_motion_window_longer_than_the_run_as_the_cli_notes_it():
    """`bearingsim run` notes a given output.motion_rotations longer than the recorded rotations with the start
    "last" (the run stores the recorded ones); bearingsim.load_scenario said nothing: it warns as it warns of
    an unread key, with the same line, and not for a window that fits."""
    from bearingsim.scenario import motion_window_note

    path = SCENARIOS / "multibody_3000rpm.toml"
    values = {"numerics.rotations": 3, "output.motion_rotations": 50}
    with pytest.warns(bearingsim.UnreadKeyWarning) as caught:
        sc = bearingsim.load_scenario(path, set=values)
    assert [str(w.message) for w in caught] == [
        f"bearingsim: note: {motion_window_note(sc, given_keys(path, values=values))}"]
    assert "output.motion_rotations = 50 is longer than the run's 3 recorded rotations" in str(caught[0].message)
    bearingsim.load_scenario(path, set={"numerics.rotations": 3, "output.motion_rotations": 3})  # no warning


def test_flat_pockets_reach_the_parameters():
    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["multibody.flat_pockets=[3, 0]"])
    assert si(sc).multibody.flat_pockets == (0, 3)


def test_toml_text_is_tomli_w_text_with_tables_cached():
    """Scenario.to_toml formats each top-level table once per content (a sweep's thousands of cases):
    the text is tomli_w's, cache hits included, and 1, 1.0 and True stay apart."""
    import tomli_w

    from bearingsim.scenario import _dumps

    from .conftest import SCENARIOS

    docs = [load_scenario(p).raw for p in sorted(SCENARIOS.glob("*.toml"))]
    docs += [
        {"a": 1, "t": {"x": 1}}, {"a": 1, "t": {"x": 1.0}}, {"a": 1, "t": {"x": True}},
        {"t": {"x": 'q"uote\\back\nnl', "é": "ü", "list": [1, 2.5, "s"], "sub": {"y": []}}, "u": {}},
        {"only": {"tables": {"deep": {"er": 1}}}},
        {"aot": [{"a": 1}, {"b": 2}], "t": {"x": 1}},
        {"t": {"aot": [{"a": 1}]}},
    ]
    for raw in docs + docs:  # the second pass hits the cache
        assert _dumps(raw) == tomli_w.dumps(raw), raw


def test_scenario_pickles_and_round_trips_equal(base_reduced):
    """A scenario goes to worker processes (``ProcessPoolExecutor().map(bearingsim.run, scenarios)``,
    joblib, dask): pickled and read back it is the same scenario, from the same source."""
    import copy
    import pickle

    sc = load_scenario(SCENARIOS / "paper_3000rpm.toml", ["numerics.rotations=1"])
    back = pickle.loads(pickle.dumps(sc))
    assert back == sc and hash(back) == hash(sc)
    assert back.source == sc.source and back.raw == sc.raw and back.to_toml() == sc.to_toml()
    assert back.operating.inner_ring_speed_rpm == 3000.0
    assert copy.deepcopy(sc) == sc and copy.copy(sc) == sc
    assert sc != sc.replace(**{"operating.inner_ring_speed_rpm": 1000.0})
    assert sc != resolve(base_reduced) and sc != "paper_3000rpm"
    with pytest.raises(AttributeError):
        sc.no_such_key


@pytest.mark.parametrize("name", ["a\x9b31mb", "invoice\u202egnp.exe", "x\u2066y", "a\u200fb", "a\u2028b", "a\x85b"])
def test_a_name_with_c1_controls_or_bidi_overrides_is_refused(base_reduced, name):
    """Issue 30, Low: a scenario name could hold C1 control characters (``\\x9b`` is a terminal's CSI)
    and bidirectional overrides (U+202E shows "invoice<RLO>gnp.exe" as "invoiceexe.png"), printed raw
    by every command and used as the archive's file name. Refused like C0 controls, naming ``name``;
    other non-ASCII names stay valid."""
    from bearingsim.errors import UserError
    from bearingsim.scenario import resolve

    with pytest.raises(UserError, match=r"name: must be a plain file name") as info:
        resolve({**base_reduced, "name": name})
    assert str(info.value).isprintable()
    for fine in ("café", "軸受", "Ωmega-2"):
        assert resolve({**base_reduced, "name": fine}).name == fine


def test_a_scenario_is_frozen(base_reduced):
    """Issue 30, Low: ``sc.name = "../../x"`` was accepted, bypassing the name check (the name is the
    default archive path), and ``sc.operating = None`` too. Assignment is refused with a message naming
    the attribute and ``replace()``; pickling and copies still work."""
    import copy
    import pickle

    sc = resolve(base_reduced)
    for item, value in (("name", "../../x"), ("operating", None), ("model_", None)):
        with pytest.raises(AttributeError, match=rf"frozen: {item} cannot be assigned; use scenario.replace"):
            setattr(sc, item, value)
    assert sc.name == "t" and sc.raw["name"] == "t"
    assert pickle.loads(pickle.dumps(sc)) == sc and copy.deepcopy(sc) == sc
    with pytest.raises(UserError, match="name"):
        sc.replace(name="../../x")


def test_a_scenario_section_is_frozen_in_one_line(base_reduced):
    """``sc.operating.radial_load_N = 1.0`` (or ``del``) was refused with pydantic's multi-line ValidationError
    ("1 validation error for OperatingSection ... Instance is frozen [type=frozen_instance ..."). It is the
    AttributeError of the scenario's own attributes, naming the dotted key and ``replace()``."""
    sc = resolve(base_reduced)
    for section, item in (("operating", "radial_load_N"), ("numerics", "rotations"), ("bearing", "new_key")):
        message = (f"Scenario is frozen: {section}.{item} cannot be assigned; use scenario.replace(**{{"
                   f"'{section}.{item}': value}}) (validated) for a changed copy")
        for change in (lambda: setattr(getattr(sc, section), item, 1.0), lambda: delattr(getattr(sc, section), item)):
            with pytest.raises(AttributeError) as info:
                change()
            assert str(info.value) == message
    with pytest.raises(AttributeError, match=r"^Scenario is frozen: name cannot be assigned; use scenario.replace"):
        sc.model_.name = "x"
    assert sc == resolve(base_reduced) and sc.replace(**{"operating.radial_load_N": 500.0}).operating.radial_load_N == 500


@pytest.mark.parametrize("sets, words", [
    (["contact.restitution=1.5"], "paper_3000rpm.toml with contact.restitution=1.5: contact.restitution: must be "
                                  "less than or equal to 1 (got 1.5)"),
    (["numerics.rotation=1"], "paper_3000rpm.toml with numerics.rotation=1: numerics.rotation: unknown key (did you "
                              "mean numerics.rotations?)"),
    (["bearing.pocket_clearance_mm=20"], "paper_3000rpm.toml with bearing.pocket_clearance_mm=20: "
                                         "bearing.pocket_clearance_mm: 20.0 mm is not smaller than the roller"),
])
def test_a_bad_override_is_named_as_the_override_not_as_the_file(sets, words):
    """A value a --set gave was refused as the scenario file's ("scenarios/paper_3000rpm.toml: contact.restitution:
    must be ...", a value the file does not hold): the line says the override that gave it."""
    from bearingsim.errors import UserError

    with pytest.raises(UserError) as got:
        load_scenario(SCENARIOS / "paper_3000rpm.toml", sets)
    assert words in str(got.value)
    with pytest.raises(UserError, match=r"paper_3000rpm\.toml with contact\.restitution=1\.5: contact\.restitution"):
        load_scenario(SCENARIOS / "paper_3000rpm.toml", values={"contact.restitution": 1.5})


@pytest.mark.parametrize("scenario, sets, head", [
    # a check across keys leads with another key than the one set (the pockets no longer fit: roller_count)
    ("multibody_3000rpm", {"bearing.pocket_clearance_mm": 5},
     "with bearing.pocket_clearance_mm=5: bearing.roller_count:"),
    ("multibody_3000rpm", {"bearing.pitch_diameter_mm": 60},
     "with bearing.pitch_diameter_mm=60: bearing.roller_count:"),
    ("multibody_6000rpm", {"bearing.cage_outer_diameter_mm": 80.0},
     "with bearing.cage_outer_diameter_mm=80.0: bearing.cage_inner_diameter_mm: the cage bore 91 mm"),
    ("multibody_3000rpm",
     {"bearing.pitch_diameter_mm": 60, "bearing.pocket_clearance_mm": 5, "contact.restitution": 0.5},
     "with bearing.pitch_diameter_mm=60 and bearing.pocket_clearance_mm=5: bearing.roller_count:"),
    # an unknown section or key: the override that named it
    ("paper_3000rpm", {"operatin.inner_ring_speed_rpm": 500},
     "with operatin.inner_ring_speed_rpm=500: operatin: unknown"),
    ("paper_3000rpm", {"bearing.roller_diametre_mm": 13.0},
     "with bearing.roller_diametre_mm=13.0: bearing.roller_diametre"),
    ("paper_3000rpm", {"operating": {"speed": 1}}, "with operating={'speed': 1}: operating.speed: unknown key"),
])
def test_a_refusal_names_every_override_it_is_about(scenario, sets, head):
    """A refusal of a check across keys, or of an unknown section, dropped the override that caused it
    ("multibody_3000rpm.toml: bearing.roller_count: 16 pockets ... at most 15 rollers" for --set
    bearing.pocket_clearance_mm=5; "paper_3000rpm.toml: operatin: unknown key" for operatin.inner_ring_speed_rpm):
    the line names every override of a key it names or its check reads, as --set and as set= alike."""
    path = SCENARIOS / f"{scenario}.toml"
    with pytest.raises(UserError) as got:
        load_scenario(path, values=sets)
    assert str(got.value).startswith(f"{path} {head}"), str(got.value)
    assert "\n" not in str(got.value)
    if not any(isinstance(v, dict) for v in sets.values()):
        with pytest.raises(UserError) as cli:
            load_scenario(path, [f"{k}={v}" for k, v in sets.items()])
        assert str(cli.value) == str(got.value)
    with pytest.raises(UserError) as plain:
        load_scenario(SCENARIOS / "paper_3000rpm.toml", ["foo.bar=1"])
    assert str(plain.value).endswith("paper_3000rpm.toml with foo.bar=1: foo: unknown key")


def test_a_key_the_settings_leave_unread_is_noted_as_unused_not_as_out_of_range():
    """A land key with a roller-guided cage (the preset's) changes nothing: `run` notes it as unused, and the
    plausible-range note leaves it out (it said the run "is of another bearing" and nothing of its being
    unused). With a land-guided cage the same values are read: no unused note, and the range note names the
    clearance outside its range. The reduced model's radial clearance with a given load zone is unread too."""
    from bearingsim.scenario import out_of_range_note, unread_note

    keys = ["bearing.cage_land_clearance_mm", "contact.land_friction"]
    sets = ["bearing.cage_land_clearance_mm=0.001", "contact.land_friction=0.2"]
    rollers = load_scenario(SCENARIOS / "multibody_3000rpm.toml", sets)
    assert unread_note(rollers, keys) == ("bearing.cage_land_clearance_mm, contact.land_friction: not used with "
                                          "bearing.cage_guidance = 'rollers' (no land to run on); no effect on the run")
    assert out_of_range_note(rollers) is None
    land = load_scenario(SCENARIOS / "multibody_3000rpm.toml", [*sets, "bearing.cage_guidance=outer_land"])
    assert unread_note(land, keys) is None
    assert "bearing.cage_land_clearance_mm = 0.001 (plausible 0.2 to 0.5)" in out_of_range_note(land)
    given = load_scenario(SCENARIOS / "paper_3000rpm.toml", ["reduced.load_zone_half_angle_deg=20"])
    note = unread_note(given, ["bearing.radial_clearance_mm", "bearing.cage_mass_kg", "numerics.dt_s"])
    assert note.startswith("bearing.cage_mass_kg: not used by the reduced model")
    assert "numerics.dt_s: not used by reduced.method = 'event'" in note
    assert "bearing.radial_clearance_mm: not used by the reduced model when reduced.load_zone_half_angle_deg" in note
    auto = load_scenario(SCENARIOS / "paper_3000rpm.toml", ["reduced.load_zone_half_angle_deg=auto"])
    assert unread_note(auto, ["bearing.radial_clearance_mm"]) is None


def test_the_reduced_models_load_zone_inputs_are_noted_unread_when_its_load_zone_is_given():
    """With reduced.load_zone_half_angle_deg given (the paper scenarios: 23.5), the load, the roller count and
    length and the radial clearance only found the load zone, so a what-if of any of them gives the paper's
    numbers unchanged: each is noted as unread (the load and roller count were not: a 2000 N run printed
    nothing and the same I_dec). With "auto" they set the load zone: no note."""
    from bearingsim.scenario import unread_note

    keys = ["operating.radial_load_N", "bearing.roller_count", "bearing.roller_length_mm", "bearing.radial_clearance_mm"]
    given = load_scenario(SCENARIOS / "paper_3000rpm.toml", ["operating.radial_load_N=2000", "bearing.roller_count=12"])
    assert unread_note(given, keys) == (
        "operating.radial_load_N, bearing.roller_count, bearing.roller_length_mm, bearing.radial_clearance_mm: not used "
        "by the reduced model when reduced.load_zone_half_angle_deg is given (it sets the load zone only when 'auto'); "
        "no effect on the run")
    auto = given.replace(**{"reduced.load_zone_half_angle_deg": "auto"})
    assert unread_note(auto, keys) is None
    multibody = load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["operating.radial_load_N=2000"])
    assert unread_note(multibody, keys) is None


def test_the_reduced_keys_a_multibody_run_does_not_read_are_noted():
    """The multibody model reads nothing of reduced.method and reduced.resting_contact, and the load zone's
    half angle only in its reduced-equivalent scene (the others' load zone comes out of the raceway
    contacts): `--set reduced.load_zone_half_angle_deg=40` on the whole bearing gave the same numbers and
    no note. Each is noted now; the reduced-equivalent scene's load zone is not."""
    from bearingsim.scenario import unread_because, unread_note

    full = load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["reduced.load_zone_half_angle_deg=40"])
    assert unread_because(full, "reduced.method") == "not used by the multibody model"
    assert unread_because(full, "reduced.resting_contact") == "not used by the multibody model"
    note = unread_note(full, ["reduced.load_zone_half_angle_deg", "bearing.pocket_clearance_mm"])
    assert note == ("reduced.load_zone_half_angle_deg: not used by the multibody model's 'full' scene (its load zone "
                    "comes out of the raceway contacts; only multibody.scene = 'reduced_equivalent' reads it); no "
                    "effect on the run")
    equivalent = load_scenario(SCENARIOS / "multibody_reduced_equivalent_3000rpm.toml")
    assert unread_note(equivalent, ["reduced.load_zone_half_angle_deg"]) is None


def test_a_cage_mass_without_its_inertia_is_refused_with_the_inertia_a_ring_of_it_has():
    """Another cage material is another mass; its inertia must follow (a ring between its radii). The
    refusal names the inertia key and gives what a uniform ring of the new mass has, m (r_in^2 + r_out^2) / 2,
    which the check then accepts (it lies between m r_in^2 and m r_out^2)."""
    import re

    with pytest.raises(UserError) as err:
        load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["bearing.cage_mass_kg=0.5"])
    text = str(err.value)
    assert "bearing.cage_inertia_kgm2" in text and "a uniform ring of this mass has" in text
    r_in, r_out = 0.0455, 0.052  # the preset cage's bore and outside radii [m]
    ring = float(re.search(r"/ 2 = ([0-9.e-]+) kg m\^2", text).group(1))
    assert ring == pytest.approx(0.5 * (r_in**2 + r_out**2) / 2, rel=5e-4)  # printed to 4 digits
    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["bearing.cage_mass_kg=0.5", f"bearing.cage_inertia_kgm2={ring}"])
    assert sc.bearing.cage_inertia_kgm2 == ring


def test_a_missing_key_is_told_to_name_a_preset_only_where_a_preset_gives_it():
    """A preset gives the bearing's keys only: a missing operating key was told "set it in the scenario or
    name a [bearing] preset", which cannot give it."""
    with pytest.raises(UserError) as err:
        resolve({"schema_version": 1, "name": "x", "model": "reduced", "bearing": {"preset": "NU214-Suzuki2023"},
                 "operating": {"radial_load_N": 3.0}}, "<test>")
    assert str(err.value).endswith("operating.inner_ring_speed_rpm: missing (set it in the scenario)")
    with pytest.raises(UserError) as err:
        resolve({"schema_version": 1, "name": "x", "model": "reduced", "bearing": {"roller_count": 16},
                 "operating": {"inner_ring_speed_rpm": 3000.0, "radial_load_N": 970.0}}, "<test>")
    assert "bearing." in str(err.value) and "missing (set it in the scenario or name a [bearing] preset)" in str(err.value)


def test_a_ring_mass_the_ring_does_not_have_is_noted():
    """multibody.inner_ring_mass_kg is read by a dynamic inner ring only: with a quasi-static ring (given, or
    chosen by inner_ring = "auto" where two or more rollers share the load: 970 N) a run with another mass
    gave the same numbers bit for bit and no note. It is noted now, with how the ring was chosen; a dynamic
    ring (given, or chosen by "auto" at 200 N, where one roller would carry the ring) reads it; a sweep
    varying a key that decides the ring's model notes nothing (some of its cases may read the mass)."""
    from bearingsim.scenario import unread_note

    mb = SCENARIOS / "multibody_3000rpm.toml"
    keys = ["multibody.inner_ring_mass_kg"]
    given = load_scenario(mb, ["multibody.inner_ring=quasi_static", "multibody.inner_ring_mass_kg=5"])
    assert unread_note(given, keys) == (
        "multibody.inner_ring_mass_kg: not used with a quasi-static (massless) inner ring (multibody.inner_ring; "
        "only multibody.inner_ring = 'dynamic' gives it a mass); no effect on the run")
    auto = load_scenario(mb, ["multibody.inner_ring_mass_kg=5"])
    assert "(auto: 3 roller(s) loaded with one at the load-zone centre (>= 2: quasi-static);" in unread_note(auto, keys)
    for varied in (["operating.radial_load_N"], ["multibody.inner_ring"]):
        assert unread_note(auto, keys, varied=varied) is None
    for sets in (["multibody.inner_ring=dynamic"], ["operating.radial_load_N=200"]):
        assert unread_note(load_scenario(mb, [*sets, "multibody.inner_ring_mass_kg=5"]), keys) is None
    equivalent = load_scenario(SCENARIOS / "multibody_reduced_equivalent_3000rpm.toml",
                               ["multibody.inner_ring_mass_kg=5"])
    assert "it has no inner ring" in unread_note(equivalent, keys)


def test_a_sweep_of_one_setting_keeps_the_notes_other_settings_decide(tmp_path):
    """A land key with a roller-guided cage is noted in a sweep that varies the load (a setting that decides
    another key's note, the ring mass's): sweeping any deciding setting dropped every such note."""
    from bearingsim.scenario import unread_note

    rollers = load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["contact.land_friction=0.2"])
    note = unread_note(rollers, ["contact.land_friction"], varied=["operating.radial_load_N"])
    assert note is not None and "bearing.cage_guidance = 'rollers'" in note
    assert unread_note(rollers, ["contact.land_friction"], varied=["bearing.cage_guidance"]) is None


def test_a_table_given_for_a_section_sets_its_keys_and_keeps_the_others(tmp_path):
    """`--set 'operating={inner_ring_speed_rpm=500}'` replaced the file's whole [operating] section: its
    2000 N and reverse direction were lost for the preset's 970 N, forward, without a word; replace() with
    the same table was refused for a missing key the scenario had. A table sets the keys it holds, as
    they given one by one would; the section's other keys are kept."""
    f = tmp_path / "custom.toml"
    f.write_text('schema_version = 1\nname = "custom"\nmodel = "reduced"\n[bearing]\npreset = "NU214-Suzuki2023"\n'
                 '[operating]\nradial_load_N = 2000.0\ndirection = "reverse"\ninner_ring_speed_rpm = 3000\n')
    one_by_one = load_scenario(f, ["operating.inner_ring_speed_rpm=500"])
    for sc in (load_scenario(f, ["operating={inner_ring_speed_rpm=500}"]),
               bearingsim.load_scenario(f, set={"operating": {"inner_ring_speed_rpm": 500}}),
               load_scenario(f).replace(**{"operating": {"inner_ring_speed_rpm": 500}})):
        assert sc.raw == one_by_one.raw
        assert (sc.operating.radial_load_N, sc.operating.direction) == (2000.0, "reverse")
    # the keys such a table gives are noted as the same keys given one by one
    assert given_keys(f, ["multibody={inner_ring_mass_kg=5}"])[-1] == "multibody.inner_ring_mass_kg"


def test_a_scenario_has_a_short_repr_naming_it_its_model_and_its_file(base_reduced):
    """``repr(Scenario)`` was the default ``<bearingsim.scenario.Scenario object at 0x...>``."""
    import pickle

    path = SCENARIOS / "multibody_3000rpm.toml"
    sc = load_scenario(path)
    assert repr(sc) == f"<Scenario 'multibody_3000rpm': multibody model, from {str(path)!r}>"
    assert repr(sc.replace(name="x")) == f"<Scenario 'x': multibody model, from {str(path)!r} with name='x'>"
    assert repr(resolve(base_reduced)) == "<Scenario 't': reduced model, from '<dict>'>"
    assert repr(pickle.loads(pickle.dumps(sc))) == repr(sc) and "\n" not in repr(sc)


def test_a_key_given_twice_in_the_overrides_is_refused_as_a_sweep_refuses_it():
    """``--set numerics.rotations=2 --set numerics.rotations=3`` ran with 3 (run, show, crosscheck, life and the
    API's ``overrides``), where a sweep refuses "numerics.rotations: given twice". One rule, where the overrides
    are parsed: refused naming the key and both overrides; ``set`` after ``overrides`` still takes its value."""
    path = SCENARIOS / "paper_3000rpm.toml"
    for sets in (["numerics.rotations=2", "numerics.rotations=3"], ["numerics.rotations=2", " numerics.rotations = 2"]):
        with pytest.raises(UserError, match=r"^--set numerics\.rotations: given twice \(numerics\.rotations=2 and "):
            load_scenario(path, sets)
        with pytest.raises(UserError, match="given twice"):
            bearingsim.load_scenario(path, overrides=sets)
    assert bearingsim.load_scenario(path, set={"numerics.rotations": 3},
                                    overrides=["numerics.rotations=2"]).numerics.rotations == 3


def test_a_key_given_once_dotted_and_once_in_its_sections_table_is_given_twice():
    """``--set operating.inner_ring_speed_rpm=1000 --set 'operating={inner_ring_speed_rpm=500}'`` ran with
    whichever came last: a section's table sets each key it holds, as those keys given one by one would
    (docs/usage.md), so the key is given twice, in either order; keys of the table that are not given twice
    still go with the dotted ones."""
    path = SCENARIOS / "paper_3000rpm.toml"
    dotted, table = "operating.inner_ring_speed_rpm=1000", "operating={inner_ring_speed_rpm=500}"
    for sets in ([dotted, table], [table, dotted]):
        with pytest.raises(UserError, match=r"^--set operating\.inner_ring_speed_rpm: given twice \("):
            load_scenario(path, sets)
    sc = load_scenario(path, ["operating.radial_load_N=900", table])
    assert (sc.raw["operating"]["radial_load_N"], sc.raw["operating"]["inner_ring_speed_rpm"]) == (900, 500)
    sc = load_scenario(path, ["operating={radial_load_N=900}", table])  # two tables of other keys: none twice
    assert (sc.raw["operating"]["radial_load_N"], sc.raw["operating"]["inner_ring_speed_rpm"]) == (900, 500)


@pytest.mark.parametrize("command", ["run", "show"])
def test_a_repeated_set_is_refused_on_the_command_line(command):
    from .test_cli import assert_user_error, bearingsim as cli

    args = ["--dry-run"] if command == "run" else []
    assert_user_error(cli(command, SCENARIOS / "paper_3000rpm.toml", "--set", "numerics.rotations=2", "--set",
                          "numerics.rotations=3", *args),
                      "--set numerics.rotations: given twice (numerics.rotations=2 and numerics.rotations=3)")


def test_an_empty_scenario_path_is_said_to_be_empty():
    """``load_scenario("")`` said ".: is a directory, not a scenario file" (``Path("")`` is the current folder)."""
    for load in (load_scenario, bearingsim.load_scenario):
        with pytest.raises(UserError, match=r"^scenario path is empty: give the path of a scenario file"):
            load("")


@pytest.mark.parametrize("overrides, api, cli", [
    (["numerics.rotations"], "overrides: 'numerics.rotations': expected KEY=VALUE",
     "--set 'numerics.rotations': expected KEY=VALUE"),
    (["=1"], "overrides: '=1': empty key", "--set '=1': empty key"),
    (["numerics.rotations=2", "numerics.rotations=3"], "overrides: numerics.rotations: given twice",
     "--set numerics.rotations: given twice"),
    (["numerics=1", "numerics.rotations=2"], "overrides: numerics.rotations: 'numerics' is a value",
     "--set: numerics.rotations: 'numerics' is a value"),
])
def test_a_bad_override_of_the_api_names_the_argument_and_of_the_cli_the_option(capsys, overrides, api, cli):
    """``bearingsim.load_scenario(p, overrides=["numerics.rotations"])`` said "--set 'numerics.rotations':
    expected KEY=VALUE", an option the caller never gave: the API's refusal names its argument, the command
    line's its option."""
    from bearingsim.cli import main

    path = SCENARIOS / "paper_3000rpm.toml"
    with pytest.raises(UserError) as err:
        bearingsim.load_scenario(path, overrides=overrides)
    assert str(err.value).startswith(api) and "--set" not in str(err.value), str(err.value)
    assert main(["run", str(path), "--dry-run", *[a for o in overrides for a in ("--set", o)]]) == 2
    assert capsys.readouterr().err.startswith(f"bearingsim: error: {cli}")


@pytest.mark.parametrize("item", [3, b"numerics.rotations=2", None])
def test_an_override_that_is_not_text_names_the_argument(item):
    """``load_scenario(p, overrides=[3])`` (or bytes) raised TypeError "argument of type 'int' is not iterable" from
    the override's parser; one line naming the argument and the item now."""
    with pytest.raises(UserError) as err:
        bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml", overrides=["numerics.rotations=2", item])
    assert str(err.value) == f"overrides: {item!r}: expected a KEY=VALUE string (got {type(item).__name__})"


@pytest.mark.parametrize("given, meant", [("rotations", "numerics.rotations"), ("restitution", "contact.restitution"),
                                          ("numerics.rotation", "numerics.rotations")])
def test_an_unknown_key_that_ends_one_known_key_is_told_that_key(given, meant):
    """``set={"rotations": 1}`` said "did you mean lubrication?" (the closest top-level name); a key that is the
    last part of exactly one known key names that key, the others keep the closest match."""
    with pytest.raises(UserError) as err:
        bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml", set={given: 1})
    assert str(err.value).endswith(f"{given}: unknown key (did you mean {meant}?)"), str(err.value)


def test_the_repr_of_a_scenario_and_its_result_shows_its_overrides():
    """Two scenarios of one file with different overrides printed alike, and a 500 rpm run of
    paper_3000rpm.toml printed as ``<ReducedResult 'paper_3000rpm': ...>``: the repr names the overrides in the
    order given (``overrides``, then ``set``, then ``replace``), the first three and how many more."""
    path = SCENARIOS / "paper_3000rpm.toml"
    plain = bearingsim.load_scenario(path)
    slow = bearingsim.load_scenario(path, overrides=["numerics.rotations=1"],
                                    set={"operating.inner_ring_speed_rpm": 500})
    head = f"<Scenario 'paper_3000rpm': reduced model, from {str(path)!r}"
    assert repr(plain) == head + ">"
    assert repr(slow) == head + " with numerics.rotations=1, operating.inner_ring_speed_rpm=500>", repr(slow)
    many = slow.replace(**{"contact.restitution": 0.5, "operating.direction": "reverse"})
    assert repr(many) == head + (" with numerics.rotations=1, operating.inner_ring_speed_rpm=500, "
                                 "contact.restitution=0.5 and 1 more>"), repr(many)
    assert many.overrides[-1] == "operating.direction='reverse'" and plain.overrides == ()
    r = bearingsim.run(slow)
    assert repr(r).startswith("<ReducedResult 'paper_3000rpm' with numerics.rotations=1, "
                              "operating.inner_ring_speed_rpm=500: I_dec_mean_Ns="), repr(r)


def test_a_wear_coefficient_below_its_range_is_called_a_specific_wear_rate_only_where_it_looks_like_one():
    """A polymer's converted Archard coefficient (k = k' H = 2e-7, below the brass preset's plausible range)
    got the hint that it may be a specific wear rate k' given as k, which reads the wear about 1e9 times low;
    a k' lies about 1e-17 to 1e-12 m^3/(N m) and a k about 1e-9 to 1e-2. Below 1e-11 the note gives the
    hint; above it, the ordinary out-of-range note."""
    from bearingsim.scenario import out_of_range_note

    for value, hinted in (("2e-7", False), ("1e-9", False), ("1e-15", True), ("5e-12", True)):
        note = out_of_range_note(load_scenario(SCENARIOS / "wear_test_6000rpm.toml",
                                               [f"wear.wear_coefficient={value}"]))
        assert f"wear.wear_coefficient = {float(value):g} (plausible" in note, note
        assert ("1e9 times low" in note) is hinted, (value, note)


def test_drag_refusal_names_the_largest_drag_coefficient_it_accepts():
    """`--set lubrication.drag_coefficient=100` on the main job said "an oil-film drag of 1.49e+03 N against a
    roller load of 47.1 N" but not which c would do. The line names the largest c the bound accepts (the drag
    is c times that of c = 1; rounded down to 3 digits, 3.15 here): it is accepted, 3.16 is refused."""
    import re

    main = SCENARIOS / "multibody_6000rpm.toml"
    with pytest.raises(UserError) as err:
        load_scenario(main, ["lubrication.drag_coefficient=100"])
    msg = str(err.value)
    assert "lubrication.drag_coefficient" in msg and "1.49e+03 N" in msg and "47.1 N" in msg
    largest = float(re.search(r"use at most ([0-9.e+-]+) here", msg).group(1))
    assert largest == 3.15
    load_scenario(main, [f"lubrication.drag_coefficient={largest}"])
    with pytest.raises(UserError, match="use at most 3.15 here"):
        load_scenario(main, ["lubrication.drag_coefficient=3.16"])
