"""Loop subdivision (skinlab/scene/mesh_subdivide.py) and the scene entry's `subdivide`: four triangles
per level, no cracks at UV seams, flat stays flat, facets flatten out, attributes per corner, and the
truth's exported mesh is the subdivided one."""

import numpy as np
import pytest

from skinlab.scene.mesh import Mesh
from skinlab.scene.mesh_subdivide import loop_subdivide
from skinlab.scene.primitives import box_mesh, sphere_mesh
from skinlab.scene.scenefile import SceneFileError, load_scene


def _grid(n=4):
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    pos = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], 1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)])
    return Mesh("grid", pos, faces, uvs=pos[:, :2].copy())


def _max_dihedral(mesh: Mesh) -> float:
    """The largest angle (degrees) between the normals of two faces sharing an edge (welded)."""
    p = mesh.positions.astype(np.float64)
    _, weld = np.unique(p, axis=0, return_inverse=True)
    f = weld.reshape(-1)[mesh.indices.astype(np.int64)]
    fn = np.cross(p[mesh.indices[:, 1]] - p[mesh.indices[:, 0]], p[mesh.indices[:, 2]] - p[mesh.indices[:, 0]])
    fn /= np.linalg.norm(fn, axis=1, keepdims=True)
    e = np.sort(np.stack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]], 1).reshape(-1, 2), axis=1)
    order = np.lexsort((e[:, 1], e[:, 0]))
    es, owner = e[order], np.repeat(np.arange(len(f)), 3)[order]
    same = (es[1:] == es[:-1]).all(1)
    cos = np.sum(fn[owner[1:][same]] * fn[owner[:-1][same]], 1)
    return float(np.degrees(np.arccos(np.clip(cos, -1, 1))).max())


def test_four_triangles_per_level_and_zero_levels_is_the_mesh():
    m = _grid()
    assert loop_subdivide(m, 0) is m
    for k in (1, 2):
        s = loop_subdivide(m, k)
        assert len(s.indices) == len(m.indices) * 4**k and np.isfinite(s.positions).all()
    with pytest.raises(ValueError, match="subdivide: expected 0 to 3 levels, got 4"):
        loop_subdivide(m, 4)


def test_flat_stays_flat_and_uvs_follow_positions():
    s = loop_subdivide(_grid(), 2)
    assert np.abs(s.positions[:, 2]).max() == 0.0
    assert np.allclose(s.normals, [0, 0, 1])
    # the boundary stays on the square's sides; UVs are linear within each parent triangle
    assert s.positions[:, :2].min() >= 0.0 and s.positions[:, :2].max() <= 1.0
    assert np.abs(s.uvs - s.positions[:, :2]).max() < 0.2  # moved, but near (Loop's even rule smooths)


def test_a_sphere_gets_smoother():
    sphere = sphere_mesh(1.0, 1)
    angles = [_max_dihedral(sphere)] + [_max_dihedral(loop_subdivide(sphere, k)) for k in (1, 2)]
    assert angles[0] > angles[1] > angles[2]
    assert angles[2] < angles[0] / 3


def test_split_vertices_do_not_crack():
    """A box's corners are split per face (UVs, normals): after subdivision every corner at one
    position has the same position and normal (no crack, no shading seam)."""
    box = box_mesh((1.0, 2.0, 3.0))
    assert len(box.positions) > len(np.unique(box.positions, axis=0))  # split vertices
    s = loop_subdivide(box, 2)
    p = s.positions.astype(np.float64)
    _, inv, counts = np.unique(np.round(p, 5), axis=0, return_inverse=True, return_counts=True)
    inv = inv.reshape(-1)
    split = counts[inv] > 1
    assert split.any()
    for g in np.unique(inv[split]):
        members = np.flatnonzero(inv == g)
        assert np.allclose(p[members], p[members[0]], atol=1e-6)
        assert np.allclose(s.normals[members], s.normals[members[0]], atol=1e-5)
    assert _max_dihedral(s) < _max_dihedral(box)  # the box's 90-degree edges rounded


def test_vertex_colours_per_corner():
    m = _grid(2)
    m = Mesh(m.name, m.positions, m.indices, uvs=m.uvs, colors=np.tile([1.0, 0.5, 0.25, 1.0], (len(m.positions), 1)))
    s = loop_subdivide(m, 1)
    assert s.colors is not None and np.allclose(s.colors, [1.0, 0.5, 0.25, 1.0])


def _scene(tmp_path, subdivide):
    from skinlab.resources import assets_root

    f = assets_root() / "meshes" / "slab-160x160x40.obj"
    p = tmp_path / "s.toml"
    p.write_text(f'[[meshes]]\nfile = "{f}"\nsubdivide = {subdivide}\n')
    return p


def test_scene_entry_subdivides_and_round_trips(tmp_path):
    from skinlab.scene.scene_save import scene_toml

    plain = load_scene(_scene(tmp_path, 0))
    smooth = load_scene(_scene(tmp_path, 1))
    n0 = sum(len(n.mesh.indices) for n in plain.mesh_nodes())
    n1 = sum(len(n.mesh.indices) for n in smooth.mesh_nodes())
    assert n1 == 4 * n0
    assert "subdivide = 1" in scene_toml(smooth)
    with pytest.raises(SceneFileError, match=r"\[\[meshes\]\]\[0\]\.subdivide|subdivide"):
        load_scene(_scene(tmp_path, 7))
