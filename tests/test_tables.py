"""Issue 28, items 5 (one standard error), 7 (progress), 8 (tables, compare of N archives):
``bearingsim table``, ``bearingsim compare A B C ...``, the table at the end of a sweep, one standard-error
estimator for sweep, cross-check and table, and the progress bar only on a terminal."""
from __future__ import annotations

import csv
import math
import os
import subprocess
import sys
import threading
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import bearingsim
from bearingsim import tables
from bearingsim.stats import batch_sem, first_impact_sem, impulse_standard_errors, summary_standard_errors, with_error

from .conftest import SCENARIOS, started
from .test_cli import assert_user_error, bearingsim as cli

PAPER = SCENARIOS / "paper_3000rpm.toml"


@pytest.fixture(scope="module")
def reduced_runs(tmp_path_factory):
    """Three reduced-model archives: a.h5 and b.h5 of the same scenario, c.h5 at restitution 0.6."""
    d = tmp_path_factory.mktemp("tables")
    sc = bearingsim.load_scenario(PAPER)
    bearingsim.run(sc).save(d / "a.h5")
    bearingsim.run(sc).save(d / "b.h5")
    bearingsim.run(bearingsim.load_scenario(PAPER, set={"contact.restitution": 0.6})).save(d / "c.h5")
    return d


# --- one standard error -------------------------------------------------------------------------

