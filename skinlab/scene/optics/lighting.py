"""NumPy twins of skinlab/shaders/lib/lighting.glsl, lib/lights.glsl light_incidence and lib/area_lights.glsl."""

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


def spot_falloff(axis, l, outer, inv):
    """Twin of lib/area_lights.glsl spot_falloff: 1 within the inner half-angle, 0 beyond the outer
    (radians), linear in angle between; l (N, 3) toward the light, axis the way it shines."""
    axis = np.asarray(axis, np.float64)
    m = -np.asarray(l, np.float64)
    angle = np.arctan2(np.linalg.norm(np.cross(axis, m), axis=-1), m @ axis)
    return np.clip((outer - angle) * inv, 0.0, 1.0)


def sphere_irradiance(r, dist):
    """Twin of lib/area_lights.glsl sphere_irradiance: pi (r / dist)^2, pi inside the sphere."""
    dist = np.asarray(dist, np.float64)
    s = np.where(dist > r, r / np.where(dist > r, dist, 1.0), 1.0)
    return np.pi * s * s


def rect_vector_irradiance(c, ex, ey, axis, p):
    """Twin of lib/area_lights.glsl rect_vector_irradiance: (N, 3) the vector irradiance of a one-sided
    rectangle of radiance 1 (Lambert's polygon formula), zero behind it."""
    c, ex, ey, axis = (np.asarray(x, np.float64) for x in (c, ex, ey, axis))
    p = np.atleast_2d(np.asarray(p, np.float64))
    corners = [c - ex - ey, c + ex - ey, c + ex + ey, c - ex + ey]
    q = [k - p for k in corners]
    q = [x / np.linalg.norm(x, axis=1, keepdims=True) for x in q]
    f = np.zeros_like(p)
    for k in range(4):
        a, b = q[k], q[(k + 1) % 4]
        m = np.cross(a, b)
        ln = np.linalg.norm(m, axis=1, keepdims=True)
        ang = np.arctan2(ln[:, 0], np.sum(a * b, 1))
        f += np.where(ln > 1e-12, ang[:, None] * m / np.where(ln > 1e-12, ln, 1.0), 0.0)
    f *= 0.5
    f = np.where((np.sum(f * (c - p), 1) < 0.0)[:, None], -f, f)
    return np.where(((p - c) @ axis > 0.0)[:, None], f, 0.0)


def light_incidence(light_vec, radiance, world, n, mm_per_unit, axis=None, shape=None):
    """Twin of lib/lights.glsl light_incidence for one light: light_vec (4,) is the direction to the
    light (w = 0) or its position (w = 1); axis (4,) the way it shines and its kind code (0 plain,
    1 spot, 2 rect, 3 sphere), shape (4,) its cone or size (skinlab/render/lights.py light_shape).
    Returns l (N, 3) and the irradiance e (N, 3) it brings to a surface facing it (point and spot
    lights: inverse square of the distance in metres; at the light's own position l falls back to n
    and the distance to MIN_LIGHT_DISTANCE_M)."""
    light_vec = np.asarray(light_vec, np.float64)
    axis = np.zeros(4) if axis is None else np.asarray(axis, np.float64)
    shape = np.zeros(4) if shape is None else np.asarray(shape, np.float64)
    world = np.atleast_2d(np.asarray(world, np.float64))
    n = np.broadcast_to(np.asarray(n, np.float64), world.shape)
    e = np.broadcast_to(np.asarray(radiance, np.float64), world.shape).copy()
    kind = axis[3]
    if light_vec[3] == 0.0:
        return np.broadcast_to(light_vec[:3], world.shape).copy(), e
    if kind > 1.5 and kind < 2.5:  # rect
        ey = np.cross(axis[:3], shape[:3])
        ey = ey / np.linalg.norm(ey) * shape[3]
        f = rect_vector_irradiance(light_vec[:3], shape[:3], ey, axis[:3], world)
        ln = _norm(f)
        return np.where(ln > 0, f / np.where(ln > 0, ln, 1.0), n), e * ln
    d = light_vec[:3] - world
    dist = _norm(d)
    l = np.where(dist > 0, d / np.where(dist > 0, dist, 1.0), n)
    if kind > 2.5:  # sphere
        return l, e * sphere_irradiance(shape[0], dist)
    e = e * inverse_square(dist * mm_per_unit)
    if kind > 0.5:  # spot
        e = e * spot_falloff(axis[:3], l, shape[0], shape[1])[:, None]
    return l, e


def _unit(x):
    ln = _norm(x)
    return x / np.maximum(ln, 1e-20)


def sphere_specular_point(c, radius, p, r, a):
    """Twin of lib/area_lights.glsl sphere_specular_point: (ls (N, 3), a' (N,), energy (N,))."""
    p, r = np.atleast_2d(np.asarray(p, np.float64)), np.atleast_2d(np.asarray(r, np.float64))
    d = np.asarray(c, np.float64) - p
    to_ray = np.sum(d * r, 1, keepdims=True) * r - d
    ln = _norm(to_ray)
    q = d + to_ray * np.where(ln > 0, np.clip(radius / np.where(ln > 0, ln, 1.0), 0.0, 1.0), 0.0)
    a_wide = np.minimum(a + radius / (2.0 * np.maximum(_norm(d)[:, 0], 1e-20)), 1.0)
    return _unit(q), a_wide, (a / a_wide) ** 2


def rect_specular_point(c, ex, ey, p, r, a):
    """Twin of lib/area_lights.glsl rect_specular_point: (ls (N, 3), a' (N,), energy (N,))."""
    c, ex, ey = (np.asarray(x, np.float64) for x in (c, ex, ey))
    p, r = np.atleast_2d(np.asarray(p, np.float64)), np.atleast_2d(np.asarray(r, np.float64))
    nrm = np.cross(ex, ey)
    den = r @ nrm
    t = np.where(np.abs(den) > 1e-20, ((c - p) @ nrm) / np.where(np.abs(den) > 1e-20, den, 1.0), -1.0)
    hit = np.where((t > 0)[:, None], p + r * t[:, None], c)
    off = hit - c
    lx, ly = ex @ ex, ey @ ey
    q = c + np.clip(off @ ex / lx, -1, 1)[:, None] * ex + np.clip(off @ ey / ly, -1, 1)[:, None] * ey - p
    radius = np.sqrt(4.0 * np.sqrt(lx * ly) / np.pi)
    a_wide = np.minimum(a + radius / (2.0 * np.maximum(_norm(c - p)[:, 0], 1e-20)), 1.0)
    return _unit(q), a_wide, (a / a_wide) ** 2
