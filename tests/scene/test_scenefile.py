import numpy as np
import pytest

from skinlab.resources import assets_root
from skinlab.scene.scenefile import DEFAULT_SCENE, SceneFileError, load_scene

ASSETS = assets_root()


def write(tmp_path, text):
    p = tmp_path / "s.toml"
    p.write_text(text)
    return p


BUNNY = f'''
[scene]
mm_per_unit = 1000.0
[materials.marble]
base_color = [0.9, 0.9, 0.88]
[[meshes]]
name = "bunny"
file = "{ASSETS / "stanford-bunny" / "bunny.ply"}"
material = "marble"
overrides = {{ roughness = 0.2 }}
[[lights]]
type = "point"
position = [0.3, 0.3, 0.3]
intensity = 2.0
'''


def test_default_scene_loads_head_with_maps_lights_and_camera():
    s = load_scene(DEFAULT_SCENE)
    assert s.mm_per_unit == 45.0
    (head,) = s.mesh_nodes()
    assert head.mesh.uvs is not None and len(head.mesh.positions) == 9279
    assert set(head.material.textures()) == {"u_base_color_map", "u_normal_map"}
    key = s.find("key")
    assert key.cast_shadow and np.allclose(
        key.direction, np.array([-0.55, -0.35, -0.75]) / np.linalg.norm([-0.55, -0.35, -0.75])
    )
    assert s.camera is not None


def test_overrides_and_default_camera(tmp_path):
    s = load_scene(write(tmp_path, BUNNY))
    (b,) = s.mesh_nodes()
    assert b.material["roughness"] == 0.2 and b.material["base_color"] == (0.9, 0.9, 0.88)
    assert s.lights()[0].kind == "point" and s.camera is not None
    # the generated camera sees the whole bunny
    lo, hi = s.world_bounds()
    assert np.linalg.norm(s.camera.world_position - (lo + hi) / 2) > np.linalg.norm(hi - lo) / 2


@pytest.mark.parametrize(
    "text, match",
    [
        ("[scene\n", r"s.toml: not valid TOML"),
        (
            "[scene]\nmm_per_unit = 1\n[[meshes]]\nfile='nope.glb'\n",
            r"s.toml: \[\[meshes\]\] #1.file: mesh file not found: .*nope.glb",
        ),
        ("[[meshes]]\nfil='x'\n", r"s.toml: \[\[meshes\]\] #1: unknown key\(s\) fil"),
        ("[materials.m]\nroughness = 2\n", r"s.toml: \[materials.m\].roughness: expected a number in \[0, 1\], got 2"),
        (
            "[materials.m]\nbase_color_map = 'missing.png'\n",
            r"\[materials.m\].base_color_map: texture file not found: .*missing.png",
        ),
        ("[[lights]]\ntype='point'\n", r"\[\[lights\]\] #1: a point light needs 'position'"),
        ("[scene]\nmm_per_unit = 1\n", r"the scene has no meshes"),
    ],
)
def test_bad_scene_files_name_file_and_key(tmp_path, text, match):
    with pytest.raises((SceneFileError, FileNotFoundError), match=match):
        load_scene(write(tmp_path, text))


def test_unknown_node_name_lists_the_file_nodes(tmp_path):
    text = BUNNY + "[meshes.nodes.Ear]\nmaterial='marble'\n"
    text = text.replace("[[lights]]", "").replace('type = "point"\nposition = [0.3, 0.3, 0.3]\nintensity = 2.0\n', "")
    with pytest.raises(SceneFileError, match="has no node named 'Ear'"):
        load_scene(write(tmp_path, text))


def test_environment_map_keys(tmp_path):
    from skinlab.scene.envmap import bundled_maps

    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    text = '[environment]\nmap = "studio"\nrotation_deg = 45\nintensity = 0.5\nshow_background = true\n'
    (tmp_path / "s.toml").write_text(text + '[[meshes]]\nfile = "tri.obj"\n')
    env = load_scene(tmp_path / "s.toml").environment
    assert env.map == bundled_maps()["studio"]
    assert (env.rotation_deg, env.intensity, env.show_background) == (45.0, 0.5, True)
    assert np.array_equal(env.ambient, np.zeros(3))  # with a map the uniform ambient is off unless given
    (tmp_path / "s.toml").write_text('[environment]\nmap = "studio"\nambient = 0.1\n[[meshes]]\nfile = "tri.obj"\n')
    assert np.allclose(load_scene(tmp_path / "s.toml").environment.ambient, 0.1)
    # a path relative to the scene file
    import shutil

    shutil.copy(bundled_maps()["city"], tmp_path / "c.exr")
    (tmp_path / "s.toml").write_text('[environment]\nmap = "c.exr"\n[[meshes]]\nfile = "tri.obj"\n')
    assert load_scene(tmp_path / "s.toml").environment.map == (tmp_path / "c.exr").resolve()