def _correlated_series(n=20, seed=3):
    """Per-rotation impulses of 4 pockets with a slow drift across rotations (correlated rotations)."""
    rng = np.random.default_rng(seed)
    drift = np.repeat(rng.normal(0.0, 1e-3, n // 4), 4)  # blocks of 4 rotations share an offset
    return 0.01 + drift[:, None] + rng.normal(0.0, 2e-4, (n, 4))


def test_sweep_crosscheck_and_table_give_the_same_standard_error():
    """Was: the sweep's index divided the per-rotation scatter by sqrt(rotations) (rotations taken as
    independent) while the cross-check used batch means, so the same archive had two standard errors.
    Now the worker (sweep), the cross-check's rung numbers and the table call one estimator; on
    correlated rotations it is the batch-means error, which differs from the naive one."""
    from bearingsim.studies.crosscheck import rung_numbers
    dec, acc = _correlated_series(), _correlated_series(seed=4)
    result = SimpleNamespace(per_rotation={"I_dec": dec, "I_acc": acc}, scenario=SimpleNamespace(model="multibody"),
                             summary={"I_dec_mean_Ns": dec.mean(), "I_acc_mean_Ns": acc.mean(),
                                      "first_impact_speed_m_s": 0.1, "cage_slip": 0.0})
    sweep = summary_standard_errors({"I_dec": dec, "I_acc": acc}, "multibody")  # what the sweep's worker calls
    cross = rung_numbers(result, reduced=False)
    from bearingsim.stats import result_standard_errors

    table = result_standard_errors(result)
    for k in ("I_dec_sem_Ns", "I_acc_sem_Ns"):
        assert sweep[k] == cross[k] == table[k]
    naive = dec.mean(axis=1).std(ddof=1) / math.sqrt(len(dec))
    assert sweep["I_dec_sem_Ns"] == batch_sem(dec.mean(axis=1)) and sweep["I_dec_sem_Ns"] > 1.5 * naive


def _c4(n: int) -> float:
    """E[s] / sigma of the sample sd of n normal values."""
    return math.sqrt(2.0 / (n - 1)) * math.exp(math.lgamma(n / 2) - math.lgamma((n - 1) / 2))


def test_batch_means_error_of_independent_rotations_is_the_plain_one_on_average(sem=batch_sem):
    """On independent rotations batch means estimate the same error as sd/sqrt(n), but from 5 batch means: for
    20 normal rotations of sd 1 its mean is exactly c4(5) / sqrt(20) (c4(5) = 0.9400), the plain one's
    c4(20) / sqrt(20) (0.9869), 4.99 % apart. The test took the mean ratio of the two to 5 %, which the plain
    estimator passed too; now the mean of 20000 errors x sqrt(20) is held to 0.006 of c4(5): one value's sd is
    sqrt(1 - c4(5)^2) = 0.34, the mean's 0.0024, so 0.006 is 2.5 of its sd, and c4(20) lies 20 of them away."""
    rng = np.random.default_rng(0)
    x = rng.normal(size=(20000, 20))
    mean = float(np.mean([sem(row) for row in x])) * math.sqrt(20)
    spread = math.sqrt(1.0 - _c4(5) ** 2) / math.sqrt(len(x))
    assert abs(mean - _c4(5)) < 2.5 * spread, (mean, _c4(5), spread)
    assert abs(_c4(20) - _c4(5)) > 15 * spread  # the plain estimator's mean is far outside


def test_the_statistics_pages_start_transient_arithmetic_follows_its_table():
    """docs/statistics.md reads its replica table: the first rotation's excess over 5 and over 40
    rotations, against the 3000 rpm rigid row's mean and median ±. It said 10.3 % / 5 "≈ 2.16 %" and
    the 40-rotation weight (0.037 mN s) "about half" of the ± (0.046 mN s): 0.8 of it."""
    import re

    text = (Path(__file__).resolve().parents[1] / "docs" / "statistics.md").read_text()
    row = re.search(r"\| rigid \| 3000 \| ([0-9.]+) \| [0-9.]+ \| ([0-9.]+) \|.*\| \+([0-9.]+) ± [0-9.]+ % \| "
                    r"\+([0-9.]+) ± ([0-9.]+) % \|", text)
    mean, pm, first, five, five_se = (float(x) for x in row.groups())
    quoted = re.search(r"10\.3 % / 5 = ([0-9.]+) %", text)
    assert quoted and float(quoted.group(1)) == pytest.approx(first / 5, abs=0.005)
    assert abs(first / 5 - five) <= 2 * five_se
    weight = re.search(r"weighs 1/40 \(\+([0-9.]+) % at 3000 rpm, ([0-9.]+) mN s: about ([0-9.]+) of a run's ±, ([0-9.]+) mN s\)",
                       text)
    rel, abs_, share, pm_quoted = (float(x) for x in weight.groups())
    assert rel == pytest.approx(first / 40, abs=0.005) and abs_ == pytest.approx(mean * rel / 100, abs=5e-4)
    assert pm_quoted == pm and share == pytest.approx(abs_ / pm, abs=0.05)


def test_reduced_model_error_is_zero_and_one_rotation_has_none():
    one = np.ones((1, 4))
    assert impulse_standard_errors(one, one, "reduced") == {"I_dec_sem_Ns": 0.0, "I_acc_sem_Ns": 0.0}
    assert math.isnan(impulse_standard_errors(one, one, "multibody")["I_dec_sem_Ns"])


def test_first_impact_speed_error_is_that_of_the_pooled_impacts():
    """``first_impact_speed_m_s`` is the mean of every recorded first impact (pockets and rotations pooled); its
    standard error takes the same 5 contiguous batches of rotations as the impulses' (docs/statistics.md), each
    batch's sum and count of impacts, and the pooled mean's ratio-estimator error. Without a missing impact it is
    the impulses' estimator of the same array; 1 rotation or no impact leaves none (NaN); the reduced model's is 0
    (one exact pass)."""
    full = _correlated_series()  # 40 rotations x 4 pockets, correlated rotations
    assert first_impact_sem(full, "multibody") == pytest.approx(batch_sem(full.mean(axis=1)), rel=1e-12)
    holes = full.copy()
    holes[::3, 1:] = np.nan  # every third rotation recorded an impact in pocket 0 only
    holes[8:16] = np.nan  # the second batch (rotations 8-15) without any
    parts = np.array_split(holes, 5)
    sums = np.array([np.nansum(c) for c in parts])
    counts = np.array([np.isfinite(c).sum() for c in parts])
    m = np.nanmean(holes)
    want = math.sqrt(np.sum((sums - m * counts) ** 2) / 20) / counts.mean()
    assert first_impact_sem(holes, "multibody") == pytest.approx(want, rel=1e-12)
    assert math.isnan(first_impact_sem(full[:1], "multibody")) and math.isnan(first_impact_sem(holes * np.nan))
    assert first_impact_sem(None, "reduced") == 0.0
    se = summary_standard_errors({"I_dec": full, "I_acc": full, "first_impact_speed": full}, "multibody")
    assert se["I_dec_sem_Ns"] == se["I_acc_sem_Ns"] == batch_sem(full.mean(axis=1))
    assert se["first_impact_speed_sem_m_s"] == pytest.approx(se["I_dec_sem_Ns"], rel=1e-12)
    # the reduced model records no per-rotation first impact: its error is still there, 0
    assert summary_standard_errors({"I_dec": full[:1], "I_acc": full[:1]}, "reduced")["first_impact_speed_sem_m_s"] == 0


def test_first_impact_speed_error_covers_the_scatter_of_the_pooled_mean_with_uneven_counts():
    """Where the batches hold very different numbers of impacts (here 90 % of the passes of the first 20 rotations
    hit, 5 % of the last 20), the pooled mean weighs the batches by their impacts: its error is the ratio
    estimator's, not the scatter of the batch means (which, weighing the nearly empty batches alike, reads it 2.2
    times too large on these simulated runs, 0.92 for the ratio estimator). Over 2000 simulated runs of independent impacts
    (seeded), the rms of the estimated error lies within 20 % of the pooled means' true scatter (the estimate of
    each run has 4 degrees of freedom; 2000 runs fix the rms to about 2 %)."""
    rng = np.random.default_rng(7)
    means, errors = [], []
    for _ in range(2000):
        v = rng.normal(0.05, 0.01, (40, 16))
        hit = rng.random((40, 16)) < np.where(np.arange(40) < 20, 0.9, 0.05)[:, None]
        v[~hit] = np.nan
        means.append(np.nanmean(v))
        errors.append(first_impact_sem(v, "multibody"))
    ratio = math.sqrt(np.mean(np.square(errors))) / np.std(means)
    assert 0.8 < ratio < 1.2, ratio


def test_a_table_marks_the_first_impact_speed_by_its_error():
    """``bearingsim table`` gives the first impact speed with its standard error and marks a row whose speed differs
    from the first row's beyond it, as it does the impulses (was: the speed alone, no error, no mark)."""
    dec = _correlated_series()
    rows = []
    for shift in (0.0, 0.0, 0.01):
        fi = 0.05 + shift + (dec - dec.mean())  # its standard error about 0.0007 m/s
        rows.append({"I_dec_mean_Ns": dec.mean(), "I_dec_sem_Ns": batch_sem(dec.mean(axis=1)),
                     "first_impact_speed_m_s": fi.mean(), "first_impact_speed_sem_m_s": first_impact_sem(fi, "multibody")})
    t = tables.Table(["run"], {"run": ["ref", "same", "faster"]},
                     {k: np.array([r[k] for r in rows]) for k in rows[0]},
                     {"I_dec_mean_Ns": "N s", "I_dec_sem_Ns": "N s", "first_impact_speed_m_s": "m/s",
                      "first_impact_speed_sem_m_s": "m/s"})
    head, cells = tables.column_cells(t, "first_impact_speed_m_s")
    assert head == "first_impact_speed [m/s]"
    assert cells[0] == with_error(rows[0]["first_impact_speed_m_s"], rows[0]["first_impact_speed_sem_m_s"]) + "  "
    assert [c.endswith(" *") for c in cells] == [False, False, True]


# --- significance marks ---------------------------------------------------------------------------

def test_marks_only_where_the_difference_exceeds_t_standard_errors():
    t = tables.Table(["run"], {"run": ["ref", "within", "beyond", "no-se"]},
                     {"I_dec_mean_Ns": np.array([10e-3, 10.5e-3, 11e-3, 20e-3]),
                      "I_dec_sem_Ns": np.array([0.2e-3, 0.2e-3, 0.2e-3, math.nan])}, {"I_dec_mean_Ns": "N s"})
    # t(0.975, 8) sqrt(0.2^2 + 0.2^2) = 2.306 x 0.283 = 0.652 mN s: 0.5 is within, 1.0 beyond; no SE: not judged
    lines = tables.format_table(t).splitlines()
    rows = {ln.split()[0]: ln for ln in lines[1:5]}
    assert rows["beyond"].endswith("*") and not rows["within"].endswith("*") and not rows["no-se"].endswith("*")
    assert not rows["ref"].endswith("*") and "± n/a" in rows["no-se"]
    assert "I_dec_mean [mN s]" in lines[0] and "11.00 ± 0.20" in rows["beyond"]  # the value to its error's decimal place
    assert lines[-2] == tables.RULE and lines[-1] == "x_ref: the row run = ref (the first case)"


def test_student_t_quantiles_match_the_printed_tables():
    """stats.t_quantile (no scipy at import): the two-sided 95 % and 99 % points of Student's t as printed in
    the standard tables, the normal's at infinite degrees of freedom, and a fractional Welch count between
    its whole neighbours."""
    from bearingsim.stats import t_quantile

    for dof, q975, q995 in ((1, 12.7062, 63.6567), (2, 4.3027, 9.9248), (4, 2.7764, 4.6041), (8, 2.3060, 3.3554),
                            (30, 2.0423, 2.7500), (math.inf, 1.9600, 2.5758)):
        assert t_quantile(0.975, dof) == pytest.approx(q975, abs=1e-4) and t_quantile(0.995, dof) == pytest.approx(
            q995, abs=1e-4), dof
    assert t_quantile(0.975, 8) < t_quantile(0.975, 5.5) < t_quantile(0.975, 5)


@pytest.mark.slow
@pytest.mark.parametrize("rotations", [4, 10])
def test_the_marks_false_rate_is_the_stated_five_percent(rotations):
    """Two standard errors marked 8 % of pairs of runs of one true mean and 12 % against an exact reference
    (SE 0, a reduced-model row), each SE coming from 5 batch means (4 degrees of freedom), though the page said
    "about 95 %". With Student's t of the Welch-Satterthwaite degrees of freedom: against an exact reference the
    rate is 5 % exactly (one t), between two runs Welch's approximation keeps it at or a little under 5 %. 8000
    pairs of normal runs: the binomial sd of 5 % is 0.24 %, so 3.9 % to 6.1 % (4.5 sd) holds it and excludes 8 %."""
    from bearingsim.stats import sem_batches, significant

    rng = np.random.default_rng(rotations)
    a, b = rng.normal(14.4, 0.3, (2, 8000, rotations))
    nb = sem_batches(rotations)
    assert nb == min(5, rotations)
    sem_a, sem_b = [batch_sem(r) for r in a], [batch_sem(r) for r in b]
    pairs = np.mean([significant(x.mean(), s, y.mean(), e, nb, nb) for x, s, y, e in zip(a, sem_a, b, sem_b)])
    exact = np.mean([significant(x.mean(), s, 14.4, 0.0, nb, nb) for x, s in zip(a, sem_a)])
    assert 0.039 < exact < 0.061 and 0.039 < pairs < 0.061, (exact, pairs)


def test_a_difference_whose_error_has_no_degrees_of_freedom_is_not_judged():
    """A standard error from one batch mean has no degrees of freedom (batches - 1 = 0), so no Student's t:
    significant() returned False ("not significant", from comparing with NaN), though its docstring promises
    None where it cannot judge. Now None, whichever side has the one batch; an exact reference (SE 0) beside
    a one-batch SE is not judged either, and two exact numbers still are (by round-off alone)."""
    from bearingsim.stats import significant

    assert significant(1.0, 0.1, 1.5, 0.1, batches=1) is None
    assert significant(1.0, 0.1, 1.5, 0.1, batches0=1) is None
    assert significant(1.0, 0.1, 1.5, 0.0, batches=1) is None
    assert significant(1.0, 0.0, 1.5, 0.0, batches=1) is True
    # two batches each: Welch's 2 degrees of freedom, t = 4.30 times 0.141 = 0.61 needed, 0.5 apart; 5 beside
    # 2 batches: 3.2 degrees of freedom, t = 3.07, 0.43 needed
    assert significant(1.0, 0.1, 1.5, 0.1, batches=2, batches0=2) is False
    assert significant(1.0, 0.1, 1.5, 0.1, batches=2) is True


def test_a_deterministic_models_round_off_is_not_marked_and_its_real_differences_are():
    """The reduced model's standard error is 0, so every difference was marked, also the last bits a pocket
    clearance leaves in I_dec through the flight's round-off (a sweep's 1000 rpm rows, 0.16/0.20/0.24 mm:
    '7.833 ± 0 *'). Differences within 1e-9 of the value are round-off, unmarked; 1000 against 6000 rpm
    (20 %) and one of 1e-6 are marked. The cross-check's verdicts use the same rule."""
    from bearingsim.studies import crosscheck as cc

    i_dec = [0.007832783677204172, 0.006223442, 0.007832783677204178, 0.007832783677204176,
             0.007832783677204172 * (1 + 1e-6)]
    t = tables.Table(["row"], {"row": ["ref", "6000rpm", "last-bits", "last-bits2", "1e-6"]},
                     {"I_dec_mean_Ns": np.array(i_dec), "I_dec_sem_Ns": np.zeros(5)}, {"I_dec_mean_Ns": "N s"})
    rows = {ln.split()[0]: ln for ln in tables.format_table(t).splitlines()[1:6]}
    assert rows["6000rpm"].endswith("*") and rows["1e-6"].endswith("*"), rows
    assert not rows["last-bits"].endswith("*") and not rows["last-bits2"].endswith("*"), rows
    rungs = [dict(rpm=1000.0, rung=k, scene=f"s{k}", I_dec_mean_Ns=m, I_dec_sem_Ns=0.0, change_from_previous=c)
             for k, m, c in ((1, i_dec[0], math.nan), (2, i_dec[2], i_dec[2] - i_dec[0]),
                             (3, i_dec[1], i_dec[1] - i_dec[2]))]
    (verdict,) = cc.verdicts(rungs)
    assert "rung 2 s2 +0.00 mN s (not significant" in verdict and "rung 3 s3 -1.61 mN s (significant" in verdict


def test_rows_with_the_same_notes_share_one_mark():
    """A study whose stages or cases carry one note alike listed it in full once per row ([1] ... [4], the
    same text); rows with the same notes share a mark and the note is listed once."""
    from bearingsim.tables import _run_notes

    names, labels = ["case"], {"case": ["a", "b", "c", "d"]}
    found = [["k is high"], [], ["k is high"], ["k is high", "short run"]]
    footnotes = _run_notes(found, names, labels)
    assert names == ["case", "notes"] and labels["notes"] == ["[1]", "", "[1]", "[2]"]
    assert footnotes == {0: "[1] k is high", 3: "[2] k is high; short run"}


# --- the commands -------------------------------------------------------------------------------------

@pytest.mark.slow
def test_compare_of_three_archives(reduced_runs):
    d = reduced_runs
    res = cli("compare", d / "a.h5", d / "b.h5", d / "c.h5")
    assert res.returncode == 1, res.stderr
    out = res.stdout
    assert "contact.restitution: 0.8, 0.8, 0.6" in out and "results: differ from a.h5: c.h5" in out
    rows = {ln.split()[0]: ln for ln in out.splitlines() if ln.endswith(("*", "  ")) or ".h5 " in ln}
    assert "*" in rows["c.h5"] and "*" not in rows["b.h5"]  # the reduced model: SE 0, any change is real
    same = cli("compare", d / "a.h5", d / "b.h5", d / "a.h5")
    assert same.returncode == 0 and same.stdout.count("scenarios: identical") == 1, same.stdout  # it said it twice
    two = cli("compare", d / "a.h5", d / "c.h5")  # two archives: the bit-for-bit comparison as before
    assert two.returncode == 1 and "contact.restitution: 0.8 -> 0.6" in two.stdout and "differs: per_rotation/I_dec" in two.stdout


@pytest.mark.slow
def test_table_of_archives_and_its_refusals(reduced_runs, tmp_path):
    d = reduced_runs
    res = cli("table", d / "a.h5", d / "c.h5", "--columns", "I_dec_mean_Ns,first_impact_speed_m_s")
    assert res.returncode == 0, res.stderr
    head = res.stdout.splitlines()[0]
    assert head.split()[:2] == ["archive", "contact.restitution"] and "[mN s]" in head and "[m/s]" in head
    a = bearingsim.load(d / "a.h5")
    assert f"{a.summary['I_dec_mean_Ns'] * 1e3:.4g} ± 0" in res.stdout
    assert_user_error(cli("table", d / "a.h5", "--columns", "I_dec_means"), "--columns", "I_dec_means")
    assert_user_error(cli("table", tmp_path), str(tmp_path), "sweep.h5")
    assert_user_error(cli("table", d / "nope.h5"), "nope.h5")


def test_a_table_of_archives_keeps_the_order_given_and_names_its_reference_row(reduced_runs, capsys):
    """`bearingsim table A.h5 B.h5 C.h5` marks each mean against x_ref, "the first row with a number", which
    the table did not name (a shell's cases/*.h5 gives the archives sorted by name, so which row it was went
    unsaid). The rows keep the order given, the help says the first is the reference, and the line under the
    rule names that row."""
    from bearingsim.cli import main

    d = reduced_runs
    for order in (("c", "a", "b"), ("b", "c", "a")):
        out = tables.format_paths([d / f"{n}.h5" for n in order]).splitlines()
        assert [ln.split()[0] for ln in out[1:4]] == [f"{n}.h5" for n in order], out
        assert out[-1] == f"x_ref: the row {order[0]}.h5 (the first archive given)", out
    with pytest.raises(SystemExit):
        main(["table", "--help"])
    assert "the first is the reference of the marks" in " ".join(capsys.readouterr().out.split())


def test_a_table_of_archives_marks_and_lists_the_notes_they_store(reduced_runs, tmp_path):
    """`bearingsim table A.h5 B.h5` ignored the notes the archives store (/bearingsim/notes); it marks the
    rows with notes [1], [2] ... in a notes column and lists them under the table, as `table DIR` does."""
    noted = tmp_path / "n.h5"
    sc = bearingsim.load_scenario(PAPER, set={"bearing.pocket_clearance_mm": 0.3})
    with pytest.warns(UserWarning, match="outside the range the preset's sensitivity studies sample"):  # the run's note
        bearingsim.run(sc).save(noted)
    assert bearingsim.load(noted).notes
    lines = tables.format_table(tables.table_of_archives([reduced_runs / "a.h5", noted])).splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("archive"))
    assert lines[head].split()[:2] == ["archive", "bearing.pocket_clearance_mm"] and "notes" in lines[head].split()
    assert "[1]" not in lines[head + 1] and "[1]" in lines[head + 2]
    assert lines[head + 3].startswith("notes: the runs' notes (of a run that is plausible but not clean")
    assert lines[head + 4].startswith("[1] bearing.pocket_clearance_mm = 0.3"), lines
    assert tables.table_of_archives([reduced_runs / "a.h5"]).footnotes == {}


def test_the_columns_a_refusal_lists_are_the_columns_accepted(reduced_runs):
    """`table A B --columns X` with an unknown X listed the runs' numbers but left out I_dec_sem_Ns and
    I_acc_sem_Ns, which --columns accepts. The refusal lists tables.column_keys: every name it lists is
    accepted, and every number of the table (what --columns accepts) is listed."""
    from bearingsim.errors import UserError

    table = tables.table_of_archives([reduced_runs / "a.h5", reduced_runs / "c.h5"])
    with pytest.raises(UserError) as err:
        tables.format_table(table, columns=["I_dec_mean_Ns", "nope"])
    message = str(err.value)
    assert message.startswith("--columns: nope: not a number of these runs (they have: ") and message.endswith(")")
    listed = message.split("(they have: ", 1)[1][:-1].split(", ")
    assert "I_dec_sem_Ns" in listed and "I_acc_sem_Ns" in listed
    assert sorted(listed) == sorted(table.numbers) == sorted(tables.column_keys(table))
    for key in listed:  # each accepted alone: a header and one cell per run
        lines = tables.format_table(table, columns=[key]).splitlines()
        i = next(i for i, line in enumerate(lines) if line.startswith("archive"))
        assert tables._bare(key) in lines[i] and lines[i + 1].startswith("a.h5 ") and lines[i + 2].startswith("c.h5 ")


def test_columns_takes_the_names_the_table_shows(reduced_runs):
    """The table's header names its columns `I_dec_mean [mN s]`, `first_impact_speed [m/s]` (and docs/commands.md
    calls them so), but `--columns I_dec_mean` was refused ("not a number of these runs"): only the summary key
    with its unit suffix, `I_dec_mean_Ns`, was taken. The name the header shows is taken for that key, giving
    the same table; a name that is neither is still refused in one line."""
    from bearingsim.errors import UserError

    table = tables.table_of_archives([reduced_runs / "a.h5", reduced_runs / "c.h5"])
    keys = ["I_dec_mean_Ns", "first_impact_speed_m_s", "I_dec_sem_Ns", "load_zone_half_angle_deg"]
    shown = ["I_dec_mean", "first_impact_speed", "I_dec_sem", "load_zone_half_angle"]
    assert tables.format_table(table, columns=shown) == tables.format_table(table, columns=keys)
    assert tables.format_paths([reduced_runs / "a.h5"], columns=["I_acc_mean"]) == tables.format_paths(
        [reduced_runs / "a.h5"], columns=["I_acc_mean_Ns"])
    with pytest.raises(UserError, match="--columns: I_dec_means: not a number of these runs"):
        tables.format_table(table, columns=["I_dec_means"])


@pytest.mark.slow
def test_table_labels_archives_of_one_name_in_different_folders_apart(reduced_runs, tmp_path):
    """Two sweeps' ``cases/<hash>.h5`` (one file name in two folders) were both labelled ``<hash>.h5``:
    a label is the file name where that is unique, else the shortest ending of the path no other
    archive shares."""
    import shutil

    d = reduced_runs
    for sweep, src in (("sw1", "a.h5"), ("sw2", "c.h5")):
        (tmp_path / sweep / "cases").mkdir(parents=True)
        shutil.copy(d / src, tmp_path / sweep / "cases" / "0123abcd.h5")
    res = cli("table", tmp_path / "sw1" / "cases" / "0123abcd.h5", tmp_path / "sw2" / "cases" / "0123abcd.h5",
              d / "b.h5", "--columns", "I_dec_mean_Ns")
    assert res.returncode == 0, res.stderr
    labels = [ln.split()[0] for ln in res.stdout.splitlines()[1:4]]
    assert labels == ["sw1/cases/0123abcd.h5", "sw2/cases/0123abcd.h5", "b.h5"], res.stdout
    assert tables.distinguishing_labels(["a.h5", "b.h5"]) == ["a.h5", "b.h5"]  # unique names unchanged
    assert tables.distinguishing_labels(["x/c.h5", "x/c.h5"]) == ["c.h5", "c.h5"]  # the same file twice


@pytest.mark.slow
def test_sweep_prints_its_table_and_table_of_the_folder_is_the_same(tmp_path):
    out = tmp_path / "sw"
    res = cli("sweep", PAPER, "--param", "operating.inner_ring_speed_rpm=1000,3000", "-o", out, "-j", "1", "--no-plots")
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    (i,) = [k for k, ln in enumerate(lines) if ln.startswith("operating.inner_ring_speed_rpm")]
    assert "I_dec_mean [mN s]" in lines[i] and lines[i + 1].startswith("1000 ") and lines[i + 2].startswith("3000 ")
    table = cli("table", out)
    assert table.returncode == 0 and lines[i:i + 4] == table.stdout.splitlines()[1:5]
    assert tables.REDUCED_EXACT in table.stdout.splitlines()  # a reduced sweep's table says what its '± 0' is
    quiet = cli("sweep", PAPER, "--param", "operating.inner_ring_speed_rpm=1000,3000", "-o", out, "-j", "1",
                "--no-plots", "-q")
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == ""


@pytest.mark.slow
def test_table_of_a_validate_folder_prints_its_fig9_and_rig_tables(tmp_path):
    """`bearingsim table DIR` of a validate folder printed its case index: 41 cases in the order they ran,
    the rig rows with "drag nan", every `*` against the first Fig. 9 case (500 rpm, c = 0.01). It prints
    validate's own tables: the Fig. 9 analog (speed against the drag coefficients and the previous model)
    and the rig table as `bearingsim validate` printed it; the case index is `table DIR/sweep.h5`."""
    out = tmp_path / "v"
    res = cli("validate", "--rig-rotations", "1", "-j", "2", "-o", out)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith("rig scene"))
    rig = lines[i:i + 7]  # the heading, the column names and the 5 speeds
    table = cli("table", out)
    assert table.returncode == 0, table.stderr
    printed = table.stdout.splitlines()
    assert "nan" not in table.stdout and "*" not in table.stdout and "drag" not in table.stdout
    assert printed[0].startswith(f"{out}: validate")
    j = printed.index(rig[0])
    assert printed[j:j + 7] == rig
    (k,) = [k for k, ln in enumerate(printed) if ln.startswith("Fig. 9 analog")]
    assert printed[k + 1].split() == ["rpm", "c", "=", "0.01", "c", "=", "0.02", "c", "=", "0.03", "previous", "c", "=",
                                      "0.02"]
    with open(out / "fig9_idec_vs_speed.csv", newline="") as fh:
        first = next(csv.DictReader(fh))
    assert printed[k + 2].split() == ["500", *(f"{float(first[c]) * 1e3:.3f}" for c in list(first)[1:])]
    assert len(printed[k + 2:j]) >= 9  # the 9 speeds (then a blank line or a note before the rig table)
    # validate itself printed the same Fig. 9 table (it printed only the rig table, though docs/validation.md
    # gives the Fig. 9 numbers as printed by it)
    f = lines.index(printed[k])
    assert lines[f:f + 11] == printed[k:k + 11]  # the heading, the column names and the 9 speeds
    index = cli("table", out / "sweep.h5")
    assert index.returncode == 0 and index.stdout.splitlines()[1].split()[:4] == ["study", "rpm", "drag", "variant"]


