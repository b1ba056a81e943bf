"""Screen-space separable subsurface scattering (Jimenez, Sundstedt & Gutierrez 2009; Jimenez et al.
2015 "Separable Subsurface Scattering"; docs/references.md#jimenez-ssss): one 1-D kernel applied horizontally then
vertically in screen space, its width in pixels from each pixel's depth. NumPy reference of the kernel used by
skinlab/shaders/techniques/ssss/blur.frag.

The 1-D kernel is built from the same normalised Gaussian fit as texture-space diffusion: at offset
x (mm), k(x) = I delta(x) + sum_k W_k g(v_k, x) with g the 1-D Gaussian of variance v_k. Applied along
x and then y it gives k(x) k(y) - the separable approximation whose error the ledger measures
(an isotropic sum of Gaussians is separable only for K = 1 and no identity term).
Sample offsets follow Jimenez's presets: denser near the centre, x_i = range t_i |t_i| for t_i uniform
in [-1, 1], range = 3 sigma of the widest Gaussian. Weights: the kernel's mass over each sample's
cell, normalised per channel to sum to 1.
"""

from __future__ import annotations

import math

import numpy as np

from .profile_fit import ProfileFit

SSSS_RANGE_SIGMAS = 3.0


def _phi(x):
    return 0.5 * (1.0 + np.vectorize(math.erf)(np.asarray(x, np.float64) / math.sqrt(2.0)))


def ssss_kernel(fit: ProfileFit, taps: int):
    """(offsets_mm (n,), weights (n, 3), range_mm) for an odd tap count."""
    if taps < 3 or taps % 2 == 0:
        raise ValueError(f"ssss_taps: expected an odd count >= 3, got {taps}")
    v = np.asarray(fit.variances_mm2, np.float64)
    W = np.asarray(fit.weights, np.float64).reshape(-1, 3)
    live = W.max(axis=1) > 0 if len(v) else np.zeros(0, bool)
    sig_max = math.sqrt(v[live].max()) if live.any() else 0.0
    rng = SSSS_RANGE_SIGMAS * sig_max
    t = np.linspace(-1.0, 1.0, taps)
    x = rng * t * np.abs(t)
    # cell edges halfway between samples (the outer cells extend to +-infinity)
    edges = np.concatenate([[-np.inf], 0.5 * (x[1:] + x[:-1]), [np.inf]])
    w = np.zeros((taps, 3))
    for k in range(len(v)):
        s = math.sqrt(max(v[k], 1e-30))
        mass = _phi(edges[1:] / s) - _phi(edges[:-1] / s)
        w += mass[:, None] * W[k][None, :]
    w[taps // 2] += np.asarray(fit.identity, np.float64)
    tot = w.sum(axis=0)
    w = np.where(tot > 0, w / np.where(tot > 0, tot, 1.0), 0.0)
    w[taps // 2] = np.where(tot > 0, w[taps // 2], 1.0)
    return x, w, rng


def separable_edge_response(x_mm, offsets, weights):
    """Fraction of a half-plane's light (lit for x < 0) at distance x past a straight edge after the
    1-D kernel along x (the perpendicular pass leaves a straight edge unchanged)."""
    x = np.atleast_1d(np.asarray(x_mm, np.float64))
    return np.stack(
        [(weights[None, :, c] * ((x[:, None] - offsets[None, :]) < 0)).sum(axis=1) for c in range(weights.shape[1])],
        axis=1,
    )
