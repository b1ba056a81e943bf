"""Technique "disk" (importance-sampled Burley disk SSS, Golubev 2018): its NumPy kernel, the GLSL
helpers against their twins, the rendered edge against the kernel's edge response, energy
conservation, depth-aware rejection and many media in one frame."""

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.disk import DiskSettings
from skinlab.scene.graph import MeshNode
from skinlab.scene.optics import burley, disk
from skinlab.scene.optics.edges import edge_response
from skinlab.scene.optics.material_medium import material_medium
from tests.tsd_scenes import entered, exact_profile, pixel_x, quad_mesh, skin, slab_scene


def medium(radius=(8.0, 4.0, 2.0), color=(0.8, 0.6, 0.5)):
    return material_medium({"subsurface_color": color, "subsurface_radius": radius, "specular": 0.0})


@pytest.mark.parametrize("model", ["burley", "dipole", "pbd", "gaussians", "blender-burley"])
@pytest.mark.parametrize("n", [8, 33, 64])
def test_kernel_is_normalised_and_follows_the_burley_cdf(model, n):
    k = disk.disk_kernel(model, medium(), n)
    assert k.radii_mm.shape == (n,) and k.weights.shape == (n, 3)
    np.testing.assert_allclose(k.weights.sum(axis=0), 1.0)
    assert np.all(k.weights >= 0) and np.all(np.diff(k.radii_mm) > 0)
    # the radii are the Burley CDF's stratified quantiles
    np.testing.assert_allclose(burley.burley_cdf(k.radii_mm, k.d_mm), (np.arange(n) + 0.5) / n, atol=1e-9)
    assert k.radii_mm[-1] < 2 * k.reach_mm
    if model == "burley":
        # importance sampling the profile's own shape: the widest channel's weights are nearly uniform
        red = k.weights[:, 0]
        assert red.max() / red.min() < 1.5, red


def test_kernel_hard_cases():
    # no channel scatters (albedo 0 or radius 0): no weight, the shader keeps the centre; edge = step
    for m in (medium(color=(0.0, 0.0, 0.0)), medium(radius=(0.0, 0.0, 0.0))):
        k = disk.disk_kernel("burley", m, 16)
        assert np.all(k.weights == 0) and np.all(np.isfinite(k.radii_mm))
        x = np.array([-1.0, 0.0, 1.0])
        np.testing.assert_array_equal(disk.disk_edge_response(x, k), np.repeat([[1.0], [0.5], [0.0]], 3, axis=1))
    # one channel without scattering, albedo 1 on the others: finite, normalised where it scatters
    k = disk.disk_kernel("burley", medium(radius=(5.0, 1.0, 0.0), color=(1.0, 1.0, 1.0)), 16)
    np.testing.assert_allclose(k.weights.sum(axis=0), [1.0, 1.0, 0.0])
    # a tiny radius: tiny disc, still finite
    k = disk.disk_kernel("burley", medium(radius=(1e-3, 1e-3, 1e-3)), 16)
    assert np.all(np.isfinite(k.weights)) and k.radii_mm.max() < 1e-2
    with pytest.raises(ValueError, match="disk_samples"):
        disk.disk_kernel("burley", medium(), 0)
    with pytest.raises(ValueError, match="sss_model"):
        disk.disk_kernel("none", medium(), 8)


def test_edge_response_approaches_the_exact_profile_edge_with_more_samples():
    m = medium()
    x = np.linspace(-20, 20, 161)
    exact = edge_response(x, exact_profile("burley", m), "profile")
    errs = [np.abs(disk.disk_edge_response(x, disk.disk_kernel("burley", m, n)) - exact).max() for n in (8, 64)]
    assert errs[1] < errs[0] and errs[1] < 0.03, errs


def test_glsl_helpers_match_their_twins(glsl):
    px = np.array([0.5, 1.5, 7.5, 100.5, 255.5, 511.5, 0.5, 33.5])
    py = np.array([0.5, 0.5, 3.5, 20.5, 255.5, 511.5, 400.5, 0.5])
    gpu = glsl.evaluate("lib/disk.glsl", "interleaved_gradient_noise(vec2(px, py))", {"px": px, "py": py})[:, 0]
    ref = disk.interleaved_gradient_noise(px, py)
    wrap = np.abs(gpu - ref)
    assert np.all(np.minimum(wrap, 1.0 - wrap) < 2e-3), (gpu, ref)  # fp32 fract of a product
    assert np.all((gpu >= 0) & (gpu < 1))
    i = np.array([0.0, 1.0, 5.0, 31.0, 63.0, 0.0, 17.0, 63.0])
    r = np.array([0.0, 1e-6, 0.5, 3.0, 40.0, 1.0, 0.0, 1e-3])
    phi = np.array([0.0, 1.0, 6.2831853, 3.0, 0.5, 0.0, 2.0, 6.0])
    gpu = glsl.evaluate("lib/disk.glsl", "disk_offset(i, r, phi)", {"i": i, "r": r, "phi": phi}, 2)
    assert_close_fp32(gpu, disk.disk_offset(i, r, phi), what="disk_offset")
    assert np.all(gpu[r == 0] == 0)


