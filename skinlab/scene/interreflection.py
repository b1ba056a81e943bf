"""Interreflection: the light a scene's surfaces throw onto each other (NumPy reference).

Every vertex of every visible mesh casts ``rays`` cosine-weighted rays into its hemisphere
(stratified: a Hammersley-like set in the disk, rotated per vertex). A ray that meets the front of
a surface records the three vertices of the triangle it met and its barycentric weights; a ray that
leaves the scene or meets a back face (the inside of an open mesh) records nothing. With those
records the irradiance a vertex receives from the scene's surfaces is

    E_bounce(i) = 1/K sum_k M(hit_k)

where M is the radiant exitance (W/m^2) of the surface hit, interpolated from its vertices. This is
the rendering equation's one-bounce estimator with cosine-weighted sampling: for a Lambertian
sender the radiance is M / pi, and E = integral L cos dw = pi E_cos[L] = E_cos[M] (Pharr, Jakob &
Humphreys, "Physically Based Rendering", 4th ed., sec. 13.6; the gathering of radiosity at mesh
vertices as in Cohen & Wallace, "Radiosity and Realistic Image Synthesis", 1993, ch. 4). Repeating
it with M = albedo x (direct + bounce) gives the next order.

Copies of one vertex (the same position and normal, split along UV seams) share one set of rays,
so the bounce light is continuous across seams. The estimate is then averaged over each vertex's
one-ring (area-weighted, on the welded mesh): bounce light varies slowly, and the average of 7 or so
independent estimates has about a third of the variance of one (a bias of about an edge length).
Where the ray budget leaves a vertex fewer rays, the average spans more rings (the one-ring's applied k
times, :func:`smoothing_rings`), so that about as many rays are averaged per vertex as at the default.

Sources: docs/references.md#interreflection. The GPU twin is skinlab/render/bounce.py with
skinlab/shaders/passes/bounce_exitance.frag (M per vertex) and bounce_rows.frag (the sum above, from
the records collapsed per receiver into its distinct senders and their summed weights, and the one-ring
average); the records are computed here once per geometry and cached (ray casting with trimesh through
Embree, the ``embreex`` package).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from skinlab.cache import Memo, stored

from .mesh import mesh_key

if TYPE_CHECKING:
    from .graph import MeshNode

GOLDEN = 0.6180339887498949  # the golden ratio's fractional part: the second coordinate's sequence
RAY_OFFSET = 1e-5  # ray origins leave the surface by this fraction of the scene's bounding diagonal
# rays per frame's geometry: the records take 24 bytes a ray (48 MB at the budget; the sky occlusion's
# direction and open flag 13 more, 26 MB) and Embree casts about
# a million a second on 2 cores; past it each vertex casts fewer rays, down to MIN_RAYS, then none
# (skinlab/render/bounce.py plans with it, and so does the environment's sky occlusion)
MAX_RAYS = 2_000_000
MIN_RAYS = 4


@dataclass
class BounceTransfer:
    """The ray records of a set of mesh nodes (all in world space).

    ``vertices[i * rays + k]``: the three global vertex indices of the triangle ray k of vertex i met,
    ``weights[i * rays + k]``: their barycentric weights divided by ``rays`` (zero for a ray that met
    nothing or a back face). Global vertex index = ``offsets[node_uid]`` + the mesh's own index."""

    rays: int
    offsets: dict[int, int]  # node uid -> first global vertex
    counts: dict[int, int]  # node uid -> its vertices
    vertices: np.ndarray  # (V * rays, 3) int64
    weights: np.ndarray  # (V * rays, 3) float32
    key: str = ""  # what the records were computed from (geometry, rays, seed): a cache key
    hit_fraction: dict[int, float] = field(default_factory=dict)  # node uid -> front hits / rays
    # the one-ring average: vertex i's estimate is sum_j ring_weights[j] E[ring_vertices[j]] over
    # j in ring_offsets[i] .. ring_offsets[i + 1] (itself and its neighbours, weights summing to 1)
    ring_offsets: np.ndarray = field(default_factory=lambda: np.zeros(1, np.int64))  # (V + 1,)
    ring_vertices: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    ring_weights: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float32))
    # the records collapsed per receiver (CSR, like the one-ring): vertex i gathers
    # sum_j sender_weights[j] M[sender_vertices[j]] over j in sender_offsets[i] .. sender_offsets[i + 1],
    # each sender once with the summed weights of every ray and corner that met it (no empty rays):
    # gather's sum in fewer terms (the GPU's, skinlab/shaders/passes/bounce_rows.frag)
    sender_offsets: np.ndarray = field(default_factory=lambda: np.zeros(1, np.int64))  # (V + 1,)
    sender_vertices: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    sender_weights: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float32))
    # the rays themselves, for the share of a map's light each vertex sees (sky_visible_share): per
    # welded vertex w its rays' unit directions sky_directions[w * rays + k] (world axes) and whether
    # each leaves the scene (sky_open); vertex i's welded vertex sky_welded[i] (-1: no normal)
    sky_directions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    sky_open: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))
    sky_welded: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))

    @property
    def total_vertices(self) -> int:
        return sum(self.counts.values())

    @property
    def any_hit(self) -> bool:
        """True when some ray met the front of a surface (else there is nothing to gather); from the
        hit fractions, not the records (the plan asks every frame)."""
        return any(f > 0.0 for f in self.hit_fraction.values())

    @property
    def any_blocked(self) -> bool:
        """True when some ray met any surface (some vertex sees less than its whole sky)."""
        return bool((~self.sky_open.reshape(-1, max(self.rays, 1))[self.sky_welded[self.sky_welded >= 0]]).any())


