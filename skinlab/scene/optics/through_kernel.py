"""Light through thin parts as a transfer through the medium (NumPy reference).

The light that leaves a point p of a translucent part from behind is the light that entered the part's
other faces, carried through the medium by the diffusion's transmission kernel: for light entering at a
boundary point q that lies a depth z below p's tangent plane, at distance s from p, the diffusion
dipole's exitance (Jensen et al. 2001, the real source's term; docs/references.md#jensen-2001) is

    K(p, q) = T(z) z (1 + sigma_tr s) e^{-sigma_tr (s - z)} / (2 pi s^3),

normalised so that over a flat slab of thickness z it integrates to T(z), the slab's exact diffuse
transmittance (skinlab/scene/optics/slab.py slab_through: all orders, not the dipole's). The exitance is
then M(p) = integral over the part's boundary of E(q) K(p, q) dA_q, E(q) the irradiance entering at q.
Estimated with rays from p into the medium, cosine-weighted about -n_p (Malley's method, as the
interreflection: skinlab/scene/interreflection.py cosine_directions), each meeting the boundary at q
after s with cos(theta) = z / s to -n_p and cosine g to the boundary there, dA = s^2 dw / g, pdf
cos(theta) / pi:

    M(p) = 1/K sum_k E(q_k) T(s_k cos theta_k) (1 + sigma_tr s_k) e^{-sigma_tr s_k (1 - cos theta_k)} / (2 g_k)

(g clamped at G_MIN against the rays that meet the boundary at a graze). On a flat slab every ray
gives T(z) on average (the integral over the hemisphere is 1), so a uniformly lit slab transmits what
the exact slab does; on a curved, folded part (the back-lit ear) each point gathers what entered the
faces the medium connects it to, along the part, instead of what one chord along the light holds
(issue 21, docs/ground-truth.md "Light through thin parts as a transfer through the medium"). A ray
leaves the part where it first meets its boundary, so no light crosses air.

Per vertex (the records per geometry, cached; the weights per material), per channel: the light
entering through, per unit base colour, as the distance-map translucency's (lib/sss_translucency.glsl),
which every technique's translucency reads in its place (lib/through_vertex.glsl). The GPU twin is
skinlab/render/through_kernel.py with skinlab/shaders/passes/through_entering.frag and through_rows.frag.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from skinlab.cache import Memo, stored

if TYPE_CHECKING:
    from skinlab.scene.graph import MeshNode

G_MIN = 0.1  # the boundary's cosine to a ray is taken at least this (rays that graze it)
WEIGHT_FLOOR = 1e-4  # a sender whose weight is below this share of its receiver's sum is left out


@dataclass
class ThroughRecords:
    """One mesh node's rays into its medium: welded vertex w's ray k is row w * rays + k. ``corners``:
    the node's own vertex indices of the triangle it met, ``bary`` their barycentric
    weights (zero for a ray that met nothing), ``s`` its length (scene units), ``cos_in`` its cosine
    to the inward normal, ``g`` its cosine to the boundary it met; ``inverse[i]``: vertex i's welded
    vertex."""

    key: str
    rays: int
    corners: np.ndarray  # (W * rays, 3) int64
    bary: np.ndarray  # (W * rays, 3) float64
    s: np.ndarray  # (W * rays,)
    cos_in: np.ndarray
    g: np.ndarray
    inverse: np.ndarray  # (V,) int64


_RECORDS = Memo(4)


def records_key(node: MeshNode, rays: int, seed: int) -> str:
    from skinlab.scene.mesh import mesh_key

    h = hashlib.sha1(b"through-kernel")
    h.update(np.array([rays, seed], np.int64).tobytes())
    h.update(np.asarray(node.world_matrix, np.float64).tobytes())
    h.update(mesh_key(node.mesh).encode())
    return h.hexdigest()


def through_records(node: MeshNode, rays: int = 64, seed: int = 0) -> ThroughRecords:
    """The node's rays into its own medium (cached per geometry, rays and seed; on disk too)."""
    if not isinstance(rays, int) or isinstance(rays, bool) or rays < 1:
        raise ValueError(f"through kernel rays: expected a positive integer (rays per vertex), got {rays!r}")
    key = records_key(node, rays, seed)
    arrays = _RECORDS.get(
        key,
        lambda: stored("through_kernel", key, lambda: _cast(node, rays, seed), "through-kernel rays", code=__name__),
    )
    return ThroughRecords(key, rays, *arrays)


