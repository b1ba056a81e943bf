"""Per-pixel profiles in the screen-space techniques, the issue's own test: two bunnies of different
media (skim milk and ketchup, Jensen et al. 2001) side by side in one frame; each matches the frame
with that bunny alone (shadows off, so neither bunny darkens the other)."""

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import MeshNode
from skinlab.scene.materials import Material
from skinlab.scene.scenefile import ASSETS, load_scene


@pytest.mark.parametrize("technique", ["ssss", "disk"])
def test_two_bunnies_of_different_media_match_each_alone(renderer, technique):
    scene = load_scene(ASSETS / "scenes" / "bunny-skimmilk.toml")
    first = scene.mesh_nodes()[0]
    other = first.material.with_overrides(
        {"subsurface_radius": (3.0, 0.8, 0.4), "subsurface_color": (0.7, 0.1, 0.05)}, name="red"
    )
    assert isinstance(other, Material)
    second = MeshNode("bunny2", first.mesh, other)
    second.translation = (0.2, 0.0, 0.0)
    scene.add(second)
    for light in scene.lights():
        light.cast_shadow = False
    scene.camera.look_at((0.08, 0.12, 0.55), (0.08, 0.1, 0.0))
    # without interreflection: together the bunnies light each other, which is not what is compared here
    st = RenderSettings(96, 64, technique=technique, bounces=0)
    both = renderer.render(scene, st)
    both_hdr = both.hdr.copy()
    own = next(p for p in both.plan.passes if p.kind in ("ssss_blur", "disk_sss"))
    kernels = own.params.ssss.kernels if technique == "ssss" else own.params.kernels
    assert len(kernels) == 2 and not both.plan.warnings  # two profiles, no one-kernel warning
    alone = {}
    for name, node in (("bunny", first), ("bunny2", second)):
        first.visible, second.visible = node is first, node is second
        alone[name] = renderer.render(scene, st).hdr.copy()
    for name in ("bunny", "bunny2"):
        mask = alone[name][..., 3] > 0  # this bunny's pixels
        assert mask.sum() > 200
        np.testing.assert_allclose(both_hdr[mask], alone[name][mask], rtol=1e-3, atol=1e-5)
    # the media differ where they are seen: the frames are not the same bunny twice
    assert np.abs(alone["bunny"][..., :3].sum() - alone["bunny2"][..., :3].sum()) > 1.0
