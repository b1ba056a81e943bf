"""Which triangles a distance-map layer can use (skinlab/shaders/passes/shadow.frag SHADOW_LAYER).

The layers of a shadow slot's distance map keep only the surfaces facing one way: the exit layer
those facing away from the light (the fragment's interpolated normal n with n . t > 0, t the
direction the light travels), the next-entry layer those facing it (n . t <= 0); the shader discards
the rest per fragment. Under a directional light t is one vector, so the sign of n . t at any point
of a triangle is that of a convex combination of its vertex normals' dot products: a triangle whose
three vertex normals all face the other way has no fragment the layer keeps. Drawing only the
other triangles writes the same texels (the discarded fragments never wrote colour or depth) and
rasterises about half as many fragments (on llvmpipe, 2048 x 2048 head layers: 33 + 46 ms -> see
docs/tsd.md, "The full frame against the plain one").

The selection is conservative: a triangle is dropped only when every vertex's dot product is beyond
a margin on the other side, so the GPU's float32 normals (its own rounding of the normal matrix)
can never disagree with it. Local lights (t varies across a triangle) draw every triangle.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from skinlab.scene.graph import MeshNode

# a vertex counts as facing one way only when its unit normal's cosine to the light's direction is
# beyond this on that side (float32 rounding of the GPU's normals is about 1e-7)
FACING_MARGIN = 1e-4

AWAY = "away"  # the exit layer: triangles some of whose fragments face away from the light
TOWARD = "toward"  # the next-entry layer: triangles some of whose fragments face the light


def layer_triangles(node: MeshNode, travel: np.ndarray, facing: str) -> np.ndarray | None:
    """The indices of the triangles of `node` a layer drawing surfaces `facing` (AWAY / TOWARD) the
    light can use, as a flat uint32 index array; None where every triangle must be drawn (the mesh
    has no normals to judge by). `travel`: the direction the directional light travels (world)."""
    mesh = node.mesh
    normals = getattr(mesh, "normals", None)
    if normals is None or len(normals) != len(mesh.positions) or len(mesh.indices) == 0:
        return None
    model = np.asarray(node.world_matrix, np.float64)
    normal_matrix = np.linalg.inv(model[:3, :3]).T
    world = np.asarray(normals, np.float64) @ normal_matrix.T
    length = np.linalg.norm(world, axis=1)
    t = np.asarray(travel, np.float64)
    t = t / max(float(np.linalg.norm(t)), 1e-300)
    cos = np.where(length > 0, (world @ t) / np.maximum(length, 1e-300), 0.0)
    faces = np.asarray(mesh.indices, np.int64).reshape(-1, 3)
    c = cos[faces]
    keep = (c > -FACING_MARGIN).any(axis=1) if facing == AWAY else (c < FACING_MARGIN).any(axis=1)
    # a vertex without a normal (length 0): its fragments' normal is the others' only; kept (cos 0)
    return faces[keep].astype(np.uint32).ravel()
