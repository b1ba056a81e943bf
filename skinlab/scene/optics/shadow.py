"""NumPy twins of skinlab/shaders/lib/shadow.glsl (and lib/shadow_soft.glsl, below) for a depth-compare
sampler with clamp-to-edge addressing and compare function '<='. shadow_pcf is the renderer's 3x3 PCF
of bilinear (LINEAR) compare taps, which lib/shadow.glsl computes with four textureGather calls (each
2 x 2 compares, exactly 0 or 1) and its own weights in fp32: the twin to fp32 rounding, whatever the
texture's filter mode (a gather ignores it). The other lookups' taps are twinned with NEAREST
filtering (each tap exactly 0 or 1, so the twin is exact); the renderer samples them with LINEAR
compare filtering, whose bilinear weights are implementation precision (llvmpipe's, for a depth
texture, are float: its 9-tap PCF of before was within 1.1e-6 of the exact bilinear one); those are
not part of the twin.

The depth bias is sized to the map's texel at the receiver (constants.py SHADOW_BIAS_TEXELS,
SHADOW_SLOPE_TEXELS, SHADOW_SLOPE_MAX): a texel and a bounded slope term, so that a lit surface
stays lit under the 3x3 PCF and light leaks at most a few texels behind an occluder, whatever the
scene's scale and the light's angle."""

from __future__ import annotations

import numpy as np

from .constants import (
    SHADOW_AREA_MIN_TEXELS,
    SHADOW_AREA_TAPS,
    SHADOW_BIAS_TEXELS,
    SHADOW_BOX_CELLS,
    SHADOW_BOX_TEXELS,
    SHADOW_FIT_REACH,
    SHADOW_SLOPE_MAX,
    SHADOW_SLOPE_TEXELS,
)


def _light_space(shadow_matrix, world) -> tuple[np.ndarray, np.ndarray]:
    m = np.asarray(shadow_matrix, np.float64)
    world = np.atleast_2d(np.asarray(world, np.float64))
    p = np.concatenate([world, np.ones((len(world), 1))], 1) @ m.T
    return m, p


def shadow_texel_scale(shadow_matrix, world, size) -> tuple[np.ndarray, np.ndarray]:
    """(texel, depth_per_unit) at each point of world (N, 3) for a map of size (width, height): the
    side of the map's texel there in world units (the larger of its two sides) and the texture depth
    per world unit along the light. GLSL shadow_texel_scale."""
    m, p = _light_space(shadow_matrix, world)
    c = p[:, :3] / p[:, 3:4]
    w = np.abs(p[:, 3])
    r0, r1, r2, r3 = (m[k, :3][None, :] for k in range(4))
    gu = np.linalg.norm(r0 - c[:, 0:1] * r3, axis=1) * float(size[0])
    gv = np.linalg.norm(r1 - c[:, 1:2] * r3, axis=1) * float(size[1])
    per_unit = np.minimum(gu, gv) / w
    return 1.0 / np.maximum(per_unit, 1e-30), np.linalg.norm(r2 - c[:, 2:3] * r3, axis=1) / w


def shadow_bias(NoL, shadow_matrix, world, size) -> np.ndarray:
    """Depth bias (texture depth units) per point: texel x (SHADOW_BIAS_TEXELS + SHADOW_SLOPE_TEXELS
    x min(tan theta, SHADOW_SLOPE_MAX)), theta the angle whose cosine is NoL. GLSL shadow_bias."""
    cosl = np.clip(np.asarray(NoL, np.float64), 1e-3, 1.0)
    slope = np.minimum(np.sqrt(1.0 - cosl * cosl) / cosl, SHADOW_SLOPE_MAX)
    texel, depth = shadow_texel_scale(shadow_matrix, world, size)
    return texel * depth * (SHADOW_BIAS_TEXELS + SHADOW_SLOPE_TEXELS * slope)