def cosine_directions(normals: np.ndarray, rays: int, seed: int = 0) -> np.ndarray:
    """(V, rays, 3) unit directions about each normal, cosine-weighted (Malley's method: uniform
    points in the unit disk lifted to the hemisphere). Stratified: point k has radius^2 (k + j)/K and
    angle 2 pi frac(k GOLDEN + r), with j, r random per vertex (Cranley-Patterson rotation)."""
    n = np.asarray(normals, np.float64)
    v = len(n)
    rng = np.random.default_rng(seed)
    jitter = rng.random((v, 1))
    rot = rng.random((v, 1))
    k = np.arange(rays)[None, :]
    u1 = (k + jitter) / rays
    u2 = np.mod(k * GOLDEN + rot, 1.0)
    r = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    x, y, z = r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(1.0 - u1, 0.0))
    # an orthonormal frame per normal (Duff et al. 2017, "Building an Orthonormal Basis, Revisited")
    sign = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]], 1)
    s = np.stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]], 1)
    return x[..., None] * t[:, None] + y[..., None] * s[:, None] + z[..., None] * n[:, None]


def world_geometry(node: MeshNode) -> tuple[np.ndarray, np.ndarray]:
    """A mesh node's vertex positions and unit normals in world space (float64)."""
    m = np.asarray(node.world_matrix, np.float64)
    p = node.mesh.positions.astype(np.float64) @ m[:3, :3].T + m[:3, 3]
    nrm = node.mesh.normals.astype(np.float64) @ np.linalg.inv(m[:3, :3])
    length = np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = np.where(length > 0.0, nrm / np.maximum(length, 1e-300), [0.0, 0.0, 1.0])
    return p, nrm


def geometry_key(nodes: list[MeshNode], rays: int, seed: int) -> str:
    """What the records depend on: each mesh's arrays (by content: the same mesh loaded twice shares
    its records) and world transform, the rays and the seed."""
    h = hashlib.sha1()
    h.update(np.array([rays, seed], np.int64).tobytes())
    for node in nodes:
        h.update(np.asarray(node.world_matrix, np.float64).tobytes())
        h.update(mesh_key(node.mesh).encode())
    return h.hexdigest()


_CACHE = Memo(8)  # key -> vertices, weights, hit fractions, ring offsets, vertices, weights, sender rows, sky rays


