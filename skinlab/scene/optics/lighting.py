"""NumPy twins of skinlab/shaders/lib/lighting.glsl."""

from __future__ import annotations

import numpy as np

from .constants import MIN_LIGHT_DISTANCE_M


def _norm(x, axis=-1):
    return np.linalg.norm(x, axis=axis, keepdims=True)


def perturb_normal(n, t, tex, scale):
    n = np.asarray(n, np.float64)
    t = np.asarray(t, np.float64)
    tex = np.asarray(tex, np.float64)
    scale = np.asarray(scale, np.float64)[..., None] if np.ndim(scale) else float(scale)
    ln = _norm(n)
    n = np.where(ln > 1e-8, n / np.where(ln > 1e-8, ln, 1), [0.0, 0.0, 1.0])
    tt = t[..., :3] - n * np.sum(n * t[..., :3], -1, keepdims=True)
    lt = _norm(tt)
    tt = tt / np.where(lt < 1e-6, 1, lt)
    b = np.cross(n, tt) * np.where(t[..., 3:4] < 0, -1.0, 1.0)
    m = tex * 2.0 - 1.0
    p = tt * (m[..., 0:1] * scale) + b * (m[..., 1:2] * scale) + n * m[..., 2:3]
    lp = _norm(p)
    out = np.where(lp > 1e-6, p / np.where(lp > 1e-6, lp, 1), n)
    return np.where(lt < 1e-6, n, out)


def inverse_square(d_mm):
    d = np.maximum(np.asarray(d_mm, np.float64) * 1e-3, MIN_LIGHT_DISTANCE_M)
    return 1.0 / (d * d)


def light_incidence(light_vec, radiance, world, n, mm_per_unit):
    """Twin of lib/lights.glsl light_incidence for one light: light_vec (4,) is the direction to the
    light (w = 0) or its position (w = 1); returns l (N, 3) and the irradiance e (N, 3) it brings to
    a surface facing it (point lights: inverse square of the distance in metres; at the light's own
    position l falls back to n and the distance to MIN_LIGHT_DISTANCE_M)."""
    light_vec = np.asarray(light_vec, np.float64)
    world = np.atleast_2d(np.asarray(world, np.float64))
    n = np.broadcast_to(np.asarray(n, np.float64), world.shape)
    e = np.broadcast_to(np.asarray(radiance, np.float64), world.shape).copy()
    if light_vec[3] == 0.0:
        return np.broadcast_to(light_vec[:3], world.shape).copy(), e
    d = light_vec[:3] - world
    dist = _norm(d)
    l = np.where(dist > 0, d / np.where(dist > 0, dist, 1.0), n)
    return l, e * inverse_square(dist * mm_per_unit)