# --- progress only on a terminal ------------------------------------------------------------------

def _validate_on_a_terminal(tmp_path, *extra):
    """``bearingsim validate --rig-rotations 0`` (36 reduced cases) with stderr on a pseudo-terminal:
    (exit code, what the terminal got, stdout)."""
    import pty

    master, slave = pty.openpty()
    got = []

    def read():
        while True:
            try:
                chunk = os.read(master, 4096)
            except OSError:
                return
            if not chunk:
                return
            got.append(chunk)

    cmd = [sys.executable, "-m", "bearingsim", "validate", "--rig-rotations", "0", "-j", "1",
           "-o", str(tmp_path / "v"), *extra]
    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    with started(cmd, stdout=subprocess.PIPE, stderr=slave, text=True) as proc:
        os.close(slave)
        out, _ = proc.communicate(timeout=600)
    reader.join(timeout=10)
    os.close(master)
    return proc.returncode, b"".join(got).decode("utf-8", "replace"), out


@pytest.mark.slow
def test_validate_shows_progress_on_a_terminal_and_not_with_q(tmp_path):
    rc, term, out = _validate_on_a_terminal(tmp_path)
    assert rc == 0 and "fig9" in term and "36/36" in term and "case" in term, term
    assert "wrote" in out
    rc, term, out = _validate_on_a_terminal(tmp_path, "-q")
    assert rc == 0 and term == "" and out == "", (term, out)


