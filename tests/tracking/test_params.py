"""Parameters grouped by what they tune: checked on construction, nested in JSON, and the flat
form of partlab 0.2 (the shipped bundle, users' bundles) still read."""

import json
import math
from dataclasses import fields, replace

import pytest

from partlab.tracking.body.params import BodyParams, PartNoise
from partlab.tracking.limbs.params import LimbParams


@pytest.mark.parametrize("cls", [BodyParams, LimbParams])
def test_nested_json_round_trip(cls):
    p = cls()
    again = cls.from_dict(json.loads(json.dumps(p.to_dict())))
    assert again == p
    assert set(p.to_dict()) == {f.name for f in fields(cls)}  # groups at the top


@pytest.mark.parametrize("cls", [BodyParams, LimbParams])
def test_every_flat_name_reaches_its_group(cls):
    """Each old flat name maps to a distinct field that exists, and every field has one old name
    (nothing was dropped or invented in the move)."""
    targets = [v for v in cls.FLAT.values() if v is not None]
    assert len(targets) == len(set(targets))
    p = cls()
    leaves = {f"{g.name}.{f.name}" for g in fields(cls) for f in fields(getattr(p, g.name))}
    assert set(targets) | set(getattr(cls, "ADDED", ())) == leaves
    assert not set(targets) & set(getattr(cls, "ADDED", ()))


def test_flat_form_of_partlab_0_2_is_read():
    flat = {"bins_per_channel": 6, "particles_max": 800, "background_history": 200, "adjust_search": 0.0,
            "height_ratios": [0.2, 0.3, 0.5], "part_noise": {"head": {"x": 2, "y": 2, "w": 1, "h": 1, "vx": 1,
                                                                      "vy": 1, "lam": 9}},
            "output_extent": {"head": [1, 1, 0, 0]}}
    b = BodyParams.from_dict(flat)
    assert b.appearance.bins_per_channel == 6 and b.particles.max == 800 and b.background.history == 200
    assert b.adjustment.search == 0.0 and b.decomposition.height_ratios == (0.2, 0.3, 0.5)
    assert b.dynamics.noise == {"head": PartNoise(x=2.0, y=2.0, w=1.0, h=1.0, vx=1.0, vy=1.0, lam=9.0)}
    assert b.output.extent == {"head": (1.0, 1.0, 0.0, 0.0)}
    assert b.particles.min == BodyParams().particles.min  # not given: default
    limb = LimbParams.from_dict({"particles": 120, "lost_frames": 7, "skin_open": 1, "sigma_d": 33.0})
    assert (limb.dynamics.particles, limb.states.lost_frames, limb.skin.open, limb.priors.sigma_d) == (120, 7, 1, 33.0)


def test_the_shipped_bundles_flat_parameters_read_as_the_defaults():
    """The shipped bundle was written flat with every hand-set default of today."""
    from partlab.models.bundle import default_bundle_path

    manifest = json.loads((default_bundle_path() / "bundle.json").read_text())
    body = BodyParams.from_dict(manifest["body_params"])
    assert replace(body, dynamics=BodyParams().dynamics, output=BodyParams().output) == BodyParams()
    assert LimbParams.from_dict(manifest["limb_params"]) == LimbParams()


@pytest.mark.parametrize("build, message", [
    (lambda: BodyParams().updated({"dynamics.noise": {**BodyParams().dynamics.noise,
                                                      "head": PartNoise(x=math.nan)}}),
     "body.dynamics.noise.head.x: must be finite and >= 0, got nan"),
    (lambda: BodyParams.from_dict({"particles": {"initial": 0}}),
     "body.particles.initial: must be an integer and >= 1, got 0"),
    (lambda: BodyParams.from_dict({"particles": {"min": 2000}}),
     r"body.particles.min: must be <= body.particles.max \(1000\), got 2000"),
    (lambda: BodyParams.from_dict({"background": {"scale": 1.5}}),
     "body.background.scale: must be finite and > 0 and <= 1, got 1.5"),
    (lambda: BodyParams.from_dict({"decomposition": {"height_ratios": [0.2, -0.1, 0.9]}}),
     r"body.decomposition.height_ratios\[1\]: must be finite and > 0, got -0.1"),
    (lambda: BodyParams.from_dict({"output": {"extent": {"head": [0, 1, 0, 0]}}}),
     r"body.output.extent.head: scales must be > 0"),
    (lambda: BodyParams.from_dict({"decomposition": {"shrink_given_parts": "yes"}}),
     "body.decomposition.shrink_given_parts: must be true or false, got 'yes'"),
    (lambda: LimbParams.from_dict({"states": {"lost_frames": 2.5}}),
     "limbs.states.lost_frames: must be an integer and >= 1, got 2.5"),
    (lambda: LimbParams.from_dict({"appearance": {"lam": -1}}),
     "limbs.appearance.lam: must be finite and > 0, got -1.0"),
    (lambda: LimbParams.from_dict({"states": {"lost_frame": 3}}),
     "limbs.states: unknown parameter.s. lost_frame"),
    (lambda: LimbParams.from_dict({"lost_frame": 3}), "unknown limbs parameter.s.: lost_frame"),
    (lambda: LimbParams().updated({"lost_frames": 3}), "limbs.lost_frames: no such parameter"),
])
def test_a_bad_value_is_refused_naming_its_field(build, message):
    with pytest.raises(ValueError, match=message):
        build()


def test_updated_changes_only_what_it_names():
    p = LimbParams().updated({"states.lost_frames": 3, "dynamics.particles": 150})
    assert p.states.lost_frames == 3 and p.dynamics.particles == 150
    assert p.states.start_frames == LimbParams().states.start_frames and p.appearance == LimbParams().appearance
    assert p.get("states.lost_frames") == 3
