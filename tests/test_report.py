"""`bearingsim report PATH -o report.html`: one self-contained HTML page, opened in a real browser.

The browser is the distribution's Chromium (/usr/bin/chromium, Debian's package `chromium`) driven by
playwright; without it these tests FAIL, saying how to install it (the README's test command does).
"""
import dataclasses
import os
import re
from html import unescape
from pathlib import Path

import numpy as np
import pytest

import bearingsim

from .conftest import ROOT, SCENARIOS
from .test_cli import assert_user_error, bearingsim as cli

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
PAPER = SCENARIOS / "paper_3000rpm.toml"
#: where the full-page screenshot of a report test is kept when BEARINGSIM_KEEP_SCREENSHOT is set (a test never
#: writes into the checkout by itself: it may not be the user's to write to)
KEPT_SCREENSHOT = ROOT / "outputs" / "report_screenshot.png"


# --- the browser --------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def browser():
    """A headless Chromium for the module, or the one line saying why there is none (each test that
    needs it fails with that line: a missing browser is not a skipped test)."""
    if not CHROMIUM.is_file():
        yield (f"{CHROMIUM} not found: the report tests open the page in the distribution's Chromium; install it "
               f"with 'bash .ci/browser' (Debian's chromium package, as the README's test command does) and run the tests again")
        return
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        yield "playwright is not installed: pip install -e '.[test]' (the test extra brings it)"
        return
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            yield b
        finally:
            b.close()


