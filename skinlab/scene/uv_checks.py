"""UV-layout checks for texture-space diffusion (d'Eon & Luebke 2007).

Texture-space diffusion renders each mesh's irradiance into a square UV texture of
``texels`` x ``texels`` texels (``TsdSettings.size``) and blurs it there with kernels measured
in millimetres. That only works when the UV layout is a faithful, non-overlapping map of the
surface, and the blur needs to know how many millimetres one texel spans. ``analyse_uvs``
measures both, in pure NumPy:

- per triangle, the Jacobian J = dP/d(u, v) (solving [p1-p0, p2-p0] = J [uv1-uv0, uv2-uv0]) and from
  it the world millimetres per texel along u and along v: |J[:, 0]| * mm_per_unit * model_scale / texels
  and likewise |J[:, 1]|; area-weighted percentiles of those over the mesh;
- degenerate triangles: zero UV area (never rasterised in UV space: their surface gets no
  irradiance) and zero world area with non-zero UV area (infinite stretch);
- triangles with UVs outside [0, 1] (clamped or wrapped by the texture);
- UV overlap and coverage, by rasterising every triangle into a ``grid`` x ``grid`` count raster
  with texel centres at ((i + 0.5) / grid, (j + 0.5) / grid). Vertices are snapped to 1/256 of a
  texel and edge functions are evaluated exactly on those integer coordinates with a half-open
  (top-left style) rule, so two triangles sharing an edge or a vertex never both cover a texel
  and never both miss it: a clean layout reads exactly 0 overlap.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .mesh import Mesh

UV_AREA_EPS = 1e-12  # UV-space triangle area (unit square = 1) at or below which a triangle is zero-UV-area
WORLD_AREA_REL_EPS = 1e-12  # world area at or below this times (bbox diagonal)^2 is zero-world-area
# zero-UV-area triangles get no irradiance; below this share of the surface that is invisible, and it
# is a note in the frame plan (--explain) instead of a warning on every render (the head and the bunny's
# atlas have a dozen slivers, 0.003 % of their surface)
ZERO_UV_SURFACE_WARN = 1e-4
OVERLAP_WARN = 0.01  # warn when more than this fraction of covered texels is covered twice or more
SUBTEXEL = 256  # vertex snapping: 1/SUBTEXEL of a raster texel (like a GPU's sub-pixel bits)
_CHUNK = 1 << 20  # raster candidates (texel, triangle) evaluated per NumPy batch
_PERCENTILES = (("p10", 0.10), ("p50", 0.50), ("p90", 0.90))


@dataclass(frozen=True)
class UVReport:
    """What ``analyse_uvs`` found. Without UVs (``has_uvs`` False) the UV-dependent fields are
    0 (counts) or nan (fractions, ``mm_per_texel``, percentiles) and ``zero_area_world`` counts every
    triangle of (near-)zero world area."""

    mesh: str  # mesh name
    has_uvs: bool
    triangles: int
    zero_area_world: int  # (near-)zero world area but non-zero UV area ("infinite stretch")
    zero_area_uv: int  # (near-)zero UV area: not rasterised in UV space, no irradiance
    out_of_range: int  # any UV outside [0, 1] (or not finite)
    overlap_fraction: float  # of covered raster texels, the fraction covered by 2+ triangles (0 if none covered)
    uv_coverage: float  # fraction of the unit UV square covered
    mm_per_texel: np.ndarray = field(repr=False)  # (T, 2): mm per texel along u, v; nan for zero-UV-area
    #                                 (and non-finite-UV) triangles, 0 for zero-world-area ones
    mm_per_texel_percentiles: dict = field(default_factory=dict)  # {"p10": (u, v), "p50": ..., "p90": ...},
    #                                 world-area weighted; nan when no triangle has finite values and positive area
    texels: int = 1024
    grid: int = 512
    zero_area_uv_surface: float = 0.0  # fraction of the mesh's world area in zero-UV-area triangles

    def notes(self) -> list[str]:
        """Harmless findings worth a line in an explanation: zero-UV-area slivers below the warning share."""
        if self.has_uvs and self.zero_area_uv and self.zero_area_uv_surface < ZERO_UV_SURFACE_WARN:
            return [
                f"{self.zero_area_uv} of {self.triangles} triangles have (near-)zero UV area: not rasterised, no "
                f"irradiance; {100 * self.zero_area_uv_surface:.2g} % of the surface, under the "
                f"{100 * ZERO_UV_SURFACE_WARN:g} % that would be visible (so no warning)"
            ]
        return []

    def warnings(self) -> list[str]:
        """Human-readable problems, each naming the mesh; empty when the layout is clean."""
        where = f"mesh {self.mesh!r}"
        out: list[str] = []
        if not self.has_uvs:
            out.append(
                f"{where} has no UV coordinates: texture-space diffusion renders irradiance into UV space "
                f"and needs them; Mesh.ensure_uvs() or generate_uvs = true in the scene file makes an xatlas atlas "
                f"(cached by mesh content)"
            )
            if self.zero_area_world:
                out.append(f"{where}: {self.zero_area_world} of {self.triangles} triangles have (near-)zero world area")
            return out
        if self.zero_area_uv and self.zero_area_uv_surface >= ZERO_UV_SURFACE_WARN:
            out.append(
                f"{where}: {self.zero_area_uv} of {self.triangles} triangles "
                f"({100 * self.zero_area_uv_surface:.2g} % of its surface) have (near-)zero UV area; they are "
                f"not rasterised in UV space, so their surface gets no irradiance"
            )
        if self.zero_area_world:
            out.append(
                f"{where}: {self.zero_area_world} of {self.triangles} triangles have (near-)zero world area but "
                f"non-zero UV area (infinite stretch: their texels map onto no surface)"
            )
        if self.out_of_range:
            out.append(
                f"{where}: {self.out_of_range} of {self.triangles} triangles have UVs outside [0, 1]; the "
                f"irradiance texture clamps or wraps them onto other parts of the layout"
            )
        if self.overlap_fraction > OVERLAP_WARN:
            out.append(
                f"{where}: UV overlap: {100 * self.overlap_fraction:.1f}% of covered texels "
                f"({self.grid}x{self.grid} raster) are covered by 2 or more triangles, which would share "
                f"(and blur together) irradiance"
            )
        return out


def _check_params(mm_per_unit, texels, grid, model_scale) -> None:
    for name, v in (("mm_per_unit", mm_per_unit), ("model_scale", model_scale)):
        if not np.isfinite(v) or v <= 0:
            raise ValueError(f"analyse_uvs: {name} must be a positive finite number, got {v!r}")
    for name, v in (("texels", texels), ("grid", grid)):
        if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or not 1 <= v <= 65536:
            raise ValueError(f"analyse_uvs: {name} must be an integer in [1, 65536], got {v!r}")


def analyse_uvs(
    mesh: Mesh, mm_per_unit: float, texels: int = 1024, grid: int = 512, model_scale: float = 1.0
) -> UVReport:
    """Check ``mesh``'s UV layout for texture-space diffusion into a ``texels``-square texture.

    ``mm_per_unit`` is the scene's physical scale and ``model_scale`` any extra uniform scale of the
    node drawing the mesh; ``grid`` is the resolution of the overlap/coverage raster."""
    _check_params(mm_per_unit, texels, grid, model_scale)
    f = mesh.indices.astype(np.int64)
    p = mesh.positions.astype(np.float64)
    T = len(f)
    e1, e2 = p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]
    world_area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    lo, hi = mesh.bounds
    diag2 = float(np.sum((hi - lo) ** 2))
    world_zero = world_area <= WORLD_AREA_REL_EPS * diag2

    if mesh.uvs is None:
        nan2 = (float("nan"), float("nan"))
        return UVReport(
            mesh.name,
            False,
            T,
            int(world_zero.sum()),
            0,
            0,
            float("nan"),
            float("nan"),
            np.full((T, 2), np.nan),
            {k: nan2 for k, _ in _PERCENTILES},
            int(texels),
            int(grid),
        )

    uv = np.asarray(mesh.uvs, np.float64)
    if uv.shape != (len(p), 2):
        raise ValueError(f"mesh {mesh.name!r}: uvs must be ({len(p)}, 2), got {uv.shape}")
    tuv = uv[f]  # (T, 3, 2)
    finite = np.asarray(np.isfinite(tuv).all(axis=(1, 2)))
    tuv = np.where(finite[:, None, None], tuv, 0.0)  # keep the arithmetic NaN-free
    d1, d2 = tuv[:, 1] - tuv[:, 0], tuv[:, 2] - tuv[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    uv_zero = finite & (0.5 * np.abs(det) < UV_AREA_EPS)
    stretch_inf = finite & ~uv_zero & world_zero
    good = finite & ~uv_zero & ~world_zero

    # J = E D^-1 with E = [e1 e2] (3x2), D = [d1 d2] (2x2)
    inv = np.where(good, 1.0 / np.where(good, det, 1.0), 0.0)[:, None]
    ju = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * inv
    jv = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * inv
    mm = (
        np.stack([np.linalg.norm(ju, axis=1), np.linalg.norm(jv, axis=1)], axis=1)
        * (mm_per_unit * model_scale)
        / texels
    )
    mm[~finite | uv_zero] = np.nan
    mm[stretch_inf] = 0.0

    weights = world_area * (mm_per_unit * model_scale) ** 2
    pct = _weighted_percentiles(mm[good], weights[good])

    outside = ~finite | ((tuv < 0.0) | (tuv > 1.0)).any(axis=(1, 2))
    counts = _raster_counts(tuv[finite & ~uv_zero], int(grid))
    covered = int(np.count_nonzero(counts))
    multi = int(np.count_nonzero(counts >= 2))
    return UVReport(
        mesh=mesh.name,
        has_uvs=True,
        triangles=T,
        zero_area_world=int(stretch_inf.sum()),
        zero_area_uv=int(uv_zero.sum()),
        out_of_range=int(outside.sum()),
        overlap_fraction=multi / covered if covered else 0.0,
        uv_coverage=covered / float(grid * grid),
        mm_per_texel=mm,
        mm_per_texel_percentiles=pct,
        zero_area_uv_surface=float(world_area[uv_zero].sum() / world_area.sum()) if world_area.sum() > 0 else 0.0,
        texels=int(texels),
        grid=int(grid),
    )


def _weighted_percentiles(values: np.ndarray, weights: np.ndarray) -> dict:
    """Per column, the smallest value whose cumulative weight reaches q of the total (inverted CDF);
    nan when there is no positive weight."""
    out = {}
    keep = weights > 0
    values, weights = values[keep], weights[keep]
    total = weights.sum()
    cols: list[tuple[np.ndarray, np.ndarray] | None] = []
    for c in range(values.shape[1] if values.ndim == 2 else 2):
        if not len(values) or not total > 0:
            cols.append(None)
            continue
        order = np.argsort(values[:, c], kind="stable")
        cols.append((values[order, c], np.cumsum(weights[order])))
    for key, q in _PERCENTILES:
        pair = []
        for col in cols:
            if col is None:
                pair.append(float("nan"))
            else:
                v, cum = col
                i = min(int(np.searchsorted(cum, q * cum[-1], side="left")), len(v) - 1)
                pair.append(float(v[i]))
        out[key] = tuple(pair)
    return out


def _raster_counts(tuv: np.ndarray, grid: int) -> np.ndarray:
    """How many triangles cover each texel centre of a ``grid`` x ``grid`` raster (flat, row-major, v rows).

    Coordinates are snapped to integers (1/SUBTEXEL texel) and edge functions are exact in float64
    for any layout within a few hundred UV units of the square, so shared edges are decided the same
    way from both sides: a centre on an edge belongs to the triangle that owns that edge (directed
    edge with dy > 0, or dy == 0 and dx < 0, after orienting every triangle counter-clockwise)."""
    counts = np.zeros(grid * grid, np.int64)
    if not len(tuv):
        return counts
    S = float(SUBTEXEL)
    q = np.rint(tuv * (grid * S))  # (n, 3, 2) integer-valued float64
    x, y = q[..., 0], q[..., 1]
    area2 = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
    flip = area2 < 0
    x[flip] = x[flip][:, [0, 2, 1]]
    y[flip] = y[flip][:, [0, 2, 1]]
    half = S / 2.0
    # texel index ranges whose centres (i * S + S/2) lie inside the bounding box, clipped to the raster
    i0 = np.maximum(np.ceil((x.min(1) - half) / S), 0).astype(np.int64)
    i1 = np.minimum(np.floor((x.max(1) - half) / S), grid - 1).astype(np.int64)
    j0 = np.maximum(np.ceil((y.min(1) - half) / S), 0).astype(np.int64)
    j1 = np.minimum(np.floor((y.max(1) - half) / S), grid - 1).astype(np.int64)
    keep = (area2 != 0) & (i1 >= i0) & (j1 >= j0)
    if not keep.any():
        return counts
    x, y, i0, i1, j0, j1 = x[keep], y[keep], i0[keep], i1[keep], j0[keep], j1[keep]
    W, H = i1 - i0 + 1, j1 - j0 + 1

    # edge k runs from vertex k to vertex k+1; E_k(p) = (bx-ax)(py-ay) - (by-ay)(px-ax) > 0 inside
    ax, ay = x, y
    bx, by = np.roll(x, -1, axis=1), np.roll(y, -1, axis=1)
    dx, dy = bx - ax, by - ay
    owned = (dy > 0) | ((dy == 0) & (dx < 0))
    cx0, cy0 = (i0 * S + half)[:, None], (j0 * S + half)[:, None]
    e0 = dx * (cy0 - ay) - dy * (cx0 - ax) + owned  # E at the box's first centre, +1 on owned edges:
    stepx, stepy = -dy * S, dx * S  # inside iff E + owned > 0 (E is integer-valued)

    # one row per (triangle, texel row of its box), then one candidate per texel of that row
    nt = len(W)
    row_t = np.repeat(np.arange(nt), H)
    row_j = np.arange(len(row_t)) - np.repeat(np.cumsum(H) - H, H)
    row_e = e0[row_t] + stepy[row_t] * row_j[:, None]  # (R, 3)
    row_w = W[row_t]
    row_base = (j0[row_t] + row_j) * grid + i0[row_t]  # flat index of the row's first texel
    row_sx = stepx[row_t]
    ends = np.cumsum(row_w)
    r = 0
    while r < len(row_w):
        r1 = max(int(np.searchsorted(ends, (ends[r - 1] if r else 0) + _CHUNK, side="right")), r + 1)
        w = row_w[r:r1]
        rr = np.repeat(np.arange(r, r1), w)
        i = np.arange(len(rr)) - np.repeat(np.cumsum(w) - w, w)
        e = row_e[rr] + row_sx[rr] * i[:, None]
        inside = (e > 0).all(axis=1)
        counts += np.bincount(row_base[rr[inside]] + i[inside], minlength=grid * grid)
        r = r1
    return counts
