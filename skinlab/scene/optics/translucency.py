"""Light through thin parts: NumPy twin of skinlab/shaders/lib/sss_translucency.glsl.

The thickness of matter between a light and a surface point comes from the shadow pass's distance
map (per texel, the distance from the light of the first surface it meets: scene units, 1e30 where
none), as in Jimenez, Whelan, Sundstedt & Gutierrez 2010, "Real-Time Realistic Skin Translucency"
(docs/references.md#jimenez-2010): the point's distance from the light minus the first surface's,
looked up at the point moved `shrink` inward along its normal, times the cosine between the normal
and the light (a flat slab's own thickness), plus the shrink (which a flat part's lookup lost); 0
where the moved point is still in front of the first surface (a point that is itself the first
surface reads 0, not the map's quantisation noise; so does a part thinner than the shrink). Only
matter counts: the map has layers (skinlab/shaders/passes/shadow.frag SHADOW_LAYER) holding, per
texel, where the light leaves the first part it crosses (the nearest surface facing away from it)
with the cosine there, and where it enters the next part (the nearest surface facing it beyond that
exit by more than the part gap); a point past the first part's exit by more than the gap gets the
first part's thickness (its chord times the exit cosine) plus its own part's (from the next entry,
times its own cosine), not the air between them. The cosine (through_cosine) is, where the part is
a sheet (the face where the light entered it faces away from the point's own), the larger of the
point's own and the entry face's (from the distance map's slope): on a curved sheet the point's own
face grazes the light where the entry face does not, and the chord times the point's cosine alone
read the sheet thin there (the back-lit ear, issue 21; docs/ground-truth.md). What crosses that
thickness is the exact slab transmittance of skinlab/scene/optics/slab.py (`slab_through`: all
orders of scattering, Fresnel in and out). Texture-space diffusion gathers it in its irradiance pass,
the screen-space techniques in the forward pass; both call the same GLSL functions.

Distance maps are (H, W) (the first surface); the part layers (H', W', 2) (the first part's exit,
its cosine) or (H', W', 3) (and the next part's entry: on the GPU a texture of its own), of any size
(the renderer's have half the distance map's texels per side: skinlab/render/translucency.py
part_layer_size); row 0 at texture v = 0 (GL order), read texel by texel (texelFetch: the bilinear
weights are computed, not the sampler's, so the twin is exact to fp32)."""

from __future__ import annotations

import numpy as np

from .boundary import BoundaryTables
from .slab import slab_exit, slab_exit_tables, slab_table, slab_through

NO_SURFACE = 1e29  # a distance-map texel at or above this holds no surface (cleared to 1e30)


def _points(world) -> np.ndarray:
    return np.atleast_2d(np.asarray(world, np.float64))


def part_layers(exit_map, shadow_matrix, world) -> np.ndarray:
    """(N, 3) at the layers' texel containing each point (clamped to the layers): the first part's
    exit, its cosine to the light, the entry into the next part (NO_SURFACE-like 1e30 where the
    layers hold none). GLSL part_layers."""
    world = _points(world)
    ex = np.asarray(exit_map, np.float64)
    nxt = ex[..., 2] if ex.shape[-1] > 2 else np.full(ex.shape[:2], 1e30)
    h, w = ex.shape[:2]
    p = np.concatenate([world, np.ones((len(world), 1))], 1) @ np.asarray(shadow_matrix, np.float64).T
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = np.nan_to_num(p[:, :2] / p[:, 3:4], nan=0.0, posinf=0.0, neginf=0.0)
    i = np.clip(np.floor(uv[:, 0] * w), 0, w - 1).astype(np.int64)
    j = np.clip(np.floor(uv[:, 1] * h), 0, h - 1).astype(np.int64)
    return np.stack([ex[j, i, 0], ex[j, i, 1], nxt[j, i]], 1)