def open_page(browser, path: Path, screenshot: Path | None = None) -> dict:
    """Open ``path`` offline (every request but the file itself refused) and return what it showed:
    console errors and failed requests, each image's ``naturalWidth``, the animation element's state,
    the section ids and the contents' link targets."""
    if isinstance(browser, str):
        pytest.fail(browser)
    context = browser.new_context(offline=True, viewport={"width": 1200, "height": 900})
    page = context.new_page()
    errors = []
    page.on("console", lambda m: errors.append(f"console {m.type}: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
    page.on("requestfailed", lambda r: errors.append(f"request failed: {r.url[:80]}"))
    page.goto(path.resolve().as_uri(), wait_until="load")
    seen = page.evaluate("""() => ({
        images: Array.from(document.images).map(i => ({id: i.id, complete: i.complete, width: i.naturalWidth,
                                                        src: i.src.slice(0, 22)})),
        video: (v => v ? {ready: v.readyState, width: v.videoWidth} : null)(document.querySelector('video#animation')),
        ids: Array.from(document.querySelectorAll('section[id]')).map(s => s.id),
        toc: Array.from(document.querySelectorAll('nav.toc a')).map(a => a.getAttribute('href')),
        external: Array.from(document.querySelectorAll('[src],[href]')).map(e => e.getAttribute('src') || e.getAttribute('href'))
                       .filter(u => !u.startsWith('data:') && !u.startsWith('#')),
        text: document.body.innerText,
        // wider than the window: the page scrolls sideways (a table past the page's edge hid its last columns)
        page_width: [document.documentElement.scrollWidth, window.innerWidth],
    })""")
    if screenshot is not None:
        screenshot.parent.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(screenshot), full_page=True)
        pdf = page.pdf(format="A4")  # what the browser's Print to PDF makes of the page (print styles)
        seen["pdf_pages"] = len(re.findall(rb"/Type\s*/Page[^s]", pdf)) if pdf.startswith(b"%PDF") else 0
    context.close()
    seen["errors"] = errors
    return seen


def assert_renders(seen: dict, sections: list[str]) -> None:
    """No console error, every image decoded, nothing outside the file, the contents linking every section."""
    assert seen["errors"] == []
    assert seen["images"], "no figure in the report"
    assert [i for i in seen["images"] if not (i["complete"] and i["width"] > 0)] == []
    assert all(i["src"].startswith("data:image/") for i in seen["images"])
    assert seen["external"] == []
    assert set(sections) <= set(seen["ids"])
    assert seen["toc"] == [f"#{s}" for s in seen["ids"]]
    assert seen["page_width"][0] <= seen["page_width"][1], f"the page is wider than the window: {seen['page_width']}"


# --- inputs -------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A folder with ``r.h5``: a reduced-model archive whose scenario name is markup (it must be shown
    as text)."""
    d = tmp_path_factory.mktemp("report")
    sc = bearingsim.load_scenario(PAPER, set={"name": "<img src=x onerror=alert(1)>"})
    bearingsim.run(sc).save(d / "r.h5")
    return d


@pytest.fixture(scope="module")
def whole(runs):
    """``runs/m.h5``: a whole-bearing archive (6000 rpm, 1 warm-up + 1 rotation)."""
    sc = bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml", set={"numerics.rotations": 1})
    bearingsim.run(sc).save(runs / "m.h5")
    return runs / "m.h5"


@pytest.mark.slow
def test_report_of_a_run_archive_renders_in_chromium(whole, browser, tmp_path):
    out = bearingsim.report(whole, tmp_path / "m.html")
    shot = KEPT_SCREENSHOT if os.environ.get("BEARINGSIM_KEEP_SCREENSHOT") else tmp_path / "report_screenshot.png"
    seen = open_page(browser, out, shot)
    assert_renders(seen, ["summary", "figures", "animation", "pockets", "checks", "scenario", "provenance"])
    figures = [i for i in seen["images"] if i["id"] != "animation"]
    assert len(figures) == len(bearingsim.load(whole).FIGURES) == 4  # forces, impulses, orbit, wear
    # the animation (bearingsim.animate of the archive's motion) decodes in the browser at the
    # frame size animation.py draws
    from bearingsim.animation import WIDTH_PX

    anim = [i for i in seen["images"] if i["id"] == "animation"]
    assert anim == [{"id": "animation", "complete": True, "width": WIDTH_PX, "src": "data:image/gif;base64,"}]
    assert shot.stat().st_size > 0
    assert seen["pdf_pages"] >= 4  # printable: contents, then 7 sections with 4 figures, over several A4 pages
    text = seen["text"]
    # the checks of bearingsim run, measured from this archive, every one passed
    assert "inner-ring displacement within the Palmgren bound" in text and "FAILED" not in text
    assert text.count("passed") >= 5
    assert 'name = "multibody_6000rpm"' in text  # the scenario as TOML
    assert "git_commit" in text and "version_numpy" in text  # the provenance
    assert not list(tmp_path.glob(".*tmp*"))


@pytest.mark.slow
def test_the_embedded_clip_is_the_last_half_rotation(whole, tmp_path):
    """The report embeds the last REPORT_CLIP_ROTATIONS cage rotations of the stored motion at
    REPORT_CLIP_FPS: decoded back from the page, the GIF has (rotations x 4 s x fps) frames; as MP4 it is a
    <video> element with the same frames."""
    import base64
    import io

    from PIL import Image

    from bearingsim import animation, reports

    html = bearingsim.report(whole, tmp_path / "a.html").read_text()
    data = re.search(r'id="animation"[^>]*src="data:image/gif;base64,([^"]+)"', html)
    data = data or re.search(r'src="data:image/gif;base64,([^"]+)"[^>]*id="animation"', html)
    im = Image.open(io.BytesIO(base64.b64decode(data.group(1))))
    want = round(reports.REPORT_CLIP_ROTATIONS * animation.SECONDS_PER_ROTATION * reports.REPORT_CLIP_FPS)
    assert im.n_frames == want == 30
    section = reports._animation_section(whole, "mp4")
    assert section.blocks[0]["element"] == "video" and section.blocks[0]["src"].startswith("data:video/mp4;base64,")


def test_the_page_on_the_report_says_what_clip_it_embeds():
    """docs/report.md said the animation is bearingsim.animate(archive, ...) "with its defaults" (the whole
    window at 30 fps); it names the clip's call and numbers, and they are the report's."""
    import inspect

    from bearingsim import animation, reports

    text = " ".join((ROOT / "docs" / "report.md").read_text().split())
    rot, fps = reports.REPORT_CLIP_ROTATIONS, reports.REPORT_CLIP_FPS
    assert "with its defaults, embedded" not in text
    assert f"the last {rot:g} cage rotation of the stored motion" in text and f"at {fps:g} frames per second" in text
    assert f"`bearingsim.animate(archive, out, last={rot:g}, fps={fps:g})`" in text
    frames = round(rot * animation.SECONDS_PER_ROTATION * fps)
    assert f"{frames / fps:g} s and {frames} frames" in text
    from bearingsim.simulation import animate  # bearingsim.animate(path, out, **kw) passes them on

    assert {"last", "fps"} <= set(inspect.signature(animate).parameters)


@pytest.mark.slow
def test_markup_in_a_scenario_name_is_shown_as_text(runs, browser, tmp_path):
    """Every value is autoescaped: a name that is an HTML tag adds no element (an unescaped <img src=x>
    would be an image that fails to load and a script that runs)."""
    out = bearingsim.report(runs / "r.h5", tmp_path / "r.html")
    html = out.read_text()
    assert "<img src=x" not in html and "&lt;img src=x onerror=alert(1)&gt;" in html
    seen = open_page(browser, out)
    assert_renders(seen, ["summary", "figures"])
    assert len(seen["images"]) == 1  # the reduced model's one figure (the pass), no injected image
    assert "<img src=x onerror=alert(1)>" in seen["text"]


def test_an_archive_without_motion_has_no_animation_section(runs):
    """A reduced-model archive holds no motion: no animation section, nothing rendered."""
    from bearingsim.reports import _animation_section

    assert _animation_section(runs / "r.h5") is None


@pytest.mark.slow
def test_the_same_archive_gives_the_same_bytes(runs, tmp_path):
    a = bearingsim.report(runs / "r.h5", tmp_path / "a.html").read_bytes()
    b = bearingsim.report(runs / "r.h5", tmp_path / "b.html").read_bytes()
    assert a == b


# --- folders ------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def folders(tmp_path_factory):
    """A reduced-model sweep (2 speeds, archives kept), sensitivity and uncertainty study (2 keys; N = 2:
    8 runs) and validate (its smallest run: 1 rig rotation), run; a cross-check and a life table written
    by their own writers from given rows (their runs take minutes)."""
    d = tmp_path_factory.mktemp("folders")
    res = cli("sweep", PAPER, "--param", "operating.inner_ring_speed_rpm=1000,3000", "--archives", "all",
              "-o", d / "sweep", "-j", "1", "-q")
    assert res.returncode == 0, res.stderr
    res = cli("sensitivity", PAPER, "--keys", "contact.restitution,lubrication.drag_coefficient", "-o", d / "sens",
              "-j", "1", "-q")
    assert res.returncode == 0, res.stderr
    res = cli("uncertainty", PAPER, "--keys", "contact.restitution,lubrication.drag_coefficient", "--samples", "2",
              "-o", d / "unc", "-j", "1", "-q")
    assert res.returncode == 0, res.stderr
    res = cli("validate", "--rig-rotations", "1", "-j", "2", "-o", d / "val", "-q")
    assert res.returncode == 0, res.stderr
    _crosscheck_table(d / "cc")
    _life_table(d / "life")
    return d


def _crosscheck_table(folder: Path) -> None:
    from bearingsim.studies import crosscheck as cc

    folder.mkdir(exist_ok=True)
    rows = [{"rpm": 3000.0, "rung": k, "scene": scene, "relaxed": what, "I_dec_mean_Ns": 5e-3 * k,
             "I_dec_sem_Ns": 2e-4, "I_acc_mean_Ns": 3e-3, "I_acc_sem_Ns": 1e-4, "first_impact_speed_m_s": 0.1,
             "cage_slip": 0.01, "archive": "", "wall_s": 1.0, "status": "done", "error": ""}
            for k, scene, what in cc.rungs()]
    cc.write_table(folder, cc.add_changes(rows), bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml"))


def _life_table(folder: Path, limit: str = "clearance=0.23mm", mapping: str = "test rows", notes=None) -> None:
    from bearingsim import archive
    from bearingsim.studies import life

    folder.mkdir()
    n = 3
    extra = {} if notes is None else {"notes": np.asarray(notes, dtype=object)}
    cols = {**extra, "stage": np.arange(n), "pocket_clearance_mm": [0.2, 0.21, 0.22], "stage_rotations": [1e6] * n,
            "rotations_end": [1e6, 2e6, 3e6], "hours_end": [10.0, 20.0, 30.0], "max_depth_rate_um_per_h": [1.0] * n,
            "max_volume_rate_mm3_per_h": [1e-3] * n, "max_depth_um": [10.0, 20.0, 30.0],
            "max_volume_mm3": [0.01, 0.02, 0.03], "clearance_end_mm": [0.21, 0.22, 0.23],
            "I_dec_mean_mNs": [14.0] * n, "pocket_worst_read": [1.2] * n, "pocket_worst_scatter": [1.18] * n,
            "pocket_uneven": [0] * n, "rate_sem_rel": [0.02] * n, "reused": [0] * n,
            "psi_deg": [np.linspace(-30.0, 25.0, 32)] * n,
            "worn_depth_front_um": np.full((n, 32, 16), 1.25), "worn_depth_rear_um": np.full((n, 32, 16), 2.5)}
    archive.write_table_file(folder / "life.h5", {k: np.asarray(v) for k, v in cols.items()}, life.LIFE_UNITS, {
        "format": life.LIFE_FORMAT, "limit": limit, "stages": n,
        "scenario": bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml").to_toml(), "mapping": mapping})


@pytest.mark.slow
@pytest.mark.parametrize("name, kind, words", [
    ("sweep", "sweep", ["inner_ring_speed_rpm", "2 cases: done 2", "I_dec_mean [mN s]",
                        # the provenance's case named by what it varies, not by its hash alone
                        "How the first case was made (operating.inner_ring_speed_rpm = 1000: cases/"]),
    ("sens", "sensitivity", ["contact.restitution", "lubrication.drag_coefficient", "d ln y / d ln x"]),
    ("unc", "uncertainty", ["Sobol indices", "2 base samples, 8 runs, seed 0", "contact.restitution"]),
    ("cc", "crosscheck", ["centred_cage", "largest change of I_dec"]),
    ("life", "life", ["clearance=0.23mm", "deepest [um]", "depth rate, fastest point [um/h]"]),
    ("val", "validate", ["Fig. 9 analog", "previous c = 0.02", "pocket 0 I_dec", "rig_idec_vs_speed.png"]),
])
def test_report_of_a_folder_renders_in_chromium(folders, browser, tmp_path, name, kind, words):
    from bearingsim.reports import kind_of

    assert kind_of(folders / name)[0] == kind
    res = cli("report", folders / name, "-o", tmp_path / f"{name}.html")
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == f"wrote {tmp_path / f'{name}.html'}"
    seen = open_page(browser, tmp_path / f"{name}.html")
    assert_renders(seen, ["table", "figures", "checks", "scenario"])
    for w in words:
        assert w in seen["text"], w


def test_a_wide_table_stays_on_the_page(browser, tmp_path):
    """A sweep of two text keys over the whole bearing's ten summary columns drew a table 1300 px wide in a page
    of 1100: the page scrolled sideways and its last columns (the wear rates) lay past the window's edge. A key's
    name may break after its "_" and "." (``<wbr>``, not inside a word), and a table still wider than the page
    scrolls in its place: the page is never wider than the window."""
    import json

    from bearingsim.sweeps.index import write_index

    keys = ["bearing.cage_guidance", "multibody.pocket_shape"]
    names = ["I_dec_mean_Ns", "I_acc_mean_Ns", "first_impact_speed_m_s", "cage_slip", "cage_rest_angle_deg",
             "load_zone_half_angle_deg", "wear_front_mean_mm3_per_h", "wear_rear_mean_mm3_per_h",
             "cage_orbit_max_m", "inner_ring_displacement_m"]
    rows = [{"case": f"c{i}", "values": {keys[0]: g, keys[1]: f}, "status": "done", "error": "", "archive": "",
             "wall_s": 1.0, "summary": {n: 0.0123456 + i for n in names} | {"I_dec_sem_Ns": 1.1e-5, "I_acc_sem_Ns": 2.2e-5}}
            for i, (g, f) in enumerate([(g, f) for g in ("outer_land", "inner_land") for f in ("arc", "flat")])]
    folder = tmp_path / "wide"
    folder.mkdir()
    write_index(folder, rows, keys, {"mode": "product", "grid": json.dumps(keys), "grid_rows": 4,
                                     "scenario": "scenarios/multibody_3000rpm.toml"})
    html = bearingsim.report(folder, tmp_path / "wide.html")
    assert "multibody.<wbr>pocket_<wbr>shape" in html.read_text()
    assert_renders(open_page(browser, html), ["table", "figures"])


@pytest.mark.slow
def test_a_folder_of_two_studies_shows_both_in_table_and_report(tmp_path):
    """`run_studies([CrossCheck(...), Fig9()], DIR)` (docs/sweeps.md) leaves two study tables in one folder;
    `table DIR` and `report DIR` showed the cross-check alone (the first table found), not the Fig. 9 one.
    Both show every study's table, in the order of tables.STUDY_TABLES, under a line naming them; a table
    file given alone is still that study alone. The cross-check's table is written by its own writer."""
    from bearingsim import tables
    from bearingsim.studies import fig9, make_engine, run_studies

    folder = tmp_path / "two"
    run_studies([fig9.Fig9(speeds=(3000,), drags=(0.02,))], folder, engine=make_engine(jobs=1))
    _crosscheck_table(folder)
    assert [k for k, _ in tables.studies_of(folder)] == ["crosscheck", "validate"]
    res = cli("table", folder)
    assert res.returncode == 0, res.stderr
    out = res.stdout
    assert out.splitlines()[0].startswith(f"{folder}: 2 studies' tables, each below: cross-check (crosscheck.h5), "
                                          f"validate ({fig9.CSV_NAME});")
    assert 0 < out.index(f"{folder / 'crosscheck.h5'}: cross-check") < out.index("Fig. 9 analog")
    value = fig9.read_fig9(folder / fig9.CSV_NAME)["I_dec_c0.02_Ns"][0]
    assert f"{value * 1e3:.3f}" in out and "largest change of I_dec" in out
    alone = cli("table", folder / fig9.CSV_NAME)
    assert alone.returncode == 0 and "Fig. 9 analog" in alone.stdout and "cross-check" not in alone.stdout
    assert_user_error(cli("table", folder, "--columns", "I_dec_mean_Ns"), "2 studies' tables", "sweep.h5")
    html = bearingsim.report(folder, tmp_path / "two.html").read_text()
    ids = re.findall(r'<section id="([^"]+)"', html)
    assert len(ids) == len(set(ids)), ids
    assert ids[:4] == ["crosscheck-table", "crosscheck-figures", "validate-table", "validate-figures"], ids
    assert "Fig. 9 analog" in html and "largest change of I_dec" in html and "centred_cage" in html


