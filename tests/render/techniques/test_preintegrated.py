"""Technique "preintegrated" (Penner & Borshukov 2011): the lookup table against its defining ring
integral, its hard cases, the GLSL lookup against its twin, per-vertex curvature, and renders: a
flat slab shades as without scattering's blur, a sphere follows the table pixel by pixel."""

import math

import moderngl
import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.render.boundary import material_boundary
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import TsdSettings
from skinlab.scene.graph import CameraNode, MeshNode, Scene
from skinlab.scene.mesh import Mesh
from skinlab.scene.optics import preintegrated as pis
from skinlab.scene.optics.boundary import table_lookup
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.profile_fit import profile_fit
from tests.tsd_scenes import light_from, skin, slab_scene


def medium(radius=(8.0, 4.0, 2.0), color=(0.8, 0.6, 0.5)):
    return material_medium({"subsurface_color": color, "subsurface_radius": radius, "specular": 0.0})


def uv_sphere(radius=1.0, rings=96, segments=192):
    th = np.linspace(0, math.pi, rings + 1)
    ph = np.linspace(0, 2 * math.pi, segments + 1)
    t, p = np.meshgrid(th, ph, indexing="ij")
    n = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    idx = []
    w = segments + 1
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = i * w + j, i * w + j + 1, (i + 1) * w + j + 1, (i + 1) * w + j
            idx += [[a, b, c], [a, c, d]]
    return n * radius, n, np.array(idx, np.uint32)


@pytest.mark.parametrize("model", ["burley", "gaussians", "dipole"])
def test_lut_rows_conserve_energy_and_wrap_past_the_terminator(model):
    lut = pis.preintegrated_lut(model, medium())
    t = lut.table
    assert t.shape == (pis.LUT_CURV, pis.LUT_NOL, 3) and np.all(np.isfinite(t)) and lut.curv_max > 0
    nol = np.linspace(-1, 1, pis.LUT_NOL)
    np.testing.assert_allclose(t[0], np.maximum(nol, 0)[:, None] * np.ones(3), atol=1e-12)  # flat: N.L
    assert np.all(np.diff(t, axis=1) >= -1e-9)  # brighter toward the light
    mid = pis.LUT_NOL // 2  # N.L = 0 (nearly: the grid's middle is 1/63 past it)
    wrap = t[:, mid - 1]  # just past the terminator: grows with curvature, red (widest) the most
    assert np.all(np.diff(wrap, axis=0) >= -1e-9) and wrap[-1, 0] > 0.05 and wrap[-1, 0] > wrap[-1, 2]
    # the ring convolution keeps the ring's light: int_0^pi D(cos theta) dtheta = int_0^pi max(cos, 0) = 1
    th = np.linspace(0, math.pi, 2001)
    fit = profile_fit(model, medium(), 6)
    for r_mm in (1.0 / lut.curv_max, 5.0, 50.0):
        d = pis.ring_diffusion(np.cos(th), r_mm, fit.variances_mm2, fit.weights, fit.identity)
        np.testing.assert_allclose(np.trapezoid(d, th, axis=0), 1.0, rtol=2e-3)