@pytest.mark.slow
def test_no_progress_text_when_stderr_is_not_a_terminal(tmp_path):
    res = cli("validate", "--rig-rotations", "0", "-j", "1", "-o", tmp_path / "v")
    assert res.returncode == 0, res.stderr
    assert "\r" not in res.stderr and "case/s" not in res.stderr and "%|" not in res.stderr, res.stderr


def test_a_table_of_one_archive_says_nothing_of_scenarios_it_compares(reduced_runs):
    """`table a.h5` printed "scenarios: identical" under a one-row table, a comparison with nothing;
    two archives of one scenario still say so."""
    one = tables.format_table(tables.table_of_archives([reduced_runs / "a.h5"]))
    two = tables.format_table(tables.table_of_archives([reduced_runs / "a.h5", reduced_runs / "b.h5"]))
    assert "scenarios: identical" not in one and "scenarios: identical" in two


def test_compare_shows_a_number_only_one_model_has_as_absent_not_nan():
    """`compare` of a reduced and a multibody archive showed the multibody model's own numbers (cage slip,
    steps, pockets) against "nan" for the reduced one, as if it had computed a NaN: the side without the
    number says (none), no difference is printed, and the row is still marked as differing."""
    from bearingsim.compare import compare_results

    def result(model, summary):
        return SimpleNamespace(scenario=SimpleNamespace(raw={"model": model}), summary=summary, data={}, groups={},
                               provenance={})

    c = compare_results(result("reduced", {"I_dec_mean_Ns": 0.005}),
                        result("multibody", {"I_dec_mean_Ns": 0.015, "cage_slip": -0.001}))
    assert c.absent == {"cage_slip": "A"} and "cage_slip" in c.summary_differs and not c.identical
    (row,) = [line for line in c.summary_table().splitlines() if line.startswith("cage_slip")]
    assert row.split() == ["cage_slip", "(none)", "-0.001", "*"]


