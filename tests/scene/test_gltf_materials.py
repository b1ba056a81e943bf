"""glTF materials read onto Skinlab's parameters (skinlab/scene/gltf_materials.py): each test builds its own
GLB with pygltflib and checks the material values and the rendered colour."""

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.scene.scenefile import load_scene
from skinlab.scene.textures import load_texture
from tests.gltf_builder import GlbBuilder, checker

SIZE = 24


def render(renderer, scene, technique="none", **kw):
    return renderer.render(scene, RenderSettings.for_technique(technique, SIZE, SIZE, shadow_size=256, **kw))


def centre(img, r=3):
    h, w = img.shape[:2]
    return img[h // 2 - r : h // 2 + r, w // 2 - r : w // 2 + r, :3].reshape(-1, 3).mean(0)


def test_base_colour_factor_and_metallic_reach_the_material_and_the_image(tmp_path, renderer):
    b = GlbBuilder()
    b.quad("red", b.material(name="red", pbr={"baseColorFactor": [0.9, 0.05, 0.05, 1.0], "metallicFactor": 0.0}))
    scene = load_scene(b.save(tmp_path / "red.glb"))
    (node,) = scene.mesh_nodes()
    m = node.material
    assert m.name == "red" and m["base_color"] == pytest.approx((0.9, 0.05, 0.05)) and m["metallic"] == 0.0
    assert m["roughness"] == 1.0  # the glTF default
    r, g, bl = centre(render(renderer, scene).hdr)
    assert r > 5 * g and r > 5 * bl  # a red quad, not the grey default

    b = GlbBuilder()
    b.quad("metal", b.material(name="metal", pbr={"baseColorFactor": [1, 0, 0, 1], "metallicFactor": 1.0}))
    (node,) = load_scene(b.save(tmp_path / "metal.glb")).mesh_nodes()
    assert node.material["metallic"] == 1.0


def test_base_colour_texture_is_an_srgb_map_and_renders_its_checker(tmp_path, renderer):
    b = GlbBuilder()
    tex = b.image(checker(8, 2, (255, 255, 255), (10, 10, 10)))
    b.quad("chk", b.material(name="chk", pbr={"baseColorTexture": {"index": tex}, "metallicFactor": 0.0}))
    scene = load_scene(b.save(tmp_path / "chk.glb"))
    (node,) = scene.mesh_nodes()
    path = node.material["base_color_map"]
    assert path is not None and path.is_file()
    px = load_texture(path, "srgb")
    assert px.max() == pytest.approx(1.0) and px.min() == pytest.approx(
        (10 / 255 + 0.055) ** 2.4 / 1.055**2.4, rel=1e-3
    )
    img = render(renderer, scene).hdr[..., :3].mean(2)
    covered = render(renderer, scene).hdr[..., 3] > 0.5
    lum = img[covered]
    assert lum.max() > 10 * max(lum.min(), 1e-6)  # light and dark cells, not one flat grey


def test_vertex_colours_multiply_the_base_colour(tmp_path, renderer):
    b = GlbBuilder()
    green = np.tile([0.05, 0.9, 0.05, 1.0], (4, 1))
    b.quad("vc", b.material(name="white", pbr={"metallicFactor": 0.0}), colors=green)
    scene = load_scene(b.save(tmp_path / "vc.glb"))
    (node,) = scene.mesh_nodes()
    assert node.mesh.colors is not None and np.allclose(node.mesh.colors[:, :3], [0.05, 0.9, 0.05])
    r, g, bl = centre(render(renderer, scene).hdr)
    assert g > 5 * r and g > 5 * bl


def test_metallic_roughness_texture_is_split_into_skinlab_maps(tmp_path):
    b = GlbBuilder()
    px = np.zeros((4, 4, 3), np.uint8)
    px[..., 1], px[..., 2] = 64, 200  # G roughness, B metalness
    tex = b.image(px)
    ntex, otex = b.image(np.full((4, 4, 3), 128, np.uint8)), b.image(np.full((4, 4, 3), 100, np.uint8))
    mat = b.material(
        name="mr",
        pbr={"metallicRoughnessTexture": {"index": tex}, "metallicFactor": 0.5, "roughnessFactor": 0.8},
        normalTexture={"index": ntex, "scale": 2.5},
        occlusionTexture={"index": otex, "strength": 0.25},
    )
    b.quad("q", mat)
    (node,) = load_scene(b.save(tmp_path / "mr.glb")).mesh_nodes()
    m = node.material
    assert m["metallic"] == 0.5 and m["roughness"] == 0.8
    assert load_texture(m["roughness_map"], "linear")[..., 0].mean() == pytest.approx(64 / 255, abs=1e-3)
    assert load_texture(m["metallic_map"], "linear")[..., 0].mean() == pytest.approx(200 / 255, abs=1e-3)
    assert m["normal_scale"] == 2.5 and m["normal_map"] is not None
    assert m["occlusion_strength"] == 0.25 and m["occlusion_map"] is not None


def test_emission_is_seen_without_any_light(tmp_path, renderer):
    b = GlbBuilder()
    mat = b.material(
        name="glow",
        emissiveFactor=[0.2, 0.6, 1.0],
        extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}},
        pbr={"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0},
    )
    b.quad("g", mat)
    scene = load_scene(b.save(tmp_path / "glow.glb"))
    (node,) = scene.mesh_nodes()
    assert node.material["emissive"] == pytest.approx((0.4, 1.2, 2.0))
    for light in scene.lights():
        light.intensity = 0.0
    scene.environment.ambient = np.zeros(3)
    assert centre(render(renderer, scene).hdr) == pytest.approx([0.4, 1.2, 2.0], rel=1e-3)
    assert not [w for w in scene.warnings if "emissive_strength" in w]  # a read extension is no warning


