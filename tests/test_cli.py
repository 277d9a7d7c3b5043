"""CLI contract: user errors are one line on stderr, exit code 2, no traceback, no archive."""
import os
import subprocess
import sys

import pytest

from . import forked_cli
from .conftest import SCENARIOS
from .forked_cli import pythonpath as _path


def bearingsim(*args, cwd=None, fresh_interpreter=False):
    """``bearingsim ARGS`` run to its end (:func:`tests.forked_cli.run`)."""
    return forked_cli.run(args, cwd=cwd, fresh_interpreter=fresh_interpreter)


def assert_user_error(res, *words):
    assert res.returncode == 2, res.stderr
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, res.stderr
    assert "Traceback" not in res.stderr
    for w in words:
        assert w in lines[0], lines[0]


@pytest.mark.parametrize(
    "setting, key",
    [
        ("bearing.roller_mass_kg=-0.013", "bearing.roller_mass_kg"),
        ("contact.restitution=2", "contact.restitution"),
        ("bearing.no_such_key=1", "bearing.no_such_key"),
        ("operating.inner_ring_speed_rpm=nan", "operating.inner_ring_speed_rpm"),
        ("bearing.roller_count=0", "bearing.roller_count"),
    ],
)
@pytest.mark.slow
def test_bad_override_exits_2_naming_key_and_writes_nothing(tmp_path, setting, key):
    out = tmp_path / "r.h5"
    res = bearingsim("run", SCENARIOS / "paper_3000rpm.toml", "-o", out, "--set", setting)
    assert_user_error(res, key)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
@pytest.mark.parametrize("scenario, sets, head", [
    ("paper_3000rpm", ["reduced.method=euler", "numerics.dt_s=1e-10"],
     "with reduced.method=euler and numerics.dt_s=1e-10: numerics.dt_s: 1e-10 s needs"),
    ("multibody_3000rpm", ["numerics.warmup_rotations=0", "contact.restitution=0.5"],
     "with numerics.warmup_rotations=0: numerics.warmup_rotations: 0 with the multibody model"),
])
def test_a_refused_run_names_the_overrides_it_is_about(tmp_path, scenario, sets, head):
    """What the run refuses before its first step (the model's step, the warm-up) blamed the file
    ("paper_3000rpm.toml: numerics.dt_s: 1e-10 s needs ...") for values --set gave: the line names them, as
    a refusal of the scenario's values does; the dry run refuses the same."""
    path = SCENARIOS / f"{scenario}.toml"
    for extra in (["--dry-run"], ["-o", tmp_path / "r.h5"]):
        res = bearingsim("run", path, *extra, *[a for s in sets for a in ("--set", s)])
        assert_user_error(res, f"{path} {head}")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_wrong_type_in_file_names_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((SCENARIOS / "paper_3000rpm.toml").read_text().replace("rotations = 1", 'rotations = "one"'))
    res = bearingsim("run", bad, "-o", tmp_path / "x.h5")
    assert_user_error(res, "numerics.rotations", str(bad))
    assert not (tmp_path / "x.h5").exists()


@pytest.mark.slow
def test_missing_scenario_file(tmp_path):
    res = bearingsim("run", tmp_path / "nope.toml")
    assert_user_error(res, "nope.toml", "not found")


@pytest.mark.slow
def test_unwritable_output_names_the_file(tmp_path):
    blocker = tmp_path / "blocker"
    blocker.write_text("")
    res = bearingsim("run", SCENARIOS / "paper_3000rpm.toml", "-o", blocker / "r.h5")
    assert_user_error(res, "blocker")


@pytest.fixture(scope="module")
def archives_to_write_from(tmp_path_factory):
    """A reduced archive and a short multibody one (rigid raceways, 1 rotation: wear needs its profile)."""
    folder = tmp_path_factory.mktemp("sources")
    reduced, multibody = folder / "r.h5", folder / "m.h5"
    res = bearingsim("run", SCENARIOS / "paper_3000rpm.toml", "-o", reduced, "--no-plots", "-q")
    assert res.returncode == 0, res.stderr
    res = bearingsim("run", SCENARIOS / "wear_test_6000rpm.toml", "-o", multibody, "--no-plots", "-q",
                     "--set", "numerics.rotations=1", "--set", "multibody.raceway_contact=rigid")
    assert res.returncode == 0, res.stderr
    return {"R": reduced, "M": multibody}


#: every command that writes into a folder, its output given as {out} (a folder) or {out}/NAME (a file)
FOLDER_WRITERS = {
    "run": ["run", SCENARIOS / "paper_3000rpm.toml", "-o", "{out}/x.h5"],
    "run-no-plots": ["run", SCENARIOS / "paper_3000rpm.toml", "-o", "{out}/x.h5", "--no-plots"],
    "rerun": ["rerun", "{R}", "-o", "{out}/x.h5"],
    "plot": ["plot", "{R}", "-o", "{out}"],
    "report": ["report", "{R}", "-o", "{out}/x.html"],
    "animate": ["animate", "{M}", "-o", "{out}/x.gif"],
    "sweep": ["sweep", SCENARIOS / "paper_3000rpm.toml", "--param", "operating.inner_ring_speed_rpm=1000:2000:2",
              "-o", "{out}"],
    "crosscheck": ["crosscheck", SCENARIOS / "multibody_3000rpm.toml", "-o", "{out}"],
    "validate": ["validate", "-o", "{out}"],
    "sensitivity": ["sensitivity", SCENARIOS / "paper_3000rpm.toml", "-o", "{out}"],
    "uncertainty": ["uncertainty", SCENARIOS / "paper_3000rpm.toml", "--samples", "4", "-o", "{out}"],
    "life": ["life", SCENARIOS / "wear_test_6000rpm.toml", "--limit", "depth=0.1mm", "-o", "{out}"],
    "wear": ["wear", "{M}", "--hours", "1", "-o", "{out}"],
    "bench-map": ["bench", "--map", "-o", "{out}"],
    "bench-fast-scene": ["bench", "--fast-scene", "-o", "{out}"],
}


#: commands of FOLDER_WRITERS without -q: bench (a source checkout's tool, its printed tables are what it is for)
NOT_QUIET = ("bench-map", "bench-fast-scene")


def test_every_command_that_writes_files_takes_quiet():
    """`plot ARCHIVE -o DIR -q` failed with "unrecognized arguments: -q" (so did `rerun` and `wear`), while
    run, report, animate, sweep and the studies take it: every command that writes files takes -q."""
    from bearingsim.cli import build_parser

    parser = build_parser()
    for command, args in FOLDER_WRITERS.items():
        if command not in NOT_QUIET:
            assert parser.parse_args([str(a) for a in args] + ["-q"]).quiet is True, command


