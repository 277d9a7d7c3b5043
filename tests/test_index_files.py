"""Issue 28, defect 5: inspect/show describe bearingsim's own index files; --param lists split only at
top-level commas, and a START:STOP:NUM range; keys the chosen model does not use are noted.

Nothing here is simulated: the index files are written directly."""
import json

import pytest

from bearingsim.errors import UserError
from bearingsim.scenario import load_scenario
from bearingsim.sweeps.index import write_index
from bearingsim.sweeps.spec import parse_param

from .conftest import SCENARIOS
from .test_cli import assert_user_error, bearingsim

SPEED = "operating.inner_ring_speed_rpm"


def _sweep_index(folder):
    rows = [{"case": f"c{i}", "values": {SPEED: s}, "status": st, "error": "", "archive": f"cases/c{i}.h5",
             "wall_s": 0.1, "summary": {"I_dec_mean_Ns": 0.005} if st == "done" else {}}
            for i, (s, st) in enumerate(((1000.0, "done"), (2000.0, "failed"), (3000.0, "done")))]
    write_index(folder, rows, [SPEED], {"mode": "product", "grid": json.dumps([SPEED]), "grid_rows": 3,
                                       "scenario": "paper_3000rpm.toml"})
    return folder / "sweep.h5"


def _crosscheck_index(folder):
    from bearingsim.studies.crosscheck import COLUMNS, write_table

    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml")
    rows = []
    for rung in (1, 2):
        row = {c: 0.001 * rung for c in COLUMNS}
        row.update(rpm=3000.0, rung=rung, scene="full", relaxed="none", archive=f"r{rung}.h5", wall_s=1.0,
                   status="done", error="")
        rows.append(row)
    return write_table(folder, rows, sc)[1], sc


@pytest.mark.slow
def test_inspect_and_show_describe_a_sweep_index(tmp_path):
    h5 = _sweep_index(tmp_path)
    res = bearingsim("inspect", h5)
    assert res.returncode == 0, res.stderr
    assert "bearingsim sweep index" in res.stdout and "3 cases (done 2, failed 1)" in res.stdout
    assert "I_dec_mean_Ns" in res.stdout and "[N s]" in res.stdout and f"swept keys: {SPEED}" in res.stdout
    res = bearingsim("show", h5)
    assert res.returncode == 0, res.stderr
    assert all(line.startswith("# ") for line in res.stdout.splitlines()) and "3 cases" in res.stdout


@pytest.mark.slow
def test_inspect_and_show_describe_a_crosscheck_table(tmp_path):
    h5, sc = _crosscheck_index(tmp_path)
    res = bearingsim("inspect", h5)
    assert res.returncode == 0, res.stderr
    assert "bearingsim cross-check table" in res.stdout and "2 rows (done 2)" in res.stdout  # a rung at a speed
    assert "change_from_previous" in res.stdout and "speeds [rpm]: 3000" in res.stdout
    res = bearingsim("show", h5)
    assert res.returncode == 0, res.stderr
    assert res.stdout == sc.to_toml()  # the cross-check's scenario, runnable


@pytest.mark.parametrize("item, values", [
    ("bearing.pocket_clearance_mm=0.1:0.4:4", [0.1, 0.2, 0.3, 0.4]),
    (f"{SPEED}=500:6000:12", [500.0 + 500.0 * i for i in range(12)]),
    ("k=1,2,3", [1, 2, 3]),
    ("k=[1, 2],[3, 4]", [[1, 2], [3, 4]]),
    ("k={a = 1, b = 2},{a = 3, b = 4}", [{"a": 1, "b": 2}, {"a": 3, "b": 4}]),
    ('k="x,y",z', ["x,y", "z"]),
])
def test_param_lists_and_ranges(item, values):
    key, got = parse_param(item)
    assert key == item.split("=", 1)[0] and got == pytest.approx(values) if isinstance(values[0], float) else got == values


@pytest.mark.parametrize("item, values", [
    ("bearing.pocket_clearance_mm=0.05:0.5:10", [0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5]),
    ("bearing.pocket_clearance_mm=0.1:0.4:4", [0.1, 0.2, 0.3, 0.4]),
    ("contact.restitution=0.1:0.9:9", [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]),
])
def test_a_range_gives_the_decimal_values_its_ends_are_written_in(item, values):
    """A range's values are the decimals a user reads in its table and selects by in the map
    (xarray's ``.sel(0.15)``), bit for bit: linspace alone gave 0.15000000000000002 and 0.30000000000000004,
    which no exact selection finds. (To 15 significant digits: each value moves by at most 1e-15 of itself.)"""
    assert parse_param(item)[1] == values


def test_param_range_needs_an_integer_count():
    with pytest.raises(UserError, match="integer NUM"):
        parse_param("k=1:2:2.5")


def test_sweep_help_documents_the_range():
    res = bearingsim("sweep", "--help")
    assert "START:STOP:NUM" in res.stdout


@pytest.mark.slow
def test_param_inline_table_is_not_split_at_its_commas(tmp_path):
    res = bearingsim("sweep", SCENARIOS / "paper_3000rpm.toml", "--param", "contact={restitution = 0.5, friction = 0.1}",
                     "-o", tmp_path, "-j", "1")
    assert_user_error(res, "contact={'restitution': 0.5, 'friction': 0.1}")  # the table whole, not '{restitution = 0.5'


