"""Photon beam diffusion (Habel, Christensen, Jarosz 2013, "Photon Beam Diffusion: A Hybrid
Monte Carlo Method for Subsurface Scattering"), as implemented in pbrt-v4 src/pbrt/bssrdf.cpp
(``BeamDiffusionMS`` / ``BeamDiffusionSS``). Float64 twin of skinlab/shaders/lib/profiles_pbd.glsl.
Equations: docs/references.md#habel-2013.

Multiple scattering integrates improved dipoles (Grosjean diffusion coefficient, PBD boundary
condition with the Fresnel moments, empirical kappa correction) over point sources at depths
z_i = -ln(1 - (i + 1/2)/N) along the refracted normally incident beam; the single-scattering term
is :func:`single_scattering.single_scatter_profile`. pbrt tabulates the result; here it is evaluated
directly (100 depth samples, vectorised).

Media are given by reduced coefficients (g = 0 after the similarity relation), so sigma_s' plays
pbrt's sigma_s with g = 0. In optical units (sigma_t' = 1): D_g = (2 - alpha)/3,
sigma_tr = sqrt((1 - alpha)/D_g), z_e = -2 D_g (1 + 3 FM2)/(1 - 2 FM1), z_v = -z_r + 2 z_e,
    phi_D = (e^{-s d_r}/d_r - e^{-s d_v}/d_v) / (4 pi D_g)
    E_n   = (z_r (1 + s d_r) e^{-s d_r}/d_r^3 - z_v (1 + s d_v) e^{-s d_v}/d_v^3) / (4 pi)
    MS    = alpha^2 / N sum_i (1 - e^{-2 (d_r + z_r)}) (phi_D (1 - 2 FM1)/4 + E_n (1 - 3 FM2)/2)
fp32 conditioning: phi_D is a difference of nearly equal terms when r >> z; it is evaluated as
e^{-s d_r}/d_r * (-expm1(-(s delta + log1p(delta/d_r)))) with delta = d_v - d_r =
(z_v^2 - z_r^2)/(d_r + d_v) computed without cancellation. r = 0 is finite (z_r >= z_0 > 0).
"""

from __future__ import annotations

import numpy as np

from ._profile_util import f64, optical, radial
from .constants import PI
from .fresnel import clamp_eta, fresnel_moment1, fresnel_moment2
from .single_scattering import depth_samples, single_scatter_profile


def pbd_ms_profile(r, alpha, mfp, eta):
    """Multiple-scattering part (1/mm^2): (N,) x (C,) -> (N, C)."""
    r, alpha, mfp = radial(r, alpha, mfp)
    x, inv_l2, valid = optical(r, mfp)
    eta = clamp_eta(eta)
    fm1, fm2 = fresnel_moment1(eta), fresnel_moment2(eta)
    Dg = (2.0 - alpha) / 3.0
    s = np.sqrt((1.0 - alpha) / Dg)
    ze_abs = 2.0 * Dg * (1.0 + 3.0 * fm2) / (1.0 - 2.0 * fm1)  # z_e = -ze_abs
    c_phi = 0.25 * (1.0 - 2.0 * fm1)
    c_e = 0.5 * (1.0 - 3.0 * fm2)
    zr = depth_samples().reshape(1, 1, -1)
    x3, s3, Dg3, ze3 = x[..., None], s[..., None], Dg[..., None], ze_abs[..., None]
    zv_abs = zr + 2.0 * ze3  # |z_v|; z_v = -|z_v|
    dr = np.sqrt(x3 * x3 + zr * zr)
    dv = np.sqrt(x3 * x3 + zv_abs * zv_abs)
    delta = 2.0 * ze3 * (2.0 * zr + 2.0 * ze3) / (dr + dv)  # (z_v^2 - z_r^2)/(d_r + d_v)
    er = np.exp(-s3 * dr)
    ev = np.exp(-s3 * dv)
    phi = er / dr * (-np.expm1(-(s3 * delta + np.log1p(delta / dr)))) / (4.0 * PI * Dg3)
    en = (zr * (s3 + 1.0 / dr) * er / (dr * dr) + zv_abs * (s3 + 1.0 / dv) * ev / (dv * dv)) / (4.0 * PI)
    kappa = -np.expm1(-2.0 * (dr + zr))
    ms = (alpha * alpha) * (kappa * (phi * c_phi + en * c_e)).mean(axis=-1) * inv_l2
    return np.where(valid, ms, 0.0)


def pbd_profile(r, alpha, mfp, eta, single=True):
    """Photon beam diffusion R(r) in 1/mm^2 (multiple + single scattering by default)."""
    out = pbd_ms_profile(r, alpha, mfp, eta)
    if single:
        out = out + single_scatter_profile(r, alpha, mfp, eta, 0.0)
    return out


def radial_integral(profile_opt, x_min=1e-5, x_max=2e3, n=600, chunk=64):
    """int_0^inf R(x) 2 pi x dx of an optical-unit profile on a log grid (plus the [0, x_min] disc).

    ``profile_opt(x) -> (N, C)``. Used for total reflectances of profiles without a closed form.
    The grid is evaluated ``chunk`` radii at a time: a profile over many channels and depth samples
    makes (radii x channels x depths) temporaries, and one of 600 x 256 x 100 float64 (120 MB each)
    runs at memory speed, several times slower than the same work in pieces that stay in cache."""
    x = np.geomspace(x_min, x_max, n)
    values = np.concatenate([profile_opt(x[i : i + chunk]) for i in range(0, n, chunk)])
    f = values * 2.0 * PI * x[:, None] * x[:, None]  # integrand in d(ln x)
    inner = profile_opt(np.array([0.0]))[0] * PI * x_min * x_min
    return inner + np.trapezoid(f, np.log(x), axis=0)


PBD_TOTAL_RADII = 300  # pbd_total's log grid: within 1e-6 of 600 radii (a test holds it), at half the cost


def pbd_total(alpha, eta, single=True):
    """Total diffuse reflectance (effective albedo rho_eff) of the PBD profile, numerically (a log
    grid of PBD_TOTAL_RADII radii)."""
    alpha = np.atleast_1d(f64(alpha))
    return radial_integral(lambda x: pbd_profile(x, alpha, 1.0, eta, single), n=PBD_TOTAL_RADII)