@pytest.mark.slow
@pytest.mark.parametrize("command", [
    ["plot", "{R}", "-o", "{out}"],
    ["wear", "{M}", "--hours", "1", "-o", "{out}"],
    ["rerun", "{R}", "-o", "{out}/again.h5"],
])
def test_quiet_prints_nothing_on_success_and_writes_the_files(tmp_path, archives_to_write_from, command):
    """-q as on `run`: the files written, nothing printed (`rerun`: bit-identical, exit 0)."""
    out = tmp_path / "out"
    res = bearingsim(*[str(a).format(out=out, **archives_to_write_from) for a in command], "-q")
    assert res.returncode == 0 and res.stdout == "" and res.stderr == "", (res.stdout, res.stderr)
    written = sorted(p.name for p in out.iterdir())
    assert written == {"plot": ["r_pass.png"], "wear": ["m_wear_profile.png", "m_wear_volume.png"],
                       "rerun": ["again.h5"]}[command[0]]


@pytest.mark.slow
@pytest.mark.parametrize("below", [False, True], ids=["file-is-the-folder", "file-above-the-folder"])
@pytest.mark.parametrize("command", list(FOLDER_WRITERS))
def test_a_file_where_the_output_folder_should_be_is_named_alike_by_every_command(
        tmp_path, archives_to_write_from, command, below):
    """A file where the output's folder (or one of its parents) should be: every command that writes
    into a folder refuses it in the same words, naming the file in the way, in one line, exit 2, and
    creates nothing. sweep, plot, rerun and the studies said "not writable (File exists)" or "(Not a
    directory)", run "cannot check the figure path", without naming the file."""
    import re

    (tmp_path / "blocker").write_text("my notes\n")
    out = tmp_path / "blocker" / "sub" if below else tmp_path / "blocker"
    args = [str(a).format(out=out, **archives_to_write_from) for a in FOLDER_WRITERS[command]]
    res = bearingsim(*args, cwd=tmp_path)
    assert_user_error(res)
    line = res.stderr.strip()
    blocking = f"{tmp_path / 'blocker'} is not a folder" if below else "it is a file"  # the folder itself: named once
    assert re.fullmatch(rf"bearingsim: error: {re.escape(str(out))}: cannot create the (output folder|\w+'s folder) "
                        rf"\({re.escape(blocking)}\)", line), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blocker"]
    assert (tmp_path / "blocker").read_text() == "my notes\n"


def test_help_names_the_default_of_every_folder_command_and_of_the_sensitivity_step():
    """``-o`` of validate, bench, crosscheck, sweep, sensitivity and uncertainty said "output folder" and
    not which (run, plot, wear, life and report name theirs); ``sensitivity --step`` did not say 10 %."""
    import argparse

    from bearingsim.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    for command in ("validate", "bench", "crosscheck", "sweep", "sensitivity", "uncertainty"):
        out = next(a for a in sub.choices[command]._actions if a.dest == "output")
        assert f"default {out.default}" in out.help, (command, out.help)
    step = next(a for a in sub.choices["sensitivity"]._actions if a.dest == "step")
    assert f"default {step.default}%" in step.help, step.help


def test_shows_help_says_a_sweep_index_gives_its_base_scenario_as_toml():
    """`show` of a sweep.h5 prints the base scenario it stores as runnable TOML (docs/commands.md); its help
    said "for a sweep.h5, what it holds as TOML comments"."""
    import argparse

    from bearingsim.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    text = " ".join(next(c.help for c in sub._choices_actions if c.dest == "show").split())
    assert "for a sweep.h5, what it holds as TOML comments" not in text, text
    assert "of a sweep.h5, its base scenario with the sweep's --set" in text, text


@pytest.mark.slow
@pytest.mark.parametrize("command", ["inspect", "show"])
def test_help_of_inspect_and_show_names_every_file_they_read(command):
    """``inspect`` and ``show`` read an archive and every index file of ``cli._describe_index`` (sweep.h5,
    map.h5, crosscheck.h5 and the study tables); their help named only an archive, sweep.h5 and
    crosscheck.h5."""
    kinds = ("archive", "sweep.h5", "map.h5", "crosscheck.h5", "sensitivity.h5", "uncertainty.h5", "life.h5")
    for args in ([command, "--help"], ["--help"]):
        res = bearingsim(*args)
        assert res.returncode == 0, res.stderr
        text = " ".join(res.stdout.split())
        if args == ["--help"]:  # the command's line in the list of commands
            text = text[text.index(f" {command} "):]
            text = text[:text.index(" plot ")] if command == "show" else text[:text.index(" show ")]
        missing = [k for k in kinds if k not in text]
        assert not missing, (args, missing, text)


@pytest.mark.slow
def test_a_count_of_one_is_singular(tmp_path):
    """Printed counts that can be one read "1 case", "1 rotation", "1 stage", ...: a one-case sweep printed
    "1 cases", a one-stage life "running 1 rotations" and "in 1 stages", a cross-check at one speed
    "1 speed(s) ... 1 rotations each, 1 process(es)"."""
    import re

    from bearingsim.wording import counted

    assert (counted(1, "case"), counted(2, "case"), counted(0, "case")) == ("1 case", "2 cases", "0 cases")
    assert counted(1, "process", "processes") == "1 process" and counted(3, "process", "processes") == "3 processes"
    paper, mb = SCENARIOS / "paper_3000rpm.toml", SCENARIOS / "wear_test_6000rpm.toml"
    rigid = ["--set", "multibody.raceway_contact=rigid"]
    commands = [
        ["sweep", paper, "--param", "operating.inner_ring_speed_rpm=1000", "-o", tmp_path / "sw", "-j", "1"],
        ["table", tmp_path / "sw"],
        ["inspect", tmp_path / "sw" / "sweep.h5"],
        ["inspect", tmp_path / "sw" / "map.h5"],
        ["sensitivity", paper, "--keys", "contact.restitution", "-o", tmp_path / "se", "-j", "1"],
        ["life", mb, "--limit", "depth=1mm", "--stages", "1", "--rotations", "1", *rigid, "-o", tmp_path / "li"],
        ["crosscheck", SCENARIOS / "multibody_3000rpm.toml", "--speeds", "3000", "--rotations", "1", *rigid,
         "-o", tmp_path / "cc", "-j", "1"],
    ]
    plural_of_one = re.compile(r"(?<![\d.])1 (cases|rotations|stages|keys|runs|values|speeds|rows|cells|"
                               r"process\(es\)|speed\(s\))(?!\w)")
    for args in commands:
        res = bearingsim(*args)
        assert res.returncode == 0, (args, res.stderr)
        found = plural_of_one.findall(res.stdout + res.stderr)
        assert not found, (args[0], found, res.stdout + res.stderr)
    res = bearingsim(*commands[0])  # again: every case cached
    assert "1 case: 0 done, 1 cached" in res.stdout, res.stdout
    res = bearingsim(*commands[-1])
    assert "1 speed x 5 rungs, 1 warm-up (rung 3: 2) + 1 rotation each, 1 process," in res.stdout, res.stdout


