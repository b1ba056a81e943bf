"""The directional shadow map fitted to the scene's box as the light sees it (skinlab/render/passes/shadow.py):
everything in the box is inside the map, the map is no larger than it must be, and a shadow edge falls
where the geometry puts it, to within the map's texel quantisation."""

import math

import numpy as np
import pytest

from skinlab.render.passes.shadow import CLIP_TO_TEXTURE, FIT_MARGIN, box_corners, light_view_proj
from skinlab.scene import transform as tf
from skinlab.scene.graph import LightNode


def _directional(direction) -> LightNode:
    light = LightNode("key", "directional")
    light.rotation = tf.look_at_rotation(np.zeros(3), np.asarray(direction, np.float64))
    return light


BOXES = [
    (np.array([-200.0, -240.0, -40.0]), np.array([200.0, 80.0, 64.0])),  # the slab-edge reference scene
    (np.array([-1.0, -1.0, -1.0]), np.array([1.0, 1.0, 1.0])),
    (np.array([0.0, 0.0, 0.0]), np.array([5.0, 0.0, 1.0])),  # flat: no extent in y
]
DIRECTIONS = [(0.0, 1.0, -1.0), (0.0, -1.0, 0.0), (0.3, -0.8, -0.5), (1.0, 0.0, 0.0)]


@pytest.mark.parametrize("box", range(len(BOXES)))
@pytest.mark.parametrize("direction", DIRECTIONS)
def test_the_box_fills_the_map(box, direction):
    lo, hi = BOXES[box]
    m = CLIP_TO_TEXTURE @ light_view_proj(_directional(direction), lo, hi)
    c = np.c_[box_corners(lo, hi), np.ones(8)] @ m.T
    c = c[:, :3] / c[:, 3:]
    assert np.isfinite(c).all()
    # inside, and touching the margin on every side: tight in x, y and depth
    edge = FIT_MARGIN / (1 + 2 * FIT_MARGIN)
    assert (c >= edge - 1e-9).all() and (c <= 1 - edge + 1e-9).all()
    for k in range(3):
        extent = c[:, k].max() - c[:, k].min()
        if extent > 1e-3:  # a flat box seen edge-on has no extent across it
            assert c[:, k].min() == pytest.approx(edge, abs=1e-5) and c[:, k].max() == pytest.approx(1 - edge, abs=1e-5)


def test_the_fit_is_smaller_than_the_bounding_sphere_on_a_flat_scene():
    lo, hi = BOXES[0]
    m = light_view_proj(_directional((0.0, 1.0, -1.0)), lo, hi)
    radius = np.linalg.norm(hi - lo) / 2
    # world size of the map across (x) and up (y): 2 / scale of the projection's rows
    across = 2 / np.linalg.norm(m[0, :3])
    up = 2 / np.linalg.norm(m[1, :3])
    assert across == pytest.approx((hi[0] - lo[0]) * (1 + 2 * FIT_MARGIN), rel=1e-5)  # 408 mm
    assert up < 2 * radius / 1.7  # 306 mm against the sphere's 532 mm: texels 1.7x smaller


def _edge_row(img: np.ndarray, cols: slice, lit_rows: slice, rows: slice) -> float:
    """Where a horizontal lit-to-dark edge lies, in rows: the first row plus the sum of each row's
    brightness relative to the lit side (exact for any blur symmetric about the edge)."""
    prof = img[..., :3].sum(-1)[:, cols].mean(1)
    return rows.start + float((prof[rows] / prof[lit_rows].mean()).sum())


@pytest.mark.parametrize("shadow_size", [512, 1024, 2048])
def test_the_slab_shadow_edge_falls_where_the_geometry_puts_it(renderer, shadow_size):
    from skinlab.bench.truth_ledger import REFERENCE_SCENES
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene

    scene = load_scene(REFERENCE_SCENES / "slab-edge-skin1.toml")
    size = 96
    img = renderer.render(scene, RenderSettings.for_technique("none", size, size, shadow_size=shadow_size)).hdr
    # the black plate (y <= -40 mm, z 60..64 mm) shadows the slab's face z = 0 below y = -40 + 64 = 24 mm
    # for light travelling along (0, 1, -1); the camera at y = 20, 300 mm away, 16 degrees high
    half = 300 * math.tan(math.radians(8))
    mm_per_px = 2 * half / size
    geometric = (20 + half - 24) / mm_per_px  # 43.45 rows from the top
    edge = _edge_row(img, slice(8, 88), slice(28, 38), slice(30, 70))
    # the depth map places an edge to half a texel; a texel of the fitted map is (320 + 104) / sqrt(2) mm
    # x 1.02 across the light, and on the face (45 degrees) sqrt(2) times that
    texel_px = (424 / math.sqrt(2)) * (1 + 2 * FIT_MARGIN) / shadow_size * math.sqrt(2) / mm_per_px
    assert abs(edge - geometric) <= 0.5 * texel_px + 0.1, (edge, geometric, texel_px)


def test_the_subsurface_frame_moves_the_shadow_edge_by_the_oblique_entry_offset(renderer):
    """Light entering at 45 degrees diffuses from sin(theta_t) z0 further along its way (Wang & Jacques
    1995; skinlab/scene/optics/oblique.py): on the slab the light travels up, away from the shadow, so every
    subsurface technique's edge lies above the plain frame's (same shadow map), by less than the
    offset (single scattering and the surface's plain share are not shifted). The path-traced truth
    puts it 0.57 px above the plain frame's at this size (rows 42.84 and 43.41 at 1024 texels)."""
    from skinlab.bench.truth_ledger import REFERENCE_SCENES
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.optics.oblique import LUMA
    from skinlab.scene.scenefile import load_scene

    scene = load_scene(REFERENCE_SCENES / "slab-edge-skin1.toml")
    size = 96
    mm_per_px = 2 * 300 * math.tan(math.radians(8)) / size
    slab = next(n.material for n in scene.mesh_nodes() if n.material.name == "skin")
    medium = material_medium(slab.values)
    z0 = np.asarray(medium.mfp_arr)  # 1 / mu_t' (isotropic phase): the shaders' u_sss_mfp
    offset_px = float(np.asarray(z0) @ LUMA) * math.sin(math.radians(45)) / medium.eta / mm_per_px

    def edge(technique):
        img = renderer.render(scene, RenderSettings.for_technique(technique, size, size, shadow_size=1024)).hdr
        return _edge_row(img, slice(8, 88), slice(28, 38), slice(30, 70))

    plain = edge("none")
    assert 0.6 < offset_px < 1.0  # skin1: z0 = 1 mm (luminance), 0.81 px
    for technique in ("tsd", "ssss", "disk", "preintegrated"):
        moved = plain - edge(technique)
        assert 0.3 < moved < offset_px, (technique, moved, offset_px)
