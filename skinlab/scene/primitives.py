"""Simple meshes made in code: a box with one UV chart per face (the reference slabs), an icosphere."""

from __future__ import annotations

import numpy as np

from .mesh import Mesh

# face: (normal axis, sign, u axis, v axis) so that u x v = the outward normal
_FACES = ((2, 1, 0, 1), (2, -1, 1, 0), (0, 1, 1, 2), (0, -1, 2, 1), (1, 1, 2, 0), (1, -1, 0, 2))


def box_mesh(size, name: str = "box") -> Mesh:
    """An axis-aligned box centred on the origin, `size` = (x, y, z) extents. Each face has its own
    four vertices (sharp normals) and its own UV chart in a 3 x 2 grid of cells with a margin of
    1/16 cell, the face scaled uniformly into its cell (the top face, +z, in the first cell)."""
    size = np.asarray(size, np.float64).reshape(3)
    if not (np.isfinite(size).all() and (size > 0).all()):
        raise ValueError(f"box size: expected three positive extents, got {size.tolist()}")
    half = size / 2
    pos, nrm, uv, tri = [], [], [], []
    for k, (axis, sign, ua, va) in enumerate(_FACES):
        n = np.zeros(3)
        n[axis] = sign
        corners = []
        for cu, cv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            p = n * half
            p[ua] = cu * half[ua]
            p[va] = cv * half[va]
            corners.append(p)
        quad = np.array(corners)
        if np.dot(np.cross(quad[1] - quad[0], quad[2] - quad[0]), n) < 0:
            quad = quad[[0, 3, 2, 1]]
        # UVs from the face's own axes, uniform scale into the cell
        e = np.array([size[ua], size[va]])
        local = np.stack([quad[:, ua], quad[:, va]], axis=1) / e.max() + 0.5 * e / e.max()
        cell = np.array([k % 3, k // 3], np.float64)
        m = 1.0 / 16
        uvk = (cell + m + local * (1 - 2 * m)) / np.array([3.0, 2.0])
        base = 4 * k
        pos.append(quad)
        nrm.append(np.tile(n, (4, 1)))
        uv.append(uvk)
        tri += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    return Mesh(
        name,
        np.concatenate(pos).astype(np.float32),
        np.array(tri, np.uint32),
        normals=np.concatenate(nrm).astype(np.float32),
        uvs=np.concatenate(uv).astype(np.float32),
        source="box_mesh",
    )


def write_obj(mesh: Mesh, path) -> None:
    """Wavefront OBJ with positions, UVs and normals per vertex (one index for all three)."""
    lines = [f"# {mesh.name}: written by skinlab.scene.primitives.write_obj", f"o {mesh.name}"]
    lines += [f"v {x:.6g} {y:.6g} {z:.6g}" for x, y, z in mesh.positions]
    lines += [f"vt {u:.6g} {v:.6g}" for u, v in mesh.uv_array("an OBJ file")]
    lines += [f"vn {x:.6g} {y:.6g} {z:.6g}" for x, y, z in mesh.normals]
    lines += ["f " + " ".join(f"{i + 1}/{i + 1}/{i + 1}" for i in t) for t in mesh.indices]
    from pathlib import Path

    Path(path).write_text("\n".join(lines) + "\n")


def sphere_mesh(radius: float = 1.0, subdivisions: int = 3, name: str = "sphere") -> Mesh:
    """An icosphere centred on the origin (smooth normals, a latitude-longitude UV per vertex, so the
    charts meet along one seam of split vertices' neighbours: enough for tests, not for textures)."""
    import trimesh

    if not (np.isfinite(radius) and radius > 0):
        raise ValueError(f"sphere radius: expected a positive number, got {radius}")
    ico = trimesh.creation.icosphere(subdivisions=int(subdivisions), radius=float(radius))
    p = np.asarray(ico.vertices, np.float64)
    n = p / np.linalg.norm(p, axis=1, keepdims=True)
    uv = np.stack(
        [np.arctan2(n[:, 0], -n[:, 2]) / (2 * np.pi) + 0.5, 1.0 - np.arccos(np.clip(n[:, 1], -1, 1)) / np.pi], 1
    )
    return Mesh(
        name,
        p.astype(np.float32),
        np.asarray(ico.faces, np.uint32),
        normals=n.astype(np.float32),
        uvs=uv.astype(np.float32),
        source="sphere_mesh",
    )
