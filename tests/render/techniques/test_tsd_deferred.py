"""The frame-cost cuts of texture-space diffusion give the same images: the irradiance shaded once per
texel from a G-buffer of the rasterised surface (TsdIrradianceParams.deferred) against shading while
rasterising, and the dilation rings restricted to the texels no triangle covered (the coverage mask)
against rings over every texel."""

from __future__ import annotations

import numpy as np
import pytest

from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import passes as tsd_passes
from skinlab.render.techniques.tsd import plan as tsd_plan
from skinlab.render.techniques.tsd.passes import read_texture, store


@pytest.fixture(scope="module")
def head():
    from skinlab.scene.scenefile import load_scene

    return load_scene("head")


def _textures(ctx, scene, size=256, **kw):
    r = Renderer(ctx)
    try:
        res = r.render(scene, RenderSettings.for_technique("tsd", 24, 24, shadow_size=256, size=size, **kw))
        t = next(iter(store(r).nodes.values()))
        return res, [read_texture(x) for x in (t.raw, *t.through_raw, t.stretch, t.irradiance, *t.levels)]
    finally:
        r.release()


def test_deferred_irradiance_is_the_rasterised_one(ctx, head, monkeypatch):
    """The head (normal, colour maps; seams; translucency records; interreflection light per vertex):
    every texture-space texture and the frame to fp32 rounding of the texel's UV (the maps' bilinear
    weights), and the shading it replaces is what the plan says."""
    out = {}
    for deferred in (False, True):
        monkeypatch.setattr(tsd_plan, "deferred_irradiance", lambda device, d=deferred: d)
        out[deferred] = _textures(ctx, head)
    (res_r, raster), (res_d, deferred) = out[False], out[True]
    irr = next(p for p in res_d.plan.passes if p.kind == "tsd_irradiance")
    assert irr.params.deferred and irr.params.translucency and "shaded once" in irr.reason
    assert any(p.kind == "bounce" for p in res_d.plan.passes)
    for k, (a, b) in enumerate(zip(raster, deferred)):
        scale = max(float(np.abs(a).max()), 1e-6)
        assert np.abs(a - b).max() <= 2e-5 * scale, (k, float(np.abs(a - b).max()), scale)
    cov = raster[0][..., 3] > 0
    np.testing.assert_array_equal(deferred[0][..., 3] > 0, cov)  # the same texels covered
    assert 0.5 < cov.mean() < 1.0
    np.testing.assert_allclose(res_d.hdr, res_r.hdr, rtol=1e-5, atol=1e-6)


def test_deferred_on_software_gl_only(ctx):
    from skinlab.render.compute import Device

    assert tsd_plan.deferred_irradiance(Device(None, True))
    assert not tsd_plan.deferred_irradiance(Device(None, False)) and not tsd_plan.deferred_irradiance(None)


def test_masked_dilation_is_the_full_one(ctx, head, monkeypatch):
    """Stretch and irradiance dilated through the coverage mask against every texel shaded, bit for bit."""
    full = _textures(ctx, head)[1]
    monkeypatch.setattr(tsd_passes.TsdNodeTargets, "mask_ready", lambda self, what: None)
    plain = _textures(ctx, head)[1]
    for k, (a, b) in enumerate(zip(full, plain)):
        np.testing.assert_array_equal(a, b, err_msg=f"texture {k}")


def test_the_isotropic_maps_leave_the_forward_pass_anisotropic(ctx, head):
    """The irradiance pass samples the maps without anisotropy through a sampler object; after it the
    forward pass filters them as before: a plain frame after a texture-space one is the plain frame
    of a fresh renderer."""
    plain = RenderSettings.for_technique("none", 48, 48, shadow_size=256, bounces=0)
    r = Renderer(ctx)
    try:
        want = r.render(head, plain).hdr
    finally:
        r.release()
    r = Renderer(ctx)
    try:
        r.render(head, RenderSettings.for_technique("tsd", 24, 24, shadow_size=256, size=256, bounces=0))
        assert not r.resources._sampled_units
        got = r.render(head, plain).hdr
    finally:
        r.release()
    np.testing.assert_array_equal(got, want)


def test_deferred_irradiance_carries_the_sky_occlusion(ctx, monkeypatch):
    """Under an environment map the G-buffer carries each vertex's sky occlusion (lib/sky_vertex.glsl's
    coefficients, techniques/tsd/surface.glsl): the deferred irradiance equals the rasterised one, and
    the occlusion is really read (turning it off changes the texture)."""
    from skinlab.scene.envmap import resolve_map
    from skinlab.scene.scenefile import load_scene

    scene = load_scene("head")
    scene.environment.map = resolve_map("studio", None)
    out = {}
    for deferred in (False, True):
        monkeypatch.setattr(tsd_plan, "deferred_irradiance", lambda device, d=deferred: d)
        out[deferred] = _textures(ctx, scene, size=128)
    (_, raster), (res_d, deferred) = out[False], out[True]
    assert "sky_occlusion" in res_d.plan.names()
    assert next(p for p in res_d.plan.passes if p.kind == "tsd_irradiance").params.deferred
    a, b = raster[0], deferred[0]  # the raw irradiance
    assert np.abs(a - b).max() <= 2e-5 * max(float(np.abs(a).max()), 1e-6), float(np.abs(a - b).max())
    _, open_sky = _textures(ctx, scene, size=128, sky_occlusion=False)
    assert np.abs(open_sky[0] - b).max() > 1e-3 * float(np.abs(b).max())