def _cast(node: MeshNode, rays: int, seed: int):
    import trimesh
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    from skinlab.scene.interreflection import RAY_OFFSET, cosine_directions, weld, world_geometry

    p, n = world_geometry(node)
    f = node.mesh.indices.astype(np.int64).reshape(-1, 3)
    first, inverse = weld(p, n)
    nw = len(first)
    if nw == 0 or len(f) == 0:
        z = np.zeros(0)
        return np.zeros((0, 3), np.int64), np.zeros((0, 3)), z, z, z, inverse
    mesh = trimesh.Trimesh(p, f, process=False)
    ray = RayMeshIntersector(mesh)
    diag = float(np.linalg.norm(p.max(0) - p.min(0))) or 1.0
    inward = -n[first]
    dirs = cosine_directions(inward, rays, seed).reshape(-1, 3)
    origins = np.repeat(p[first] - n[first] * (RAY_OFFSET * diag), rays, axis=0)
    tri, idx, loc = ray.intersects_id(origins, dirs, multiple_hits=False, return_locations=True)
    corners = np.zeros((nw * rays, 3), np.int64)
    bary = np.zeros((nw * rays, 3))
    s = np.zeros(nw * rays)
    g = np.ones(nw * rays)
    if len(tri):
        b = trimesh.triangles.points_to_barycentric(p[f[tri]], loc)
        b = np.clip(np.nan_to_num(b, nan=1.0 / 3.0), 0.0, 1.0)
        b /= np.maximum(b.sum(1, keepdims=True), 1e-12)
        corners[idx] = f[tri]
        bary[idx] = b
        s[idx] = np.linalg.norm(loc - origins[idx], axis=1)
        g[idx] = np.abs(np.einsum("ij,ij->i", mesh.face_normals[tri], dirs[idx]))
    cos_in = np.einsum("ij,ij->i", dirs, np.repeat(inward, rays, axis=0))
    return corners, bary, s, np.clip(cos_in, 0.0, 1.0), g, inverse


@dataclass
class ThroughRows:
    """The transfer per receiving vertex (CSR): vertex i gathers sum_j weights[j] E[senders[j]] over
    j in offsets[welded[i]] .. offsets[welded[i] + 1] (copies of a vertex share their row)."""

    offsets: np.ndarray  # (W + 1,) int64
    senders: np.ndarray  # (M,) int64: the node's own vertex indices
    weights: np.ndarray  # (M, 3) float32
    welded: np.ndarray  # (V,) int64
    depth_mm: np.ndarray  # (W,): the depth below the receiver's tangent plane the light came from, mm
    # (its rays' s cos(theta) weighted by their green weight; the exit factor's slab thickness)


def ray_weights(rec: ThroughRecords, sigma_tr_mm, mm_per_unit: float, through) -> np.ndarray:
    """(W * rays, 3): each ray's share of the transfer (module docstring), before its corners'
    barycentric split. ``through(z_mm)`` -> (..., 3): the slab transmittance at normal incidence."""
    sig = np.asarray(sigma_tr_mm, np.float64).reshape(1, 3)
    s = rec.s * float(mm_per_unit)
    hit = rec.bary.sum(1) > 0
    t = np.asarray(through(s * rec.cos_in), np.float64).reshape(-1, 3)
    decay = (1.0 + sig * s[:, None]) * np.exp(-sig * (s * (1.0 - rec.cos_in))[:, None])
    w = t * decay / (2.0 * np.maximum(rec.g, G_MIN))[:, None] / rec.rays
    return np.where(hit[:, None], w, 0.0)


def through_rows(rec: ThroughRecords, sigma_tr_mm, mm_per_unit: float, through) -> ThroughRows:
    """The records' rays collapsed per receiver into its distinct senders, summed per channel, the
    ones under WEIGHT_FLOOR of their receiver's sum left out (renormalised: the sum is kept)."""
    w = ray_weights(rec, sigma_tr_mm, mm_per_unit, through)
    nw = len(rec.s) // max(rec.rays, 1)
    z = (rec.s * rec.cos_in * float(mm_per_unit)).reshape(nw, rec.rays)
    wg = w[:, 1].reshape(nw, rec.rays)
    depth = (wg * z).sum(1) / np.maximum(wg.sum(1), 1e-300)
    receiver = np.repeat(np.arange(nw), rec.rays * 3)
    sender = rec.corners.reshape(-1)
    per = (w[:, None, :] * rec.bary[:, :, None]).reshape(-1, 3)
    keep = per.max(1) > 0
    receiver, sender, per = receiver[keep], sender[keep], per[keep]
    nv = int(rec.corners.max()) + 1 if len(rec.corners) else 1
    pair = receiver * nv + sender
    uniq, inv = np.unique(pair, return_inverse=True)
    summed = np.stack([np.bincount(inv, per[:, c], minlength=len(uniq)) for c in range(3)], 1)
    r, snd = uniq // nv, uniq % nv
    total = np.stack([np.bincount(r, summed[:, c], minlength=nw) for c in range(3)], 1)
    big = (summed >= WEIGHT_FLOOR * total[r]).any(1)
    kept_total = np.stack([np.bincount(r[big], summed[big, c], minlength=nw) for c in range(3)], 1)
    scale = np.where(kept_total > 0, total / np.maximum(kept_total, 1e-300), 0.0)
    r, snd, summed = r[big], snd[big], summed[big] * scale[r[big]]
    offsets = np.zeros(nw + 1, np.int64)
    np.cumsum(np.bincount(r, minlength=nw), out=offsets[1:])
    return ThroughRows(offsets, snd.astype(np.int64), summed.astype(np.float32), rec.inverse, depth)