def test_lut_hard_cases():
    nol = np.linspace(-1, 1, pis.LUT_NOL)
    for m in (medium(color=(0, 0, 0)), medium(radius=(0, 0, 0))):  # nothing scatters: N.L everywhere
        lut = pis.preintegrated_lut("burley", m)
        assert lut.curv_max == 0
        np.testing.assert_allclose(lut.table, np.maximum(nol, 0)[None, :, None] * np.ones((pis.LUT_CURV, 1, 3)))
    lut = pis.preintegrated_lut("burley", medium(radius=(6, 0, 0), color=(1, 1, 1)))  # albedo 1, one channel
    assert np.all(np.isfinite(lut.table)) and lut.table[-1, pis.LUT_NOL // 2 - 1, 0] > 0
    np.testing.assert_allclose(lut.table[..., 1:], np.maximum(nol, 0)[None, :, None] * np.ones((pis.LUT_CURV, 1, 2)))
    # a ring of radius -> 0 or inf stays finite
    fit = profile_fit("burley", medium(), 6)
    for r in (1e-6, 1e6, math.inf):
        assert np.all(np.isfinite(pis.ring_diffusion(nol, r, fit.variances_mm2, fit.weights, fit.identity)))


def test_vertex_curvature():
    p, n, idx = uv_sphere(2.0, 24, 48)
    k = pis.vertex_curvature(p, n, idx)
    np.testing.assert_allclose(k[np.abs(p[:, 2]) < 1.5], 0.5, rtol=0.02)  # 1/R away from the poles
    flat = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
    up = np.tile([0, 0, 1.0], (4, 1))
    np.testing.assert_array_equal(pis.vertex_curvature(flat, up, np.array([0, 1, 2, 0, 2, 3])), 0.0)
    dup = np.array([[0, 0, 0], [0, 0, 0], [1, 0, 0]], np.float32)  # a degenerate edge, an unused vertex
    k = pis.vertex_curvature(np.vstack([dup, [[5, 5, 5]]]), np.tile([0, 0, 1.0], (4, 1)), np.array([0, 1, 2]))
    assert np.all(np.isfinite(k)) and k[3] == 0


def test_glsl_lookup_matches_its_twin(glsl, ctx):
    lut = pis.preintegrated_lut("burley", medium())
    tex = ctx.texture((pis.LUT_NOL, pis.LUT_CURV), 3, lut.table.astype(np.float32).tobytes(), dtype="f4")
    tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    tex.repeat_x = tex.repeat_y = False
    nol = np.array([-1.5, -1.0, -0.3, -0.01, 0.0, 0.013, 0.5, 0.99, 1.0, 2.0, 0.2, -0.2])
    curv = np.array([0.0, 0.1, 0.2, 0.3, 0.0, 1e-6, lut.curv_max, 2 * lut.curv_max, 0.05, 0.7, 0.4, 0.25])
    t = curv / lut.curv_max
    gpu = glsl.evaluate(
        "lib/preintegrated.glsl",
        "pis_lookup(u_lut, vec2(64.0, 64.0), nol, t)",
        {"nol": nol, "t": t},
        3,
        samplers={"u_lut": ("sampler2D", tex)},
    )
    ref = pis.lut_lookup(lut, nol, curv)
    # the GPU's linear filter weights have 8 fractional bits: compare at that precision
    np.testing.assert_allclose(gpu, ref, atol=4e-3)
    assert_close_fp32(gpu[[1, 4, 8]], ref[[1, 4, 8]], what="pis_lookup at texel centres")
    tex.release()


def test_flat_slab_shades_like_the_unblurred_subsurface_term(renderer):
    """Curvature 0: the table is max(N.L, 0), so a uniformly lit flat slab is texture-space
    diffusion's flat result (nothing to move)."""
    scene = slab_scene(material=skin("burley"))
    tsd_img = renderer.render(scene, RenderSettings(48, 48, technique=TsdSettings(size=64))).hdr[24, 24, :3].copy()
    res = renderer.render(scene, RenderSettings(48, 48, technique="preintegrated"))
    assert [p.kind for p in res.plan.passes] == ["forward", "tonemap"]  # no pass of its own
    np.testing.assert_allclose(res.hdr[24, 24, :3], tsd_img, rtol=2e-3)


def test_curvature_is_computed_only_in_its_frames(renderer, monkeypatch):
    """The curvature stream is the technique's (Technique.vertex_streams): a frame of another technique
    computes and binds none; the first pre-integrated frame computes it once per mesh, later ones
    reuse it, and a frame of another technique after it binds it no more."""
    from skinlab.render.techniques import preintegrated as technique

    calls = []

    def counted(*args):
        calls.append(1)
        return pis.vertex_curvature(*args)

    monkeypatch.setattr(technique, "vertex_curvature", counted)
    scene = slab_scene(material=skin("burley"))
    mesh = scene.mesh_nodes()[0].mesh
    tsd_settings = RenderSettings(16, 16, technique=TsdSettings(size=32))
    renderer.render(scene, tsd_settings)
    gm = renderer.resources.meshes[mesh.uid]
    assert calls == [] and gm.streams == {} and gm.active == ()
    for _ in range(2):
        res = renderer.render(scene, RenderSettings(16, 16, technique="preintegrated"))
        assert res.plan.vertex_streams == (technique.CURVATURE,)
        assert calls == [1] and gm.active == (technique.CURVATURE,) and technique.CURVATURE in gm.streams
    renderer.render(scene, tsd_settings)
    assert calls == [1] and gm.active == ()


def test_sphere_follows_the_table(renderer, multiple_only):
    """A sphere of radius 10 mm lit from the side, seen along z (nearly orthographic): along the
    middle row each pixel is base x E x [max(N.L, 0) entry(N.L) + (D(N.L, 1/R) - max(N.L, 0)) entry_d]
    x exit(N.V) x subsurface / pi (the hook in NumPy; the shared single-scattering term left out),
    past the terminator too."""
    R, mm = 1.0, 10.0
    p, n, idx = uv_sphere(R)
    mat = skin("burley", radius=(8.0, 4.0, 2.0), color=(0.8, 0.6, 0.5), specular=0.0)
    scene = Scene("sphere", mm)
    scene.environment.ambient = np.zeros(3)
    scene.add(MeshNode("ball", Mesh("ball", p.astype(np.float32), idx, normals=n.astype(np.float32)), mat))
    scene.add(light_from((1.0, 0.0, 0.0)))  # lights the +x side
    dist = 200.0
    cam = CameraNode("cam", yfov=2 * math.atan(1.1 * R / dist), znear=dist / 2, zfar=dist * 2)
    cam.look_at((0, 0, dist), (0, 0, 0))
    scene.add(cam)
    size = 96
    res = renderer.render(scene, RenderSettings(size, size, shadow_size=256, technique="preintegrated"))
    row = res.hdr[size // 2, :, :3].astype(np.float64)
    x = ((np.arange(size) + 0.5) / size * 2 - 1) * 1.1 * R
    inside = np.abs(x) < 0.9 * R  # away from the silhouette
    nol, nov = x / R, np.sqrt(np.maximum(1 - (x / R) ** 2, 0))
    lut = pis.preintegrated_lut("burley", material_medium(mat.values))
    D = pis.lut_lookup(lut, nol, np.full_like(x, 1.0 / (R * mm)))
    b = material_boundary(mat)
    flat = np.maximum(nol, 0.0)[:, None]
    entering = flat * table_lookup(b.entry, flat[:, 0]) + (D - flat) * b.entry_diffuse[None, :]
    base = np.asarray(mat["subsurface_color"])  # the subsurface albedo (the colour rule, docs/scenes.md)
    ref = base * entering * table_lookup(b.exit, nov) / math.pi  # E = 1
    np.testing.assert_allclose(row[inside], ref[inside], rtol=0.05, atol=2e-3)
    past = inside & (nol < -0.05)
    # light past the terminator (without the table: none), red scattering furthest
    assert row[past, 0].max() > 5e-4 and row[past, 0].max() > 3 * row[past, 2].max()


def test_cli_and_viewer_reach_preintegrated(ctx, tmp_path):
    import subprocess
    import sys

    from skinlab.scene.scenefile import ASSETS, DEFAULT_SCENE
    from skinlab.viewer.core import ViewerCore

    help_text = subprocess.run(
        [sys.executable, "-m", "skinlab.cli", "render", "--help"], capture_output=True, text=True, check=True
    ).stdout
    assert "--preintegrated-softening X" in help_text and "a number in [0, 1] (default: 1.0)" in help_text
    head = tmp_path / "head.toml"
    head.write_text(DEFAULT_SCENE.read_text().replace("../lee-perry-smith/", f"{ASSETS / 'lee-perry-smith'}/"))
    c = ViewerCore(ctx, head, RenderSettings(32, 24, shadow_size=256), settle_s=0.05)
    try:
        seen = [c.cycle_technique() for _ in range(8)]
        assert "preintegrated" in seen
        c.set_technique("preintegrated")
        assert c.render() and c.errors() == []
        assert c.set_technique_option("softening", 0.5) == 0.5
    finally:
        c.close()
