"""NumPy twins of shaders/lib/lighting.glsl."""
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
