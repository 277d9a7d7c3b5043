"""Archives as a working tool: the Python API, and `plot`, `rerun`, `compare`, `show` on archives."""
import json
import re
import shutil

import h5py
import numpy as np
import pytest

import bearingsim

from .conftest import ROOT, SCENARIOS
from .test_cli import assert_user_error, bearingsim as cli


def test_readme_api_example_runs(tmp_path, monkeypatch):
    """The README's Python example, run as written (from the repository root, in a scratch copy)."""
    text = (ROOT / "README.md").read_text()
    block = re.search(r"<!-- api-example -->\s*```python\n(.*?)```", text, re.S)
    assert block, "README has no api-example block"
    monkeypatch.chdir(tmp_path)
    shutil.copytree(SCENARIOS, tmp_path / "scenarios")
    ns = {}
    exec(compile(block.group(1), "README api-example", "exec"), ns)
    r, r2 = ns["r"], ns["r2"]
    # the override took effect, and the archive gives the same result back
    assert r.scenario.operating.inner_ring_speed_rpm == 500
    assert r2.summary == r.summary
    assert np.array_equal(r2.per_rotation["I_dec"], r.per_rotation["I_dec"])
    assert r.per_rotation["I_dec"].shape == (1, 1)
    assert set(r.impacts) >= {"time_s", "theta_deg", "approach_speed_m_s", "impulse_Ns", "pocket", "face"}


def test_figure_title_names_the_speed_actually_run():
    sc = bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml", set={"operating.inner_ring_speed_rpm": 500.0})
    r = bearingsim.run(sc)
    fig = r.plot_pass()
    title = fig.axes[0].get_title()
    assert "500 rpm" in title and "3000 rpm" not in title.split(":", 1)[1]


def test_set_with_a_bad_key_is_a_user_error():
    with pytest.raises(bearingsim.UserError, match="bearing.nope"):
        bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml", set={"bearing.nope": 1.0})


@pytest.fixture(scope="module")
def reduced_archive(tmp_path_factory):
    d = tmp_path_factory.mktemp("arch")
    # the tests read the archive, never its figures: --no-plots (the figures are plot's and run's own tests)
    res = cli("run", SCENARIOS / "paper_1000rpm.toml", "-o", d / "a.h5", "-q", "--no-plots")
    assert res.returncode == 0, res.stderr
    return d / "a.h5"


@pytest.fixture(scope="module")
def multibody_archive(tmp_path_factory):
    d = tmp_path_factory.mktemp("mb")
    res = cli("run", SCENARIOS / "multibody_6000rpm.toml", "--set", "numerics.rotations=1", "-o", d / "m.h5", "-q",
              "--no-plots")  # plot draws them again from a copy of the archive alone
    assert res.returncode == 0, res.stderr
    return d / "m.h5"


@pytest.mark.slow
def test_plot_draws_every_figure_again_from_the_archive_alone(tmp_path, multibody_archive):
    lone = tmp_path / "copy.h5"
    shutil.copy(multibody_archive, lone)  # no PNG, no scenario file beside it
    res = cli("plot", lone, "-o", tmp_path / "figs")
    assert res.returncode == 0, res.stderr
    names = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert names == ["copy_forces.png", "copy_impulses.png", "copy_orbit.png", "copy_wear.png"]
    assert all((tmp_path / "figs" / n).stat().st_size > 10_000 for n in names)


def _edit_json_attr(group, key, change):
    """Change one value of a format-2 attribute group in place (``attrs_json``)."""
    import json

    values = json.loads(group.attrs["attrs_json"])
    values[key] = change(values[key])
    group.attrs["attrs_json"] = json.dumps(values)