def gather(rows: ThroughRows, entering: np.ndarray) -> np.ndarray:
    """(V, 3): the light through to each vertex for the irradiance ``entering`` (V, 3) at each vertex
    (the twin of skinlab/shaders/passes/through_rows.frag)."""
    e = np.asarray(entering, np.float64)
    nw = len(rows.offsets) - 1
    owner = np.repeat(np.arange(nw), np.diff(rows.offsets))
    per = rows.weights.astype(np.float64) * e[rows.senders]
    welded = np.stack([np.bincount(owner, per[:, c], minlength=nw) for c in range(3)], 1)
    return welded[rows.welded]


_ROWS = Memo(4)  # (records key, medium, colour, scale) -> ThroughRows: a frame plan asks every frame


def medium_rows(node: MeshNode, material, mm_per_unit: float, rays: int = 64) -> ThroughRows:
    """The node's transfer for its material (skinlab/scene/optics/material_medium.py: per channel
    sigma_tr from the slab's decay, the slab table at the material's index); cached by the records,
    the medium and the scale."""
    from .material_medium import material_medium
    from .slab import slab_decay, slab_table, slab_through

    values = material.values
    med = material_medium(values)
    colour = np.asarray(values["subsurface_color"], np.float64)
    rec = through_records(node, rays)
    params = np.concatenate([med.alpha_arr, med.mfp_arr, [med.eta, float(mm_per_unit)], colour.ravel()])
    key = rec.key + hashlib.sha1(np.asarray(params, np.float64).tobytes()).hexdigest()

    def build() -> ThroughRows:
        table = slab_table(med.alpha_arr, colour)
        mfp = np.asarray(med.mfp_arr, np.float64)
        sigma = np.where(mfp > 0, slab_decay(med.alpha_arr) / np.where(mfp > 0, mfp, 1.0), 0.0)

        def through(z_mm):
            return slab_through(np.ones_like(z_mm), z_mm, table, med.mfp_arr, med.alpha_arr, med.eta)

        return through_rows(rec, sigma, mm_per_unit, through)

    return _ROWS.get(key, build)


# A mesh whose median edge is longer than this many of its medium's longest diffusion lengths
# (1 / sigma_tr) samples the transfer too coarsely per vertex (a box of 4 vertices a face reads its
# corners): the distance map's slab serves it instead (skinlab/render/through_kernel.py plan_through).
MAX_EDGE_DIFFUSION_LENGTHS = 2.0


def diffusion_length_mm(material) -> float:
    """The medium's longest diffusion length 1 / sigma_tr per channel (mm; 0 where nothing scatters)."""
    from .material_medium import material_medium
    from .slab import slab_decay

    med = material_medium(material.values)
    mfp = np.asarray(med.mfp_arr, np.float64)
    k = np.asarray(slab_decay(med.alpha_arr), np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        length = np.where((mfp > 0) & (k > 0), mfp / np.where(k > 0, k, 1.0), 0.0)
    return float(length.max())


def median_edge_mm(node: MeshNode, mm_per_unit: float) -> float:
    """The median length of the node's triangle edges in the world (mm)."""
    from skinlab.scene.interreflection import world_geometry

    p, _ = world_geometry(node)
    f = node.mesh.indices.astype(np.int64).reshape(-1, 3)
    if len(f) == 0:
        return 0.0
    e = np.linalg.norm(p[f] - p[np.roll(f, 1, axis=1)], axis=2)
    return float(np.median(e)) * float(mm_per_unit)


def fine_enough(node: MeshNode, material, mm_per_unit: float) -> tuple[bool, str]:
    """(whether the node's vertices sample its transfer finely enough, why not)."""
    edge, length = median_edge_mm(node, mm_per_unit), diffusion_length_mm(material)
    if edge <= MAX_EDGE_DIFFUSION_LENGTHS * length:
        return True, ""
    return False, (
        f"its median edge ({edge:.3g} mm) is longer than {MAX_EDGE_DIFFUSION_LENGTHS:g} diffusion lengths "
        f"({length:.3g} mm) of its medium: too coarse per vertex (subdivide it)"
    )


def clear_cache() -> None:
    _RECORDS.clear()
    _ROWS.clear()