def build_transfer(nodes: list[MeshNode], rays: int = 64, seed: int = 0) -> BounceTransfer:
    """The ray records of `nodes` against each other (cached per geometry, rays and seed: the same
    meshes at the same places share them, whichever scene object holds them; on disk too: casting
    is the slow part of loading a scene, 0.6 s for the head). Thread-safe: a frame plan may start
    it early on a worker thread (:func:`prefetch_transfer`) and ask for it later."""
    if not isinstance(rays, int) or isinstance(rays, bool) or rays < 1:
        raise ValueError(f"interreflection rays: expected a positive integer (rays per vertex), got {rays!r}")
    key = geometry_key(nodes, rays, seed)
    offsets, counts, total = {}, {}, 0
    for node in nodes:
        offsets[node.uid], counts[node.uid] = total, len(node.mesh.positions)
        total += len(node.mesh.positions)
    hit = _CACHE.get(
        key,
        lambda: stored(
            "interreflection", key, lambda: _cast(nodes, rays, seed, total), "interreflection rays", code=__name__
        ),
    )
    vertices, weights, fractions, r_off, r_vert, r_w, s_off, s_vert, s_w, sky_dirs, sky_open, sky_welded = hit
    return BounceTransfer(
        rays,
        offsets,
        counts,
        vertices,
        weights,
        key,
        {n.uid: f for n, f in zip(nodes, fractions)},
        r_off,
        r_vert,
        r_w,
        s_off,
        s_vert,
        s_w,
        sky_dirs,
        sky_open,
        sky_welded,
    )


def weld(positions: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, inverse): copies of a vertex (bit-identical position and normal) map to one welded
    vertex; ``first[w]`` is its first copy, ``inverse[i]`` vertex i's welded index."""
    key = np.ascontiguousarray(np.concatenate([positions, normals], 1).astype(np.float64))
    _, first, inverse = np.unique(key.view(np.dtype((np.void, key.itemsize * 6))).ravel(), True, True)
    return first.astype(np.int64), inverse.ravel().astype(np.int64)


