"""One real-browser run of the app: Playwright drives Debian's chromium against
``partlab app`` on a free loopback port with its own data directory.

upload a synthetic clip -> track it -> drag one box in the editor -> toggle its
failure flag -> the store holds the new box and the flag. Saves a screenshot of the
Correct page (``docs/correct.png`` with ``PARTLAB_SCREENSHOT=1``, else in tmp).
"""

from __future__ import annotations

import contextlib
import os
import re
import time
from pathlib import Path

import pytest
from playwright import sync_api as playwright  # the test extra installs it: a broken import fails

from partlab.commands.app import serving

CHROMIUM = "/usr/bin/chromium"
ROOT = Path(__file__).resolve().parents[2]
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]

if not os.path.exists(CHROMIUM):
    pytest.skip("chromium is not installed (apt-get install chromium; .ci/run does it)", allow_module_level=True)


@contextlib.contextmanager
def _serving(tmp_path, **extra_env):
    # no demo project: tests/app/test_demo.py covers it, and rendering it would slow every first page
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]), PARTLAB_DEMO="0",
               **extra_env)
    with open(tmp_path / "server.log", "w") as log:
        try:
            with serving(env, log, cwd=ROOT) as running:
                yield running
        except RuntimeError as exc:
            raise RuntimeError(f"{exc}: {(tmp_path / 'server.log').read_text()}") from None


@pytest.fixture
def server(tmp_path):
    with _serving(tmp_path) as running:
        yield running


def _wait_for(predicate, timeout=30.0, what="condition"):
    end = time.time() + timeout
    while time.time() < end:
        value = predicate()
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture
def scene(tmp_path):
    """A short synthetic clip (one walker) with its exact boxes."""
    from partlab.labelling.synth import render_scenario
    from partlab.tracking.tracks import read_tracks_csv

    out = render_scenario("single", tmp_path / "scene", seed=1, n_frames=12, width=320, height=240)
    clip = out / "walker.mp4"
    (out / "clip.mp4").rename(clip)
    return clip, read_tracks_csv(out / "truth.csv")


@pytest.fixture
def page(tmp_path):
    """A chromium page; its last view is kept as tmp_path/last.png (next to the app's
    server.log) to see where a failed run stopped."""
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page(viewport={"width": 1280, "height": 1000})
        page.set_default_timeout(60_000)
        try:
            yield page
        finally:
            try:
                page.screenshot(path=str(tmp_path / "last.png"), full_page=True)
            except playwright.Error:
                pass
            browser.close()


def _settled(page) -> None:
    """Wait until the app's current run has ended (no request in flight, no running indicator)."""
    page.wait_for_load_state("networkidle")
    page.locator('[data-testid="stStatusWidget"]').wait_for(state="detached", timeout=30000)


def _navigate(page, link: str, shown) -> None:
    """Click the sidebar's page link ``link`` until ``shown`` (a locator of the new page) appears. A
    click that lands while the current page's run is still drawing can be lost (CI, once in ~50
    runs: the Projects page never came after "Signed in as"), so wait for the run to end first and
    click once more if the page did not change."""
    for attempt in range(3):
        _settled(page)
        page.get_by_role("link", name=link).click()
        try:
            shown.wait_for(timeout=20_000)
            return
        except playwright.TimeoutError:
            if attempt == 2:
                raise


def _upload(page, uploader, path, confirmation: str) -> None:
    """Give the uploader a file and wait for the page's confirmation. A file handed to an
    uploader that the rerun after "Create project" is still replacing can be dropped by the
    browser (seen once in ~10 runs on a fresh clone), so wait for the rerun to end, and hand
    the file once more if no confirmation came."""
    _settled(page)
    uploader.set_input_files(str(path))
    try:
        page.get_by_text(confirmation).wait_for(timeout=15000)
    except Exception:
        uploader.set_input_files(str(path))
        page.get_by_text(confirmation).wait_for()