def test_compare_of_two_says_what_its_mark_means():
    """`compare A B` marks a number that is not bit-identical, however small the difference (-0.07 % of the
    cage orbit is marked); `table` and `compare A B C` mark significance with a legend. The two-archive
    table says what its mark means and where significance is judged; bit-identical results get no legend."""
    from bearingsim.compare import compare_results

    def result(summary):
        return SimpleNamespace(scenario=SimpleNamespace(raw={"model": "multibody"}), summary=summary,
                               data={}, groups={}, provenance={})

    c = compare_results(result({"cage_orbit_max_m": 1.0e-4, "I_dec_mean_Ns": 0.015}),
                        result({"cage_orbit_max_m": 0.9993e-4, "I_dec_mean_Ns": 0.015}))
    lines = c.summary_table().splitlines()
    assert [line.split()[0] for line in lines if line.endswith("*")] == ["cage_orbit_max_m"]
    assert lines[-1].startswith("* : not bit-identical, however small the difference;")
    assert "bearingsim table A B" in lines[-1]
    same = compare_results(result({"I_dec_mean_Ns": 0.015}), result({"I_dec_mean_Ns": 0.015}))
    assert same.identical and not any("*" in line for line in same.summary_table().splitlines())


def test_compare_of_a_zero_shows_no_change_or_a_change_from_zero_not_nan():
    """`compare A B` of a reduced run at 3000 rpm (event) and one at 500 rpm (euler) printed
    `I_dec_std_Ns 0 0 0 nan` and `I_acc_mean_Ns 0 0.00874 0.00874 nan *`: the relative change divided by
    |A| = 0. Two zeros are no change (0, as for any two equal numbers); a change from zero says so, its size
    in the B - A column."""
    from bearingsim.compare import compare_results

    def result(summary):
        return SimpleNamespace(scenario=SimpleNamespace(raw={"model": "reduced"}), summary=summary,
                               data={}, groups={}, provenance={})

    c = compare_results(result({"I_dec_std_Ns": 0.0, "I_acc_mean_Ns": 0.0, "I_dec_mean_Ns": 0.00528}),
                        result({"I_dec_std_Ns": 0.0, "I_acc_mean_Ns": 0.00874, "I_dec_mean_Ns": 0.01288}))
    table = c.summary_table()
    rows = {line.split()[0]: line.split() for line in table.splitlines()[1:]}
    assert "nan" not in table and "inf" not in table, table
    assert rows["I_dec_std_Ns"] == ["I_dec_std_Ns", "0", "0", "0", "0"]
    assert rows["I_acc_mean_Ns"] == ["I_acc_mean_Ns", "0", "0.00874", "0.00874", "from", "0", "*"]
    assert rows["I_dec_mean_Ns"][4:] == [f"{(0.01288 - 0.00528) / 0.00528:.3g}", "*"]


