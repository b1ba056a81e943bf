"""Texture-space diffusion (d'Eon & Luebke 2007, GPU Gems 3 ch. 14; docs/references.md#deon-luebke-2007):
the kernel design shared by the GPU passes (skinlab/render/techniques/tsd/, skinlab/shaders/techniques/tsd/*.frag) and
its NumPy reference twin.

The diffusion step, per channel c, of an irradiance texture E (premultiplied by albedo^mix):

    D_c = I_c E_c + sum_k W_kc (G(v_k) * E)_c          I_c + sum_k W_kc = 1

G(v) a 2-D Gaussian of variance v mm^2, measured on the surface: each texel's step in millimetres
comes from the stretch map (world mm per texel along u and v). The Gaussians are blurred in a chain,
level_k = G(v_k - v_{k-1}) * level_{k-1} (G(a) * G(b) = G(a + b)), each step as two separable 1-D
passes (u then v) of ``taps`` samples at offsets t_i sigma, t_i in [-3, 3], linear interpolation
between the two nearest texels along the blur axis (done by hand with two texel fetches, so the GPU
and this twin agree to fp32 rounding rather than to a sampler's 8-bit filter weights).

Textures are premultiplied by coverage (alpha = 1 where a UV chart was rasterised, 0 elsewhere): the
blur convolves (E a, a) and the gather divides, so texels outside the charts never darken a border
(normalised convolution), on top of the dilation of the irradiance past chart borders.

The weights W come from a K-Gaussian fit with shared variances of the material's profile
(skinlab/scene/optics/profile_fit.py profile_fit), normalised per channel to sum to 1: the kernel redistributes
light, the colour comes from the albedo (pre-/post-scatter texturing), so a constant irradiance
keeps its mean. Gaussians below NEGLIGIBLE_WEIGHT in every channel are dropped; Gaussians narrower
than a texel cannot be resolved by the texture and join the identity weight I.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from skinlab.cache import table

from .constants import (
    COVERAGE_EPS,
    TSD_MAX_STEP_TEXELS,
    TSD_MIN_MM_PER_TEXEL,
    TSD_TAP_RANGE,
)
from .profile_fit import ProfileFit

TSD_MIN_TAPS = 7  # d'Eon & Luebke's 7-tap kernel is the smallest
TSD_MAX_TAPS = 31
TSD_SUBTEXEL_SIGMA = 0.35  # a Gaussian whose sigma is below this many texels is the identity
NEGLIGIBLE_WEIGHT = 1e-3  # a Gaussian below this weight in every channel is skipped


@dataclass(frozen=True)
class BlurStep:
    level: int  # index into the kept levels
    variance_mm2: float  # the level's total variance v_k
    sigma_mm: float  # sqrt(v_k - v_{k-1}): this step's blur
    taps: int
    weight: tuple  # (3,) W_k


@dataclass(frozen=True)
class DiffusionKernel:
    steps: tuple  # BlurStep per kept level, ascending variance
    identity: np.ndarray  # (3,) weight of the unblurred irradiance
    skipped: tuple = field(default=())  # (what, why) for the plan

    @property
    def levels(self) -> int:
        return len(self.steps)

    def weights(self) -> np.ndarray:
        return np.array([s.weight for s in self.steps]).reshape(-1, 3)


def tap_count(sigma_texels: float) -> int:
    """Odd tap count with spacing of at most one texel over +-3 sigma, within [7, 31]."""
    s = min(max(float(sigma_texels), 0.0), TSD_MAX_STEP_TEXELS)
    n = 2 * math.ceil(TSD_TAP_RANGE * s) + 1
    return int(min(max(n, TSD_MIN_TAPS), TSD_MAX_TAPS))


@table(maxsize=64)
def blur_taps(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Offsets t_i (in sigmas, uniform over [-3, 3]) and weights: the Gaussian's mass over each
    tap's cell, normalised to sum to 1."""
    if n < 1 or n % 2 == 0:
        raise ValueError(f"taps: expected an odd positive count, got {n}")
    if n == 1:
        return np.zeros(1), np.ones(1)
    t = np.linspace(-TSD_TAP_RANGE, TSD_TAP_RANGE, n)
    h = t[1] - t[0]
    cdf = lambda x: 0.5 * (1.0 + np.vectorize(math.erf)(x / math.sqrt(2.0)))
    w = cdf(t + h / 2) - cdf(t - h / 2)
    return t, w / w.sum()