def test_upload_track_drag_and_flag_in_the_browser(server, page, store, scene, tmp_path):
    url, proc = server
    clip_file, boxes = scene
    boxes = boxes.drop(columns=["source"])
    page.goto(url)

    # a project and the clip (the demo project may be there already; make our own)
    page.get_by_text("New project").first.wait_for()
    _settled(page)  # a click while the first run still draws the expander could close it again
    if not page.get_by_label("Project name").is_visible():  # expanded when there is no project yet
        page.get_by_text("New project").first.click()
    page.get_by_label("Project name").fill("browser")
    page.get_by_role("button", name="Create project").click()
    page.get_by_text("Created project 'browser'.").wait_for()
    page.get_by_text("Project: browser").wait_for()
    _upload(page, page.locator("input[type=file]").first, clip_file, "Added walker.mp4: 12 frames")
    project = store.project_by_name("browser")
    [clip] = store.clips(project.id)

    # track: start from the init boxes of frame 0
    _navigate(page, "Track", page.get_by_test_id("stExpander").get_by_text("Import boxes from a tracks CSV"))
    page.get_by_test_id("stExpander").get_by_text("Import boxes from a tracks CSV").click()
    init = boxes[boxes.frame == 0]
    init.to_csv(tmp_path / "init.csv", index=False)
    page.locator("input[type=file]").last.set_input_files(str(tmp_path / "init.csv"))
    page.get_by_role("button", name="Store these boxes as a tracker run").click()
    page.get_by_text(f"Stored {len(init)} boxes as run").wait_for()
    page.get_by_text("the stored boxes of frame 0").click()
    page.get_by_role("button", name="Track the whole clip").click()
    page.get_by_text(re.compile(r": done \(|: failed:")).first.wait_for(timeout=120_000)
    assert store.runs(clip.id).tracker.tolist() == ["import", "body"]
    assert store.tracks(clip.id).frame.max() == 11  # the tracker followed the walker to the end
    head0 = store.frame_boxes(clip.id, 0).set_index("part").loc["head"]

    # correct: drag the head box of frame 0 right and down, then press F
    head = page.locator('rect[data-part="head"][data-track="1"]').first
    _navigate(page, "Correct", head)
    page.wait_for_timeout(500)
    bb = _wait_for(head.bounding_box, timeout=15, what="the head box")
    scale = 320 / page.locator(".pl-overlay").bounding_box()["width"]  # image px per screen px
    cx, cy = bb["x"] + bb["width"] / 2, bb["y"] + bb["height"] / 2
    page.mouse.move(cx, cy)
    page.mouse.down()
    page.mouse.move(cx + 15, cy + 10, steps=4)
    page.mouse.move(cx + 30, cy + 20, steps=4)
    page.mouse.up()
    page.keyboard.press("f")

    def saved():
        df = store.frame_boxes(clip.id, 0)
        row = df[(df.part == "head") & (df.track_id == 1)]
        return [row.iloc[0]] if len(row) and bool(row.iloc[0].failure) else None

    [head1] = _wait_for(saved, what="the moved and flagged head box in the store")
    assert head1.source == "human" and int(head1.revision) == 2
    assert head1.x - head0.x == pytest.approx(30 * scale, abs=1.0)
    assert head1.y - head0.y == pytest.approx(20 * scale, abs=1.0)
    assert (head1.w, head1.h) == (head0.w, head0.h)
    page.get_by_text("head FAIL").first.wait_for()

    shot = ROOT / "docs" / "correct.png" if os.environ.get("PARTLAB_SCREENSHOT") == "1" \
        else tmp_path / "correct.png"
    shot.parent.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(shot), full_page=True)
    assert shot.stat().st_size > 10_000

    # undo (Ctrl+Z) takes the flag back off as a new revision; redo (Ctrl+Y) puts it on again
    def head_now():
        df = store.frame_boxes(clip.id, 0)
        return df[(df.part == "head") & (df.track_id == 1)].iloc[0]

    _focus_editor(page)
    page.keyboard.press("Control+z")
    _wait_for(lambda: int(head_now().revision) == 3, what="the undo")
    assert not bool(head_now().failure) and head_now().x == head1.x
    # a key pressed while the undo's rerun is still drawing the editor can be lost (CI, once): wait
    # for the run to end, and press once more if nothing came (a redo with nothing left is a no-op)
    _settled(page)
    for attempt in range(3):
        _focus_editor(page)  # the undo's rerun redraws the editor, which may take the focus away
        page.keyboard.press("Control+y")
        try:
            _wait_for(lambda: int(head_now().revision) == 4, timeout=10, what="the redo")
            break
        except AssertionError:
            if attempt == 2:
                raise
            _settled(page)
    assert bool(head_now().failure) and head_now().x == head1.x and int(head_now().revision) == 4

    # killing the app mid-session loses no saved edit
    proc.kill()
    proc.wait(10)
    [again] = _wait_for(saved, timeout=1, what="the edit after the app was killed")
    assert (again.x, again.y, bool(again.failure), int(again.revision)) == (head1.x, head1.y, True, 4)


def _drag(page, locator, dx: float, dy: float) -> None:
    # the editor redraws its boxes when Python sends new data, and lays itself out again when the
    # page around it changes: wait for the box to be there and to stay where it is
    bb = _wait_for(locator.bounding_box, timeout=15, what="the box to drag")
    for _ in range(50):
        page.wait_for_timeout(150)
        now = _wait_for(locator.bounding_box, timeout=15, what="the box to drag")
        if now == bb:
            break
        bb = now
    cx, cy = bb["x"] + bb["width"] / 2, bb["y"] + bb["height"] / 2
    page.mouse.move(cx, cy)
    page.mouse.down()
    page.mouse.move(cx + dx / 2, cy + dy / 2, steps=3)
    page.mouse.move(cx + dx, cy + dy, steps=3)
    page.mouse.up()


def _drag_edit(page, locator, dx: float, dy: float) -> None:
    """:func:`_drag` until the editor has sent an edit. A drag made while the editor lays itself
    out again can miss the box (no edit leaves the page; seen once in a fresh-clone run), so
    drag once more if the editor's sequence number did not move within 10 s."""
    page.bring_to_front()
    seq = page.evaluate("() => window.partlabEditor.seq")
    _until(page, lambda: _drag(page, locator, dx, dy), f"() => window.partlabEditor.seq > {seq}", 3, 10_000)