def test_rendered_edge_follows_the_kernel_and_keeps_energy(renderer, multiple_only):
    """Across a straight shadow edge, the rendered profile averaged down the columns (the average
    over the per-pixel rotation) is the NumPy kernel's edge response (without the unblurred single
    scattering); far from the edge the lit side keeps exactly its light (the accepted weights are
    renormalised)."""
    n = 160
    scene = slab_scene(occluder=True, material=skin("burley"))
    x_mm, px_mm = pixel_x(n, 1.0) * scene.mm_per_unit, 2 * scene.mm_per_unit / n  # from where the light entered
    for samples in (16, 64):
        res = renderer.render(scene, RenderSettings(n, n, shadow_size=4096, technique=DiskSettings(samples=samples)))
        assert [p.kind for p in res.plan.passes] == ["shadow", "forward", "disk_sss", "tonemap"]
        prm = res.plan.passes[2].params
        k = prm.kernels[0]
        assert len(k.radii_mm) == samples
        rows = res.hdr[8:-8, :, :3].astype(np.float64).mean(axis=0)
        lit = rows[-8:].mean(axis=0)
        own = entered(lambda e, k=k: disk.disk_edge_response(-e, k), x_mm, scene, px_mm)
        err = np.abs(rows / lit - own)
        assert err.max() < 0.02 + 0.5 / samples, (samples, err.max(axis=0))  # pixel-scale sampling
        # energy: the filtered subsurface light against the unfiltered one, far from the edge
        f = renderer.last_frame.targets
        before = np.frombuffer(f["disk_diffuse"].read(), np.float32).reshape(n, n, 4)[..., :3]
        after = np.frombuffer(f["disk_filtered"].read(), np.float32).reshape(n, n, 4)[..., :3]
        far = (slice(8, -8), slice(-12, None))  # the unlit side: nothing arrives from the far lit side
        lit_side = (slice(8, -8), slice(n // 2 - 60, n // 2 - 50))
        np.testing.assert_allclose(after[far], before[far], atol=1e-6)
        # the lit side away from the edge: light moves toward the edge, none is added
        tot_before, tot_after = before[lit_side].sum(axis=(0, 1)), after[lit_side].sum(axis=(0, 1))
        assert np.all(tot_after <= tot_before * 1.02)


def test_flat_lit_slab_is_unchanged(renderer):
    """Energy conservation: a uniformly lit slab filters to itself (every weight renormalised)."""
    n = 64
    scene = slab_scene(material=skin("pbd"))
    renderer.render(scene, RenderSettings(n, n, shadow_size=256, technique=DiskSettings(samples=24)))
    f = renderer.last_frame.targets
    before = np.frombuffer(f["disk_diffuse"].read(), np.float32).reshape(n, n, 4)
    after = np.frombuffer(f["disk_filtered"].read(), np.float32).reshape(n, n, 4)
    assert before[..., :3].max() > 0 and np.all(before[..., 3] == 1.5)  # profile index 0 + 1, radius scale 1 / 2
    np.testing.assert_allclose(after, before, rtol=1e-4)


def test_depth_aware_rejection(renderer):
    """A second, nearer slab over half the view: its pixels next to the silhouette look the same with
    or without the far slab behind them."""
    scene = slab_scene(material=skin("burley"))
    scene.add(MeshNode("near", quad_mesh("near", -1.5, 0.0, -1.5, 1.5, z=10.0), skin("burley", base=(1, 1, 1))))
    st = RenderSettings(96, 96, shadow_size=512, technique=DiskSettings(samples=32))
    a = renderer.render(scene, st).hdr
    scene.find("slab").visible = False
    b = renderer.render(scene, st).hdr
    np.testing.assert_allclose(a[20:76, 40:46], b[20:76, 40:46], rtol=0.02, atol=1e-4)


def test_two_media_in_one_frame_match_each_rendered_alone(renderer):
    """Per-pixel profiles: two slabs of different media side by side (a gap between them) under a
    shadow edge each; each half of the frame matches the frame with only that slab."""
    scene = slab_scene(occluder=True, material=skin("burley"))
    scene.find("slab").visible = False
    wide = skin("burley", radius=(8.0, 4.0, 2.0))
    narrow = skin("dipole", radius=(1.0, 0.5, 0.25), color=(0.9, 0.5, 0.3))
    scene.add(MeshNode("top", quad_mesh("top", -1.0, 1.0, 0.05, 1.0), wide))
    scene.add(MeshNode("bottom", quad_mesh("bottom", -1.0, 1.0, -1.0, -0.05), narrow))
    st = RenderSettings(128, 128, shadow_size=2048, technique=DiskSettings(samples=32))
    both = renderer.render(scene, st)
    both_hdr = both.hdr.copy()
    prm = both.plan.passes[-2].params
    assert len(prm.kernels) == 2 and not both.plan.warnings
    alone = {}
    for name in ("top", "bottom"):
        for other in ("top", "bottom"):
            scene.find(other).visible = other == name
        alone[name] = renderer.render(scene, st).hdr.copy()
    # a sample on another profile's pixel is rejected, so each slab is shaded as if alone, up to the gap
    top, bottom = slice(0, 61), slice(67, 128)  # image rows run top to bottom: y > 0 first
    np.testing.assert_allclose(both_hdr[top], alone["top"][top], rtol=1e-3, atol=1e-5)
    np.testing.assert_allclose(both_hdr[bottom], alone["bottom"][bottom], rtol=1e-3, atol=1e-5)
    # and the two halves are different: the narrow medium's edge is sharper
    assert np.abs(alone["top"][20, :, 0] - alone["bottom"][100, :, 0]).max() > 0.01


def test_cli_lists_and_renders_disk(tmp_path):
    import subprocess
    import sys

    help_text = subprocess.run(
        [sys.executable, "-m", "skinlab.cli", "render", "--help"], capture_output=True, text=True, check=True
    ).stdout
    assert "--disk-samples N" in help_text and "an integer in [8, 64] (default: 32)" in help_text
    out = tmp_path / "d.png"
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "skinlab.cli",
            "render",
            "--size",
            "32x32",
            "--technique",
            "disk",
            "--disk-samples",
            "8",
            "--out",
            str(out),
            "--explain",
        ],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0 and out.exists() and "disk_sss" in run.stdout, run.stderr
    bad = subprocess.run(
        [
            sys.executable,
            "-m",
            "skinlab.cli",
            "render",
            "--size",
            "8x8",
            "--technique",
            "disk",
            "--disk-samples",
            "4",
            "--out",
            str(tmp_path / "e.png"),
        ],
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2 and "--disk-samples: expected an integer in [8, 64], got 4" in bad.stderr
    assert "Traceback" not in bad.stderr


def test_viewer_cycles_to_disk(ctx, tmp_path):
    from skinlab.scene.scenefile import ASSETS, DEFAULT_SCENE
    from skinlab.viewer.core import ViewerCore

    head = tmp_path / "head.toml"
    head.write_text(DEFAULT_SCENE.read_text().replace("../lee-perry-smith/", f"{ASSETS / 'lee-perry-smith'}/"))
    c = ViewerCore(ctx, head, RenderSettings(32, 24, shadow_size=256), settle_s=0.05)
    try:
        seen = [c.settings.technique_name]
        for _ in range(8):
            seen.append(c.cycle_technique())
        assert "disk" in seen and "exact" not in seen
        c.set_technique("disk")
        assert c.render() and c.errors() == []
        assert {"disk_diffuse", "disk_filtered"} <= set(c.targets())
        assert c.set_technique_option("samples", 16) == 16 and c.settings.technique.samples == 16
    finally:
        c.close()


@pytest.mark.parametrize("compute", ["off", "on"])  # the fragment pass and its compute shader (RenderSettings.compute)
def test_pass_matches_its_numpy_model_pixel_by_pixel(renderer, compute):
    """The disk pass on a shadow-edge slab with a nearer slab over part of it (rejection in depth)
    against skinlab/scene/optics/disk.py disk_filter_reference on the same forward targets. A sample's
    position may differ in fp32 by ~1e-3 pixel and a sample land on the neighbouring texel, so 98 %
    of the pixels must agree to 1e-4 relative, all to 5 % (on llvmpipe all agree to 5e-7)."""
    import math

    n = 64
    scene = slab_scene(occluder=True, material=skin("burley"))
    scene.add(MeshNode("near", quad_mesh("near", 0.3, 0.9, -0.6, 0.2, z=0.5), skin("dipole", radius=(3, 2, 1))))
    st = RenderSettings(n, n, shadow_size=1024, technique=DiskSettings(samples=16), compute=compute)
    res = renderer.render(scene, st)
    f = renderer.last_frame
    prm = next(p.params for p in res.plan.passes if p.kind == "disk_sss")
    assert prm.compute is (compute == "on")
    src = np.frombuffer(f.targets["disk_diffuse"].read(), np.float32).reshape(n, n, 4)
    gpu = np.frombuffer(f.targets["disk_filtered"].read(), np.float32).reshape(n, n, 4)[..., :3]
    depth = np.frombuffer(f.targets["depth"].read(), np.float32).reshape(n, n).astype(np.float64)
    cam = scene.camera
    zn, zf = cam.znear, cam.zfar
    view_z = 2 * zn * zf / (zf + zn - (depth * 2 - 1) * (zf - zn))
    ys, xs = np.mgrid[0:n, 0:n] + 0.5
    phi = 2 * math.pi * disk.interleaved_gradient_noise(xs, ys)
    ref = disk.disk_filter_reference(
        src[..., :3],
        src[..., 3],
        view_z,
        prm.table(),
        np.array([k.reach_mm for k in prm.kernels]),
        scene.mm_per_unit,
        n / (2 * math.tan(cam.yfov / 2)),
        phi,
    )
    assert len(prm.kernels) == 2 and np.abs(ref - src[..., :3]).max() > 0.01  # it filters
    rel = np.abs(gpu - ref) / np.maximum(np.abs(ref), 1e-3)
    worst = rel.max(axis=2)
    assert np.mean(worst < 1e-4) > 0.98 and worst.max() < 0.05, (np.mean(worst < 1e-4), worst.max())
