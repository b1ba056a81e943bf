"""Homogeneous scattering media, unit conversions and presets.

A :class:`Medium` is stored per RGB channel as the reduced single-scattering albedo
alpha = sigma_s'/sigma_t' and the mean free path l = 1/sigma_t' (mm), plus the relative index eta.
That form has finite limits everywhere (l = 0: no scattering; alpha = 1: no absorption), unlike
(sigma_s', sigma_a) which blow up as l -> 0. Conversions:

* (sigma_s', sigma_a) [1/mm]  <->  (alpha, l):  l = 1/(sigma_s' + sigma_a), alpha = sigma_s' l
* (alpha, eta) -> surface albedo A (the total diffuse reflectance R_d, what a user sees as colour):
  ``method="pbd"`` (default; photon beam diffusion integrated numerically - the model closest to the
  Monte Carlo reference, see docs/accuracy.md) or ``"dipole"`` (Jensen 2001 closed form).
* A -> alpha: numerical inversion of that total reflectance (monotonic in alpha): bisection on the
  dipole closed form, or interpolation in a 256-albedo PBD table per eta; or ``"cycles"``, the
  Chiang 2016 random-walk fit used by Cycles (docs/references.md#blender-burley),
  alpha = 1 - exp(A(-5.09406 + A(2.61188 - 4.31805 A))).
* artist radius R (Blender) <-> l:  l = R/(4 pi)  (Cycles' convention; docs/references.md#blender-burley).

Presets: the twelve measured materials of Jensen et al. 2001 Table 1, read from
skinlab/assets/presets/jensen2001_table1.csv (1/mm).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass

import numpy as np

from skinlab.cache import parallel_map, table
from skinlab.resources import asset_path

from .constants import MIN_MFP_MM, PI
from .dipole import dipole_total
from .pbd import pbd_total

PRESET_FILE = asset_path("presets", "jensen2001_table1.csv")
ALBEDO_METHODS = ("pbd", "dipole", "cycles")


def _rgb(x, name: str) -> np.ndarray:
    """Validate a scalar or RGB triple of finite numbers."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number or an R,G,B triple, got {x!r}") from None
    if a.ndim == 0:
        a = np.repeat(a, 3)
    if a.shape != (3,):
        raise ValueError(f"{name}: expected a number or 3 values (R,G,B), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: values must be finite, got {a.tolist()}")
    return a


def _nonneg(x, name):
    a = _rgb(x, name)
    if np.any(a < 0):
        raise ValueError(f"{name}: must be >= 0, got {a.tolist()}")
    return a


def _unit(x, name):
    a = _rgb(x, name)
    if np.any((a < 0) | (a > 1)):
        raise ValueError(f"{name}: must lie in [0, 1], got {a.tolist()}")
    return a


def check_eta(eta) -> float:
    try:
        e = float(eta)
    except (TypeError, ValueError):
        raise ValueError(f"eta: expected a number, got {eta!r}") from None
    if not np.isfinite(e) or e <= 0:
        raise ValueError(f"eta: relative index of refraction must be > 0, got {eta!r}")
    return e


# --- conversions -------------------------------------------------------------------------------


def coefficients_to_albedo_mfp(sigma_s, sigma_a):
    """(sigma_s', sigma_a) in 1/mm -> (alpha, mfp_mm). sigma_t' = 0 has no profile: ValueError."""
    s = _nonneg(sigma_s, "sigma_s")
    a = _nonneg(sigma_a, "sigma_a")
    t = s + a
    if np.any(t <= 0):
        raise ValueError(
            f"sigma_s + sigma_a: must be > 0 in every channel (got sigma_s={s.tolist()}, "
            f"sigma_a={a.tolist()}); a medium that neither scatters nor absorbs has no profile"
        )
    with np.errstate(over="ignore"):
        mfp = 1.0 / t
    if not np.all(np.isfinite(mfp)):
        raise ValueError(
            f"sigma_s + sigma_a: {t.tolist()} 1/mm is too small; its mean free path 1/sigma_t "
            f"overflows (need sigma_s + sigma_a > {1.0 / np.finfo(np.float64).max:.3g} 1/mm)"
        )
    return s / t, mfp


