"""Sensitivity and uncertainty studies (issue 25): the reduced model's sensitivities against a central
difference of the event solver, Sobol indices of the Ishigami function through the study's own design
and estimators, resume, a failing case, ranges in the archive, bad input refused in one line."""
from __future__ import annotations

import math

import numpy as np
import pytest

import bearingsim
from bearingsim.cli import main
from bearingsim.parameters import Parameters
from bearingsim.scenario import load_scenario
from bearingsim.studies import sensitivity as sens
from bearingsim.studies.uncertainty import design, sobol_indices

from .conftest import SCENARIOS

REDUCED = SCENARIOS / "paper_6000rpm.toml"
KEYS = ["lubrication.drag_coefficient", "contact.restitution"]


@pytest.mark.slow
def test_reduced_sensitivities_are_the_event_solvers_central_difference(tmp_path):
    """Each row's S equals (ln I(x+) - ln I(x-)) / (ln x+ - ln x-) with I computed here directly by the
    event solver from Parameters at x (1 -+ 10 %) (the table's values come from the case archives, so
    they agree to rounding: 1e-6 relative is the issue's bound). The solver's rotations repeat, so SE 0."""
    from bearingsim.reduced import simulate

    sc = load_scenario(REDUCED)
    res = sens.run_sensitivity(sc, tmp_path, KEYS, 0.1)
    rows = [r for r in res.table if r["quantity"] == "I_dec"]
    assert [r["key"] for r in rows] == KEYS
    for r in rows:
        x = {"lubrication.drag_coefficient": 0.02, "contact.restitution": 0.8}[r["key"]]
        xm, xp = x * 0.9, x * 1.1  # both inside the preset's ranges: not clipped
        assert (r["x_minus"], r["x_plus"]) == pytest.approx((xm, xp), rel=1e-15, abs=0)
        im = simulate(Parameters.from_scenario(sc.replace(**{r["key"]: xm}))).summary["I_dec_mean_Ns"]
        ip = simulate(Parameters.from_scenario(sc.replace(**{r["key"]: xp}))).summary["I_dec_mean_Ns"]
        expected = (math.log(ip) - math.log(im)) / (math.log(xp) - math.log(xm))
        assert r["sensitivity"] == pytest.approx(expected, rel=1e-6, abs=1e-12)
        assert r["sensitivity_se"] == 0.0
        # no standard error shows what the step does: the slope at half the step beside it, x (1 -+ 5 %)
        i2 = [simulate(Parameters.from_scenario(sc.replace(**{r["key"]: x * f}))).summary["I_dec_mean_Ns"]
              for f in (0.95, 1.05)]
        half = (math.log(i2[1]) - math.log(i2[0])) / (math.log(1.05) - math.log(0.95))
        assert r["sensitivity_half_step"] == pytest.approx(half, rel=1e-6, abs=1e-12)
    # the restitution's at 6000 rpm is no local slope: +0.50 at 10 %, -0.48 at 5 % (I_dec is piecewise smooth,
    # with jumps where the number of impacts of a pass changes)
    assert rows[1]["sensitivity"] > 0.3 and rows[1]["sensitivity_half_step"] < -0.3
    # the drag brakes the roller in the no-load zone: more drag, larger rear-face impulse
    assert rows[0]["sensitivity"] > 0
    assert (tmp_path / "sensitivity.png").stat().st_size > 0 and (tmp_path / "sensitivity.csv").is_file()


def _ishigami(x):
    return np.sin(x[..., 0]) + 7.0 * np.sin(x[..., 1]) ** 2 + 0.1 * x[..., 2] ** 4 * np.sin(x[..., 0])


# analytic Sobol indices of the Ishigami function (a = 7, b = 0.1; Saltelli et al. 2010, Sec. 4)
ISHIGAMI_S1 = np.array([0.3139, 0.4424, 0.0])
ISHIGAMI_ST = np.array([0.5576, 0.4424, 0.2437])


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_sobol_indices_of_the_ishigami_function(seed):
    """N = 4096 base samples through design() and sobol_indices(), the functions the uncertainty study
    uses. Tolerance: 4 bootstrap standard errors of each index (they fall as 1/sqrt(N): 0.007-0.022 at
    this N, measured), so a wrong estimator (e.g. S1 without the V normalisation or Homma-Saltelli's
    biased form) fails; the 95 % bootstrap intervals hold the exact values."""
    bounds = np.array([[-math.pi, math.pi]] * 3)
    a, b, ab = design(bounds, 4096, seed)
    s = sobol_indices(_ishigami(a), _ishigami(b), _ishigami(ab), seed)
    assert np.all(s["S1_se"] < 0.03) and np.all(s["ST_se"] < 0.03)
    assert np.all(np.abs(s["S1"] - ISHIGAMI_S1) <= 4 * s["S1_se"])
    assert np.all(np.abs(s["ST"] - ISHIGAMI_ST) <= 4 * s["ST_se"])
    assert np.all((s["ST_low"] <= ISHIGAMI_ST) & (ISHIGAMI_ST <= s["ST_high"]))


def test_two_seeds_agree_within_their_intervals_and_a_seed_repeats():
    bounds = np.array([[-math.pi, math.pi]] * 3)
    r = []
    for seed in (3, 4, 3):
        a, b, ab = design(bounds, 1024, seed)
        r.append(sobol_indices(_ishigami(a), _ishigami(b), _ishigami(ab), seed))
    for name in ("S1", "ST"):
        assert np.array_equal(r[0][name], r[2][name])  # seeded: reproducible
        diff = np.abs(r[0][name] - r[1][name])
        assert np.all(diff <= 2 * np.hypot(r[0][f"{name}_se"], r[1][f"{name}_se"]))


def test_a_rarely_nonzero_output_has_finite_intervals():
    """An output that is zero at all but one point of A and B (the reduced model's I_acc at 6000 rpm):
    resamples without that point do not vary; they give no share (left out), not +-inf, so the
    intervals are finite numbers and no warning is raised (pytest turns warnings into errors)."""
    fa, fb, fab = np.zeros(16), np.zeros(16), np.zeros((2, 16))
    fb[3], fab[0, 5] = 1.0, 1.0
    r = sobol_indices(fa, fb, fab, 0)
    for name in ("S1_low", "S1_high", "ST_low", "ST_high"):
        assert np.all(np.isfinite(r[name])), name
    assert np.all(r["ST_low"] <= r["ST"]) and np.all(r["ST"] <= r["ST_high"])


