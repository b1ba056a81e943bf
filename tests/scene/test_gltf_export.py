"""The scene as glTF (skinlab/scene/gltf_export.py): export, import, the same materials; lights and
camera written as KHR_lights_punctual and a perspective camera."""

import json
from pathlib import Path

import numpy as np
import pygltflib
import pytest

from skinlab.scene.gltf_export import export_gltf
from skinlab.scene.materials import Material
from skinlab.scene.scenefile import load_scene
from skinlab.scene.textures import load_texture
from tests.gltf_builder import png_bytes
from tests.tsd_scenes import quad_mesh, slab_scene


def same_material(a: Material, b: Material):
    for p in a.params:
        x, y = a[p.name], b[p.name]
        if p.kind == "texture":
            assert (x is None) == (y is None), p.name
            if x is not None:  # the channels both have (a one-channel map comes back as the R of RGB)
                ta, tb = load_texture(x, p.colorspace), load_texture(y, p.colorspace)
                k = min(ta.shape[2], tb.shape[2])
                np.testing.assert_allclose(ta[..., :k], tb[..., :k], atol=1.0 / 255 + 1e-6, err_msg=p.name)
        elif p.kind == "choice":
            assert x == y, p.name
        else:
            assert np.asarray(x, float) == pytest.approx(np.asarray(y, float), rel=1e-6, abs=1e-9), p.name


def write_png(path, pixels):
    path.write_bytes(png_bytes(pixels))
    return path


def materials(tmp_path):
    grey = write_png(tmp_path / "c.png", np.full((4, 4, 4), (200, 120, 80, 255), np.uint8))
    rough = write_png(tmp_path / "r.png", np.full((4, 4, 3), 90, np.uint8))
    return [
        Material(
            "skin",
            {
                "subsurface": 0.9,
                "subsurface_color": (0.85, 0.5, 0.35),
                "subsurface_radius": (8.0, 3.0, 1.5),
                "subsurface_scatter_anisotropy": 0.4,
                "specular": 0.3,
                "roughness": 0.45,
                "sss_model": "pbd",
                "base_color_map": str(grey),
            },
        ),  # fmt: skip
        Material(
            "card",
            {
                "alpha_mode": "mask",
                "alpha_cutoff": 0.3,
                "base_color_map": str(grey),
                "alpha": 0.8,
                "roughness_map": str(rough),
                "uv_offset": (0.25, 0.0),
                "uv_scale": (2.0, 2.0),
            },
        ),  # fmt: skip
        Material("lamp", {"emissive": (3.0, 1.5, 0.2), "metallic": 0.7, "roughness": 0.2}),
        Material("leaf", {"diffuse_transmission": 0.5, "diffuse_transmission_color": (0.2, 0.8, 0.1)}),
    ]


def test_export_import_gives_the_same_materials(tmp_path):
    scene = slab_scene(mm_per_unit=20.0)
    (slab,) = scene.mesh_nodes()
    mats = materials(tmp_path)
    slab.material = mats[0]
    from skinlab.scene.graph import MeshNode

    for i, m in enumerate(mats[1:]):
        scene.add(MeshNode(f"part{i}", quad_mesh(f"part{i}", -1, 1, -1, 1, z=0.1 * (i + 1)), m))
    glb, warnings = export_gltf(scene, tmp_path / "out.glb", aspect=1.0)
    assert warnings == []
    (tmp_path / "back.toml").write_text(f'[scene]\nmm_per_unit = 20.0\n[[meshes]]\nfile = "{glb}"\n')
    back = load_scene(tmp_path / "back.toml")
    assert not [w for w in back.warnings if "not read by Skinlab" in w and "KHR_materials" in w]
    got = {n.name: n.material for n in back.mesh_nodes()}
    same_material(mats[0], got["slab"])
    for i, m in enumerate(mats[1:]):
        same_material(m, got[f"part{i}"])
    # geometry and placement
    assert np.allclose(got["part0"].name and back.find("part0").world_matrix, scene.find("part0").world_matrix)
    assert np.allclose(back.find("slab").mesh.uvs, slab.mesh.uvs, atol=1e-7)
    # lights and camera are in the file
    g = pygltflib.GLTF2().load(str(glb))
    lights = g.extensions["KHR_lights_punctual"]["lights"]
    assert [l["name"] for l in lights] == [l.name for l in scene.lights()]
    assert len(g.cameras) == 1 and g.cameras[0].perspective.yfov == pytest.approx(scene.camera.yfov)


def test_gltf_text_file_and_bad_paths(tmp_path):
    scene = slab_scene()
    path, _ = export_gltf(scene, tmp_path / "s.gltf")
    data = json.loads(path.read_text())
    assert data["buffers"][0]["uri"].startswith("data:")
    assert load_scene(path).mesh_nodes()[0].material["subsurface"] == 1.0
    with pytest.raises(ValueError, match=r"expected a .glb or .gltf path"):
        export_gltf(scene, tmp_path / "s.obj")


