"""Single scattering (Jensen et al. 2001 section 2.3, after Hanrahan & Krueger 1993) with a
Henyey-Greenstein phase function and exact dielectric Fresnel transmission. Float64 twin of
skinlab/shaders/lib/profiles_single.glsl.

Two forms:

* :func:`single_scatter_brdf` - the BRDF-like term of Jensen 2001 (docs/references.md#jensen-2001):
  f_r^(1) = alpha F p(cos_s) / (eta^2 (|n.T_i| + |n.T_o|)), F = F_t(eta, w_i) F_t(eta, w_o), T_i and
  T_o the refracted directions. It is what a renderer adds to the dipole at a shading point. The
  1/eta^2 is the change of solid angle across the interface (Hanrahan & Krueger 1993's radiance
  compression), which the paper's printed form leaves out: without it the term's albedo at eta 1.3
  was 1.68 times that of the flat-medium Monte Carlo's first-bounce photons (tests/scene/optics/test_boundary.py).
* :func:`single_scatter_profile` - the same physics as a *radial profile* for a normally incident
  beam: the light scattered once at depth t on the refracted beam and leaving through the surface
  at distance r (pbrt-v4 src/pbrt/bssrdf.cpp ``BeamDiffusionSS``, Habel et al. 2013). This is the
  form compared with the Monte Carlo reference (which also counts singly scattered light) and
  the one added to the photon-beam-diffusion profile.

Directions: w_i, w_o point away from the surface (like the BRDF code). The scattering cosine is
between the propagation direction of the refracted incident light T_i and the propagation direction
of the light leaving towards w_o, i.e. -T_o (T_o = refraction of -w_o into the medium).
"""

from __future__ import annotations

import numpy as np

from ._profile_util import f64, optical, radial
from .constants import PBD_SAMPLES
from .fresnel import clamp_eta, fresnel_from_cosines, hg_phase


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def refract_cos(cos_i, eta):
    """Cosine of the refracted direction for light entering a medium of relative index eta."""
    c = np.clip(f64(cos_i), 0.0, 1.0)
    eta = f64(eta)
    # cos_t^2 = ((eta - 1)(eta + 1) + c^2)/eta^2: no cancellation at grazing incidence
    return np.sqrt(np.maximum((eta - 1.0) * (eta + 1.0) + c * c, 0.0)) / eta


def single_scatter_brdf(n, wi, wo, alpha, eta, g):
    """Jensen 2001 single-scattering BRDF-like term, (..., 3) vectors -> (..., C) for albedo (C,).

    Zero when either direction is below the surface. Entering light is never totally reflected
    (eta >= 1 assumed for the refraction; eta < 1 uses the same formula with cos_t clamped).
    """
    n, wi, wo = f64(n), f64(wi), f64(wo)
    ci = _dot(n, wi)
    co = _dot(n, wo)
    eta = f64(eta)
    cti = refract_cos(ci, eta)
    cto = refract_cos(co, eta)
    # T = -w/eta + (c/eta - c_t) n ; propagation after scattering is -T_o
    ti = -wi / eta[..., None] + ((ci / eta - cti)[..., None]) * n
    to = -wo / eta[..., None] + ((co / eta - cto)[..., None]) * n
    cos_s = np.clip(-_dot(ti, to), -1.0, 1.0)
    ft = (1.0 - fresnel_from_cosines(np.clip(ci, 0, 1), cti, 1.0, eta)) * (
        1.0 - fresnel_from_cosines(np.clip(co, 0, 1), cto, 1.0, eta)
    )
    denom = np.maximum(cti + cto, 1e-4) * eta * eta
    val = ft * hg_phase(cos_s, g) / denom
    val = np.where((ci > 0) & (co > 0), val, 0.0)
    return val[..., None] * f64(alpha)


def depth_samples():
    """-ln(1 - (i + 1/2)/N), i = 0..N-1, written as -ln((N - i - 1/2)/N) (exact numerator)."""
    i = np.arange(PBD_SAMPLES, dtype=np.float64)
    return -np.log((PBD_SAMPLES - i - 0.5) / PBD_SAMPLES)


def single_scatter_profile(r, alpha, mfp, eta, g=0.0):
    """Radial single-scattering profile (1/mm^2) of a normally incident beam (pbrt-v4 BeamDiffusionSS).

    In optical units, with q_i = -ln(1 - (i + 1/2)/N) and t_i = t_crit + q_i (t_crit = x sqrt(eta^2 - 1)):
        E = alpha/N sum_i e^{-(d_i + t_crit)} / d_i^2 p_HG(-cos_o) (1 - F(cos_o -> cos_t)) cos_o
    with d_i = sqrt(x^2 + t_i^2), cos_o = t_i/d_i. The transmitted cosine is computed from the
    geometry, cos_t^2 = q (q + 2 t_crit)/d^2, exact where the usual 1 - eta^2 sin^2 cancels.
    r = 0 is finite (t_i >= q_0 > 0).
    """
    r, alpha, mfp = radial(r, alpha, mfp)
    x, inv_l2, valid = optical(r, mfp)
    eta = clamp_eta(eta)
    q = depth_samples().reshape(1, 1, -1)
    x3 = x[..., None]
    if eta > 1.0:
        tc = x3 * np.sqrt((eta - 1.0) * (eta + 1.0))
        t = tc + q
        ct2_num = q * (q + 2.0 * tc)
    else:
        tc = np.zeros_like(x3)
        t = q
        ct2_num = t * t + (1.0 - eta) * (1.0 + eta) * x3 * x3
    d2 = x3 * x3 + t * t
    d = np.sqrt(d2)
    cos_o = t / d
    cos_t = np.sqrt(ct2_num / d2)
    tr = 1.0 - fresnel_from_cosines(cos_o, cos_t, eta, 1.0)
    e = np.exp(-(d + tc)) / d2 * hg_phase(-cos_o, g) * tr * cos_o
    out = alpha * e.mean(axis=-1) * inv_l2
    return np.where(valid, out, 0.0)
