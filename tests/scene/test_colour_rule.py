"""One rule for colour (docs/scenes.md, the colour rule): the colour map multiplies the subsurface colour
per texel, the medium comes from the subsurface colour x the map's mean, and a preset sets the same
parameters in scene files, the API and the viewer."""

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from skinlab.scene.materials import Material, preset_values
from skinlab.scene.optics.material_medium import material_medium, subsurface_albedo
from skinlab.scene.optics.media import Medium, preset
from skinlab.scene.scenefile import load_scene
from skinlab.viewer.panel import PanelModel
from tests.tsd_scenes import skin, slab_scene

SIZE = 16


def grey_map(tmp_path, value=180):
    from PIL import Image

    path = tmp_path / "grey.png"
    Image.fromarray(np.full((4, 4, 3), value, np.uint8)).save(path)
    return path


def mean_rgb(renderer, scene, technique="tint"):
    img = renderer.render(scene, RenderSettings.for_technique(technique, SIZE, SIZE, shadow_size=128)).hdr
    return img[4:-4, 4:-4, :3].reshape(-1, 3).mean(0)


@pytest.mark.parametrize("technique", ["tint", "ssss", "tsd"])
def test_the_colour_map_multiplies_the_subsurface_colour(tmp_path, renderer, technique):
    grey = grey_map(tmp_path)
    kw = {"size": 64} if technique == "tsd" else {}
    colours = {}
    for name, colour in (("green", (0.2, 0.8, 0.2)), ("red", (0.8, 0.2, 0.2))):
        mat = skin(color=colour, base_color_map=str(grey))
        scene = slab_scene(material=mat)
        img = renderer.render(scene, RenderSettings.for_technique(technique, SIZE, SIZE, shadow_size=128, **kw)).hdr
        colours[name] = img[4:-4, 4:-4, :3].reshape(-1, 3).mean(0)
    g, r = colours["green"], colours["red"]
    assert g[1] > 2 * g[0] and r[0] > 2 * r[1]  # the subsurface colour shows through the map


def test_the_medium_is_the_subsurface_colour_times_the_maps_mean(tmp_path):
    grey = grey_map(tmp_path, 128)
    values = skin(color=(0.9, 0.6, 0.4), base_color_map=str(grey)).values
    mean = ((128 / 255 + 0.055) / 1.055) ** 2.4
    assert subsurface_albedo(values) == pytest.approx(np.array([0.9, 0.6, 0.4]) * mean, rel=1e-3)
    plain = Medium.from_artist_radius(np.array([0.9, 0.6, 0.4]) * mean, values["subsurface_radius"], eta=1.0)
    assert material_medium(values).alpha_arr == pytest.approx(plain.alpha_arr, rel=1e-6)


def test_a_preset_sets_the_same_values_everywhere(tmp_path):
    want = preset_values("ketchup")
    assert set(want) == {"base_color", "subsurface_color", "subsurface_radius", "subsurface", "specular"}
    # the API, two ways
    a = Material("a").apply_preset("ketchup")
    b = Material("b").update({"preset": "ketchup", "roughness": 0.3})
    assert all(a[k] == v for k, v in want.items()) and all(b[k] == v for k, v in want.items())
    assert b["roughness"] == 0.3  # the other values after the preset
    # a scene file
    (tmp_path / "q.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "s.toml").write_text('[materials.k]\npreset = "ketchup"\n[[meshes]]\nfile = "q.obj"\nmaterial = "k"\n')
    m = load_scene(tmp_path / "s.toml").mesh_nodes()[0].material
    assert all(m[k] == v for k, v in want.items())
    # the viewer
    scene = load_scene(tmp_path / "s.toml")
    panel = PanelModel(scene, presets=lambda: {"ketchup": preset("ketchup")})
    panel.material.update({"base_color": (0.1, 0.1, 0.1), "subsurface": 0.2})
    panel.apply_preset("ketchup")
    assert all(panel.material[k] == v for k, v in want.items())
    with pytest.raises(ValueError, match=r"material 'a': preset: unknown material 'jam'"):
        a.apply_preset("jam")


def test_a_preset_on_a_textured_material_turns_its_colour(tmp_path, renderer):
    grey = grey_map(tmp_path, 230)
    m = Material("k", {"base_color_map": str(grey)}).apply_preset("ketchup")
    r, g, b = mean_rgb(renderer, slab_scene(material=m, light_dir=(0.7, 0.0, -1.0)))  # no highlight
    assert r > 3 * g and r > 3 * b  # ketchup red, through the map


def test_the_head_takes_its_subsurface_colour(renderer):
    scene = load_scene("head")
    skin_mat = scene.mesh_nodes()[0].material
    st = RenderSettings.for_technique("tint", 24, 24, shadow_size=128)
    before = renderer.render(scene, st).hdr[..., :3]
    skin_mat.update({"subsurface_color": [0.2, 0.8, 0.2]})
    after = renderer.render(scene, st).hdr[..., :3]
    covered = before.sum(2) > 0
    rb, gb = before[covered, 0].sum(), before[covered, 1].sum()
    ra, ga = after[covered, 0].sum(), after[covered, 1].sum()
    assert rb > gb and ga > ra  # skin-coloured, then green
