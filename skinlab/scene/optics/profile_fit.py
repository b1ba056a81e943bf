"""Shared-variance Gaussian fits of a material's radial diffusion profile (fit_gaussians on the profile
named by its sss_model), normalised per channel: the kernel of texture-space diffusion
(skinlab/scene/optics/tsd.py design_kernel), of the screen-space blur (skinlab/scene/optics/ssss.py)
and of the pre-integrated skin table (skinlab/scene/optics/preintegrated.py). MODEL_PROFILES maps a
material's sss_model to the profile registry's name (skinlab/scene/optics/profiles.py)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skinlab.cache import table

from .constants import SKIN6_VARIANCES, SKIN6_WEIGHTS
from .gaussians import NoEnergy, fit_gaussians
from .media import Medium
from .profiles import get_profile

MAX_FIT_GAUSSIANS = 6  # the most Gaussians a fit holds (d'Eon & Luebke's skin profile has six)
FIT_TAIL_WEIGHT = 0.0  # fit_gaussians' tail_weight for the profile fits

# The radius the d'Eon & Luebke skin Gaussians correspond to (the default skin radius, mm): the
# "gaussians" model scales their widths by the material's mean radius over this one.
SKIN6_RADIUS_MM = (3.67, 1.37, 0.68)

# material sss_model -> profile registry name used for the Gaussian fit
MODEL_PROFILES = {
    "dipole": "dipole",
    "burley": "burley",
    "blender-burley": "blender-burley",
    "pbd": "pbd",
    "gaussians": "deon-skin",
}


@dataclass(frozen=True)
class ProfileFit:
    model: str
    variances_mm2: np.ndarray  # (K,)
    weights: np.ndarray  # (K, 3) normalised: identity + sum = 1 per channel
    identity: np.ndarray  # (3,) weight of the unblurred irradiance (channels with no scattering)
    rel_error: np.ndarray  # (3,) the fit's relative L2 error on r R(r)


@table(disk=True, maxsize=128)
def profile_fit(model: str, medium: Medium, K: int = 6) -> ProfileFit:
    """K shared-variance Gaussians for `model` (a material sss_model) and `medium`, normalised."""
    if model not in MODEL_PROFILES:
        raise ValueError(
            f"sss_model: no Gaussian profile fit for {model!r}; expected one of {', '.join(MODEL_PROFILES)}"
        )
    if not (isinstance(K, int) and 1 <= K <= MAX_FIT_GAUSSIANS):
        raise ValueError(f"gaussians: expected an integer in [1, {MAX_FIT_GAUSSIANS}], got {K!r}")
    # channels that scatter at all (mean free paths below MIN_MFP_MM are "no scattering" for every
    # profile); the others keep the unblurred irradiance
    scatter = medium.scattering
    if model == "gaussians":
        radius = np.where(scatter, medium.artist_radius_mm, 0.0)
        scale = float(radius[scatter].mean() / np.mean(SKIN6_RADIUS_MM)) if scatter.any() else 0.0
        v_all = np.asarray(SKIN6_VARIANCES) * scale**2
        w_all = np.asarray(SKIN6_WEIGHTS, dtype=np.float64).reshape(-1, 3)  # (6, 3)
        if K < len(v_all):  # keep the K widest-weighted Gaussians
            keep = np.sort(np.argsort(-w_all.sum(axis=1))[:K])
            v_all, w_all = v_all[keep], w_all[keep]
        v, w, err = v_all, w_all, np.zeros(3)
    elif not scatter.any():
        v, w, err = np.zeros(0), np.zeros((0, 3)), np.zeros(3)
    else:
        prof = get_profile(MODEL_PROFILES[model])
        # fit only the scattering channels; the others are identity
        fn = lambda r: prof.evaluate(np.asarray(r, np.float64), medium) * scatter[None, :]
        try:
            fit = fit_gaussians(fn, K, tail_weight=FIT_TAIL_WEIGHT)
            v, w, err = fit.variances_mm2, fit.weights.copy(), np.where(scatter, fit.rel_error, 0.0)
        except NoEnergy:  # the light spreads less than 1e-5 mm in every scattering channel: none scatters
            v, w, err = np.zeros(0), np.zeros((0, 3)), np.zeros(3)
    w = np.where(scatter[None, :], w, 0.0)
    tot = w.sum(axis=0)
    ok = tot > 0
    wn = np.where(ok[None, :], w / np.where(ok, tot, 1.0)[None, :], 0.0)
    return ProfileFit(model, np.asarray(v, np.float64), wn, np.where(ok, 0.0, 1.0), err)
