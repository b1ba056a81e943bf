"""The alternatives to texture-space diffusion: the brute-force exact reference, screen-space
separable SSS and the per-pixel tint baseline, each against its own NumPy model."""

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.exact import ExactSettings
from skinlab.render.techniques.ssss import SsssSettings
from skinlab.render.techniques.tsd import TsdSettings
from skinlab.render.techniques.tsd.passes import frame_nodes, read_texture
from skinlab.scene.optics import ssss
from skinlab.scene.optics.edges import edge_response
from skinlab.scene.optics.exact_profile import exact_profile_convolution
from skinlab.scene.optics.material_medium import material_medium
from tests.tsd_scenes import entered, exact_profile, pixel_x, skin, slab_scene


def edge_row(res, n):
    row = res.hdr[n // 2, :, :3].astype(np.float64)
    return row, row[-8:].mean(axis=0)


@pytest.mark.parametrize("model", ["burley", "pbd"])
def test_exact_reference_follows_the_profile_edge_and_numpy_brute_force(renderer, model, multiple_only):
    n = 192
    scene = slab_scene(occluder=True, material=skin(model))
    res = renderer.render(scene, RenderSettings(n, n, shadow_size=4096, technique=ExactSettings(size=n)))
    assert [p.kind for p in res.plan.passes].count("tsd_exact") == 1
    assert "tsd_blur" not in [p.kind for p in res.plan.passes]
    t = frame_nodes(renderer.last_frame)[scene.find("slab").uid]
    medium = material_medium(t.material.values)
    row, lit = edge_row(res, n)
    texel_mm = 2 * scene.mm_per_unit / n
    x_mm = pixel_x(n, 1.0) * scene.mm_per_unit
    # the edge response averaged over an irradiance texel: each texel holds the light over its square
    # (lib/shadow.glsl shadow_pcf_area), from where the light entered (entered: spread as the frame does)
    within = (np.arange(16) + 0.5) / 16 - 0.5
    profile = exact_profile(model, medium)
    er = lambda e: edge_response(-e, profile, "profile")  # noqa: E731
    edge = np.mean([entered(er, x_mm + w * texel_mm, scene, texel_mm, averaged=True) for w in within], axis=0)
    err = np.abs(row / lit - edge)
    assert err.max() < 0.03, (err.max(axis=0), int(err.argmax()) // 3)
    # texture level against the NumPy brute-force convolution of the same irradiance
    irr, stretch = read_texture(t.targets.irradiance), read_texture(t.targets.stretch)
    gpu = read_texture(t.targets.levels[0])[..., :3]
    ref = exact_profile_convolution(
        irr, (stretch[n // 2, n // 2, 0], stretch[n // 2, n // 2, 1]), exact_profile(model, medium)
    )
    core = (slice(16, -16), slice(16, -16))
    rel = np.abs(gpu[core] - ref[core]).sum(axis=(0, 1)) / np.abs(ref[core]).sum(axis=(0, 1))
    assert np.all(rel < 0.02), rel


def test_screen_space_sss_follows_its_separable_kernel(renderer, multiple_only):
    """Across a straight shadow edge facing the camera, the horizontal pass does all the work: the
    rendered edge is the 1-D kernel's cumulative sum (at the pixel scale), within 2 %; and it is a
    fair approximation of the exact profile's edge (within 6 %)."""
    n = 160
    scene = slab_scene(occluder=True, material=skin("burley"))
    for taps in (11, 25):
        st = RenderSettings(n, n, shadow_size=4096, technique=SsssSettings(taps=taps))
        res = renderer.render(scene, st)
        assert [p.kind for p in res.plan.passes] == ["shadow", "forward", "ssss_blur", "tonemap"]
        plan = res.plan.passes[2].params.ssss
        kernel = plan.kernels[0]  # the frame's one scattering material
        assert plan.taps == len(kernel.offsets_mm) == taps
        row, lit = edge_row(res, n)
        x_mm, px_mm = pixel_x(n, 1.0) * scene.mm_per_unit, 2 * scene.mm_per_unit / n  # from where the light entered:
        own = entered(lambda e, k=kernel: ssss.separable_edge_response(-e, k.offsets_mm, k.weights), x_mm, scene, px_mm)
        err = np.abs(row / lit - own)
        assert err.max() < 0.02 + 1.0 / taps, (taps, err.max(axis=0))
        medium = material_medium(kernel.material.values)
        exact = entered(
            lambda e, m=medium: edge_response(-e, exact_profile("burley", m), "profile"), x_mm, scene, px_mm
        )
        assert np.abs(row / lit - exact).max() < 0.06 + 1.0 / taps
    # the kernel itself: weights sum to 1 per channel, symmetric offsets
    np.testing.assert_allclose(kernel.weights.sum(axis=0), 1.0)
    np.testing.assert_allclose(kernel.offsets_mm, -kernel.offsets_mm[::-1])


def test_screen_space_sss_does_not_bleed_across_depth_discontinuities(renderer):
    """A second, nearer slab over half the view: its scattering must not pull in the far slab's
    light across the silhouette (follow-the-surface), so the near slab's unlit side stays dark."""
    from skinlab.scene.graph import MeshNode
    from tests.tsd_scenes import quad_mesh

    scene = slab_scene(material=skin("burley"))
    near = quad_mesh("near", -1.5, 0.0, -1.5, 1.5, z=10.0)  # 10 units = 200 mm nearer the camera
    near_mat = skin("burley", base=(1.0, 1.0, 1.0))
    scene.add(MeshNode("near", near, near_mat))
    scene.lights()[0].intensity = 1.0
    st = RenderSettings(96, 96, shadow_size=512, technique=SsssSettings(taps=25))
    a = renderer.render(scene, st).hdr
    scene.find("slab").visible = False
    b = renderer.render(scene, st).hdr
    # the near slab's pixels next to the silhouette look the same with or without the far slab
    cols = slice(40, 46)
    np.testing.assert_allclose(a[20:76, cols], b[20:76, cols], rtol=0.02, atol=1e-4)


def test_tint_baseline_is_the_profile_colour_without_blur(renderer, multiple_only):
    scene = slab_scene(material=skin("burley"))
    st = RenderSettings(48, 48, technique=TsdSettings(size=64))
    tsd_img = renderer.render(scene, st).hdr[24, 24, :3]
    res = renderer.render(scene, RenderSettings(48, 48, technique="tint"))
    assert [p.kind for p in res.plan.passes] == ["forward", "tonemap"]
    tint = res.plan.passes[0].params.hook.tints[scene.find("slab").uid][1]
    np.testing.assert_allclose(res.hdr[24, 24, :3], tsd_img * tint, rtol=1e-3)
    assert tint.max() == 1.0 and tint.min() < 1.0