@pytest.mark.slow
def test_report_of_a_validate_folder_is_its_own_kind(folders, tmp_path):
    """A validate folder was reported as a sweep: "sweep of cases over study, rpm, drag, variant (41 cases)",
    one bar chart of every case, the rig rows with "drag nan", `*` marks against the first Fig. 9 case, and
    none of validate's figures or tables. It is a kind of its own: the Fig. 9 table and the rig table, the
    three figures validate drew (the same PNG bytes), then the cases, a case's scenario and provenance."""
    import base64

    from bearingsim import reports
    from bearingsim.studies import fig9, rig

    folder = folders / "val"
    assert reports.kind_of(folder) == ("validate", folder / fig9.CSV_NAME)
    listing = cli("inspect", folder)  # its first line names every table it lists, the rig's too
    assert listing.returncode == 0 and listing.stdout.startswith(
        f"{folder}: a sweep or study folder; its files below: {fig9.CSV_NAME}, {rig.CSV_NAME}, sweep.h5\n"), listing
    assert reports.kind_of(folder / "sweep.h5")[0] == "sweep"  # the case index alone, as for every study
    html = bearingsim.report(folder, tmp_path / "v.html").read_text()
    title = re.search(r"<h1>(.*?)</h1>", html).group(1)
    assert title.startswith("Validation against the paper") and "sweep" not in title
    for name in (fig9.PNG_NAME, *rig.FIGURE_NAMES):
        assert base64.b64encode((folder / name).read_bytes()).decode() in html, name
    tables = re.search(r'<section id="table">(.*?)</section>', html, re.S).group(1)
    assert "sweep_cases" not in html and " *<" not in html and "nan" not in tables and "drag" not in tables
    table = fig9.read_fig9(folder / fig9.CSV_NAME)
    assert f"<td class=\"num\">{table['I_dec_c0.02_Ns'][0] * 1e3:.4g}</td>" in html  # 500 rpm, c = 0.02
    rows = rig.read_rig(folder / rig.CSV_NAME)
    assert len(rows) == 5 and f"{rows[0]['pocket0_over_reduced']:.3g}" in html
    assert "name = &#34;rig_500rpm&#34;" in html  # the scenario: a rig case's, from its archive (escaped)
    assert "41 cases: done 41" in html