def test_a_folder_of_nothing_names_every_folder_table_reads(tmp_path):
    """`bearingsim table EMPTY_DIR` said "give the folder of a sweep, cross-check or validate run, or archives",
    leaving out the sensitivity, uncertainty and life folders whose tables it prints as well."""
    from bearingsim.errors import UserError

    with pytest.raises(UserError) as err:
        tables.format_paths([tmp_path])
    assert str(err.value).startswith(f"{tmp_path}: holds no sweep.h5")
    for kind in tables.STUDY_NAMES.values():
        assert kind in str(err.value), kind


def test_the_cage_slip_is_shown_in_per_cent_with_its_unit():
    """The tables' cage_slip column had no unit in its header, beside columns that all have theirs, and showed
    the fraction (0.004086); it is a percentage, headed cage_slip [%] (0.4086), in `bearingsim table` and the
    report's tables alike (one function, tables.column_cells); `--columns` still names it cage_slip."""
    t = tables.Table(["run"], {"run": ["a", "b"]}, {"cage_slip": np.array([0.00408585, -0.0012])}, {"cage_slip": "1"})
    head, cells = tables.column_cells(t, "cage_slip")
    assert head == "cage_slip [%]" and cells == ["0.4086", "-0.12"], (head, cells)
    lines = tables.format_table(t, columns=["cage_slip"]).splitlines()
    assert "cage_slip [%]" in lines[0] and lines[1].split() == ["a", "0.4086"], lines


