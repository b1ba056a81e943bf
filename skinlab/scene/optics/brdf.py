"""NumPy twins of skinlab/shaders/lib/brdf.glsl (Burley 2012 principled BRDF pieces), float64.

Same names, same clamps as the GLSL; arrays broadcast. Vectors have shape (..., 3).
"""

from __future__ import annotations

import numpy as np

from .constants import INV_PI, MIN_COS, MIN_GGX_ALPHA, PI, SPECULAR_F0_SCALE


def _f(x):
    return np.asarray(x, dtype=np.float64)


def pow5(x):
    x = _f(x)
    x2 = x * x
    return x2 * x2 * x


def ggx_alpha(roughness):
    r = _f(roughness)
    return np.maximum(r * r, MIN_GGX_ALPHA)


def ggx_d(NoH, a):
    NoH = np.clip(_f(NoH), 0.0, 1.0)
    a2 = _f(a) ** 2
    s2 = (1.0 - NoH) * (1.0 + NoH)
    d = s2 + NoH * NoH * a2
    return a2 / (PI * d * d)


def smith_lambda(NoX, a):
    c = np.clip(_f(NoX), MIN_COS, 1.0)
    t2 = (1.0 - c) * (1.0 + c) / (c * c)
    x = _f(a) ** 2 * t2
    return 0.5 * x / (np.sqrt(1.0 + x) + 1.0)


def smith_g2(NoL, NoV, a):
    return 1.0 / (1.0 + smith_lambda(NoL, a) + smith_lambda(NoV, a))


def fresnel_schlick(f0, VoH):
    """Schlick's Fresnel from f0 toward F90 = min(50 f0, 1) at grazing (Karis 2013: below 2 % no real
    interface, so an index-matched boundary, f0 = 0, reflects nothing). f0 has a trailing RGB axis;
    VoH broadcasts against the rest."""
    f0 = _f(f0)
    w = pow5(1.0 - np.clip(_f(VoH), 0.0, 1.0))
    return f0 + (np.clip(50.0 * f0, 0.0, 1.0) - f0) * w[..., None]


def burley_diffuse(NoL, NoV, LoH, roughness):
    fd90 = 0.5 + 2.0 * _f(roughness) * _f(LoH) ** 2
    fl = 1.0 + (fd90 - 1.0) * pow5(1.0 - np.clip(_f(NoL), 0.0, 1.0))
    fv = 1.0 + (fd90 - 1.0) * pow5(1.0 - np.clip(_f(NoV), 0.0, 1.0))
    return fl * fv * INV_PI


def specular_ggx(NoL, NoV, NoH, VoH, a, f0):
    NoL = _f(NoL)
    nl = np.maximum(NoL, MIN_COS)
    nv = np.maximum(_f(NoV), MIN_COS)
    scal = ggx_d(NoH, a) * smith_g2(nl, nv, a) / (4.0 * nl * nv)
    f = fresnel_schlick(f0, VoH)
    out = scal[..., None] * f
    return np.where((NoL > 0.0)[..., None], out, 0.0)


def principled_f0(base, metallic, specular):
    base = _f(base)
    m = _f(metallic)[..., None]
    return (SPECULAR_F0_SCALE * _f(specular))[..., None] * (1.0 - m) + base * m


def _dot(a, b):
    return np.sum(_f(a) * _f(b), axis=-1)


def half_vector(n, v, l):
    h = _f(v) + _f(l)
    ln = np.linalg.norm(h, axis=-1, keepdims=True)
    return np.where(ln > 1e-6, h / np.where(ln > 1e-6, ln, 1.0), _f(n))


def principled_brdf_cos(n, v, l, base, roughness, metallic, specular):
    n, v, l, base = (
        np.broadcast_to(_f(x), np.broadcast_shapes(np.shape(n), np.shape(v), np.shape(l), np.shape(base)))
        for x in (n, v, l, base)
    )
    NoL = _dot(n, l)
    h = half_vector(n, v, l)
    NoV = _dot(n, v)
    NoH = _dot(n, h)
    LoH = _dot(l, h)
    a = ggx_alpha(roughness)
    diffuse = base * ((1.0 - _f(metallic)) * burley_diffuse(NoL, NoV, LoH, roughness))[..., None]
    spec = specular_ggx(NoL, NoV, NoH, LoH, a, principled_f0(base, metallic, specular))
    out = (diffuse + spec) * NoL[..., None]
    return np.where((NoL > 0.0)[..., None], out, 0.0)
