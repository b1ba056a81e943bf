"""A scene written back as TOML (skinlab/scene/scene_save.py, the viewer's Ctrl+S) loads again with the
same materials, camera and lights."""

from pathlib import Path

import numpy as np
import pytest

from skinlab.scene.scene_save import save_scene
from skinlab.scene.scenefile import load_scene


def materials(scene):
    return {n.name: dict(n.material.values) for n in scene.mesh_nodes(visible_only=False)}


def test_an_edited_head_round_trips(tmp_path):
    scene = load_scene("head")
    mat = scene.mesh_nodes()[0].material
    mat.update({"roughness": 0.31, "subsurface_color": [0.2, 0.8, 0.2]})
    mat.apply_preset("skin2")
    scene.orbit_camera(25)
    scene.find("key").intensity = 4.5
    scene.environment.exposure = 1.7
    path = save_scene(scene, tmp_path / "edited.toml")
    back = load_scene(path)
    assert materials(back) == materials(scene)
    assert np.allclose(back.camera.world_matrix, scene.camera.world_matrix, atol=1e-9)
    assert back.camera.yfov == pytest.approx(scene.camera.yfov)
    assert back.find("key").intensity == 4.5 and back.environment.exposure == 1.7
    assert [(l.name, l.kind, l.cast_shadow) for l in back.lights()] == [
        (l.name, l.kind, l.cast_shadow) for l in scene.lights()
    ]
    assert np.allclose(back.find("key").direction, scene.find("key").direction)
    assert back.mesh_nodes()[0].mesh.uvs[0] == pytest.approx(scene.mesh_nodes()[0].mesh.uvs[0])  # flip_v kept
    with pytest.raises(ValueError, match=r"expected a .toml path"):
        save_scene(scene, tmp_path / "x.json")


def test_a_glb_with_its_own_materials_round_trips(tmp_path):
    from tests.gltf_builder import GlbBuilder

    b = GlbBuilder()
    b.quad("a", b.material(name="red", pbr={"baseColorFactor": [1, 0, 0, 1]}))
    b.quad("b", b.material(name="glow", emissiveFactor=[0, 1, 0]), centre=(0, 0, 1))
    scene = load_scene(b.save(tmp_path / "two.glb"))
    scene.find("b").visible = False
    back = load_scene(save_scene(scene, tmp_path / "two.toml"))
    assert materials(back) == materials(scene)
    assert back.find("b").visible is False and back.find("a").material["base_color"] == (1.0, 0.0, 0.0)


def test_environment_map_and_spot_and_area_lights_round_trip(tmp_path):
    from skinlab.scene import transform as tf
    from skinlab.scene.envmap import bundled_maps
    from skinlab.scene.graph import LightNode

    scene = load_scene("head-studio")
    scene.environment.rotation_deg = -75.0
    scene.environment.intensity = 0.6
    for kind, kw in (("spot", {"inner_deg": 12.0, "outer_deg": 33.0}), ("rect", {"width": 2.0, "height": 0.5}),
                     ("sphere", {"radius": 0.3})):  # fmt: skip
        light = LightNode(kind, kind, intensity=2.0, **kw)
        light.translation = (1.0, 2.0, 8.0)
        light.rotation = tf.look_at_rotation((0, 0, 0), (-0.1, -0.2, -1.0))
        scene.add(light)
    back = load_scene(save_scene(scene, tmp_path / "lit.toml"))
    env = back.environment
    assert env.map == bundled_maps()["studio"] and (env.rotation_deg, env.intensity) == (-75.0, 0.6)
    assert env.show_background and not env.ambient.any()
    for kind in ("spot", "rect", "sphere"):
        a, b = scene.find(kind), back.find(kind)
        assert b.kind == kind and np.allclose(a.world_position, b.world_position)
        assert (a.inner_deg, a.outer_deg, a.width, a.height, a.radius) == pytest.approx(
            (b.inner_deg, b.outer_deg, b.width, b.height, b.radius)
        )
        if kind != "sphere":
            assert np.allclose(a.direction, b.direction)


LIGHT_KINDS = [
    ("directional", {}),
    ("point", {}),
    ("spot", {"inner_deg": 7.5, "outer_deg": 61.0}),
    ("rect", {"width": 0.25, "height": 3.0}),
    ("sphere", {"radius": 1.75}),
]


def lit_scene(kind, shape, shadow: bool):
    """The bunny under one light of `kind` (its colour, intensity, shadow and shape not the defaults)."""
    from skinlab.scene import transform as tf
    from skinlab.scene.graph import LightNode

    scene = load_scene("skinlab/assets/stanford-bunny/bunny.ply")
    for light in list(scene.lights()):
        light.visible = False  # switched off: saved as off
    light = LightNode("only", kind, color=(0.9, 0.4, 0.2), intensity=3.25, cast_shadow=shadow, **shape)
    light.translation = (0.5, 1.5, 4.0)
    light.rotation = tf.look_at_rotation((0, 0, 0), (-0.2, -0.4, -1.0))
    scene.add(light)
    return scene, light


def light_state(light):
    out = {"kind": light.kind, "color": tuple(float(x) for x in np.round(light.color, 7)), "intensity": light.intensity,
           "cast_shadow": light.cast_shadow, "visible": light.visible}  # fmt: skip
    if light.kind != "directional":
        out["position"] = tuple(float(x) for x in np.round(light.world_position, 7))
    if light.kind in ("directional", "spot", "rect"):
        out["direction"] = tuple(float(x) for x in np.round(light.direction, 7))
    shape = {"spot": ("inner_deg", "outer_deg"), "rect": ("width", "height"), "sphere": ("radius",)}
    out |= {k: getattr(light, k) for k in shape.get(light.kind, ())}
    return out


@pytest.mark.parametrize("kind, shape", LIGHT_KINDS, ids=[k for k, _ in LIGHT_KINDS])
def test_each_light_kind_round_trips_with_its_colour_intensity_shadow_and_shape(tmp_path, kind, shape):
    scene, light = lit_scene(kind, shape, shadow=kind in ("spot", "sphere"))
    back = load_scene(save_scene(scene, tmp_path / "one.toml"))
    lights = {l.name: l for l in back.nodes() if l in back.lights() or l.name in ("key", "fill")}
    assert [l.name for l in back.lights()] == ["only"]  # the switched-off ones stay off ...
    assert not lights["key"].visible and not lights["fill"].visible  # ... and stay in the file
    assert light_state(back.find("only")) == light_state(light)


@pytest.mark.parametrize("background", [True, False])
def test_the_environment_round_trips_from_a_file_or_by_name(tmp_path, background):
    from skinlab.scene.envmap import bundled_maps, write_map

    scene = load_scene("skinlab/assets/stanford-bunny/bunny.ply")
    own = write_map(tmp_path / "own.exr", np.full((8, 16, 3), 0.5, np.float32))
    env = scene.environment
    env.map = own if background else bundled_maps()["city"]
    env.rotation_deg, env.intensity, env.show_background = 123.5, 0.25, background
    back = load_scene(save_scene(scene, tmp_path / "sub" / "env.toml")).environment
    assert Path(back.map).resolve() == Path(env.map).resolve()
    assert (back.rotation_deg, back.intensity, back.show_background, back.exposure) == (
        123.5, 0.25, background, env.exposure)  # fmt: skip