def design_kernel(
    fit: ProfileFit, mm_per_texel_p10: float, mm_per_texel_p50: float, taps: int | None = None
) -> DiffusionKernel:
    """Blur chain for `fit` on a texture whose (area-weighted) 10th / 50th percentile of millimetres
    per texel are given: drop negligible Gaussians, fold sub-texel ones into the identity, choose taps
    from each step's width in texels (at the 10th percentile, where the kernel is widest in texels)
    unless `taps` fixes the count."""
    skipped = []
    ident = fit.identity.astype(np.float64).copy()
    kept_v: list[float] = []
    kept_w: list[np.ndarray] = []
    p50 = max(float(mm_per_texel_p50), TSD_MIN_MM_PER_TEXEL)
    p10 = max(float(mm_per_texel_p10), TSD_MIN_MM_PER_TEXEL)
    for k, v in enumerate(fit.variances_mm2):
        w = fit.weights[k]
        if np.all(w < NEGLIGIBLE_WEIGHT):
            skipped.append(
                (f"gaussian {k} (v={v:.3g} mm2)", f"weight {w.max():.1e} < {NEGLIGIBLE_WEIGHT:g} in every channel")
            )
            continue
        if math.sqrt(max(v, 0.0)) / p50 < TSD_SUBTEXEL_SIGMA:
            skipped.append(
                (
                    f"gaussian {k} (v={v:.3g} mm2)",
                    f"sigma {math.sqrt(max(v, 0)):.3g} mm = {math.sqrt(max(v, 0)) / p50:.3g} texel "
                    f"(at the median {p50:.3g} mm per texel), under the {TSD_SUBTEXEL_SIGMA} texel a blur "
                    "needs: joins the unblurred term",
                )
            )
            ident += w
            continue
        kept_v.append(float(v))
        kept_w.append(w)
    weights = np.array(kept_w).reshape(-1, 3)
    # renormalise what is left (dropped negligible weights) so the kernel still sums to 1
    tot = ident + weights.sum(axis=0)
    scale = np.where(tot > 0, 1.0 / np.where(tot > 0, tot, 1.0), 0.0)
    ident = np.where(tot > 0, ident * scale, 1.0)
    weights = weights * scale[None, :]
    steps, prev = [], 0.0
    for i, (v, w) in enumerate(zip(kept_v, weights)):
        sigma = math.sqrt(max(v - prev, 0.0))
        steps.append(BlurStep(i, v, sigma, int(taps) if taps else tap_count(sigma / p10), tuple(float(x) for x in w)))
        prev = v
    return DiffusionKernel(tuple(steps), ident, tuple(skipped))


# -- NumPy reference twin of the GPU passes ------------------------------------------------------------
# Arrays are (rows = v, columns = u, channels), row 0 at v = 0 (as the GPU texture is read back).


