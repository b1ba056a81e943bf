"""How much light a rough dielectric boundary reflects and transmits (flux fractions), from outside
and from inside the medium: the boundary the path-traced truth renders for a material with an index
above 1 (Mitsuba's ``roughdielectric``, GGX with alpha = roughness^2; skinlab/truth/export.py).

The microfacet model is Walter et al. 2007 ("Microfacet models for refraction through rough
surfaces", EGSR) with the separable Smith shadowing of GGX, G1(v) = 2 / (1 + sqrt(1 + alpha^2
tan^2 theta_v)). Of light arriving along w_i, a microfacet normal m is drawn from the distribution
of visible normals (Heitz 2018, "Sampling the GGX distribution of visible normals", JCGT 7(4)); the
facet reflects F(w_i.m) of it and refracts the rest, and what leaves along w_o is kept with
G1(w_o) (Walter's BSDF divided by that sampling density; what Mitsuba's weight is, in flux). The
directional albedos here integrate that over a fixed stratified grid of facet samples (smooth in
the cosine, deterministic).

This single-scattering microfacet model is not energy conserving: light that a facet sends into a
neighbouring facet (masked) is lost, not scattered again. From outside at alpha 0.2 and index 1.3
R + T is 0.997 at normal incidence and 0.89 at cosine 0.1; from inside, where light beyond the
critical angle is totally reflected by facets at grazing angles, 0.85 at cosine 0.5 and 0.76 at
0.1. Light under a rough boundary meets it again and again (skin's red: the internal reflectance is
0.45), so the loss adds up: a flat skin1 slab at index 1.3 reflects 8 % less red light under the
rough boundary (roughness 0.45) than under a smooth one (docs/ground-truth.md, "The rough boundary
at index 1.3").
"""

from __future__ import annotations

import numpy as np

from skinlab.cache import table

from .fresnel import fresnel_dielectric

SMOOTH_ALPHA = 1e-3  # below this the boundary is a smooth dielectric (as the truth exporter)
_GRID = 48  # facet samples per axis (stratified midpoints)
_GL_N = 96  # Gauss-Legendre nodes of the hemispherical means


def ggx_g1(cos_v, alpha: float) -> np.ndarray:
    """Smith shadowing of GGX for a direction at cosine cos_v (> 0) to the macro normal."""
    c = np.clip(np.asarray(cos_v, np.float64), 1e-9, 1.0)
    tan2 = (1.0 - c * c) / (c * c)
    return 2.0 / (1.0 + np.sqrt(1.0 + alpha * alpha * tan2))


def _visible_normals(mu: np.ndarray, alpha: float, n: int = _GRID) -> tuple[np.ndarray, np.ndarray]:
    """Facet normals (len(mu), n*n, 3) drawn from the GGX distribution of visible normals for
    w_i = (sqrt(1 - mu^2), 0, mu) (Heitz 2018, listing 1), and w_i (len(mu), 3)."""
    mu = np.clip(np.asarray(mu, np.float64), 1e-6, 1.0)
    wi = np.stack([np.sqrt(np.maximum(1.0 - mu * mu, 0.0)), np.zeros_like(mu), mu], -1)
    vh = wi * np.array([alpha, alpha, 1.0])
    vh /= np.linalg.norm(vh, axis=-1, keepdims=True)
    # orthonormal basis around vh (vh has no y component: T1 = (-vh.z, 0, vh.x)/len, T2 = vh x T1)
    lensq = vh[:, 0] ** 2 + vh[:, 1] ** 2
    t1 = np.where(
        lensq[:, None] > 1e-12,
        np.stack([-vh[:, 1], vh[:, 0], np.zeros_like(mu)], -1) / np.sqrt(np.maximum(lensq, 1e-30))[:, None],
        np.array([1.0, 0.0, 0.0]),
    )
    t2 = np.cross(vh, t1)
    u = (np.arange(n) + 0.5) / n
    u1, u2 = np.meshgrid(u, u, indexing="ij")
    r, phi = np.sqrt(u1.ravel()), 2.0 * np.pi * u2.ravel()
    p1 = r * np.cos(phi)
    p2 = r * np.sin(phi)
    s = 0.5 * (1.0 + vh[:, 2:3])
    p2 = (1.0 - s) * np.sqrt(np.maximum(1.0 - p1 * p1, 0.0)) + s * p2
    p3 = np.sqrt(np.maximum(1.0 - p1 * p1 - p2 * p2, 0.0))
    nh = p1[..., None] * t1[:, None, :] + p2[..., None] * t2[:, None, :] + p3[..., None] * vh[:, None, :]
    m = nh * np.array([alpha, alpha, 1.0])
    m[..., 2] = np.maximum(m[..., 2], 0.0)
    m /= np.maximum(np.linalg.norm(m, axis=-1, keepdims=True), 1e-30)
    return m, wi