@pytest.mark.slow
def test_inspect_refuses_foreign_file(tmp_path):
    f = tmp_path / "x.h5"
    f.write_bytes(b"\x00" * 100)
    assert_user_error(bearingsim("inspect", f), "x.h5")


@pytest.mark.slow
def test_a_new_run_over_an_archive_removes_the_figures_it_does_not_write(tmp_path, archives_to_write_from):
    """`run -o X.h5 --force` over a multibody run's archive left X_forces.png, X_impulses.png, ... beside
    the reduced run's archive, and a rerun -o (which draws none) left every figure of the run it replaced.
    Once the new archive is written, the figures of any model at that stem that it does not write are
    removed: only figures bearingsim drew so named (regular PNG files with its mark), nothing else (a user's
    picture of such a name included); a run that fails first leaves them all."""
    import shutil

    from bearingsim.plotting import figure, figure_png

    png = figure_png(figure())  # an earlier run's figure
    users = tmp_path / "X_impulses.png"
    figure().savefig(users, format="png")  # a user's picture: a PNG without bearingsim's mark
    shutil.copy(archives_to_write_from["M"], tmp_path / "X.h5")
    for name in ("forces", "wear"):
        (tmp_path / f"X_{name}.png").write_bytes(png)
    (tmp_path / "elsewhere.png").write_bytes(png)
    (tmp_path / "X_orbit.png").symlink_to(tmp_path / "elsewhere.png")  # a link: the user's
    kept = {"X_notes.png": png, "X_wear.png.bak": png, "Y_forces.png": png, "X_pass.txt": b"mine",
            users.name: users.read_bytes()}
    for name, data in kept.items():
        (tmp_path / name).write_bytes(data)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    # a run that fails after it started (exit 3, no archive): the old archive and figures as they were
    res = bearingsim("run", SCENARIOS / "paper_3000rpm.toml", "-o", tmp_path / "X.h5", "--force",
                     "--set", "reduced.load_zone_half_angle_deg=179.9")
    assert res.returncode == 3, res.stderr
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    res = bearingsim("run", SCENARIOS / "paper_3000rpm.toml", "-o", tmp_path / "X.h5", "--force", "-q")
    assert res.returncode == 0, res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["X.h5", "X_pass.png", "X_orbit.png", "elsewhere.png", *kept])
    assert all((tmp_path / name).read_bytes() == data for name, data in kept.items())
    res = bearingsim("rerun", tmp_path / "X.h5", "-o", tmp_path / "X.h5")  # writes no figures
    assert res.returncode == 0, res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["X.h5", "X_orbit.png", "elsewhere.png", *kept])


#: every command that reads an archive, given a scenario file {S} (compare: second, then first)
ARCHIVE_READERS = {
    "rerun": ["rerun", "{S}"], "inspect": ["inspect", "{S}"], "plot": ["plot", "{S}"],
    "animate": ["animate", "{S}", "-o", "{tmp}/a.gif"], "compare": ["compare", "{S}", "{S}"],
    "wear": ["wear", "{S}", "--hours", "1"], "report": ["report", "{S}", "-o", "{tmp}/r.html"],
    "table": ["table", "{S}"],
}


@pytest.mark.parametrize("named", [".toml", ".txt"])
@pytest.mark.parametrize("command", list(ARCHIVE_READERS))
def test_a_scenario_file_given_for_an_archive_names_the_commands_that_read_it(tmp_path, command, named):
    """The commands that read an archive said "not an HDF5 file (truncated, or not a bearingsim archive)"
    of a scenario file; they say what it is and which commands read it, as 'run x.h5' hints the other way.
    A scenario saved under another name is told by its TOML (and 'show' resolves it)."""
    scenario = tmp_path / f"mine{named}"
    scenario.write_text((SCENARIOS / "paper_3000rpm.toml").read_text())
    args = [a.format(S=scenario, tmp=tmp_path) for a in ARCHIVE_READERS[command]]
    res = bearingsim(*args)
    assert_user_error(res, f"{scenario}: is a scenario file, not an archive; 'bearingsim run {scenario}' runs it",
                      f"'bearingsim show {scenario}' prints it resolved")
    assert sorted(p.name for p in tmp_path.iterdir()) == [scenario.name]
    if command == "compare":
        res = bearingsim("compare", SCENARIOS / "paper_3000rpm.toml", tmp_path / "nope.h5")
        assert_user_error(res, "paper_3000rpm.toml: is a scenario file")
    if named == ".txt" and command == "inspect":  # what the hint says works
        res = bearingsim("show", scenario)
        assert res.returncode == 0 and res.stdout.startswith(f"# resolved from {scenario}"), res.stderr
    if named == ".txt" and command == "table":  # any other text file keeps the archive reader's line
        other = tmp_path / "notes.txt"
        other.write_text("schema = 1\n")
        assert_user_error(bearingsim("inspect", other), "notes.txt: not an HDF5 file")


@pytest.mark.parametrize("name, head", [("sweep.csv", "case,operating.inner_ring_speed_rpm,status\n"),
                                        ("crosscheck.csv", "rpm,rung,scene,relaxed\n"),
                                        ("rig_idec_vs_speed.csv", "rpm,rotations,pocket0\n")])
@pytest.mark.parametrize("command", ["table", "inspect", "plot", "show", "rerun", "report"])
def test_a_csv_table_given_for_an_archive_names_its_folder(tmp_path, name, head, command):
    """``bearingsim table DIR/sweep.csv`` (or inspect, plot, show, rerun of a study's CSV table) said "not an
    HDF5 file (truncated, or not a bearingsim archive)" of a table bearingsim wrote; it says what it is and
    which command reads its folder. A CSV of that name that bearingsim did not write keeps the old line."""
    table = tmp_path / name
    table.write_text(head)
    reader = "report" if command == "report" else "table"  # report: "(no sweep.h5, ... in it)" of a file
    assert_user_error(bearingsim(command, table), f"{table}: a table bearingsim wrote (CSV), not an archive",
                      f"'bearingsim {reader} {tmp_path}' ")
    table.write_text("x,y\n")
    assert_user_error(bearingsim(command, table), f"{table}: not a" if reader == "report" else f"{table}: not an HDF5")


