"""The tint baseline (the `tint` technique, skinlab/render/techniques/tint/): each pixel's subsurface
light times one colour from the material's exact profile, no light moved."""

from __future__ import annotations

import numpy as np

from .media import Medium
from .profile_fit import MODEL_PROFILES
from .profiles import get_profile


def profile_tint(model: str, medium: Medium) -> np.ndarray:
    """The per-pixel tint baseline (no convolution): the exact profile evaluated at one radius, the
    mean free path averaged over the scattering channels, scaled so the brightest channel is 1.
    Kept only as the baseline it is: it shifts colour but moves no light."""
    scatter = medium.scattering
    if model not in MODEL_PROFILES or not scatter.any():
        return np.ones(3)
    r0 = float(medium.mfp_arr[scatter].mean())
    R = np.asarray(get_profile(MODEL_PROFILES[model]).evaluate(np.array([r0]), medium), np.float64)[0]
    R = np.where(scatter, np.maximum(R, 0.0), R.max() if R.max() > 0 else 1.0)
    return R / R.max() if R.max() > 0 else np.ones(3)
