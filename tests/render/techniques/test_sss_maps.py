"""Per-texel subsurface weight and radius maps (skinlab/scene/materials.py subsurface_map,
subsurface_radius_map; skinlab/shaders/lib/sss_maps.glsl): the weight map in every technique's hook, the
radius map in the disk technique's per-pixel sample radius."""

import numpy as np
import pytest
from PIL import Image

from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.disk import DiskSettings
from tests.tsd_scenes import skin, slab_scene


def grey_png(path, left, right, n=64):
    """An n x n greyscale PNG: columns u < 1/2 at `left`, the rest at `right` (0..255)."""
    img = np.full((n, n), right, np.uint8)
    img[:, : n // 2] = left
    Image.fromarray(img, "L").convert("RGB").save(path)
    return str(path)


@pytest.mark.parametrize("technique", ["tint", "ssss", "disk", "preintegrated", "tsd"])
def test_weight_map_halves_match_the_plain_weights(renderer, tmp_path, technique):
    """A uniformly lit slab (nothing for a blur to move) with a weight map black on the left half and
    white on the right: each half, further from the middle than the blur's reach, matches the slab
    with subsurface 0 (plain Burley diffuse) or 1."""
    m = grey_png(tmp_path / "w.png", 0, 255)
    n, R = 48, (2.0, 1.0, 0.5)  # the view spans 40 mm; compared pixels are 10 mm from the middle
    st = RenderSettings(n, n, shadow_size=256, technique=technique)
    img = {}
    for key, mat in (
        ("map", skin("burley", radius=R, subsurface_map=m)),
        ("zero", skin("burley", radius=R, subsurface=0.0)),
        ("one", skin("burley", radius=R)),
    ):
        img[key] = renderer.render(slab_scene(material=mat), st).hdr[..., :3].copy()
    rows, left, right = slice(8, -8), slice(4, n // 2 - 12), slice(n // 2 + 12, -4)
    # the weight shows (plain Burley diffuse and the subsurface term differ by ~2.4 % here)
    assert np.abs(img["zero"][rows, left] - img["one"][rows, left]).max() > 0.005
    np.testing.assert_allclose(img["map"][rows, left], img["zero"][rows, left], rtol=2e-3, atol=1e-5)
    np.testing.assert_allclose(img["map"][rows, right], img["one"][rows, right], rtol=2e-3, atol=1e-5)


def test_radius_map_scales_the_disk_radius(renderer, tmp_path):
    """A uniform radius map of grey g is the material with subsurface_radius x 2 g/255 (the disk's
    radii and depth reach scale with the pixel's radius scale; the weights do not change)."""
    g = 64
    m = grey_png(tmp_path / "r.png", g, g)
    k = 2 * g / 255
    n = 128
    st = RenderSettings(n, n, shadow_size=2048, technique=DiskSettings(samples=32))
    mapped = renderer.render(slab_scene(occluder=True, material=skin("burley", subsurface_radius_map=m)), st)
    mapped = mapped.hdr[..., :3].copy()
    scaled = renderer.render(slab_scene(occluder=True, material=skin("burley", radius=(8 * k, 4 * k, 2 * k))), st)
    full = renderer.render(slab_scene(occluder=True, material=skin("burley")), st).hdr[..., :3].copy()
    # the map is a half-float texture: its scale differs from 2 g / 255 in the fourth digit, which
    # moves a few samples across a pixel boundary at the shadow edge
    diff = np.abs(mapped - scaled.hdr[..., :3])
    assert np.quantile(diff, 0.99) < 1e-3 and diff.mean() < 1e-4 and diff.max() < 0.02, (diff.mean(), diff.max())
    assert np.abs(mapped - full).max() > 0.02  # the map changed the edge


def test_radius_map_widens_texture_space_diffusion_through_the_stretch_map(renderer, tmp_path):
    """TSD: a uniform radius map of grey g divides the stretch map (mm per texel) by 2 g / 255, so the
    blurred edge is the one of the material with subsurface_radius x 2 g / 255 (its Gaussian fit
    scaled), and the stretch map is redone when the map changes."""
    from skinlab.render.techniques.tsd import TsdSettings
    from skinlab.render.techniques.tsd.passes import frame_nodes, read_texture

    g = 191
    k = 2 * g / 255
    n = 128
    st = RenderSettings(n, n, shadow_size=2048, technique=TsdSettings(size=256))
    plain = slab_scene(occluder=True, material=skin("burley"))
    renderer.render(plain, st)
    s_plain = read_texture(frame_nodes(renderer.last_frame)[plain.find("slab").uid].targets.stretch)[..., :2].copy()
    mapped_scene = slab_scene(
        occluder=True, material=skin("burley", subsurface_radius_map=grey_png(tmp_path / "r.png", g, g))
    )
    mapped = renderer.render(mapped_scene, st).hdr[..., :3].copy()
    t = frame_nodes(renderer.last_frame)[mapped_scene.find("slab").uid]
    s_map = read_texture(t.targets.stretch)[..., :2]
    core = (slice(16, -16), slice(16, -16))
    np.testing.assert_allclose(s_map[core], s_plain[core] / k, rtol=2e-3)
    scaled = renderer.render(slab_scene(occluder=True, material=skin("burley", radius=(8 * k, 4 * k, 2 * k))), st)
    full = renderer.render(plain, st).hdr[..., :3]
    row = slice(n // 2 - 4, n // 2 + 4)
    err = np.abs(mapped[row] - scaled.hdr[row, :, :3]).max()
    assert err < 0.1 * np.abs(full[row] - scaled.hdr[row, :, :3]).max() + 2e-3, err