@pytest.mark.slow
def test_a_sweep_file_given_for_an_archive_says_what_it_is(tmp_path):
    """A sweep's sweep.h5 or map.h5 given to a command that reads a run's archive (rerun, compare, wear,
    animate, table of the map) was "HDF5 file but not a bearingsim archive (no /bearingsim group)", of a
    file bearingsim wrote; the line says which of its files it is and names the commands that read it."""
    res = bearingsim("sweep", SCENARIOS / "paper_3000rpm.toml", "--param", "operating.inner_ring_speed_rpm=1000,2000",
                     "--param", "bearing.pocket_clearance_mm=0.1,0.2", "-q", "--no-plots", "-o", tmp_path / "sw")
    assert res.returncode == 0, res.stderr
    index, grid = tmp_path / "sw" / "sweep.h5", tmp_path / "sw" / "map.h5"
    for args, path, what in ((["rerun", grid], grid, "a sweep's map"), (["compare", index, index], index, "a sweep's index"),
                             (["wear", grid, "--hours", "1"], grid, "a sweep's map"),
                             (["animate", index, "-o", tmp_path / "a.gif"], index, "a sweep's index"),
                             (["table", grid], grid, "a sweep's map")):
        assert_user_error(bearingsim(*args), f"{path}: {what} written by bearingsim, not a run archive",
                          f"'bearingsim inspect {path}' says what it holds", f"'bearingsim table {path.parent}'")
    assert not (tmp_path / "a.gif").exists()
    assert bearingsim("inspect", grid).returncode == 0 and bearingsim("table", tmp_path / "sw").returncode == 0


@pytest.mark.slow
def test_a_sweep_folder_given_for_an_archive_sends_to_case_archives_only_when_there_are_some(tmp_path):
    """A sweep folder given for an archive said "its cases' archives are in DIR/cases" of a reduced-model sweep,
    whose cases keep no archive by default: there is no DIR/cases. The line says so, and names the folder
    where the cases did keep their archives (--archives all)."""
    for archives, kept in (([], False), (["--archives", "all"], True)):
        folder = tmp_path / ("kept" if kept else "none")
        res = bearingsim("sweep", SCENARIOS / "paper_3000rpm.toml", "--param", "operating.inner_ring_speed_rpm=1000,2000",
                         *archives, "-q", "--no-plots", "-o", folder)
        assert res.returncode == 0, res.stderr
        assert (folder / "cases").is_dir() == kept
        res = bearingsim("show", folder)  # a command that reads an archive (inspect lists the folder's files)
        assert_user_error(res, f"{folder}: is a sweep or study folder, not an archive")
        if kept:
            assert f"its cases' archives are in {folder / 'cases'}" in res.stderr
        else:
            assert "cases' archives are in" not in res.stderr and "its cases kept no archives" in res.stderr


@pytest.mark.slow
def test_reduced_run_writes_archive_with_public_names_and_figure(tmp_path):
    """`bearingsim run` on a paper scenario writes the archive (public names of issue 2, a unit on every
    dataset, the resolved scenario) and the Fig. 8 analog PNG; `inspect` reads it back; the same scenario
    run twice gives the same numbers (determinism)."""
    import h5py
    import numpy as np

    from bearingsim import archive

    out = tmp_path / "p.h5"
    res = bearingsim("run", SCENARIOS / "paper_500rpm.toml", "-o", out, "--set", "numerics.rotations=3")
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "p_pass.png").stat().st_size > 10_000
    with h5py.File(out, "r") as f:
        assert f["results/per_rotation/I_dec"].shape == (3, 1)
        assert f["results/per_rotation/I_acc"].shape == (3, 1)
        for col in ("time_s", "theta_deg", "approach_speed_m_s", "impulse_Ns", "pocket", "face"):
            assert col in f["results/impacts"]
        summary, units = archive.group_attrs(f["results/summary"])
        for key in ("I_dec_mean_Ns", "I_dec_std_Ns", "I_acc_mean_Ns", "I_acc_std_Ns",
                    "first_impact_speed_m_s", "first_impact_energy_J"):
            assert np.isfinite(summary[key]) and key in units
        missing = []
        f.visititems(lambda n, o: missing.append(n) if isinstance(o, h5py.Dataset)
                     and n not in ("scenario", "bearingsim/notes")  # texts, not quantities
                     and not n.startswith("h5md") and "unit" not in o.attrs else None)
        assert missing == []
        assert 'inner_ring_speed_rpm = 500' in f["scenario"][()].decode()
        first = f["results/per_rotation/I_dec"][()]
    res = bearingsim("inspect", out)
    assert res.returncode == 0 and "I_dec_mean_Ns" in res.stdout
    out2 = tmp_path / "q.h5"
    assert bearingsim("run", SCENARIOS / "paper_500rpm.toml", "-o", out2, "--set", "numerics.rotations=3",
                      "--no-plots", "-q").returncode == 0
    with h5py.File(out2, "r") as f:
        assert np.array_equal(f["results/per_rotation/I_dec"][()], first)


@pytest.mark.slow
def test_inspect_into_a_pipe_closed_early_stops_quietly(tmp_path):
    """``bearingsim inspect x.h5 | head -1``: once the reader has gone, the command stops with exit 0
    and nothing on stderr (no "Broken pipe" error, no traceback)."""
    import os

    import numpy as np

    from bearingsim import archive
    from bearingsim.datatypes import AttrGroup, NamedArray
    from bearingsim.reduced import ReducedResult
    from bearingsim.scenario import load_scenario

    from .conftest import started

    keys = {f"quantity_{i:05d}_Ns": float(i) for i in range(6000)}  # a 260 kB listing: more than a pipe holds
    res = ReducedResult(load_scenario(SCENARIOS / "paper_3000rpm.toml"),
                        {"results/per_rotation/I_dec": NamedArray(np.ones((3, 2)), "N s")},
                        {"results/summary": AttrGroup(keys, {k: "N s" for k in keys})})
    path = archive.write(res, tmp_path / "big.h5")
    r, w = os.pipe()
    try:
        import fcntl

        fcntl.fcntl(w, fcntl.F_SETPIPE_SZ, 4096)  # the smallest pipe: the writer is sure to meet the closed end
    except (ImportError, AttributeError, OSError):
        pass
    with open(r, "rb") as reader, open(w, "wb") as writer:
        with started([sys.executable, "-m", "bearingsim", "inspect", path], stdout=writer,
                     stderr=subprocess.PIPE) as proc:
            writer.close()  # the child holds the only write end
            first = reader.readline()
            reader.close()  # what `head -1` does after its line
            _, err = proc.communicate(timeout=120)
    assert first.startswith(f"{path}: bearingsim archive".encode()), first
    assert (proc.returncode, err.decode()) == (0, "")