def _distance_quad(dist: np.ndarray, shadow_matrix, world: np.ndarray):
    """The four texel centres of the distance map `dist` (H, W) around each point's light-space
    position, clamped to the map (GLSL distance_quad): inside (the position in the map), uv (0 where
    outside), the bilinear fractions (fx, fy), the texel indices (ia, ib, ja, jb) and their distances
    (d00, d10, d01, d11)."""
    h, w = dist.shape
    p = np.concatenate([world, np.ones((len(world), 1))], 1) @ np.asarray(shadow_matrix, np.float64).T
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = p[:, :2] / p[:, 3:4]
    inside = np.all((uv >= 0.0) & (uv <= 1.0), axis=1)
    uv = np.where(inside[:, None], uv, 0.0)
    x, y = uv[:, 0] * w - 0.5, uv[:, 1] * h - 0.5
    i0, j0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    fx, fy = x - i0, y - j0
    ia, ib = np.clip(i0, 0, w - 1), np.clip(i0 + 1, 0, w - 1)
    ja, jb = np.clip(j0, 0, h - 1), np.clip(j0 + 1, 0, h - 1)
    corners = (dist[ja, ia], dist[ja, ib], dist[jb, ia], dist[jb, ib])
    return inside, uv, (fx, fy), (ia, ib, ja, jb), corners


def first_hit_distance(distance_map, shadow_matrix, world) -> tuple[np.ndarray, np.ndarray]:
    """(first, hit) per point of world (N, 3): the map's distance at the point's light-space
    position, bilinear between the four nearest texel centres (clamped to the map) where all four
    hold a surface, else the texel containing the point; hit False outside the map or where that
    texel holds no surface (first 0 outside). GLSL first_hit_distance."""
    dist = np.asarray(distance_map, np.float64)
    h, w = dist.shape
    inside, uv, (fx, fy), _, (d00, d10, d01, d11) = _distance_quad(dist, shadow_matrix, _points(world))
    bilinear = (d00 * (1 - fx) + d10 * fx) * (1 - fy) + (d01 * (1 - fx) + d11 * fx) * fy
    all4 = np.maximum(np.maximum(d00, d10), np.maximum(d01, d11)) < NO_SURFACE
    i = np.clip(np.floor(uv[:, 0] * w).astype(np.int64), 0, w - 1)
    j = np.clip(np.floor(uv[:, 1] * h).astype(np.int64), 0, h - 1)
    nearest = dist[j, i]
    first = np.where(inside, np.where(all4, bilinear, nearest), 0.0)
    return first, inside & (all4 | (nearest < NO_SURFACE))


def entry_face(distance_map, shadow_matrix, eye, world) -> np.ndarray:
    """(N, 4) the face where a directional light (eye w = 0) entered the part in front of each point
    (the first surface it meets on the way there): its outward normal (toward the light) and its cosine
    to the light, from the distance map's slope across the four texel centres first_hit_distance
    interpolates (the bilinear's gradient, scene units per scene unit across the light's orthographic
    view: the matrix's rows scale world to uv): (grad z, -1) / sqrt(1 + |grad z|^2) in the view's frame;
    no slope across a clamped neighbour (the map's border). 0 where unknown: a point light, outside
    the map, or one of the four texels without a surface. GLSL entry_face."""
    world = _points(world)
    eye = np.asarray(eye, np.float64).reshape(4)
    if eye[3] != 0.0:
        return np.zeros((len(world), 4))
    m = np.asarray(shadow_matrix, np.float64)
    dist = np.asarray(distance_map, np.float64)
    h, w = dist.shape
    inside, _, (fx, fy), (ia, ib, ja, jb), (d00, d10, d01, d11) = _distance_quad(dist, m, world)
    all4 = np.maximum(np.maximum(d00, d10), np.maximum(d01, d11)) < NO_SURFACE
    rows = m[:2, :3]
    texel = 1.0 / (np.array([w, h], np.float64) * np.linalg.norm(rows, axis=1))
    with np.errstate(invalid="ignore", over="ignore"):
        gx = ((d10 - d00) * (1 - fy) + (d11 - d01) * fy) / texel[0]
        gy = ((d01 - d00) * (1 - fx) + (d11 - d10) * fx) / texel[1]
        gx, gy = np.where(ib > ia, gx, 0.0), np.where(jb > ja, gy, 0.0)
        c = 1.0 / np.sqrt(1.0 + gx * gx + gy * gy)
        axes = rows / np.linalg.norm(rows, axis=1, keepdims=True)
        n = (gx[:, None] * axes[0] + gy[:, None] * axes[1] - eye[:3]) * c[:, None]
    ok = (inside & all4)[:, None]
    return np.where(ok, np.concatenate([n, c[:, None]], 1), 0.0)