def rough_albedos(mu, alpha: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """(R, T): the fractions of the flux arriving at cosine mu (to the macro normal, on the side the
    light comes from) that a rough dielectric of GGX alpha and relative index eta (the far side's
    index over the near side's: 1.3 from outside skin, 1/1.3 from inside) reflects and transmits.
    At alpha below SMOOTH_ALPHA: the smooth boundary's F and 1 - F."""
    mu = np.clip(np.asarray(mu, np.float64), 0.0, 1.0)
    shape = mu.shape
    mu = mu.ravel()
    if alpha < SMOOTH_ALPHA:
        f = fresnel_dielectric(mu, eta)
        return f.reshape(shape), (1.0 - f).reshape(shape)
    # the cosines a block at a time: each makes (block x facets x 3) temporaries, which stay in cache
    # (the same numbers as one block of all, faster on a long list such as the 257-node table)
    parts = [_rough_albedos(mu[i : i + _BLOCK], alpha, eta) for i in range(0, max(len(mu), 1), _BLOCK)]
    r, t = np.concatenate([x[0] for x in parts]), np.concatenate([x[1] for x in parts])
    return r.reshape(shape), t.reshape(shape)


_BLOCK = 64  # cosines per block of rough_albedos


def _rough_albedos(mu: np.ndarray, alpha: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """rough_albedos for a 1-D block of cosines (alpha >= SMOOTH_ALPHA)."""
    m, wi = _visible_normals(mu, alpha)
    c = np.clip(np.einsum("kj,ksj->ks", wi, m), 0.0, 1.0)  # w_i . m (> 0 for visible facets)
    f = fresnel_dielectric(c, eta)
    wr = 2.0 * c[..., None] * m - wi[:, None, :]
    r = np.where(wr[..., 2] > 0.0, f * ggx_g1(wr[..., 2], alpha), 0.0)
    # refraction through the facet: w_t = (c/eta - cos_t) m - w_i/eta
    sin2_t = (1.0 - c * c) / (eta * eta)
    cos_t = np.sqrt(np.maximum(1.0 - sin2_t, 0.0))
    wt = (c / eta - cos_t)[..., None] * m - wi[:, None, :] / eta
    t = np.where((wt[..., 2] < 0.0) & (sin2_t < 1.0), (1.0 - f) * ggx_g1(-wt[..., 2], alpha), 0.0)
    return r.mean(-1), t.mean(-1)


@table(maxsize=64)
def rough_diffuse_albedos(alpha: float, eta: float) -> tuple[float, float]:
    """(R_d, T_d): reflected and transmitted fractions of diffuse (cosine-weighted) light arriving at
    the boundary, 2 int R(mu) mu dmu and 2 int T(mu) mu dmu (pass eta < 1 for light from inside)."""
    x, w = np.polynomial.legendre.leggauss(_GL_N)
    mu, w = 0.5 * (x + 1.0), 0.5 * w
    r, t = rough_albedos(mu, alpha, eta)
    return float(2.0 * np.sum(w * mu * r)), float(2.0 * np.sum(w * mu * t))
