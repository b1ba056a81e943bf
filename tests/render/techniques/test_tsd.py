"""Texture-space diffusion on the GPU against its NumPy references (skinlab/scene/optics/tsd.py)."""

import math

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import TsdSettings
from skinlab.render.techniques.tsd.passes import frame_nodes, read_texture, store
from skinlab.scene import transform as tf
from skinlab.scene.mesh import Mesh
from skinlab.scene.optics import tsd
from skinlab.scene.optics.boundary import boundary_tables, ms_rest_lookup, ms_rest_table, table_lookup
from skinlab.scene.optics.edges import edge_response
from skinlab.scene.optics.exact_profile import exact_profile_convolution
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.single_scattering import single_scatter_brdf
from skinlab.scene.optics.slab import slab_table, slab_through
from tests.tsd_scenes import entered, exact_profile, pixel_x, quad_mesh, skin, slab_scene


def tsd_node(renderer, scene, name="slab"):
    return frame_nodes(renderer.last_frame)[scene.find(name).uid]


def test_dilation_pass_matches_its_twin(renderer):
    """techniques/tsd/dilate.frag against dilate_reference on a texture with islands, holes and edges."""
    from types import SimpleNamespace

    from skinlab.render.techniques.tsd.passes import dilate

    rng = np.random.default_rng(5)
    n = 32
    img = np.zeros((n, n, 4), np.float32)
    mask = rng.random((n, n)) < 0.15
    mask[10:20, 4:12] = True
    img[mask, :3] = rng.uniform(0.1, 2.0, (mask.sum(), 3))
    img[mask, 3] = 1.0
    t = store(renderer).targets(SimpleNamespace(uid=-1), n)
    t.stretch.write(img.tobytes())
    dilate(renderer, t, t.stretch, t.stretch, 4)  # in place
    gpu = read_texture(t.stretch)
    ref = tsd.dilate_reference(img, 4)
    np.testing.assert_allclose(gpu, ref, rtol=1e-5, atol=1e-6)
    assert (ref[..., 3] > 0).sum() > mask.sum()  # it did grow
    np.testing.assert_array_equal(gpu[mask], img[mask])  # covered texels are untouched
    t.raw.write(img.tobytes())  # from one texture into another (the irradiance), an odd count
    dilate(renderer, t, t.raw, t.irradiance, 3)
    np.testing.assert_allclose(read_texture(t.irradiance), tsd.dilate_reference(img, 3), rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(read_texture(t.raw), img)  # the source is kept
    store(renderer).nodes.pop(-1).release()


def test_gpu_diffusion_matches_numpy_twin_and_reports_fit_error(renderer):
    """Irradiance and stretch read back from the GPU, convolved in NumPy with the same Gaussian chain,
    must give the GPU's blurred levels to fp32 rounding. A trapezoid slab makes the stretch vary."""
    mesh = Mesh(
        "slab",
        np.array([[-1, -1, 0], [1, -1, 0], [1.6, 1, 0], [-1.6, 1, 0]], np.float32),
        np.array([[0, 1, 2], [0, 2, 3]], np.uint32),
        normals=np.tile([0, 0, 1.0], (4, 1)),
        uvs=np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32),
    )
    scene = slab_scene(occluder=True, mesh=mesh)
    renderer.render(scene, RenderSettings(64, 64, shadow_size=1024, technique=TsdSettings(size=128)), readback=False)
    t = tsd_node(renderer, scene)
    irr, stretch = read_texture(t.targets.irradiance), read_texture(t.targets.stretch)
    assert np.ptp(stretch[..., 0]) > 0.05 * stretch[..., 0].mean()  # the stretch does vary
    assert t.kernel.levels >= 3
    levels, diffused = tsd.diffuse_reference(irr, stretch, t.kernel)
    for k, ref in enumerate(levels):
        gpu = read_texture(t.targets.levels[k])
        np.testing.assert_allclose(gpu, ref, rtol=1e-4, atol=1e-5 * np.abs(ref).max(), err_msg=f"level {k}")
    # the fit's error: the same irradiance convolved with the exact profile (rectangle slab, uniform
    # stretch, so the brute-force reference applies)
    scene = slab_scene(occluder=True)
    renderer.render(scene, RenderSettings(64, 64, shadow_size=1024, technique=TsdSettings(size=128)), readback=False)
    t = tsd_node(renderer, scene)
    irr, stretch = read_texture(t.targets.irradiance), read_texture(t.targets.stretch)
    # the stretch pass: a 40 mm square on 128 texels is 0.3125 mm per texel along u and v
    cov = stretch[..., 3] > 0
    np.testing.assert_allclose(stretch[cov, :2], 2 * 20.0 / 128, rtol=1e-5)
    _, diffused = tsd.diffuse_reference(irr, stretch, t.kernel)
    exact = exact_profile_convolution(
        irr, (stretch[64, 64, 0], stretch[64, 64, 1]), exact_profile("burley", material_medium(t.material.values))
    )
    rel_l1 = np.abs(diffused - exact).sum(axis=(0, 1)) / np.abs(exact).sum(axis=(0, 1))
    print(f"K=6 Gaussian fit vs exact Burley convolution, relative L1 per channel: {rel_l1.round(4)}")
    assert np.all(np.isfinite(rel_l1)) and np.all(rel_l1 < 0.03), rel_l1


