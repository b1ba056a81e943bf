"""The environment map's orientation is the same in the frame and in the truth: a map that is black
but for one bright texel lights the same side of a sphere in Skinlab's frame and in a tiny Mitsuba
render, at three rotations (skinlab/scene/envmap.py, skinlab/truth/export.py)."""

import math

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.scene.envmap import write_map
from skinlab.scene.graph import CameraNode, MeshNode, Scene
from skinlab.scene.materials import Material
from skinlab.scene.primitives import sphere_mesh

pytest.importorskip("mitsuba")

W, H = 64, 32
TEXEL = (16, 12)  # column, row: u = 0.258, theta = 70 degrees: toward +X of the map, a little up


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))


def one_texel_scene(tmp_path, rotation_deg: float) -> Scene:
    px = np.zeros((H, W, 3), np.float32)
    i, j = TEXEL
    px[j, i] = 2000.0
    path = write_map(tmp_path / "one-texel.exr", px)
    s = Scene("one-texel", 10.0)
    s.environment.ambient = np.zeros(3)
    s.environment.map = path
    s.environment.rotation_deg = rotation_deg
    mat = Material("white", {"base_color": [0.8, 0.8, 0.8], "specular": 0.0, "roughness": 1.0})
    s.add(MeshNode("sphere", sphere_mesh(1.0, 3), mat))
    cam = CameraNode("cam", yfov=math.radians(30.0), znear=1.0, zfar=20.0)
    cam.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0))
    s.add(cam)
    return s


def lit_centroid(img: np.ndarray) -> np.ndarray:
    """(x, y) of the brightness-weighted centroid of the object's pixels, in [-1, 1], y up."""
    lum = img[..., :3].mean(-1) * (img[..., 3] > 0.5)
    h, w = lum.shape
    ys, xs = np.mgrid[0:h, 0:w]
    x = (xs + 0.5) / w * 2 - 1
    y = 1 - (ys + 0.5) / h * 2
    return np.array([(lum * x).sum(), (lum * y).sum()]) / max(lum.sum(), 1e-30)


@pytest.mark.parametrize("rotation, side", [(0.0, +1), (180.0, -1), (-90.0, 0)])
def test_one_bright_texel_lights_the_same_side_in_frame_and_truth(tmp_path, renderer, rotation, side):
    from skinlab.truth.reference import ReferenceRequest, render_reference

    s = one_texel_scene(tmp_path, rotation)
    frame = renderer.render(s, RenderSettings.for_technique("none", 32, 32, shadow_size=256, bounces=0)).hdr
    truth = render_reference(s, ReferenceRequest(32, 32, spp=64, passes=2), progress=False).image
    cf, ct = lit_centroid(frame), lit_centroid(truth)
    # rotation 0: the texel is toward +X (image right); 180: -X (left); -90: +Z, toward the camera
    for c in (cf, ct):
        if side == 0:
            assert abs(c[0]) < 0.1, (cf, ct)
        else:
            assert side * c[0] > 0.25, (cf, ct)
        assert c[1] > 0.05, (cf, ct)  # the texel is above the horizon: the upper half is lit
    assert np.allclose(cf, ct, atol=0.03), (cf, ct)
    # the same light (measured: the frame 1-2 % darker, the truth's noise at 64 spp a few %)
    e_f, e_t = frame[..., :3].sum(), truth[..., :3].sum()
    assert abs(e_f / e_t - 1) < 0.05, (e_f, e_t)