def through_cosine(
    distance_map, shadow_matrix, eye, world, normal, back, shrink, exit_map=None, part_gap=0.0
) -> np.ndarray:
    """(N,) the cosine at which light through the part in front of each point is taken to cross it:
    where the part is a sheet (the entry face, entry_face at the lookup point world - shrink normal,
    faces away from the point's own: their normals opposed) the larger of the point's own (`back`) and
    the entry face's; `back` where the light skims through a bulge (the normals on one side), where the
    entry face is unknown and where the point lies past the first part's exit (the layered case). The
    thickness is the chord times it and the light enters at it (thickness_mm, translucent_irradiance,
    translucent_exit with it as `back`). GLSL sss_through_cosine."""
    normal = _points(normal)
    p = _points(world) - float(shrink) * normal
    back = np.asarray(back, np.float64).reshape(-1)
    f = entry_face(distance_map, shadow_matrix, eye, p)
    sheet = (f[:, 3] > 0.0) & ((normal * f[:, :3]).sum(1) < 0.0)
    c = np.where(sheet, np.maximum(f[:, 3], back), back)
    if exit_map is not None:
        lay = part_layers(exit_map, shadow_matrix, p)
        other = (lay[:, 0] < NO_SURFACE) & (distance_from_light(eye, p) > lay[:, 0] + float(part_gap))
        c = np.where(other, back, c)
    return c


def distance_from_light(eye, world) -> np.ndarray:
    """Distance from the light along its travel (directional: eye = (direction it travels, 0)) or to
    its position (point: eye = (position, 1)); scene units. GLSL distance_from_light."""
    eye = np.asarray(eye, np.float64).reshape(4)
    world = _points(world)
    return world @ eye[:3] if eye[3] == 0.0 else np.linalg.norm(world - eye[:3], axis=1)


def thickness_mm(
    distance_map, shadow_matrix, eye, world, normal, back, shrink, mm_per_unit, exit_map=None, part_gap=0.0
):
    """(d_mm, hit): the thickness (mm, along the normal) of matter between the light and each point;
    normal (N, 3) the outward geometric normal, back (N,) its cosine with the direction the light
    travels, shrink and part_gap in scene units; exit_map (the part layers, module docstring) None:
    one part. GLSL sss_thickness_mm."""
    p = _points(world) - float(shrink) * _points(normal)
    first, hit = first_hit_distance(distance_map, shadow_matrix, p)
    at = distance_from_light(eye, p)
    back = np.asarray(back, np.float64)
    inside = at - first
    d = np.where(inside > 0.0, (inside * back + float(shrink)) * float(mm_per_unit), 0.0)
    if exit_map is not None:
        lay = part_layers(exit_map, shadow_matrix, p)
        other = (lay[:, 0] < NO_SURFACE) & (at > lay[:, 0] + float(part_gap))
        own = np.where(lay[:, 2] < at, at - lay[:, 2], 0.0)
        through_both = np.maximum(lay[:, 0] - first, 0.0) * lay[:, 1] + own * back
        d = np.where(other, (through_both + float(shrink)) * float(mm_per_unit), d)
    return np.where(hit, d, 0.0), hit