def test_a_users_picture_in_a_validate_folder_is_not_shown_as_its_figure(folders, tmp_path):
    """A validate folder's figures were picked by the PNG signature alone, so a user's picture saved under
    a figure's name was shown as the study's; only a PNG bearingsim drew (its mark) is."""
    import shutil

    from bearingsim.studies import fig9, rig, validate

    folder = tmp_path / "val"
    shutil.copytree(folders / "val", folder)
    assert validate.read_validate(folder).figures == [folder / n for n in (fig9.PNG_NAME, *rig.FIGURE_NAMES)]
    mine = folder / rig.FIGURE_NAMES[0]
    mine.write_bytes(b"\x89PNG\r\n\x1a\n" + b"\x00" * 64)  # a PNG signature, no mark of bearingsim's
    assert validate.read_validate(folder).figures == [folder / fig9.PNG_NAME, folder / rig.FIGURE_NAMES[1]]


def test_the_per_pocket_table_of_one_rotation_shows_no_standard_deviation(tmp_path):
    """A run of one recorded rotation was reported "mean and standard deviation over 1 recorded rotations"
    with a standard deviation of 0 in every pocket, a spread that one rotation cannot show; it says
    "1 recorded rotation" and shows "-" for the deviations, as for any number it cannot give."""
    def pocket_rows(rotations):
        r = bearingsim.run(bearingsim.load_scenario(PAPER, {"numerics.rotations": rotations}))
        path = r.save(tmp_path / f"r{rotations}.h5")
        html = bearingsim.report(path, tmp_path / f"r{rotations}.html").read_text()
        section = re.search(r'<section id="pockets">(.*?)</section>', html, re.S).group(1)
        return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", section))

    one = pocket_rows(1)
    assert "over 1 recorded rotation [mN s]" in one and "rotations [mN s]" not in one, one
    assert re.search(r" 0 [0-9.]+ - [0-9.]+ - ", one), one
    two = pocket_rows(2)
    assert "over 2 recorded rotations [mN s]" in two and re.search(r" 0 [0-9.]+ 0 [0-9.]+ 0 ", two), two


@pytest.mark.slow
def test_a_sweep_page_says_when_no_case_failed(tmp_path):
    """A sweep's page said "a failed case keeps its one-line error:" and nothing after the colon when no
    case had failed; it says no case failed, and lists the failed cases under that line when some did."""
    def checks_text(folder):
        html = bearingsim.report(folder, tmp_path / f"{folder.name}.html").read_text()
        section = re.search(r'<section id="checks">(.*?)</section>', html, re.S).group(1)
        return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", section))

    res = cli("sweep", PAPER, "--param", "operating.inner_ring_speed_rpm=500,1000", "-o", tmp_path / "ok", "-q",
              "--no-plots")
    assert res.returncode == 0, res.stderr
    text = checks_text(tmp_path / "ok")
    assert "2 cases: done 2." in text and "one-line error. No case failed." in text and "error:" not in text, text
    res = cli("sweep", PAPER, "--set", "operating.gravity=false", "--param",  # no drag, no gravity: fails as it runs
              "lubrication.drag_coefficient=0.02,0", "-o", tmp_path / "one_failed", "-q", "--no-plots")
    assert res.returncode == 1, res.stderr
    text = checks_text(tmp_path / "one_failed")
    assert "done 1, failed 1" in text and "one-line error: Failed cases" in text and "No case failed" not in text, text
    assert "no rear-face impact" in text