def _until(page, act, done: str, tries: int, timeout: int) -> None:
    """``act()``, then wait ``timeout`` ms for the page's ``done`` (a JS function) to hold; again
    up to ``tries`` times (an action the page's own rerun swallowed), failing on the last."""
    for attempt in range(tries):
        act()
        try:
            page.wait_for_function(done, timeout=timeout)
            return
        except playwright.TimeoutError:
            if attempt == tries - 1:
                raise


def test_a_stale_edit_from_a_second_session_is_refused_not_lost(server, page, store, scene):
    url, _ = server
    clip_file, boxes = scene
    project = store.create_project("shared")  # before the app's first run: the first project
    clip = store.add_clip(project.id, clip_file)
    store.save_tracker_run(clip.id, boxes.drop(columns=["source"]))
    second = page.context.browser.new_page(viewport={"width": 1280, "height": 1000})  # another session
    second.set_default_timeout(60_000)  # a loaded 2-core machine takes over 30 s for a rerun at times
    heads = []
    for pg in (page, second):
        pg.goto(url + "/correct")
        heads.append(pg.locator('rect[data-part="head"][data-track="1"]').first)
        heads[-1].wait_for()
    before = store.frame_boxes(clip.id, 0).set_index("part").loc["head"]

    _drag_edit(page, heads[0], 20, 0)  # the first session moves the head right...
    _wait_for(lambda: store.revision(clip.id, 0, 1, "head") == 1, timeout=60, what="the first session's edit")
    _drag_edit(second, heads[1], 0, 20)  # ...the second, which still shows the old box, moves it down
    second.get_by_text("was changed by someone else (revision 1, you had 0)").wait_for()
    after = store.frame_boxes(clip.id, 0).set_index("part").loc["head"]
    assert int(after.revision) == 1 and after.x > before.x and after.y == before.y  # the first edit stands
    # the refused session now shows the stored box and can apply its change again
    shown = "(window.partlabEditor.boxes.get(0) || []).find((b) => b.track_id === 1 && b.part === 'head')"
    # (its own refused drag bumped the box's revision optimistically: wait for the stored place too)
    second.wait_for_function(f"() => {{ const b = {shown}; return b && b.revision === 1 && "
                             f"Math.abs(b.x - {float(after.x)}) < 0.01 && Math.abs(b.y - {float(after.y)}) < 0.01; }}")
    _settled(second)
    _drag_edit(second, heads[1], 0, 20)
    _wait_for(lambda: store.revision(clip.id, 0, 1, "head") == 2, timeout=60, what="the second session's retry")
    final = store.frame_boxes(clip.id, 0).set_index("part").loc["head"]
    assert final.x == after.x and final.y > after.y


def test_every_page_has_an_address_that_opens_it(server, page):
    url, _ = server
    for path, heading in (("", "Projects and clips"), ("/projects", "Projects and clips"), ("/train", "Train"),
                          ("/export", "Export")):
        page.goto(url + path)
        page.locator("h1", has_text=heading).wait_for()
        page.get_by_role("link", name="Correct").wait_for()  # the page links are drawn
        assert page.get_by_text("Page not found").count() == 0, path


# ----------------------------------------------------------------------------- the Correct page as a tool
W768, H576, N768 = 768, 576, 90