def _edge_row(renderer, model: str, place: float, angular_radius: float = 0.0):
    """The shadow-edge slab (192 texels over 40 mm, the edge `place` of a texel into one): the row
    across the edge / its lit level, the exact profile's edge response summed against it (texels of
    light too much per channel) and its per-pixel error against that response averaged over a texel."""
    n = 192
    scene = slab_scene(occluder=True, material=skin(model))
    h = 1.02  # slab_scene's occluder height and edge (units): the light along (1 + e, 0, -1) moves it h e
    tilt = place * (2.0 / n) / h
    d = np.array([1.0 + tilt, 0.0, -1.0])
    scene.lights()[0].rotation = tf.look_at_rotation(np.zeros(3), d / np.linalg.norm(d))
    scene.lights()[0].angular_radius = angular_radius
    res = renderer.render(scene, RenderSettings(n, n, shadow_size=4096, technique=TsdSettings(size=n)))
    t = tsd_node(renderer, scene)
    row = res.hdr[n // 2, :, :3].astype(np.float64)
    lit = row[-8:].mean(axis=0)
    texel_mm = 2 * scene.mm_per_unit / n
    x_mm = (pixel_x(n, 1.0) - h * tilt) * scene.mm_per_unit
    profile = exact_profile(model, material_medium(t.material.values))

    def response(x):  # x from where the light entered, spread as the frame spreads it (entered)
        return entered(lambda e: edge_response(-e, profile, "profile"), x, scene, texel_mm, averaged=True)

    edge = response(x_mm)
    moved = (row / lit - edge).sum(axis=0)  # pixels (= texels) of light too much
    within = (np.arange(16) + 0.5) / 16 - 0.5  # across a texel (midpoint rule)
    held = np.mean([response(x_mm + w * texel_mm) for w in within], axis=0)
    return row / lit, moved, np.abs(row / lit - held)


@pytest.mark.parametrize("model", ["burley", "dipole", "pbd"])
@pytest.mark.parametrize("place", [0.0, 0.25, 0.5])
def test_shadow_edge_follows_the_profile_edge_response(renderer, model, place, multiple_only):
    """A slab lit across a sharp shadow edge, the edge on an irradiance texels' border or `place` of a
    texel into one (the light tilted): the light that leaves is the light that entered, the edge where
    the light entered: the multiply scattered radiance / its lit level summed over the row is the
    exact profile's edge response's within a tenth of a texel, wherever the edge falls (one point's
    shadow per texel moved the edge to the texels' grid: a quarter of a texel of light too much or
    too little at 0 and 0.5); at every pixel within 4.5 % (absolute, of the lit level) of that edge
    response averaged over a texel, what each texel holds (lib/shadow.glsl shadow_pcf_area; the most
    in blue, whose profile is hardly wider than the texel, 0.21 mm: the blur's discrete taps)."""
    row, moved, err = _edge_row(renderer, model, place)
    assert np.all(np.abs(moved) < 0.1), (model, place, moved)
    assert np.all(np.isfinite(err))
    assert err.max() < 0.045, (model, err.max(axis=0), int(err.argmax()) // 3)
    # and the edge is really there: the shadowed side is dark, the red channel bleeds furthest
    n = len(row)
    assert row[: n // 8].max() < 0.02
    mid = row[n // 2 - 6]
    assert mid[0] > mid[2]


@pytest.mark.parametrize("place", [0.0, 0.5])
def test_a_soft_light_s_narrow_penumbra_keeps_the_edge_where_it_falls(renderer, place, multiple_only):
    """The same edge under a light with a size whose penumbra is a fifth of a texel (angular radius
    1 mrad; lib/shadow_soft.glsl's filter at a point, a few shadow-map texels, aliased the edge to the
    texel grid like the hard shadow's one point did): shadow_soft_area widens the filter by the texel's
    footprint, so the light summed across the edge is the exact response's within a tenth of a texel
    on the grid's border and half a texel into one."""
    row, moved, err = _edge_row(renderer, "burley", place, angular_radius=1e-3)
    assert np.all(np.abs(moved) < 0.1), (place, moved)
    assert np.all(np.isfinite(err)) and err.max() < 0.06, err.max(axis=0)


def test_constant_irradiance_keeps_its_mean(renderer):
    """Energy: with uniform light, every blurred level equals the irradiance (the kernel sums to 1;
    the colour is the albedo's), and the image is the same as with a tiny radius."""
    scene = slab_scene(material=skin("burley", color=(0.8, 0.6, 0.5)))  # the subsurface albedo
    res = renderer.render(scene, RenderSettings(64, 64, technique=TsdSettings(size=128)))
    t = tsd_node(renderer, scene)
    irr = tsd.unpremultiply(read_texture(t.targets.irradiance))
    for k in range(t.kernel.levels):
        lv = tsd.unpremultiply(read_texture(t.targets.levels[k]))
        np.testing.assert_allclose(lv, irr, rtol=2e-5)
    np.testing.assert_allclose(np.asarray(t.kernel.identity) + t.kernel.weights().sum(axis=0), 1.0, rtol=1e-12)
    img = res.hdr[..., :3]
    np.testing.assert_allclose(img, np.broadcast_to(img[32, 32], img.shape), rtol=1e-4)
    # the level: albedo x entering irradiance / pi x the exit distribution (normal view, NoV = 1),
    # the irradiance being light x entry factor x albedo^mix; plus single scattering and the
    # multiple scattering's non-separable rest where the light lands, albedo x light x Jensen's term
    # and x the rest at (1, 1) (skinlab/scene/optics/boundary.py)
    base = np.array([0.8, 0.6, 0.5])
    medium = material_medium(t.material.values)
    tab = boundary_tables(medium.alpha_arr, t.material["subsurface_color"], medium.eta)
    light = irr[64, 64] / (table_lookup(tab.entry, 1.0) * np.sqrt(base))
    z = np.array([0.0, 0.0, 1.0])
    single = light * base * single_scatter_brdf(z, z, z, tab.single, medium.eta, 0.0)
    rest = (
        light
        * base
        * ms_rest_lookup(ms_rest_table(medium.alpha_arr, t.material["subsurface_color"], medium.eta), 1.0, 1.0)
    )
    assert np.all(rest > 0.01 * single)  # index-matched: the rest is there
    expected = base * irr[64, 64] / np.sqrt(base) / np.pi * table_lookup(tab.exit, 1.0) + single + rest
    np.testing.assert_allclose(img[32, 32], expected, rtol=1e-3)


def test_scale_invariance(renderer):
    """Only millimetres matter. Doubling the scene's mm per unit makes the object twice as large in
    millimetres; doubling the radius with it (the issue's "halving" would quarter radius / size)
    leaves the image unchanged, as does describing the same scene with half the coordinates and
    twice the mm per unit."""
    st = RenderSettings(96, 96, shadow_size=2048, technique=TsdSettings(size=128))
    a = renderer.render(slab_scene(occluder=True, mm_per_unit=20.0, material=skin(radius=(8.0, 4.0, 2.0))), st).hdr
    b = renderer.render(slab_scene(occluder=True, mm_per_unit=40.0, material=skin(radius=(16.0, 8.0, 4.0))), st).hdr
    np.testing.assert_allclose(a, b, atol=2e-4 * a.max())
    # the same physical scene described in other units: half the coordinates, twice the mm per unit
    d = renderer.render(
        slab_scene(half=0.5, occluder=True, mm_per_unit=40.0, material=skin(radius=(8.0, 4.0, 2.0))), st
    ).hdr
    np.testing.assert_allclose(a, d, atol=2e-4 * a.max())
    # and the physics does depend on the ratio: the same radius at twice the size is a sharper edge
    # (single scattering, the same at every scale, is a part of both)
    c = renderer.render(slab_scene(occluder=True, mm_per_unit=40.0, material=skin(radius=(8.0, 4.0, 2.0))), st).hdr
    assert np.abs(c - a).max() > 0.01 * a.max()


def test_uv_seam_does_not_darken(renderer):
    """The slab cut at x = 0 into two UV charts far apart: under uniform light the seam must look
    like the rest (dilation + coverage-normalised blurs); a kernel pulling in empty texels would
    darken both sides of the cut by up to half."""
    pos = np.array(
        [[-1, -1, 0], [0, -1, 0], [0, 1, 0], [-1, 1, 0], [0, -1, 0], [1, -1, 0], [1, 1, 0], [0, 1, 0]], np.float32
    )
    uv = np.array(
        [[0.05, 0.05], [0.4, 0.05], [0.4, 0.95], [0.05, 0.95], [0.6, 0.05], [0.95, 0.05], [0.95, 0.95], [0.6, 0.95]],
        np.float32,
    )
    mesh = Mesh(
        "seamed",
        pos,
        np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]], np.uint32),
        normals=np.tile([0, 0, 1.0], (8, 1)),
        uvs=uv,
    )
    scene = slab_scene(mesh=mesh, material=skin(radius=(20.0, 10.0, 5.0)))
    res = renderer.render(scene, RenderSettings(96, 96, technique=TsdSettings(size=128)))
    img = res.hdr[..., :3]
    core = img[20:76, 20:76]
    ref = img[48, 24]
    np.testing.assert_allclose(core, np.broadcast_to(ref, core.shape), rtol=0.01)
    assert tsd_node(renderer, scene, "slab").kernel.steps[-1].sigma_mm > 1.0  # wide enough to reach the seam


def test_translucency_through_thin_parts(renderer):
    """Light from behind a thin sheet comes through (the exact diffuse transmittance of a slab of its
    thickness, skinlab/scene/optics/slab.py); a thick block lets almost nothing through; no shadow-casting
    light, no translucency."""

    def sheet(thickness_units, shadow=True):
        s = slab_scene(material=skin(radius=(8.0, 4.0, 2.0)), light_dir=(0, 0, 1))
        s.lights()[0].cast_shadow = shadow
        from skinlab.scene.graph import MeshNode
        from skinlab.scene.materials import Material

        back = quad_mesh("back", -1, 1, 1, -1, z=-thickness_units)  # facing -z, toward the light
        s.add(MeshNode("back", back, Material("back", {"specular": 0.0})))
        return s

    st = RenderSettings(48, 48, shadow_size=1024, technique=TsdSettings(size=64))
    thin = renderer.render(sheet(0.5 / 20.0), st)  # 0.5 mm
    thick = renderer.render(sheet(20.0 / 20.0), st)  # 20 mm
    none = renderer.render(sheet(0.5 / 20.0, shadow=False), st)
    c = thin.hdr[24, 24, :3]
    # red goes furthest (the frame shows the light through times the subsurface colour 0.8, 0.6, 0.5)
    assert c[0] > 0.04 and c[0] > c[2]
    # the irradiance texel is the light through 0.5 mm at normal incidence (e = 1) x the subsurface
    # albedo^mix: the exact diffuse transmittance of a 0.5 mm slab (skinlab/scene/optics/slab.py) per
    # unit subsurface albedo (the colour rule, docs/scenes.md)
    st_thin = sheet(0.5 / 20.0)
    renderer.render(st_thin, st, readback=False)
    t = frame_nodes(renderer.last_frame)[st_thin.find("slab").uid]
    irr = tsd.unpremultiply(read_texture(t.targets.irradiance))[32, 32]
    medium = material_medium(t.material.values)
    table = slab_table(medium.alpha_arr, t.material["subsurface_color"])
    through = slab_through(1.0, 0.5, table, medium.mfp_arr, medium.alpha_arr, medium.eta)
    mix = st.technique.albedo_mix
    np.testing.assert_allclose(irr, through * np.asarray(t.material["subsurface_color"]) ** mix, rtol=2e-3)
    assert thick.hdr[24, 24, 0] < 0.05 * c[0]
    assert none.hdr[24, 24, :3].max() == 0.0
    assert "translucency" in dict(none.plan.skipped)


@pytest.mark.parametrize("technique", ["tsd", "ssss"])
def test_uniform_sky_reflects_chandrasekhars_albedo(renderer, technique):
    """An index-matched slab under a uniform sky of radiance 1 (no light), seen from above, returns
    by reciprocity the directional albedo of all orders, 1 - H(1) sqrt(1 - a) (Chandrasekhar): the
    multiple scattering through the entry/exit tables plus the sky's single scattering
    (sss_single_ambient; without it the frame read 67 % dark in blue, a = 0.49)."""
    from skinlab.scene.optics.boundary import albedo_isotropic

    colour = (0.46, 0.23, 0.126)
    scene = slab_scene(material=skin(radius=(8.0, 4.0, 2.0), color=colour, base=colour), ambient=1.0)
    scene.lights()[0].intensity = 0.0
    opts = {"size": 128} if technique == "tsd" else {}
    img = renderer.render(scene, RenderSettings.for_technique(technique, 48, 48, shadow_size=256, **opts)).hdr
    medium = material_medium(scene.find("slab").material.values)
    want = np.array([float(albedo_isotropic(a, 1.0)) for a in medium.alpha_arr])
    got = img[22:26, 22:26, :3].reshape(-1, 3).mean(0)
    np.testing.assert_allclose(got, want, rtol=0.01)


@pytest.mark.parametrize("technique", ["tsd", "ssss"])
@pytest.mark.parametrize("cos_light", [1.0, 0.3])
def test_a_lit_slab_reflects_chandrasekhars_brdf(renderer, technique, cos_light):
    """An index-matched slab lit by a directional light at cosine mu0 (no sky), seen from above,
    returns Chandrasekhar's exact half-space BRDF at (1, mu0) times E mu0: the separable multiple
    scattering plus its non-separable rest (lib/sss_boundary.glsl sss_ms_rest) plus Jensen's single
    scattering. The separable form alone is 1.9-3.0 % dark for normal light and brighter at mu0 = 0.3
    (skin1's albedos; the test checks it is off by more than 1.5 %), the frame within 1 %."""
    from skinlab.scene.optics.boundary import exact_ms_brdf_matched, separable_ms_brdf

    colour = (0.46, 0.23, 0.126)
    s = math.sqrt(1.0 - cos_light**2)
    scene = slab_scene(material=skin(radius=(8.0, 4.0, 2.0), color=colour, base=colour), light_dir=(s, 0.0, -cos_light))
    opts = {"size": 128} if technique == "tsd" else {}
    img = renderer.render(scene, RenderSettings.for_technique(technique, 48, 48, shadow_size=256, **opts)).hdr
    medium = material_medium(scene.find("slab").material.values)
    ss = lambda a: a / (4 * np.pi * (1.0 + cos_light))
    want = np.array([cos_light * (float(exact_ms_brdf_matched(a, 1.0, cos_light)) + ss(a)) for a in medium.alpha_arr])
    sep = np.array([cos_light * (float(separable_ms_brdf(a, 1.0, 1.0, cos_light)) + ss(a)) for a in medium.alpha_arr])
    assert np.all(np.abs(sep / want - 1) > 0.015)  # what the rest takes back
    got = img[22:26, 22:26, :3].reshape(-1, 3).mean(0)
    np.testing.assert_allclose(got, want, rtol=0.01)


def test_entry_spread_off_takes_the_shadow_at_the_mean_entry_point(renderer, multiple_only):
    """RenderSettings.entry_spread: on, the shadow where the light entered is spread over three lookups
    per channel (skinlab/scene/optics/oblique.py); off, one lookup at the mean entry point. The two frames
    are the same far from the shadow's edge and differ across it; off, the light summed across the edge
    is the hard shift's (each channel's edge response shifted by the luminance offset) within a tenth
    of a texel, as before the spread."""
    from skinlab.scene.optics.oblique import entry_offset

    n = 192
    scene = slab_scene(occluder=True, material=skin("burley"))
    rows = {}
    for spread in (True, False):
        res = renderer.render(
            scene, RenderSettings(n, n, shadow_size=4096, entry_spread=spread, technique=TsdSettings(size=n))
        )
        row = res.hdr[n // 2, :, :3].astype(np.float64)
        rows[spread] = row / row[-8:].mean(axis=0)
    far = np.r_[0:16, n - 16 : n]
    np.testing.assert_allclose(rows[True][far], rows[False][far], atol=2e-3)
    assert np.abs(rows[True] - rows[False]).max() > 0.01
    t = tsd_node(renderer, scene)
    medium = material_medium(t.material.values)
    off = entry_offset(np.array([[0.0, 0.0, 1.0]]), -scene.lights()[0].direction[None], medium.mfp_arr, medium.eta, 1.0)
    x_mm = pixel_x(n, 1.0) * scene.mm_per_unit + off[0][0]  # from the mean entry point
    edge = edge_response(-x_mm, exact_profile("burley", medium), "profile")
    moved = (rows[False] - edge).sum(axis=0)
    assert np.all(np.abs(moved) < 0.1), moved
