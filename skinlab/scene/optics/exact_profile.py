"""The exact radial profile as the exact technique convolves it (skinlab/render/techniques/exact/,
skinlab/shaders/techniques/exact/gather.frag): its table (exact_profile_lut, the support holding
EXACT_ENERGY of every channel's light) and the brute-force NumPy convolution of an irradiance texture
with a profile (exact_profile_convolution), the reference texture-space diffusion's Gaussian fit and
the exact technique are compared with."""

from __future__ import annotations

import math

import numpy as np

from .media import Medium
from .profile_fit import MODEL_PROFILES
from .profiles import get_profile

EXACT_ENERGY = 0.999  # the exact convolution's support: the radius holding this of every channel's energy


def exact_profile_lut(model: str, medium: Medium, n: int = 512, energy: float | None = None):
    """Tables for the brute-force texture-space convolution (skinlab/shaders/techniques/exact/gather.frag):
    r_max (mm, the radius holding `energy` (default EXACT_ENERGY) of every scattering channel's light), R(r) at
    r_i = i r_max / (n - 1) normalised so its integral over the disc r <= r_max is 1 per channel, and
    the cumulative energy E(r_i) = int_0^r_i R 2 pi r dr (for the centre texel). Channels that do not
    scatter get R = 0 and E = 1 (a delta)."""
    scatter = medium.scattering
    prof = get_profile(MODEL_PROFILES[model])
    fn = lambda r: np.asarray(prof.evaluate(np.asarray(r, np.float64), medium), np.float64) * scatter[None, :]
    if not scatter.any():
        return 1e-3, np.zeros((n, 3)), np.ones((n, 3))
    from .gaussians import NoEnergy, _energy_radius

    try:
        r_max = _energy_radius(fn, EXACT_ENERGY if energy is None else energy)
    except NoEnergy:  # the light spreads less than 1e-5 mm: a delta in every channel
        return 1e-3, np.zeros((n, 3)), np.ones((n, 3))
    r = np.linspace(0.0, r_max, n)
    # fine quadrature of the cumulative energy (the profile may be singular at 0: Burley ~ 1/r)
    rf = np.concatenate([[0.0], np.geomspace(r_max * 1e-7, r_max, 20000)])
    Rf = fn(np.maximum(rf, r_max * 1e-9))
    seg = 0.5 * (Rf[1:] * rf[1:, None] + Rf[:-1] * rf[:-1, None]) * np.diff(rf)[:, None] * 2 * math.pi
    cum = np.concatenate([np.zeros((1, 3)), np.cumsum(seg, axis=0)])
    tot = np.where(cum[-1] > 0, cum[-1], 1.0)
    E = np.stack([np.interp(r, rf, cum[:, c] / tot[c]) for c in range(3)], axis=1)
    R = fn(np.maximum(r, r_max * 1e-9)) / tot[None, :]
    E = np.where(scatter[None, :], E, 1.0)
    return float(r_max), R, E


def exact_profile_convolution(
    irradiance: np.ndarray, mm_per_texel: tuple[float, float], profile_fn, radius_mm: float | None = None
) -> np.ndarray:
    """Brute-force convolution of an irradiance texture (uniform stretch mm_per_texel = (u, v)) with
    a radial profile normalised to sum 1 per channel over the texel grid (profile_fn(r_mm) -> (N, 3)).
    The kernel is evaluated at texel centres with 4x4 supersampling; normalised convolution by coverage.
    For the reference comparisons (fit error); O(texels x kernel) — use small textures."""
    from scipy.signal import fftconvolve

    irr = np.asarray(irradiance, np.float64)
    mu, mv = float(mm_per_texel[0]), float(mm_per_texel[1])
    if radius_mm is None:
        radius_mm = 0.5 * min(irr.shape[1] * mu, irr.shape[0] * mv)
    nu, nv = int(math.ceil(radius_mm / mu)), int(math.ceil(radius_mm / mv))
    ss = 4
    off = (np.arange(ss) + 0.5) / ss - 0.5
    ys, xs = np.mgrid[-nv : nv + 1, -nu : nu + 1]
    # the radial profile tabulated once (log-spaced; some profiles cost ~0.1 ms per radius) and
    # interpolated at the 4x4 sub-samples of every kernel texel
    r_tab = np.concatenate([[0.0], np.geomspace(1e-6, max(2.0 * radius_mm, 1e-3), 4000)])
    R_tab = np.asarray(profile_fn(r_tab), np.float64).reshape(len(r_tab), -1)
    ker = np.zeros(ys.shape + (3,))
    for oy in off:
        for ox in off:
            r = np.hypot((xs + ox) * mu, (ys + oy) * mv)
            ker += np.stack([np.interp(r, r_tab, R_tab[:, c]) for c in range(3)], axis=-1)
    ker = np.maximum(ker, 0.0)
    ker /= np.maximum(ker.sum(axis=(0, 1)), 1e-300)
    a = irr[..., 3]
    out = np.zeros(irr.shape[:2] + (3,))
    for c in range(3):
        num = fftconvolve(irr[..., c], ker[..., c], mode="same")
        den = fftconvolve(a, ker[..., c], mode="same")
        out[..., c] = np.where(den > 1e-9, num / np.maximum(den, 1e-9), 0.0)
    return out
