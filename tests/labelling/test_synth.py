import json

import numpy as np
import pandas as pd
import pytest

from partlab.cli import main
from partlab.labelling.synth import SCENARIOS, make_scene, render_scenario
from partlab.labelling.synth.figure import FACE, HAIR, SHOES, TROUSERS, TROUSERS_FAR, colour_table
from partlab.tracking.parts import BOX_PARTS
from partlab.tracking.tracks import read_tracks_csv


@pytest.fixture(scope="module")
def clean_single():
    return make_scene("single", seed=5, n_frames=60, width=480, height=320, clean=True)


def _row(truth, frame, track, part):
    r = truth[(truth.frame == frame) & (truth.track_id == track) & (truth.part == part)]
    assert len(r) == 1, (frame, track, part)
    return r.iloc[0]


def _colour_bbox(frame, colours, region):
    """Bounding box [x1, y1, x2, y2] of pixels with exactly one of ``colours`` inside ``region``."""
    x1, y1, x2, y2 = region
    sub = frame[y1:y2, x1:x2]
    hit = np.zeros(sub.shape[:2], bool)
    for c in colours:
        hit |= np.all(sub == np.asarray(c, np.uint8), axis=-1)
    ys, xs = np.nonzero(hit)
    return np.array([xs.min() + x1, ys.min() + y1, xs.max() + x1, ys.max() + y1])


def _edges(r):
    return np.array([r.x, r.y, r.x + r.w - 1, r.y + r.h - 1])


def test_head_and_hipleg_boxes_are_tight_on_the_drawn_colours(clean_single):
    scene = clean_single
    lut = colour_table(scene.appearances[0])
    T = len(scene.frames)
    errs_head, errs_leg = [], []
    for i in range(0, T, 3):
        if 0.6 * T < i < 0.8 * T:  # standing, turning and waving: the hand may be up by the head
            continue
        person = _row(scene.truth, i, 1, "person")
        torso = _row(scene.truth, i, 1, "torso")
        head = _row(scene.truth, i, 1, "head")
        leg = _row(scene.truth, i, 1, "hipleg")
        px1, py1 = int(person.x) - 3, int(person.y) - 3
        px2, py2 = int(person.x + person.w) + 3, int(person.y + person.h) + 3
        # above the torso's middle: the hands swing lower than that while walking
        got = _colour_bbox(scene.frames[i], [lut[HAIR], lut[FACE]], (px1, py1, px2, int(torso.y + torso.h / 2)))
        errs_head.append(np.abs(got - _edges(head)).max())
        got = _colour_bbox(scene.frames[i], [lut[TROUSERS], lut[TROUSERS_FAR], lut[SHOES]],
                           (px1, int(leg.y) - 2, px2, py2))
        errs_leg.append(np.abs(got - _edges(leg)).max())
    assert len(errs_head) >= 10
    assert max(errs_head) <= 1, errs_head
    assert np.median(errs_leg) == 0 and max(errs_leg) <= 2, errs_leg


def test_part_boxes_nest_in_the_person_and_stack_head_torso_hipleg(clean_single):
    t = clean_single.truth
    T = t.frame.max() + 1
    t = t[(t.frame < 0.6 * T) | (t.frame > 0.8 * T)]  # not while waving (the hand is above the head)
    wide = t.pivot_table(index="frame", columns="part", values=["x", "y", "w", "h"])
    for part in ("head", "torso", "hipleg", "left_hand", "right_hand"):
        assert (wide["x"][part] >= wide["x"]["person"]).all()
        assert (wide["y"][part] + wide["h"][part] <= wide["y"]["person"] + wide["h"]["person"]).all()
    assert (wide["y"]["person"] == wide["y"]["head"]).all()  # nothing above the hair
    assert (wide["y"]["head"] < wide["y"]["torso"]).all() and (wide["y"]["torso"] < wide["y"]["hipleg"]).all()
    assert (wide["y"]["hipleg"] + wide["h"]["hipleg"] == wide["y"]["person"] + wide["h"]["person"]).all()
    ratio = wide["h"]["head"] / wide["h"]["person"]
    top = 0.22 if clean_single.appearances[0].long_hair else 0.16  # long hair falls to the shoulders
    assert ratio.between(0.09, top).all()  # a head is about 1/7.5 of the body


