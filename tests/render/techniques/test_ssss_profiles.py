"""Screen-space techniques with per-pixel profiles (ssss here; disk in test_disk.py): each pixel is blurred with its own
material's kernel (a table of profiles, the index written by the forward pass), so two media in one
frame each match the frame with that medium alone."""

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.ssss import SsssSettings
from skinlab.scene.graph import MeshNode
from skinlab.scene.optics import ssss
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.profile_fit import profile_fit
from tests.tsd_scenes import quad_mesh, skin, slab_scene


def test_two_media_in_one_frame_match_each_rendered_alone(renderer):
    scene = slab_scene(occluder=True, material=skin("burley"))
    scene.find("slab").visible = False
    wide = skin("burley", radius=(8.0, 4.0, 2.0))
    narrow = skin("dipole", radius=(1.0, 0.5, 0.25), color=(0.9, 0.5, 0.3))
    scene.add(MeshNode("top", quad_mesh("top", -1.0, 1.0, 0.05, 1.0), wide))
    scene.add(MeshNode("bottom", quad_mesh("bottom", -1.0, 1.0, -1.0, -0.05), narrow))
    st = RenderSettings(128, 128, shadow_size=2048, technique=SsssSettings(taps=17))
    both = renderer.render(scene, st)
    both_hdr = both.hdr.copy()
    plan = both.plan.passes[-2].params.ssss
    assert len(plan.kernels) == 2 and not both.plan.warnings  # one kernel per medium, no warning
    assert "2: 'slab' (burley), 'slab' (dipole)" in both.plan.passes[-2].reason
    # each kernel is its own medium's
    for k, mat in zip(plan.kernels, (wide, narrow)):
        off, w, _ = ssss.ssss_kernel(profile_fit(mat["sss_model"], material_medium(mat.values), 6), 17)
        np.testing.assert_allclose(k.weights, w)
    alone = {}
    for name in ("top", "bottom"):
        for other in ("top", "bottom"):
            scene.find(other).visible = other == name
        alone[name] = renderer.render(scene, st).hdr.copy()
    top, bottom = slice(0, 60), slice(68, 128)  # image rows run top to bottom: y > 0 first
    np.testing.assert_allclose(both_hdr[top], alone["top"][top], rtol=1e-3, atol=1e-5)
    np.testing.assert_allclose(both_hdr[bottom], alone["bottom"][bottom], rtol=1e-3, atol=1e-5)
    assert np.abs(alone["top"][20, :, 0] - alone["bottom"][100, :, 0]).max() > 0.01


@pytest.mark.parametrize("technique", ["ssss", "disk"])
def test_more_profiles_than_the_table_holds_warns(renderer, technique):
    from skinlab.render.profile_table import MAX_PROFILES
    from skinlab.resources import shader_root

    # the one table size (skinlab/render/profile_table.py) is the size both shaders declare
    define = {"ssss": ("blur.glsl", "MAX_SSSS_PROFILES"), "disk": ("gather.glsl", "MAX_DISK_PROFILES")}[technique]
    src = (shader_root() / "techniques" / technique / define[0]).read_text(encoding="utf-8")
    assert f"#define {define[1]} {MAX_PROFILES}\n" in src

    scene = slab_scene(material=skin("burley"))
    scene.find("slab").visible = False
    for i in range(MAX_PROFILES + 1):
        y = -1.0 + 2.0 * i / (MAX_PROFILES + 1)
        m = skin("burley", radius=(1.0 + i, 1.0, 1.0))
        scene.add(MeshNode(f"strip{i}", quad_mesh(f"strip{i}", -1.0, 1.0, y, y + 0.1), m))
    res = renderer.render(scene, RenderSettings(32, 32, shadow_size=128, technique=technique))
    prm = res.plan.passes[-2].params
    kernels = prm.ssss.kernels if technique == "ssss" else prm.kernels
    assert len(kernels) == MAX_PROFILES
    assert any(f"{technique} keeps {MAX_PROFILES} profiles per frame: node 'strip16'" in w for w in res.plan.warnings)
    assert np.all(np.isfinite(res.hdr))
