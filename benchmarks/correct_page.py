"""The Correct page on a real clip: step and Play rates from the browser's frame cache, and the
screenshots of docs/app.md.

Starts ``partlab app`` on a scratch data directory (no demo), adds the PETS09-S2L1 clip
(``../shared/data/pets09_s2l1_vtest/vtest.avi``, 768x576, 795 frames; never copied into the
repo) with boxes made from its full-body truth (person from the truth; head, torso, hip-leg at
fixed body proportions: a labelling session's look, not a tracker's accuracy), then drives
Debian's chromium through Playwright at 1440x900: 20 single steps (key press to the new frame
and its boxes on screen, measured in the page), Play at 25 frames/s for 4 s, and zoom 4x on a
head. Prints median/max per repetition and writes ``docs/img/correct-*.png`` with ``--shots``.

    python benchmarks/correct_page.py [--repeat 3] [--shots]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
# ../shared/data beside the repository (or beside the folder of worktrees holding it)
_PETS_UNDER = [p / "shared" / "data" / "pets09_s2l1_vtest" for p in (ROOT.parent, ROOT.parent.parent)]
PETS = next((p for p in _PETS_UNDER if p.is_dir()), _PETS_UNDER[0])
ARGS = ["--headless", "--no-sandbox", "--disable-gpu"]


def pets_boxes(gt: Path) -> pd.DataFrame:
    t = pd.read_csv(gt)
    parts = {"person": (0, 0, 1, 1), "head": (0.27, 0, 0.46, 0.1), "torso": (0.1, 0.12, 0.8, 0.38),
             "hipleg": (0.05, 0.5, 0.9, 0.5)}
    out = [t.assign(part=p, x=t.x + a * t.w, y=t.y + b * t.h, w=c * t.w, h=d * t.h)
           for p, (a, b, c, d) in parts.items()]
    return pd.concat(out)[["frame", "track_id", "part", "x", "y", "w", "h"]]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--shots", action="store_true", help="write docs/img/correct-*.png")
    a = ap.parse_args()
    data = Path(tempfile.mkdtemp(prefix="partlab-correct-"))
    env = dict(os.environ, PARTLAB_DATA=str(data), PARTLAB_DEMO="0", PYTHONPATH=str(ROOT))
    sys.path.insert(0, str(ROOT))
    os.environ.update(PARTLAB_DATA=str(data))
    from partlab.commands.app import serving
    from partlab.labelling.store import Store

    store = Store()
    project = store.create_project("PETS09")
    clip = store.add_clip(project.id, PETS / "vtest.avi", name="PETS09-S2L1 view 1")
    store.save_tracker_run(clip.id, pets_boxes(PETS / "gt.csv"), tracker="import")
    with serving(env, subprocess.DEVNULL, cwd=ROOT) as (url, _proc):
        from playwright.sync_api import sync_playwright

        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
            for rep in range(a.repeat):
                page = browser.new_page(viewport={"width": 1440, "height": 900})
                page.set_default_timeout(120_000)
                run(page, url, a.shots and rep == 0, rep)
                page.close()
            browser.close()
    print(f"load average during the run: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (commit {commit()})")


def commit() -> str:
    """The short hash of the commit measured."""
    return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                          cwd=ROOT).stdout.strip()


def ev(page, expr):
    return page.evaluate(f"() => {{ const e = window.partlabEditor; return {expr}; }}")


def run(page, url: str, shots: bool, rep: int) -> None:
    page.goto(url + "/correct")
    page.wait_for_function("() => window.partlabEditor && window.partlabEditor.stats.ready === 0")
    start = 100
    page.evaluate(f"() => window.partlabEditor.show({start}, true)")
    page.wait_for_function(f"() => window.partlabEditor.stats.ready === {start} "
                           "&& window.partlabEditor.frames.size >= 45")
    page.locator(".pl-frame").click()
    for i in range(1, 21):
        page.keyboard.press("ArrowRight")
        page.wait_for_function(f"() => window.partlabEditor.stats.ready === {start + i}", polling="raf")
        page.wait_for_timeout(60)
    shown = ev(page, "e.stats.shown.map((x) => x[1])")
    page.select_option(".pl-speed", "25")
    page.wait_for_function("() => window.partlabEditor.frames.size >= 60")
    page.locator(".pl-frame").click()
    page.keyboard.press(" ")
    page.wait_for_timeout(4000)
    page.keyboard.press(" ")
    played, ms = ev(page, "[e.stats.played, e.stats.playMs]")
    print(f"run {rep}: step median {statistics.median(shown):.1f} ms, max {max(shown):.0f} ms (20 steps); "
          f"play {1000 * played / ms:.1f} frames/s at 25 asked ({played} frames)")
    if not shots:
        return
    img = ROOT / "docs" / "img"
    img.mkdir(parents=True, exist_ok=True)
    page.evaluate("() => window.partlabEditor.show(150, true)")
    page.wait_for_function("() => window.partlabEditor.stats.ready === 150")
    page.wait_for_timeout(1500)
    page.screenshot(path=str(img / "correct-page.png"))
    # labels on all boxes, then zoomed 4x on one person with the head selected
    page.locator(".pl-frame").click()
    page.keyboard.press("l")
    page.wait_for_timeout(300)
    page.locator(".pl-main").screenshot(path=str(img / "correct-labels.png"))
    page.keyboard.press("l")
    head = page.locator('rect.pl-box[data-part="head"]').first
    bb = head.bounding_box()
    page.mouse.click(bb["x"] + bb["width"] / 2, bb["y"] + bb["height"] / 2)
    for _ in range(8):
        bb = head.bounding_box()
        page.mouse.move(bb["x"] + bb["width"] / 2, bb["y"] + bb["height"] / 2)
        page.mouse.wheel(0, -120)
        page.wait_for_timeout(150)
    page.locator(".pl-main").screenshot(path=str(img / "correct-zoom.png"))
    page.keyboard.press("0")
    page.wait_for_timeout(300)
    page.locator(".pl-timeline").screenshot(path=str(img / "correct-timeline.png"))
    for f in img.glob("correct-*.png"):  # keep them small
        subprocess.run([sys.executable, "-c", "import cv2,sys; i=cv2.imread(sys.argv[1]); "
                        "cv2.imwrite(sys.argv[1], i, [cv2.IMWRITE_PNG_COMPRESSION, 9])", str(f)], check=True)


if __name__ == "__main__":
    main()
