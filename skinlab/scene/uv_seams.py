"""Seam extensions: the surface across a UV seam, unfolded into each chart's gutter.

Texture-space diffusion blurs irradiance in UV space. Where the surface continues across a UV seam
(an edge whose two triangles sit in different places of the UV layout: two charts, or one chart that
wraps), the blur near the seam would read the empty (or dilated) gutter instead of the light on the
other side. ``seam_extension`` builds, once per mesh and band width, the geometry that fixes this:

- seam edges: 3D edges (positions welded exactly, as atlas generators split vertices: mesh_topology.weld) shared by two
  triangles whose UVs along the edge differ;
- for every seam edge, seen from each side (owner triangle A, source triangle B): the similarity
  transform of the UV plane (rotation, uniform scale, translation, and a reflection when the two charts
  have opposite orientations) that maps B's UV edge onto A's, chosen so B lands on the far side of the
  edge from A. It continues B's chart's parameterisation into A's frame, matching A exactly along the
  edge (a first-order continuation: the metric jumps where the two charts' scales differ);
- the triangles of B's chart within ``band_uv`` of the edge (past it, in A's frame), transformed:
  "extension triangles" with their 3D corners (the stretch pass measures them), their UVs in A's
  frame and their original UVs in B's chart (``src_uv``: where their irradiance is), and ``depth``,
  the distance past A's edge line (UV units), so that where bands of several edges (or of two
  charts packed close) overlap, the nearest edge's extension wins. Triangles are clipped to the far
  side of the edge line (depth >= 0, so it stays affine over each and the depth test is exact);
- every chart border edge's own strip of gutter (``border_bands``), which claims the gutter nearest
  that border wherever no extension is nearer (there the gutter keeps dilation, not another chart's
  continuation).

The GPU side (skinlab/render/techniques/tsd/seams.py) rasterises the extension triangles into a "seam map"
(RG = src_uv) under the real charts (real texels always win) and lets the blurs follow it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .mesh import Mesh
from .mesh_topology import welded_mesh

EDGE_EPS = 1e-12  # squared UV length under which an edge is degenerate (no transform through it)
FLAT_EPS = 1e-3  # a triangle whose UV height over the seam edge is below this x the edge is degenerate
REACH_3D = 2.0  # extension triangles lie within this x the band's width (in 3D, at the owner's scale) of the edge
# an extension triangle is kept where the owner's own UV-to-3D map, continued linearly past the edge,
# puts its corners within this fraction of their distance from the edge of where they are (curvature and
# a parameterisation that changes across the seam make it differ; folded or mismatched charts, a lot)
CONTINUATION_TOL = 0.5
# a seam across which the UV scale jumps by more than this factor is not continued (the metric of
# the two charts differs too much for a first-order continuation; and its band would span the chart)
SCALE_LIMIT = 8.0


@dataclass(frozen=True)
class SeamExtension:
    """Extension triangles of one mesh (see the module docstring). T extension triangles, S seam edges."""

    band_uv: float  # how far past each seam edge the extension reaches (UV units)
    seam_pairs: np.ndarray  # (S, 2) triangle indices on the two sides of each seam edge
    seam_pids: np.ndarray  # (S, 2) welded position ids of each seam edge's endpoints
    positions: np.ndarray  # (T, 3, 3) world corners (the source triangle's, unchanged)
    normals: np.ndarray  # (T, 3, 3)
    uv: np.ndarray  # (T, 3, 2) corners in the owner chart's UV frame
    src_uv: np.ndarray  # (T, 3, 2) corners' own UVs (in the source chart)
    depth: np.ndarray  # (T, 3) signed distance past the owner's seam edge line (UV units)
    owner: np.ndarray  # (T,) the owner triangle (A) whose seam edge made it
    source: np.ndarray  # (T,) the source triangle (in B's chart)
    chart: np.ndarray  # (F,) chart id of every triangle of the mesh (charts())
    border_uv: np.ndarray  # (K, 3, 2) every chart border's own strip of gutter (border_bands)
    border_depth: np.ndarray  # (K, 3) distance from the border edge (UV units)
    _mesh: list = field(default_factory=list, repr=False, compare=False, metadata={"transient": True})

    @property
    def triangles(self) -> int:
        return len(self.source)

    def mesh(self, name: str = "seams") -> Mesh:
        """The extension triangles as a Mesh (three vertices each; UVs in the owners' frames), made once."""
        if not self._mesh:
            n = self.triangles
            self._mesh.append(
                Mesh(
                    name,
                    self.positions.reshape(-1, 3),
                    np.arange(3 * n, dtype=np.uint32).reshape(-1, 3),
                    normals=self.normals.reshape(-1, 3),
                    uvs=self.uv.reshape(-1, 2),
                )
            )
        return self._mesh[0]


def _edge_table(f: np.ndarray, key: np.ndarray):
    """Per triangle edge (T*3): triangle, local edge k, sorted key pair."""
    t = np.repeat(np.arange(len(f)), 3)
    k = np.tile(np.arange(3), len(f))
    a, b = key[f[t, k]], key[f[t, (k + 1) % 3]]
    return t, k, np.minimum(a, b), np.maximum(a, b)


def charts(mesh: Mesh, pid: np.ndarray | None = None) -> np.ndarray:
    """Chart id per triangle: triangles connected through edges that agree in 3D and in UV."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    f = mesh.indices.astype(np.int64)
    pid = welded_mesh(mesh).ids if pid is None else pid
    key = np.concatenate([pid[:, None].astype(np.float64), mesh.uv_array("chart finding").astype(np.float64)], 1)
    _, uvid = np.unique(key, axis=0, return_inverse=True)
    t, _, lo, hi = _edge_table(f, uvid.ravel())
    order = np.lexsort((hi, lo))
    lo, hi, t = lo[order], hi[order], t[order]
    same = (lo[1:] == lo[:-1]) & (hi[1:] == hi[:-1])
    a, b = t[:-1][same], t[1:][same]
    g = coo_matrix((np.ones(len(a)), (a, b)), shape=(len(f), len(f)))
    return connected_components(g, directed=False)[1]


def border_edges(mesh: Mesh, pid: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(triangles, local edges k: corners k, k+1) of every chart border edge: an edge no other
    triangle shares in UV (a seam, or the mesh's own boundary)."""
    f = mesh.indices.astype(np.int64)
    pid = welded_mesh(mesh).ids if pid is None else pid
    key = np.concatenate([pid[:, None].astype(np.float64), mesh.uv_array("chart finding").astype(np.float64)], 1)
    _, uvid = np.unique(key, axis=0, return_inverse=True)
    t, k, lo, hi = _edge_table(f, uvid.ravel())
    _, inv, count = np.unique(np.stack([lo, hi], 1), axis=0, return_inverse=True, return_counts=True)
    single = count[inv.ravel()] == 1
    return t[single], k[single]


def _border_frames(mesh: Mesh, pid: np.ndarray | None = None):
    """Each chart border edge (degenerate ones left out) in UV: its ends a0, a1, its unit direction and
    its unit normal pointing away from its triangle, each (K, 2)."""
    f = mesh.indices.astype(np.int64)
    uv = mesh.uv_array("chart finding").astype(np.float64)
    t, k = border_edges(mesh, pid)
    a0, a1, a2 = uv[f[t, k]], uv[f[t, (k + 1) % 3]], uv[f[t, (k + 2) % 3]]
    e = a1 - a0
    ln = np.linalg.norm(e, axis=1)
    ok = ln > np.sqrt(EDGE_EPS)
    a0, a1, a2, e = a0[ok], a1[ok], a2[ok], e[ok] / ln[ok][:, None]
    nrm = np.stack([e[:, 1], -e[:, 0]], 1)
    nrm = np.where((np.einsum("ij,ij->i", a2 - a0, nrm) > 0)[:, None], -nrm, nrm)  # away from the triangle
    return a0, a1, e, nrm


def border_bands(mesh: Mesh, band_uv: float, pid: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Every chart border edge's own strip of gutter: a quad `band_uv` wide outside the edge, as two
    triangles (K, 3, 2) with their distance from the edge (K, 3). In the seam map they claim the
    gutter nearest a chart's border for that chart (dilation, no fill) wherever no extension is nearer:
    a border without an extension (or a chart too small to have one) keeps its own neighbourhood."""
    a0, a1, _, nrm = _border_frames(mesh, pid)
    b0, b1 = a0 + band_uv * nrm, a1 + band_uv * nrm
    quads = np.concatenate([np.stack([a0, a1, b1], 1), np.stack([a0, b1, b0], 1)])
    zero, one = np.zeros(len(a0)), np.full(len(a0), band_uv)
    depth = np.concatenate([np.stack([zero, zero, one], 1), np.stack([zero, one, one], 1)])
    return quads, depth


def border_strips(mesh: Mesh, out_uv: float, in_uv: float = 0.0, pid: np.ndarray | None = None) -> np.ndarray:
    """A thin rectangle around every chart border edge, as two triangles (K, 3, 2) in UV: from `in_uv`
    inside the edge to `out_uv` outside it, and `out_uv` past both ends. Together they cover every
    point within `out_uv` of a chart's border outside the chart (past a convex corner too: such a point
    lies in the rectangle of an edge it is outside of). With out_uv >= half a texel's diagonal they hold
    every gutter texel whose square overlaps a chart: the texels a nearest lookup inside the chart can
    read (texture-space diffusion's light-through record, skinlab/render/techniques/tsd/passes.py)."""
    a0, a1, e, nrm = _border_frames(mesh, pid)
    p0, p1 = a0 - out_uv * e, a1 + out_uv * e
    c = [p0 - in_uv * nrm, p1 - in_uv * nrm, p1 + out_uv * nrm, p0 + out_uv * nrm]
    return np.concatenate([np.stack([c[0], c[1], c[2]], 1), np.stack([c[0], c[2], c[3]], 1)])


def seam_edges(mesh: Mesh):
    """(pairs (S, 2) triangles, local edges (S, 2), endpoint position ids (S, 2), pid per vertex): every
    manifold 3D edge whose two triangles' UVs along it differ."""
    f = mesh.indices.astype(np.int64)
    pid = welded_mesh(mesh).ids
    t, k, lo, hi = _edge_table(f, pid)
    order = np.lexsort((hi, lo))
    t, k, lo, hi = t[order], k[order], lo[order], hi[order]
    n = len(lo)
    start = np.ones(n, bool)
    start[1:] = (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])
    gid = np.cumsum(start) - 1
    count = np.bincount(gid)
    first = np.flatnonzero(start)
    two = first[count == 2]  # manifold edges: exactly two triangles
    ta, tb, ka, kb = t[two], t[two + 1], k[two], k[two + 1]
    uv = mesh.uv_array("seam finding").astype(np.float64)

    def corner_uv(tt, kk, p):
        v0, v1 = f[tt, kk], f[tt, (kk + 1) % 3]
        return np.where((pid[v0] == p)[:, None], uv[v0], uv[v1])

    p, q = lo[two], hi[two]
    d = np.maximum(
        np.abs(corner_uv(ta, ka, p) - corner_uv(tb, kb, p)).max(1),
        np.abs(corner_uv(ta, ka, q) - corner_uv(tb, kb, q)).max(1),
    )
    seam = (d > 0) & (ta != tb)
    return (
        np.stack([ta[seam], tb[seam]], 1),
        np.stack([ka[seam], kb[seam]], 1),
        np.stack([p[seam], q[seam]], 1),
        pid,
    )


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def seam_transform(a0, a1, a2, b0, b1, b2):
    """The similarity z -> M z + c of the UV plane with M (2, 2) mapping b0 -> a0 and b1 -> a1 and
    putting b2 on the other side of the edge than a2 (a reflection where needed); None if degenerate."""
    ea, eb = a1 - a0, b1 - b0
    if ea @ ea < EDGE_EPS or eb @ eb < EDGE_EPS:
        return None
    if abs(_cross(ea, a2 - a0)) < FLAT_EPS * (ea @ ea) or abs(_cross(eb, b2 - b0)) < FLAT_EPS * (eb @ eb):
        return None  # a sliver in UV: which side is "across" is not defined
    za, zb = complex(*ea), complex(*eb)
    side_a = _cross(ea, a2 - a0)
    for mirror in (False, True):
        s = za / (zb.conjugate() if mirror else zb)
        rot = np.array([[s.real, -s.imag], [s.imag, s.real]])
        m = rot @ np.diag([1.0, -1.0]) if mirror else rot
        c = a0 - m @ b0
        if _cross(ea, m @ b2 + c - a0) * side_a < 0:
            return m, c
    return None


def clip_triangles(attrs: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Clip triangles to d >= 0, d affine over each: attrs (n, 3, k) corner attributes (the last one d
    itself), d (n, 3); returns (m, 3, k), every corner's attributes interpolated along the cut edges
    (exact for attributes affine over the triangle). A triangle with one corner below 0 becomes two."""
    neg = d < 0
    count = neg.sum(1)
    out = [attrs[count == 0]]

    def cut(a, da, b, db):  # the point on a-b where d = 0
        t = (da / (da - db))[:, None]
        return a + (b - a) * t

    for n_neg in (1, 2):
        sel = count == n_neg
        if not sel.any():
            continue
        a, dd, ng = attrs[sel], d[sel], neg[sel]
        # rotate the corners so the odd one out (the single negative, or the single positive) is first
        odd = np.argmax(ng if n_neg == 1 else ~ng, axis=1)
        idx = (odd[:, None] + np.arange(3)[None, :]) % 3
        a = np.take_along_axis(a, idx[:, :, None], 1)
        dd = np.take_along_axis(dd, idx, 1)
        p01 = cut(a[:, 0], dd[:, 0], a[:, 1], dd[:, 1])
        p02 = cut(a[:, 0], dd[:, 0], a[:, 2], dd[:, 2])
        if n_neg == 1:  # corners 1, 2 kept: the quad p01, 1, 2, p02
            out.append(np.stack([p01, a[:, 1], a[:, 2]], 1))
            out.append(np.stack([p01, a[:, 2], p02], 1))
        else:  # only corner 0 kept
            out.append(np.stack([a[:, 0], p01, p02], 1))
    return np.concatenate(out)


class _Seam(NamedTuple):
    """One side of a seam edge: owner triangle A, source triangle B, B's UVs mapped into A's frame."""

    owner: int  # A
    source: int  # B
    m: np.ndarray  # (2, 2) the similarity's linear part (seam_transform)
    c: np.ndarray  # (2,) its translation
    a0: np.ndarray  # the edge's first corner in A's UVs
    t_hat: np.ndarray  # unit UV direction along A's edge
    n_hat: np.ndarray  # unit UV normal of A's edge, away from A (positive depth)
    length: float  # the edge's UV length in A's frame
    centre: np.ndarray  # the edge's midpoint in B's UVs (where its source triangles are looked for)
    radius: float  # the UV query radius around it
    reach3: float  # how far (3D) from the edge's midpoint a source triangle may lie
    mid3: np.ndarray  # the edge's 3D midpoint
    jac: np.ndarray  # (3, 2) A's UV-to-3D map (continued linearly past the edge)
    p0: np.ndarray  # the edge's first corner in 3D
    length3: float  # the edge's 3D length


def _directed_seam(f, uv, pos, pid, own, src, p, band_uv: float, reach: float) -> _Seam | None:
    """The seam edge seen from `own` = (A, A's local edge) with source `src` = (B, B's local edge), `p`
    the welded position id of the edge's first endpoint; None where it is not continued (a degenerate
    transform, or a UV scale jump beyond SCALE_LIMIT). `reach`: the largest triangle's UV radius."""
    (A, kA), (B, kB) = own, src
    va, vb = f[A, [kA, (kA + 1) % 3]], f[B, [kB, (kB + 1) % 3]]
    if pid[va[0]] != p:
        va = va[::-1]
    if pid[vb[0]] != p:
        vb = vb[::-1]
    a0, a1, a2 = uv[va[0]], uv[va[1]], uv[f[A, (kA + 2) % 3]]
    b0, b1, b2 = uv[vb[0]], uv[vb[1]], uv[f[B, (kB + 2) % 3]]
    tr = seam_transform(a0, a1, a2, b0, b1, b2)
    if tr is None:
        return None
    m, c = tr
    d_uv = np.stack([uv[f[A, 1]] - uv[f[A, 0]], uv[f[A, 2]] - uv[f[A, 0]]], 1)
    jac = np.stack([pos[f[A, 1]] - pos[f[A, 0]], pos[f[A, 2]] - pos[f[A, 0]]], 1) @ np.linalg.inv(d_uv)
    scale = float(np.sqrt(abs(np.linalg.det(m))))
    if not 1.0 / SCALE_LIMIT <= scale <= SCALE_LIMIT:
        return None
    la = float(np.linalg.norm(a1 - a0))
    t_hat = (a1 - a0) / la
    n_hat = np.array([t_hat[1], -t_hat[0]])
    if (a2 - a0) @ n_hat > 0:
        n_hat = -n_hat  # positive depth: away from A
    radius = np.hypot(0.5 * la, band_uv) / scale + reach
    e3 = pos[va[1]] - pos[va[0]]
    reach3 = REACH_3D * np.hypot(0.5 * np.linalg.norm(e3), band_uv * np.linalg.norm(e3) / la)
    return _Seam(
        A, B, m, c, a0, t_hat, n_hat, la, 0.5 * (b0 + b1), radius, reach3,
        0.5 * (pos[va[0]] + pos[va[1]]), jac, pos[va[0]], float(np.linalg.norm(e3)),
    )  # fmt: skip


def directed_seams(mesh: Mesh, band_uv: float, edges=None) -> list[_Seam]:
    """Both sides of every seam edge (`edges`: seam_edges(mesh), found here where not given) that is
    continued: owner A, source B and the transform of B's UVs into A's frame, in seam-edge order."""
    f = mesh.indices.astype(np.int64)
    uv = mesh.uv_array("seam extensions").astype(np.float64)
    pos = mesh.positions.astype(np.float64)
    pairs, local, pids, pid = edges if edges is not None else seam_edges(mesh)
    tri_uv = uv[f]  # (T, 3, 2)
    reach = np.sqrt(((tri_uv - tri_uv.mean(1)[:, None]) ** 2).sum(-1)).max() if len(f) else 0.0
    seams = []
    for (ta, tb), (ka, kb), (p, _q) in zip(pairs, local, pids):
        for own, src in (((ta, ka), (tb, kb)), ((tb, kb), (ta, ka))):
            s = _directed_seam(f, uv, pos, pid, own, src, p, band_uv, reach)
            if s is not None:
                seams.append(s)
    return seams


def _stacked(seams: list[_Seam], name: str) -> np.ndarray:
    """One field of every seam as an array (seam order)."""
    return np.array([getattr(s, name) for s in seams])


def _source_triangles(mesh: Mesh, seams: list[_Seam], chart: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(seam index, triangle) pairs: the triangles of each seam's source chart within its UV query
    radius and near the edge in 3D too (a UV layout that overlaps itself, or a chart folded in UV,
    puts far surface near in UV)."""
    from scipy.spatial import cKDTree

    f = mesh.indices.astype(np.int64)
    pos = mesh.positions.astype(np.float64)
    cen = mesh.uv_array("seam extensions").astype(np.float64)[f].mean(1)
    size3 = np.sqrt(((pos[f] - pos[f].mean(1)[:, None]) ** 2).sum(-1)).max(1)  # 3D radius per triangle
    hits = cKDTree(cen).query_ball_point(_stacked(seams, "centre"), _stacked(seams, "radius"))
    sid = np.repeat(np.arange(len(seams)), [len(h) for h in hits])
    cand = np.concatenate([np.asarray(h, np.int64) for h in hits]) if len(sid) else np.zeros(0, np.int64)
    d3 = np.linalg.norm(pos[f[cand]].mean(1) - _stacked(seams, "mid3")[sid], axis=1) - size3[cand]
    same = (chart[cand] == chart[_stacked(seams, "source")[sid]]) & (d3 < _stacked(seams, "reach3")[sid])
    return sid[same], cand[same]


def _in_owner_frame(seams: list[_Seam], sid: np.ndarray, corners_uv: np.ndarray):
    """Source triangles' corners (n, 3, 2) in their seam's owner frame: (the UVs there, their offset from
    the edge's first corner, the depth past the edge line, the position along the edge), each (n, 3[, 2])."""
    w = np.einsum("nij,nkj->nki", _stacked(seams, "m")[sid], corners_uv) + _stacked(seams, "c")[sid][:, None, :]
    rel = w - _stacked(seams, "a0")[sid][:, None, :]
    dist = np.einsum("nkj,nj->nk", rel, _stacked(seams, "n_hat")[sid])
    along = np.einsum("nkj,nj->nk", rel, _stacked(seams, "t_hat")[sid])
    return w, rel, dist, along


def _continues(seams: list[_Seam], sid: np.ndarray, rel: np.ndarray, corners3: np.ndarray) -> np.ndarray:
    """Whether the owner's UV-to-3D map, continued linearly past the edge, puts each source triangle's
    corners (`rel`: their offsets in the owner's frame) within CONTINUATION_TOL of their distance from
    the edge of where they are (`corners3`)."""
    mid3 = _stacked(seams, "mid3")[sid][:, None, :]
    pred = _stacked(seams, "p0")[sid][:, None, :] + np.einsum("nij,nkj->nki", _stacked(seams, "jac")[sid], rel)
    err = np.linalg.norm(pred - corners3, axis=2).max(1)
    far = np.maximum(np.linalg.norm(pred - mid3, axis=2).max(1), _stacked(seams, "length3")[sid])
    return err <= CONTINUATION_TOL * far


def _extension_corners(mesh: Mesh, seams: list[_Seam], chart: np.ndarray, band_uv: float) -> np.ndarray:
    """The extension triangles' corner attributes (n, 3, 13): position, normal, UV in the owner's frame,
    own UV, source triangle, owner, depth; clipped to depth >= 0 (past the edge: affine there)."""
    f = mesh.indices.astype(np.int64)
    tri_uv = mesh.uv_array("seam extensions").astype(np.float64)[f]
    sid, cand = _source_triangles(mesh, seams, chart)
    w, rel, dist, along = _in_owner_frame(seams, sid, tri_uv[cand])
    length = _stacked(seams, "length")[sid]
    keep = (dist.max(1) > 0) & (dist.min(1) < band_uv) & (along.max(1) > 0) & (along.min(1) < length)
    keep &= _continues(seams, sid, rel, mesh.positions.astype(np.float64)[f[cand]])
    sid, cand, w, dist = sid[keep], cand[keep], w[keep], dist[keep]
    n = len(cand)
    at = np.concatenate(
        [
            mesh.positions[f[cand]].astype(np.float64),
            mesh.normals[f[cand]].astype(np.float64),
            w,
            tri_uv[cand],
            np.broadcast_to(cand[:, None, None], (n, 3, 1)).astype(np.float64),
            np.broadcast_to(_stacked(seams, "owner")[sid][:, None, None], (n, 3, 1)).astype(np.float64),
            dist[:, :, None],
        ],
        2,
    )
    return clip_triangles(at, dist)


def seam_extension(mesh: Mesh, band_uv: float) -> SeamExtension:
    """Extension triangles reaching ``band_uv`` (UV units) past every seam edge of ``mesh``, on both
    sides; see the module docstring."""
    if mesh.uvs is None:
        raise ValueError(f"mesh {mesh.name!r}: seam extensions need UVs")
    if not band_uv > 0:
        raise ValueError(f"band_uv: expected > 0, got {band_uv}")
    edges = seam_edges(mesh)
    pairs, _local, pids, pid = edges
    chart = charts(mesh, pid)
    border = border_bands(mesh, band_uv, pid)
    seams = directed_seams(mesh, band_uv, edges)
    at = _extension_corners(mesh, seams, chart, band_uv) if seams else np.zeros((0, 3, 13))
    return SeamExtension(
        band_uv=float(band_uv),
        seam_pairs=pairs,
        seam_pids=pids,
        positions=at[:, :, 0:3].astype(np.float32),
        normals=at[:, :, 3:6].astype(np.float32),
        uv=at[:, :, 6:8].astype(np.float32),
        src_uv=at[:, :, 8:10].astype(np.float32),
        depth=np.maximum(at[:, :, -1], 0.0).astype(np.float32),
        owner=np.rint(at[:, 0, 11]).astype(np.int64),
        source=np.rint(at[:, 0, 10]).astype(np.int64),
        chart=chart,
        border_uv=border[0].astype(np.float32),
        border_depth=border[1].astype(np.float32),
    )