@pytest.mark.parametrize("v, e, text", [(18.3, 0.17, "18.30 ± 0.17"), (14.407, 0.0095, "14.4070 ± 0.0095"),
                                        (15.6, 0.7, "15.60 ± 0.70"), (18.3, 2.5, "18.3 ± 2.5"),
                                        (1834.2, 25.0, "1834 ± 25"), (1234.5, 170.0, "1230 ± 170"),
                                        (15.19, 3.1e31, "15.19 ± 3.1e+31"),
                                        (5.28, 0.0, "5.28 ± 0"), (5.28, math.nan, "5.28 ± n/a"),
                                        (0.5, 1e-12, "0.5 ± 1e-12")])
def test_a_value_is_shown_to_its_errors_decimal_place(v, e, text):
    """"18.3 ± 0.17" hid that the mean's second decimal means something (18.30): the value is shown to the
    decimal place of its error's second significant digit, trailing zeros kept; an error of 0 (the reduced
    model's), none, one far below the value (beyond 10 decimals) or a huge one keep the value's 4 digits."""
    from bearingsim.tables import with_error

    assert with_error(v, e) == text


@pytest.mark.slow
def test_a_table_of_both_models_says_what_the_reduced_models_zero_error_is(tmp_path):
    """A table of a reduced and a whole-bearing archive put "5.28 ± 0" beside "14.76 ± 0.25 *" without a word: it
    says the reduced model's ± 0 is its exactness and a mark is the models' difference; one model's table does
    not."""
    import bearingsim
    from bearingsim.tables import MIXED_MODELS, REDUCED_EXACT, format_table, table_of

    red, whole = tmp_path / "r.h5", tmp_path / "m.h5"
    bearingsim.run(bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml")).save(red)
    bearingsim.run(bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml",
                                            set={"numerics.rotations": 2, "multibody.raceway_contact": "rigid"})
                   ).save(whole)
    assert MIXED_MODELS in table_of([red, whole]).notes
    assert MIXED_MODELS not in table_of([whole, whole]).notes and MIXED_MODELS not in table_of([red]).notes
    # the reduced model's own table says it too, in its own words (every '± 0', every mark a real difference)
    assert table_of([red, red]).exact and REDUCED_EXACT in format_table(table_of([red, red])).splitlines()
    assert not table_of([red, whole]).exact and not table_of([whole]).exact
    assert REDUCED_EXACT not in format_table(table_of([red, whole]))