def test_the_textured_head_round_trips_with_its_colour_map(tmp_path):
    """The colour rule through glTF: the map goes out as baseColorTexture and multiscatterColorTexture,
    the medium's albedo (subsurface colour x the map's mean) into the extinction; back at the same scale
    the same material (the mesh file opened with --mm-per-unit 45)."""
    from skinlab.scene.scene_edits import make_edits

    head = load_scene("head")
    glb, _ = export_gltf(head, tmp_path / "head.glb")
    back = load_scene(glb, make_edits(mm_per_unit=45.0))
    a, b = head.mesh_nodes()[0].material, back.mesh_nodes()[0].material
    same_material(a, b)
    assert np.allclose(back.mesh_nodes()[0].mesh.uvs, head.mesh_nodes()[0].mesh.uvs, atol=1e-6)


def gltf_lights(glb) -> dict:
    """name -> (type, colour, intensity, cone half-angles in degrees, position, direction) of the
    KHR_lights_punctual lights in a glTF file, read back with pygltflib (Skinlab's importer reads
    meshes and materials, not lights)."""
    import math

    g = pygltflib.GLTF2().load(str(glb))
    defs = (g.extensions or {}).get("KHR_lights_punctual", {"lights": []})["lights"]
    out = {}
    for n in g.nodes:
        ref = (n.extensions or {}).get("KHR_lights_punctual")
        if ref is None:
            continue
        d = defs[ref["light"]]
        m = np.asarray(n.matrix, np.float64).reshape(4, 4).T  # column-major
        cone = d.get("spot", {})
        out[d["name"]] = {
            "type": d["type"],
            "color": tuple(d["color"]),
            "intensity": d["intensity"],
            "cone_deg": tuple(
                round(math.degrees(cone[k]), 9) for k in ("innerConeAngle", "outerConeAngle") if k in cone
            ),
            "position": tuple(np.round(m[:3, 3], 7)),
            "direction": tuple(np.round(-m[:3, 2] / np.linalg.norm(m[:3, 2]), 7)),  # the node's -Z
        }
    return out


def test_each_light_kind_in_the_glb_and_one_warning_for_what_glTF_cannot_hold(tmp_path):
    """Directional, point and spot lights come back from the file with their colour, intensity, cone,
    position and direction; rect and sphere lights and the environment map are left out, named in one
    warning."""
    from skinlab.scene import transform as tf
    from skinlab.scene.envmap import bundled_maps
    from skinlab.scene.graph import LightNode

    scene = slab_scene()
    for light in list(scene.lights()):
        light.visible = False
    kinds = {"far": ("directional", {}), "bulb": ("point", {}),
             "cone": ("spot", {"inner_deg": 12.0, "outer_deg": 40.0}),
             "panel": ("rect", {"width": 2.0, "height": 0.5}), "ball": ("sphere", {"radius": 0.3})}  # fmt: skip
    for i, (name, (kind, shape)) in enumerate(kinds.items()):
        light = LightNode(name, kind, color=(0.9, 0.5, 0.25 + 0.1 * i), intensity=1.5 + i, **shape)
        light.translation = (0.5 * i, 1.0, 3.0)
        light.rotation = tf.look_at_rotation((0, 0, 0), (0.1 * i, -0.3, -1.0))
        scene.add(light)
    scene.environment.map = bundled_maps()["studio"]
    scene.environment.rotation_deg = 30.0
    glb, warnings = export_gltf(scene, tmp_path / "lit.glb", aspect=1.0)
    got = gltf_lights(glb)
    assert sorted(got) == ["bulb", "cone", "far"]
    for name, w in got.items():
        light = scene.find(name)
        assert w["type"] == light.kind and w["intensity"] == light.intensity
        assert w["color"] == pytest.approx(tuple(light.color))
        if light.kind != "directional":
            assert w["position"] == pytest.approx(tuple(light.world_position), abs=1e-6)
        if light.kind != "point":
            assert w["direction"] == pytest.approx(tuple(light.direction), abs=1e-6)
    assert got["cone"]["cone_deg"] == pytest.approx((12.0, 40.0))
    assert len(warnings) == 1, warnings
    (w,) = warnings
    assert "'panel'" in w and "'ball'" in w and "rect" in w and "sphere" in w and "studio" in w and "30 deg" in w
    for name in ("far", "bulb", "cone"):
        assert f"'{name}'" not in w
    # nothing left out: no warning
    plain, none = export_gltf(slab_scene(), tmp_path / "plain.glb", aspect=1.0)
    assert none == [] and gltf_lights(plain)


def test_skinlab_export_prints_the_one_warning(tmp_path, capsys):
    from skinlab.cli import main

    bunny = (Path("skinlab/assets/stanford-bunny/bunny.ply")).resolve()
    (tmp_path / "s.toml").write_text(
        f'[environment]\nmap = "studio"\n[[meshes]]\nfile = "{bunny}"\n'
        '[[lights]]\nname = "key"\ntype = "spot"\nposition = [0, 0, 3]\n'
        '[[lights]]\nname = "soft"\ntype = "rect"\nposition = [0, 1, 3]\n'
    )
    assert main(["export", str(tmp_path / "s.toml"), "--out", str(tmp_path / "s.glb")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("warning: not written") and "'soft'" in err[0] and "studio" in err[0]
    assert sorted(gltf_lights(tmp_path / "s.glb")) == ["key"]
