"""Edge responses: the fraction of a lit half-plane's light leaving at signed distance x (mm) past a
straight shadow edge (x < 0 lit), per channel, as x_mm -> (N, 3) functions. What the accuracy ledger
compares techniques by (docs/ledger.md): a delta (no scattering) gives a step, a Gaussian sum or a
tabulated radial profile its integral across the edge (skinlab/scene/optics/tsd.py edge_response)."""

from __future__ import annotations

import numpy as np


def step(x) -> np.ndarray:
    """The hard step of no scattering, (N,): 1 on the lit side, 1/2 on the edge, 0 beyond."""
    x = np.asarray(x)
    return np.where(x < 0, 1.0, np.where(x == 0, 0.5, 0.0))


def step_edge(x) -> np.ndarray:
    """No scattering as an edge response, (N, 3)."""
    return np.repeat(step(x)[:, None], 3, axis=1)


def scattering_channels(medium) -> np.ndarray:
    """(3,) bool: the channels that scatter (a mean free path of at least MIN_MFP_MM and albedo > 0)."""
    from skinlab.scene.optics.constants import MIN_MFP_MM

    return (medium.mfp_arr >= MIN_MFP_MM) & (medium.alpha_arr > 0)


def model_edge(model: str, medium):
    """The edge response of a diffusion model's exact radial profile (channels that do not scatter
    get none), or None for a model without a profile."""
    from skinlab.scene.optics.profile_fit import MODEL_PROFILES
    from skinlab.scene.optics.profiles import get_profile
    from skinlab.scene.optics.tsd import edge_response

    if model not in MODEL_PROFILES:
        return None
    scatter = scattering_channels(medium)
    prof = get_profile(MODEL_PROFILES[model])
    fn = lambda r: prof.evaluate(np.asarray(r, np.float64), medium) * scatter[None, :]
    return lambda x: edge_response(x, fn, "profile")


def gaussians_edge(kernel):
    """The edge response of a texture-space diffusion kernel (its Gaussian sum plus identity)."""
    from skinlab.scene.optics.tsd import edge_response

    return lambda x: edge_response(x, kernel, "gaussians")


def separable_edge(offsets_mm, weights):
    """The edge response of a screen-space separable kernel across an edge along a screen axis."""
    from skinlab.scene.optics.ssss import separable_edge_response

    return lambda x: separable_edge_response(x, np.asarray(offsets_mm), np.asarray(weights))
