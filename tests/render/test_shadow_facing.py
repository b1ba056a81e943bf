"""The distance-map layers drawn from the triangles that can face their way (skinlab/render/shadow_facing.py):
no triangle a layer keeps a fragment of is left out, about half are, and the maps are the same texels."""

from __future__ import annotations

import numpy as np

import skinlab.render.passes.shadow as shadow_pass
from skinlab.render.passes.shadow import ShadowPass
from skinlab.render.settings import RenderSettings
from skinlab.render.shadow_facing import AWAY, TOWARD, layer_triangles
from skinlab.render.translucency import part_layer_size
from skinlab.scene.graph import MeshNode
from skinlab.scene.materials import Material
from skinlab.scene.primitives import sphere_mesh


def test_no_triangle_with_a_fragment_facing_the_layers_way_is_left_out():
    node = MeshNode("ball", sphere_mesh(1.0, 3), Material())
    node.scale = (1.0, 2.5, 0.6)  # a non-uniform scale: the normals go through the normal matrix
    travel = np.array([0.3, -0.8, -0.52])
    travel /= np.linalg.norm(travel)
    mesh = node.mesh
    faces = mesh.indices.reshape(-1, 3).astype(np.int64)
    normal_matrix = np.linalg.inv(np.asarray(node.world_matrix)[:3, :3]).T
    n = mesh.normals.astype(np.float64) @ normal_matrix.T
    # the interpolated normal's cosine at random points of every triangle (and its corners)
    rng = np.random.default_rng(1)
    b = rng.dirichlet((1.0, 1.0, 1.0), 64)
    b = np.concatenate([b, np.eye(3)])
    interp = np.einsum("sk,fkc->fsc", b, n[faces])
    c = interp @ travel
    for facing, has in ((AWAY, (c > 0).any(1)), (TOWARD, (c <= 0).any(1))):
        kept = layer_triangles(node, travel, facing)
        assert kept is not None
        kept_faces = {tuple(f) for f in kept.reshape(-1, 3).tolist()}
        needed = {tuple(f) for f in faces[has].tolist()}
        assert needed <= kept_faces, facing  # nothing the layer keeps a fragment of is dropped
        assert 0.4 < len(kept_faces) / len(faces) < 0.65, (facing, len(kept_faces) / len(faces))
    # a mesh without normals: every triangle
    bare = MeshNode("bare", sphere_mesh(1.0, 1), Material())
    bare.mesh.normals = np.zeros((0, 3), np.float32)
    assert layer_triangles(bare, travel, AWAY) is None


def distance_layers(renderer, scene) -> dict[str, np.ndarray]:
    renderer.reuse = False
    renderer.render(scene, RenderSettings(64, 64, shadow_size=512), readback=False)
    sp = next(p for p in renderer.passes.values() if isinstance(p, ShadowPass))
    out = {}
    for slot, shadow_map in sp.maps.items():
        if shadow_map.distance is not None:
            out[f"distance{slot}"] = np.frombuffer(shadow_map.distance.read(), np.float32).copy()
            out[f"exit{slot}"] = np.frombuffer(sp.layers[slot].exit.read(), np.float32).copy()
            out[f"entry{slot}"] = np.frombuffer(sp.layers[slot].entry.read(), np.float32).copy()
            n = part_layer_size(512)  # the part layers' own size, half the shadow map's
            assert n == 256 and sp.layers[slot][0].size == sp.layers[slot][2].size == (n, n)
    return out


def test_the_layers_are_the_same_texels_as_from_every_triangle(renderer, monkeypatch):
    from skinlab.scene.scenefile import load_scene

    scene = load_scene("head")
    subset = distance_layers(renderer, scene)
    assert subset and all(np.isfinite(v).all() for v in subset.values())
    assert (subset["exit0"][0::2] < 1e29).mean() > 0.05  # the exit layer holds surfaces
    monkeypatch.setattr(shadow_pass, "layer_triangles", lambda *a: None)  # every triangle drawn
    every = distance_layers(renderer, scene)
    for k in subset:
        assert np.array_equal(subset[k], every[k]), k
