"""Single scattering under a light at a finite distance (point and spot lights).

The BRDF-like single-scattering term (skinlab/scene/optics/single_scattering.py, Jensen et al. 2001
section 2.3) assumes that every point on the refracted view ray below x_o sees the light from one
direction with one irradiance, attenuated only by the path inside: true of a sun. A point light a few
mean free paths away is seen from points deeper down from other directions, farther away, and
through a path inside that is not z / mu_i. Along the refracted view ray (s its length, z = s mu_o
the depth; docs/references.md#jensen-2001, eq. 3's integral before it is done for a far light)

    L(x_o, w_o) = alpha sigma_t  integral_0^inf  e^{-sigma_t s} p(cos theta(s)) E(s) ds
    E(s) = I / R(s)^2 e^{-sigma_t s_in(s)},

R the distance from the light to the point, s_in the part of it inside the medium. For a far light
E(s) = E_0 e^{-sigma_t s mu_o / mu_i} and theta is fixed: L_far = alpha p(theta_0) E_0 mu_i / (mu_i + mu_o),
the term the frame adds. With t = sigma_t s (1 + mu_o / mu_i) the ratio of the two is

    gain = integral_0^inf e^{-t} p(theta(s)) / p(theta_0) (R_0 / R(s))^2 e^{-sigma_t (s_in(s) - s mu_o / mu_i)} dt,

1 for a far light, done by Gauss-Laguerre quadrature on NEAR_SINGLE_NODES nodes (the integrand is
smooth: the far light's own decay is in the weight). The surface is taken as the tangent plane at
x_o (the geometric normal). s_in = R z / (z + h), h the light's height over the plane (similar
triangles). At eta > 1 the light inside seems to come from the paraxial (sagittal) virtual source:
eta D along the refracted direction to the light (n'/s' = n/s at a plane), h its height; the
directions are the refracted ones, as in single_scatter_brdf. Exact at eta = 1 (tested against a
brute-force integral in tests/scene/optics/test_near_single.py).

GLSL twin: skinlab/shaders/lib/sss_near_single.glsl sss_near_single_gain.
"""

from __future__ import annotations

import numpy as np

from .constants import MIN_COS, NEAR_SINGLE_MAX_GAIN, NEAR_SINGLE_MIN_OPTICAL, NEAR_SINGLE_T, NEAR_SINGLE_W
from .fresnel import hg_phase
from .single_scattering import refract_cos


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)


def _refracted_up(w: np.ndarray, ng: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The direction inside the medium, pointing out (toward the side of w), of light crossing the
    plane along w (unit, pointing out), and its cosine to ng."""
    mu = np.clip(np.sum(w * ng, -1), 0.0, 1.0)
    mu_t = refract_cos(mu, eta)
    t = (w - mu[..., None] * ng) / eta[..., None] + mu_t[..., None] * ng
    return _unit(t), mu_t


def near_single_gain(d_mm, ng, v, sigma_t, eta, g, nodes=None) -> np.ndarray:
    """(N, 3) the factor on the single-scattering BRDF term of a point or spot light at x_o.

    d_mm (N, 3): from x_o to the light, millimetres; ng (N, 3): unit geometric normals; v (N, 3): unit
    directions to the eye; sigma_t (N, 3) or (3,): the real extinction per millimetre (0: none, the
    gain is 0); eta (N,) or scalar: the relative index (at least 1: below it the boundary's single
    scattering uses 1 too); g: Henyey-Greenstein anisotropy. 1 where the light grazes the plane
    (mu_i <= MIN_COS) or is a far one; at most NEAR_SINGLE_MAX_GAIN. `nodes`: (t, w) of another
    quadrature (the tests' reference)."""
    d = np.atleast_2d(np.asarray(d_mm, np.float64))
    ng = _unit(np.atleast_2d(np.asarray(ng, np.float64)))
    v = _unit(np.atleast_2d(np.asarray(v, np.float64)))
    n = max(len(d), len(ng), len(v))
    d, ng, v = (np.broadcast_to(a, (n, 3)) for a in (d, ng, v))
    sig = np.broadcast_to(np.asarray(sigma_t, np.float64), (n, 3))
    eta = np.broadcast_to(np.maximum(np.asarray(eta, np.float64), 1.0), (n,))
    ts, ws = (NEAR_SINGLE_T, NEAR_SINGLE_W) if nodes is None else nodes
    with np.errstate(all="ignore"):
        return _integrate(d, ng, v, sig, eta, float(g), np.asarray(ts, np.float64), np.asarray(ws, np.float64))


def _integrate(d, ng, v, sig, eta, g, ts, ws) -> np.ndarray:
    dist = np.linalg.norm(d, axis=-1)
    l = d / np.maximum(dist, 1e-300)[:, None]
    mu_i = np.sum(l * ng, -1)
    valid = (mu_i > MIN_COS) & (dist > 0)
    tl, mu_ti = _refracted_up(l, ng, eta)
    tv, mu_to = _refracted_up(v, ng, eta)
    mu_ti, mu_to = np.maximum(mu_ti, MIN_COS), np.maximum(mu_to, MIN_COS)
    # distances in units of the virtual source's distance eta D: q = sigma_t eta D, the optical one
    q = np.maximum(sig * (eta * dist)[:, None], NEAR_SINGLE_MIN_OPTICAL)  # (N, 3)
    h = mu_ti  # the virtual source's height over the plane, / (eta D)
    cos0 = np.sum(-tl * tv, -1)
    p0 = hg_phase(cos0, g)
    k = 1.0 + mu_to / mu_ti
    gain = np.zeros_like(q)
    for t, w in zip(ts, ws):
        s = t / (q * k[:, None])  # the path length on the view ray, / (eta D)
        z = s * mu_to[:, None]  # its depth
        # from the point p = -tv s to the source at tl (both / (eta D)): r = tl + tv s
        r = tl[:, None, :] + tv[:, None, :] * s[..., None]  # (N, 3 channels, 3)
        big_r = np.linalg.norm(r, axis=-1)
        s_in = big_r * z / (z + h[:, None])
        cos_s = np.sum(-r * tv[:, None, :], -1) / big_r
        # -sigma_t (s_in - s mu_o / mu_i), in units of eta D: the far light's decay is in the weight
        decay = np.exp(-q * (s_in - s * (mu_to / mu_ti)[:, None]))
        gain += w * hg_phase(cos_s, g) / p0[:, None] * decay / (big_r * big_r)
    gain = np.minimum(gain, NEAR_SINGLE_MAX_GAIN)
    return np.where(valid[:, None], np.where(np.isfinite(gain), gain, 0.0), 1.0)
