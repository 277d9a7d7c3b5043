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
    text = plausibility.NEWTON_NOTE.format(fails=5, steps=22922, share=5 / 22922)
    assert "did not converge" in text and "ring_newton_failures" in text and "docs/" in text