def test_lone_walker_is_occluded_only_where_its_own_body_hides_a_hand(clean_single):
    t = clean_single.truth
    assert set(t["part"]) == set(BOX_PARTS)
    # no one else in the scene: a part is seen (0) or wholly behind the walker's own body (1, a
    # far hand behind the hips: 19 left-hand and 8 right-hand frames of these 60)
    assert set(t["occluded"].unique()) == {0.0, 1.0}
    hidden = t[t["occluded"] > 0]
    assert set(hidden["part"]) == {"left_hand", "right_hand"}
    assert hidden["part"].value_counts().to_dict() == {"left_hand": 19, "right_hand": 8}


def test_a_hand_behind_its_own_body_is_occluded_and_so_is_what_it_holds():
    """Exchange seed 3: person 2 (profile, facing left) takes the object with the right (far)
    hand and brings it back to rest behind the torso (frames 90-149). The hand's truth is wholly
    occluded, and the object, drawn at the hand's depth, is hidden by the shirt: no pixel of its
    colour left there (before: occluded 0.0 and the object drawn over the shirt)."""
    scene = make_scene("exchange", seed=3, n_frames=150, width=360, height=240, clean=True)
    t = scene.truth
    row = _row(t, 96, 2, "right_hand")
    assert (row.x, row.y, row.w, row.h) == (201, 179, 7, 8)
    assert row.occluded == 1.0
    assert _row(t, 96, 2, "left_hand").occluded == 0.0  # the near hand, in view
    assert _row(t, 60, 2, "right_hand").occluded == 0.0  # out in front, taking the object
    colour = tuple(int(scene.events["colour"][0][k:k + 2], 16) for k in (5, 3, 1))  # "#rrggbb" -> BGR
    frame = scene.frames[96].astype(int)
    near = np.abs(frame - np.array(colour)[None, None, :]).sum(axis=2) < 30
    assert int(near.sum()) == 0
    # at the handover the object is in the hands, in view: drawn as before
    assert int((np.abs(scene.frames[60].astype(int) - np.array(colour)).sum(axis=2) < 30).sum()) > 20