def _people_clip(tmp_path):
    """A 768x576 clip (textured ground, so its JPEGs weigh what a real frame's do) with three
    walking people; track 1's head is a 15x7 px box, the size of a PETS09 head."""
    import numpy as np

    from partlab.labelling.video import write_video

    rng = np.random.default_rng(3)
    ground = (rng.integers(60, 140, (H576 // 4, W768 // 4, 3), dtype=np.uint8).repeat(4, 0).repeat(4, 1))
    frames, rows = [], []
    for f in range(N768):
        img = ground.copy()
        for t, (x0, y0, vx) in {1: (100, 200, 2), 2: (400, 260, -1), 3: (520, 150, 1)}.items():
            x = x0 + vx * f
            img[y0:y0 + 80, x:x + 32] = (40 + 50 * t, 90, 200 - 40 * t)
            img[y0:y0 + 7, x + 9:x + 24] = (150, 170, 230)
            rows += [dict(frame=f, track_id=t, part="person", x=x, y=y0, w=32, h=80),
                     dict(frame=f, track_id=t, part="head", x=x + 9, y=y0, w=15, h=7),
                     dict(frame=f, track_id=t, part="torso", x=x + 2, y=y0 + 8, w=28, h=32),
                     dict(frame=f, track_id=t, part="hipleg", x=x + 1, y=y0 + 40, w=30, h=40)]
        frames.append(img)
    import pandas as pd

    return write_video(tmp_path / "people.mp4", frames, fps=10.0), pd.DataFrame(rows)


@pytest.fixture
def quiet_server(server):
    """The app without the demo project (nothing renders or tracks while we measure)."""
    return server


def _editor(page, expr: str):
    return page.evaluate(f"() => {{ const e = window.partlabEditor; return {expr}; }}")


def _show_and_tell(page, frame: int) -> None:
    """Show ``frame`` and wait until the editor has told Python of it. The page's runs after an
    undo can mount the editor again while its 400 ms sync timer is pending (the old editor's
    message is then dropped, the new one never saw the step: in CI, 2 runs in 2 after a fresh
    clone), so show the frame again until the editor on the page has sent it."""
    def show():
        _settled(page)
        _editor(page, f"(e.sentFrame = -1, e.show({frame}, true))")

    _until(page, show, f"() => window.partlabEditor.sentFrame === {frame}", 4, 15_000)


def _focus_editor(page):
    page.locator(".pl-frame").click()  # the frame label: focuses the editor without touching a box


def _streamlit_select(page, label: str, option: str):
    """Pick ``option`` in the Streamlit selectbox labelled ``label`` (again if a rerun closed it)."""
    page.locator('[data-testid="stStatusWidget"]').wait_for(state="detached", timeout=60_000)
    box = page.locator('[data-testid="stSelectbox"]').filter(has=page.get_by_text(label, exact=True)).first
    for _ in range(5):
        box.click()
        choice = page.get_by_role("listbox").get_by_role("option", name=option, exact=True)
        try:
            choice.click(timeout=10_000)
            return
        except playwright.Error:
            page.keyboard.press("Escape")
            page.wait_for_timeout(500)
    raise AssertionError(f"could not pick {option!r} in {label!r}")


@pytest.mark.timeout(900)  # on a shared machine the keyframe's background tracking alone takes minutes
def test_correct_page_steps_plays_zooms_and_edits_tracks_from_the_browser(quiet_server, store, tmp_path):
    import statistics

    from partlab.labelling import formats

    url, _ = quiet_server
    clip_file, boxes = _people_clip(tmp_path)
    project = store.create_project("people")
    clip = store.add_clip(project.id, clip_file)
    store.save_tracker_run(clip.id, boxes, tracker="import")
    from partlab.labelling import trackops
    from partlab.tracking.core.box import Box

    for f in (0, 25, 50):  # keyframes every 25 frames on track 3's head; the one at 50 drawn 12 px too far right
        r = boxes[(boxes.frame == f) & (boxes.track_id == 3) & (boxes.part == "head")].iloc[0]
        store.edit_box(clip.id, f, 3, "head", Box(r.x + 12 * (f == 50), r.y, r.w, r.h), expected_revision=0)
    trackops.fill_between(store, clip.id, 3, "head", 25)  # the straight lines between them
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page(viewport={"width": 1440, "height": 900})
        page.set_default_timeout(60_000)
        try:
            _run_correct_page(page, url, store, clip, tmp_path, statistics, formats)
        finally:
            try:
                page.screenshot(path=str(tmp_path / "last.png"), full_page=True)
            except playwright.Error:
                pass
            browser.close()


def _run_correct_page(page, url, store, clip, tmp_path, statistics, formats):
    page.goto(url + "/correct")
    page.wait_for_function("() => window.partlabEditor && window.partlabEditor.stats.ready === 0", timeout=90_000)
    # the whole frame is above the fold at 1440x900
    vp = page.locator(".pl-viewport").bounding_box()
    assert vp["y"] + vp["height"] <= 900 and vp["width"] > 600, vp
    page.wait_for_function("() => window.partlabEditor.frames.size >= 40", timeout=60_000)
    _focus_editor(page)

    # (1) stepping from the frame cache: the new frame and its boxes on screen, 20 steps
    wall = []
    for i in range(1, 21):
        t = time.perf_counter()
        page.keyboard.press("ArrowRight")
        page.wait_for_function(f"() => window.partlabEditor.stats.ready === {i}", polling="raf")
        wall.append(1000 * (time.perf_counter() - t))
        page.wait_for_timeout(60)
    shown = _editor(page, "e.stats.shown.map((x) => x[1])")
    assert len(shown) == 20 and _editor(page, "e.cur") == 20
    assert len(page.locator('rect.pl-box[data-track="2"]').all()) == 4  # the boxes of the new frame are drawn
    print(f"\nframe step 768x576: key to frame shown median {statistics.median(shown):.1f} ms "
          f"(max {max(shown):.0f}), through playwright median {statistics.median(wall):.1f} ms (max {max(wall):.0f})")

    # Play at 25 frames/s from the cache
    page.select_option(".pl-speed", "25")
    page.wait_for_function("() => window.partlabEditor.frames.size >= 70", timeout=60_000)
    _focus_editor(page)
    page.keyboard.press(" ")
    page.wait_for_timeout(2000)  # 50 frames at 25 fps: from frame 20 it stops short of the clip's end (89)
    played, ms, stalls, playing = _editor(page, "[e.stats.played, e.stats.playMs, e.stats.stalls, e.playing]")
    assert playing and played > 5, (played, stalls, playing)
    page.keyboard.press(" ")
    assert not _editor(page, "e.playing")
    print(f"play 768x576 at 25 fps asked: {1000 * played / ms:.1f} frames/s over {played} frames "
          f"({stalls} animation frames waited for the cache)")

    # (2) zoom 4x on the 15x7 px head of track 1 and resize it with the mouse
    frame = _editor(page, "e.cur")
    head = page.locator('rect.pl-box[data-part="head"][data-track="1"]')
    bb = _wait_for(head.bounding_box, what="the head box")  # the editor redraws its boxes: wait for them
    page.mouse.click(bb["x"] + bb["width"] / 2, bb["y"] + bb["height"] / 2)
    for _ in range(12):
        if _editor(page, "e.zoom") >= 4:
            break
        bb = _wait_for(head.bounding_box, what="the head box")
        page.mouse.move(bb["x"] + bb["width"] / 2, bb["y"] + bb["height"] / 2)
        page.mouse.wheel(0, -120)
        page.wait_for_timeout(100)
    zoom = _editor(page, "e.zoom")
    assert zoom >= 4
    bb = _wait_for(head.bounding_box, what="the head box")
    assert bb["width"] >= 4 * 15 - 1 and bb["height"] >= 4 * 7 - 1
    se = _wait_for(page.locator('rect.pl-handle[data-handle="se"]').bounding_box, what="the head's corner handle")
    sx, sy = se["x"] + se["width"] / 2, se["y"] + se["height"] / 2
    truth = store.frame_boxes(clip.id, frame).set_index(["track_id", "part"]).loc[(1, "head")]  # before the drag
    page.mouse.move(sx, sy)
    page.mouse.down()
    page.mouse.move(sx + 10, sy + 6, steps=3)
    page.mouse.move(sx + 20, sy + 12, steps=3)
    page.mouse.up()

    def resized():
        row = store.frame_boxes(clip.id, frame).set_index(["track_id", "part"]).loc[(1, "head")]
        return [row] if row.source == "human" else None

    [row] = _wait_for(resized, what="the resized head in the store")
    assert (row.x, row.y) == (truth.x, truth.y)
    assert row.w - truth.w == pytest.approx(20 / zoom, abs=0.3) and row.h - truth.h == pytest.approx(12 / zoom, abs=0.3)
    person = store.frame_boxes(clip.id, frame).set_index(["track_id", "part"]).loc[(1, "person")]
    assert person.x + person.w >= row.x + row.w - 0.01  # the person box grew with its head
    page.keyboard.press("0")  # fit again

    _move_a_keyframe(page, store, clip)

    # (4) merge, split and delete from a frame on, each with undo and redo from the editor's keys
    def ids(f):
        return sorted(set(store.frame_boxes(clip.id, f).track_id))

    def operate(track, op, other=None):
        page.get_by_role("tab", name="Tracks").click()
        _streamlit_select(page, "Track", f"#{track}")
        _streamlit_select(page, "Operation", op)
        if other is not None:
            field = page.get_by_label("Other / new id")
            field.fill(str(other))
            field.press("Enter")
        page.get_by_role("button", name="Apply").click()
        page.get_by_text("Done: ").first.wait_for()
        page.locator('[data-testid="stStatusWidget"]').wait_for(state="detached", timeout=60_000)

    def keys(combo):
        _focus_editor(page)
        page.keyboard.press(combo)

    operate(3, "merge into track", 2)
    _wait_for(lambda: ids(frame) == [1, 2], what="track 3 merged into 2")
    keys("Control+z")
    _wait_for(lambda: ids(frame) == [1, 2, 3], what="the merge undone")
    keys("Control+y")
    _wait_for(lambda: ids(frame) == [1, 2], what="the merge redone")
    operate(1, "split at this frame")
    _wait_for(lambda: ids(frame) == [2, 4] and ids(frame - 1) == [1, 2], what="track 1 split at the frame")
    keys("Control+z")
    _wait_for(lambda: ids(frame) == [1, 2], what="the split undone")
    keys("Control+y")
    _wait_for(lambda: ids(frame) == [2, 4], what="the split redone")
    operate(2, "delete from this frame on")
    _wait_for(lambda: ids(frame) == [4] and ids(frame - 1) == [1, 2], what="track 2 deleted from the frame on")
    keys("Control+z")
    _wait_for(lambda: ids(frame) == [2, 4], what="the deletion undone")
    keys("Control+y")
    _wait_for(lambda: ids(frame) == [4], what="the deletion redone")

    # the export reflects the three operations
    out = formats.export_clip(store, clip.id, "mot", tmp_path / "mot", frames=False)
    gt = next(out.rglob("gt.txt"))
    import pandas as pd

    mot = pd.read_csv(gt, header=None).iloc[:, :2].set_axis(["frame", "id"], axis=1)
    # MOT frames are 1-based, one file per part, ids numbered by the exporter
    before, after = set(mot[mot.frame == frame].id), set(mot[mot.frame == frame + 1].id)
    assert len(before) == 2 and len(after) == 1 and not after & before, (before, after)  # #1, #2 | #4
    assert not store.human_frames(clip.id) == []  # the resized head is a correction

    if os.environ.get("PARTLAB_SCREENSHOT") == "1":
        page.screenshot(path=str(ROOT / "docs" / "correct.png"))


def test_sign_in_and_a_second_browser_without_credentials_sees_no_project(store, tmp_path, monkeypatch):
    """Sign-in on (what ``partlab app --host 0.0.0.0`` serves): a browser sees a sign-in form and no
    project until it signs in; a wrong password gets a sentence; after signing in, only the user's
    project; a second browser (its own cookies and storage) sees the form again. An upload over the
    limit, refused by the browser itself, says why in words."""
    from partlab.labelling import access

    mine, theirs = store.create_project("street-mine"), store.create_project("lab-theirs")
    access.add_user(store, "ana", "ana-password")
    access.add_user(store, "olga", "olga-password")
    access.grant(store, "ana", mine.id, "owner")
    access.grant(store, "olga", theirs.id, "owner")
    big = tmp_path / "big.mp4"
    big.write_bytes(b"\0" * (2 * 2**20 + 10))
    monkeypatch.setenv("PARTLAB_MAX_UPLOAD_MB", "1")  # Streamlit's own limit too (streamlit_command reads it)
    with _serving(tmp_path, PARTLAB_AUTH="password") as (url, _), \
            playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        first, second = (browser.new_context(viewport={"width": 1280, "height": 1000}) for _ in range(2))
        page = first.new_page()
        page.set_default_timeout(60_000)
        try:
            page.goto(url + "/correct")  # a deep link asks to sign in as well
            page.get_by_label("User name").wait_for()
            _settled(page)
            for name in ("street-mine", "lab-theirs"):
                assert page.get_by_text(name).count() == 0
            page.get_by_label("User name").fill("ana")
            page.get_by_label("Password", exact=True).fill("olga-password")
            page.get_by_role("button", name="Sign in").click()
            page.get_by_text("Wrong user name or password.").wait_for()
            page.get_by_label("Password", exact=True).fill("ana-password")
            page.get_by_role("button", name="Sign in").click()
            page.get_by_text("Signed in as ana").wait_for()
            page.get_by_text("This project has no clips yet").wait_for()  # still the Correct page it asked for
            _navigate(page, "Projects and clips", page.get_by_text("Project: street-mine"))
            assert page.get_by_text("lab-theirs").count() == 0
            # an upload over the 1 MB limit: the browser refuses it, and the page says so in words
            uploader = page.locator('[data-testid="stFileUploaderDropzoneInput"]')
            _settled(page)
            uploader.set_input_files(str(big))
            said = page.get_by_text("File must be 1.0MB or smaller.")
            said.wait_for(state="attached")
            # Streamlit alone renders it 1 px wide for screen readers only; shown, it is a line of text
            _wait_for(lambda: (said.bounding_box() or {}).get("width", 0) > 100, what="the refusal shown as text")
            assert store.clips(mine.id) == []
            # another browser, no credentials: the form, no project
            other = second.new_page()
            other.set_default_timeout(60_000)
            other.goto(url + "/projects")
            other.get_by_label("User name").wait_for()
            _settled(other)
            for name in ("street-mine", "lab-theirs", "Signed in as"):
                assert other.get_by_text(name).count() == 0
        finally:
            try:
                page.screenshot(path=str(tmp_path / "last.png"), full_page=True)
            except playwright.Error:
                pass
            browser.close()


def test_an_event_is_added_stretched_and_undone_on_the_timeline_and_exported(server, page, store, tmp_path):
    """On the Correct page's timeline: E adds a clap from the shown frame, dragging its right end
    stretches it, Ctrl+Z takes the stretch back; the CVAT export holds the event as tags."""
    import pandas as pd

    from partlab.labelling import formats
    from partlab.labelling.video import write_video
    from tests.app.conftest import walker_boxes, walker_frames

    url, _ = server
    clip_file = write_video(tmp_path / "walk40.mp4", walker_frames(40), fps=10.0)
    project = store.create_project("events")
    clip = store.add_clip(project.id, clip_file)
    store.save_tracker_run(clip.id, walker_boxes(40), tracker="import")
    page.goto(url + "/correct")
    page.wait_for_function("() => window.partlabEditor && window.partlabEditor.stats.ready === 0", timeout=90_000)
    _settled(page)
    page.select_option(".pl-event-type", "clap")
    _focus_editor(page)
    page.keyboard.press("e")  # a clap over frames 0..9 (one second at 10 fps)

    def stored():
        ev = store.events(clip.id)
        return [(int(r.start_frame), int(r.end_frame), r.type, int(r.revision)) for r in ev.itertuples()]

    _wait_for(lambda: stored() == [(0, 9, "clap", 1)], what="the new event in the store")
    # the editor shows the stored event (with its id) on the timeline's event row
    page.wait_for_function("() => { const e = window.partlabEditor; return e.events.length === 1 && "
                           "e.events[0].id !== null && e.tlGeom && e.tlGeom.lanes.count === 1; }")
    _settled(page)
    x0, x1, y = page.evaluate("""() => {
        const e = window.partlabEditor, g = e.tlGeom, r = e.timeline.getBoundingClientRect();
        return [r.left + g.X(10), r.left + g.X(19) + 0.5 * (g.X(1) - g.X(0)), r.top + g.evTop + g.laneH / 2]; }""")
    page.mouse.move(x0 - 1, y)
    page.mouse.down()
    page.mouse.move((x0 + x1) / 2, y, steps=3)
    page.mouse.move(x1, y, steps=3)
    page.mouse.up()
    _wait_for(lambda: stored() == [(0, 19, "clap", 2)], what="the stretched event in the store")
    # the page's run after the store's change draws the editor with the stored event: wait for it
    # (read at once, the editor could still show the run before, 0-9: CI, 2 runs in 2)
    page.wait_for_function("() => window.partlabEditor.eventInfo.textContent === '#1 clap 0-19'")

    _settled(page)
    _focus_editor(page)
    page.keyboard.press("Control+z")
    _wait_for(lambda: stored() == [(0, 9, "clap", 3)], what="the stretch undone")
    page.wait_for_function("() => window.partlabEditor.events.length === 1 && window.partlabEditor.events[0].end === 9")

    out = formats.export_clip(store, clip.id, "cvat", tmp_path / "cvat", frames=False)
    csv = pd.read_csv(out / "events.csv")
    assert csv[["start_frame", "end_frame", "kind"]].values.tolist() == [[0, 9, "clap"]]
    assert (out / "events.xml").read_text().count('<tag label="clap"') == 10


def _move_a_keyframe(page, store, clip):
    """(3) Track mode: track 3's head has keyframes at 0, 25 and 50, the one at 50 drawn 12 px too far
    right. Dragging it onto the head draws the straight line from 25 to 50 at once, then the tracker's
    boxes of that track and part replace it (a background job); every other box stays, and one undo
    takes back the move, the line and the tracker's boxes."""
    import pandas as pd

    def rows(query):
        return store.tracks(clip.id).query(query).drop(columns="revision").reset_index(drop=True)

    mine = "track_id == 3 and part == 'head' and 25 < frame < 50"
    # everything else but the person box at 50, the bounding rectangle of its parts again (Zhao & Lee sec. 5.3)
    rest = "track_id != 3 or (part != 'head' and not (part == 'person' and frame == 50))"
    others, before = rows(rest), rows(mine)
    runs, back = len(store.runs(clip.id)), _editor(page, "e.cur")
    _editor(page, "e.show(50, true)")
    page.wait_for_function("() => window.partlabEditor.cur === 50 && window.partlabEditor.ready(50)")
    head = page.locator('rect.pl-box[data-part="head"][data-track="3"]')
    scale = _wait_for(head.bounding_box, what="track 3's head")["width"] / 15  # screen px per image px
    t = time.perf_counter()
    _drag(page, head, -12 * scale, 0)

    def moved():
        key = store.frame_boxes(clip.id, 50).set_index(["track_id", "part"]).loc[(3, "head")]
        return [key] if key.source == "human" and int(key.revision) == 2 else None

    [key] = _wait_for(moved, what="the moved keyframe")
    assert key.x == pytest.approx(529 + 50, abs=3)  # on the drawn head (x 529 + frame; a 15 px box)
    _wait_for(lambda: len(store.runs(clip.id)) >= runs + 1, what="the straight line")
    t_line = time.perf_counter() - t

    def tracked():
        now = rows(mine)
        return [now] if len(store.runs(clip.id)) >= runs + 2 and now.state.isin(["tracked", "review"]).any() else None

    # a background job: seconds on an idle machine, minutes on a shared one (nothing else waits for it)
    [now] = _wait_for(tracked, timeout=400, what="the tracker's in-between boxes")
    print(f"\nkeyframe moved: straight line stored {t_line:.1f} s, tracker's boxes of frames 26..49 "
          f"{time.perf_counter() - t:.1f} s after the drag ({now.state.value_counts().to_dict()})")
    assert store.runs(clip.id).iloc[-1].tracker == "keyframes" and len(now) == 24
    truth = 529 + now.frame.to_numpy()
    assert abs(now.x.to_numpy() - truth).max() < abs(before.x.to_numpy() - truth).max()  # nearer than before
    pd.testing.assert_frame_equal(rows(rest), others)
    page.get_by_text(re.compile("Tracker boxes between the keyframes of head #3: done")).wait_for()
    page.locator('[data-testid="stStatusWidget"]').wait_for(state="detached", timeout=60_000)
    _focus_editor(page)
    page.keyboard.press("Control+z")

    def undone():
        key = store.frame_boxes(clip.id, 50).set_index(["track_id", "part"]).loc[(3, "head")]
        return key.x == 529 + 50 + 12 and rows(mine)[["x", "y"]].equals(before[["x", "y"]]) or None

    _wait_for(undone, what="the keyframe move undone with its in-between boxes")
    pd.testing.assert_frame_equal(rows(rest), others)
    # back to the frame the track operations below apply at, once Python has been told of it
    _show_and_tell(page, back)
    page.locator('[data-testid="stStatusWidget"]').wait_for(state="detached", timeout=60_000)


# ----------------------------------------------------------------------------- a take of several views
@pytest.fixture
def take3(store, tmp_path):
    """A 3-camera synthetic take (standing, 320x240, 6 frames) in the store, its exact head and
    hand boxes of every view stored as the 3D tracker's run of each view (camera, X, Y, Z)."""
    from partlab.labelling.multiview import store_take_tracks
    from partlab.labelling.synth.multiview import render_take
    from partlab.tracking.tracks import read_tracks_csv

    out = render_take("standing", tmp_path / "take", 3, seed=1, n_frames=6, width=320, height=240, chessboard=False)
    truth = read_tracks_csv(out / "truth.csv")
    truth = truth[truth.part.isin(["head", "left_hand", "right_hand"])].drop(columns=["source"])
    project = store.create_project("take")  # before the app's first run: the session opens it
    take = store.import_take(project.id, out)
    store_take_tracks(store, take.id, truth)
    return take, truth


def test_a_hand_corrected_in_one_view_of_a_3_camera_take_moves_the_other_views(server, page, store, take3):
    """The Done-when of the multi-camera issue: in the Correct page of a 3-camera take, drag a hand
    in view cam0; its 3D point moves along cam0's new line of sight (where cam1's and cam2's boxes
    agree best) and cam1's and cam2's hand boxes move to that point's reprojection."""
    import numpy as np

    from partlab.tracking.camera import Camera

    url, _ = server
    take, truth = take3
    clips = {st.name: st.clip_id for st in take.streams}
    cams = {st.name: Camera.from_dict(st.calibration, st.name) for st in take.streams}
    f0 = truth[(truth.frame == 0) & (truth.occluded < 0.5)]
    # the hand to correct: one every view sees at frame 0, the largest in cam0
    seen = f0[f0.part != "head"].groupby("part").camera.nunique()
    hand = f0[(f0.camera == "cam0") & f0.part.isin(seen[seen == 3].index)].sort_values("w").iloc[-1].part

    def box(name):
        df = store.frame_boxes(clips[name], 0)
        return df[(df.part == hand) & (df.track_id == 1)].iloc[0]

    def centre(row):
        return np.array([row.x + row.w / 2, row.y + row.h / 2])

    before = {n: box(n) for n in cams}
    page.goto(url + "/correct")
    page.get_by_text("cam1 at frame 0").wait_for(timeout=90_000)  # the other views beside the editor
    page.get_by_text("cam2 at frame 0").wait_for()
    page.wait_for_function("() => window.partlabEditor && window.partlabEditor.ready(0)", timeout=90_000)
    _settled(page)
    target = page.locator(f'rect.pl-box[data-part="{hand}"][data-track="1"]')
    scale = 320 / page.locator(".pl-overlay").bounding_box()["width"]  # image px per screen px
    _drag(page, target, 16 / scale, -10 / scale)  # 16 px right and 10 px up in the image

    def followed():
        now = {n: box(n) for n in cams}
        return [now] if now["cam0"].source == "human" and all(
            abs(now[n].x - before[n].x) > 1e-6 for n in ("cam1", "cam2")) else None

    [now] = _wait_for(followed, timeout=60, what="the other views' boxes in the store")
    assert now["cam0"].x - before["cam0"].x == pytest.approx(16, abs=1.5)
    assert now["cam0"].y - before["cam0"].y == pytest.approx(-10, abs=1.5)
    X = np.array([now["cam0"].X, now["cam0"].Y, now["cam0"].Z])
    np.testing.assert_allclose(cams["cam0"].project(X[None])[0], centre(now["cam0"]), atol=0.01)  # on cam0's line
    for n in ("cam1", "cam2"):
        assert now[n].source == "tracker" and now[n].camera == n  # followed the correction, not a keyframe
        np.testing.assert_allclose([now[n].X, now[n].Y, now[n].Z], X)
        np.testing.assert_allclose(centre(now[n]), cams[n].project(X[None])[0], atol=0.5)  # the reprojection
        assert np.linalg.norm(centre(now[n]) - centre(before[n])) > 2.0, n  # and it moved
        assert (now[n].w, now[n].h) == (before[n].w, before[n].h)
    # the other views beside the editor are drawn again; cam1 in the editor shows its moved box
    page.get_by_text("cam2 at frame 0").wait_for()

    def shown_x():  # the image x of the hand's box in the editor on screen (None while it redraws)
        try:
            overlay = page.locator(".pl-overlay").bounding_box(timeout=2000)
            bb = target.bounding_box(timeout=2000)
        except playwright.Error:  # none, or two editors while the page swaps them
            return None
        return (bb["x"] - overlay["x"]) * 320 / overlay["width"] if bb and overlay else None

    def editor_at(x):
        return lambda: (lambda v: v is not None and abs(v - x) < 1.0)(shown_x())

    _settled(page)
    page.get_by_test_id("stRadio").get_by_text("cam1", exact=True).click()
    _wait_for(editor_at(now["cam1"].x), timeout=60, what="cam1's moved hand in the editor")
    page.get_by_text("cam0 at frame 0").wait_for()
    # one undo in cam0 takes back the move in every view
    _settled(page)
    page.get_by_test_id("stRadio").get_by_text("cam0", exact=True).click()
    _wait_for(editor_at(now["cam0"].x), timeout=60, what="cam0's corrected hand in the editor")
    _settled(page)
    page.locator('button[data-act="undo"]').click()
    _wait_for(lambda: all(box(n).x == before[n].x for n in cams), what="the undo in every view")