def albedo_mfp_to_coefficients(alpha, mfp_mm):
    """(alpha, l) -> (sigma_s', sigma_a) in 1/mm; l = 0 gives inf (sigma_a = 0 where alpha = 1)."""
    al = _unit(alpha, "alpha")
    l = _nonneg(mfp_mm, "mfp")
    with np.errstate(divide="ignore", invalid="ignore"):
        st = 1.0 / l
        ss = np.where(al > 0, al * st, 0.0)
        sa = np.where(al < 1, (1.0 - al) * st, 0.0)
    return ss, sa


def radius_to_mfp(radius_mm):
    """Blender artist radius R -> mean free path l = R/(4 pi)."""
    return _nonneg(radius_mm, "radius") / (4.0 * PI)


def mfp_to_radius(mfp_mm):
    """Mean free path l -> Blender artist radius R = 4 pi l."""
    return _nonneg(mfp_mm, "mfp") * 4.0 * PI


def surface_albedo(alpha, eta, method: str = "pbd"):
    """Total diffuse reflectance A (per unit entering flux, normal incidence) of a medium."""
    al = _unit(alpha, "alpha")
    e = check_eta(eta)
    if method == "dipole":
        return dipole_total(al, e)
    if method == "pbd":
        tab_a, tab_r = _pbd_table(round(e, 6))
        return np.interp(al, tab_a, tab_r)
    if method == "cycles":
        return _cycles_forward(al)
    raise ValueError(f"method: unknown albedo method {method!r}; choose one of {ALBEDO_METHODS}")


@table(disk=True, maxsize=32)
def _pbd_table(eta: float):
    """alpha grid (dense near 1, as pbrt's rhoSamples) and PBD effective albedo, made monotonic."""
    n = 256
    i = np.arange(n)
    a = (1.0 - np.exp(-8.0 * i / (n - 1))) / (1.0 - np.exp(-8.0))
    a[-1] = 1.0
    r = np.concatenate(parallel_map(lambda k: pbd_total(a[k : k + 64], eta), list(range(0, n, 64))))
    return a, np.maximum.accumulate(r)


def _cycles_alpha(A):
    return 1.0 - np.exp(A * (-5.09406 + A * (2.61188 - 4.31805 * A)))


def _cycles_forward(alpha):
    """Inverse of the Cycles fit (monotonic on [0, 1]) by bisection."""
    lo, hi = np.zeros_like(alpha), np.ones_like(alpha)
    top = _cycles_alpha(np.ones_like(alpha))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = _cycles_alpha(mid) < alpha
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return np.where(alpha >= top, 1.0, 0.5 * (lo + hi))


def invert_surface_albedo(A, eta, method: str = "pbd"):
    """Surface albedo A (R_d colour) -> reduced single-scattering albedo alpha, per channel.

    "pbd" / "dipole": numerical inversion of the model's total reflectance (monotonic in alpha);
    an A above the model's maximum (alpha = 1) gives alpha = 1. "cycles": Chiang 2016 fit."""
    A = _unit(A, "albedo")
    e = check_eta(eta)
    if method == "cycles":
        return np.clip(_cycles_alpha(A), 0.0, 1.0)
    if method == "pbd":
        tab_a, tab_r = _pbd_table(round(e, 6))
        # strictly increasing table for interp (flat parts only at the ends)
        keep = np.concatenate([[True], np.diff(tab_r) > 0])
        return np.clip(np.interp(A, tab_r[keep], tab_a[keep]), 0.0, 1.0)
    if method == "dipole":
        lo, hi = np.zeros(3), np.ones(3)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            below = dipole_total(mid, e) < A
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        return 0.5 * (lo + hi)
    raise ValueError(f"method: unknown albedo method {method!r}; choose one of {ALBEDO_METHODS}")