def _card_scene(tmp_path, mode, alpha=1.0):
    """A red quad behind a quad whose left half is transparent (a colour map with alpha 0 there)."""
    b = GlbBuilder()
    px = np.full((4, 4, 4), 255, np.uint8)
    px[..., 3] = 255
    px[:, :2, 3] = 0  # left half cut away
    px[..., :3] = (20, 20, 230)
    card = b.material(
        name="card",
        pbr={"baseColorTexture": {"index": b.image(px)}, "metallicFactor": 0.0, "baseColorFactor": [1, 1, 1, alpha]},
        alphaMode=mode,
        alphaCutoff=0.5,
    )
    b.quad("back", b.material(name="back", pbr={"baseColorFactor": [0.9, 0.05, 0.05, 1], "metallicFactor": 0.0}),
           centre=(0, 0, -0.5), size=3.0)  # fmt: skip
    b.quad("card", card)
    return load_scene(b.save(tmp_path / f"card-{mode}.glb"))


def test_alpha_mask_cuts_the_card_in_colour_and_in_the_depth_prepass(tmp_path, renderer):
    scene = _card_scene(tmp_path, "MASK")
    card = scene.find("card")
    assert card.material["alpha_mode"] == "mask" and card.material["alpha_cutoff"] == 0.5
    for prepass in (False, True):
        img = render(renderer, scene, depth_prepass=prepass).hdr
        h = img.shape[0] // 2
        left, right = img[h, SIZE // 2 - 4, :3], img[h, SIZE // 2 + 4, :3]
        assert left[0] > 3 * left[2], "the red quad shows through the cut-away half"
        assert right[2] > 3 * right[0], "the kept half is the card's blue"


def test_alpha_mask_casts_no_shadow_where_cut(tmp_path, renderer):
    scene = _card_scene(tmp_path, "MASK")
    for light in scene.lights():  # one light straight down the view axis: the card's shadow falls behind it
        light.cast_shadow = light.name == "key"
        light.rotation = (0.0, 0.0, 0.0, 1.0)
    masked = render(renderer, scene).hdr
    card = scene.find("card")
    card.visible = False  # the back quad alone, lit, for reference
    bare = render(renderer, scene).hdr
    card.visible = True
    card.material.update({"alpha_mode": "opaque"})
    opaque = render(renderer, scene).hdr
    h, x = SIZE // 2, SIZE // 2 - 4  # a back-quad pixel behind the card's cut-away half
    # masked: the cut half casts nothing, the back is as bright as without the card; opaque: the
    # card itself is seen there
    assert masked[h, x, 0] == pytest.approx(bare[h, x, 0], rel=0.05)
    assert opaque[h, x, 2] > 3 * opaque[h, x, 0]


def test_alpha_blend_mixes_over_what_is_behind(tmp_path, renderer):
    scene = _card_scene(tmp_path, "BLEND", alpha=0.5)
    img = render(renderer, scene).hdr
    h = img.shape[0] // 2
    right = img[h, SIZE // 2 + 4, :3]
    assert right[0] > 0.1 * right.max() and right[2] > 0.1 * right.max()  # red and blue both there
    assert 0.4 < img[h, SIZE // 2 + 4, 3] <= 1.0


def test_unknown_extensions_are_named_in_one_warning(tmp_path, renderer):
    b = GlbBuilder()
    b.quad("q", b.material(name="x", extensions={"KHR_materials_clearcoat": {"clearcoatFactor": 1.0},
                                                  "EXT_made_up": {}}))  # fmt: skip
    scene = load_scene(b.save(tmp_path / "ext.glb"))
    found = [w for w in scene.warnings if "not read by Skinlab" in w]
    assert len(found) == 1 and "KHR_materials_clearcoat" in found[0] and "EXT_made_up" in found[0]
    assert found[0] in render(renderer, scene).plan.warnings


def test_a_scene_file_material_wins_over_the_files_own(tmp_path):
    b = GlbBuilder()
    b.quad("q", b.material(name="red", pbr={"baseColorFactor": [1, 0, 0, 1]}))
    glb = b.save(tmp_path / "q.glb")
    (tmp_path / "own.toml").write_text(f'[[meshes]]\nfile = "{glb}"\noverrides = {{ roughness = 0.2 }}\n')
    (node,) = load_scene(tmp_path / "own.toml").mesh_nodes()
    assert node.material["base_color"] == (1.0, 0.0, 0.0) and node.material["roughness"] == 0.2
    (tmp_path / "named.toml").write_text(
        f'[materials.grey]\nbase_color = 0.5\n[[meshes]]\nfile = "{glb}"\nmaterial = "grey"\n'
    )
    (node,) = load_scene(tmp_path / "named.toml").mesh_nodes()
    assert node.material["base_color"] == (0.5, 0.5, 0.5)


def test_texture_transform_moves_the_map(tmp_path, renderer):
    px = np.zeros((4, 4, 3), np.uint8)
    px[:, :2] = (250, 250, 250)  # left half white, right half black
    renders = {}
    for name, ext in (("plain", None), ("shifted", {"KHR_texture_transform": {"offset": [0.5, 0.0]}})):
        b = GlbBuilder()
        info = {"index": b.image(px)}
        if ext:
            info["extensions"] = ext
            b.extensions_used.add("KHR_texture_transform")
        b.quad("q", b.material(name=name, pbr={"baseColorTexture": info, "metallicFactor": 0.0}))
        scene = load_scene(b.save(tmp_path / f"{name}.glb"))
        renders[name] = (scene.mesh_nodes()[0].material, render(renderer, scene).hdr[..., :3].mean(2))
    m = renders["shifted"][0]
    assert m["uv_offset"] == (0.5, 0.0) and m["uv_scale"] == (1.0, 1.0) and m["uv_rotation"] == 0.0
    assert "UV_TRANSFORM" in m.defines() and "UV_TRANSFORM" not in renders["plain"][0].defines()
    h, q = SIZE // 2, SIZE // 4
    plain, shifted = renders["plain"][1], renders["shifted"][1]
    assert plain[h, h - q] > 5 * plain[h, h + q]  # left bright
    assert shifted[h, h + q] > 5 * shifted[h, h - q]  # offset by half a texture: right bright


def test_ior_and_specular_extensions_set_specular(tmp_path):
    b = GlbBuilder()
    b.quad("q", b.material(name="c", extensions={"KHR_materials_ior": {"ior": 1.376},
                                                 "KHR_materials_specular": {"specularFactor": 0.5}}))  # fmt: skip
    (node,) = load_scene(b.save(tmp_path / "c.glb")).mesh_nodes()
    f0 = ((1.376 - 1) / (1.376 + 1)) ** 2
    assert node.material["specular"] == pytest.approx(f0 * 0.5 / 0.08)


def _volume_glb(tmp_path, name, scatter_ext, scatter, thickness=1.0, dt=None):
    b = GlbBuilder()
    ext = {
        "KHR_materials_volume": {
            "thicknessFactor": thickness,
            "attenuationDistance": 0.5,
            "attenuationColor": [0.9, 0.5, 0.2],
        },  # fmt: skip
        scatter_ext: scatter,
    }
    if dt is not None:
        ext["KHR_materials_diffuse_transmission"] = {"diffuseTransmissionFactor": dt}
    b.quad("q", b.material(name=name, extensions=ext, pbr={"metallicFactor": 0.0}))
    return b.save(tmp_path / f"{name}.glb")


@pytest.mark.parametrize("ext", ["KHR_materials_volume_scatter", "KHR_materials_scatter"])
def test_scattering_volume_drafts_become_the_subsurface_medium(tmp_path, ext):
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.optics.similarity import van_de_hulst_albedo

    scatter = {"multiscatterColorFactor": [0.8, 0.6, 0.4], "scatterAnisotropy": 0.5}
    if ext == "KHR_materials_scatter":
        scatter["scatterStrengthFactor"] = 0.5
    glb = _volume_glb(tmp_path, "v", ext, scatter, dt=0.8)
    (tmp_path / "s.toml").write_text(f'[scene]\nmm_per_unit = 10.0\n[[meshes]]\nfile = "{glb}"\n')
    scene = load_scene(tmp_path / "s.toml")
    m = scene.mesh_nodes()[0].material
    colour = np.array([0.8, 0.6, 0.4]) * (0.5 if ext == "KHR_materials_scatter" else 1.0)
    assert m["subsurface"] == 0.8 and m["subsurface_color"] == pytest.approx(tuple(colour))
    assert m["subsurface_scatter_anisotropy"] == 0.5 and m.has_subsurface
    # the medium's real extinction is the draft's: sigma_a / (1 - rho_ss), per scene unit
    rho = van_de_hulst_albedo(colour, 0.5)
    sigma_a = -np.log([0.9, 0.5, 0.2]) / 0.5
    sigma_t = sigma_a / (1 - rho)
    reduced_mm = np.asarray(m["subsurface_radius"]) / (4 * np.pi)  # Skinlab's l' in mm
    assert 1.0 / (reduced_mm / 10.0) == pytest.approx(sigma_t * (1 - rho * 0.5), rel=1e-9)
    assert material_medium(m.values).mfp_arr == pytest.approx(reduced_mm)
    assert not [w for w in scene.warnings if "not read by Skinlab" in w]


def test_diffuse_transmission_lets_light_from_behind_through(tmp_path, renderer):
    imgs = {}
    for name, dt in (("opaque", None), ("leaf", 0.6)):
        b = GlbBuilder()
        dtx = {"diffuseTransmissionFactor": dt, "diffuseTransmissionColorFactor": [0.2, 0.9, 0.2]}
        ext = {"KHR_materials_diffuse_transmission": dtx} if dt else None
        b.quad("q", b.material(name=name, extensions=ext, pbr={"metallicFactor": 0.0}))
        scene = load_scene(b.save(tmp_path / f"{name}.glb"))
        if dt:
            m = scene.mesh_nodes()[0].material
            assert m["diffuse_transmission"] == 0.6 and m["diffuse_transmission_color"] == (0.2, 0.9, 0.2)
        for light in scene.lights():  # the key light from behind the quad, the fill off
            light.rotation = (0.0, 1.0, 0.0, 0.0)  # travels +Z: from behind toward the camera
            light.intensity = light.intensity if light.name == "key" else 0.0
        scene.environment.ambient = np.zeros(3)
        imgs[name] = centre(render(renderer, scene).hdr)
    assert imgs["opaque"].max() < 1e-6
    r, g, b_ = imgs["leaf"]
    assert g > 0.05 and g > 3 * r and g > 3 * b_  # green light through the leaf


def test_a_volume_without_scattering_is_warned_about(tmp_path):
    b = GlbBuilder()
    b.quad("q", b.material(name="glass", extensions={"KHR_materials_volume": {"thicknessFactor": 1.0}}))
    scene = load_scene(b.save(tmp_path / "glass.glb"))
    assert any("KHR_materials_volume without scattering" in w for w in scene.warnings)
    assert not scene.mesh_nodes()[0].material.has_subsurface


def test_embedded_textures_are_written_even_with_the_disk_cache_off(tmp_path, monkeypatch):
    monkeypatch.setenv("SKINLAB_CACHE_DIR", "off")
    b = GlbBuilder()
    b.quad("q", b.material(name="chk", pbr={"baseColorTexture": {"index": b.image(checker(4, 2))}}))
    (node,) = load_scene(b.save(tmp_path / "off.glb")).mesh_nodes()
    path = node.material["base_color_map"]
    assert path.is_file() and "skinlab-gltf-" in str(path) and not (tmp_path / "off").exists()
