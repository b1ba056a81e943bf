"""Texture-space diffusion is planned from the scene; bad input gives warnings or errors, never NaN."""

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import TsdSettings
from skinlab.render.techniques.tsd.passes import store
from skinlab.resources import assets_root
from skinlab.scene.materials import Material
from skinlab.scene.mesh import Mesh
from skinlab.scene.optics import tsd
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.profile_fit import ProfileFit, profile_fit
from skinlab.scene.scenefile import load_scene
from tests.tsd_scenes import quad_mesh, skin, slab_scene

ST = RenderSettings(48, 48, shadow_size=256, technique=TsdSettings(size=64))


def kinds(plan):
    return [p.kind for p in plan.passes]


def test_no_scattering_material_means_no_texture_space_passes(renderer):
    for mat in (
        skin(model="none"),
        skin(subsurface=0.0),
        skin(radius=(0.0, 0.0, 0.0)),
        Material("plain", {"base_color": (0.5, 0.5, 0.5)}),
    ):
        res = renderer.render(slab_scene(material=mat), ST)
        assert not any(k.startswith("tsd") for k in kinds(res.plan)), mat.values
        assert np.isfinite(res.hdr).all() and res.hdr[24, 24, :3].max() > 0
    # and settings override per render: --sss none / --sss dipole
    res = renderer.render(slab_scene(), RenderSettings(48, 48, sss_model="none", technique=TsdSettings(size=64)))
    assert kinds(res.plan) == ["forward", "tonemap"]
    res = renderer.render(
        slab_scene(material=skin(model="none")),
        RenderSettings(48, 48, sss_model="dipole", technique=TsdSettings(size=64)),
    )
    assert "tsd_irradiance" in kinds(res.plan) and "scatters (dipole)" in res.plan.explain()


def test_stretch_map_is_recomputed_only_when_geometry_changes(renderer):
    scene = slab_scene()
    node = scene.find("slab")

    def stretch_ran(res):
        return "tsd_stretch[slab]" in res.plan.ran()

    first = renderer.render(scene, ST)
    assert stretch_ran(first)
    n = store(renderer).stretch_updates
    second = renderer.render(scene, ST)
    assert "tsd_stretch[slab]" in second.plan.reused() and store(renderer).stretch_updates == n
    assert f"reused: inputs unchanged since frame {renderer.frame_number - 1}" in second.plan.explain()
    node.translation = (0.1, 0.0, 0.0)  # a move changes no length on the surface
    node.rotation = (0.0, 0.0, np.sin(0.2), np.cos(0.2))
    assert not stretch_ran(renderer.render(scene, ST))
    node.mesh.positions = node.mesh.positions * np.float32(2.0)  # the geometry changes...
    node.mesh.version += 1
    third = renderer.render(scene, ST)
    assert stretch_ran(third) and store(renderer).stretch_updates == n + 1
    scene.mm_per_unit *= 2  # ...or the scene scale
    assert stretch_ran(renderer.render(scene, ST))
    node.scale = (1.0, 3.0, 1.0)  # ...or the node's scale
    assert stretch_ran(renderer.render(scene, ST))


def test_texture_space_targets_are_released_when_no_longer_used(renderer):
    a, b = slab_scene(), slab_scene()
    renderer.render(a, ST, readback=False)
    assert a.find("slab").uid in store(renderer).nodes
    renderer.render(b, ST, readback=False)  # another scene (a reload, say)
    assert set(store(renderer).nodes) == {b.find("slab").uid}
    renderer.render(b, RenderSettings(48, 48, sss_model="none", technique=TsdSettings(size=64)), readback=False)
    assert store(renderer).nodes == {}


def test_negligible_and_subtexel_gaussians_are_skipped():
    fit = ProfileFit(
        "test",
        np.array([1e-4, 0.5, 2.0, 8.0]),
        np.array([[0.3, 0.3, 0.3], [0.4, 0.4, 0.4], [0.2999, 0.2999, 0.2999], [1e-4, 5e-4, 0.0]]),
        np.zeros(3),
        np.zeros(3),
    )
    k = tsd.design_kernel(fit, 0.1, 0.1)
    assert [s.variance_mm2 for s in k.steps] == [0.5, 2.0]
    skipped = dict(k.skipped)
    assert any("weight" in why for why in skipped.values())  # the 8 mm2 one
    assert any("texel" in why for why in skipped.values())  # the 1e-4 mm2 one
    # like with like: the width in texels is compared with the threshold in texels
    (why,) = [w for w in skipped.values() if "texel" in w]
    assert why.startswith(
        f"sigma 0.01 mm = 0.1 texel (at the median 0.1 mm per texel), under the {tsd.TSD_SUBTEXEL_SIGMA}"
    )
    np.testing.assert_allclose(k.identity + k.weights().sum(axis=0), 1.0)
    np.testing.assert_allclose(k.identity, 0.3 / 0.9999, rtol=1e-6)  # sub-texel mass is kept, unblurred
    # chained variances: each step blurs by the difference
    assert k.steps[1].sigma_mm == pytest.approx(np.sqrt(1.5))