def test_hidden_walker_at_the_middle_of_the_crossing():
    n = 75
    scene = make_scene("pair_cross", seed=2, n_frames=n, width=360, height=240)
    t = scene.truth
    mid = t[(t.frame == n // 2) & (t.part == "person")].set_index("track_id")["occluded"]
    assert mid.max() > 0.7 and mid.min() == 0.0
    far = int(mid.idxmax())
    # the far walker's torso and hip-leg are mostly hidden; at the start nobody is
    assert _row(t, n // 2, far, "torso").occluded > 0.8 and _row(t, n // 2, far, "hipleg").occluded > 0.5
    assert _row(t, n // 2, far, "head").occluded > 0.5  # a short walker behind a tall one
    # at the start nobody hides anybody (a hand behind its own walker's hips is hidden: 1.0)
    first = t[t.frame == 0]
    assert first[~first["part"].str.endswith("hand")]["occluded"].max() == 0.0
    assert set(first["occluded"].unique()) <= {0.0, 1.0}


def test_pillar_hides_the_walker_by_its_overlap():
    scene = make_scene("pillar", seed=1, n_frames=40, width=360, height=240)
    (pillar,) = scene.occluders
    person = scene.truth[scene.truth.part == "person"]
    x1, x2 = person.x, person.x + person.w
    apart = (x2 <= pillar.x) | (x1 >= pillar.x + pillar.w)
    inside = (x1 >= pillar.x) & (x2 <= pillar.x + pillar.w)
    assert apart.sum() > 10 and inside.sum() >= 2
    assert (person.occluded[apart] == 0).all()
    assert (person.occluded[inside] == 1.0).all()
    partly = ~apart & ~inside
    assert person.occluded[partly].between(0.0, 1.0, inclusive="neither").all()


def test_same_seed_same_scene_other_seed_other_scene():
    a = make_scene("crowd", seed=7, n_frames=5, width=240, height=160)
    b = make_scene("crowd", seed=7, n_frames=5, width=240, height=160)
    c = make_scene("crowd", seed=8, n_frames=5, width=240, height=160)
    assert np.array_equal(a.frames, b.frames)
    pd.testing.assert_frame_equal(a.truth, b.truth)
    assert np.abs(a.frames.astype(int) - c.frames.astype(int)).mean() > 3
    assert a.appearances != c.appearances
    shirts = np.array([p.shirt for p in a.appearances], float)
    gaps = [np.linalg.norm(shirts[i] - shirts[j]) for i in range(4) for j in range(i + 1, 4)]
    assert min(gaps) > 70  # clearly different shirts (BGR distance)


@pytest.mark.parametrize("name", [s for s in SCENARIOS if s != "random"])  # random: its own tests
def test_every_scenario_renders_valid_truth(name, tmp_path):
    out = render_scenario(name, tmp_path / name, seed=3, n_frames=12, width=240, height=160)
    truth = read_tracks_csv(out / "truth.csv")
    init = read_tracks_csv(out / "init.csv")
    meta = json.loads((out / "scene.json").read_text())
    assert meta["name"] == name and meta["n_frames"] == 12 and (meta["width"], meta["height"]) == (240, 160)
    n_tracks = {"pair_cross": 2, "crowd": 4, "exchange": 2, "handshake": 2}.get(name, 1)
    assert sorted(truth.track_id.unique()) == list(range(1, n_tracks + 1))
    assert (truth.source == "truth").all() and truth.occluded.between(0, 1).all()
    assert sorted(truth.frame.unique()) == list(range(12))
    expected_parts = set(BOX_PARTS) - ({"hipleg"} if name in ("desk", "pick_place") else set())
    # the activity scenes' people stand near the camera: at 240x160 their legs are mostly below the
    # frame, and a part with less than half of itself in the frame has no row
    legs_out = {"hipleg"} if name in ("exchange", "handshake", "clap") else set()
    for tid, rows in truth.groupby("track_id"):
        assert expected_parts - legs_out <= set(rows.part) <= expected_parts
        assert expected_parts - legs_out <= set(init[init.track_id == tid].part) <= expected_parts
    assert (init.frame == 0).all()
    assert (out / "occluders.csv").exists() == (name == "pillar")
    assert (truth.x >= 0).all() and (truth.x + truth.w <= 240).all() and (truth.y + truth.h <= 160).all()


def test_pillar_writes_its_occluder(tmp_path):
    out = render_scenario("pillar", tmp_path, seed=0, n_frames=3, width=240, height=160)
    occ = pd.read_csv(out / "occluders.csv")
    assert list(occ.columns) == ["x", "y", "w", "h"] and len(occ) == 1
    assert 90 < occ.x[0] + occ.w[0] / 2 < 150 and occ.h[0] > 100


def test_people_are_100_to_220_px_tall_and_over_30_px_wide_at_720x480():
    for name in ("single", "crowd"):
        scene = make_scene(name, seed=0, n_frames=30, width=720, height=480)
        person = scene.truth[(scene.truth.part == "person") & (scene.truth.occluded < 0.01)]
        assert person.h.between(95, 230).all(), (name, person.h.min(), person.h.max())
        # seen side-on with the legs together a person is narrower (seed 002 sec. 5: over 30 px)
        assert (person.w > 30).mean() > 0.9 and person.w.min() > 22, (name, person.w.min())
        if name == "crowd":  # depth: the farthest person is drawn clearly smaller
            assert person.groupby("track_id").h.mean().agg(lambda h: h.max() / h.min()) > 1.3


def test_bend_puts_the_head_down_and_walks_on():
    scene = make_scene("bend", seed=0, n_frames=60, width=360, height=240)
    t = scene.truth
    head_y = t[t.part == "head"].set_index("frame").y
    person_h = t[t.part == "person"].set_index("frame").h
    standing = head_y.iloc[:15].mean()
    assert head_y.loc[30:34].max() - standing > 0.25 * person_h.iloc[:15].mean()
    person_x = t[t.part == "person"].set_index("frame").x
    assert person_x.iloc[-1] - person_x.loc[32] > 40  # walks on after bending


def test_desk_clap_and_reach():
    scene = make_scene("desk", seed=1, n_frames=150, width=360, height=240)
    t = scene.truth
    assert "hipleg" not in set(t.part)

    def centre(part):
        r = t[t.part == part].set_index("frame")
        return np.stack([r.x + r.w / 2, r.y + r.h / 2], 1), r.w.to_numpy()

    left, lw = centre("left_hand")
    right, _ = centre("right_hand")
    gap = np.linalg.norm(left - right, axis=1)
    assert gap[40:61].min() < 1.3 * lw[40:61].max()  # the hands meet
    assert gap[20] > 3 * lw[20] and gap[75] > 3 * lw[75]  # and are apart before and after
    rest = right[70]
    assert np.linalg.norm(right[95] - rest) > 3 * lw[95]  # the right hand reaches out...
    assert right[95][0] < rest[0]  # ...towards image left (the person's right)
    assert np.linalg.norm(right[130] - rest) < 2 * lw[130]  # and comes back
    head_x = t[t.part == "head"].x.to_numpy()
    assert 1 <= head_x.max() - head_x.min() < 20  # the head turns a little


def test_bad_names_and_sizes_are_refused():
    with pytest.raises(ValueError, match="pair_cross"):
        make_scene("nobody")
    with pytest.raises(ValueError, match="too small"):
        make_scene("single", width=20, height=20)
    with pytest.raises(ValueError, match="seed"):
        make_scene("single", seed=-1)


def test_cli_writes_the_files(tmp_path, capsys):
    out = tmp_path / "scene"
    assert main(["synth", str(out), "--scenario", "bend", "--seed", "4", "--frames", "6", "--size", "160x120"]) == 0
    for f in ("clip.mp4", "truth.csv", "init.csv", "scene.json"):
        assert (out / f).exists(), f
    from partlab.labelling.video import probe

    info = probe(out / "clip.mp4")
    assert (info.width, info.height, info.frame_count) == (160, 120, 6)
    assert main(["synth", str(tmp_path / "x"), "--scenario", "parade"]) == 2
    err = capsys.readouterr().err
    assert "parade" in err and "pillar" in err and "desk" in err
    assert main(["synth", str(tmp_path / "x"), "--size", "big"]) == 2
    assert not (tmp_path / "x").exists()
    (tmp_path / "afile").write_text("not a directory")
    assert main(["synth", str(tmp_path / "afile"), "--frames", "2", "--size", "96x64"]) == 2
    assert "cannot write" in capsys.readouterr().err


def test_decoded_clip_frames_match_the_truth_frames(tmp_path):
    """Frame i of the mp4 as OpenCV decodes it is truth frame i (no codec off-by-one)."""
    from partlab.labelling.video import open_video

    n = 10
    out = render_scenario("single", tmp_path, seed=2, n_frames=n, width=240, height=160)
    scene = make_scene("single", seed=2, n_frames=n, width=240, height=160)
    person = scene.truth[scene.truth.part == "person"].set_index("frame")
    clip = open_video(out / "clip.mp4")
    for i in (1, 5, 8):
        near = person.loc[i - 1:i + 1]
        x1, y1 = int(near.x.min()), int(near.y.min())
        x2, y2 = int((near.x + near.w).max()), int((near.y + near.h).max())
        decoded = clip.read(i)[y1:y2, x1:x2].astype(int)
        diffs = [np.abs(decoded - scene.frames[j][y1:y2, x1:x2]).mean() for j in (i - 1, i, i + 1)]
        assert int(np.argmin(diffs)) == 1 and diffs[1] < 0.7 * min(diffs[0], diffs[2]), (i, diffs)


def test_owner_maps_agree_with_the_truth_and_the_background():
    scene = make_scene("pillar", seed=0, n_frames=30, width=240, height=160, owners=True)
    assert scene.owners.shape == (30, 160, 240) and scene.background.shape == (160, 240, 3)
    (pillar,) = scene.occluders
    x, y, w, h = (int(v) for v in pillar.as_tuple())
    assert (scene.owners[:, y:y + h, x:x + w] == 255).all()
    person = scene.truth[scene.truth.part == "person"].set_index("frame")
    for t in range(0, 30, 5):
        ys, xs = np.nonzero(scene.owners[t] == 1)
        r = person.loc[t]
        if r.occluded == 1.0:
            assert len(ys) == 0
            continue
        # every visible pixel of the walker is inside its box, and it is a sizeable share of the box
        assert xs.min() >= r.x and xs.max() < r.x + r.w and ys.min() >= r.y and ys.max() < r.y + r.h
        assert len(ys) / (r.w * r.h) * 1.0 > 0.25 * (1 - r.occluded)
    assert make_scene("single", n_frames=2, width=96, height=64).owners is None


def test_single_walker_turns_back_through_facing_the_camera_and_waves(clean_single):
    from partlab.labelling.synth.camera import Camera
    from partlab.labelling.synth.motion import walk

    camera = Camera.for_frame(480, 320)
    m = walk(camera, 100, [(0.0, -0.8, 8.0), (0.6, 0.6, 7.0), (0.8, 0.6, 7.0), (1.0, 0.0, 8.5)])
    assert np.cos(m.facing[10]) > 0.95  # walking right (and a little towards the camera), side-on
    assert (np.sin(m.facing[62:74]) < -0.45).all() and np.sin(m.facing[62:74]).min() < -0.98  # turns facing the camera
    assert np.cos(m.facing[95]) < -0.5  # walking back left
    assert m.gait[70] == 0 and m.gait[10] == 1  # standing while turning
    t = clean_single.truth
    T = t.frame.max() + 1
    hand = t[t.part == "right_hand"].set_index("frame")
    head = t[t.part == "head"].set_index("frame")
    left = t[t.part == "left_hand"].set_index("frame")
    waving = [f for f in range(T) if 0.69 * T <= f <= 0.72 * T]
    assert waving and all(hand.y[f] < head.y[f] + head.h[f] for f in waving)  # the right hand is up by the head
    assert all(left.y[f] > head.y[f] + head.h[f] for f in waving)  # the left one is not
    assert all(hand.y[f] > head.y[f] + head.h[f] for f in range(0, int(0.5 * T)))  # walking: hands down


def test_left_hand_is_the_persons_own_left():
    from partlab.labelling.synth.appearance import Appearance
    from partlab.labelling.synth.camera import LocalView
    from partlab.labelling.synth.figure import FigurePose, draw_figure

    app = Appearance((0, 0, 200), (100, 50, 0), (150, 180, 220), (20, 20, 20), (30, 30, 30))
    view = LocalView(200.0, 300.0, 100.0, 0.4)

    def hand_x(facing):
        fig = draw_figure(FigurePose(facing=facing), app, view)
        return [fig.origin[0] + np.nonzero(fig.masks[p].any(axis=0))[0].mean() for p in ("left_hand", "right_hand")]

    left, right = hand_x(-np.pi / 2)  # facing the camera: the own left hand is on the image right
    assert left - right > 30
    left, right = hand_x(np.pi / 2)  # facing away: on the image left
    assert right - left > 30


def test_random_scenario_varies_people_camera_and_looks():
    from partlab.labelling.synth.scene import RANDOM_SIZES, make_scene, random_size

    counts, heights, sizes = set(), [], set()
    for seed in range(6):
        w, h = random_size(seed)
        sizes.add((w, h))
        scene = make_scene("random", seed=seed, n_frames=3, width=w, height=h)
        person = scene.truth[scene.truth["part"] == "person"]
        counts.add(person["track_id"].nunique())
        heights.extend((person["h"] / h).tolist())
        assert scene.frames.shape[1:3] == (h, w)
        assert {"head", "torso", "hipleg"} <= set(scene.truth["part"])
    assert sizes <= set(RANDOM_SIZES) and len(sizes) >= 2
    assert len(counts) >= 3 and max(counts) <= 12 and min(counts) >= 1
    assert min(heights) < 0.3 < max(heights)  # people of clearly different sizes in the frame


def test_random_appearances_cover_any_number_and_vary_proportions():
    from partlab.labelling.synth.appearance import random_appearances

    apps = random_appearances(np.random.default_rng(3), 12)
    assert len(apps) == 12
    girth = [a.girth for a in apps]
    assert max(girth) - min(girth) > 0.2 and all(0.8 <= g <= 1.3 for g in girth)
    legs = [a.legs for a in apps]
    assert max(legs) - min(legs) > 0.06 and all(0.92 <= v <= 1.08 for v in legs)
    assert len({a.shirt for a in apps}) == 12


def test_random_camera_tilts_verticals_converge_and_rolls():
    from partlab.labelling.synth.camera import Camera

    rolls = []
    for seed in range(8):
        cam = Camera.random(np.random.default_rng(seed), 640, 480)
        canvas, warp = cam.drawing()
        assert warp is not None and canvas.width > 640 and canvas.height > 480
        rolls.append(cam.roll)
        # a person-high vertical at the left and at the right of the frame, 8 m away
        z, s = 8.0, float(canvas.scale(8.0))
        lean = []
        for xr in (-0.8, 0.8):
            x = float(cam.x_from_fraction(xr, z))
            fx, fy = canvas.floor_point(x, z)
            pts = np.array([[fx, fy, 1.0], [fx, fy - 1.8 * s, 1.0]]).T
            q = warp @ pts
            qx, qy = q[0] / q[2], q[1] / q[2]
            lean.append((qx[1] - qx[0]) / (qy[0] - qy[1]))  # image x per row going up
        if cam.horizon < 0.5 * cam.height:  # looking down: the tops lean apart (verticals meet below)
            assert lean[1] - lean[0] > 0.05
    assert max(rolls) - min(rolls) > np.radians(2) and max(np.abs(rolls)) <= np.radians(4) + 1e-9


def test_tilted_random_scene_truth_boxes_follow_the_warped_pixels():
    from partlab.labelling.synth.scene import make_scene

    scene = make_scene("random", seed=3, n_frames=2, width=480, height=360, owners=True)
    person = scene.truth[(scene.truth["frame"] == 1) & (scene.truth["part"] == "person")
                         & (scene.truth["occluded"] == 0)]
    checked = 0
    for r in person.itertuples():
        ys, xs = np.nonzero(scene.owners[1] == r.track_id)
        if len(xs) < 200:
            continue
        got = np.array([xs.min(), ys.min(), xs.max() + 1, ys.max() + 1])
        want = np.array([r.x, r.y, r.x + r.w, r.y + r.h])
        assert np.abs(got - want).max() <= 2, (r.track_id, got, want)
        checked += 1
    assert checked >= 1


def test_a_part_mostly_outside_the_frame_has_no_truth_row():
    from partlab.labelling.synth.scene import MIN_IN_FRAME, _warped_extent

    # a 10 x 20 part of which 3 columns (30 %) lie inside a 100 x 100 frame (identity warp)
    mask = np.ones((20, 10), bool)
    warp = np.eye(3)
    assert _warped_extent(mask, 97, 40, warp, 100, 100) == (97, 40, 3, 20)  # the person row keeps its sliver
    assert _warped_extent(mask, 97, 40, warp, 100, 100, MIN_IN_FRAME) is None
    # 6 columns (60 %) inside: still a part in view
    assert _warped_extent(mask, 94, 40, warp, 100, 100, MIN_IN_FRAME) == (94, 40, 6, 20)


def test_random_people_start_once_in_view_and_not_mostly_hidden():
    from partlab.labelling.synth.scene import MAX_START_HIDDEN

    scene = make_scene("random", seed=0, n_frames=12, width=320, height=240)
    person = scene.truth[scene.truth.part == "person"].set_index(["track_id", "frame"])
    starts = scene.init.groupby("track_id")["frame"].min()
    # people 1 and 5 stand half or more behind others at frame 0: they start when they come out
    assert person.loc[(1, 0), "occluded"] > 0.5 and person.loc[(5, 0), "occluded"] > 0.7
    assert (starts[1], starts[5]) == (3, 2)
    for tid, frame in starts.items():
        hidden = person.loc[(tid, slice(None)), "occluded"].to_numpy()
        if (hidden <= MAX_START_HIDDEN).any():  # else: never in view, started where it shows most
            assert person.loc[(tid, frame), "occluded"] <= MAX_START_HIDDEN
