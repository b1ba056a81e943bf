"""Shared plumbing for the radial profiles: broadcasting and the optical-unit scaling.

Every profile is evaluated in optical units (mean free path l = 1/sigma_t' = 1) at x = r / l and
scaled back as R(r) = R_opt(r / l) / l^2. A mean free path below MIN_MFP_MM means no scattering
(profile 0) and x beyond PROFILE_MAX_OPTICAL_R gives 0, so nothing becomes inf or NaN.
"""

from __future__ import annotations

import numpy as np

from .constants import MIN_MFP_MM, PROFILE_MAX_OPTICAL_R


def f64(x):
    return np.asarray(x, dtype=np.float64)


def radial(r, *params):
    """r (N,) and channel parameters (3,) or scalars -> r as (N, 1) and params as (1, C)."""
    r = f64(r)
    if r.ndim == 0:
        r = r[None]
    r = r.reshape(-1, 1)
    out = [r]
    for p in params:
        p = f64(p)
        out.append(p.reshape(1, -1) if p.ndim else p.reshape(1, 1))
    return out


def optical(r, mfp):
    """(x = r / l with l clamped, inv_l2, valid mask) for r (N,1), mfp (1,C)."""
    valid_l = mfp >= MIN_MFP_MM
    l = np.where(valid_l, mfp, 1.0)
    x = np.abs(r) / l
    valid = valid_l & (x < PROFILE_MAX_OPTICAL_R)
    x = np.where(valid, x, 0.0)
    return x, 1.0 / (l * l), valid
