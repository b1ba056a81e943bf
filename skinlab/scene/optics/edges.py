"""Edge responses: the fraction of a lit half-plane's light leaving at signed distance x (mm) past a
straight shadow edge (x < 0 lit), per channel, as x_mm -> (N, 3) functions. What the accuracy ledger
compares techniques by (docs/ledger.md): a delta (no scattering) gives a step, a Gaussian sum or a
tabulated radial profile its integral across the edge (edge_response)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .tsd import DiffusionKernel


def step(x) -> np.ndarray:
    """The hard step of no scattering, (N,): 1 on the lit side, 1/2 on the edge, 0 beyond."""
    x = np.asarray(x)
    return np.where(x < 0, 1.0, np.where(x == 0, 0.5, 0.0))


def step_edge(x) -> np.ndarray:
    """No scattering as an edge response, (N, 3)."""
    return np.repeat(step(x)[:, None], 3, axis=1)


def edge_response(x_mm: np.ndarray, fit_or_profile, kind: str = "gaussians") -> np.ndarray:
    """Fraction of a half-plane's irradiance (lit for x < 0) that leaves at distance x (mm) past the edge,
    per channel, for a normalised kernel: sum_k W_k Phi(-x / sigma_k) (+ identity step) for a Gaussian
    fit; for a radial profile (kind='profile', fit_or_profile = profile_fn(r_mm) -> (N, C)), the
    integral of R over the half-plane, by quadrature, divided by its integral over the plane."""
    x = np.atleast_1d(np.asarray(x_mm, np.float64))
    if kind == "gaussians":
        k: DiffusionKernel = fit_or_profile
        out = np.outer(step(x), k.identity)
        for s in k.steps:
            sig = math.sqrt(s.variance_mm2)
            phi = 0.5 * (1.0 + np.vectorize(math.erf)(-x / (sig * math.sqrt(2.0))))
            out += np.outer(phi, s.weight)
        return out
    fn = fit_or_profile
    # L(d) = int R(sqrt(d^2 + y^2)) dy: the light leaving at distance d from a line source; the
    # fraction beyond distance |x| from the edge is int_{|x|}^inf L / int_{-inf}^inf L.
    d = np.concatenate([[0.0], np.geomspace(1e-6, 400.0, 1500)])
    ys = np.concatenate([[0.0], np.geomspace(1e-6, 400.0, 1500)])
    r_tab = np.concatenate([[0.0], np.geomspace(1e-6, 600.0, 4000)])
    R_tab = np.asarray(fn(r_tab), np.float64).reshape(len(r_tab), -1)
    rr = np.hypot(d[:, None], ys[None, :])
    prof = np.stack([np.interp(rr, r_tab, R_tab[:, c]) for c in range(R_tab.shape[1])], axis=-1)
    line = 2.0 * np.trapezoid(prof, ys, axis=1)  # (nd, C)
    seg = 0.5 * (line[1:] + line[:-1]) * np.diff(d)[:, None]
    tail = np.concatenate([np.cumsum(seg[::-1], axis=0)[::-1], np.zeros((1, line.shape[1]))])  # int_d^inf
    half = tail[0]
    res = np.zeros((len(x), line.shape[1]))
    for c in range(line.shape[1]):
        far = np.interp(np.abs(x), d, tail[:, c]) / (2.0 * half[c]) if half[c] > 0 else np.where(x < 0, 0.5, 0.5)
        res[:, c] = np.where(x > 0, far, 1.0 - far)
    return res


def model_edge(model: str, medium):
    """The edge response of a diffusion model's exact radial profile (channels that do not scatter
    get none), or None for a model without a profile."""
    from skinlab.scene.optics.profile_fit import MODEL_PROFILES
    from skinlab.scene.optics.profiles import get_profile

    if model not in MODEL_PROFILES:
        return None
    scatter = medium.scattering
    prof = get_profile(MODEL_PROFILES[model])
    fn = lambda r: prof.evaluate(np.asarray(r, np.float64), medium) * scatter[None, :]
    return lambda x: edge_response(x, fn, "profile")


def gaussians_edge(kernel):
    """The edge response of a texture-space diffusion kernel (its Gaussian sum plus identity)."""
    return lambda x: edge_response(x, kernel, "gaussians")


def separable_edge(offsets_mm, weights):
    """The edge response of a screen-space separable kernel across an edge along a screen axis."""
    from skinlab.scene.optics.ssss import separable_edge_response

    return lambda x: separable_edge_response(x, np.asarray(offsets_mm), np.asarray(weights))