@pytest.mark.slow
def test_keys_the_reduced_model_does_not_use_are_noted(tmp_path):
    base = SCENARIOS / "paper_3000rpm.toml"
    res = bearingsim("run", base, "--set", "bearing.cage_guidance=outer_land", "--set", "numerics.rotations=1",
                     "--set", "bearing.cage_land_clearance_mm=0.5", "--no-plots", "-o", tmp_path / "a.h5")
    assert res.returncode == 0, res.stderr
    notes = [line for line in res.stderr.splitlines() if line.strip()]
    assert notes == ["bearingsim: note: bearing.cage_guidance, bearing.cage_land_clearance_mm: not used by the "
                     "reduced model (no effect on the run)"]
    res = bearingsim("sweep", base, "--param", "multibody.raceway_contact=rigid,hertz", "--set", "numerics.rotations=1",
                     "--no-plots", "-o", tmp_path / "s", "-j", "1")
    assert res.returncode == 0, res.stderr
    assert [line for line in res.stderr.splitlines() if "note" in line] == [
        "bearingsim: note: multibody.raceway_contact: not used by the reduced model (no effect on the run)"]
    # keys the model uses: no note
    res = bearingsim("run", base, "--set", "numerics.rotations=1", "--no-plots", "-o", tmp_path / "b.h5")
    assert res.returncode == 0 and "note" not in res.stderr, res.stderr


@pytest.mark.slow
def test_a_sweep_of_a_key_its_settings_leave_unread_is_noted(tmp_path):
    """A sweep of the load on a paper scenario (load zone given) gives the same case three times: noted, as
    `run` notes it (the sweep printed nothing). Sweeping the load zone's setting too, some cases read the
    load: no note."""
    base = SCENARIOS / "paper_3000rpm.toml"
    res = bearingsim("sweep", base, "--param", "operating.radial_load_N=500,2000", "--no-plots", "-o", tmp_path / "s",
                     "-j", "1")
    assert res.returncode == 0, res.stderr
    assert [line for line in res.stderr.splitlines() if "note" in line] == [
        "bearingsim: note: operating.radial_load_N: not used by the reduced model when "
        "reduced.load_zone_half_angle_deg is given (it sets the load zone only when 'auto'); no effect on the run"]
    res = bearingsim("sweep", base, "--param", "operating.radial_load_N=500,2000", "--param",
                     "reduced.load_zone_half_angle_deg=auto,23.5", "--no-plots", "-o", tmp_path / "t", "-j", "1")
    assert res.returncode == 0 and "note" not in res.stderr, res.stderr


def test_unused_keys_per_model():
    from bearingsim.scenario import unused_keys

    keys = ["multibody.scene", "bearing.cage_guidance", "bearing.pocket_clearance_mm", "reduced.load_zone_half_angle_deg"]
    assert unused_keys("reduced", keys) == ["multibody.scene", "bearing.cage_guidance"]
    assert unused_keys("multibody", keys) == []  # its reduced-equivalent scene reads the load zone
    assert unused_keys("multibody", ["reduced.method", "reduced.resting_contact"]) == ["reduced.method",
                                                                                      "reduced.resting_contact"]


def test_every_summary_key_is_documented_with_its_unit():
    from bearingsim import multibody, reduced
    from bearingsim.stats import SEM_UNITS
    from .conftest import archive_summary_table

    table, rows = archive_summary_table()
    units = {**reduced.SUMMARY_UNITS, **multibody.SUMMARY_UNITS, **multibody.RIGID_SUMMARY_UNITS,
             **multibody.LAND_SUMMARY_UNITS, **SEM_UNITS}
    missing = [k for k in [*units, "scene", "pockets"] if k not in rows and k not in table]
    assert missing == []
    wrong = {k: (rows[k], u) for k, u in units.items() if k in rows and rows[k] != u}
    assert wrong == {}
    assert "total over all recorded steps" in table  # land_torque_impulse_Nms is a run total, unlike the others


@pytest.mark.parametrize("item, message", [
    ("=1,2", "--param '=1,2': empty key; expected KEY=V1,V2,..."),  # it said "--set '=1': empty key"
    (".k=1", "--param '.k=1': empty key"),
    (f"{SPEED}=1000:2000", f"--param '{SPEED}=1000:2000': expected START:STOP:NUM (NUM evenly spaced numbers, both "
                           f"ends included), e.g. {SPEED}=1000:2000:3"),  # it said "must be a valid number"
    (f"{SPEED}=1000:2000:3:4", "expected START:STOP:NUM"),
])
def test_a_bad_param_is_named_as_the_param_it_is(item, message):
    with pytest.raises(UserError) as exc:
        parse_param(item)
    assert message in str(exc.value) and "--set" not in str(exc.value), str(exc.value)


def test_crosscheck_speeds_given_as_a_range_say_the_form_they_take():
    from bearingsim.studies.crosscheck import parse_speeds

    with pytest.raises(UserError) as exc:
        parse_speeds("1000:3000:3")
    assert str(exc.value) == ("--speeds '1000:3000:3': --speeds takes a list, not a range START:STOP:NUM as --param "
                              "does: give inner-ring speeds in rpm separated by commas, e.g. 1000,3000,6000")
    assert parse_speeds("1000,3000") == (1000.0, 3000.0)
