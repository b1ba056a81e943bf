"""Jensen et al. 2001 dipole diffusion profile (SIGGRAPH 2001, "A Practical Model for Subsurface
Light Transport", eqs. 4-6 and the total diffuse reflectance of section 2.4). Float64 twin of
skinlab/shaders/lib/profiles_dipole.glsl. Equations: docs/references.md#jensen-2001.

Parameterisation shared by all profiles: alpha = sigma_s'/sigma_t' (reduced single-scattering
albedo), mfp = l = 1/sigma_t' in mm, eta = relative index of refraction (clamped to the range of
the F_dr fit, see fresnel.clamp_eta). In optical units (sigma_t' = 1):

    z_r = 1,  D = 1/3,  A = (1 + F_dr)/(1 - F_dr),  z_v = z_r + 4 A D,  sigma_tr = sqrt(3 (1 - alpha))
    R_d(x) = alpha/(4 pi) [z_r (sigma_tr + 1/d_r) e^{-sigma_tr d_r}/d_r^2
                         + z_v (sigma_tr + 1/d_v) e^{-sigma_tr d_v}/d_v^2]

with d_r = sqrt(x^2 + z_r^2), d_v = sqrt(x^2 + z_v^2): the paper's (sigma_tr d + 1) e^{..}/d^3 written
as (sigma_tr + 1/d) e^{..}/d^2 so that d -> inf gives 0 * finite, not inf * 0. R(r) = R_d(r/l)/l^2.
r = 0 is finite analytically (d_r = z_r); no clamp is needed.
"""

from __future__ import annotations

import numpy as np

from ._profile_util import f64, optical, radial
from .constants import PI
from .fresnel import fdr


def dipole_a(eta):
    """Boundary mismatch A = (1 + F_dr)/(1 - F_dr)."""
    f = fdr(eta)
    return (1.0 + f) / (1.0 - f)


def sigma_tr_optical(alpha):
    """Effective transport coefficient in units of sigma_t': sqrt(3 (1 - alpha))."""
    return np.sqrt(3.0 * np.maximum(1.0 - f64(alpha), 0.0))


def dipole_pole(z, d, s_tr):
    """One pole of the dipole (twin of skinlab/shaders/lib/profiles_dipole.glsl dipole_pole)."""
    return z * (s_tr + 1.0 / d) * np.exp(-s_tr * d) / (d * d)


def dipole_profile(r, alpha, mfp, eta):
    """R_d(r) in 1/mm^2 for r in mm: (N,) x (C,) -> (N, C)."""
    r, alpha, mfp = radial(r, alpha, mfp)
    x, inv_l2, valid = optical(r, mfp)
    s_tr = sigma_tr_optical(alpha)
    zv = 1.0 + 4.0 / 3.0 * dipole_a(eta)
    dr = np.sqrt(x * x + 1.0)
    dv = np.sqrt(x * x + zv * zv)
    out = alpha / (4.0 * PI) * (dipole_pole(1.0, dr, s_tr) + dipole_pole(zv, dv, s_tr)) * inv_l2
    return np.where(valid, out, 0.0)


def dipole_total(alpha, eta):
    """Closed-form total diffuse reflectance (the exact integral of dipole_profile over the plane):
    (alpha/2)(1 + e^{-(4/3) A sqrt(3(1-alpha))}) e^{-sqrt(3(1-alpha))}."""
    alpha = f64(alpha)
    s = sigma_tr_optical(alpha)
    return 0.5 * alpha * (1.0 + np.exp(-4.0 / 3.0 * dipole_a(eta) * s)) * np.exp(-s)