# --- the medium ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Medium:
    """Homogeneous medium per RGB channel. Use the constructors; fields are validated tuples."""

    alpha: tuple[float, float, float]
    mfp_mm: tuple[float, float, float]
    eta: float = 1.3
    name: str = ""

    def __post_init__(self):
        object.__setattr__(self, "alpha", tuple(_unit(self.alpha, "alpha").tolist()))
        object.__setattr__(self, "mfp_mm", tuple(_nonneg(self.mfp_mm, "mfp").tolist()))
        object.__setattr__(self, "eta", check_eta(self.eta))

    # constructors
    @classmethod
    def from_coefficients(cls, sigma_s, sigma_a, eta=1.3, name=""):
        """Reduced scattering sigma_s' and absorption sigma_a in 1/mm."""
        al, l = coefficients_to_albedo_mfp(sigma_s, sigma_a)
        return cls(tuple(al), tuple(l), eta, name)

    @classmethod
    def from_surface_albedo(cls, albedo, mfp_mm, eta=1.3, method="pbd", name=""):
        """A user colour (diffuse surface albedo R_d per channel) and mean free path l (mm)."""
        al = invert_surface_albedo(albedo, eta, method)
        return cls(tuple(al), tuple(_nonneg(mfp_mm, "mfp")), eta, name)

    @classmethod
    def from_artist_radius(cls, albedo, radius_mm, eta=1.3, method="pbd", name=""):
        """Blender-style colour + radius: l = R/(4 pi)."""
        return cls.from_surface_albedo(albedo, radius_to_mfp(radius_mm), eta, method, name)

    @classmethod
    def preset(cls, name: str):
        return preset(name)

    # derived quantities
    @property
    def alpha_arr(self) -> np.ndarray:
        return np.array(self.alpha)

    @property
    def mfp_arr(self) -> np.ndarray:
        return np.array(self.mfp_mm)

    @property
    def scattering(self) -> np.ndarray:
        """(3,) bool: the channels that scatter at all, a mean free path of at least MIN_MFP_MM (a
        shorter one is no scattering for every profile) and an albedo above 0."""
        return (self.mfp_arr >= MIN_MFP_MM) & (self.alpha_arr > 0)

    @property
    def sigma_s(self) -> np.ndarray:
        return albedo_mfp_to_coefficients(self.alpha, self.mfp_mm)[0]

    @property
    def sigma_a(self) -> np.ndarray:
        return albedo_mfp_to_coefficients(self.alpha, self.mfp_mm)[1]

    @property
    def sigma_t(self) -> np.ndarray:
        with np.errstate(divide="ignore"):
            return 1.0 / self.mfp_arr

    @property
    def sigma_tr(self) -> np.ndarray:
        """Effective transport coefficient sqrt(3 sigma_a sigma_t') in 1/mm."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.sqrt(3.0 * (1.0 - self.alpha_arr)) / self.mfp_arr

    @property
    def artist_radius_mm(self) -> np.ndarray:
        return mfp_to_radius(self.mfp_mm)

    def surface_albedo(self, method: str = "pbd") -> np.ndarray:
        return surface_albedo(self.alpha, self.eta, method)

    def scaled(self, k: float) -> Medium:
        """Same medium with every length multiplied by k (scene-scale changes)."""
        return Medium(self.alpha, tuple(self.mfp_arr * float(k)), self.eta, self.name)


@table(maxsize=1)
def _load_presets() -> dict[str, Medium]:
    out = {}
    with open(PRESET_FILE, newline="") as fh:
        rows = [ln for ln in fh if ln.strip() and not ln.lstrip().startswith("#")]
    for row in csv.DictReader(rows):
        ss = [float(row[f"sigma_s_{c}"]) for c in "rgb"]
        sa = [float(row[f"sigma_a_{c}"]) for c in "rgb"]
        out[row["material"]] = Medium.from_coefficients(ss, sa, float(row["eta"]), row["material"])
    return out


def forget_presets() -> None:
    """Drop the presets read so far: the next look-up reads PRESET_FILE afresh (hot reload)."""
    _load_presets.cache_clear()


def preset_names() -> list[str]:
    return sorted(_load_presets())


def preset(name: str) -> Medium:
    p = _load_presets()
    if name not in p:
        raise ValueError(f"preset: unknown material {name!r}; choose one of {', '.join(sorted(p))}")
    return p[name]
