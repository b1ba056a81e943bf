"""Loop subdivision of a triangle mesh: the surface smoothed, each triangle split in four per level.

A coarse scan's facets are invisible under smooth shading normals in the frame, but an index-matched
path-traced truth has no shading normals: light enters each flat facet at that facet's cosine, so a
grazing light draws the facets into the truth (the nose close-up at 2.5 mm triangles, 0.27 mm pixels:
docs/ground-truth.md "Facets in the truth"). A scene entry's ``subdivide = N`` gives the frame and the
truth the same smoother surface.

Loop 1987 ("Smooth Subdivision Surfaces Based on Triangles", M.S. thesis, University of Utah) with
Warren's weights for the even vertices (beta = 3 / (8 n) for valence n > 3, 3 / 16 for n = 3) and the
usual boundary rules (odd: the edge's midpoint; even: 3/4 the vertex + 1/8 each boundary neighbour),
as in pbrt-v3's loopsubdiv.cpp. Positions are subdivided on the mesh welded by position, so vertices
split for UV seams move together (no cracks); UVs and vertex colours are per corner, linear within
each parent triangle (a seam stays a seam). Normals are the area-weighted normals of the welded
result, shared across seams; tangents are made again from the UVs when needed.
"""

from __future__ import annotations

import numpy as np

from .mesh import Mesh, vertex_normals

MAX_LEVELS = 3  # 64 triangles per original one


def _edges(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each face's three edges (a-b, b-c, c-a) as indices into the unique undirected edges, and those
    edges (E, 2) with the smaller index first."""
    e = np.stack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]], 1).reshape(-1, 2)
    e = np.sort(e, axis=1)
    uniq, inv = np.unique(e, axis=0, return_inverse=True)
    return inv.reshape(-1, 3), uniq


def _subdivide_once(mesh: Mesh) -> Mesh:
    pos = mesh.positions.astype(np.float64)
    faces = mesh.indices.astype(np.int64)
    welded, weld = np.unique(pos, axis=0, return_inverse=True)
    weld = weld.reshape(-1)
    wf = weld[faces]  # faces over welded vertices
    nw = len(welded)
    face_edges, edges = _edges(wf)
    count = np.bincount(face_edges.ravel(), minlength=len(edges))
    # the vertex opposite each face edge: c for a-b, a for b-c, b for c-a
    opposite = wf[:, [2, 0, 1]].ravel()
    opp_sum = np.zeros((len(edges), 3))
    np.add.at(opp_sum, face_edges.ravel(), welded[opposite])
    a, b = welded[edges[:, 0]], welded[edges[:, 1]]
    interior = (count == 2)[:, None]
    odd = np.where(interior, 3.0 / 8.0 * (a + b) + 1.0 / 8.0 * opp_sum, 0.5 * (a + b))
    # even vertices: the neighbours over every edge, and over the boundary edges apart
    boundary = count == 1
    valence = np.bincount(edges.ravel(), minlength=nw).astype(np.float64)
    ring = np.zeros((nw, 3))
    np.add.at(ring, edges[:, 0], welded[edges[:, 1]])
    np.add.at(ring, edges[:, 1], welded[edges[:, 0]])
    b_count = np.bincount(edges[boundary].ravel(), minlength=nw)
    b_ring = np.zeros((nw, 3))
    np.add.at(b_ring, edges[boundary, 0], welded[edges[boundary, 1]])
    np.add.at(b_ring, edges[boundary, 1], welded[edges[boundary, 0]])
    n = np.maximum(valence, 1.0)
    beta = np.where(valence == 3, 3.0 / 16.0, 3.0 / (8.0 * n))
    even = (1.0 - n * beta)[:, None] * welded + beta[:, None] * ring
    on_boundary = b_count > 0
    # a boundary vertex with two boundary neighbours: 3/4 + 1/8 + 1/8; a non-manifold one stays put
    even = np.where(on_boundary[:, None], welded, even)
    two = b_count == 2
    even[two] = 0.75 * welded[two] + 0.125 * b_ring[two]
    even[valence == 0] = welded[valence == 0]
    # the new mesh, per corner: the original (unwelded) vertices, then one vertex per unwelded edge,
    # whose position is its welded edge's odd vertex and whose attributes the mean of its two ends
    nv = len(pos)
    uf_edges, u_edges = _edges(faces)
    # the welded edge of each unwelded edge (any face using it says which)
    welded_of = np.empty(len(u_edges), np.int64)
    welded_of[uf_edges.ravel()] = face_edges.ravel()
    new_pos = np.concatenate([even[weld], odd[welded_of]])

    def attribute(x):
        if x is None:
            return None
        x = np.asarray(x, np.float64)
        return np.concatenate([x, 0.5 * (x[u_edges[:, 0]] + x[u_edges[:, 1]])])

    e_ab, e_bc, e_ca = (nv + uf_edges[:, k] for k in range(3))
    va, vb, vc = faces[:, 0], faces[:, 1], faces[:, 2]
    new_faces = np.concatenate(
        [np.stack(f, 1) for f in ((va, e_ab, e_ca), (e_ab, vb, e_bc), (e_ca, e_bc, vc), (e_ab, e_bc, e_ca))]
    )
    # normals over the welded result: one per position, shared by the corners a seam split
    new_weld = np.concatenate([weld, nw + welded_of])
    welded_normals = vertex_normals(
        np.concatenate([even, odd]).astype(np.float32), new_weld[new_faces].astype(np.uint32)
    )
    return Mesh(
        mesh.name,
        new_pos.astype(np.float32),
        new_faces.astype(np.uint32),
        normals=welded_normals[new_weld],
        uvs=attribute(mesh.uvs),
        source=mesh.source,
        notes=mesh.notes,
        colors=attribute(mesh.colors),
    )


def loop_subdivide(mesh: Mesh, levels: int) -> Mesh:
    """`mesh` Loop-subdivided `levels` times (0: the mesh itself); at most MAX_LEVELS."""
    levels = int(levels)
    if not 0 <= levels <= MAX_LEVELS:
        raise ValueError(f"subdivide: expected 0 to {MAX_LEVELS} levels, got {levels}")
    for _ in range(levels):
        mesh = _subdivide_once(mesh)
    return mesh
