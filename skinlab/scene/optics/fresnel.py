"""Dielectric Fresnel terms and phase functions shared by the diffusion profiles (float64).

NumPy twin of skinlab/shaders/lib/profiles_common.glsl (same names, same clamps).

Conventions (as pbrt-v4 util/scattering.h ``FrDielectric``): ``eta`` is the relative index
n_medium / n_outside. ``cos_i > 0`` means light arriving from outside; ``cos_i < 0`` means light
inside the medium heading out (the ratio is inverted). Total internal reflection gives 1.
"""

from __future__ import annotations

import numpy as np

from .constants import DIFFUSION_ETA_MAX, DIFFUSION_ETA_MIN, FDR_GT1, FDR_LT1, FM1_GE1, FM1_LT1, FM2_GE1, FM2_LT1, PI


def _f(x):
    return np.asarray(x, dtype=np.float64)


def fresnel_from_cosines(cos_i, cos_t, eta_i, eta_t):
    """Unpolarised Fresnel reflectance from both cosines (no cancellation: sums of positives)."""
    ci, ct, ni, nt = _f(cos_i), _f(cos_t), _f(eta_i), _f(eta_t)
    rs_n, rs_d = ni * ci - nt * ct, ni * ci + nt * ct
    rp_n, rp_d = nt * ci - ni * ct, nt * ci + ni * ct
    with np.errstate(invalid="ignore", divide="ignore"):
        rs = np.where(rs_d > 0, rs_n / np.where(rs_d > 0, rs_d, 1.0), 1.0)
        rp = np.where(rp_d > 0, rp_n / np.where(rp_d > 0, rp_d, 1.0), 1.0)
    return 0.5 * (rs * rs + rp * rp)


def fresnel_dielectric(cos_i, eta):
    """Exact dielectric reflectance (pbrt-v4 FrDielectric). 1 under total internal reflection.

    cos_t^2 = 1 - (1 - c)(1 + c) / eta^2 (the (1-c)(1+c) form avoids 1 - c^2 cancellation).
    """
    c = np.clip(_f(cos_i), -1.0, 1.0)
    eta = _f(eta)
    inside = c < 0
    e = np.where(inside, 1.0 / eta, eta)
    c = np.abs(c)
    sin2_t = (1.0 - c) * (1.0 + c) / (e * e)
    tir = sin2_t >= 1.0
    cos_t = np.sqrt(np.maximum(1.0 - sin2_t, 0.0))
    f = fresnel_from_cosines(c, cos_t, 1.0, e)
    return np.where(tir, 1.0, f)


def hg_phase(cos_theta, g):
    """Henyey-Greenstein phase function, cos_theta between the propagation directions before and
    after scattering (g > 0 forward). Normalised to 1 over the sphere."""
    c, g = _f(cos_theta), _f(g)
    denom = 1.0 + g * g - 2.0 * g * c
    # (1 - g)(1 + g) for 1 - g^2; denom >= (1 - |g|)^2 > 0 for |g| < 1
    return (1.0 - g) * (1.0 + g) / (4.0 * PI * denom * np.sqrt(denom))


def clamp_eta(eta):
    return np.clip(_f(eta), DIFFUSION_ETA_MIN, DIFFUSION_ETA_MAX)


def fdr(eta):
    """Diffuse Fresnel reflectance for light inside the medium (Jensen 2001 / Egan & Hilgeman 1979).

    eta is clamped to [DIFFUSION_ETA_MIN, DIFFUSION_ETA_MAX], the range where the fits hold."""
    eta = clamp_eta(eta)
    ie = 1.0 / eta
    gt = FDR_GT1[0] * ie * ie + FDR_GT1[1] * ie + FDR_GT1[2] + FDR_GT1[3] * eta
    lt = FDR_LT1[0] + FDR_LT1[1] * ie + FDR_LT1[2] * ie * ie + FDR_LT1[3] * ie * ie * ie
    return np.where(eta >= 1.0, gt, lt)


def _poly(c, x):
    acc = np.zeros_like(x)
    for k in reversed(c):
        acc = acc * x + k
    return acc


def fresnel_moment1(eta):
    """pbrt-v4 FresnelMoment1 (polynomial fit; eta clamped like :func:`fdr`)."""
    eta = clamp_eta(eta)
    return np.where(eta < 1.0, _poly(FM1_LT1, eta), _poly(FM1_GE1, eta))


def fresnel_moment2(eta):
    """pbrt-v4 FresnelMoment2 (polynomial fit; eta clamped like :func:`fdr`)."""
    eta = clamp_eta(eta)
    ie = 1.0 / eta
    c = FM2_GE1
    ge = (
        c[0]
        + ie * (c[1] + ie * (c[2] + ie * c[3]))
        + eta * (c[4] + eta * (c[5] + eta * (c[6] + eta * (c[7] + eta * c[8]))))
    )
    return np.where(eta < 1.0, _poly(FM2_LT1, eta), ge)