@pytest.mark.slow  # over 2 s (quick subset under a minute)
def test_a_failing_case_is_kept_and_the_rerun_runs_only_it(tmp_path, monkeypatch):
    """The + run of the drag coefficient given the explicit Euler method at a 5 ms step fails
    (unstable): its key's rows have NaN numbers, status failed and the error; the other key's rows are
    complete. Run again without the fault: the seven finished runs come from their archives."""
    sc = load_scenario(REDUCED)
    real = sens.perturbed_scenarios

    def broken(scenario, keys, step):
        return [(k, side, v, x.replace(**{"reduced.method": "euler", "numerics.dt_s": 0.005})
                 if (k, side, step) == (KEYS[0], "+", 0.1) else x) for k, side, v, x in real(scenario, keys, step)]

    monkeypatch.setattr(sens, "perturbed_scenarios", broken)
    res = sens.run_sensitivity(sc, tmp_path, KEYS, 0.1)
    by = {(r["key"], r["quantity"]): r for r in res.table}
    bad = by[(KEYS[0], "I_dec")]
    assert bad["status"] == "failed" and bad["error"] and math.isnan(bad["sensitivity"])
    assert by[(KEYS[1], "I_dec")]["status"] == "done" and math.isfinite(by[(KEYS[1], "I_dec")]["sensitivity"])
    assert res.outcome.count("failed") == 1
    stored, _ = sens.read_table(tmp_path / "sensitivity.h5")
    assert [r["status"] for r in stored if r["quantity"] == "I_dec"] == ["failed", "done"]
    monkeypatch.setattr(sens, "perturbed_scenarios", real)
    again = sens.run_sensitivity(sc, tmp_path, KEYS, 0.1)
    assert again.outcome.count("cached") == 7 and again.outcome.count("done") == 1  # 4 runs a key: +-step, +-step/2
    assert {(r["key"], r["quantity"]): r["sensitivity"] for r in again.table}[(KEYS[1], "I_dec")] == \
        by[(KEYS[1], "I_dec")]["sensitivity"]


@pytest.mark.slow
def test_uncertainty_reads_the_summaries_the_archives_hold(tmp_path):
    """The study's finish step takes each case's summary from the sweep's record (no archive loaded in
    full): its outputs equal, bit for bit, the numbers of every archive loaded in full, both after the
    runs (records from the runs) and on a resume (records read back from the archives)."""
    from bearingsim.studies.engine import load_result, run_studies
    from bearingsim.studies.uncertainty import Uncertainty

    sc = load_scenario(REDUCED)
    for expect in ("done", "cached"):
        study = Uncertainty(sc, 2, seed=5, keys=KEYS)
        out = run_studies([study], tmp_path)
        assert out.count(expect) == len(study.cases) == 8
        records = {r["case"]: r for r in out.sweep.rows}
        f = study.outputs_of(tmp_path, records)
        for (block, j), c in study.grid.items():
            row = 0 if block == "A" else 1 if block == "B" else 2 + block
            full = load_result(tmp_path, records[c.hash]).summary
            assert f["I_dec"][row, j] == full["I_dec_mean_Ns"] and f["I_acc"][row, j] == full["I_acc_mean_Ns"]
        assert np.all(np.isfinite(f["I_dec"])) and np.ptp(f["I_dec"]) > 0  # the design varies the answer


def test_ranges_are_stored_in_the_archive_and_shown(tmp_path, capsys):
    out = tmp_path / "x.h5"
    assert main(["run", str(REDUCED), "-o", str(out), "--no-plots", "-q"]) == 0
    assert main(["show", str(out)]) == 0
    text = capsys.readouterr().out
    assert "[ranges.bearing.pocket_clearance_mm]" in text and "range = [" in text
    back = bearingsim.load(out).scenario
    from bearingsim.ranges import ranged_keys

    assert ranged_keys(back)["bearing.pocket_clearance_mm"][:2] == (0.16, 0.24)