def shadow_pcf(
    depth_map: np.ndarray, shadow_matrix: np.ndarray, world: np.ndarray, NoL, nearest: bool = False
) -> np.ndarray:
    """The 3x3 PCF at each point. depth_map: (H, W) with row 0 at texture v = 0 (GL order). world: (N, 3).
    The nine taps at offsets -1, 0, +1 texel, each bilinear: with t = uv x size - 1/2, b = floor(t) and
    f = t - b, the 4 x 4 texels from b - 1 to b + 2 weighted 1 - f, 1, 1, f per axis, / 9 (GLSL
    shadow_pcf's textureGather path). `nearest`: the nine taps with NEAREST filtering instead (GLSL's
    fallback without textureGather, on a NEAREST texture)."""
    m, p = _light_space(shadow_matrix, world)
    c = p[:, :3] / p[:, 3:4]
    outside = (c < 0).any(1) | (c > 1).any(1)
    h, w = depth_map.shape
    ref = c[:, 2] - shadow_bias(NoL, m, world, (w, h))
    total = np.zeros(len(c))
    if nearest:
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                u = c[:, 0] + dx / w
                v = c[:, 1] + dy / h
                i = np.clip(np.floor(u * w).astype(np.int64), 0, w - 1)
                j = np.clip(np.floor(v * h).astype(np.int64), 0, h - 1)
                total += (ref <= depth_map[j, i]).astype(np.float64)
    else:  # the outer weights as lerps, as GLSL's: a wholly lit (shadowed) footprint reads exactly 1 (0)
        tu, tv = c[:, 0] * w - 0.5, c[:, 1] * h - 0.5
        bu, bv = np.floor(tu), np.floor(tv)
        fu, fv = tu - bu, tv - bv
        i = [np.clip(bu.astype(np.int64) + k - 1, 0, w - 1) for k in range(4)]
        rows = []
        for k in range(4):
            j = np.clip(bv.astype(np.int64) + k - 1, 0, h - 1)
            s0, s1, s2, s3 = ((ref <= depth_map[j, ik]).astype(np.float64) for ik in i)
            rows.append((s1 + s2) + (s0 + fu * (s3 - s0)))
        total = (rows[1] + rows[2]) + (rows[0] + fv * (rows[3] - rows[0]))
    return np.where(outside, 1.0, total / 9.0)


def shadow_tap(depth_map: np.ndarray, shadow_matrix: np.ndarray, world: np.ndarray, NoL) -> np.ndarray:
    """One bilinear compare tap at each point (a LINEAR depth-compare texture): the four texels around
    uv x size - 1/2 compared with the biased depth (shadow_bias), weighted bilinearly, clamped to the
    map's edge; 1 outside the map. GLSL shadow_tap."""
    m, p = _light_space(shadow_matrix, world)
    c = p[:, :3] / p[:, 3:4]
    outside = (c < 0).any(1) | (c > 1).any(1)
    h, w = depth_map.shape
    ref = c[:, 2] - shadow_bias(NoL, m, world, (w, h))
    tu, tv = c[:, 0] * w - 0.5, c[:, 1] * h - 0.5
    bu, bv = np.floor(tu), np.floor(tv)
    fu, fv = tu - bu, tv - bv
    i0, i1 = (np.clip(bu.astype(np.int64) + k, 0, w - 1) for k in (0, 1))
    j0, j1 = (np.clip(bv.astype(np.int64) + k, 0, h - 1) for k in (0, 1))
    lit = lambda j, i: (ref <= depth_map[j, i]).astype(np.float64)  # noqa: E731
    row0 = lit(j0, i0) * (1.0 - fu) + lit(j0, i1) * fu
    row1 = lit(j1, i0) * (1.0 - fu) + lit(j1, i1) * fu
    return np.where(outside, 1.0, row0 * (1.0 - fv) + row1 * fv)