@pytest.mark.slow
def test_rerun_is_bit_identical_and_names_what_differs(tmp_path, reduced_archive):
    res = cli("rerun", reduced_archive, fresh_interpreter=True)  # another process than the run's, its own hash seed
    assert res.returncode == 0 and "bit-identical" in res.stdout, res.stdout + res.stderr
    tampered = tmp_path / "t.h5"
    shutil.copy(reduced_archive, tampered)
    with h5py.File(tampered, "r+") as f:
        _edit_json_attr(f["results/summary"], "I_dec_mean_Ns", lambda v: v * (1.0 + 1e-12))
        _edit_json_attr(f["provenance"], "version_numpy", lambda v: "0.0.1")
        _edit_json_attr(f["provenance"], "model_version", lambda v: v - 1)  # written by the model before
    res = cli("rerun", tampered)
    assert res.returncode == 1
    assert "I_dec_mean_Ns" in res.stdout and "differs" in res.stdout and "numpy: archive 0.0.1" in res.stdout
    # the model's own version, bumped when a change moves numbers, is the likeliest reason: named too
    from bearingsim.model_versions import MODEL_VERSIONS

    v = MODEL_VERSIONS["reduced"]
    assert f"model version: archive {v - 1}, now {v} (bumped when a change moves the model's numbers: " \
           "CHANGELOG.md says which)" in res.stdout, res.stdout


def test_an_archive_written_before_an_added_array_reruns_and_compares_identical(tmp_path, reduced_archive):
    """A reduced archive of a version that did not record the trace's I_acc_cumulative (ADDED_ARRAYS: recorded
    since, beside the same numbers) reruns bit-identical and compares identical to a new one (exit 0), each
    saying which array it did not compare and why; a number changed in such an archive still differs."""
    old = tmp_path / "old.h5"
    shutil.copy(reduced_archive, old)
    with h5py.File(old, "r+") as f:
        del f["results/trace/I_acc_cumulative"]
    line = ("  not in {}: trace/I_acc_cumulative (recorded by later versions than the one that wrote {}; "
            "not compared)")
    res = cli("rerun", old)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "rerun is bit-identical" in res.stdout and line.format("A", "A") in res.stdout.splitlines(), res.stdout
    res = cli("compare", reduced_archive, old)
    assert res.returncode == 0 and line.format("B", "B") in res.stdout.splitlines(), res.stdout
    assert res.stdout.splitlines()[-1].startswith("results: identical")
    with h5py.File(old, "r+") as f:
        f["results/trace/I_dec_cumulative"][-1] *= 1.0 + 1e-12
    res = cli("compare", reduced_archive, old)
    assert res.returncode == 1 and "differs: trace/I_dec_cumulative" in res.stdout, res.stdout
    assert line.format("B", "B") in res.stdout.splitlines()


def test_compare_of_two_models_results_says_no_array_is_of_a_later_version():
    """``bearingsim compare`` of a reduced against a multibody archive said "not in B: trace/I_acc_cumulative
    (recorded by later versions than the one that wrote B; not compared)": the multibody model records no trace,
    in any version. Between two models an array of one only differs as any other, and each model version is
    named with its model ("model version: A 1 (reduced model), B 9 (multibody model) ...")."""
    import warnings

    from bearingsim.compare import compare_results

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        red = bearingsim.run(bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml", set={"numerics.rotations": 1}))
        mb = bearingsim.run(bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml", set={
            "multibody.raceway_contact": "rigid", "numerics.rotations": 1}))
    c = compare_results(red, mb)
    text = "\n".join(c.difference_lines(shown=1000) + c.version_lines())
    assert "later versions" not in text and not c.unrecorded, text
    assert "trace/I_acc_cumulative" in c.arrays_differ and c.how["trace/I_acc_cumulative"] == "only in A"
    assert (f"  model version: A {red.provenance['model_version']} (reduced model), B "
            f"{mb.provenance['model_version']} (multibody model)") in text, text