def test_a_sweep_pages_notes_marks_have_their_key_under_the_table(tmp_path):
    """A sweep page's table of cases marked rows [1] in its notes column with no key to them; the key (the
    case's notes, as `bearingsim table` lists them) follows the table."""
    import html as html_text

    res = cli("sweep", PAPER, "--param", "bearing.pocket_clearance_mm=0.2,0.3", "-o", tmp_path / "s", "-q",
              "--no-plots")
    assert res.returncode == 0, res.stderr
    html = bearingsim.report(tmp_path / "s", tmp_path / "s.html").read_text()
    section = re.search(r'<section id="table">(.*?)</section>', html, re.S).group(1)
    text = html_text.unescape(re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", section)))
    table, after = text.split("notes: the runs' notes (of a run that is plausible")
    assert "[1]" in table, text
    assert "[1] bearing.pocket_clearance_mm = 0.3" in after, text


@pytest.mark.slow
def test_a_table_file_reports_its_folder(folders):
    from bearingsim.reports import kind_of

    assert kind_of(folders / "sens" / "sensitivity.h5") == ("sensitivity", folders / "sens" / "sensitivity.h5")
    assert kind_of(folders / "sens" / "sweep.h5") == ("sweep", folders / "sens" / "sweep.h5")


# --- refusals -----------------------------------------------------------------------------------
@pytest.mark.slow
def test_not_a_bearingsim_path_is_one_line(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    assert_user_error(cli("report", tmp_path, "-o", tmp_path / "r.html"), str(tmp_path), "not a bearingsim archive")
    assert_user_error(cli("report", tmp_path / "notes.txt", "-o", tmp_path / "r.html"), "notes.txt")
    assert_user_error(cli("report", tmp_path / "missing.h5", "-o", tmp_path / "r.html"), "not found")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]  # nothing written


@pytest.mark.slow
def test_unwritable_outputs_are_one_line_and_keep_what_is_there(runs, tmp_path):
    src = runs / "r.h5"
    user = tmp_path / "mine.html"
    user.write_text("<html>my own page</html>")
    assert_user_error(cli("report", src, "-o", user), "mine.html", "not replaced")
    assert user.read_text() == "<html>my own page</html>"
    assert_user_error(cli("report", src, "-o", tmp_path / "r.pdf"), "must end in .html or .htm")  # both taken
    (tmp_path / "dir.html").mkdir()
    assert_user_error(cli("report", src, "-o", tmp_path / "dir.html"), "dir.html", "directory")
    assert_user_error(cli("report", src, "-o", user / "sub" / "r.html"), "cannot create the report's folder")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir.html", "mine.html"]


def test_the_default_report_goes_beside_what_it_reports(tmp_path, monkeypatch):
    """Without -o the page goes beside PATH, named after it, as the docs' examples write it: an archive
    X.h5 gives X.html, a folder DIR gives DIR.html beside it, "." its own name in the folder above. (It
    went to ./report.html: into whatever folder the command ran in, the same file for every report.)"""
    from bearingsim.reports import default_output

    (tmp_path / "outputs" / "sweep.v2").mkdir(parents=True)
    (tmp_path / "outputs" / "run.h5").write_bytes(b"")
    monkeypatch.chdir(tmp_path / "outputs")
    assert default_output("run.h5") == Path("run.html")
    assert default_output(tmp_path / "outputs" / "run.h5") == tmp_path / "outputs" / "run.html"
    assert default_output("sweep.v2") == Path("sweep.v2.html")  # a folder's name is kept whole
    assert default_output("sweep.v2/") == Path("sweep.v2.html")
    assert default_output(".") == tmp_path / "outputs.html"


@pytest.mark.slow
def test_report_without_output_writes_beside_the_archive(runs, tmp_path):
    import shutil

    shutil.copy(runs / "r.h5", tmp_path / "r.h5")
    res = cli("report", "r.h5", "--animation", "none", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "wrote r.html"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5", "r.html"]
    assert "<html" in (tmp_path / "r.html").read_text()


@pytest.mark.slow
def test_the_apis_report_without_output_goes_beside_the_archive(runs, tmp_path, monkeypatch):
    """`bearingsim.report(path)` wrote ./report.html in the folder Python ran in, where the command line
    and docs/report.md put the page beside PATH, named after it."""
    import shutil

    shutil.copy(runs / "r.h5", tmp_path / "r.h5")
    (tmp_path / "cwd").mkdir()
    monkeypatch.chdir(tmp_path / "cwd")
    assert bearingsim.report(tmp_path / "r.h5", animation=None) == tmp_path / "r.html"
    assert "<html" in (tmp_path / "r.html").read_text() and list((tmp_path / "cwd").iterdir()) == []


@pytest.mark.slow
def test_a_report_replaces_its_own_earlier_report(runs, tmp_path):
    out = tmp_path / "r.html"
    bearingsim.report(runs / "r.h5", out)
    first = out.stat().st_mtime_ns
    bearingsim.report(runs / "r.h5", out)
    assert out.stat().st_mtime_ns >= first and out.read_bytes().startswith(b"<!DOCTYPE html>\n<!-- bearingsim report")
    assert [p.name for p in tmp_path.iterdir()] == ["r.html"]  # no temporary file left


def test_the_template_ships_with_the_package():
    """pyproject's package-data names the templates: every file in bearingsim/templates matches it (a
    wheel without the template would fail at the first report)."""
    import fnmatch
    import tomllib

    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    patterns = meta["tool"]["setuptools"]["package-data"]["bearingsim"]
    files = [p.relative_to(ROOT / "bearingsim").as_posix() for p in (ROOT / "bearingsim" / "templates").iterdir()]
    assert files and all(any(fnmatch.fnmatch(f, pat) for pat in patterns) for f in files)
    assert "jinja2>=3.1" in meta["project"]["dependencies"]
    assert any(d.startswith("playwright") for d in meta["project"]["optional-dependencies"]["test"])


def test_a_check_that_fails_is_shown_as_failed(runs):
    """The checks table is measured, not a list of labels: an archive read back with a non-finite
    impulse (a crafted file: bearingsim run writes none) shows that check FAILED and says the archive
    does not pass, with the reason plausibility.check gives."""
    from bearingsim.reports import _checks_blocks

    result = bearingsim.load(runs / "r.h5")
    rows = _checks_blocks(result)[0]["rows"]
    assert [r["passed"] for r in rows] == [True, True]
    stored = result.data["results/per_rotation/I_dec"]  # its arrays are read-only: put in another, all NaN,
    result.data["results/per_rotation/I_dec"] = dataclasses.replace(stored, data=np.full_like(stored.data, np.nan))
    # as a damaged archive would give it
    blocks = _checks_blocks(result)
    assert [(r["name"], r["passed"]) for r in blocks[0]["rows"]] == [("summary numbers finite", True),
                                                                      ("I_dec and I_acc per rotation finite", False)]
    assert blocks[1]["text"].startswith("This archive does NOT pass the checks: non-finite I_dec per rotation")


def test_a_check_that_gives_a_note_is_not_called_passed(runs, monkeypatch):
    """A kept run whose warm-up and resting-place checks found something (they give notes; only the others
    refuse a run) read "Every check that could be made passed" under the rows marked FAILED; then FAILED
    for a warm-up bias of +0.11 %, the positive of a statistical test (is the first rotation still in the
    start's transient?), which the command line words as a note. The rows read "note", the verdict names
    them as noted, not failed, and points to the notes; FAILED stays for a check that failed."""
    from bearingsim import plausibility
    from bearingsim.reports import Section, _checks_blocks, render

    rows = [("summary numbers finite", "8 numbers", True), ("warm-up reached a steady state", "+34.4 %", False),
            ("cage rests in one place", "31.5 deg", False), ("cage speed steady", "not evaluated", None)]
    monkeypatch.setattr(plausibility, "checks_made", lambda result: rows)
    monkeypatch.setattr(plausibility, "check", lambda result: ["bearingsim: note: the first recorded rotation ..."])
    blocks = _checks_blocks(bearingsim.load(runs / "r.h5"))
    verdict = blocks[1]["text"]
    assert verdict.startswith("Noted (a finding, not a failure): warm-up reached a steady state; cage rests in "
                              "one place. No check that refuses a run failed"), verdict
    assert "Every check" not in verdict and "Did not pass" not in verdict
    assert "Not evaluated here, and no pass: cage speed steady" in verdict
    assert blocks[2]["items"] == ["the first recorded rotation ..."]
    html = render("r", "r.h5", "run", [Section("checks", "Checks", blocks)])
    assert html.count('<td class="noted">note</td>') == 2 and "FAILED" not in html
    rows[0] = ("summary numbers finite", "8 numbers; not finite: I_dec_mean_Ns", False)
    blocks = _checks_blocks(bearingsim.load(runs / "r.h5"))
    assert blocks[1]["text"].startswith("Did not pass: summary numbers finite. Noted (a finding, not a failure): ")
    html = render("r", "r.h5", "run", [Section("checks", "Checks", blocks)])
    assert html.count('<td class="fail">FAILED</td>') == 1 and html.count('<td class="noted">note</td>') == 2


def test_a_life_page_to_a_volume_limit_shows_the_volume_and_the_stages_notes(tmp_path):
    """A life study to a volume limit prints the volume it reads and the stages' run notes under its history;
    its report showed the depth columns and no note."""
    _life_table(tmp_path / "v", limit="volume=0.03mm3", notes=["", "k is high", "k is high"])
    html = bearingsim.report(tmp_path / "v", tmp_path / "v.html").read_text()
    text = re.sub(r"\s+", " ", re.search(r'<section id="table">(.*?)</section>', html, re.S).group(1))
    assert "largest volume [mm3]" in text and "volume rate [mm3/h]" in text and "deepest [um]" not in text
    assert "note (2 of 3 stages): k is high" in text


def test_a_life_page_states_the_life_and_the_stage_count_note_as_the_command_does(tmp_path):
    """The report of a life folder showed the limit and the history, but not the life itself, the study's answer:
    `bearingsim life` and `bearingsim table` print it first ("life of X to LIMIT: 30 ± 0.35 h = 3e+06 inner-ring
    rotations in 3 stages (±: ...)"), the page had it only inside its figure's title, a picture. Nor did it say
    what the command notes of a study with the worn shape fed back in few stages (the life read long). The page
    states both, in the command's words."""
    from bearingsim.studies import life

    _life_table(tmp_path / "l", mapping="shape")
    html = bearingsim.report(tmp_path / "l", tmp_path / "l.html").read_text()
    text = unescape(re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", re.search(r'<section id="table">(.*?)</section>',
                                                                          html, re.S).group(1))))
    cols, attrs = life.read_life(tmp_path / "l" / "life.h5")
    headline = life.life_headline(cols, "Life of multibody_6000rpm to clearance=0.23mm", attrs)
    assert headline.startswith("Life of multibody_6000rpm to clearance=0.23mm: 30 ± ") and " h = 3e+06 inner-ring" in headline
    assert headline in text, text[:400]
    assert life.format_history(cols, "Life of multibody_6000rpm to clearance=0.23mm", attrs).splitlines()[0] == headline
    assert "3 stages with the worn shape fed back" in text and "give --stages 20 or more" in text