@pytest.mark.slow
def test_compare_keeps_its_verdict_when_the_reader_of_its_output_has_gone(tmp_path, base_reduced):
    """``compare a b | head -1``: exit 1 says "the results differ" even when the pipe breaks while the
    comparison prints (as it did at random: exit 0, "identical"). The reader is gone before the command
    starts, so the pipe breaks at its first write, every time."""
    import bearingsim
    from bearingsim.scenario import resolve

    from .conftest import started

    paths = []
    for rpm in (1000.0, 2000.0, 2000.0):
        sc = resolve({**base_reduced, "operating": {**base_reduced["operating"], "inner_ring_speed_rpm": rpm}})
        paths.append(bearingsim.run(sc).save(tmp_path / f"a{len(paths)}.h5"))
    for archives, verdict in ((paths[:2], 1), (paths[1:], 0), (paths, 1)):
        r, w = os.pipe()
        os.close(r)
        with open(w, "wb") as writer, started([sys.executable, "-m", "bearingsim", "compare", *archives],
                                              stdout=writer, stderr=subprocess.PIPE) as proc:
            writer.close()
            _, err = proc.communicate(timeout=120)
        assert (proc.returncode, err.decode()) == (verdict, ""), archives


@pytest.mark.slow
@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_stdout_on_a_full_device_is_named_in_the_error(tmp_path):
    """``bearingsim show s.toml > /dev/full``: exit 2 with one line naming standard output (it said
    "bearingsim: error: bearingsim: No space left on device")."""
    from .conftest import ROOT, started

    env = {**os.environ, "PYTHONPATH": _path()}
    with open("/dev/full", "w") as full, started([sys.executable, "-m", "bearingsim", "show",
                                                 SCENARIOS / "paper_3000rpm.toml"],
                                                env=env, stdout=full, stderr=subprocess.PIPE, text=True) as proc:
        _, err = proc.communicate(timeout=120)
    assert proc.returncode == 2 and err.count("\n") == 1, err
    assert err.startswith("bearingsim: error: cannot write to standard output (") and err.endswith(")\n"), err