def test_rows_whose_notes_differ_in_their_numbers_only_share_one_mark():
    """A table's rows each had their own note mark when their notes differed in a number only (the warm-up note
    gives each run's own rotations): four runs gave four footnotes of ~400 characters that differ in a few digits.
    Rows whose notes are of one kind share a mark, whose footnote is the first row's, saying the others differ in
    their numbers; notes in other words keep their own mark, and notes alike read as before."""
    names, labels = ["run"], {"run": ["a", "b", "c", "d", "e"]}
    found = [["first rotation +3.2% off (t = 5.0)"], [], ["first rotation -6.5% off (t = 40.5)"], ["k is high"],
             ["k is high"]]
    notes = tables._run_notes(found, names, labels)
    assert labels["notes"] == ["[1]", "", "[1]", "[2]", "[2]"]
    assert notes == {0: "[1] first rotation +3.2% off (t = 5.0) (the numbers of the first row marked [1]; the others "
                        "differ in theirs)",
                     3: "[2] k is high"}


def test_a_key_a_case_does_not_set_is_shown_as_missing_not_as_nan():
    """validate's index labels its cases by study, rpm, drag and variant, and its rig cases set no drag (NaN) and no
    variant (""): `bearingsim table DIR/sweep.h5` and `bearingsim wear DIR` printed "nan" in the drag column, and
    the report's case notes "study = rig, rpm = 500, drag = nan, variant = ". The table prints "-", as it does a
    missing number, and the report names only what the case sets."""
    import numpy as np

    from bearingsim.reports import _case_values
    from bearingsim.wording import distinct_texts

    drag = [0.01, 0.02, float("nan"), np.float64("nan")]
    assert distinct_texts(drag) == ["0.01", "0.02", "-", "-"]
    assert distinct_texts([970.000001, 970.000002, float("nan")]) == ["970.000001", "970.000002", "-"]
    cols = {"case": ["a", "b"], "study": ["fig9", "rig"], "rpm": np.array([500.0, 500.0]),
            "drag": np.array([0.02, np.nan]), "variant": ["present", ""]}
    meta = {"axes": ["study", "rpm", "drag", "variant"]}
    assert _case_values(cols, meta) == ["study = fig9, rpm = 500, drag = 0.02, variant = present",
                                        "study = rig, rpm = 500"]