@pytest.mark.slow
def test_the_life_history_of_a_report_is_the_table_the_command_prints(folders, tmp_path):
    """The report of a life folder put every column of life.h5 into its table, the worn-depth profiles
    (32 bins x 16 pockets a stage) as numpy's text ("[[1.25 1.25 ...") and the columns in the file's order;
    it is the table `bearingsim life` and `bearingsim table` print, a row per stage (the profiles are the
    figure's)."""
    from bearingsim.studies import life

    html = bearingsim.report(folders / "life", tmp_path / "l.html").read_text()
    table = re.search(r'<section id="table">(.*?)</section>', html, re.S).group(1)
    heads = [h.replace("<wbr>", "") for h in re.findall(r"<th(?:\s[^>]*)?>(.*?)</th>", table)]  # the text a reader sees
    assert heads == [h for _, h, _, _ in life.HISTORY_TABLE], heads
    assert "[[" not in table and "1.25" not in table and "..." not in table
    cols, _ = life.read_life(folders / "life" / "life.h5")
    for row in life.history_rows(cols):
        assert "".join(f"<td class=\"num\">{c}</td>" for c in row) in re.sub(r"\s+<", "<", table)


@pytest.mark.slow
def test_a_life_page_to_a_depth_limit_says_what_the_command_notes(tmp_path):
    """`bearingsim life --limit depth=...` notes under its history that the deepest point is an end bin's,
    so the rotations to that limit are those of the bin width (docs/wear.md): the page, which a reader takes
    instead of the command's output, must say it too, and what its mapping means; a clearance limit (read
    from volumes) gets no such note."""
    from bearingsim.studies import life

    _life_table(tmp_path / "depth", limit="depth=0.1mm", mapping="shape")
    html = bearingsim.report(tmp_path / "depth", tmp_path / "d.html").read_text()
    text = re.sub(r"\s+", " ", re.search(r'<section id="table">(.*?)</section>', html, re.S).group(1))
    assert "reads the deepest worn point" in text and "1.85 deg of psi wide" in text
    assert life.MAPPINGS["shape"] in text
    _life_table(tmp_path / "clearance", mapping="shape")
    html = bearingsim.report(tmp_path / "clearance", tmp_path / "c.html").read_text()
    assert "reads the deepest worn point" not in html


@pytest.mark.slow
def test_checks_an_archive_cannot_make_are_not_evaluated_not_passed(whole, tmp_path):
    """bearingsim run judges the warm-up from at least 4 recorded rotations and the cage-speed drift from the
    speeds at the start and end of the recording, which only a fresh run holds, and where the cage rests
    from at least 2 recorded rotations. Read back from a 1-rotation archive none can be made: the page must
    list all three as not evaluated, and its verdict must not say that every check passed (it said so,
    listing neither of the first two)."""
    from bearingsim.reports import _checks_blocks

    blocks = _checks_blocks(bearingsim.load(whole))
    rows = {r["name"]: r for r in blocks[0]["rows"]}
    assert rows["warm-up reached a steady state"]["passed"] is None
    assert "1 recorded rotation" in rows["warm-up reached a steady state"]["measured"]
    assert rows["cage speed steady (no drift over the recorded rotations)"]["passed"] is None
    assert rows["cage rests in one place"]["passed"] is None
    assert [r["passed"] for r in blocks[0]["rows"] if r["passed"] is not None] == [True] * 5
    assert not blocks[1]["text"].startswith("Every check passed") and "Not evaluated here" in blocks[1]["text"]
    html = bearingsim.report(whole, tmp_path / "c.html", animation=None).read_text()
    assert html.count('<td class="skip">not evaluated</td>') == 3


@pytest.mark.slow
def test_an_uncertainty_reports_its_spread_in_the_units_the_command_prints(tmp_path):
    """The report of an uncertainty folder gave the spread of I_dec and I_acc as bare numbers in N s
    (0.005934), under no unit, while the command and `table` print them in mN s (5.934 mN s); it gives
    them as the command does, with the unit."""
    from bearingsim.studies import uncertainty as unc

    res = cli("uncertainty", PAPER, "--keys", "contact.restitution", "--samples", "2", "-o", tmp_path / "unc",
              "-j", "1", "-q")
    assert res.returncode == 0, res.stderr
    html = bearingsim.report(tmp_path / "unc", tmp_path / "u.html").read_text()
    spreads = unc.read_table(tmp_path / "unc" / "uncertainty.h5")[1]
    cells = re.findall(r"<tr><td>(I_dec[^<]*)</td>((?:<td[^>]*>[^<]*</td>)+)</tr>", html)
    label, numbers = cells[0]  # the spread's row (the Sobol indices' rows follow)
    assert label == "I_dec [mN s]"
    median = re.findall(r">([^<]*)<", numbers)[0]
    spread = next(s for s in spreads if s["quantity"] == "I_dec")
    assert median == f"{spread['median'] * 1e3:.4g}"


# --- study pages say what they show --------------------------------------------------------------
@pytest.fixture(scope="module")
def small_studies(tmp_path_factory):
    """A reduced-model sensitivity study of one key (4 runs: the step and the half step) and a sweep of two
    drag coefficients whose second case fails as it runs (no drag, no gravity: no rear-face impact)."""
    d = tmp_path_factory.mktemp("small")
    res = cli("sensitivity", PAPER, "--keys", "contact.restitution", "--set", "numerics.rotations=1", "-o",
              d / "sens", "-j", "1", "-q")
    assert res.returncode == 0, res.stderr
    res = cli("sweep", PAPER, "--set", "operating.gravity=false", "--param", "lubrication.drag_coefficient=0.02,0",
              "-o", d / "sweep", "-j", "1", "-q", "--no-plots")
    assert res.returncode == 1, res.stderr
    return d