def shadow_pcf_area(
    depth_map: np.ndarray, shadow_matrix: np.ndarray, world: np.ndarray, NoL, du, dv, nearest: bool = False
) -> np.ndarray:
    """The visibility averaged over each receiver's footprint, the parallelogram spanned by the world
    vectors du and dv (N, 3) centred on world (N, 3) (a texture-space texel's; GLSL shadow_pcf_area):
    shadow_pcf (with `nearest`) where the footprint spans at most SHADOW_AREA_MIN_TEXELS of the map's
    texels along both sides, else ceil(e) taps along a side spanning e texels (at most
    SHADOW_AREA_TAPS), each a NEAREST compare at its own depth on the footprint's plane with
    shadow_pcf's bias at the centre."""
    m, p = _light_space(shadow_matrix, world)
    world = np.atleast_2d(np.asarray(world, np.float64))
    c = p[:, :3] / p[:, 3:4]
    outside = (c < 0).any(1) | (c > 1).any(1)
    h, w = depth_map.shape
    _, pa = _light_space(m, world + np.atleast_2d(np.asarray(du, np.float64)))
    _, pb = _light_space(m, world + np.atleast_2d(np.asarray(dv, np.float64)))
    a = pa[:, :3] / pa[:, 3:4] - c
    b = pb[:, :3] / pb[:, 3:4] - c
    ea = np.hypot(a[:, 0] * w, a[:, 1] * h)
    eb = np.hypot(b[:, 0] * w, b[:, 1] * h)
    na = np.clip(np.ceil(ea), 1, SHADOW_AREA_TAPS).astype(np.int64)
    nb = np.clip(np.ceil(eb), 1, SHADOW_AREA_TAPS).astype(np.int64)
    bias = shadow_bias(NoL, m, world, (w, h))
    total = np.zeros(len(c))
    for j in range(SHADOW_AREA_TAPS):
        for i in range(SHADOW_AREA_TAPS):
            on = (i < na) & (j < nb)
            s = (i + 0.5) / na - 0.5
            t = (j + 0.5) / nb - 0.5
            q = c + s[:, None] * a + t[:, None] * b
            lit = q[:, 2] - bias <= _nearest(depth_map, q[:, 0], q[:, 1])
            total += np.where(on, lit, 0.0)
    area = total / (na * nb)
    small = np.maximum(ea, eb) <= SHADOW_AREA_MIN_TEXELS
    return np.where(outside, 1.0, np.where(small, shadow_pcf(depth_map, m, world, NoL, nearest), area))


