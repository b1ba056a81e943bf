"""Christensen & Burley 2015 normalized diffusion ("Approximate Reflectance Profiles for Efficient
Subsurface Scattering", Pixar TM 15-04) and Blender's (Cycles / EEVEE) truncated variant with its
samplers. Float64 twin of skinlab/shaders/lib/profiles_burley.glsl.

    R(r) = A s (e^{-s r/l} + e^{-s r/(3 l)}) / (8 pi l r) = A (e^{-r/d} + e^{-r/(3d)}) / (8 pi d r),  d = l/s

integrates to A over the plane. r = 0: the profile diverges like 1/r; it is evaluated at
max(r, BURLEY_R0_EPS d), the analytic value at the rim of a disc of radius ~1e-3 d (continuous and
finite; the energy inside that disc is underestimated by about 2.5e-4 A). l < MIN_MFP_MM is "no
scattering": 0.
"""

from __future__ import annotations

import numpy as np

from ._profile_util import f64, optical, radial
from .constants import BURLEY_R0_EPS, BURLEY_TRUNCATE, BURLEY_TRUNCATE_CDF, MIN_MFP_MM, PI, PROFILE_MAX_OPTICAL_R

SCALING_VARIANTS = ("diffuse", "searchlight", "dmfp")


def burley_s(A, variant="searchlight"):
    """Scaling factor s(A) (Christensen & Burley 2015, section 5, eqs. 5-7; docs/references.md#christensen-burley-2015).

    "diffuse": diffuse surface transmission, l = mean free path: 1.9 - A + 3.5 (A - 0.8)^2
    "searchlight": perpendicular incidence, l = mean free path: 1.85 - A + 7 |A - 0.8|^3
    "dmfp": l is the diffuse mean free path (1/sigma_tr): 3.5 + 100 (A - 0.33)^4
    """
    A = f64(A)
    if variant == "diffuse":
        return 1.9 - A + 3.5 * (A - 0.8) ** 2
    if variant == "searchlight":
        return 1.85 - A + 7.0 * np.abs(A - 0.8) ** 3
    if variant == "dmfp":
        return 3.5 + 100.0 * (A - 0.33) ** 4
    raise ValueError(f"variant: unknown Burley scaling {variant!r}; choose one of {SCALING_VARIANTS}")


def burley_profile_d(r, A, d):
    """Normalized diffusion in terms of the shape parameter d = l/s (mm): (N,) x (C,) -> (N, C)."""
    r, A, d = radial(r, A, d)
    x, inv_d2, valid = optical(r, d)
    xs = np.maximum(x, BURLEY_R0_EPS)
    body = (np.exp(-xs) + np.exp(-xs / 3.0)) / (8.0 * PI * xs)
    out = A * body * inv_d2
    return np.where(valid, out, 0.0)


def burley_profile(r, A, mfp, variant="searchlight"):
    """R(r) in 1/mm^2 from surface albedo A and mean free path l (mm) with the chosen s(A)."""
    A, mfp = f64(A), f64(mfp)
    return burley_profile_d(r, A, mfp / burley_s(A, variant))


def burley_cdf(r, d):
    """Fraction of the (untruncated) profile's energy within radius r: 1 - e^{-x}/4 - 3 e^{-x/3}/4."""
    x = f64(r) / f64(d)
    return 1.0 - 0.25 * np.exp(-x) - 0.75 * np.exp(-x / 3.0)


def burley_sample_golubev(xi, d):
    """Closed-form inverse of burley_cdf (Golubev 2018): u = 1 - xi, G = 1 + 4u(2u + sqrt(1 + 4u^2)),
    r = 3 d ln((1 + G^{-1/3} + G^{1/3}) / (4u)). xi in [0, 1); xi = 1 gives inf."""
    u = 1.0 - f64(xi)
    with np.errstate(divide="ignore"):
        G = 1.0 + 4.0 * u * (2.0 * u + np.sqrt(1.0 + 4.0 * u * u))
        g3 = np.cbrt(G)
        return 3.0 * f64(d) * np.log((1.0 + 1.0 / g3 + g3) / (4.0 * u))


# --- Blender (Cycles / EEVEE) conventions -------------------------------------------------------


def blender_radius_to_mfp(radius):
    """User radius R -> mean free path l = R / (4 pi) (Cycles closure set-up; docs/references.md#blender-burley)."""
    return f64(radius) / (4.0 * PI)


def blender_d(A, radius):
    """Blender's shape parameter d = l / s(A), s the diffuse-transmission fit."""
    return blender_radius_to_mfp(radius) / burley_s(A, "diffuse")


def blender_burley_profile(r, A, radius):
    """Cycles-style Burley: zero for r >= 16 d and renormalised by the truncated CDF, so that it
    integrates to exactly A. (N,) x (C,) -> (N, C) in 1/mm^2."""
    A = f64(A)
    d = blender_d(A, radius)
    r2, d2 = radial(r, d)
    out = burley_profile_d(r, A, d) / BURLEY_TRUNCATE_CDF
    return np.where(np.abs(r2) < BURLEY_TRUNCATE * d2, out, 0.0)


def blender_burley_pdf(r, d):
    """Radial pdf (2 pi r included) of the truncated profile: (e^{-r/d} + e^{-r/3d}) / (4 d CDF_16)."""
    r, d = f64(r), f64(d)
    x = r / d
    p = (np.exp(-x) + np.exp(-x / 3.0)) / (4.0 * d * BURLEY_TRUNCATE_CDF)
    return np.where((x >= 0) & (x < BURLEY_TRUNCATE), p, 0.0)


def blender_burley_cdf(r, d):
    return np.clip(burley_cdf(np.minimum(f64(r), BURLEY_TRUNCATE * f64(d)), d) / BURLEY_TRUNCATE_CDF, 0.0, 1.0)


def burley_root_find(xi, tol=1e-6, max_iter=10):
    """Newton inversion of 1 - e^{-x}/4 - 3 e^{-x/3}/4 = xi for x = r/d (Cycles
    ``bssrdf_burley_root_find``): start x = e^{2.4 xi^2} - 1 (xi <= 0.9) else 15, |f| < 1e-6, 10 steps."""
    xi = f64(xi)
    x = np.where(xi <= 0.9, np.exp(2.4 * xi * xi) - 1.0, 15.0)
    active = np.ones_like(x, dtype=bool)
    for _ in range(max_iter):
        e3 = np.exp(-x / 3.0)
        e1 = e3 * e3 * e3
        f = 1.0 - 0.25 * e1 - 0.75 * e3 - xi
        fp = 0.25 * e1 + 0.25 * e3
        active &= (np.abs(f) >= tol) & (fp != 0)
        if not active.any():
            break
        x = np.where(active, np.maximum(x - f / np.where(fp != 0, fp, 1.0), 0.0), x)
    return x


def blender_burley_sample(xi, d, method="newton"):
    """Radius r (mm) for xi in [0, 1) from the truncated profile: xi is scaled by the truncated
    CDF, then inverted by Newton (as Cycles) or the Golubev closed form."""
    xi = f64(xi) * BURLEY_TRUNCATE_CDF
    if method == "newton":
        return burley_root_find(xi) * f64(d)
    if method == "golubev":
        return burley_sample_golubev(xi, d)
    raise ValueError(f"method: unknown sampler {method!r}; choose 'newton' or 'golubev'")


__all__ = [n for n in dir() if n.startswith(("burley", "blender")) or n == "SCALING_VARIANTS"]
_ = (MIN_MFP_MM, PROFILE_MAX_OPTICAL_R)