def _page(folder, out) -> str:
    return bearingsim.report(folder, out).read_text()


def _section_text(html, section) -> str:
    import html as html_text

    body = re.search(rf'<section id="{section}">(.*?)</section>', html, re.S).group(1)
    return html_text.unescape(re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", body)))


def test_a_deterministic_sensitivity_page_has_the_commands_caveat_and_no_standard_error(small_studies, tmp_path,
                                                                                         monkeypatch):
    """The reduced model has no standard error: its page showed "0.497 ± 0 (half step: -0.48)" as if the 0 were
    measured, under a caption "± one standard error", and a tornado chart titled "± 1 standard error (batch means
    over rotations)", without the command's line on what the half step says. The page shows S and S at half the
    step, no "±", the command's line under the table, and the chart claims no batch-means errors."""
    from bearingsim.studies import sensitivity as sens

    titles = []
    drawn = sens.plot_tornado
    monkeypatch.setattr(sens, "plot_tornado", lambda rows, title="": titles.append(title) or drawn(rows, title))
    html = _page(small_studies / "sens", tmp_path / "sens.html")
    text = _section_text(html, "table")
    assert "half step:" in text and "±" not in text.replace("(1 ± 10%)", ""), text
    assert sens.HALF_STEP_NOTE in text and "a deterministic model has no standard error" in text
    assert len(titles) == 1 and "batch means" not in titles[0] and "no standard error" in titles[0], titles


def test_a_sweep_pages_title_is_one_line_and_its_tables_note_ends_before_the_marks_key(small_studies, tmp_path):
    """The sweep's two-line figure title was the page's <title> and <h1>, its two lines run together
    ("... (2 cases) paper_3000rpm: reduced model ..."), and the table's note ran the marks' key into its
    sentence ("... paper_3000rpm.toml * : |x - x_ref| > ..."). The title is the first line, what the cases share
    a sentence under it; the note is a sentence, the key its own line."""
    import html as html_text

    html = _page(small_studies / "sweep", tmp_path / "sweep.html")
    title = html_text.unescape(re.search(r"<title>(.*?)</title>", html, re.S).group(1))
    h1 = html_text.unescape(re.search(r"<h1>(.*?)</h1>", html, re.S).group(1))
    assert "\n" not in title and "\n" not in h1, (title, h1)
    assert h1 == "sweep of paper_3000rpm over drag coefficient (2 cases)", h1
    assert "What the cases share: reduced model" in _section_text(html, "table")
    notes = [html_text.unescape(n) for n in re.findall(r'<p class="note">(.*?)</p>', html, re.S)]
    assert len(notes) == 2 and notes[0].endswith("of a sweep of " + str(PAPER) + "."), notes
    assert notes[1].startswith("* : |x - x_ref| >"), notes


def test_a_figure_caption_is_its_docstrings_first_paragraph_in_plain_words():
    """A run figure's caption took the first line of its docstring, so a first sentence that wrapped was cut
    mid-sentence on the page ("...; F_acc", "..., the mean", "...; each"). It is the whole first paragraph
    now, on one line, with the docstring's literals and cross-references as plain words."""
    from bearingsim.reports import figure_caption

    doc = """Fig. 9 analog: the impulse against speed, I_dec in
        :data:`~bearingsim.plotting.REAR` as ``bearingsim run`` prints it, with
        :func:`bearingsim.stats.batch_sem`.

        Details that are not the caption."""
    assert figure_caption(doc, "x") == ("Fig. 9 analog: the impulse against speed, I_dec in REAR as bearingsim run "
                                        "prints it, with batch_sem.")
    assert figure_caption(None, "orbit") == "orbit"


@pytest.mark.slow
def test_a_run_page_captions_each_figure_with_a_whole_sentence(runs, whole, tmp_path):
    """Each figure of a run's page (whole bearing and reduced model) is captioned with its plot method's
    first paragraph, a whole sentence in plain words."""
    import html as html_text
    import inspect

    for archive in (whole, runs / "r.h5"):
        result = bearingsim.load(archive)
        got = [html_text.unescape(c) for c in
               re.findall(r"<figcaption>(.*?)</figcaption>", _page(archive, tmp_path / "p.html"), re.S)]
        want = [" ".join(inspect.cleandoc(getattr(result, f"plot_{n}").__doc__).split("\n\n")[0].split())
                for n in result.FIGURES]
        assert got[:len(want)] == [w.replace("``", "") for w in want], got
        assert all(c.endswith(".") and ":data:" not in c and "``" not in c for c in got), got


@pytest.mark.slow
def test_a_run_page_heads_its_summary_with_the_numbers_bearingsim_run_prints(runs, whole, tmp_path):
    """The summary of a run's page began with every number of /results/summary in SI (0.0180909 N s), where
    `bearingsim run` prints the headline numbers in mN s with their standard errors: the page now heads its
    summary with those words (tables.headline, which the command line prints from too)."""
    from bearingsim.tables import headline

    for archive, words in ((whole, "mN s per pocket and cage rotation; no standard error from 1 recorded rotation"),
                           (runs / "r.h5", "mN s per pocket and cage rotation")):
        summary = _section_text(_page(archive, tmp_path / "p.html"), "summary")
        rows = headline(bearingsim.load(archive))
        assert [key for key, *_ in rows][:2] == ["I_dec_mean_Ns", "I_acc_mean_Ns"]
        assert summary.index("Headline numbers") < summary.index("Summary numbers (SI")
        for key, _, _, said in rows:
            assert said == "" or said in summary, (key, said, summary)
        assert rows[0][3].endswith(words), rows[0]


def test_a_studys_figures_have_captions_saying_what_they_show(small_studies, tmp_path):
    """A run's page captions each figure with what it shows; a study's captioned them with their file names
    ("sweep I", "sensitivity"). Each says what it shows, and the reduced model's tornado chart that it has no
    error bars."""
    from bearingsim import reports
    from bearingsim.sweeps.plot import FIGURE_NAMES

    sweep = re.findall(r"<figcaption>(.*?)</figcaption>", _page(small_studies / "sweep", tmp_path / "w.html"))
    assert len(sweep) == 1 and "per pocket and cage rotation against the first swept key" in sweep[0], sweep
    assert sweep == [reports.SWEEP_CAPTIONS["sweep_I.png"]]
    sens = re.findall(r"<figcaption>(.*?)</figcaption>", _page(small_studies / "sens", tmp_path / "s.html"))
    assert len(sens) == 1 and sens[0].startswith("Tornado chart: the change of ln I_dec"), sens
    assert "no error bars: a deterministic model has no standard error" in sens[0]
    assert set(reports.SWEEP_CAPTIONS) == set(FIGURE_NAMES)  # a caption for every figure a sweep draws


def test_a_damaged_file_is_refused_saying_what_is_wrong_with_it(runs, tmp_path):
    """`report` of a truncated archive said it was "not a bearingsim archive, nor a sweep, ... folder (no
    sweep.h5, ... in it)", words for a folder, where `animate` and `inspect` said the file was truncated. A
    file given to report is refused with what the commands that read an archive say is wrong with it."""
    data = (runs / "r.h5").read_bytes()
    (tmp_path / "trunc.h5").write_bytes(data[:len(data) // 2])
    (tmp_path / "empty.h5").write_bytes(b"")
    for name, words in (("trunc.h5", "truncated file"), ("empty.h5", "not an HDF5 file")):
        res = cli("report", tmp_path / name, "-o", tmp_path / "r.html")
        assert_user_error(res, f"{tmp_path / name}: ", words)
        assert "folder" not in res.stderr and "in it" not in res.stderr, res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty.h5", "trunc.h5"]


def test_a_failed_case_is_listed_with_its_values(small_studies, tmp_path):
    """A sweep page's "Failed cases" table listed each failed case by its hash alone, where the table of the
    cases' notes beside it names the values too; it names them (the case with no drag failed)."""
    html = _page(small_studies / "sweep", tmp_path / "f.html")
    table = re.search(r"<caption>Failed cases</caption>(.*?)</table>", html, re.S).group(1)
    assert [h for h in re.findall(r"<th>(.*?)</th>", table)] == ["case", "values", "error"], table
    cells = re.findall(r"<td[^>]*>(.*?)</td>", table)
    assert len(cells) == 3 and cells[1] == "lubrication.drag_coefficient = 0", cells


def test_the_crosscheck_page_gives_slip_in_per_cent_and_impulses_as_the_table_does(tmp_path):
    """The cross-check page's slip column was a bare fraction (0.01 for 1 %) where ``bearingsim table`` and the
    command's own table give per cent, and its impulses "5 ± 0.2" where the table gives "5.00 ± 0.20": the same
    quantity reads the same on every page."""
    from bearingsim import reports

    _crosscheck_table(tmp_path)
    _, sections, _ = reports._crosscheck_sections(tmp_path / "crosscheck.h5")
    block = sections[0].blocks[0]
    slip = block["head"].index("cage slip [%]")
    first = block["rows"][0]
    assert first[slip] == "1" and first[4] == "5.00 ± 0.20" and first[5] == "3.00 ± 0.10", first


def test_a_report_another_command_is_writing_is_refused_in_one_line(runs, tmp_path):
    """Two commands writing one report page: the second is refused in one line naming the file and its lock,
    where the last to finish replaced the other's page unseen."""
    from bearingsim.outputs import OutputLock

    out = tmp_path / "r.html"
    with OutputLock(out, "report"):
        res = cli("report", runs / "r.h5", "-o", out)
    assert res.returncode == 2
    assert res.stderr.strip().splitlines() == [f"bearingsim: error: {out}: another bearingsim command is writing this "
                                               f"report (lock .r.html.lock is held); wait for it or choose another -o"]
    assert not out.exists()
    assert cli("report", runs / "r.h5", "-o", out).returncode == 0 and out.is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.html"]  # its lock gone with it


def test_a_whole_bearing_sensitivitys_chart_caption_names_every_panel(tmp_path):
    """The report's caption of a whole-bearing sensitivity's tornado chart read "the change of ln I_dec and ln
    I_acc across each key's plausible range" under a chart of four panels (the cage slip's, a fraction, and the
    cage's eccentricity too); it names each panel. A reduced-model study's chart has the two it names."""
    from bearingsim.reports import _sensitivity_sections
    from bearingsim.studies import sensitivity as sens

    sc = bearingsim.load_scenario(SCENARIOS / "multibody_3000rpm.toml")
    rows = [{"key": "contact.cage_friction", "quantity": q, "measure": m, "x": 0.1, "x_minus": 0.09,
             "x_plus": 0.11, "y_minus": 1.0, "y_minus_se": 0.01, "y_plus": 1.1, "y_plus_se": 0.01,
             "sensitivity": 0.5, "sensitivity_se": 0.05, "over_range": 0.5, "sensitivity_half_step": np.nan,
             "x_minus_half": np.nan, "x_plus_half": np.nan, "archive_minus": "", "archive_plus": "",
             "status": "done", "error": ""} for q, _, m in sens.QUANTITIES]
    sens.write_table(tmp_path, rows, sc, 0.1, runs=2)
    sections = _sensitivity_sections(tmp_path / "sensitivity.h5")[1]
    (caption,) = [b["caption"] for s in sections for b in s.blocks if b["kind"] == "figure"]
    assert caption.startswith("Tornado chart: the change of ln I_dec, ln I_acc, cage_slip (a fraction) and ln "
                              "cage_eccentricity across each key's plausible range"), caption
    reduced = [r for r in rows if r["quantity"] in sens.REDUCED_QUANTITIES]
    sens.write_table(tmp_path, reduced, sc, 0.1, runs=2)
    sections = _sensitivity_sections(tmp_path / "sensitivity.h5")[1]
    (caption,) = [b["caption"] for s in sections for b in s.blocks if b["kind"] == "figure"]
    assert caption.startswith("Tornado chart: the change of ln I_dec and ln I_acc across"), caption


def test_a_sensitivitys_page_names_the_keys_it_left_out(tmp_path):
    """A default key whose value is 0 is left out of a sensitivity study (no relative step moves it): the command's
    first lines and `bearingsim table DIR` name it ("left out: lubrication.drag_coefficient (its value is 0.0: ...)"),
    the report's page did not, so its table read as every ranged key's. The page names it above the table."""
    from bearingsim.reports import _sensitivity_sections
    from bearingsim.studies import sensitivity as sens

    sc = bearingsim.load_scenario(PAPER, set={"lubrication.drag_coefficient": 0.0})
    rows = [{"key": "contact.restitution", "quantity": q, "measure": "log", "x": 0.8, "x_minus": 0.72,
             "x_plus": 0.88, "y_minus": 1.0, "y_minus_se": 0.0, "y_plus": 1.1, "y_plus_se": 0.0, "sensitivity": 0.5,
             "sensitivity_se": 0.0, "over_range": 0.5, "sensitivity_half_step": 0.5, "x_minus_half": 0.76,
             "x_plus_half": 0.84, "archive_minus": "", "archive_plus": "", "status": "done", "error": ""}
            for q in sens.REDUCED_QUANTITIES]
    why = "its value is 0.0: a relative step x (1 ± step) cannot move it"
    sens.write_table(tmp_path, rows, sc, 0.1, left_out=[("lubrication.drag_coefficient", why)], runs=4)
    texts = [b["text"] for s in _sensitivity_sections(tmp_path / "sensitivity.h5")[1] for b in s.blocks
             if b["kind"] == "text"]
    assert f"Left out of the default keys: lubrication.drag_coefficient ({why})." in texts, texts
    sens.write_table(tmp_path, rows, sc, 0.1, runs=4)
    assert not [b for s in _sensitivity_sections(tmp_path / "sensitivity.h5")[1] for b in s.blocks
                if b["kind"] == "text" and "Left out" in b["text"]]
