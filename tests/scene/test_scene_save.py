"""A scene written back as TOML (skinlab/scene/scene_save.py, the viewer's Ctrl+S) loads again with the
same materials, camera and lights."""

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
