"""Compute shaders for the screen- and texture-space passes (skinlab/render/compute.py): every pass with a
compute variant gives its fragment pass's image to fp32 rounding (on llvmpipe, bit for bit), the
compute kernels match the NumPy twins the fragment passes are checked against (the disk pass's
model: tests/render/techniques/test_disk.py, both paths), the planner picks the
path per pass and says why, and a context without compute shaders falls back to the fragment path."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from skinlab.render.compute import Device, choose_path
from skinlab.render.frame_plan import PlannedPass
from skinlab.render.plan import plan_frame
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd.passes import (
    TsdBlurPass,
    dilate,
    read_texture,
    seam_fill,
    store,
)
from skinlab.render.techniques.tsd.plan import TsdBlurParams
from skinlab.scene.graph import MeshNode
from skinlab.scene.optics import tsd
from skinlab.scene.optics.tsd import BlurStep
from tests.render.techniques.test_tsd_seams import _random_seam_case
from tests.tsd_scenes import quad_mesh, skin, slab_scene

FP32 = 4 * np.finfo(np.float32).eps


def assert_fp32_equal(a, b, what):
    tol = FP32 * np.maximum(np.abs(a), 1e-3)
    bad = np.abs(np.asarray(a, np.float64) - b) > tol
    assert not bad.any(), (what, int(bad.sum()), float(np.abs(a - b).max()))


def two_media_slab():
    """The shadow-edge slab (burley) with a nearer dipole slab over part of it (depth rejection, two
    profiles) and some ambient light."""
    s = slab_scene(occluder=True, material=skin("burley"), ambient=0.05)
    s.add(MeshNode("near", quad_mesh("near", 0.3, 0.9, -0.6, 0.2, z=0.5), skin("dipole", radius=(3, 2, 1))))
    return s


def both_paths(renderer, scene, technique, **kw):
    out = {}
    for mode in ("off", "on"):
        renderer.forget_reuse()
        st = RenderSettings.for_technique(technique, 40, 32, shadow_size=512, compute=mode, **kw)
        out[mode] = renderer.render(scene, st)
    return out["off"], out["on"]


@pytest.mark.parametrize(
    "technique,extra",
    [("none", {}), ("ssss", {}), ("disk", {"samples": 16}), ("tsd", {"size": 64}), ("exact", {"size": 32})],
)
@pytest.mark.parametrize("supersample", [1, 2])
def test_each_compute_pass_gives_its_fragment_pass_image(renderer, technique, extra, supersample):
    frag, comp = both_paths(renderer, two_media_slab(), technique, supersample=supersample, **extra)
    ran = [p for p in comp.plan.passes if "compute shader" in p.reason]
    assert "tonemap" in [p.name for p in ran]  # the tone mapping (and the supersample filter) ran as compute
    if technique != "none":
        assert len(ran) >= 2, comp.plan.explain()  # ...and the technique's own passes
    assert not any("compute shader" in p.reason for p in frag.plan.passes)
    assert_fp32_equal(comp.hdr, frag.hdr, "hdr")
    assert np.abs(comp.ldr.astype(int) - frag.ldr).max() <= 1
    assert np.abs(frag.hdr[..., :3]).max() > 0.01  # a lit frame


def test_texture_space_compute_passes_on_a_mesh_with_seams(renderer):
    """The head at 256 texels: its UV seams (the seam fill in the dilation and after the blur) and its
    maps; every texture-space level and the stretch map equal on both paths."""
    from skinlab.scene.scenefile import load_scene

    scene = load_scene("head")
    levels = {}
    for mode in ("off", "on"):
        renderer.forget_reuse()
        res = renderer.render(
            scene, RenderSettings.for_technique("tsd", 24, 24, shadow_size=256, size=256, compute=mode), ("hdr",)
        )
        assert any(p.kind == "tsd_blur" for p in res.plan.passes) and any(
            p.kind == "tsd_seams" for p in res.plan.passes
        )
        t = next(iter(store(renderer).nodes.values()))
        levels[mode] = [read_texture(x) for x in (t.stretch, t.irradiance, *t.levels)] + [res.hdr]
    for k, (a, b) in enumerate(zip(levels["off"], levels["on"])):
        assert_fp32_equal(b, a, f"texture {k}")


def test_compute_dilation_matches_its_twin(renderer):
    """techniques/tsd/dilate.comp (every ring in one dispatch, in shared memory) against
    dilate_reference: islands, holes, the texture's edges, work groups' edges; in place and not."""
    rng = np.random.default_rng(7)
    n = 37  # not a multiple of the 16-texel work group
    img = np.zeros((n, n, 4), np.float32)
    mask = rng.random((n, n)) < 0.12
    mask[10:20, 14:19] = True
    img[mask, :3] = rng.uniform(0.1, 2.0, (mask.sum(), 3))
    img[mask, 3] = 1.0
    t = store(renderer).targets(SimpleNamespace(uid=-31), n)
    try:
        t.stretch.write(img.tobytes())
        dilate(renderer, t, t.stretch, t.stretch, 4, compute=True)
        np.testing.assert_allclose(read_texture(t.stretch), tsd.dilate_reference(img, 4), rtol=1e-5, atol=1e-6)
        t.raw.write(img.tobytes())
        dilate(renderer, t, t.raw, t.irradiance, 3, compute=True)
        ref = tsd.dilate_reference(img, 3)
        np.testing.assert_allclose(read_texture(t.irradiance), ref, rtol=1e-5, atol=1e-6)
        assert (ref[..., 3] > 0).sum() > 2 * mask.sum()  # it did grow
        np.testing.assert_array_equal(read_texture(t.raw), img)  # the source is kept
    finally:
        store(renderer).nodes.pop(-31).release()


def test_compute_seam_fill_and_blur_match_their_twins(renderer):
    """The blur and the seam fill as compute shaders against diffuse_reference with the seam map and
    seam_fill_reference (the fragment passes' twins), 1e-4."""
    n = 40
    img, seam, _, _ = _random_seam_case(n)
    node = SimpleNamespace(uid=-32, name="seams")
    t = store(renderer).targets(node, n)
    try:
        t.raw.write(img.tobytes())
        t.seam_map(renderer.ctx).texture.write(seam.tobytes())
        seam_fill(renderer, t, t.raw, t.irradiance, compute=True)
        filled = read_texture(t.irradiance)
        np.testing.assert_allclose(filled, tsd.seam_fill_reference(img, seam), rtol=1e-4, atol=1e-5)
        stretch = np.zeros((n, n, 4), np.float32)
        stretch[..., :2] = np.linspace(0.2, 0.5, n)[None, :, None]
        stretch[..., 3] = 1.0
        t.stretch.write(stretch.tobytes())
        step = BlurStep(0, 1.0, 1.0, 11, (1.0, 1.0, 1.0))
        kernel = tsd.DiffusionKernel((step,), np.zeros(3))
        for seams in (None, object()):
            prm = TsdBlurParams(node=node, size=n, material=None, kernel=kernel, step=step, seams=seams, compute=True)
            TsdBlurPass(renderer).run(SimpleNamespace(targets={}), PlannedPass("b", "tsd_blur", "x", (n, n), "", prm))
            (want,), _ = tsd.diffuse_reference(filled, stretch, kernel, seam if seams is not None else None)
            got = read_texture(t.levels[0])
            np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-5 * np.abs(want).max())
    finally:
        store(renderer).nodes.pop(-32).release()


