"""Registry of radial diffusion profiles: one interface for the CLI and the renderer.

Every model maps a :class:`~skinlab.scene.optics.media.Medium` and radii r (mm) to R(r) (N, 3) in 1/mm^2:
the light leaving the surface per unit area at distance r, per unit flux *entering* the medium
(normally incident; the renderer applies the entry/exit Fresnel of its specular layer itself), and
to the total reflectance (3,) = integral of R(r) 2 pi r dr.

Names:
  "none"           no subsurface transport: the profile is a delta at r = 0 (R(r) = 0 for every
                   r, including 0); total = the surface albedo, to be rendered as plain diffuse.
  "dipole"         Jensen 2001 dipole (multiple scattering only), closed-form total.
  "dipole+ss"      dipole + the single-scattering radial term (Jensen's full model for a beam).
  "burley"         Christensen-Burley normalized diffusion, A = PBD surface albedo, l = mfp,
                   perpendicular-incidence ("searchlight") s(A).
  "blender-burley" Cycles/EEVEE Burley: radius R = 4 pi l, diffuse-transmission s(A), truncated at
                   16 d and renormalised.
  "gaussians"      K = 6 Gaussians with shared variances fitted to the PBD profile (fit_gaussians).
  "deon-skin"      d'Eon & Luebke's six-Gaussian skin profile scaled by the surface albedo (a fixed
                   shape: ignores the mean free path except that l < MIN_MFP_MM gives 0).
  "pbd"            photon beam diffusion, multiple + single scattering (pbrt-v4).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from skinlab.cache import table

from .burley import blender_burley_profile, burley_profile
from .constants import MIN_MFP_MM
from .dipole import dipole_profile, dipole_total
from .gaussians import GaussianFit, deon_skin_profile, fit_gaussians, gaussian_sum_profile
from .media import Medium, mfp_to_radius
from .pbd import pbd_profile, pbd_total, radial_integral
from .single_scattering import single_scatter_profile


@dataclass(frozen=True)
class ProfileModel:
    name: str
    description: str
    evaluate: Callable[[np.ndarray, Medium], np.ndarray]  # (r_mm (N,), medium) -> (N, 3) 1/mm^2
    total: Callable[[Medium], np.ndarray]  # medium -> (3,)
    note: str = ""  # what a reader of a table of R(r) must know (a delta, a singularity at r = 0)


def _r(r):
    r = np.atleast_1d(np.asarray(r, dtype=np.float64)).ravel()
    if np.any(~np.isfinite(r)) or np.any(r < 0):
        raise ValueError("r: radii must be finite and >= 0 (mm)")
    return r


def _numeric_total(fn, m: Medium):
    """Integrate fn in optical units per channel (each channel's own mfp scales out)."""
    out = np.zeros(3)
    for c in range(3):
        if m.mfp_mm[c] <= 0:
            continue
        one = Medium(m.alpha, (1.0, 1.0, 1.0), m.eta)
        out[c] = radial_integral(lambda x, one=one, c=c: fn(x, one)[:, c : c + 1])[0]
    return out


@table(disk=True, maxsize=64)
def gaussian_fit_for(m: Medium, K: int = 6) -> GaussianFit:
    """Shared-variance Gaussian fit of the medium's PBD profile (cached per medium)."""
    return fit_gaussians(lambda r: pbd_profile(r, m.alpha_arr, m.mfp_arr, m.eta), K)


def _no_profile(m: Medium) -> bool:
    return bool(np.all((m.mfp_arr < MIN_MFP_MM) | (m.alpha_arr <= 0)))


def _gauss_eval(r, m):
    if _no_profile(m):
        return np.zeros((len(r), 3))
    f = gaussian_fit_for(m)
    return gaussian_sum_profile(r, f.variances_mm2, f.weights)


def _gauss_total(m):
    if _no_profile(m):
        return np.zeros(3)
    return gaussian_fit_for(m).weights.sum(axis=0)


def _A(m: Medium):
    return m.surface_albedo("pbd")


_R0_NOTE = (
    "R(r) diverges like 1/r at r = 0; the value shown at r = 0 is R at r = 2^-10 d (BURLEY_R0_EPS, d = l/s), "
    "the rim of a tiny disc, finite so that renderers can use it"
)

_MODELS = [
    ProfileModel(
        "none",
        "no subsurface transport (delta at r = 0)",
        lambda r, m: np.zeros((len(r), 3)),
        _A,
        "no subsurface transport: all light leaves where it entered (a delta at r = 0, not a function), so "
        "R(r) = 0 for every r and the total is the surface albedo, rendered as plain diffuse",
    ),
    ProfileModel(
        "dipole",
        "Jensen et al. 2001 dipole",
        lambda r, m: dipole_profile(r, m.alpha_arr, m.mfp_arr, m.eta),
        lambda m: dipole_total(m.alpha_arr, m.eta),
    ),
    ProfileModel(
        "dipole+ss",
        "Jensen 2001 dipole + single scattering",
        lambda r, m: (
            dipole_profile(r, m.alpha_arr, m.mfp_arr, m.eta) + single_scatter_profile(r, m.alpha_arr, m.mfp_arr, m.eta)
        ),
        lambda m: (
            dipole_total(m.alpha_arr, m.eta)
            + _numeric_total(lambda x, u: single_scatter_profile(x, u.alpha_arr, u.mfp_arr, u.eta), m)
        ),
    ),
    ProfileModel(
        "burley",
        "Christensen-Burley 2015, searchlight s(A)",
        lambda r, m: burley_profile(r, _A(m), m.mfp_arr, "searchlight"),
        _A,
        _R0_NOTE,
    ),
    ProfileModel(
        "blender-burley",
        "Blender Burley (R = 4 pi l, diffuse s(A), truncated at 16 d)",
        lambda r, m: blender_burley_profile(r, _A(m), mfp_to_radius(m.mfp_mm)),
        _A,
        _R0_NOTE,
    ),
    ProfileModel("gaussians", "6 shared-variance Gaussians fitted to PBD", _gauss_eval, _gauss_total),
    ProfileModel(
        "deon-skin",
        "d'Eon & Luebke 2007 skin Gaussians x surface albedo",
        lambda r, m: deon_skin_profile(r, _A(m) * (m.mfp_arr >= MIN_MFP_MM)),
        _A,
    ),
    ProfileModel(
        "pbd",
        "photon beam diffusion (Habel 2013 / pbrt-v4), MS + SS",
        lambda r, m: pbd_profile(r, m.alpha_arr, m.mfp_arr, m.eta),
        lambda m: np.where(m.mfp_arr > 0, pbd_total(m.alpha_arr, m.eta), 0.0),
    ),
]
PROFILE_MODELS: dict[str, ProfileModel] = {p.name: p for p in _MODELS}


def profile_names() -> list[str]:
    return list(PROFILE_MODELS)


def get_profile(name: str) -> ProfileModel:
    if name not in PROFILE_MODELS:
        raise ValueError(f"model: unknown profile {name!r}; choose one of {', '.join(PROFILE_MODELS)}")
    return PROFILE_MODELS[name]


def evaluate_profile(name: str, r_mm, medium: Medium) -> np.ndarray:
    """R(r) (N, 3) in 1/mm^2 of model `name` for `medium` at radii r_mm (mm, >= 0)."""
    return get_profile(name).evaluate(_r(r_mm), medium)


def total_reflectance(name: str, medium: Medium) -> np.ndarray:
    """Integral of R(r) over the plane (3,) (for "none": the delta's weight, the surface albedo)."""
    return np.asarray(get_profile(name).total(medium), dtype=np.float64)