@pytest.mark.parametrize("args, words", [
    (["--keys", "bearing.roller_mass_kg"], "--keys bearing.roller_mass_kg: no range"),  # continuous, unranged, read
    (["--step", "0"], "--step '0'"),
    (["--step", "150%"], "--step '150%'"),
    # per cent without its sign, and a negative step: the refusal says what to give (it said the bound alone)
    (["--step", "10"], "--step '10': the relative step must be above 0 and below 100 % (runs at x (1 - step) and "
                       "x (1 + step)); did you mean --step 10%?"),
    (["--step=-10%"], "--step '-10%': the relative step must be above 0 and below 100 % (runs at x (1 - step) and "
                      "x (1 + step)); a step is taken both ways, give it positive"),
    # apart from its option: argparse read '-10%' as an unknown option ("expected one argument"); now the value's
    (["--step", "-10%"], "--step '-10%': the relative step must be above 0 and below 100 % (runs at x (1 - step) "
                         "and x (1 + step)); a step is taken both ways, give it positive"),
    (["--step", "-.5"], "--step '-.5'"),
])
def test_bad_sensitivity_input_is_one_line(tmp_path, capsys, args, words):
    code = main(["sensitivity", str(REDUCED), "-o", str(tmp_path / "o"), *args])
    err = capsys.readouterr().err
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("command", ["sensitivity", "uncertainty"])
@pytest.mark.parametrize("scenario, sets, key, words", [
    # a misspelt key: the scenario reader's "did you mean", not an invitation to give it a range
    ("paper_3000rpm", [], "bearing.pocket_clearence_mm",
     "--keys bearing.pocket_clearence_mm: unknown key (did you mean bearing.pocket_clearance_mm?)"),
    ("paper_3000rpm", [], "bearing", "--keys bearing: a section, not a key"),
    # a top-level setting (was: a traceback, ValueError: not enough values to unpack, in ranges.key_kind)
    ("paper_3000rpm", [], "name", "--keys name: a top-level setting of the scenario, not a number"),
    ("paper_3000rpm", [], "model", "--keys model: a top-level setting of the scenario"),
    # ranged keys the run never reads: both runs of a pair identical (was: S +0.000, I_acc n/a, exit 0)
    ("paper_3000rpm", [], "bearing.cage_mass_kg",
     "--keys bearing.cage_mass_kg: {src}: not used by the reduced model, so varying it changes no run; leave it out"),
    ("paper_3000rpm", [], "contact.cage_friction", "not used by the reduced model"),
    ("paper_3000rpm", [], "multibody.traction_mu_max", "not used by the reduced model"),
    ("paper_3000rpm", ["reduced.load_zone_half_angle_deg=30"], "bearing.radial_clearance_mm",
     "when reduced.load_zone_half_angle_deg is given"),
    ("multibody_3000rpm", [], "bearing.cage_land_clearance_mm",
     "--keys bearing.cage_land_clearance_mm: {src}: not used with bearing.cage_guidance = 'rollers'"),
    # a count or a choice has no range and no derivative (was: "give [ranges.bearing.roller_count] range = ...")
    ("multibody_3000rpm", [], "bearing.roller_count",
     "--keys bearing.roller_count: not a continuous number (a count or a choice): it has no range or derivative; "
     "sweep its values instead (bearingsim sweep --param bearing.roller_count=A,B,...)"),
    ("multibody_3000rpm", [], "bearing.cage_guidance", "--keys bearing.cage_guidance: not a continuous number"),
    # a list of numbers (was: "give [ranges.wear.worn_depth_front_um] range = ...", a range then refused as
    # "must be a valid list")
    ("paper_3000rpm", [], "wear.worn_depth_front_um",
     "--keys wear.worn_depth_front_um: not a continuous number (a list of numbers): it has no range or derivative"),
    ("multibody_3000rpm", [], "wear.worn_depth_rear_um", "--keys wear.worn_depth_rear_um: not a continuous number"),
    # Archard's k and H: read, but they only scale the wear outputs (was: a ranged k ran both runs, bit-identical
    # I_dec, and printed S +0.000 with a standard error; the uncertainty study spent its runs and printed n/a)
    ("multibody_6000rpm", ["multibody.raceway_contact=rigid", "numerics.rotations=2"], "wear.wear_coefficient",
     "--keys wear.wear_coefficient: Archard's wear coefficient k only scales the wear outputs (worn volumes and "
     "depths are proportional to k and 1/H), so varying it changes no I_dec, I_acc, cage slip or eccentricity, "
     "the numbers the study measures; leave it out"),
    ("paper_3000rpm", [], "wear.wear_coefficient", "proportional to k and 1/H"),
    ("paper_3000rpm", [], "wear.hardness_Pa", "--keys wear.hardness_Pa: the cage's hardness H only scales the wear"),
])
def test_a_key_that_is_not_one_or_not_read_is_refused_naming_it(tmp_path, capsys, command, scenario, sets, key,
                                                                 words):
    src = str(SCENARIOS / f"{scenario}.toml")
    extra = ["--samples", "4"] if command == "uncertainty" else []
    code = main([command, src, *[a for s in sets for a in ("--set", s)], "--keys", key, *extra,
                 "-o", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert words.format(src=src) in err, err
    assert "range = [low, high]" not in err and not (tmp_path / "o").exists()


def test_the_default_keys_are_those_the_model_reads():
    """The default keys leave out what the run does not read; the refusal of --keys uses the same rule."""
    reduced = load_scenario(PAPER_3000)
    assert sens.default_keys(reduced) == ["bearing.roller_diameter_mm", "bearing.pitch_diameter_mm",
                                          "bearing.pocket_clearance_mm", "lubrication.drag_coefficient",
                                          "contact.restitution"]
    multibody = load_scenario(SCENARIOS / "multibody_3000rpm.toml")
    keys = sens.default_keys(multibody)
    assert "bearing.cage_mass_kg" in keys and "contact.cage_friction" in keys
    assert not {"bearing.cage_land_clearance_mm", "contact.land_friction"} & set(keys)
    land = load_scenario(SCENARIOS / "multibody_3000rpm.toml", ["bearing.cage_guidance=outer_land"])
    assert {"bearing.cage_land_clearance_mm", "contact.land_friction"} <= set(sens.default_keys(land))
    from bearingsim.ranges import ranged_keys
    from bearingsim.scenario import unread_because

    assert all(unread_because(sc, k) is None for sc in (reduced, multibody, land) for k in sens.default_keys(sc))
    assert all(sens.unmeasured_because(sc, k) is None for sc in (reduced, multibody, land) for k in sens.default_keys(sc))
    assert "wear.wear_coefficient" in ranged_keys(multibody) and "wear.wear_coefficient" not in keys


def test_keys_given_as_one_text_are_keys_not_characters():
    """The API's ``keys`` as one text is one key, or several separated by commas as ``--keys`` takes them (a
    text is a sequence: it was read as its characters, "keys: c: unknown key")."""
    sc = load_scenario(PAPER_3000)
    assert sens.check_keys(sc, "contact.restitution", origin="keys") == ["contact.restitution"]
    assert sens.check_keys(sc, "contact.restitution, lubrication.drag_coefficient", origin="keys") == [
        "contact.restitution", "lubrication.drag_coefficient"]
    with pytest.raises(bearingsim.UserError, match=r"^keys: contact\.restitutio: unknown key"):
        sens.check_keys(sc, "contact.restitutio", origin="keys")


def test_a_range_outside_the_keys_bounds_is_refused_in_one_line(tmp_path, capsys):
    sc = tmp_path / "mine.toml"
    sc.write_text(REDUCED.read_text() + '\n[ranges.contact.restitution]\nrange = [0.5, 1.2]\nreason = "mine"\n')
    code = main(["sensitivity", str(sc), "-o", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "ranges.contact.restitution" in err and "1.2" in err and "less than or equal to 1" in err


def test_a_range_of_a_list_key_is_refused_as_not_a_continuous_number(tmp_path, capsys):
    """A range given to a list key (wear.worn_depth_front_um, list[list[float]]) was refused as "must be a
    valid list" (the key was taken for a continuous number because its type names float)."""
    sc = tmp_path / "mine.toml"
    sc.write_text(REDUCED.read_text() + '\n[ranges.wear.worn_depth_front_um]\nrange = [1, 2]\nreason = "mine"\n')
    code = main(["sensitivity", str(sc), "-o", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert (f"{sc}: ranges.wear.worn_depth_front_um: wear.worn_depth_front_um is not a continuous number; only such "
            f"keys take a range") in err, err
    from bearingsim.ranges import is_continuous, key_kind

    multibody = load_scenario(SCENARIOS / "multibody_3000rpm.toml")
    assert [key_kind(multibody, k) for k in ("wear.worn_depth_rear_um", "bearing.cage_land_clearance_mm",
                                             "multibody.inner_ring_mass_kg", "bearing.roller_count")] == \
        ["list", "float", "float", "other"]
    assert not is_continuous(multibody, "wear.worn_depth_rear_um")


@pytest.mark.slow
def test_inspect_and_show_read_the_study_tables(tmp_path, capsys):
    """`inspect` names what a sensitivity.h5 or uncertainty.h5 is and lists its columns; `show` gives the
    scenario it was made from as runnable TOML (as for sweep.h5 and crosscheck.h5)."""
    from bearingsim.studies.uncertainty import run_uncertainty

    sc = load_scenario(REDUCED)
    sens.run_sensitivity(sc, tmp_path / "s", KEYS[:1], 0.1)
    run_uncertainty(sc, tmp_path / "u", samples=4, seed=0, keys=KEYS)
    for path, what in ((tmp_path / "s" / "sensitivity.h5", "sensitivity table"),
                       (tmp_path / "u" / "uncertainty.h5", "uncertainty table")):
        assert main(["inspect", str(path)]) == 0
        text = capsys.readouterr().out
        assert what in text and "paper_6000rpm" in text and "columns:" in text
        assert main(["show", str(path)]) == 0
        shown = capsys.readouterr().out
        assert load_scenario_text(shown) == sc


@pytest.mark.slow
def test_plot_draws_a_study_table_figure_again(tmp_path, capsys):
    """`plot sensitivity.h5` / `plot uncertainty.h5` said "not a bearingsim archive": they draw the study's
    figure again from its table alone, the same bytes as the study drew."""
    from bearingsim.studies.uncertainty import run_uncertainty

    sc = load_scenario(REDUCED)
    sens.run_sensitivity(sc, tmp_path / "s", KEYS[:1], 0.1)
    run_uncertainty(sc, tmp_path / "u", samples=4, seed=0, keys=KEYS)
    for table, png in (("s/sensitivity.h5", "sensitivity.png"), ("u/uncertainty.h5", "uncertainty.png")):
        out = tmp_path / "again" / table.split("/")[0]
        code = main(["plot", str(tmp_path / table), "-o", str(out)])
        captured = capsys.readouterr()
        assert code == 0 and captured.err == "", captured.err
        assert captured.out == f"wrote {out / png}\n"
        assert (out / png).read_bytes() == (tmp_path / table).parent.joinpath(png).read_bytes()


@pytest.mark.slow
def test_table_prints_a_study_table_as_its_command_did(tmp_path, capsys):
    """`bearingsim table` of a sensitivity or uncertainty folder printed its case index (every run in the
    order it ran, marked against the first), and of its sensitivity.h5 or uncertainty.h5 "not a bearingsim
    archive". Both print the study's table: the lines the study's command printed, after one line naming
    the file and the study."""
    runs = {"s": ["sensitivity", str(REDUCED), "--keys", KEYS[0]],
            "u": ["uncertainty", str(REDUCED), "--keys", ",".join(KEYS), "--samples", "2"]}
    for folder, argv in runs.items():
        assert main([*argv, "-o", str(tmp_path / folder), "-j", "1"]) == 0
        lines = capsys.readouterr().out.splitlines()
        body = [ln for ln in lines[1:] if not ln.startswith(("wrote ", "runs: "))]  # the command's table
        table = tmp_path / folder / f"{argv[0]}.h5"
        for path in (tmp_path / folder, table):
            assert main(["table", str(path)]) == 0
            printed = capsys.readouterr().out.splitlines()
            assert printed[0].startswith(f"{table}: {argv[0]} of paper_6000rpm: ")
            assert printed[1:] == body, (printed, body)
        # the reduced model's sensitivity has no standard error: S at half the step beside S instead of a ± column
        assert any(("S1 [95 % CI]" if folder == "u" else "S, half step") in ln for ln in body), body
        assert folder == "u" or not any("± SE" in ln for ln in body), body


def load_scenario_text(text):
    import tomllib

    from bearingsim.scenario import resolve

    return resolve(tomllib.loads(text), "shown")


def test_every_study_command_takes_quiet(tmp_path, capsys):
    """-q means the same on every command that runs many cases: nothing printed when all goes well."""
    from bearingsim.cli import build_parser

    parser = build_parser()
    for cmd in (["sweep", "x.toml"], ["crosscheck", "x.toml"], ["validate"], ["sensitivity", "x.toml"],
                ["uncertainty", "x.toml", "--samples", "4"], ["life", "x.toml", "--limit", "depth=0.1mm"]):
        assert parser.parse_args([*cmd, "-q"]).quiet is True, cmd
    assert main(["sensitivity", str(REDUCED), "--keys", KEYS[0], "-o", str(tmp_path), "-j", "1", "-q"]) == 0
    assert capsys.readouterr().out == ""
    assert (tmp_path / "sensitivity.csv").is_file()


PAPER_3000 = SCENARIOS / "paper_3000rpm.toml"  # the reduced model's I_acc is 0 there (no front-face impact)


def test_a_number_that_is_zero_in_both_runs_says_n_a_and_why(tmp_path, capsys):
    """The reduced model's I_acc is 0 in both runs of every key at 3000 rpm: its log-sensitivity has no
    value. The printed table showed "+nan nan +nan"; it says n/a and why, and so does the report's table
    (NaN stays in sensitivity.h5, an empty field in the CSV)."""
    from bearingsim import reports

    code = main(["sensitivity", str(PAPER_3000), "--keys", "contact.restitution", "-o", str(tmp_path), "-j", "1"])
    out = capsys.readouterr().out
    assert code == 0 and "nan" not in out.lower(), out
    (row,) = [ln for ln in out.splitlines() if ln.startswith("contact.restitution") and " I_acc " in ln]
    assert row.split()[2:5] == ["n/a", "n/a", "n/a"], row
    assert row.endswith("(I_acc is 0 in both runs: no effect, and no relative change to measure)"), row
    rows, _ = sens.read_table(tmp_path / "sensitivity.h5")
    i_acc = next(r for r in rows if r["quantity"] == "I_acc")
    assert math.isnan(i_acc["sensitivity"]) and i_acc["y_minus"] == i_acc["y_plus"] == 0.0
    _, sections, _ = reports._sensitivity_sections(tmp_path / "sensitivity.h5")
    cells = {tuple(c[:2]): c for c in sections[0].blocks[0]["rows"]}
    assert cells[("contact.restitution", "I_acc")][3:] == ["n/a", "n/a",  # a deterministic model's: no ± at all
                                                          "I_acc is 0 in both runs: no effect, and no relative change to measure"]
    assert cells[("contact.restitution", "I_dec")][5] == ""
    # the other reasons a number is missing
    base = {**i_acc, "y_minus": 0.0, "y_plus": 1e-3}
    assert sens.missing_note(base) == "I_acc is 0 in one run: no relative change (ln 0)"
    assert sens.missing_note({**base, "status": "failed"}) == "a run failed"
    finite = {**base, "sensitivity": 0.5, "sensitivity_se": math.nan, "over_range": math.nan}
    assert sens.missing_note(finite) == ("no standard error from fewer than 2 rotations; the key's range starts at 0: "
                                         "no change over it on a log scale")


def test_a_key_whose_value_is_zero_is_left_out_of_the_default_keys(tmp_path, capsys):
    """A ranged key at 0 (a user's frictionless or dragless bearing) refused the whole default study with
    "--keys lubrication.drag_coefficient: its value (0.0) has no relative step", though no --keys was
    given. It is left out, and said so; named in --keys it is refused as before. The uncertainty study,
    which samples the ranges themselves, takes it."""
    from bearingsim.studies.uncertainty import Uncertainty

    zero = ["--set", "lubrication.drag_coefficient=0"]
    code = main(["sensitivity", str(PAPER_3000), *zero, "-o", str(tmp_path / "s"), "-j", "1"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert ("left out: lubrication.drag_coefficient: its value is 0.0: a relative step x (1 ± step) cannot move it; "
            "give it a nonzero value to vary it") in captured.out
    rows, meta = sens.read_table(tmp_path / "s" / "sensitivity.h5")
    assert "lubrication.drag_coefficient" not in {r["key"] for r in rows} and "drag_coefficient" in meta["left_out"]
    code = main(["sensitivity", str(PAPER_3000), *zero, "--keys", "lubrication.drag_coefficient", "-o",
                 str(tmp_path / "k")])
    err = capsys.readouterr().err
    assert code == 2 and "--keys lubrication.drag_coefficient: its value (0.0) has no relative step" in err
    sc = load_scenario(PAPER_3000, ["lubrication.drag_coefficient=0"])
    assert "lubrication.drag_coefficient" in Uncertainty(sc, 2).keys


def test_the_printed_table_says_what_the_cage_slips_s_is():
    """The cage slip's S is d y / d ln x of the slip itself (a fraction), the other rows' d ln y / d ln x, in one
    column headed S: `bearingsim sensitivity scenarios/multibody_3000rpm.toml ...` printed "cage_slip  +0.128" beside
    "I_dec  +15.728" and nothing said which was which, nor in what unit (the report has a measure column). A line
    under the table says it, when the table has a cage slip's row; the tornado chart's axis names the fraction."""
    from bearingsim.studies.sensitivity import format_table

    def row(quantity, measure, s):
        return {"key": "bearing.cage_inner_diameter_mm", "quantity": quantity, "measure": measure, "x": 91.0,
                "x_minus": 90.0, "x_plus": 92.0, "y_minus": 1.0, "y_minus_se": 0.01, "y_plus": 1.2,
                "y_plus_se": 0.01, "sensitivity": s, "sensitivity_se": 0.01, "over_range": s * 0.022,
                "sensitivity_half_step": float("nan"), "x_minus_half": float("nan"), "x_plus_half": float("nan")}

    text = format_table([row("I_dec", "log", 15.7), row("cage_slip", "lin", 0.128)])
    note = text.splitlines()[-1]
    assert note.startswith("cage_slip: S = d y / d ln x, y the slip as a fraction (0.001 = 0.1 %"), text
    assert note.endswith("the other rows: S = d ln y / d ln x"), note
    assert "d y / d ln x" not in format_table([row("I_dec", "log", 15.7)])


def test_uncertainty_prints_its_spread_in_the_tables_units():
    """`bearingsim uncertainty` prints the median and 5-95 % interval of the impulses in mN s and of the cage slip
    in per cent, as every table does (it printed the impulses in N s without a unit, 0.0145 beside tables of 14.5,
    and the slip as a fraction without a unit, 0.004 beside the cross-check's and `table`'s 0.4 %)."""
    from bearingsim.studies.uncertainty import format_table

    text = format_table([{"quantity": "I_dec", "median": 0.0145, "p05": 0.0101, "p95": 0.0203, "runs_used": 8.0},
                         {"quantity": "cage_slip", "median": 0.004, "p05": 0.001, "p95": 0.007, "runs_used": 8.0}], [])
    assert "I_dec      median 14.5, 5-95 %: 10.1 .. 20.3 mN s (8 runs)" in text
    assert "cage_slip  median 0.4, 5-95 %: 0.1 .. 0.7 % (8 runs)" in text
    from bearingsim.studies.uncertainty import _spread_title

    title = _spread_title("cage_slip", {"median": 0.004, "p05": 0.001, "p95": 0.007})
    assert title == "cage slip: median 0.4 %\n5-95 %: 0.1 .. 0.7 %", title


def test_uncertainty_shows_indices_it_cannot_give_as_n_a():
    """A quantity that does not vary over the samples (the reduced model's I_acc, 0 in every run) has no
    Sobol indices: `uncertainty` printed "+nan [+nan, +nan]", where `sensitivity` says n/a and why."""
    from bearingsim.studies.uncertainty import format_table

    nan = float("nan")
    row = {"quantity": "I_acc", "key": "lubrication.drag_coefficient", **dict.fromkeys(
        ("S1", "S1_low", "S1_high", "ST", "ST_low", "ST_high"), nan)}
    text = format_table([], [row])
    assert "nan" not in text and "n/a" in text and "its variance is 0 or unknown" in text


@pytest.mark.slow
def test_uncertainty_of_one_key_counts_the_runs_it_makes(tmp_path, capsys):
    """With one key, AB_0 is A with its only column from B: B itself. The engine runs a case once (by content
    hash), so N (k + 2) = 3N cases are 2N runs; the command line and the table's ``runs`` said 3N."""
    from bearingsim.studies.uncertainty import Uncertainty, read_table

    key = "bearing.pocket_clearance_mm"
    study = Uncertainty(load_scenario(REDUCED), 2, keys=[key])
    assert len(study.cases) == 6 and study.runs == 4
    assert np.array_equal(study.ab[0], study.b)  # the reason: AB_0 is B
    assert main(["uncertainty", str(REDUCED), "--keys", key, "--samples", "2", "-j", "1",
                 "-o", str(tmp_path / "u")]) == 0
    out = capsys.readouterr().out
    assert "N = 2 (4 runs)" in out and "runs: 4 done, 0 cached, 0 failed" in out
    assert read_table(tmp_path / "u" / "uncertainty.h5")[2]["runs"] == 4


def test_the_tornado_draws_the_change_across_each_range_it_is_ordered_by():
    """The chart ranks keys by over_range = S ln(high / low) (docs/sensitivity.md) and its bars are that
    number, ± SE(S) |ln(high / low)|: a key of slope -0.2 over a 1 % range (pitch diameter) sits below one
    of slope +0.3 over a factor-4 range, with the shorter bar. (The bars were the local slopes S, which put
    the longest bar on a key ranked low.) A range from 0 has no bar and says so in its label."""
    import math

    from bearingsim.studies.sensitivity import plot_tornado

    def row(key, q, s, se, ratio):
        return {"key": key, "quantity": q, "sensitivity": s, "sensitivity_se": se,
                "over_range": s * math.log(ratio) if ratio else math.nan}

    rows = [row("bearing.pitch_diameter_mm", "I_dec", -0.2, 0.01, 1.01),
            row("lubrication.drag_coefficient", "I_dec", 0.3, 0.02, 4.0),
            row("contact.cage_friction", "I_dec", 0.5, 0.05, None)]
    fig = plot_tornado(rows)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_yticklabels()]  # top first (ticks from the top down)
    bars = sorted(ax.patches, key=lambda b: -b.get_y())  # top first, the order of the labels from the top
    assert labels == ["lubrication.drag_coefficient", "bearing.pitch_diameter_mm",
                            "contact.cage_friction (range from 0)"]
    assert [b.get_width() for b in bars] == pytest.approx([0.3 * math.log(4.0), -0.2 * math.log(1.01)])
    assert ax.get_xlabel() == "change of ln y across the range" and ax.get_title() == "I_dec"
    import matplotlib.pyplot as plt

    plt.close(fig)



def test_the_tornado_draws_no_bar_for_a_missing_number_nor_an_error_bar_for_a_missing_error():
    """The tornado passed np.nan_to_num(over_range) and np.nan_to_num(SE): a failed pair was a bar of 0 and a
    slope of n/a standard error (a run of one recorded rotation) an error bar of 0, under "± 1 standard
    error". Now neither is drawn: "n/a" at 0, a hatched bar counted in the panel's title; the error bar of a
    slope of 0 is SE(S) ln(high / low), ln(high / low) from the key's other row (it was 0 x SE / 0: NaN)."""
    from bearingsim.studies.sensitivity import plot_tornado

    def row(key, q, s, se, ratio):
        return {"key": key, "quantity": q, "sensitivity": s, "sensitivity_se": se,
                "over_range": s * math.log(ratio)}

    def error_bars(ax):  # the segments of its error bars (a NaN error leaves none, an error of 0 one of length 0)
        return [seg for c in ax.containers if hasattr(c, "has_xerr") for col in c.lines[2]
                for seg in col.get_segments() if len(seg)]

    rows = [row("lubrication.drag_coefficient", "I_dec", 0.3, 0.02, 4.0),
            row("lubrication.drag_coefficient", "I_acc", 0.0, 0.05, 4.0),
            row("bearing.pitch_diameter_mm", "I_dec", -0.2, math.nan, 1.01),  # one rotation: no SE
            row("bearing.pitch_diameter_mm", "I_acc", -0.1, math.nan, 1.01),
            row("contact.restitution", "I_dec", math.nan, math.nan, 2.0),  # a failed pair
            row("contact.restitution", "I_acc", math.nan, math.nan, 2.0)]
    fig = plot_tornado(rows)
    dec, acc = fig.axes
    for ax in (dec, acc):
        assert len(ax.patches) == 2 and [t.get_text() for t in ax.texts] == [" n/a"]
        assert sorted(str(b.get_hatch()) for b in ax.patches) == ["//", "None"]
        (bar,) = error_bars(ax)  # the drag coefficient's
        assert ax.get_title().endswith("\nerror bars: ±1 standard error; hatched: none (n/a), 1 of 2 bars")
    (bar,) = error_bars(acc)
    assert np.ptp(bar[:, 0]) == pytest.approx(2 * 0.05 * math.log(4.0))  # ± SE ln 4 about a slope of 0
    from bearingsim.studies.sensitivity import tornado_errors  # the chart's title and the report's caption

    assert tornado_errors([r for r in rows if r["key"] != "lubrication.drag_coefficient"]).startswith(
        "no error bars: no slope has a standard error (n/a")


def test_a_tornado_panel_without_a_slope_has_no_error_remark():
    """The reduced model at 3000 rpm has I_acc = 0: every I_acc slope is n/a, and its panel was titled "no
    error bars: no bar has a standard error (n/a)" under a figure titled exact (plotting.error_title took
    an empty panel for one of n/a bars). A panel without a bar has no error remark, nor has an exact
    model's panel (its slopes' standard errors 0, or n/a where there is no slope)."""
    from bearingsim.plotting import error_title
    from bearingsim.studies.sensitivity import plot_tornado

    def row(key, q, s, se):
        return {"key": key, "quantity": q, "sensitivity": s, "sensitivity_se": se,
                "over_range": s * math.log(2.0), "sensitivity_half_step": s}

    keys = ("lubrication.drag_coefficient", "contact.restitution")
    exact = [row(k, "I_dec", 0.3, 0.0) for k in keys] + [row(k, "I_acc", math.nan, math.nan) for k in keys]
    for rows in (exact, [{**r, "sensitivity_half_step": math.nan, "sensitivity_se": 0.01 if r["quantity"] ==
                          "I_dec" else math.nan} for r in exact]):  # the reduced model's, a multibody one's
        fig = plot_tornado(rows)
        assert [ax.get_title() for ax in fig.axes] == ["I_dec", "I_acc"]
    assert error_title([]) == ""  # nothing drawn: nothing to say of its errors


def test_the_sobol_chart_draws_no_bar_for_an_index_of_na_nor_an_error_bar_for_a_missing_interval():
    """uncertainty.png drew np.nan_to_num of the indices and their intervals: an index the table gives as n/a
    ("its variance is 0 or unknown") was a bar of 0, a missing interval an error bar of 0 under "bars: 95 %
    bootstrap intervals". Now neither is drawn: "n/a" at 0, a hatched bar, both counted in the title."""
    from bearingsim.studies.uncertainty import plot_indices

    def row(key, v, half):
        return {"quantity": "I_dec", "key": key, **{f"{n}{end}": v + d for n in ("S1", "ST")
                                                    for end, d in (("", 0.0), ("_low", -half), ("_high", half))}}

    rows = [row("lubrication.drag_coefficient", 0.6, 0.1), row("contact.restitution", 0.2, math.nan),
            row("contact.cage_friction", math.nan, math.nan)]
    spread = [{"quantity": "I_dec", "median": 0.018, "p05": 0.017, "p95": 0.019}]
    (ax,) = plot_indices(rows, spread).axes
    assert len(ax.patches) == 4 and [str(b.get_hatch()) for b in ax.patches].count("//") == 2
    segs = [seg for c in ax.containers if hasattr(c, "has_xerr") for col in c.lines[2] for seg in col.get_segments()
            if len(seg)]
    assert len(segs) == 2 and all(np.ptp(seg[:, 0]) == pytest.approx(0.2) for seg in segs)  # the drag's ± 0.1
    assert sorted(t.get_text() for t in ax.texts) == [" S1 n/a", " ST n/a"]
    assert ax.get_title().endswith("\nn/a (variance 0 or unknown): 2 of 6 indices"
                                   "\nhatched (no interval): 2 of 6 indices")


@pytest.mark.parametrize("step, shown, half", [("0.1%", "0.1%", "0.05%"), ("12.5%", "12.5%", "6.25%"),
                                              ("0.1", "10%", "5%")])
def test_the_step_is_shown_as_given(tmp_path, capsys, monkeypatch, step, shown, half):
    """`--step=0.1%` printed "at x (1 ± 0%)" and `--step=12.5%` "(1 ± 12%)" (a whole percent): the command's
    line, `bearingsim table`, the report's table and the tornado's title show the step as given. The reduced
    model runs each key at half the step too, and the lines say so (they said "2 runs" after it did)."""
    from bearingsim import reports

    titles = []
    drawn = sens.plot_tornado
    monkeypatch.setattr(sens, "plot_tornado", lambda rows, title="": titles.append(title) or drawn(rows, title))
    code = main(["sensitivity", str(REDUCED), "--keys", KEYS[0], f"--step={step}", "-o", str(tmp_path), "-j", "1"])
    out = capsys.readouterr().out
    runs = f"4 runs at x (1 ± {shown}) and x (1 ± {half}) within each key's range"
    assert code == 0 and runs in out.splitlines()[0], out
    assert titles and all(f"x (1 ± {shown}) within each key's range" in t for t in titles), titles
    assert main(["table", str(tmp_path)]) == 0
    assert runs in capsys.readouterr().out.splitlines()[0]
    _, sections, _ = reports._sensitivity_sections(tmp_path / "sensitivity.h5")
    assert f"(runs at x (1 ± {shown}))" in sections[0].blocks[0]["caption"], sections[0].blocks[0]["caption"]


def test_a_half_step_clipped_onto_the_full_step_is_no_agreement(tmp_path, capsys):
    """At 3000 rpm the roller diameter (13 mm, the top of its range [12.7, 13]) and the pitch diameter (97.5 mm,
    range +-0.5 mm) are clipped to their ranges at 10 % and at 5 % alike: the half step's runs are the full
    step's. Their "S, half step" said the same as S, which reads as "the slope is local", and the header
    counted 4 runs a key (5 x 4) where 16 ran. Now the half step is n/a with why, the roller diameter's
    one-sided difference is said, the count is the runs that ran, and the drag coefficient keeps its half step."""
    keys = ["bearing.roller_diameter_mm", "bearing.pitch_diameter_mm", "lubrication.drag_coefficient"]
    code = main(["sensitivity", str(SCENARIOS / "paper_3000rpm.toml"), "--keys", ",".join(keys), "-o", str(tmp_path),
                 "-j", "1"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "3 keys, 8 runs at x (1 ± 10%) and x (1 ± 5%) within each key's range (not 4 a key" in out.splitlines()[0]
    assert "runs: 8 done, 0 cached, 0 failed" in out
    rows, meta = sens.read_table(tmp_path / "sensitivity.h5")
    by = {r["key"]: r for r in rows if r["quantity"] == "I_dec"}
    clipped = "half step n/a: clipped to the key's range onto the full step's values"
    for k in keys[:2]:
        assert math.isnan(by[k]["sensitivity_half_step"]) and math.isfinite(by[k]["sensitivity"]), by[k]
        assert clipped in sens.row_note(by[k])
    assert sens.step_notes(by[keys[0]])[0] == "one-sided: x+ is x, the top of the key's range"
    assert sens.step_notes(by[keys[1]]) == [clipped]
    assert math.isfinite(by[keys[2]]["sensitivity_half_step"]) and sens.step_notes(by[keys[2]]) == []
    line = next(x for x in out.splitlines() if x.startswith(keys[0]))
    assert line.split()[4] == "n/a" and clipped in line, line  # key, quantity, S, over range, S at half the step
    assert meta["runs"] == 8
    assert main(["table", str(tmp_path)]) == 0
    assert "3 keys, 8 runs" in capsys.readouterr().out.splitlines()[0]


def test_inspect_gives_every_number_column_of_the_table_a_unit(tmp_path, capsys):
    """`inspect sensitivity.h5` listed x, x_minus, y_minus ... without units."""
    row = {c: 1.0 for c in sens.COLUMNS}
    row.update(key="contact.restitution", quantity="I_dec", measure="log", x_minus_half=0.76, x_plus_half=0.84,
               archive_minus="", archive_plus="", status="done", error="")
    _, h5 = sens.write_table(tmp_path, [row], load_scenario(REDUCED), 0.1)
    assert main(["inspect", str(h5)]) == 0
    lines = {line.split()[0]: line for line in capsys.readouterr().out.splitlines() if line.startswith("  ")}
    for c in ("x", "x_minus", "x_plus", "x_minus_half", "x_plus_half", "y_minus", "y_minus_se", "y_plus", "y_plus_se"):
        assert "number [" in lines[c], lines[c]
    assert "[the key's unit]" in lines["x"] and "N s" in lines["y_minus"]


def test_the_csv_holds_the_half_steps_values_as_the_h5_does(tmp_path):
    """docs/sensitivity.md calls sensitivity.csv and sensitivity.h5 the same table; the CSV lacked the half
    step's values x_minus_half, x_plus_half. It has every column of the .h5 but each pair's archives, status
    and error, with the same numbers."""
    import csv
    import json

    from bearingsim import archive

    row = {c: 1.0 for c in sens.COLUMNS}
    row.update(key="contact.restitution", quantity="I_dec", measure="log", x_minus_half=0.76, x_plus_half=0.84,
               archive_minus="", archive_plus="", status="done", error="")
    csv_path, h5 = sens.write_table(tmp_path, [row], load_scenario(REDUCED), 0.1)
    with open(csv_path, newline="") as fh:
        (got,) = list(csv.DictReader(fh))
    _, meta = archive.read_table_file(h5, sens.INDEX_FORMAT)
    columns = json.loads(meta["columns"])
    assert list(got) == [c for c in columns if c not in ("archive_minus", "archive_plus", "status", "error")]
    assert (float(got["x_minus_half"]), float(got["x_plus_half"])) == (0.76, 0.84)


@pytest.mark.parametrize("args, words", [
    # numpy's generator took any; the table's int64 attribute did not (was: every case run, then exit 1, a
    # traceback ending "TypeError: Object dtype dtype('O') has no native HDF5 equivalent")
    (["--seed", "99999999999999999999999"], "--seed 99999999999999999999999: give an integer from 0 to "
                                            "9223372036854775807"),
    (["--seed", str(2**64)], f"--seed {2**64}: give an integer from 0 to"),
    (["--seed", str(2**63)], f"--seed {2**63}: give an integer from 0 to"),
    (["--seed", "-1"], "--seed -1: give an integer from 0 to"),
    # 7 x 16384 = 114688 cases, over a sweep's limit (was: not refused; at larger counts out of memory, with
    # advice on numerics keys)
    (["--samples", "16384"], "--samples 16384: 114688 cases (16384 x 7: the samples A, B and one block per key) are "
                             "more than the 100000 a sweep or study may have; give at most --samples 14285"),
    (["--samples", str(10**12)], f"--samples {10**12}: {7 * 10**12} cases"),
])
def test_uncertainty_refuses_a_seed_or_a_sample_count_it_cannot_keep(tmp_path, capsys, args, words):
    code = main(["uncertainty", str(SCENARIOS / "paper_3000rpm.toml"), "--samples", "8", *args,
                 "-o", str(tmp_path / "u"), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and words in err, err
    assert not (tmp_path / "u").exists()


@pytest.mark.parametrize("kw, words", [
    (dict(samples=0), "samples: 0: give at least 2 base samples"),
    (dict(samples=2.5), "samples: 2.5: give at least 2 base samples"),
    (dict(samples=2, seed=-1), "seed: -1: give an integer from 0 to 9223372036854775807"),
    (dict(samples=16384), "samples: 16384: 114688 cases (16384 x 7: the samples A, B and one block per key) are more "
                          "than the 100000 a sweep or study may have; give at most samples=14285"),
])
def test_the_apis_uncertainty_refuses_its_samples_and_seed_as_its_arguments(kw, words):
    """``bearingsim.uncertainty`` names its own arguments in a refusal, not the command's options (it said
    "--samples 0: ..." to a caller who gave ``samples=0``)."""
    with pytest.raises(bearingsim.UserError) as err:
        bearingsim.uncertainty(load_scenario(SCENARIOS / "paper_3000rpm.toml"), **kw)
    assert str(err.value).startswith(words), str(err.value)


@pytest.mark.slow  # a sensitivity study of a few reduced runs (~3.6 s)
def test_the_largest_seed_is_kept_in_the_table(tmp_path):
    from bearingsim.studies.uncertainty import MAX_SEED

    assert main(["uncertainty", str(SCENARIOS / "paper_3000rpm.toml"), "--samples", "2", "--keys",
                 "contact.restitution", "--seed", str(MAX_SEED), "-o", str(tmp_path / "u"), "-q"]) == 0
    from bearingsim import archive
    from bearingsim.studies.uncertainty import INDEX_FORMAT

    assert archive.read_table_file(tmp_path / "u" / "uncertainty.h5", INDEX_FORMAT)[1]["seed"] == MAX_SEED


@pytest.mark.parametrize("study", ["sensitivity", "uncertainty"])
@pytest.mark.parametrize("key, words", [("nope.key", "keys: nope.key: unknown key"),
                                        ("bearing", "keys: bearing: a section, not a key"),
                                        ("bearing.cage_mass_kg", "keys: bearing.cage_mass_kg: ")])
def test_a_bad_key_of_the_api_is_named_as_its_argument(tmp_path, study, key, words):
    """``bearingsim.sensitivity(sc, keys=["nope.key"])`` said "--keys nope.key: unknown key", the command line's
    option: the API's refusal names its argument ``keys`` (the command line keeps --keys, tested above)."""
    sc = load_scenario(PAPER_3000)
    with pytest.raises(bearingsim.UserError) as err:
        if study == "sensitivity":
            bearingsim.sensitivity(sc, tmp_path / "o", keys=[key])
        else:
            bearingsim.uncertainty(sc, 4, tmp_path / "o", keys=[key])
    assert str(err.value).startswith(words) and "--keys" not in str(err.value), str(err.value)
    assert not (tmp_path / "o").exists()


def _paper_3000rpm_at_16_samples():
    """The indices and spreads `bearingsim uncertainty scenarios/paper_3000rpm.toml --samples 16` printed (I_dec)."""
    printed = {"bearing.roller_diameter_mm": ((-0.004, -0.012, 0.000), (0.0001, 0.00001, 0.0004)),
               "bearing.pitch_diameter_mm": ((0.016, 0.003, 0.030), (0.0002, 0.00001, 0.0009)),
               "bearing.pocket_clearance_mm": ((-0.063, -0.130, 0.001), (0.016, 0.007, 0.029)),
               "lubrication.drag_coefficient": ((1.035, 0.536, 1.588), (0.971, 0.566, 1.450)),
               "contact.restitution": ((-0.003, -0.105, 0.105), (0.031, 0.017, 0.053))}
    rows = [{"quantity": "I_dec", "key": k, **{f"{n}{end}": v for n, three in zip(("S1", "ST"), both)
                                              for end, v in zip(("", "_low", "_high"), three)}}
            for k, both in printed.items()]
    spread = [{"quantity": "I_dec", "median": 0.005346, "p05": 0.004339, "p95": 0.006581, "runs_used": 32.0}]
    return rows, spread


def test_the_sobol_chart_gives_the_commands_unit_and_says_which_indices_it_does_not_resolve():
    """uncertainty.png of paper_3000rpm at N = 16 titled its panel "I dec: median 0.005346, 5-95 %: 0.004339 ..
    0.006581" (N s, no unit; the command prints 5.346 .. mN s), and drew shares from -0.13 to 1.59 as if they
    were read: 5 of its 10 indices have a 95 % interval that reaches 0 as the command prints it ([-0.130,
    +0.001], [+0.000, +0.000]), and shares below 0 or above 1 are the estimator's scatter. The title gives the
    command's numbers and unit, those bars are faded and counted, and the region outside 0..1 is marked."""
    from bearingsim.studies.uncertainty import format_table, plot_indices

    rows, spread = _paper_3000rpm_at_16_samples()
    printed = format_table(spread, rows)
    assert "median 5.346, 5-95 %: 4.339 .. 6.581 mN s" in printed
    (ax,) = plot_indices(rows, spread).axes
    title = ax.get_title()
    assert title.startswith("$I_{dec}$: median 5.346 mN s\n5-95 %: 4.339 .. 6.581 mN s"), title
    assert "\nnot told from 0 (95 % interval reaches 0): 5 of 10 indices" in title, title
    faded = {(c.get_label(), round(p.get_y() + p.get_height() / 2)): p.get_alpha() is not None and p.get_alpha() < 1
             for c in ax.containers if hasattr(c, "patches") for p in c.patches}
    rows_at = {round(y): k for y, k in zip(range(4, -1, -1), [r["key"] for r in rows])}
    unresolved = sorted((label, rows_at[y]) for (label, y), f in faded.items() if f)
    assert unresolved == [("first order", "bearing.pocket_clearance_mm"), ("first order", "bearing.roller_diameter_mm"),
                          ("first order", "contact.restitution"), ("total", "bearing.pitch_diameter_mm"),
                          ("total", "bearing.roller_diameter_mm")], unresolved
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(lb.startswith("outside 0..1: no share, the estimate's scatter") for lb in labels), labels
    assert any("faded: 95 % interval reaches 0" in lb for lb in labels), labels


def test_the_closing_line_counts_the_runs_with_notes(tmp_path, capsys):
    """`bearingsim sensitivity` (and uncertainty, validate) ended on "runs: 4 done, 0 cached, 0 failed; archives in
    DIR/cases" whatever the runs' notes, where sweep and crosscheck count the cases with notes and say where they are
    listed. A pocket clearance outside the preset's plausible range notes every run; the preset's notes none."""
    code = main(["sensitivity", str(REDUCED), "--keys", "lubrication.drag_coefficient", "--set",
                 "bearing.pocket_clearance_mm=0.1", "-o", str(tmp_path / "noted"), "-j", "1"])
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert code == 0 and last == (f"runs: 4 done, 0 cached, 0 failed; archives in {tmp_path / 'noted' / 'cases'}; "
                                  f"4 runs with notes ('bearingsim table {tmp_path / 'noted' / 'sweep.h5'}' marks them "
                                  f"in its notes column and lists them)"), last
    assert main(["sensitivity", str(REDUCED), "--keys", "lubrication.drag_coefficient", "-o",
                 str(tmp_path / "clean"), "-j", "1"]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("runs: 4 done") and "with notes" not in last, last
