"""A run's outputs say which run they are (issue 28, defects 2, 3 and 6): an archive or a sweep folder of a
different scenario or sweep is not replaced without --force, figure titles name what differs from the
preset, and notes are explained once and silenced by -q."""
import pytest

from bearingsim import cli, plausibility
from bearingsim.scenario import load_scenario
from bearingsim.simulation import run as simulate
from bearingsim.sweeps import worker

from .conftest import SCENARIOS
from .test_cli import assert_user_error, bearingsim

BASE = SCENARIOS / "paper_3000rpm.toml"
SPEED = "operating.inner_ring_speed_rpm"


# --- defect 2: --set must not silently replace another scenario's archive --------------------------------
@pytest.mark.slow
def test_run_refuses_to_replace_an_archive_of_another_scenario(tmp_path):
    out = tmp_path / "a.h5"
    assert bearingsim("run", BASE, "-o", out, "--no-plots", "-q").returncode == 0
    before = out.read_bytes()
    res = bearingsim("run", BASE, "--set", f"{SPEED}=500", "-o", out, "--no-plots", "-q")
    assert_user_error(res, str(out), SPEED, "--force", "-o")
    assert out.read_bytes() == before  # nothing replaced
    # a rerun of the same scenario may replace it; --force replaces a different one
    assert bearingsim("run", BASE, "-o", out, "--no-plots", "-q").returncode == 0
    res = bearingsim("run", BASE, "--set", f"{SPEED}=500", "-o", out, "--no-plots", "-q", "--force")
    assert res.returncode == 0, res.stderr
    assert load_scenario(BASE, [f"{SPEED}=500"]) == __import__("bearingsim").load(out).scenario


@pytest.mark.slow
def test_sweep_folder_of_another_sweep_is_refused_resume_and_force_work(tmp_path):
    first = ("sweep", BASE, "--param", f"{SPEED}=1000,2000", "-o", tmp_path, "-j", "1", "--no-plots",
             "--archives", "all")  # the case archives are what this test follows
    assert bearingsim(*first).returncode == 0
    cases = sorted(p.name for p in (tmp_path / "cases").glob("*.h5"))
    res = bearingsim("sweep", BASE, "--param", f"{SPEED}=3000,4000", "-o", tmp_path, "-j", "1", "--no-plots")
    assert_user_error(res, str(tmp_path), "--force")
    assert sorted(p.name for p in (tmp_path / "cases").glob("*.h5")) == cases  # nothing added or removed
    res = bearingsim(*first)  # the same sweep again: resumed (all cached)
    assert res.returncode == 0 and "2 cached" in res.stdout, res.stderr
    res = bearingsim("sweep", BASE, "--param", f"{SPEED}=3000,4000", "-o", tmp_path, "-j", "1", "--no-plots",
                     "--force", "--archives", "all")
    assert res.returncode == 0, res.stderr
    now = sorted(p.name for p in (tmp_path / "cases").glob("*.h5"))
    assert len(now) == 2 and not set(now) & set(cases)  # the first sweep's archives are gone, not mixed in


# --- defect 3: figure titles name what differs from the preset ---------------------------------------------
def test_title_names_what_differs_from_the_preset():
    plain = simulate(load_scenario(BASE))
    assert plain.title().endswith("\nload zone ±23.5°")  # the paper scenario's own setting
    changed = simulate(load_scenario(BASE, ["bearing.pocket_clearance_mm=0.3", "bearing.roller_count=14"]))
    assert changed.title().endswith("\n14 rollers, s = 0.3 mm, load zone ±23.5°")


def test_multibody_differences_are_named_compactly():
    from bearingsim.scenario import differences_from_preset

    sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml",
                       ["multibody.raceway_contact=rigid", "bearing.cage_guidance=outer_land",
                        "bearing.radial_clearance_mm=0.1"])
    text = ", ".join(differences_from_preset(sc))
    assert "raceway rigid" in text and "outer-land cage" in text and "0.1 mm" in text
    assert differences_from_preset(load_scenario(SCENARIOS / "multibody_3000rpm.toml")) == []


# --- defect 6: notes are silenced by -q and not printed per sweep case -----------------------------------
NOTE = "bearingsim: note: test note"


def test_quiet_run_prints_no_note(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(plausibility, "check", lambda result: [NOTE])
    assert cli.main(["run", str(BASE), "-o", str(tmp_path / "a.h5"), "--no-plots", "-q"]) == 0
    assert capsys.readouterr().err == ""
    assert cli.main(["run", str(BASE), "-o", str(tmp_path / "a.h5"), "--no-plots"]) == 0
    assert NOTE in capsys.readouterr().err


def test_sweep_case_prints_no_note(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(plausibility, "check", lambda result: [NOTE])
    worker._run_to_file(load_scenario(BASE), tmp_path / "case.h5")
    assert capsys.readouterr().err == ""


def test_newton_note_says_what_it_means():
    """What the note says, in one readable line (it ran to 355 characters under every default run): how many
    steps, the share and the refusal's bound, what those steps did, and where to read more."""
    text = plausibility.NEWTON_NOTE.format(fails=5, steps=22922, share=5 / 22922)
    assert "did not converge in 5 of 22922 steps (0.02%; refused above 1%)" in text
    assert "kept the solve's last iterate" in text and "ring_newton_failures" in text and "docs/archive.md" in text
    assert len(text) <= 240, len(text)


def test_the_library_prints_nothing_its_notes_are_log_records(tmp_path, monkeypatch, capsys, caplog):
    """A note of a plausible but not clean run reaches a Python caller as ``result.notes`` and a record
    of the ``bearingsim`` loggers, never as text on its stderr; only the command line prints it."""
    import logging

    from bearingsim.simulation import run_scenario

    monkeypatch.setattr(plausibility, "check", lambda result: [NOTE])
    sc = load_scenario(BASE)
    with caplog.at_level(logging.INFO, logger="bearingsim"):
        out = run_scenario(sc, tmp_path / "a.h5", figures=False)
    assert out.result.notes == [NOTE]
    assert capsys.readouterr().err == ""
    assert [r.getMessage() for r in caplog.records if r.name.startswith("bearingsim")] == [NOTE]


def test_the_api_warns_of_a_plausible_run_that_is_not_clean(monkeypatch):
    """``bearingsim.run`` returns a plausible but not clean result with its notes in ``result.notes`` and
    each issued once as a :class:`bearingsim.errors.PlausibilityWarning` pointing at the caller's line."""
    import warnings

    import bearingsim as api
    from bearingsim.errors import PlausibilityWarning

    monkeypatch.setattr(plausibility, "check", lambda result: [NOTE])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = api.run(load_scenario(BASE))
    assert r.notes == [NOTE]
    assert [(w.category, str(w.message)) for w in caught] == [(PlausibilityWarning, NOTE)]
    assert caught[0].filename == __file__
    monkeypatch.setattr(plausibility, "check", lambda result: [])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert api.run(load_scenario(BASE)).notes == []
