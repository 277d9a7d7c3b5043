"""The README's two pictures, drawn from the main job's archive (``bearingsim run
scenarios/multibody_6000rpm.toml`` writes ``outputs/multibody_6000rpm.h5``):

    python -m benchmarks.readme_images [ARCHIVE]

* ``docs/animation_still.png``: one frame of ``bearingsim animate`` (the last frame of the stored motion's
  first tenth of a rotation, as the animation draws it);
* ``docs/report_top.png``: the top of ``bearingsim report``'s page as headless Chromium shows it
  (1200 x 900 px; ``/usr/bin/chromium`` through playwright, as tests/test_report.py opens it).

It overwrites those two files of the checkout (the GIF and the page it draws them from go to temporary
folders, removed after) and takes some seconds.
"""
from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAIN = ROOT / "outputs" / "multibody_6000rpm.h5"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def still(archive: Path, out: Path) -> None:
    from PIL import Image

    from bearingsim import animate, load

    res = load(archive)
    with tempfile.TemporaryDirectory() as tmp:
        gif = animate(archive, Path(tmp) / "a.gif", fps=30, rotations=_first_tenth(res))
        im = Image.open(gif)
        im.seek(im.n_frames - 1)
        im.convert("RGB").save(out, optimize=True)


def _first_tenth(res) -> tuple[float, float]:
    from bearingsim.animation import _Motion

    lo, hi = _Motion(res).window(None, "archive")
    return lo, lo + 0.1 * (hi - lo)


def report_top(archive: Path, out: Path) -> None:
    from playwright.sync_api import sync_playwright

    import bearingsim

    with tempfile.TemporaryDirectory() as tmp:
        page_file = bearingsim.report(archive, Path(tmp) / "report.html")
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)
            page = browser.new_context(offline=True, viewport={"width": 1200, "height": 900}).new_page()
            page.goto(page_file.resolve().as_uri(), wait_until="load")
            page.screenshot(path=str(out))
            browser.close()


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.readme_images", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("archive", nargs="?", help="the archive to draw from (default: outputs/multibody_6000rpm.h5)")
    return ap


def main(argv=None) -> None:
    given = parser().parse_args(argv).archive
    archive = Path(os.path.relpath(Path(given) if given else MAIN))  # the page names it as given
    still(archive, ROOT / "docs" / "animation_still.png")
    report_top(archive, ROOT / "docs" / "report_top.png")
    print(f"wrote {ROOT / 'docs' / 'animation_still.png'}, {ROOT / 'docs' / 'report_top.png'} from {archive}")


if __name__ == "__main__":
    main()