@pytest.mark.slow
def test_compare_of_runs_that_store_different_motion_compares_their_results(multibody_archive):
    """Storing motion (``[output] motion_*``) changes no number of a run (docs/archive.md), but ``compare`` of a
    run with it against the same run without it said "results: differ" (exit 1) over the 18 motion series only
    one held. The motion series are compared only between runs that store the same motion; otherwise they are
    named as not compared, with the keys that differ. With the same [output] keys a missing series differs."""
    from bearingsim.compare import compare_results
    from bearingsim.simulation import COMPARED, load

    a, b = load(multibody_archive, only=COMPARED), load(multibody_archive, only=COMPARED)
    motion = [k for k in b.series if k.startswith("motion_")]
    assert len(motion) == 6, motion  # 6 series of step, time and value: 18 arrays
    for k in motion:
        del b.series[k]
    c = compare_results(a, b)
    assert not c.identical and len(c.arrays_differ) == 18 and c.how[c.arrays_differ[0]] == "only in A"
    b.scenario = b.scenario.replace(**{"output.motion_rotations": 0.0})
    c = compare_results(a, b)
    assert c.identical and len(c.unstored) == 18 and not c.arrays_differ, c.arrays_differ
    assert ("  not compared: 18 motion series (what a run stores for animations beyond its results; the runs store "
            "different motion: output.motion_rotations 2.0 -> 0.0)") in c.unrecorded_lines()


@pytest.mark.slow
def test_rerun_of_a_multibody_archive_is_bit_identical(multibody_archive):
    res = cli("rerun", multibody_archive, fresh_interpreter=True)  # another process than the run's
    assert res.returncode == 0 and "bit-identical" in res.stdout, res.stdout + res.stderr


@pytest.mark.slow
def test_compare_exit_codes_like_diff(tmp_path, reduced_archive):
    assert cli("compare", reduced_archive, reduced_archive).returncode == 0
    other = tmp_path / "o.h5"
    assert cli("run", SCENARIOS / "paper_1000rpm.toml", "--set", "contact.restitution=0.7", "-o", other, "-q",
               "--no-plots").returncode == 0
    res = cli("compare", reduced_archive, other)
    assert res.returncode == 1
    assert "contact.restitution: 0.8 -> 0.7" in res.stdout and "I_dec_mean_Ns" in res.stdout
    bad = tmp_path / "bad.h5"
    bad.write_text("not an archive")
    assert_user_error(cli("compare", reduced_archive, bad), "bad.h5")


def test_compare_of_results_that_differ_names_the_versions_that_differ(tmp_path, reduced_archive):
    """The same scenario gives bit-identical numbers on one installation; another numpy can round a
    transcendental function's last digit otherwise. ``compare`` of two archives that differ named no version
    (``rerun`` did): it lists each package or model version that differs between them, as ``rerun`` does;
    results that are identical need none."""
    other = tmp_path / "o.h5"
    shutil.copy(reduced_archive, other)
    with h5py.File(other, "r+") as f:
        old = json.loads(f["provenance"].attrs["attrs_json"])["version_numpy"]
        _edit_json_attr(f["provenance"], "version_numpy", lambda v: "1.26.0")
    res = cli("compare", reduced_archive, other)
    assert res.returncode == 0 and "package version" not in res.stdout, res.stdout  # identical results
    with h5py.File(other, "r+") as f:
        _edit_json_attr(f["results/wear"], "rear_per_hour_m3_h", lambda v: v * (1.0 + 1e-12))
    res = cli("compare", reduced_archive, other)
    assert res.returncode == 1 and f"  package version numpy: A {old}, B 1.26.0\n" in res.stdout, res.stdout