def test_tap_count_follows_kernel_width():
    assert tsd.tap_count(0.1) == tsd.TSD_MIN_TAPS
    assert tsd.tap_count(2.0) == 13  # 2 * ceil(3 * 2) + 1
    assert tsd.tap_count(1e9) == tsd.TSD_MAX_TAPS
    t, w = tsd.blur_taps(13)
    assert len(t) == 13 and abs(w.sum() - 1) < 1e-12 and abs(np.sum(w * t * t) - 1.0) < 0.05


def test_shader_variant_matches_the_levels_used(renderer):
    res = renderer.render(slab_scene(), ST)
    n = next(p for p in res.plan.passes if p.kind == "tsd_irradiance").params.kernel.levels
    keys = [k for k in renderer.programs.entries if "passes/forward.frag" in str(k)]
    assert any(f"('TSD_LEVELS', '{n}')" in str(k) for k in keys), keys


def test_missing_uvs_generate_an_atlas_with_a_warning(renderer):
    mesh = quad_mesh("nouv", -1, 1, -1, 1)
    mesh.uvs = None
    res = renderer.render(slab_scene(mesh=Mesh("nouv", mesh.positions, mesh.indices, mesh.normals)), ST)
    assert any("has no UVs" in w and "xatlas" in w for w in res.plan.warnings)
    assert "tsd_irradiance" in kinds(res.plan) and np.isfinite(res.hdr).all()
    assert res.hdr[24, 24, :3].max() > 0


def test_overlapping_uvs_and_zero_area_triangles_warn_but_render_finite(renderer):
    pos = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0], [0, 0, 0], [0.5, 0.5, 0], [1, 1, 0]], np.float32)
    # triangle 3: collinear world positions (zero area: infinite stretch) over a real UV triangle;
    # triangle 4: the same UVs as triangle 1 (overlap)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.1, 0.1], [0.3, 0.1], [0.2, 0.3]], np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [0, 1, 2]], np.uint32)
    mesh = Mesh("bad", pos, idx, normals=np.tile([0, 0, 1.0], (7, 1)), uvs=uv)
    res = renderer.render(slab_scene(mesh=mesh), ST)
    text = " ".join(res.plan.warnings)
    assert "overlap" in text and "zero world area" in text, res.plan.warnings
    assert np.isfinite(res.hdr).all()
    from skinlab.render.techniques.tsd.passes import read_texture

    for name, tex in renderer.last_frame.targets.items():
        if name.startswith("tsd"):
            assert np.isfinite(read_texture(tex)).all(), name


@pytest.mark.parametrize(
    "values",
    [
        {"subsurface_radius": (0.0, 0.0, 0.0)},
        {"subsurface_radius": (5.0, 0.0, 1.0)},  # one channel does not scatter
        {"subsurface_radius": (1000.0, 1000.0, 1000.0)},  # far wider than the object
        {"subsurface_radius": (1e-6, 1e-6, 1e-6)},  # far narrower than a texel
        {"subsurface_color": (0.0, 0.0, 0.0)},  # albedo 0
        {"subsurface_color": (1.0, 1.0, 1.0)},  # albedo 1: no absorption
        {"base_color": (0.0, 0.0, 0.0)},
        {"roughness": 0.0, "specular": 1.0},
    ],
)
@pytest.mark.parametrize("model", ["dipole", "burley", "blender-burley", "gaussians", "pbd"])
def test_hard_material_values_stay_finite(renderer, model, values):
    res = renderer.render(slab_scene(occluder=True, material=skin(model=model, **values)), ST)
    assert np.isfinite(res.hdr).all(), (model, values)
    assert res.hdr[..., :3].min() >= 0


def test_zero_radius_channel_is_unblurred():
    m = material_medium({"subsurface_color": (0.8, 0.5, 0.4), "subsurface_radius": (5.0, 0.0, 1.0), "specular": 0.5})
    f = profile_fit("burley", m, 4)
    assert f.identity[1] == 1.0 and np.all(f.weights[:, 1] == 0)
    assert f.identity[0] == 0.0 and f.weights[:, 0].sum() == pytest.approx(1.0)


def test_unknown_model_and_bad_settings_are_clear_errors():
    m = material_medium({"subsurface_color": (0.8, 0.5, 0.4), "subsurface_radius": (5.0, 1.0, 1.0), "specular": 0.5})
    with pytest.raises(ValueError, match="sss_model: no Gaussian profile fit for 'fog'"):
        profile_fit("fog", m, 4)
    with pytest.raises(ValueError, match="render setting sss_model: expected one of"):
        RenderSettings(sss_model="fog")
    with pytest.raises(ValueError, match=r"tsd setting gaussians: expected an integer in \[1, 6\], got 0"):
        TsdSettings(gaussians=0)
    with pytest.raises(ValueError, match="render setting technique: expected one of tsd, exact, ssss, tint, none"):
        RenderSettings(technique="fog")