def seam_bilinear_reference(src: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Twin of skinlab/shaders/lib/tsd_seams.glsl seam_bilinear: src (H, W, C) read bilinearly at uv (..., 2)
    (texel centres at (i + 0.5) / size, clamped at the edges), float32 like the shader."""
    src = np.asarray(src, np.float32)
    H, W, _ = src.shape
    x = np.asarray(uv, np.float32) * np.array([W, H], np.float32) - np.float32(0.5)
    fl = np.floor(x)
    f = (x - fl).astype(np.float32)
    i = fl.astype(np.int64)

    def at(dx, dy):
        return src[np.clip(i[..., 1] + dy, 0, H - 1), np.clip(i[..., 0] + dx, 0, W - 1)]

    lo = at(0, 0) + (at(1, 0) - at(0, 0)) * f[..., 0:1]
    hi = at(0, 1) + (at(1, 1) - at(0, 1)) * f[..., 0:1]
    return lo + (hi - lo) * f[..., 1:2]


def seam_fill_reference(src: np.ndarray, seam: np.ndarray) -> np.ndarray:
    """Twin of skinlab/shaders/techniques/tsd/seam_fill.frag: the texels the seam map (H, W, 4: RG source UV, A
    marked) marks take src at the seam map's UV; the rest are copied."""
    src = np.asarray(src, np.float32)
    across = seam_bilinear_reference(src, seam[..., :2])
    return np.where((seam[..., 3] > 0.5)[..., None], across, src).astype(np.float32)


def blur_axis_reference(src: np.ndarray, mm_per_texel: np.ndarray, sigma_mm: float, taps: int, axis: str) -> np.ndarray:
    """One 1-D pass of skinlab/shaders/techniques/tsd/blur.frag: src (H, W, 4) premultiplied, mm_per_texel
    (H, W, 2) (u, v); axis 'u' (columns) or 'v' (rows). float32 arithmetic like the shader."""
    src = np.asarray(src, np.float32)
    H, W, _ = src.shape
    t, w = blur_taps(int(taps))
    d = 0 if axis == "u" else 1
    mm = np.maximum(mm_per_texel[..., d].astype(np.float32), np.float32(TSD_MIN_MM_PER_TEXEL))
    step = np.minimum(np.float32(sigma_mm) / mm, np.float32(TSD_MAX_STEP_TEXELS)).astype(np.float32)
    rows, cols = np.mgrid[0:H, 0:W]
    out = np.zeros_like(src)
    for ti, wi in zip(t.astype(np.float32), w.astype(np.float32)):
        x = ti * step
        fl = np.floor(x)
        f = (x - fl)[..., None]
        i0 = fl.astype(np.int64)
        if d == 0:
            ra, ca, rb, cb = rows, np.clip(cols + i0, 0, W - 1), rows, np.clip(cols + i0 + 1, 0, W - 1)
        else:
            ra, ca, rb, cb = np.clip(rows + i0, 0, H - 1), cols, np.clip(rows + i0 + 1, 0, H - 1), cols
        a, b = src[ra, ca], src[rb, cb]
        out += wi * (a + (b - a) * f)
    return out


def diffuse_reference(irradiance: np.ndarray, stretch: np.ndarray, kernel: DiffusionKernel, seam=None):
    """The whole diffusion step in NumPy: returns (levels, diffused) where levels are the
    premultiplied blurred textures (like the GPU's) and diffused (H, W, 3) is I E + sum_k W_k level_k
    (each level divided by its coverage). `seam`: the seam map; each level's gutter is then filled
    across the seams (seam_fill_reference), as the blur pass does."""
    cur = np.asarray(irradiance, np.float32)
    levels = []
    for s in kernel.steps:
        cur = blur_axis_reference(cur, stretch, s.sigma_mm, s.taps, "u")
        cur = blur_axis_reference(cur, stretch, s.sigma_mm, s.taps, "v")
        if seam is not None:
            cur = seam_fill_reference(cur, seam)
        levels.append(cur)
    return levels, gather_reference(irradiance, levels, kernel)


def unpremultiply(t: np.ndarray) -> np.ndarray:
    a = t[..., 3:4]
    return np.where(a > COVERAGE_EPS, t[..., :3] / np.maximum(a, COVERAGE_EPS), 0.0)


def gather_reference(irradiance, levels, kernel: DiffusionKernel) -> np.ndarray:
    out = unpremultiply(np.asarray(irradiance, np.float32)) * kernel.identity[None, None, :]
    for s, lv in zip(kernel.steps, levels):
        out = out + unpremultiply(lv) * np.asarray(s.weight)[None, None, :]
    return out


def dilate_reference(img: np.ndarray, rings: int) -> np.ndarray:
    """Twin of skinlab/shaders/techniques/tsd/dilate.frag applied `rings` times: an empty texel (alpha <=
    COVERAGE_EPS) takes the mean of its covered 8-neighbours (each un-premultiplied, rgba / a) and
    becomes covered; covered texels are kept."""
    cur = np.asarray(img, np.float32).copy()
    H, W, _ = cur.shape
    for _ in range(rings):
        a = cur[..., 3]
        cov = a > COVERAGE_EPS
        un = np.where(cov[..., None], cur / np.where(cov, a, 1.0)[..., None], 0.0).astype(np.float32)
        pad = np.pad(un, ((1, 1), (1, 1), (0, 0)))
        pc = np.pad(cov, 1)
        s = np.zeros_like(un)
        n = np.zeros((H, W), np.float32)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                s += pad[1 + dy : 1 + dy + H, 1 + dx : 1 + dx + W]
                n += pc[1 + dy : 1 + dy + H, 1 + dx : 1 + dx + W]
        fill = np.where(n[..., None] > 0, s / np.maximum(n, 1)[..., None], 0.0)
        cur = np.where(cov[..., None], cur, fill).astype(np.float32)
    return cur


def through_fill_reference(raw, through0, through1, through_cos, seam=None):
    """Twin of skinlab/shaders/techniques/tsd/through_fill.frag: the irradiance pass's light-through records
    (through0/1 (H, W, 4): a slot's light through and its thickness; through_cos (H, W, 2): the
    slots' cosines on the far face) with the gutter filled. A covered texel (raw's alpha >
    COVERAGE_EPS) keeps its record; a gutter texel the seam map marks takes the covered texels of the
    bilinear footprint at the seam map's UV (seam_bilinear_reference's weights, renormalised); any
    other gutter texel, or a marked one with no covered texel there, its covered 8-neighbours with
    equal weights. The light (rgb) is averaged over the covered texels; a slot's thickness and cosine
    over those whose cosine is > 0 (the ones holding light of that slot). Returns the three arrays,
    float32."""
    raw = np.asarray(raw, np.float32)
    r0, r1 = np.asarray(through0, np.float32), np.asarray(through1, np.float32)
    rc = np.asarray(through_cos, np.float32)[..., :2]
    H, W, _ = raw.shape
    cov = raw[..., 3] > COVERAGE_EPS
    s0 = np.zeros((H, W, 4), np.float32)
    s1 = np.zeros((H, W, 4), np.float32)
    sc = np.zeros((H, W, 2), np.float32)
    w = np.zeros((H, W, 3), np.float32)

    def add(rows, cols, weight, where):
        """Accumulate the records at (rows, cols) with `weight` where `where` (H, W) holds."""
        weight = np.where(where & cov[rows, cols], weight, np.float32(0.0)).astype(np.float32)
        c = rc[rows, cols]
        lit = (c > 0).astype(np.float32) * weight[..., None]
        s0[..., :3] += r0[rows, cols, :3] * weight[..., None]
        s0[..., 3] += r0[rows, cols, 3] * lit[..., 0]
        s1[..., :3] += r1[rows, cols, :3] * weight[..., None]
        s1[..., 3] += r1[rows, cols, 3] * lit[..., 1]
        sc[...] += c * lit
        w[...] += np.concatenate([weight[..., None], lit], -1)

    rows, cols = np.mgrid[0:H, 0:W]
    gutter = ~cov
    if seam is not None:
        marked = gutter & (np.asarray(seam)[..., 3] > 0.5)
        x = np.asarray(seam, np.float32)[..., :2] * np.array([W, H], np.float32) - np.float32(0.5)
        fl = np.floor(x)
        f = (x - fl).astype(np.float32)
        i = fl.astype(np.int64)
        fx, fy = f[..., 0], f[..., 1]
        one = np.float32(1.0)
        for dx, dy, wt in (
            (0, 0, (one - fx) * (one - fy)),
            (1, 0, fx * (one - fy)),
            (0, 1, (one - fx) * fy),
            (1, 1, fx * fy),
        ):
            add(np.clip(i[..., 1] + dy, 0, H - 1), np.clip(i[..., 0] + dx, 0, W - 1), wt, marked)
    ring = gutter & (w[..., 0] <= 0)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dx == 0 and dy == 0:
                continue
            inside = (rows + dy >= 0) & (rows + dy < H) & (cols + dx >= 0) & (cols + dx < W)
            add(np.clip(rows + dy, 0, H - 1), np.clip(cols + dx, 0, W - 1), np.float32(1.0), ring & inside)
    inv = (np.float32(1.0) / np.maximum(w, np.float32(1e-30))).astype(np.float32)
    has = (w[..., 0] > 0)[..., None]
    f0 = np.where(has, np.concatenate([s0[..., :3] * inv[..., 0:1], s0[..., 3:] * inv[..., 1:2]], -1), 0.0)
    f1 = np.where(has, np.concatenate([s1[..., :3] * inv[..., 0:1], s1[..., 3:] * inv[..., 2:3]], -1), 0.0)
    fc = sc * inv[..., 1:3]
    keep = cov[..., None]
    return (
        np.where(keep, r0, f0).astype(np.float32),
        np.where(keep, r1, f1).astype(np.float32),
        np.where(keep, rc, fc).astype(np.float32),
    )