@pytest.mark.slow
def test_compare_and_rerun_see_a_stored_number_outside_the_summary(tmp_path, reduced_archive):
    """"results: identical" covers every stored result, not only the summary and the per-rotation arrays:
    the reduced model's wear rates (/results/wear), pass and operating point are attribute groups, and a
    multibody archive's wear profiles are arrays. Two runs of other wear keys, whose summaries and impulses
    are the same, said "results: identical" (exit 0); a tampered wear rate, or wear profile, gave a clean
    rerun."""
    wear = tmp_path / "wear.h5"
    assert cli("run", SCENARIOS / "paper_1000rpm.toml", "--set", "wear.wear_coefficient=1e-4", "-o", wear, "-q",
               "--no-plots").returncode == 0
    res = cli("compare", reduced_archive, wear)
    assert res.returncode == 1 and "results: differ" in res.stdout, res.stdout
    assert "differs: wear/rear_per_hour_m3_h" in res.stdout and "differs: per_rotation" not in res.stdout
    assert "  *" not in res.stdout.split("results:")[0]  # the summary itself is bit-identical
    tampered = tmp_path / "t.h5"
    shutil.copy(reduced_archive, tampered)
    with h5py.File(tampered, "r+") as f:
        _edit_json_attr(f["results/wear"], "rear_per_hour_m3_h", lambda v: v * (1.0 + 1e-12))
    res = cli("rerun", tampered)
    assert res.returncode == 1 and "differs: wear/rear_per_hour_m3_h" in res.stdout, res.stdout


@pytest.mark.slow
def test_rerun_sees_a_changed_wear_profile_of_a_multibody_archive(tmp_path, multibody_archive):
    tampered = tmp_path / "t.h5"
    shutil.copy(multibody_archive, tampered)
    with h5py.File(tampered, "r+") as f:
        f["results/wear/profile_work_rear"][0, 0] += 1e-9
    res = cli("rerun", tampered)
    assert res.returncode == 1 and "differs: wear/profile_work_rear" in res.stdout, res.stdout


@pytest.mark.slow
def test_compare_and_rerun_see_every_array_and_time_series_bit_for_bit(tmp_path, multibody_archive, reduced_archive):
    """"identical" and "bit-identical" are over every number the run computed: every dataset under /results
    and every time series under /observables, bit for bit (-0.0 is not 0.0). They compared the per-rotation
    and wear arrays only: a figure's table, an impact, the cage orbit or a time series changed in a copy, or
    a -0.0 for a 0.0, gave "results: identical" (exit 0) and a clean rerun."""
    edits = {"force_vs_theta": lambda d: d.__setitem__((0, 0), d[0, 0] + 100.0),
             "impacts/impulse_Ns": lambda d: d.__setitem__(0, d[0] * 2.0),
             "cage_orbit": lambda d: d.__setitem__((5, 1), d[5, 1] + 1e-6),
             "per_rotation/cage_slip": lambda d: d.__setitem__(0, d[0] + 1e-9),
             "observables/cage_slip/value": lambda d: d.__setitem__(3, d[3] + 1e-3),
             "observables/motion_pocket_force/value": lambda d: d.__setitem__((2, 3, 1), d[2, 3, 1] + 1.0)}
    for name, edit in edits.items():
        tampered = tmp_path / f"{name.replace('/', '_')}.h5"
        shutil.copy(multibody_archive, tampered)
        with h5py.File(tampered, "r+") as f:
            edit(f[name if name.startswith("observables") else f"results/{name}"])
        res = cli("compare", multibody_archive, tampered)
        assert res.returncode == 1 and f"differs: {name} (1 of " in res.stdout, res.stdout
        assert "results: differ" in res.stdout and "1 of 69 arrays and other numbers differ" in res.stdout
    res = cli("compare", multibody_archive, multibody_archive)
    assert res.returncode == 0 and "results: identical (20 summary numbers, 69 arrays" in res.stdout, res.stdout
    zero, signed = tmp_path / "zero.h5", tmp_path / "signed.h5"
    for path, value in ((zero, 0.0), (signed, -0.0)):
        shutil.copy(reduced_archive, path)
        with h5py.File(path, "r+") as f:
            f["results/per_rotation/I_acc"][0, 0] = value
    res = cli("compare", zero, signed)
    assert res.returncode == 1, res.stdout
    assert "differs: per_rotation/I_acc (1 of 1 values, largest |B - A| 0: the sign of a zero" in res.stdout
    with h5py.File(signed, "r+") as f:
        f["results/trace/l_r"][10] += 1e-9
    res = cli("rerun", signed)
    assert res.returncode == 1 and "differs: trace/l_r (1 of " in res.stdout, res.stdout
    assert "differs: per_rotation/I_acc" in res.stdout