def test_the_path_is_chosen_per_pass_and_explained(ctx):
    scene = two_media_slab()
    gpu, llvmpipe = Device(None, False), Device(None, True)
    old_gl = Device("the GL context is 3.3 (compute shaders need 4.3)", False)
    st = lambda mode: RenderSettings.for_technique("ssss", 32, 32, shadow_size=256, compute=mode)  # noqa: E731
    for device, mode, compute, why in (
        (gpu, "auto", True, "auto: GPU"),
        (llvmpipe, "auto", False, "auto: faster than its compute shader on software GL"),
        (llvmpipe, "on", True, "compute on"),
        (gpu, "off", False, "compute off"),
        (old_gl, "on", False, "compute on, but the GL context is 3.3 (compute shaders need 4.3)"),
        (None, "on", False, "compute on, but the planner was given no GL context"),
    ):
        plan = plan_frame(scene, st(mode), device=device)
        blur = next(p for p in plan.passes if p.kind == "ssss_blur")
        assert blur.params.compute is compute
        assert blur.reason.endswith(f"; {'compute' if compute else 'fragment'} shader ({why})"), blur.reason
    # a pass declared faster as compute on software GL takes it there under auto
    assert choose_path(st("auto"), llvmpipe, software="compute").compute
    assert not choose_path(st("auto"), old_gl, software="compute").compute


def test_a_context_without_compute_renders_the_fragment_path(renderer):
    """compute = on with a context that has no compute shaders (the viewer's 3.3 window): the fragment
    path, the same image, and the plan says why."""
    scene = two_media_slab()
    st = RenderSettings.for_technique("ssss", 32, 32, shadow_size=256, compute="on")
    want = renderer.render(scene, st).hdr
    real = renderer.device
    renderer.device = Device("the GL context is 3.3 (compute shaders need 4.3)", True)
    try:
        res = renderer.render(scene, st)
    finally:
        renderer.device = real
    assert not any("; compute shader" in p.reason for p in res.plan.passes), res.plan.explain()
    assert "but the GL context is 3.3" in next(p.reason for p in res.plan.passes if p.kind == "ssss_blur")
    assert_fp32_equal(res.hdr, want, "hdr")


def test_compute_setting_is_declared_checked_and_offered(tmp_path):
    from skinlab.declare import Field
    from skinlab.viewer.panel import render_widgets, technique_value

    opt = RenderSettings.options()["compute"]
    assert isinstance(opt, Field) and opt.kind == "choice" and opt.choices == ("auto", "on", "off")
    assert RenderSettings().compute == "auto"
    with pytest.raises(ValueError, match=r"render setting compute: expected one of auto, on, off, got 'fast'"):
        RenderSettings(compute="fast")
    w = next(w for w in render_widgets(RenderSettings()) if w.param == "compute")
    assert w.widget == "combo" and w.choices == ("auto", "on", "off") and w.value == "auto"
    assert technique_value(RenderSettings(), "compute", "off") == "off"


def test_compute_option_on_the_command_line():
    import argparse

    from skinlab.commands.technique_options import add_render_options, render_options_from_args

    p = argparse.ArgumentParser()
    add_render_options(p)
    assert render_options_from_args(p.parse_args(["--compute", "off"]))["compute"] == "off"
    assert "compute" not in render_options_from_args(p.parse_args([]))
    with pytest.raises(SystemExit):
        p.parse_args(["--compute", "sometimes"])