def one_rings(positions, faces, first, inverse) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each vertex's one-ring on the welded mesh, as CSR (offsets, vertices, weights): itself and
    its edge neighbours (as their first copies), weighted by their area (a third of the incident
    triangles'), the weights of a ring summing to 1."""
    nw = len(first)
    f = inverse[faces]
    tri_area = 0.5 * np.linalg.norm(
        np.cross(positions[faces[:, 1]] - positions[faces[:, 0]], positions[faces[:, 2]] - positions[faces[:, 0]]),
        axis=1,
    )
    area = np.bincount(f.ravel(), np.repeat(tri_area / 3.0, 3), minlength=nw)
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]], np.stack([np.arange(nw)] * 2, 1)])
    # each undirected edge (and each vertex with itself) once as the key a * nw + b, a <= b: unique
    # over integers, not rows (np.unique(axis=0) sorts structured rows, 6x slower on the head)
    a, b = np.minimum(edges[:, 0], edges[:, 1]), np.maximum(edges[:, 0], edges[:, 1])
    key = np.unique(a * nw + b)
    a, b = key // nw, key % nw
    other = a != b
    key = np.sort(np.concatenate([key, b[other] * nw + a[other]]))  # both directions, self once, by (from, to)
    pairs = np.stack([key // nw, key % nw], 1)
    w = area[pairs[:, 1]]
    total = np.bincount(pairs[:, 0], w, minlength=nw)
    w = np.where(total[pairs[:, 0]] > 0, w / np.maximum(total[pairs[:, 0]], 1e-300), 0.0)
    # a welded vertex no triangle uses (area 0): its own estimate alone
    lonely = total == 0
    w[lonely[pairs[:, 0]] & (pairs[:, 0] == pairs[:, 1])] = 1.0
    counts_w = np.bincount(pairs[:, 0], minlength=nw)
    start_w = np.concatenate([[0], np.cumsum(counts_w)])
    # every copy of a welded vertex has its ring
    counts = counts_w[inverse]
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    # entry j of vertex i is its welded vertex's entry (j - offsets[i]): no loop over the vertices
    within = np.arange(offsets[-1]) - np.repeat(offsets[:-1], counts)
    idx = np.repeat(start_w[inverse], counts) + within
    return offsets, first[pairs[idx, 1]], w[idx].astype(np.float32)


def _cast(nodes: list[MeshNode], rays: int, seed: int, total: int):
    import trimesh

    if total == 0:
        z = np.zeros(0, np.int64)
        one, w0 = np.zeros(1, np.int64), np.zeros(0, np.float32)
        rays_none = (np.zeros((0, 3), np.float32), np.zeros(0, bool), z)
        return np.zeros((0, 3), np.int64), np.zeros((0, 3), np.float32), [], one, z, w0, one, z, w0, *rays_none

    pos, nrm, faces = [], [], []
    start = 0
    for node in nodes:
        p, n = world_geometry(node)
        pos.append(p)
        nrm.append(n)
        faces.append(node.mesh.indices.astype(np.int64) + start)
        start += len(p)
    p_all, n_all, f_all = np.concatenate(pos), np.concatenate(nrm), np.concatenate(faces)
    mesh = trimesh.Trimesh(p_all, f_all, process=False)
    try:  # Embree's BVH: 0.6 M rays in about a second on 2 cores (trimesh's fallback needs rtree and is far slower)
        from trimesh.ray.ray_pyembree import RayMeshIntersector
    except ImportError:
        raise RuntimeError(
            "interreflection: casting rays needs embreex (pip install embreex; a dependency in pyproject.toml), "
            "or render without it: bounces = 0 (--bounces 0)"
        ) from None
    mesh.ray = RayMeshIntersector(mesh)
    diag = float(np.linalg.norm(p_all.max(0) - p_all.min(0))) or 1.0
    first, inverse = weld(p_all, n_all)
    nw = len(first)
    dirs = cosine_directions(n_all[first], rays, seed).reshape(-1, 3)
    origins = np.repeat(p_all[first] + n_all[first] * (RAY_OFFSET * diag), rays, axis=0)
    tri, ray, loc = mesh.ray.intersects_id(origins, dirs, multiple_hits=False, return_locations=True)
    vertices = np.zeros((nw * rays, 3), np.int64)
    weights = np.zeros((nw * rays, 3), np.float32)
    blocked = np.zeros(nw * rays, bool)
    blocked[ray] = True  # met a surface, front or back: no sky that way
    if len(tri):
        front = np.einsum("ij,ij->i", mesh.face_normals[tri], dirs[ray]) < 0.0
        tri, ray, loc = tri[front], ray[front], loc[front]
        corners = f_all[tri]
        bary = trimesh.triangles.points_to_barycentric(p_all[corners], loc)
        bary = np.clip(np.nan_to_num(bary, nan=1.0 / 3.0), 0.0, 1.0)
        bary /= np.maximum(bary.sum(1, keepdims=True), 1e-12)
        vertices[ray] = corners
        weights[ray] = (bary / rays).astype(np.float32)
    no_normal = np.concatenate([np.linalg.norm(n.mesh.normals, axis=1) == 0 for n in nodes])
    weights[np.repeat(no_normal[first], rays)] = 0.0  # a vertex without a normal (no triangle uses it) receives nothing
    # every copy of a welded vertex gets its records
    rows = (inverse[:, None] * rays + np.arange(rays)[None, :]).ravel()
    vertices, weights = vertices[rows], weights[rows]
    hit_rays = (weights.sum(1) > 0).reshape(total, rays).mean(1)
    fractions, start = [], 0
    for node in nodes:
        k = len(node.mesh.positions)
        fractions.append(float(hit_rays[start : start + k].mean()))
        start += k
    rings = ring_power(one_rings(p_all, f_all, first, inverse), smoothing_rings(rays))
    welded = np.where(no_normal, -1, inverse).astype(np.int64)
    sky_rays = (dirs.astype(np.float32), ~blocked, welded)
    return vertices, weights, fractions, *rings, *sender_rows(vertices, weights, rays), *sky_rays


# The average's reach: as many rings as make the rays averaged per vertex at least this many (the
# default's 64 rays over a one-ring of about 7 vertices). A mesh over the ray budget casts fewer rays
# per vertex (the nose close-up's head subdivided twice: 13), and a one-ring average of those left the
# bounce light blotchy, 1-2 mm blobs in the nose's shadow where the truth is smooth (issue 21).
SMOOTH_SAMPLES = 448


def smoothing_rings(rays: int) -> int:
    """How many rings the average spans at `rays` per vertex: the least k >= 1 with rays x (1 + 3 k
    (k + 1)) >= SMOOTH_SAMPLES (a regular triangle mesh's k-ring has 1 + 3 k (k + 1) vertices)."""
    k = 1
    while rays * (1 + 3 * k * (k + 1)) < SMOOTH_SAMPLES and k < 16:
        k += 1
    return k


def ring_power(rings: tuple[np.ndarray, np.ndarray, np.ndarray], k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The one-ring average (CSR offsets, vertices, weights per vertex) applied k times, as one CSR
    average over the k-ring (each row still summing to 1); k = 1 returns the rings as they are."""
    if k <= 1:
        return rings
    from scipy.sparse import csr_matrix

    offsets, vertices, weights = rings
    n = len(offsets) - 1
    m = csr_matrix((weights.astype(np.float64), vertices, offsets), shape=(n, max(n, int(vertices.max(initial=0)) + 1)))
    m = m[:, :n]
    out = m
    for _ in range(k - 1):
        out = out @ m
    out = out.tocsr()
    out.sort_indices()
    return out.indptr.astype(np.int64), out.indices.astype(np.int64), out.data.astype(np.float32)


def sender_rows(vertices: np.ndarray, weights: np.ndarray, rays: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ray records (BounceTransfer.vertices / weights, `rays` rows per receiver) collapsed per
    receiver: CSR (offsets, senders, weights), each receiver's distinct senders in increasing order
    with the summed weights (float64 sums, stored as float32) of every ray corner that met them;
    corners of zero weight (rays that met nothing) left out."""
    n = len(vertices) // max(rays, 1)
    receiver = np.repeat(np.arange(n, dtype=np.int64), rays * 3)
    sender = vertices.reshape(-1).astype(np.int64)
    w = weights.reshape(-1).astype(np.float64)
    live = w > 0.0
    key = receiver[live] * max(n, 1) + sender[live]
    uniq, inverse = np.unique(key, return_inverse=True)
    summed = np.bincount(inverse, w[live], minlength=len(uniq))
    owner = uniq // max(n, 1)
    offsets = np.concatenate([[0], np.cumsum(np.bincount(owner, minlength=n))]).astype(np.int64)
    return offsets, uniq % max(n, 1), summed.astype(np.float32)


def sky_visible_share(transfer: BounceTransfer, radiance: np.ndarray) -> np.ndarray:
    """(V, 4) per vertex the share of a map's light its rays see, per channel (RGB), and the share of
    its rays that leave the scene (the sky's visibility, a). `radiance` (N, 3): the (smooth) map along
    each ray of ``transfer.sky_directions``. With cosine-weighted rays w_k, sum_k L(w_k) over the open rays
    against the sum over all is the visible share of E = int L cos dw, exact as the rays grow (the
    rays' estimate, not nine SH coefficients of the blocked set: a sharp occluder in front of a small
    bright part of the map hides it). Numerator and denominator are each one-ring averaged like the
    bounce light; a vertex whose rays see no light keeps its rays' share; one without a normal sees all."""
    v = transfer.total_vertices
    out = np.ones((v, 4), np.float64)
    if v == 0 or len(transfer.sky_open) == 0:
        return out.astype(np.float32)
    rays = transfer.rays
    nw = len(transfer.sky_open) // rays
    lit = np.asarray(radiance, np.float64).reshape(nw, rays, -1)
    open_ = transfer.sky_open.reshape(nw, rays)
    per = np.concatenate([(lit * open_[..., None]).sum(1), lit.sum(1), open_.mean(1, keepdims=True)], 1)
    welded = transfer.sky_welded
    rows = np.where(welded[:, None] >= 0, per[np.maximum(welded, 0)], 1.0)
    ring = transfer.ring_weights.astype(np.float64)[:, None] * rows[transfer.ring_vertices]
    owner = np.repeat(np.arange(v), np.diff(transfer.ring_offsets))
    avg = _sum_rows(owner, ring, v)
    c = lit.shape[-1]
    num, den, fraction = avg[:, :c], avg[:, c : 2 * c], avg[:, 2 * c]
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), fraction[:, None])
    out[:, :3] = np.clip(share, 0.0, 1.0)
    out[:, 3] = np.clip(fraction, 0.0, 1.0)
    out[welded < 0] = 1.0
    return out.astype(np.float32)


def open_toward(nodes: list[MeshNode], key: str, directions: np.ndarray) -> np.ndarray:
    """(V, J) whether a ray from each vertex (global order, off its surface as the records' rays) along
    each world direction `directions` (J, 3) leaves the scene: the visibility of a small bright source,
    sharper than a vertex's cosine-weighted rays hold it. `key`: the transfer's (the geometry's) key,
    under which the ray intersector is kept. A vertex without a normal sees everything."""
    p_all, n_all, intersector, diag = _INTERSECTORS.get(key, lambda: _intersector(nodes))
    d = np.asarray(directions, np.float64).reshape(-1, 3)
    out = np.ones((len(p_all), len(d)), bool)
    has = np.linalg.norm(n_all, axis=1) > 0
    origins = p_all[has] + n_all[has] * (RAY_OFFSET * diag)
    for j, w in enumerate(d):
        out[has, j] = ~intersector.intersects_any(origins, np.broadcast_to(w, origins.shape).copy())
    return out


_INTERSECTORS = Memo(2)  # geometry key -> world positions, normals, Embree intersector, bounding diagonal


def _intersector(nodes: list[MeshNode]):
    import trimesh
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    pos, nrm, faces, start = [], [], [], 0
    for node in nodes:
        p, n = world_geometry(node)
        pos.append(p)
        nrm.append(np.where(np.linalg.norm(node.mesh.normals, axis=1, keepdims=True) > 0, n, 0.0))
        faces.append(node.mesh.indices.astype(np.int64) + start)
        start += len(p)
    p_all, n_all = np.concatenate(pos), np.concatenate(nrm)
    mesh = trimesh.Trimesh(p_all, np.concatenate(faces), process=False)
    diag = float(np.linalg.norm(p_all.max(0) - p_all.min(0))) or 1.0
    return p_all, n_all, RayMeshIntersector(mesh), diag


def _sum_rows(owner: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """(n, C): the rows of `values` (M, C) summed by `owner` (M,) in their order (np.add.at's sums,
    through bincount per column: several times faster)."""
    return np.stack([np.bincount(owner, values[:, k], minlength=n) for k in range(values.shape[1])], 1)


def gather(transfer: BounceTransfer, exitance: np.ndarray) -> np.ndarray:
    """(V, C) irradiance each vertex receives from the surfaces its rays met, for the senders'
    radiant exitance `exitance` (V, C) per global vertex."""
    m = np.asarray(exitance, np.float64)
    if m.shape[0] != transfer.total_vertices:
        raise ValueError(
            f"interreflection gather: exitance has {m.shape[0]} vertices, the transfer {transfer.total_vertices}"
        )
    per_ray = np.einsum("rj,rjc->rc", transfer.weights.astype(np.float64), m[transfer.vertices])
    return per_ray.reshape(transfer.total_vertices, transfer.rays, -1).sum(1)


def smooth(transfer: BounceTransfer, irradiance: np.ndarray) -> np.ndarray:
    """The one-ring average of per-vertex estimates (module docstring)."""
    e = np.asarray(irradiance, np.float64)
    per = transfer.ring_weights.astype(np.float64)[:, None] * e[transfer.ring_vertices]
    owner = np.repeat(np.arange(transfer.total_vertices), np.diff(transfer.ring_offsets))
    out = np.zeros_like(e)
    np.add.at(out, owner, per)
    return out


def bounce_irradiance(transfer: BounceTransfer, direct: np.ndarray, albedo: np.ndarray, bounces: int) -> np.ndarray:
    """Irradiance from interreflection up to order `bounces` (0: none), per global vertex: each
    order's senders leave albedo x (direct + the previous orders' bounce light)."""
    direct = np.asarray(direct, np.float64)
    e = np.zeros_like(direct)
    for _ in range(bounces):
        e = smooth(transfer, gather(transfer, np.asarray(albedo, np.float64) * (direct + e)))
    return e


def sender_albedo(base, metallic, specular) -> np.ndarray:
    """The fraction of the light arriving at a surface that it sends back out, as the bounce counts
    it: the diffuse albedo base x (1 - metallic) plus the specular reflectance at normal incidence
    (principled F0), both as if Lambertian (a first-order estimate: the specular part is a few
    percent and leaves in a lobe). A subsurface material's total diffuse reflectance is its base
    colour (skinlab/scene/materials.py), so the same holds for it. GLSL twin: skinlab/shaders/lib/bounce.glsl."""
    from .optics.brdf import principled_f0

    base = np.asarray(base, np.float64)
    m = np.asarray(metallic, np.float64)[..., None]
    return base * (1.0 - m) + principled_f0(base, metallic, specular)


def clear_cache() -> None:
    _CACHE.clear()
    _INTERSECTORS.clear()