def in_window(fine_matrix, world, size, reach) -> np.ndarray:
    """Whether each point's lookup in a map fitted to the view (skinlab/render/shadow_fit.py; GLSL
    shadow_in_window) lies within it: its texel position at least `reach` (N,) or a scalar texels from
    every edge of the map `size` (w, h) texels, in front of it (w > 0)."""
    _, p = _light_space(fine_matrix, world)
    w = p[:, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        c = p[:, :2] / np.where(w > 0, w, 1.0)[:, None] * np.asarray(size, np.float64)
    r = np.asarray(reach, np.float64).reshape(-1, 1)
    return (w > 0) & (c >= r).all(1) & (c <= np.asarray(size, np.float64) - r).all(1)


def shadow_pcf_fitted(fine_map, fine_matrix, depth_map, shadow_matrix, world, NoL, nearest: bool = False):
    """The fitted map's 3x3 PCF where in_window (SHADOW_FIT_REACH), else the full map's (GLSL
    shadow_pcf_fitted)."""
    h, w = fine_map.shape
    inside = in_window(fine_matrix, world, (w, h), SHADOW_FIT_REACH)
    fine = shadow_pcf(fine_map, fine_matrix, world, NoL, nearest)
    full = shadow_pcf(depth_map, shadow_matrix, world, NoL, nearest)
    return np.where(inside, fine, full)


def shadow_pcf_area_fitted(fine_map, fine_matrix, depth_map, shadow_matrix, world, NoL, du, dv, nearest=False):
    """shadow_pcf_area on the fitted map where the footprint's lookup lies within it (SHADOW_FIT_REACH
    and the footprint's half-extent in its texels), else on the full map (GLSL shadow_pcf_area_fitted)."""
    world = np.atleast_2d(np.asarray(world, np.float64))
    h, w = fine_map.shape
    _, p = _light_space(fine_matrix, world)
    _, pa = _light_space(fine_matrix, world + np.atleast_2d(np.asarray(du, np.float64)))
    _, pb = _light_space(fine_matrix, world + np.atleast_2d(np.asarray(dv, np.float64)))
    c = p[:, :2] / p[:, 3:4]
    half = 0.5 * (np.abs(pa[:, :2] / pa[:, 3:4] - c) + np.abs(pb[:, :2] / pb[:, 3:4] - c)) * [w, h]
    inside = in_window(fine_matrix, world, (w, h), SHADOW_FIT_REACH + half.max(1))
    fine = shadow_pcf_area(fine_map, fine_matrix, world, NoL, du, dv, nearest)
    full = shadow_pcf_area(depth_map, shadow_matrix, world, NoL, du, dv, nearest)
    return np.where(inside, fine, full)


def shadow_box(depth_map, shadow_matrix, world, NoL, w) -> np.ndarray:
    """The compares averaged over a box `w` (N, 2) texels wide centred where each point falls (clamp to
    edge; GLSL shadow_box, whose gathers are NEAREST compares: the twin to fp32 rounding): up to
    SHADOW_BOX_TEXELS wide, each texel weighted by its share of the box; wider, the mean over the box's
    SHADOW_BOX_CELLS^2 cells of the 2 x 2 texels around the texel corner nearest each cell's centre."""
    m, p = _light_space(shadow_matrix, world)
    world = np.atleast_2d(np.asarray(world, np.float64))
    c = p[:, :3] / p[:, 3:4]
    outside = (c < 0).any(1) | (c > 1).any(1)
    h, wd = depth_map.shape
    z = c[:, 2] - shadow_bias(NoL, m, world, (wd, h))
    w = np.atleast_2d(np.asarray(w, np.float64))
    lo = c[:, :2] * [wd, h] - 0.5 * w
    hi = lo + w

    def lit(jx, jy):
        cols = np.clip(jx.astype(np.int64), 0, wd - 1)
        rows = np.clip(jy.astype(np.int64), 0, h - 1)
        return (z <= depth_map[rows, cols]).astype(np.float64)

    exact = np.zeros(len(c))
    j0 = np.floor(lo)
    for ky in range(6):
        jy = j0[:, 1] + ky
        oy = np.maximum(0.0, np.minimum(hi[:, 1], jy + 1) - np.maximum(lo[:, 1], jy))
        for kx in range(6):
            jx = j0[:, 0] + kx
            ox = np.maximum(0.0, np.minimum(hi[:, 0], jx + 1) - np.maximum(lo[:, 0], jx))
            exact += ox * oy * lit(jx, jy)
    exact /= w[:, 0] * w[:, 1]
    sampled = np.zeros(len(c))
    n = SHADOW_BOX_CELLS
    for gy in range(n):
        for gx in range(n):
            k = np.floor(lo + (np.array([gx, gy]) + 0.5) * w / n + 0.5)
            for dx in (-1, 0):
                for dy in (-1, 0):
                    sampled += 0.25 * lit(k[:, 0] + dx, k[:, 1] + dy)
    sampled /= n * n
    return np.where(outside, 1.0, np.where(w.max(1) > SHADOW_BOX_TEXELS, sampled, exact))


def _footprint_texels(m, world, du, dv, size) -> np.ndarray:
    _, p = _light_space(m, world)
    _, pa = _light_space(m, world + np.atleast_2d(np.asarray(du, np.float64)))
    _, pb = _light_space(m, world + np.atleast_2d(np.asarray(dv, np.float64)))
    c = p[:, :2] / p[:, 3:4]
    return (np.abs(pa[:, :2] / pa[:, 3:4] - c) + np.abs(pb[:, :2] / pb[:, 3:4] - c)) * np.asarray(size, np.float64)


def shadow_box_fitted(fine_map, fine_matrix, depth_map, shadow_matrix, world, NoL, du, dv) -> np.ndarray:
    """A screen sample's shadow (GLSL shadow_box_fitted, its gather path): shadow_box over the bounding box
    of the footprint du, dv (N, 3) in the fitted map's texels (at least 1) where the lookup lies within
    it; the full map's 3x3 PCF outside."""
    world = np.atleast_2d(np.asarray(world, np.float64))
    h, wd = fine_map.shape
    w = np.maximum(_footprint_texels(fine_matrix, world, du, dv, (wd, h)), 1.0)
    inside = in_window(fine_matrix, world, (wd, h), SHADOW_FIT_REACH + 0.5 * w.max(1))
    box = shadow_box(fine_map, fine_matrix, world, NoL, w)
    return np.where(inside, box, shadow_pcf(depth_map, shadow_matrix, world, NoL))


SOFT_SEARCH_TAPS = 8  # blocker search taps (lib/shadow_soft.glsl)
SOFT_TAPS = 12  # filter taps
SOFT_SEARCH_TEXELS = 96.0  # the blocker search spans at most this radius (texels)
GOLDEN_ANGLE = 2.399963229728653


def vogel_tap(k: int, n: int = SOFT_TAPS) -> np.ndarray:
    """Tap k of n on a Vogel (golden-angle) disk of radius 1 (lib/shadow_soft.glsl vogel_tap)."""
    r = np.sqrt((k + 0.5) / n)
    a = k * GOLDEN_ANGLE
    return np.array([r * np.cos(a), r * np.sin(a)])


def _nearest(img: np.ndarray, u, v) -> np.ndarray:
    h, w = img.shape
    i = np.clip(np.floor(np.asarray(u) * w).astype(np.int64), 0, w - 1)
    j = np.clip(np.floor(np.asarray(v) * h).astype(np.int64), 0, h - 1)
    return img[j, i]


def shadow_soft(depth_map, dist_map, shadow_matrix, soft, eye, world, NoL, spread2=0.0) -> np.ndarray:
    """Twin of lib/shadow_soft.glsl shadow_soft (shadow_soft_spread with `spread2`, (N,) or a scalar:
    the squared uv radius the filter grows by in quadrature) with NEAREST filtering of both maps
    (each compare tap exactly 0 or 1): maps (H, W) with row 0 at v = 0; soft and eye (4,); world (N, 3)."""
    world = np.atleast_2d(np.asarray(world, np.float64))
    soft, eye = np.asarray(soft, np.float64), np.asarray(eye, np.float64)
    p = np.concatenate([world, np.ones((len(world), 1))], 1) @ np.asarray(shadow_matrix, np.float64).T
    c = p[:, :3] / p[:, 3:4]
    outside = (c < 0).any(1) | (c > 1).any(1)
    d_r = world @ eye[:3] if eye[3] == 0.0 else np.linalg.norm(world - eye[:3], axis=1)
    local = soft[1] > 0.5
    k = soft[2] / np.maximum(d_r, 1e-20) if local else np.full(len(world), soft[2])
    texel = 1.0 / depth_map.shape[1]
    if local:
        nearest = np.maximum(d_r - soft[3], 0.05 * d_r)
        widest = 2.0 * soft[0] * (d_r - nearest) / nearest
    else:
        widest = np.full(len(world), 2.0 * soft[0] * soft[3])
    spread2 = np.broadcast_to(np.asarray(spread2, np.float64), (len(world),))
    search = np.maximum(np.clip(0.5 * widest * k, texel, SOFT_SEARCH_TEXELS * texel), np.sqrt(spread2))
    bias = 2.0 * texel / k
    total = np.zeros(len(world))
    count = np.zeros(len(world))
    for t in range(SOFT_SEARCH_TAPS):
        o = vogel_tap(t, SOFT_SEARCH_TAPS)
        d = _nearest(dist_map, c[:, 0] + o[0] * search, c[:, 1] + o[1] * search)
        hit = d < d_r - bias
        total += np.where(hit, d, 0.0)
        count += hit
    d_b = np.where(count > 0, total / np.maximum(count, 1), d_r)  # no blocker: lit (below)
    w = 2.0 * soft[0] * (d_r - d_b) / np.maximum(d_b, 1e-20) if local else 2.0 * soft[0] * (d_r - d_b)
    radius = np.sqrt(np.maximum(0.5 * w * k, 1.5 * texel) ** 2 + spread2)
    ref = c[:, 2] - shadow_bias(NoL, shadow_matrix, world, depth_map.shape[::-1]) * np.maximum(
        1.0, radius / (1.5 * texel)
    )
    lit = np.zeros(len(world))
    for t in range(SOFT_TAPS):
        o = vogel_tap(t)
        lit += (ref <= _nearest(depth_map, c[:, 0] + o[0] * radius, c[:, 1] + o[1] * radius)).astype(np.float64)
    return np.where(outside | (count == 0), 1.0, lit / SOFT_TAPS)


def shadow_soft_area(depth_map, dist_map, shadow_matrix, soft, eye, world, NoL, du, dv) -> np.ndarray:
    """Twin of lib/shadow_soft.glsl shadow_soft_area: shadow_soft with the receiver's footprint (the
    parallelogram of the world vectors du, dv (N, 3) centred on world) as spread2 = (|a|^2 + |b|^2) / 6,
    a and b its sides in the map's uv (the disk with the footprint's second moments)."""
    world = np.atleast_2d(np.asarray(world, np.float64))
    _, p = _light_space(shadow_matrix, world)
    _, pa = _light_space(shadow_matrix, world + np.atleast_2d(np.asarray(du, np.float64)))
    _, pb = _light_space(shadow_matrix, world + np.atleast_2d(np.asarray(dv, np.float64)))
    c = p[:, :2] / p[:, 3:4]
    a = pa[:, :2] / pa[:, 3:4] - c
    b = pb[:, :2] / pb[:, 3:4] - c
    spread2 = ((a * a).sum(1) + (b * b).sum(1)) / 6.0
    return shadow_soft(depth_map, dist_map, shadow_matrix, soft, eye, world, NoL, spread2)
