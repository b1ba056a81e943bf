"""Pre-integrated skin shading (Penner & Borshukov, "Pre-Integrated Skin Shading", GPU Pro 2, 2011;
docs/references.md#penner-borshukov-2011): the diffusion profile integrated around a ring of radius
r = 1/curvature lit from one side, tabulated over N.L and curvature. NumPy reference of the lookup
table skinlab/shaders/techniques/preintegrated/forward.glsl reads, and of the per-vertex curvature.

    D(theta, r) = int_{-pi}^{pi} max(cos(theta + x), 0) R(2 r sin(x/2)) dx / int_{-pi}^{pi} R(2 r sin(x/2)) dx

with theta = acos(N.L) and R the material's radial profile through its normalised Gaussian fit
(skinlab/scene/optics/profile_fit.py profile_fit; Penner integrated d'Eon's Gaussians): R(d) = sum_k W_k G(v_k, d).
Each Gaussian is integrated on its own grid (x within 8 sigma_k / r), so narrow Gaussians on wide
rings stay resolved; a channel that does not scatter (the fit's identity weight) is max(N.L, 0), as
is curvature 0 (a flat surface). The table's rows are curvature 0 .. curv_max (1/mm, linear), its
columns N.L -1 .. 1 (linear); curv_max = 2 / sigma of the profile's widest Gaussian, where the
result no longer changes much (a ring of radius sigma / 2 scatters nearly evenly).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skinlab.cache import table

from .media import Medium
from .profile_fit import profile_fit

LUT_NOL = 64  # columns: N.L from -1 to 1
LUT_CURV = 64  # rows: curvature from 0 to curv_max
RING_SAMPLES = 513  # quadrature points per Gaussian and ring


@dataclass(frozen=True)
class PreintegratedLut:
    table: np.ndarray  # (LUT_CURV, LUT_NOL, 3) float64, D per channel
    curv_max: float  # 1/mm at the last row (0 when nothing scatters: every row is max(N.L, 0))


def ring_diffusion(nol, radius_mm, variances, weights, identity) -> np.ndarray:
    """D(theta, r) for N.L values (N,) on a ring of radius_mm (inf: flat): (N, 3)."""
    nol = np.clip(np.asarray(nol, np.float64), -1.0, 1.0)
    theta = np.arccos(nol)
    flat = np.maximum(nol, 0.0)[:, None] * np.ones(3)
    v = np.asarray(variances, np.float64)
    W = np.asarray(weights, np.float64).reshape(-1, 3)
    if not np.isfinite(radius_mm) or len(v) == 0 or W.sum() <= 0:
        return flat
    r = float(radius_mm)
    num, den = np.zeros((len(nol), 3)), np.zeros(3)
    for vk, wk in zip(v, W):
        if wk.max() <= 0:
            continue
        s = math.sqrt(max(vk, 1e-30))
        half = min(math.pi, 8.0 * s / r)
        x = np.linspace(-half, half, RING_SAMPLES)
        d = 2.0 * r * np.sin(np.abs(x) / 2.0)
        g = np.exp(-(d * d) / (2.0 * vk)) / (2.0 * math.pi * vk)  # the 2-D Gaussian G(v, d)
        dx = x[1] - x[0]
        tw = np.full_like(x, dx)
        tw[[0, -1]] *= 0.5  # trapezoid
        lit = np.maximum(np.cos(theta[:, None] + x[None, :]), 0.0)
        num += (lit @ (g * tw))[:, None] * wk[None, :]
        den += float((g * tw).sum()) * wk
    ok = den > 0
    scat = np.where(ok[None, :], num / np.where(ok, den, 1.0)[None, :], flat)
    ident = np.asarray(identity, np.float64)
    return ident[None, :] * flat + (1.0 - ident[None, :]) * scat


@table(disk=True, maxsize=64)
def preintegrated_lut(model: str, medium: Medium, gaussians: int = 6) -> PreintegratedLut:
    """The table for a material's sss_model and medium (cached per medium)."""
    fit = profile_fit(model, medium, gaussians)
    live = np.asarray(fit.weights).reshape(-1, 3).max(axis=1) > 0 if len(fit.variances_mm2) else np.zeros(0, bool)
    nol = np.linspace(-1.0, 1.0, LUT_NOL)
    if not live.any():
        return PreintegratedLut(np.repeat(np.maximum(nol, 0.0)[None, :, None], LUT_CURV, 0).repeat(3, 2), 0.0)
    curv_max = 2.0 / math.sqrt(float(np.max(np.asarray(fit.variances_mm2)[live])))
    rows = []
    for k in np.linspace(0.0, curv_max, LUT_CURV):
        radius = math.inf if k <= 0 else 1.0 / k
        rows.append(ring_diffusion(nol, radius, fit.variances_mm2, fit.weights, fit.identity))
    return PreintegratedLut(np.stack(rows), curv_max)


def lut_lookup(lut: PreintegratedLut, nol, curv_mm) -> np.ndarray:
    """Bilinear lookup as the GPU's linear filter does it (texel centres at the grid points): (N, 3)."""
    nol = np.clip(np.asarray(nol, np.float64), -1.0, 1.0)
    c = np.asarray(curv_mm, np.float64)
    u = (nol + 1.0) / 2.0 * (LUT_NOL - 1)
    v = np.zeros_like(c) if lut.curv_max <= 0 else np.clip(c / lut.curv_max, 0.0, 1.0) * (LUT_CURV - 1)
    u0, v0 = np.clip(np.floor(u).astype(int), 0, LUT_NOL - 2), np.clip(np.floor(v).astype(int), 0, LUT_CURV - 2)
    fu, fv = (u - u0)[:, None], (v - v0)[:, None]
    t = lut.table
    top = t[v0, u0] * (1 - fu) + t[v0, u0 + 1] * fu
    bot = t[v0 + 1, u0] * (1 - fu) + t[v0 + 1, u0 + 1] * fu
    return top * (1 - fv) + bot * fv


def vertex_curvature(positions, normals, indices) -> np.ndarray:
    """Per-vertex mean curvature magnitude (1/scene unit) from the mesh: the mean over a vertex's
    edges of (n_j - n_i).(p_j - p_i) / |p_j - p_i|^2 (exactly 1/R on a sphere of radius R), its
    absolute value (Penner's lookup is even in curvature). (V,) float32; an isolated vertex gets 0."""
    p = np.asarray(positions, np.float64)
    n = np.asarray(normals, np.float64)
    tri = np.asarray(indices, np.int64).reshape(-1, 3)
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    e = np.unique(np.sort(e, axis=1), axis=0)
    i, j = e[:, 0], e[:, 1]
    dp = p[j] - p[i]
    l2 = np.einsum("ij,ij->i", dp, dp)
    k = np.where(l2 > 0, np.einsum("ij,ij->i", n[j] - n[i], dp) / np.where(l2 > 0, l2, 1.0), 0.0)
    acc = np.bincount(i, k, len(p)) + np.bincount(j, k, len(p))
    cnt = np.bincount(i, None, len(p)) + np.bincount(j, None, len(p))
    mean = np.where(cnt > 0, acc / np.maximum(cnt, 1), 0.0)
    return np.abs(mean).astype(np.float32)
