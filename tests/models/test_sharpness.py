import numpy as np

from partlab.models.sharpness import fit_lam


def test_fit_lam_recovers_the_sharpness_of_sampled_distances():
    rng = np.random.default_rng(0)
    for lam in (3.0, 20.0):
        d = rng.uniform(0, 1, 400_000)
        d = d[rng.uniform(0, 1, d.size) < np.exp(-lam * d * d)][:4000]
        assert abs(fit_lam(d * d) - lam) / lam < 0.1
    # small distances: close to 1 / (2 mean d^2)
    d2 = np.full(100, 0.01)
    assert abs(fit_lam(d2) - 50.0) / 50.0 < 0.05
    assert np.isnan(fit_lam(np.array([])))


def test_colour_distances_on_a_synthetic_walker():
    from partlab.labelling.synth import make_scene
    from partlab.models.sharpness import colour_distances

    scene = make_scene("single", seed=3, n_frames=30, width=360, height=240)
    frames = lambda: ((i, scene.frames[i]) for i in range(len(scene.frames)))  # noqa: E731
    d2 = colour_distances(frames, scene.truth)
    assert set(d2) == {"head", "torso", "hipleg", "person"}
    assert len(d2["torso"]) == 29                       # every frame after the first
    # the same reference, then boxes beside the person (background) from frame 1 on
    t = scene.truth
    off = t.assign(x=np.where(t["frame"] > 0, t["x"] + 3 * t["w"], t["x"]))
    d2_off = colour_distances(frames, off)
    assert np.mean(d2["torso"]) < 0.1
    assert np.mean(d2_off["torso"][:5]) > 3 * np.mean(d2["torso"][:5])
    assert fit_lam(d2["torso"]) > fit_lam(d2_off["torso"])
