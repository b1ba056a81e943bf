"""Whether a mesh has a part thinner than a given distance: a vertex whose ray, straight in along
its normal, leaves the mesh within that distance through a triangle facing away from it (the far
side). Texture-space translucency (skinlab/shaders/techniques/tsd/irradiance.frag) measures the same kind of
thickness - the slab between a surface facing the light and the point - so a material whose light
dies out within a distance cannot shine through a mesh with no part that thin
(skinlab/render/techniques/tsd/plan.py).

The translucency's thickness runs from the first surface the light meets, of any mesh; for a closed
mesh that surface lies no nearer than where the light entered the mesh itself, so the mesh's own
thickness bounds it. An open mesh (a scan with a hole, a single sheet in front of another) bounds
nothing: it counts as thin at any limit (is_closed). Exact for the vertices' rays
(Moeller & Trumbore 1997 ray-triangle test); between vertices a curved surface can be thinner, which
the skip's image test bounds (tests/render/techniques/test_tsd_translucency_skip.py).
"""

from __future__ import annotations

import numpy as np

from skinlab.cache import content_key, stored

from .mesh import mesh_key
from .mesh_topology import edge_report

_CACHE: dict = {}
_SEED_RAYS = 256  # vertices tested against every triangle first (a thin part is usually found here)
_PAIRS = 1_000_000  # (ray, triangle) pairs per batch


class _Rays:
    def __init__(self, mesh):
        pos = np.asarray(mesh.positions, np.float64)
        tri = np.asarray(mesh.indices, np.int64)
        nrm = np.asarray(mesh.normals, np.float64)
        length = np.linalg.norm(nrm, axis=1)
        use = np.flatnonzero(length > 0)
        self.dirs = -nrm[use] / length[use, None]  # inward
        self.orig = pos[use]
        self.v0 = pos[tri[:, 0]]
        self.e1 = pos[tri[:, 1]] - self.v0
        self.e2 = pos[tri[:, 2]] - self.v0
        self.n_face = np.cross(self.e1, self.e2)
        extent = float(np.linalg.norm(pos.max(0) - pos.min(0))) or 1.0
        self.t_min = 1e-6 * extent  # a ray starting on a triangle does not leave through it
        self.centre = self.v0 + (self.e1 + self.e2) / 3.0
        corners = (self.v0, self.v0 + self.e1, self.v0 + self.e2)
        self.radius = np.sqrt(np.max([((x - self.centre) ** 2).sum(1) for x in corners], axis=0))

    def nearest_hit(self, pr: np.ndarray, pt: np.ndarray, limit: float) -> float:
        """The shortest distance in (t_min, limit] at which some ray pr[k] leaves through triangle
        pt[k]; inf when none does."""
        d, nf = self.dirs[pr], self.n_face[pt]
        dn = np.einsum("ij,ij->i", nf, d)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.einsum("ij,ij->i", self.v0[pt] - self.orig[pr], nf) / dn
        keep = np.flatnonzero((dn > 0) & (t > self.t_min) & (t <= limit))  # exit side, within reach
        if len(keep) == 0:
            return np.inf
        pr, pt, d, t = pr[keep], pt[keep], d[keep], t[keep]
        x = self.orig[pr] + t[:, None] * d - self.v0[pt]  # the hit on the triangle's plane
        e1, e2 = self.e1[pt], self.e2[pt]
        a, b, c = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
        p, q = (x * e1).sum(1), (x * e2).sum(1)
        det = a * c - b * b
        with np.errstate(divide="ignore", invalid="ignore"):
            u, v = (c * p - b * q) / det, (a * q - b * p) / det
        eps = 1e-9
        inside = (det > 0) & (u >= -eps) & (v >= -eps) & (u + v <= 1 + eps)
        return float(t[inside].min()) if inside.any() else np.inf


def is_closed(mesh) -> bool:
    """Whether the mesh, its vertices welded by position (skinlab/scene/mesh_topology.py, one answer
    with the truth's and the warnings'), is closed: every edge shared by exactly two triangles."""
    return edge_report(mesh).closed  # kept per mesh identity and version


def thinner_than(mesh, limit: float) -> bool:
    """Whether some part of the mesh is thinner than `limit` (mesh units; see the module docstring);
    always for an open mesh. What a search finds is kept per mesh identity and version: the thinnest
    part seen so far and the largest limit known to have no part thinner, so that a new limit
    between them (a material being edited) is answered without a new search in most cases."""
    if not is_closed(mesh):
        return True
    if not limit > 0:
        return False
    key = ("thickness", mesh.uid, mesh.version)
    known = _CACHE.get(key)
    if known is None:
        if len(_CACHE) > 256:
            _CACHE.clear()
        known = _CACHE[key] = {"thin": np.inf, "thick": 0.0}
    if limit >= known["thin"]:
        return True
    if limit <= known["thick"]:
        return False
    found = stored(  # on disk too: a search takes 0.1-0.2 s on the head
        "thickness",
        content_key(mesh_key(mesh), float(limit)),
        lambda: _nearest_within(_Rays(mesh), float(limit)),
        f"the thickness of mesh {mesh.name!r}",
        code=__name__,
    )
    if found <= limit:
        known["thin"] = min(known["thin"], found)
        return True
    known["thick"] = max(known["thick"], float(limit))
    return False


def _nearest_within(r: _Rays, limit: float) -> float:
    """A hit distance <= limit (the nearest of the first batch that has one), or inf."""
    n_rays, n_tri = len(r.orig), len(r.v0)
    seed = np.random.default_rng(0).choice(n_rays, size=min(_SEED_RAYS, n_rays), replace=False)
    for chunk in np.array_split(seed, max(1, len(seed) * n_tri // _PAIRS)):
        t = r.nearest_hit(np.repeat(chunk, n_tri), np.tile(np.arange(n_tri), len(chunk)), limit)
        if t <= limit:
            return t
    # every ray against the triangles near enough to be hit within the limit (the hit lies within
    # `limit` of the vertex, so the triangle's centre within limit + its radius); the few large
    # triangles (a cap, a floor) against every ray, so that they do not widen the search of the rest
    big = r.radius > np.quantile(r.radius, 0.99)
    large, small = np.flatnonzero(big), np.flatnonzero(~big)
    for chunk in np.array_split(np.arange(n_rays), max(1, n_rays * len(large) // _PAIRS)):
        if len(large):
            t = r.nearest_hit(np.repeat(chunk, len(large)), np.tile(large, len(chunk)), limit)
            if t <= limit:
                return t
    if len(small) == 0:
        return np.inf
    from scipy.spatial import cKDTree

    tree = cKDTree(r.centre[small])
    reach = limit + float(r.radius[small].max())
    for chunk in np.array_split(np.arange(n_rays), max(1, n_rays // 1024)):
        near = tree.query_ball_point(r.orig[chunk], r=reach)
        counts = np.fromiter((len(x) for x in near), np.int64, len(near))
        if counts.sum() == 0:
            continue
        pt = small[np.concatenate([np.asarray(x, np.int64) for x in near])]
        t = r.nearest_hit(np.repeat(chunk, counts), pt, limit)
        if t <= limit:
            return t
    return np.inf
