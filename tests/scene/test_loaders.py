import numpy as np
import pytest
import trimesh

from skinlab.resources import assets_root
from skinlab.scene.loaders import load_mesh_file
from skinlab.scene.scenefile import load_scene

ASSETS = assets_root()


def two_level_glb(path):
    s = trimesh.Scene()
    box = trimesh.creation.box(extents=(1, 1, 1))
    ico = trimesh.creation.icosphere(subdivisions=1, radius=0.3)
    s.add_geometry(box, node_name="Body", geom_name="body_geom")
    s.add_geometry(
        ico,
        node_name="Eye",
        geom_name="eye_geom",
        parent_node_name="Body",
        transform=trimesh.transformations.translation_matrix([0.0, 0.5, 0.6]),
    )
    s.export(str(path))
    return path


def test_gltf_keeps_hierarchy_names_and_transforms(tmp_path):
    nodes = {n.name: n for n in load_mesh_file(two_level_glb(tmp_path / "two.glb"))}
    assert nodes["Eye"].parent == "Body" and nodes["Body"].parent is None
    assert np.allclose(nodes["Eye"].matrix[:3, 3], [0.0, 0.5, 0.6])
    assert len(nodes["Eye"].mesh.positions) == 42


def test_per_node_materials_from_scene_file(tmp_path):
    glb = two_level_glb(tmp_path / "two.glb")
    (tmp_path / "s.toml").write_text(f'''
[materials.skin]
roughness = 0.5
[materials.eye]
roughness = 0.05
[[meshes]]
file = "{glb}"
material = "skin"
[meshes.nodes.Eye]
material = "eye"
overrides = {{ specular = 0.9 }}
''')
    s = load_scene(tmp_path / "s.toml")
    body, eye = s.find("Body"), s.find("Eye")
    assert body.material["roughness"] == 0.5
    assert eye.material["roughness"] == 0.05 and eye.material["specular"] == 0.9
    assert eye.parent is body
    assert np.allclose(eye.world_position, [0.0, 0.5, 0.6])


def test_obj_and_unsupported_and_empty(tmp_path):
    obj = tmp_path / "t.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
    (n,) = load_mesh_file(obj)
    assert n.mesh.uvs is not None and n.mesh.indices.shape == (1, 3)
    with pytest.raises(ValueError, match=r"x.fbx: unsupported mesh format '.fbx'"):
        (tmp_path / "x.fbx").write_text("")
        load_mesh_file(tmp_path / "x.fbx")
    bad = tmp_path / "bad.ply"
    bad.write_text("this is not a ply file")
    with pytest.raises(ValueError, match="bad.ply"):
        load_mesh_file(bad)


def test_bunny_without_uvs_gets_an_atlas_or_a_clear_error():
    (n,) = load_mesh_file(ASSETS / "stanford-bunny" / "bunny.ply")
    m = n.mesh
    assert m.uvs is None
    with pytest.raises(ValueError, match=r"mesh 'bunny' \(.*bunny.ply\) has no UV coordinates, and texture-space"):
        m.ensure_uvs("texture-space diffusion needs them", generate=False)
    from dataclasses import replace

    copy = replace(m)  # do not mutate the cached mesh
    copy.ensure_uvs()
    assert copy.uvs.shape == (len(copy.positions), 2) and copy.version == m.version + 1
    assert copy.uvs.min() >= 0 and copy.uvs.max() <= 1
    assert np.isfinite(copy.ensure_tangents()).all()

    # the atlas covers the whole surface: same area in 3D as the original mesh
    def area(p, f):
        return 0.5 * np.linalg.norm(np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]), axis=1).sum()

    assert area(copy.positions, copy.indices) == pytest.approx(area(m.positions, m.indices), rel=1e-6)


def _grid_mesh(n=6):
    from skinlab.scene.mesh import Mesh

    xs, ys = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    pos = np.stack([xs.ravel(), ys.ravel(), np.sin(3 * xs.ravel()) * 0.2], axis=1)
    q = np.arange(n * n).reshape(n, n)[:-1, :-1].ravel()
    faces = np.concatenate([np.stack([q, q + 1, q + n], 1), np.stack([q + 1, q + n + 1, q + n], 1)])
    return Mesh("grid", pos, faces, source="grid.obj")


def test_atlas_is_cached_by_mesh_content(tmp_path, monkeypatch, capsys):
    """The second atlas of the same geometry comes from the cache (xatlas is not called), says
    nothing, and equals the first; other geometry misses; a damaged cache file is remade."""
    import xatlas

    from skinlab.scene.mesh import generate_atlas

    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path))
    first = _grid_mesh()
    generate_atlas(first)
    err = capsys.readouterr().err
    assert "generating a UV atlas for mesh 'grid' (grid.obj), 50 triangles" in err and str(tmp_path) in err
    (cached,) = (tmp_path / "atlas").glob("*.npz")
    assert not [p for p in (tmp_path / "atlas").iterdir() if p.name.startswith(".")]  # no temporary left

    def refuse(*a, **k):
        raise AssertionError("xatlas called although the atlas is cached")

    monkeypatch.setattr(xatlas, "parametrize", refuse)
    second = _grid_mesh()
    generate_atlas(second)
    assert capsys.readouterr().err == ""
    assert np.array_equal(second.uvs, first.uvs) and np.array_equal(second.indices, first.indices)
    assert np.array_equal(second.positions, first.positions)
    other = _grid_mesh(5)
    with pytest.raises(AssertionError, match="xatlas called"):
        generate_atlas(other)  # different content: a miss
    monkeypatch.undo()
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path))
    cached.write_bytes(b"broken")
    third = _grid_mesh()
    generate_atlas(third)
    assert "generating a UV atlas" in capsys.readouterr().err
    assert np.array_equal(third.uvs, first.uvs)


def test_generated_atlases_leave_the_loader_cache_alone(tmp_path):
    """generate_uvs (and texture-space diffusion on a mesh without UVs) give the scene an atlased
    copy: loading the file again still gives the mesh as the file has it."""
    from skinlab.scene.scenefile import load_scene

    scene_file = tmp_path / "s.toml"
    scene_file.write_text(f'[[meshes]]\nfile = "{ASSETS / "stanford-bunny" / "bunny.ply"}"\ngenerate_uvs = true\n')
    (node,) = load_scene(scene_file).mesh_nodes()
    assert node.mesh.uvs is not None
    (again,) = load_mesh_file(ASSETS / "stanford-bunny" / "bunny.ply")
    assert again.mesh.uvs is None and again.mesh is not node.mesh
    (node2,) = load_scene(scene_file).mesh_nodes()
    assert node2.mesh is node.mesh  # one atlas per source mesh and process
