"""Crafted archives (issue 30, item 7): an archive whose structure is not what bearingsim writes is
refused on read by one check of its layout (:func:`bearingsim.archive.check_layout`), with a
:class:`bearingsim.UserError` naming the file and what is wrong; ``show``, ``plot``, ``compare`` and
``rerun`` print that one line and exit 2, with no traceback."""
from __future__ import annotations

import json
import shutil

import h5py
import numpy as np
import pytest

import bearingsim

from .conftest import SCENARIOS
from .test_cli import assert_user_error, bearingsim as cli


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    """A complete reduced-model archive (one rotation)."""
    path = tmp_path_factory.mktemp("crafted") / "r.h5"
    bearingsim.run(bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml")).save(path)
    return path


def _summary_value(f, key, value):
    g = f["results/summary"]
    attrs = json.loads(g.attrs["attrs_json"])
    attrs[key] = value
    g.attrs["attrs_json"] = json.dumps(attrs)


def _replace(f, name, data):
    del f[name]
    f[name] = data


def _nested_scenario(f):
    text = f["scenario"][()].decode()
    _replace(f, "scenario", text + "\nx = " + "[" * 100_000 + "]" * 100_000 + "\n")


CASES = {  # name: (change to a complete archive, words the one-line error must hold)
    "summary-deleted": (lambda f: f.__delitem__("results/summary"), ["/results/summary", "not a group"]),
    "summary-a-dataset": (lambda f: _replace(f, "results/summary", np.zeros(3)), ["/results/summary"]),
    "summary-value-a-string": (lambda f: _summary_value(f, "I_dec_mean_Ns", "lots"), ["I_dec_mean_Ns", "not a number"]),
    "summary-value-a-list": (lambda f: _summary_value(f, "I_acc_mean_Ns", [1, 2]), ["/results/summary", "attrs_json"]),
    "summary-json-deep": (lambda f: f["results/summary"].attrs.__setitem__("attrs_json", "[" * 100_000),
                          ["/results/summary", "nested too deeply"]),
    "scenario-nested-100000-deep": (_nested_scenario, ["/scenario", "nested too deeply"]),
    "scenario-a-group": (lambda f: (f.__delitem__("scenario"), f.create_group("scenario")), ["/scenario", "not a dataset"]),
    "scenario-numbers": (lambda f: _replace(f, "scenario", np.zeros(4)), ["/scenario", "not a text"]),
    "observables-a-dataset": (lambda f: f.__setitem__("observables", np.zeros(4)), ["/observables", "not a group"]),
    "observables-lengths-differ": (
        lambda f: (f.__setitem__("observables/x/step", np.arange(3)), f.__setitem__("observables/x/time", np.zeros(3)),
                   f.__setitem__("observables/x/value", np.zeros(5))), ["/observables/x", "length"]),
    "model-contradicts-data": (lambda f: f["bearingsim"].attrs.__setitem__("model", "multibody"),
                               ["/bearingsim@model", "multibody", "reduced"]),
    "model-unknown": (lambda f: f["bearingsim"].attrs.__setitem__("model", "fem"), ["/bearingsim@model", "fem"]),
    "model-a-number": (lambda f: f["bearingsim"].attrs.__setitem__("model", 7), ["/bearingsim@model"]),
    "per-rotation-3d": (lambda f: _replace(f, "results/per_rotation/I_dec", np.zeros((1, 1, 2))),
                        ["/results/per_rotation/I_dec", "3 dimension"]),
    "per-rotation-rows-not-the-scenario's": (lambda f: _replace(f, "results/per_rotation/I_acc", np.zeros((7, 1))),
                                             ["/results/per_rotation/I_acc", "rotations = 7"]),
    "per-rotation-text": (lambda f: _replace(f, "results/per_rotation/I_acc", np.array([[b"x"]])),
                          ["/results/per_rotation/I_acc", "expected numbers"]),
    "impacts-column-short": (lambda f: _replace(f, "results/impacts/pocket", np.zeros(1, np.int64)),
                             ["/results/impacts/pocket", "impacts"]),
    "trace-half-missing": (lambda f: f.__delitem__("results/trace/l_r"), ["/results/trace/l_r", "missing"]),
    "complete-the-string-false": (lambda f: f["bearingsim"].attrs.__setitem__("complete", "false"),
                                  ["/bearingsim@complete", "not a boolean"]),
}


def _crafted(archive, tmp_path, name):
    path = tmp_path / f"{name}.h5"
    shutil.copy(archive, path)
    with h5py.File(path, "r+") as f:
        CASES[name][0](f)
    return path


@pytest.mark.parametrize("name", list(CASES))
def test_load_refuses_a_crafted_archive_with_a_user_error(archive, tmp_path, name):
    path = _crafted(archive, tmp_path, name)
    with pytest.raises(bearingsim.UserError) as info:
        bearingsim.load(path)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith(str(path)), msg
    for w in CASES[name][1]:
        assert w in msg, msg


def test_the_untouched_archive_loads(archive):
    r = bearingsim.load(archive)
    assert r.per_rotation["I_dec"].shape == (1, 1) and "I_dec_mean_Ns" in r.summary


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CASES))
def test_show_prints_one_line_and_exits_2(archive, tmp_path, name):
    path = _crafted(archive, tmp_path, name)
    assert_user_error(cli("show", path), path.name, *CASES[name][1])


@pytest.mark.slow
@pytest.mark.parametrize("command", ["plot", "compare", "rerun"])
@pytest.mark.parametrize("name", ["summary-value-a-string", "model-contradicts-data", "observables-a-dataset"])
def test_plot_compare_rerun_print_one_line_and_exit_2(archive, tmp_path, command, name):
    path = _crafted(archive, tmp_path, name)
    args = (path, archive) if command == "compare" else (path,)
    assert_user_error(cli(command, *args), path.name)
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]  # no figure, no archive written


def test_a_sweep_does_not_trust_complete_false(archive, tmp_path):
    """A sweep's resume check (``archive.peek``) reads the same flag: the string "false" is not complete."""
    from bearingsim import archive as arch

    path = _crafted(archive, tmp_path, "complete-the-string-false")
    assert arch.peek(path) is None and arch.peek(archive) is not None