def test_bunny_preset_scene_generates_uvs_and_scatters(renderer, tmp_path):
    scene = load_scene(assets_root() / "scenes" / "bunny-skimmilk.toml")
    (node,) = scene.mesh_nodes()
    assert node.mesh.uvs is not None  # generate_uvs = true
    assert node.material["subsurface_radius"][0] > 10  # skim milk scatters far (Jensen 2001)
    res = renderer.render(scene, RenderSettings(64, 64, shadow_size=256, technique=TsdSettings(size=128)))
    assert "tsd_irradiance" in kinds(res.plan) and np.isfinite(res.hdr).all()
    cover = res.hdr[..., 3] > 0
    assert 0.1 < cover.mean() < 0.9 and res.hdr[cover, :3].mean() > 0.05
    bad = tmp_path / "b.toml"
    bad.write_text('[materials.m]\npreset = "jam"\n[[meshes]]\nfile = "x.ply"\nmaterial = "m"\n')
    with pytest.raises(ValueError, match=r"\[materials.m\].preset: unknown material 'jam'"):
        load_scene(bad)


@pytest.mark.parametrize("technique", ["tsd", "exact"])
def test_sub_texel_profile_is_scattered_locally_with_the_boundary(renderer, technique):
    """A profile narrower than a texel needs no blur, but the light still enters and leaves through
    the medium's boundary: the slab lit at 45 degrees and seen from above reads
    E mu0 albedo (entry(mu0) exit(mu) / pi + the non-separable rest + Jensen's single scattering),
    from the NumPy tables (not the plain Burley diffuse the planner used to fall back to)."""
    from skinlab.scene.optics.boundary import boundary_tables, ms_rest_lookup, ms_rest_table, table_lookup
    from skinlab.scene.optics.single_scattering import single_scatter_brdf

    mat = skin(radius=(0.05, 0.05, 0.05), color=(0.8, 0.5, 0.2))
    scene = slab_scene(material=mat, light_dir=(1.0, 0.0, -1.0))
    rs = RenderSettings.for_technique(technique, 48, 48, shadow_size=256, size=64)
    res = renderer.render(scene, rs)
    assert not any(k.startswith("tsd") for k in kinds(res.plan))  # nothing to blur
    assert any("scattered locally" in why for _, why in res.plan.skipped), res.plan.skipped
    m = material_medium(mat.values)
    t = boundary_tables(m.alpha_arr, mat["subsurface_color"], m.eta)
    mu0 = np.sqrt(0.5)
    n, l, v = np.array([0.0, 0.0, 1.0]), np.array([-mu0, 0.0, mu0]), np.array([0.0, 0.0, 1.0])
    ss = single_scatter_brdf(n, l, v, t.single, m.eta, 0.0)
    colour = np.asarray(mat["subsurface_color"])  # the subsurface albedo (the colour rule, docs/scenes.md)
    rest = ms_rest_lookup(ms_rest_table(m.alpha_arr, mat["subsurface_color"], m.eta), 1.0, mu0)
    want = colour * mu0 * (table_lookup(t.entry, mu0) * table_lookup(t.exit, 1.0) / np.pi + rest + ss)
    got = res.hdr[23:25, 23:25, :3].reshape(-1, 3).mean(0)
    np.testing.assert_allclose(got, want, rtol=2e-3)
    plain = renderer.render(scene, RenderSettings.for_technique("none", 48, 48)).hdr[23:25, 23:25, :3]
    assert np.abs(plain.reshape(-1, 3).mean(0) / want - 1).max() > 0.05  # the old fallback was off


def test_the_uv_check_is_stored_by_mesh_content_and_read_back_equal(tmp_path, monkeypatch):
    """uv_report keeps analyse_uvs' report on disk (the head's takes about 0.1 s per start): another mesh
    of the same content (as a new process loads it) reads an equal report; another texel count is
    another key."""
    from skinlab import cache
    from skinlab.render.techniques.tsd.plan import uv_report
    from skinlab.scene.graph import MeshNode

    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path))
    built, loaded = cache.BUILT["uv_report"], cache.LOADED["uv_report"]
    first = uv_report(MeshNode("q", quad_mesh("q", 0.0, 1.0, 0.0, 1.0), skin()), 1.0, 64)
    again = uv_report(MeshNode("q", quad_mesh("q", 0.0, 1.0, 0.0, 1.0), skin()), 1.0, 64)
    assert (cache.BUILT["uv_report"], cache.LOADED["uv_report"]) == (built + 1, loaded + 1)
    assert again is not first and again.uv_coverage == first.uv_coverage and again.texels == 64
    np.testing.assert_array_equal(again.mm_per_texel, first.mm_per_texel)
    assert again.mm_per_texel_percentiles == first.mm_per_texel_percentiles
    uv_report(MeshNode("q", quad_mesh("q", 0.0, 1.0, 0.0, 1.0), skin()), 1.0, 128)
    assert cache.BUILT["uv_report"] == built + 2