@pytest.mark.slow
def test_show_gives_a_runnable_scenario_with_the_same_results(tmp_path, reduced_archive):
    res = cli("show", reduced_archive)
    assert res.returncode == 0
    toml = tmp_path / "again.toml"
    toml.write_text(res.stdout)
    assert cli("run", toml, "-o", tmp_path / "again.h5", "-q", "--no-plots").returncode == 0
    assert cli("compare", reduced_archive, tmp_path / "again.h5").returncode == 0


def test_run_on_an_archive_gets_a_hint(reduced_archive):
    assert_user_error(cli("run", reduced_archive), "archive", "rerun", "show")


def test_inspect_calls_the_automatic_steps_largest_roller_load_an_estimate(multibody_archive):
    """The automatic step's Q_max is Stribeck's a-priori 5W/Z plus the centrifugal load, not the run's largest
    roller load: `bearingsim inspect` calls it an estimate."""
    res = cli("inspect", multibody_archive)
    assert res.returncode == 0, res.stderr
    m = re.search(r"Palmgren, Q_max ≈ ([0-9]+) N, Stribeck's estimate 5W/Z \+ m omega_c\^2 r_p, not the run's roller "
                  r"loads; 2/omega_n", res.stdout)
    assert m, res.stdout


def test_inspect_of_a_reduced_archive_lists_its_operating_point_pass_and_wear(reduced_archive):
    """`bearingsim inspect` of a reduced-model archive listed the summary and the datasets only, not the
    operating point (cage and roller speeds, rolling velocity), the pass or the wear rates that the archive
    stores, with units, as attributes of /results/operating_point, /results/pass and /results/wear: it lists
    each group with its numbers and units, as the archive holds them."""
    from bearingsim.archive import group_attrs

    res = cli("inspect", reduced_archive)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    with h5py.File(reduced_archive, "r") as f:
        stored = {g: group_attrs(f["results"][g]) for g in ("operating_point", "pass", "wear")}
    for group, (values, units) in stored.items():
        (at,) = [i for i, ln in enumerate(lines) if ln.startswith(f"/results/{group}:")]
        shown = lines[at + 1:at + 1 + len(values)]
        assert [ln.split()[0] for ln in shown] == sorted(values), (group, shown)
        for k, line in zip(sorted(values), shown):
            if isinstance(values[k], float):
                assert line.split()[1:] == [f"{values[k]:.6g}", *units[k].split()], line
    assert any(ln.split()[:3] == ["omega_c_rad_s", f"{stored['operating_point'][0]['omega_c_rad_s']:.6g}", "rad/s"]
               for ln in lines), lines


def test_a_run_changed_by_set_says_so_beside_its_scenarios_name(tmp_path):
    """``bearingsim run scenarios/paper_3000rpm.toml --set operating.inner_ring_speed_rpm=500`` titled its
    figures "paper_3000rpm: reduced model (event), 500 rpm forward, ...": the name of a file that runs at 3000
    rpm beside the 500 rpm that ran. The title says what --set changed beside the name, also when the
    figures are drawn again from the archive."""
    res = cli("run", SCENARIOS / "paper_3000rpm.toml", "--set", "operating.inner_ring_speed_rpm=500", "-o",
              tmp_path / "a.h5", "-q", "--no-plots")
    assert res.returncode == 0, res.stderr
    title = bearingsim.load(tmp_path / "a.h5").plot_pass().axes[0].get_title()
    assert title.startswith("paper_3000rpm (--set operating.inner_ring_speed_rpm=500): reduced model (event), "
                            "500 rpm forward"), title