def through(back, d_mm, tables: BoundaryTables, medium, colour) -> np.ndarray:
    """(N, 3): of the irradiance on a surface facing the light, per unit base colour, what crosses a
    slab d_mm thick lit at cosine `back` on its far side and leaves through this side: the exact slab
    transmittance (skinlab/scene/optics/slab.py slab_through, at the boundary's index `tables.eta`). `medium`:
    the material's medium (alpha_arr, mfp_arr), `colour` its subsurface_color (the table is per unit
    of it): what skinlab/render/boundary.py binds. GLSL sss_through."""
    back = np.atleast_1d(np.asarray(back, np.float64))
    d = np.broadcast_to(np.atleast_1d(np.asarray(d_mm, np.float64)), back.shape)
    table = slab_table(medium.alpha_arr, colour)
    return slab_through(back, d, table, medium.mfp_arr, medium.alpha_arr, tables.eta).reshape(-1, 3)


def through_incidence(c, depth_mm, tables: BoundaryTables, medium, colour) -> np.ndarray:
    """(N, 3): what light entering at cosine `c` changes of the light a part `depth_mm` thick lets through,
    for weights made for light entering along the normal (the transfer through the medium's,
    skinlab/scene/optics/through_kernel.py): through(c, d) / through(1, d), and 1 where through(1, d) is not
    above 1e-30 (no depth: a vertex whose rays met nothing, where the slab lets nothing through; or a part
    too thick for the light to be a float). GLSL sss_through_incidence (lib/sss_translucency.glsl)."""
    c = np.atleast_1d(np.asarray(c, np.float64))
    d = np.broadcast_to(np.atleast_1d(np.asarray(depth_mm, np.float64)), c.shape)
    at_c = through(c, d, tables, medium, colour)
    normal = through(np.ones_like(c), d, tables, medium, colour)
    return np.where(normal > 1e-30, at_c / np.maximum(normal, 1e-30), 1.0)


def translucent_irradiance(e, back, d_mm, hit, tables: BoundaryTables, medium, colour) -> np.ndarray:
    """(N, 3) irradiance entering through thin parts from one light of irradiance e (3,) on a surface
    facing it: e back through(back, d) where the light is behind the surface (back > 0) and the map
    has a surface in front (hit); 0 elsewhere. GLSL sss_translucent_light."""
    back = np.atleast_1d(np.asarray(back, np.float64))
    ok = (back > 0) & np.asarray(hit, bool)
    t = through(np.where(ok, back, 1.0), np.where(ok, d_mm, 0.0), tables, medium, colour)
    return np.where(ok[:, None], np.asarray(e, np.float64).reshape(1, 3) * back[:, None] * t, 0.0)


def translucent_exit(mu, back, d_mm, tables: BoundaryTables, medium, colour) -> np.ndarray:
    """(N, 3) the exit factor of the light through thin parts toward a viewer at cosine mu (light that
    arrived at cosine `back` on the far face of a part d_mm thick): skinlab/scene/optics/slab.py slab_exit with
    the material's tables (what skinlab/render/boundary.py binds). Radiance: base colour / pi x
    translucent_irradiance x this (the reflected light's exit(mu) is boundary.py's). GLSL: the factor
    sss_translucent_light_toward applies (sss_slab_exit(mu, back, d_mm))."""
    mu = np.atleast_1d(np.asarray(mu, np.float64))
    back = np.broadcast_to(np.atleast_1d(np.asarray(back, np.float64)), mu.shape)
    d = np.broadcast_to(np.atleast_1d(np.asarray(d_mm, np.float64)), mu.shape)
    table = slab_table(medium.alpha_arr, colour)
    ex = slab_exit_tables(medium.alpha_arr, table, tables.eta)
    out = [slab_exit(m, b, x, table, ex, medium.mfp_arr, tables.eta) for m, b, x in zip(mu, back, d)]
    return np.array(out, np.float64).reshape(-1, 3)
