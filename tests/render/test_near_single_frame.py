"""The near light's single scattering in the frame (lib/surface_inputs.glsl sss_near_single, the
forward pass): under point-light-skin1's light 2 mm above the slab the term is darker right below the
light and brighter far from its foot than a far light's (skinlab/scene/optics/near_single.py), and a
sun's frame is the same with it or without."""

import numpy as np

from skinlab.gl.shader_source import ShaderLibrary
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.resources import assets_root
from skinlab.scene.optics.near_single import near_single_gain
from skinlab.scene.scenefile import load_scene

REFERENCE = assets_root() / "scenes" / "reference"


def _frames(ctx, scene_file, size):
    scene = load_scene(REFERENCE / scene_file)
    st = RenderSettings(size, size)  # the default technique
    near = Renderer(ctx).render(scene, st).hdr[..., :3].astype(np.float64)
    far_lib = ShaderLibrary(defines={"passes/forward.frag": {"MEASURE_FAR_SINGLE": 1}})
    far = Renderer(ctx, far_lib).render(scene, st).hdr[..., :3].astype(np.float64)
    return scene, near, far


def test_point_light_single_scattering_is_the_near_lights(ctx):
    n = 48
    scene, near, far = _frames(ctx, "point-light-skin1.toml", n)
    assert np.isfinite(near).all() and np.isfinite(far).all()
    diff = (near - far).sum(-1)
    centre = diff[n // 2 - 2 : n // 2 + 2, n // 2 - 2 : n // 2 + 2].mean()
    # the view is 17.3 mm wide: its corners are about 12 mm from the light's foot
    ring = np.concatenate([diff[:3, :3].ravel(), diff[:3, -3:].ravel(), diff[-3:, :3].ravel(), diff[-3:, -3:].ravel()])
    g_centre = near_single_gain([0.0, 0.0, 2.0], [0, 0, 1.0], [0, 0, 1.0], [1.0] * 3, 1.0, 0.0)[0, 0]
    g_ring = near_single_gain([12.0, 0.0, 2.0], [0, 0, 1.0], [0, 0, 1.0], [1.0] * 3, 1.0, 0.0)[0, 0]
    assert g_centre < 1.0 < g_ring  # what the frame should show
    assert centre < 0.0 and (ring > 0.0).all()
    assert abs(centre) > 1e-3 * near[n // 2, n // 2].sum()  # not rounding: a visible part of the frame


def test_a_suns_frame_does_not_change(ctx):
    _, near, far = _frames(ctx, "slit-skin1.toml", 32)
    assert np.array_equal(near, far)