@pytest.mark.slow
@pytest.mark.parametrize("command", ["show", "inspect"])
def test_a_non_ascii_name_under_an_ascii_locale_is_no_traceback(tmp_path, base_reduced, command):
    """Issue 30, Low: under a C locale (stdout ASCII, strict) a scenario named "café" made ``show`` and
    ``inspect`` die of UnicodeEncodeError. ``show`` writes its TOML as UTF-8 (what a TOML file is:
    ``show a.h5 > s.toml`` runs again); other output escapes what the terminal cannot show."""
    import tomllib

    import bearingsim
    from bearingsim.scenario import resolve

    from .conftest import ROOT, started

    path = bearingsim.run(resolve({**base_reduced, "name": "café"})).save(tmp_path / "a.h5")
    env = {**os.environ, "PYTHONPATH": _path(), "LC_ALL": "C", "PYTHONIOENCODING": "ascii",
           "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}
    with started([sys.executable, "-m", "bearingsim", command, path], env=env, stdout=subprocess.PIPE,
                 stderr=subprocess.PIPE) as proc:
        out, err = proc.communicate(timeout=120)
    assert (proc.returncode, err.decode("ascii", "replace")) == (0, "")
    if command == "show":
        assert tomllib.loads(out.decode("utf-8"))["name"] == "café"
    else:
        assert "scenario caf\\xe9" in out.decode("ascii")


@pytest.mark.slow
@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_stdout_on_a_full_device_after_the_archive_is_not_exit_2(tmp_path):
    """Issue 30, Low: ``bearingsim run ... > /dev/full`` wrote its archive, then exited 2 ("bad input,
    no archive") with "bearingsim: error: bearingsim: No space left on device". Now exit 0 with one line
    saying standard output failed and the archive is complete."""
    from .conftest import ROOT, started

    out = tmp_path / "out.h5"
    env = {**os.environ, "PYTHONPATH": _path()}
    with open("/dev/full", "w") as full, started([sys.executable, "-m", "bearingsim", "run",
                                                 SCENARIOS / "paper_3000rpm.toml", "-o", out, "--no-plots"],
                                                env=env, stdout=full, stderr=subprocess.PIPE, text=True) as proc:
        _, err = proc.communicate(timeout=120)
    lines = err.strip().splitlines()
    assert proc.returncode == 0 and len(lines) == 1, err
    assert "standard output" in lines[0] and f"the archive {out} is complete" in lines[0]
    assert out.is_file()


@pytest.mark.slow
def test_a_study_folder_given_to_plot_names_the_studys_own_table(tmp_path):
    """`bearingsim plot DIR` of a sensitivity, uncertainty or life folder said "'bearingsim plot DIR/sweep.h5'
    draws its figures", which draws only the cases' overview (sweep_cases.png): the tornado, the Sobol figure and
    life.png come from sensitivity.h5, uncertainty.h5 and life.h5. The line names the study's table, which
    draws its figure; a sweep folder's still names its sweep.h5."""
    import numpy as np

    from bearingsim import archive
    from bearingsim.studies import crosscheck, sensitivity, uncertainty
    from bearingsim.studies import life as life_study
    from bearingsim.tables import STUDY_TABLES, studies_of

    paper = SCENARIOS / "paper_6000rpm.toml"
    runs = {"sensitivity": ["sensitivity", paper, "--keys", "contact.restitution"],
            "uncertainty": ["uncertainty", paper, "--keys", "contact.restitution", "--samples", "2"],
            "sweep": ["sweep", paper, "--param", "contact.restitution=0.7,0.8", "--archives", "all"]}
    for kind, argv in runs.items():
        folder = tmp_path / kind
        res = bearingsim(*argv, "-q", "-j", "1", "-o", folder)
        assert res.returncode == 0, res.stderr
        table = folder / ("sweep.h5" if kind == "sweep" else f"{kind}.h5")
        said = f"'bearingsim plot {table}' draws " + ("its figures" if kind == "sweep" else "the study's figure")
        assert_user_error(bearingsim("plot", folder), f"{folder}: is a sweep or study folder, not an archive", said,
                          f"its cases' archives are in {folder / 'cases'}")
        if kind != "sweep":
            assert "sweep.h5" not in bearingsim("plot", folder).stderr
            res = bearingsim("plot", table, "-o", tmp_path / "again")
            assert res.returncode == 0 and res.stdout == f"wrote {tmp_path / 'again' / f'{kind}.png'}\n", res
    life = tmp_path / "life"  # a life study's table (its stages are multibody runs: not run here)
    life.mkdir()
    (life / "sweep.h5").write_bytes(b"")
    archive.write_table_file(life / "life.h5", {"stage": np.arange(2)}, {}, {"format": life_study.LIFE_FORMAT})
    res = bearingsim("show", life)
    assert_user_error(res, f"'bearingsim plot {life / 'life.h5'}' draws the study's figure")
    assert "sweep.h5" not in res.stderr
    # the archive finds the tables by their format (it does not import the studies): as bearingsim.tables does
    formats = (life_study.LIFE_FORMAT, crosscheck.INDEX_FORMAT, sensitivity.INDEX_FORMAT, uncertainty.INDEX_FORMAT)
    assert sorted(archive.STUDY_TABLE_FORMATS) == sorted(f.rstrip("0123456789. ") for f in formats)
    assert len(STUDY_TABLES) == len(formats) + 1  # and validate's table, a CSV: its folder names its sweep.h5
    for folder in (*(tmp_path / kind for kind in runs), life):
        assert archive._study_tables(folder) == [t for _, t in studies_of(folder)], folder


def test_minus_j_0_is_refused_in_the_same_words_by_every_command_that_takes_it(tmp_path, capsys):
    """sweep said "--jobs: must be at least 1 (got 0)", crosscheck, validate, sensitivity and uncertainty
    "-j 0: give at least 1 worker process"."""
    from bearingsim import cli

    paper, multibody = str(SCENARIOS / "paper_3000rpm.toml"), str(SCENARIOS / "multibody_3000rpm.toml")
    for argv in (["sweep", paper, "--param", "operating.inner_ring_speed_rpm=1000"], ["crosscheck", multibody],
                 ["validate"], ["sensitivity", paper], ["uncertainty", paper, "--samples", "2"]):
        assert cli.main([*argv, "-j", "0", "-o", str(tmp_path / "o")]) == 2, argv
        err = capsys.readouterr().err
        assert err.endswith("error: -j 0: give at least 1 worker process\n"), (argv, err)
    assert list(tmp_path.iterdir()) == []


def test_rerun_force_without_output_is_refused(tmp_path, base_reduced, capsys):
    """`rerun --force` ("with -o: replace an archive of a different scenario there") was accepted without -o
    and did nothing; it is refused in one line before the archive is read or run."""
    import bearingsim
    from bearingsim import cli
    from bearingsim.scenario import resolve

    archive = tmp_path / "a.h5"
    bearingsim.run(resolve(base_reduced)).save(archive)
    before = archive.read_bytes()
    assert cli.main(["rerun", str(archive), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--force applies with -o" in err, err
    assert archive.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["a.h5"]


@pytest.mark.slow
def test_rerun_prints_the_reruns_notes_as_run_does(tmp_path):
    """`rerun` printed no note of the run it repeats, though the reliability page said `run` and `rerun` print
    them: with and without -o it prints the rerun's notes on stderr as `run` does, -q none."""
    archive = tmp_path / "a.h5"
    res = bearingsim("run", SCENARIOS / "multibody_3000rpm.toml", "--set", "numerics.rotations=3", "-o", archive,
                     "--no-plots")
    assert res.returncode == 0, res.stderr
    notes = [ln for ln in res.stderr.splitlines() if ln.startswith("bearingsim: note: ")]
    assert any("warm-up could not be judged" in n for n in notes), res.stderr
    for extra in ([], ["-o", tmp_path / "b.h5"]):
        res = bearingsim("rerun", archive, *extra)
        assert res.returncode == 0 and "bit-identical" in res.stdout, res.stdout + res.stderr
        assert [ln for ln in res.stderr.splitlines() if ln.startswith("bearingsim: note: ")] == notes, res.stderr
    res = bearingsim("rerun", "-q", archive, "-o", tmp_path / "b.h5")
    assert res.returncode == 0 and res.stderr == "", res.stderr


def test_life_refuses_its_rotations_given_twice_as_crosscheck_does(tmp_path, capsys):
    """`life --rotations 1 --set numerics.rotations=2` ran 1 rotation per stage and dropped the --set without
    a word; crosscheck refused the same pair. Refused in one line before any stage runs."""
    from bearingsim import cli

    mb = str(SCENARIOS / "multibody_3000rpm.toml")
    argv = ["life", mb, "--limit", "depth=1mm", "--stages", "1", "--rotations", "1", "-o", str(tmp_path / "li")]
    assert cli.main([*argv, "--set", "numerics.rotations=2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--rotations 1 and --set numerics.rotations=2" in err, err
    assert list(tmp_path.iterdir()) == []


def test_a_sweep_file_given_for_a_scenario_or_an_archive_says_what_it_is(tmp_path):
    """A sweep file given to run, show or crosscheck was "schema_version: missing"; given to inspect or rerun,
    "is a scenario file ... 'bearingsim run FILE' runs it", which run then refused. Each names the sweep."""
    f = SCENARIOS / "sweeps" / "speed_zip_and_extras.toml"
    for args in (["run", f, "-o", tmp_path / "a.h5"], ["show", f], ["crosscheck", f, "-o", tmp_path / "cc"],
                 ["inspect", f], ["rerun", f]):
        assert_user_error(bearingsim(*args), f"{f}: is a sweep file", f"'bearingsim sweep {f}' runs it")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow  # a multibody run (~2 s)
def test_a_motion_window_longer_than_the_run_is_noted_before_it(tmp_path):
    """`--set output.motion_rotations=50` with `numerics.rotations=3` ran silently and stored 3 rotations of
    motion: the run (and its dry run) says so in one note before it starts; a window the run holds, a run
    that did not give the key (the default 2 rotations of a 1-rotation run) and -q give none."""
    import h5py

    scenario = SCENARIOS / "multibody_3000rpm.toml"
    long = ("--set", "output.motion_rotations=50", "--set", "numerics.rotations=3")
    dry = bearingsim("run", scenario, *long, "--dry-run", "-o", tmp_path / "m.h5")
    real = bearingsim("run", scenario, *long, "--no-plots", "-o", tmp_path / "m.h5")
    for res in (dry, real):
        assert res.returncode == 0, res.stderr
        lines = [line for line in res.stderr.splitlines() if "motion_rotations" in line]
        assert lines == ["bearingsim: note: output.motion_rotations = 50 is longer than the run's 3 recorded rotations "
                         "(numerics.rotations): the archive stores the motion of those 3, the whole recorded run "
                         "(docs/archive.md, Motion)"], res.stderr
    with h5py.File(tmp_path / "m.h5", "r") as f:  # the whole run: 3 rotations of 240 poses and the last pose
        assert f["observables/motion_cage_angle/value"].shape[0] == 3 * 240 + 1
    for sets in (("--set", "output.motion_rotations=3", "--set", "numerics.rotations=3"),
                 ("--set", "numerics.rotations=1"), (*long, "-q")):
        res = bearingsim("run", scenario, *sets, "--dry-run", "-o", tmp_path / "n.h5")
        assert res.returncode == 0 and "motion_rotations" not in res.stderr, (sets, res.stderr)


@pytest.mark.slow
def test_run_and_inspect_print_the_mean_impulses_with_their_standard_errors(tmp_path):
    """A whole-bearing run's headline impulses are means over rotations: ``run`` and ``inspect`` print each with
    its batch-means standard error (the one ``table`` shows, docs/statistics.md), recomputed here from the archive's
    per-rotation arrays, and ``run`` beside it in mN s per pocket and cage rotation as ``table`` shows it; the
    reduced model's, exact, carry none."""
    import math
    import re

    import h5py
    import numpy as np

    from bearingsim import archive
    from bearingsim.stats import batch_sem, pocket_means
    from bearingsim.tables import with_error

    out = tmp_path / "m.h5"
    res = bearingsim("run", SCENARIOS / "multibody_3000rpm.toml", "-o", out, "--no-plots",
                     "--set", "numerics.rotations=4")
    assert res.returncode == 0, res.stderr
    shown = {m[1]: (float(m[2]), float(m[3]), m[4])
             for m in re.finditer(r"(I_(?:dec|acc)_mean_Ns) +(\S+) \u00b1 (\S+)  \((\S+ \u00b1 \S+) mN s per pocket and "
                                  r"cage rotation; standard error, batch means over 4 recorded rotations\)", res.stdout)}
    assert set(shown) == {"I_dec_mean_Ns", "I_acc_mean_Ns"}, res.stdout
    listing = bearingsim("inspect", out).stdout
    with h5py.File(out, "r") as f:
        summary = archive.group_attrs(f["results/summary"])[0]
        for key, (mean, se, human) in shown.items():
            rows = f[f"results/per_rotation/{key[:5]}"][()]
            want = batch_sem(pocket_means(rows))
            assert math.isclose(se, float(f"{want:.2g}"), rel_tol=1e-12) and want > 0
            assert math.isclose(mean, float(f"{summary[key]:.6g}"), rel_tol=1e-12)
            assert human == with_error(summary[key] * 1e3, want * 1e3)  # as bearingsim table shows it
            assert f"{key} \u00b1 {want:.2g} N s" in listing
        # the first impact speed: the mean of every recorded first impact, its error from the 4 rotations' own
        # means (4 rotations: 4 batches of one), each the mean of the impacts that rotation recorded
        fi = f["results/per_rotation/first_impact_speed"][()]
        per_rot = [r[np.isfinite(r)].mean() for r in fi]
        want = float(np.std(per_rot, ddof=1) / math.sqrt(len(per_rot)))
        mean = summary["first_impact_speed_m_s"]
        assert mean == fi[np.isfinite(fi)].mean() and want > 0
        assert (f"first_impact_speed_m_s       {mean:.6g} \u00b1 {want:.2g}  ({with_error(mean, want)} m/s; standard "
                f"error, batch means over 4 recorded rotations)") in res.stdout, res.stdout
        assert f"first_impact_speed_m_s \u00b1 {want:.2g} m/s" in listing
        assert f" {with_error(mean, want)}  " in bearingsim("table", out).stdout  # its column, as the run's words
        # the cage slip (shown in per cent) and the load zone: batch means of their values in each rotation
        for key, name, scale, unit in (("cage_slip", "cage_slip", 100.0, "%"),
                                       ("load_zone_half_angle_deg", "load_zone_half_angle", 1.0, "deg")):
            want = batch_sem(f[f"results/per_rotation/{name}"][()])
            assert (f"{key:28s} {summary[key]:.6g} \u00b1 {want:.2g}  ({with_error(summary[key] * scale, want * scale)} "
                    f"{unit}; standard error, batch means over 4 recorded rotations)") in res.stdout, res.stdout
            assert f"{key} \u00b1 {want:.2g}" in listing
    assert "standard errors (batch means over 4 recorded rotations)" in listing
    with h5py.File(out, "a") as f:  # a damaged archive is still listed: no error line from text per rotation
        del f["results/per_rotation/I_dec"]
        f["results/per_rotation/I_dec"] = [b"a", b"b"]
    res = bearingsim("inspect", out)
    assert res.returncode == 0 and "standard errors" not in res.stdout, res.stderr
    one = tmp_path / "one.h5"
    res = bearingsim("run", SCENARIOS / "multibody_3000rpm.toml", "-o", one, "--no-plots",
                     "--set", "numerics.rotations=1")
    assert "mN s per pocket and cage rotation; no standard error from 1 recorded rotation)" in res.stdout, res.stdout
    assert "standard errors: none (1 recorded rotation gives no scatter)" in bearingsim("inspect", one).stdout
    red = tmp_path / "p.h5"
    res = bearingsim("run", SCENARIOS / "paper_3000rpm.toml", "-o", red, "--no-plots")
    assert res.returncode == 0 and "\u00b1" not in res.stdout and "standard error" not in res.stdout
    assert "(5.2802 mN s per pocket and cage rotation)" in res.stdout  # docs/validation.md: 5.280 mN s at 3000 rpm
    assert "standard errors" not in bearingsim("inspect", red).stdout


def test_inspect_of_a_sweep_or_study_folder_lists_its_files(tmp_path):
    """``inspect DIR`` of a sweep's folder was refused ("is a sweep or study folder, not an archive") where
    ``table DIR`` and ``report DIR`` read it: it lists the folder's study tables and its case index, each as
    ``inspect FILE`` lists it; a folder without a sweep is still refused in one line."""
    out = tmp_path / "sw"
    assert bearingsim("sweep", SCENARIOS / "paper_3000rpm.toml", "--param", "operating.inner_ring_speed_rpm=1000,2000",
                      "-o", out, "-q", "--no-plots").returncode == 0
    res = bearingsim("inspect", out)
    assert res.returncode == 0, res.stderr
    index, grid = (bearingsim("inspect", out / name).stdout for name in ("sweep.h5", "map.h5"))
    assert res.stdout == f"{out}: a sweep or study folder; its files below: sweep.h5, map.h5\n\n{index}\n{grid}", \
        res.stdout
    assert_user_error(bearingsim("inspect", tmp_path), str(tmp_path), "is a directory, not an archive")
    (out / "sweep.h5").write_bytes((out / "sweep.h5").read_bytes()[:3000])  # damaged: said as inspect FILE says it
    assert_user_error(bearingsim("inspect", out), f"{out / 'sweep.h5'}: damaged or truncated file")


@pytest.mark.slow
def test_inspect_of_a_validate_folder_names_its_csv_tables(tmp_path):
    """``inspect DIR`` of the folder ``validate`` writes was refused ("fig9_idec_vs_speed.csv: not a bearingsim
    sweep index"): it handed the study's CSV table to the reader of HDF5 indexes. It now names the study's
    tables, the command that prints them, and lists the folder's case index as ``inspect sweep.h5`` does."""
    out = tmp_path / "val"
    assert bearingsim("validate", "--rig-rotations", "0", "-o", out, "-q").returncode == 0
    res = bearingsim("inspect", out)
    assert res.returncode == 0, res.stderr
    index = bearingsim("inspect", out / "sweep.h5").stdout
    head = f"{out}: a sweep or study folder; its files below: fig9_idec_vs_speed.csv, sweep.h5\n\n"
    assert res.stdout.startswith(head + f"{out}: bearingsim validate tables (CSV, one row per speed): "
                                 f"fig9_idec_vs_speed.csv\n'bearingsim table {out}' prints them"), res.stdout
    assert res.stdout.endswith(index), res.stdout


@pytest.mark.parametrize("command", [
    ["run", "{paper}"],
    ["sweep", "{paper}", "--param", "operating.inner_ring_speed_rpm=1000,2000"],
    ["sensitivity", "{paper}", "--keys", "contact.restitution"],
    ["crosscheck", "{mb}"],
    ["life", "{mb}", "--limit", "clearance=0.4mm"],
])
def test_an_empty_output_path_is_refused_not_read_as_the_current_folder(tmp_path, command):
    """`-o ""` (a shell's `-o "$OUT"` with OUT unset) was read as the current folder: a sweep wrote its index,
    map and figures there. Every command's -o refuses an empty path, exit 2, naming the option, writing
    nothing; '.' still names the current folder."""
    args = [a.format(paper=SCENARIOS / "paper_3000rpm.toml", mb=SCENARIOS / "multibody_6000rpm.toml")
            for a in command]
    res = bearingsim(*args, "-o", "", cwd=tmp_path)
    assert res.returncode == 2 and "Traceback" not in res.stderr, res.stderr
    assert res.stderr.splitlines() == [
        f"bearingsim {command[0]}: error: argument -o/--output: an empty path: give a file or folder ('.' for the "
        f"current one) (bearingsim {command[0]} --help)"], res.stderr
    assert list(tmp_path.iterdir()) == []


def _subparsers() -> dict:
    """Every subcommand's parser, by name, as the program builds them (not a list that could go stale)."""
    import argparse

    from bearingsim.cli import build_parser

    return next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices


def assert_argparse_error(res, prog: str, *words):
    """argparse's refusal of a command line: one line on stderr naming the command and its --help, exit 2."""
    lines = res.stderr.splitlines()
    assert res.returncode == 2 and len(lines) == 1, res.stderr
    assert lines[0].startswith(f"{prog}: error: ") and lines[0].endswith(f" ({prog} --help)"), lines[0]
    for w in words:
        assert w in lines[0], lines[0]
    assert res.stdout == ""


@pytest.mark.parametrize("command", sorted(_subparsers()))
def test_a_bad_command_line_is_one_line_naming_the_commands_help(command):
    """argparse printed a usage block of three lines and more above its error (`bearingsim run`: the usage,
    then "bearingsim run: error: the following arguments are required: scenario"), and an option no
    subcommand takes was refused by the main parser ("bearingsim: error: unrecognized arguments"). Every
    subcommand's bad option and missing argument is now one line naming the subcommand and its --help,
    exit 2; --help still prints the usage."""
    parser = _subparsers()[command]
    prog = f"bearingsim {command}"
    required = [a.dest for a in parser._actions if a.required]
    res = bearingsim(command, "--no-such-option")
    if required:
        assert_argparse_error(res, prog, "the following arguments are required: ")
        assert_argparse_error(bearingsim(command), prog, "the following arguments are required: ")
    else:
        assert_argparse_error(res, prog, "unrecognized arguments: --no-such-option")
    helped = bearingsim(command, "--help")
    assert helped.returncode == 0 and helped.stdout.startswith(f"usage: {prog} "), helped.stdout


@pytest.mark.parametrize("args, words", [
    (["rnu"], ["argument command: invalid choice: 'rnu' (choose from 'run', ", "did you mean 'run'?"]),
    (["xyzzy"], ["argument command: invalid choice: 'xyzzy' (choose from 'run', "]),
    ([], ["the following arguments are required: command"]),
    (["--no-such-option"], ["the following arguments are required: command"]),
])
def test_an_unknown_or_missing_subcommand_is_one_line_with_the_closest_name(args, words):
    """`bearingsim rnu` printed the usage with the whole command list on three lines, then "invalid choice";
    now one line, which names the closest command when there is one (difflib), exit 2."""
    res = bearingsim(*args)
    assert_argparse_error(res, "bearingsim", *words)
    assert ("did you mean" in res.stderr) == (args == ["rnu"]), res.stderr


def test_an_unknown_option_value_names_the_closest_choice():
    res = bearingsim("report", "x.h5", "--animation", "gf")
    assert_argparse_error(res, "bearingsim report", "argument --animation: invalid choice: 'gf'",
                          "did you mean 'gif'?")


def test_a_validate_folder_given_to_plot_says_what_its_sweep_h5_draws(tmp_path):
    """`bearingsim plot DIR` of a validate folder said "'bearingsim plot DIR/sweep.h5' draws its figures", which
    draws the cases' overview (sweep_cases.png, written into the folder) and none of validate's Fig. 9 or rig
    figures: the line says it draws the cases' overview, and that validate run again redraws its own."""
    folder = tmp_path / "val"
    folder.mkdir()
    (folder / "sweep.h5").write_bytes(b"")
    (folder / "fig9_idec_vs_speed.csv").write_text("speed_rpm,c\n500,1\n")
    res = bearingsim("plot", folder)
    assert_user_error(res, f"{folder}: is a sweep or study folder, not an archive",
                      f"'bearingsim plot {folder / 'sweep.h5'}' draws its cases' overview (validate's own figures: "
                      f"the same 'bearingsim validate -o {folder}' again redraws them from its cases)")
    assert "draws its figures" not in res.stderr


def test_a_negative_value_apart_from_its_option_is_joined_to_it_and_nothing_else_is():
    """cli_common._negative_values_joined: argparse takes '-10' as a value but reads '-10%' or '-.5e-3' as an
    unknown option; no bearingsim option starts with a digit, so a token that starts as a negative number after a
    long option is that option's value. A value inside a --set, a short option's, and what follows '--' stay."""
    from bearingsim.cli_common import _negative_values_joined as joined

    assert joined(["sensitivity", "a.toml", "--step", "-10%"]) == ["sensitivity", "a.toml", "--step=-10%"]
    assert joined(["--hours", "-.5e-3", "--step", "5%"]) == ["--hours=-.5e-3", "--step", "5%"]
    assert joined(["--set", "operating.radial_load_N=-5", "-o", "-1"]) == ["--set", "operating.radial_load_N=-5",
                                                                           "-o", "-1"]
    assert joined(["--step=-1%", "-2"]) == ["--step=-1%", "-2"]
    assert joined(["run", "--", "--step", "-10%"]) == ["run", "--", "--step", "-10%"]
