"""The forward pass's depth pre-pass shades each pixel once and changes no pixel."""

import dataclasses

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import MeshNode
from skinlab.scene.materials import Material
from skinlab.scene.scenefile import load_scene
from tests.tsd_scenes import quad_mesh, slab_scene


@pytest.mark.parametrize("technique", ["none", "tsd", "ssss"])
def test_prepass_changes_no_pixel_of_the_head(renderer, technique):
    scene = load_scene(None)
    on = RenderSettings.for_technique(technique, 64, 64, shadow_size=256)
    off = dataclasses.replace(on, depth_prepass=False)
    a, b = renderer.render(scene, on), renderer.render(scene, off)
    assert "depth pre-pass" in a.plan.explain() and "depth pre-pass" not in b.plan.explain()
    np.testing.assert_array_equal(a.hdr, b.hdr)
    np.testing.assert_array_equal(a.depth, b.depth)


def test_prepass_shows_the_nearest_surface_whatever_the_draw_order(renderer):
    scene = slab_scene()  # the slab at z = 0, seen from +z
    red = Material("red", {"base_color": (1.0, 0.0, 0.0), "specular": 0.0})
    scene.add(MeshNode("near", quad_mesh("near", -0.5, 0.5, -0.5, 0.5, z=0.2), red))  # drawn after the slab
    far = slab_scene()
    far.add(MeshNode("behind", quad_mesh("behind", -0.5, 0.5, -0.5, 0.5, z=-0.2), red))  # hidden
    for s, centre_red in ((scene, True), (far, False)):
        res = renderer.render(s, RenderSettings(32, 32, technique="none"))
        px = res.hdr[16, 16, :3]
        assert (px[0] > 2 * px[1]) == centre_red, px
        ref = renderer.render(s, RenderSettings(32, 32, technique="none", depth_prepass=False))
        np.testing.assert_array_equal(res.hdr, ref.hdr)
