"""Spot and area lights in the frame against the path-traced truth (tiny Mitsuba renders of a matte
floor seen from above): the same light on the same floor, pixel by pixel, and the exporter's
emitters without rendering."""

import math

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.scene import transform as tf
from skinlab.scene.graph import CameraNode, LightNode, MeshNode, Scene
from skinlab.scene.materials import Material
from skinlab.truth import export as ex
from tests.scene.test_interreflection import grid_mesh


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))


def floor_scene(light: LightNode) -> Scene:
    """A 2 x 2 matte floor in z = 0 (50 x 50 quads, so the frame's per-vertex nothing smooths much),
    seen straight down from far above, lit by `light`; metres (1000 mm per unit)."""
    s = Scene("floor", 1000.0)
    s.environment.ambient = np.zeros(3)
    mat = Material("matte", {"base_color": (0.5, 0.5, 0.5), "specular": 0.0, "roughness": 1.0})
    s.add(MeshNode("floor", grid_mesh(50, (-1, -1, 0), (2, 0, 0), (0, 2, 0), "floor"), mat))
    s.add(light)
    cam = CameraNode("cam", yfov=2 * math.atan(1.0 / 20.0), znear=1.0, zfar=40.0)
    cam.look_at((0.0, 0.0, 20.0), (0.0, 0.0, 0.0))
    s.add(cam)
    return s


def place(light: LightNode, position, direction) -> LightNode:
    light.translation = position
    light.rotation = tf.look_at_rotation(np.zeros(3), np.asarray(direction, np.float64))
    return light


LIGHTS = {
    "spot": lambda: place(
        LightNode("spot", "spot", intensity=2.0, inner_deg=15.0, outer_deg=35.0), (0.2, 0.0, 1.0), (0.0, 0.1, -1.0)
    ),
    "sphere": lambda: place(LightNode("sphere", "sphere", intensity=3.0, radius=0.25), (0.3, -0.2, 0.6), (0, 0, -1)),
    "rect": lambda: place(
        LightNode("rect", "rect", intensity=3.0, width=0.8, height=0.4), (-0.2, 0.1, 0.5), (0.3, 0.0, -1.0)
    ),
}


@pytest.mark.parametrize("kind", list(LIGHTS))
def test_light_on_a_floor_matches_the_truth(renderer, kind):
    pytest.importorskip("mitsuba")
    from skinlab.truth.reference import ReferenceRequest, render_reference

    s = floor_scene(LIGHTS[kind]())
    frame = renderer.render(s, RenderSettings.for_technique("none", 32, 32, bounces=0, supersample=2)).hdr
    ref = render_reference(s, ReferenceRequest(32, 32, spp=256, passes=2), progress=False)
    f, t = frame[..., 0], ref.image[..., 0]
    noise = np.abs(ref.half_a - ref.half_b)[..., 0] / 2
    lit = t > 0.05 * t.max()
    assert lit.mean() > 0.1
    # per 4x4 block, where the light is well above the floor's horizon everywhere it is seen
    fb = f.reshape(8, 4, 8, 4).mean((1, 3))
    tb = t.reshape(8, 4, 8, 4).mean((1, 3))
    nb = noise.reshape(8, 4, 8, 4).mean((1, 3))
    bright = tb > 0.2 * tb.max()
    rel = np.abs(fb - tb)[bright] / tb[bright]
    # measured: median 0.07 / 0.4 / 0.6 %, worst 0.3 / 1.0 / 2.4 % (spot, sphere, rect), energy within 0.5 %
    assert np.median(rel) < 0.015 and rel.max() < 0.04 + 4 * (nb[bright] / tb[bright]).max(), (
        np.median(rel),
        rel.max(),
    )
    assert abs(f.sum() / t.sum() - 1) < 0.015, f.sum() / t.sum()


def test_exporter_emitters_of_spot_and_area_lights():
    spot = ex.describe(floor_scene(LIGHTS["spot"]()), 8, 8).emitters[0]
    assert spot["kind"] == "spot" and spot["cutoff_deg"] == 35.0 and spot["beam_deg"] == 15.0
    assert np.allclose(spot["position"], [200.0, 0.0, 1000.0])  # millimetres, the frame's origin at the floor
    assert np.allclose(spot["intensity"], 2.0e6)  # per mm^2 where Skinlab's falls off per m^2
    sph = ex.describe(floor_scene(LIGHTS["sphere"]()), 8, 8)
    e = sph.emitters[0]
    assert e["kind"] == "sphere" and e["radius"] == pytest.approx(250.0) and np.allclose(e["radiance"], 3.0)
    assert any("area lights" in n for n in sph.notes)
    r = ex.describe(floor_scene(LIGHTS["rect"]()), 8, 8).emitters[0]
    from skinlab.truth.description import rect_to_world

    m = rect_to_world(r)
    # Mitsuba's rectangle [-1, 1]^2 in z = 0 onto the light: corners 800 x 400 mm, +z the way it shines
    assert np.isclose(np.linalg.norm(m[:3, 0]) * 2, 800.0) and np.isclose(np.linalg.norm(m[:3, 1]) * 2, 400.0)
    assert np.dot(np.cross(m[:3, 0], m[:3, 1]), r["normal"]) > 0
