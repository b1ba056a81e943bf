"""Sums of Gaussians: d'Eon & Luebke 2007 (GPU Gems 3, ch. 14; docs/references.md#deon-luebke-2007)
six-Gaussian skin profile and a
fitter that approximates any radial profile by K Gaussians with ONE set of variances shared by the
R, G, B channels (texture-space diffusion blurs once per variance for all channels) and per-channel
non-negative weights. Float64 twin of skinlab/shaders/lib/profiles_gaussians.glsl.

    G(v, r) = e^{-r^2/(2v)} / (2 pi v)    (integrates to 1 over the plane; G(v1) * G(v2) = G(v1 + v2))
    R(r) = sum_k w_k G(v_k, r)            (total reflectance = sum_k w_k per channel)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ._profile_util import f64
from .constants import PI, SKIN6_VARIANCES, SKIN6_WEIGHTS

MIN_VARIANCE_MM2 = 1e-12  # narrower Gaussians are deltas: "no scattering", value 0


def gaussian(v, r):
    """G(v, r) = e^{-r^2/2v}/(2 pi v); 0 for v below MIN_VARIANCE_MM2 (a delta)."""
    v, r = f64(v), f64(r)
    ok = v >= MIN_VARIANCE_MM2
    vs = np.where(ok, v, 1.0)
    with np.errstate(over="ignore"):
        g = np.exp(-(r * r) / (2.0 * vs)) / (2.0 * PI * vs)
    return np.where(ok, g, 0.0)


def gaussian_sum_profile(r, variances, weights):
    """(N,) radii (mm) x (K,) variances (mm^2) x (K, C) weights -> (N, C) in 1/mm^2."""
    r = np.atleast_1d(f64(r)).reshape(-1, 1)
    v = f64(variances).reshape(1, -1)
    return gaussian(v, r) @ f64(weights).reshape(v.shape[1], -1)


SKIN6_V = np.array(SKIN6_VARIANCES)
SKIN6_W = np.array(SKIN6_WEIGHTS)


def deon_skin_profile(r, albedo=(1.0, 1.0, 1.0)):
    """d'Eon & Luebke's six-Gaussian skin profile (weights sum to 1 per channel) times albedo."""
    return gaussian_sum_profile(r, SKIN6_V, SKIN6_W) * f64(albedo).reshape(1, -1)


@dataclass(frozen=True)
class GaussianFit:
    variances_mm2: np.ndarray  # (K,), ascending, shared by all channels
    weights: np.ndarray  # (K, C) non-negative
    rel_error: np.ndarray  # (C,) ||r (R - fit)||_2 / ||r R||_2 on the fit grid
    r_max_mm: float

    def profile(self, r):
        return gaussian_sum_profile(r, self.variances_mm2, self.weights)


class NoEnergy(ValueError):
    """The profile carries no energy between 1e-5 mm and 10 m in any channel: nothing to fit (a
    channel of albedo 0, or one whose light spreads less than 1e-5 mm: no scattering at any scale a
    frame resolves)."""


ENERGY_GRID_MM = (1e-5, 1e4)  # where _energy_radius looks for a profile's energy


def _cumulative_energy(profile_fn) -> tuple[np.ndarray, np.ndarray]:
    """(r (N,) on ENERGY_GRID_MM, cumulative energy int_0^r R 2 pi r' dr' (N, C)) by the trapezoid rule in log r."""
    r = np.geomspace(*ENERGY_GRID_MM, 2000)
    f = np.maximum(f64(profile_fn(r)).reshape(len(r), -1), 0.0) * 2 * PI * r[:, None] ** 2
    cum = np.concatenate(
        [np.zeros((1, f.shape[1])), np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(np.log(r))[:, None], axis=0)]
    )
    return r, cum


def _energy_radius(profile_fn, fraction):
    """Smallest radius holding `fraction` of every channel's energy (int R 2 pi r dr); NoEnergy if
    no channel has any on ENERGY_GRID_MM."""
    r, cum = _cumulative_energy(profile_fn)
    tot = cum[-1]
    if not np.all(np.isfinite(tot)):
        raise ValueError("profile_fn: profile has no finite energy to fit")
    if np.all(tot <= 0):
        raise NoEnergy("profile_fn: profile has no positive energy to fit")
    idx = [np.searchsorted(cum[:, c], fraction * tot[c]) for c in range(cum.shape[1]) if tot[c] > 0]
    return float(r[min(max(idx), len(r) - 1)])


TAIL_FRACTIONS = (0.9, 0.99, 0.999, 0.9999)  # fit_gaussians(tail_weight > 0): the energy kept beyond these


def tail_energies(profile_fn, fractions=TAIL_FRACTIONS) -> tuple[np.ndarray, np.ndarray]:
    """(radii (T,), energy beyond each (T, C)): the radii holding `fractions` of every channel's
    energy (the widest channel's, _energy_radius) and each channel's energy (int R 2 pi r dr)
    beyond them."""
    r, cum = _cumulative_energy(profile_fn)
    radii = np.array([_energy_radius(profile_fn, q) for q in fractions])
    inside = np.stack([np.interp(radii, r, cum[:, c]) for c in range(cum.shape[1])], axis=1)
    return radii, np.maximum(cum[-1][None, :] - inside, 0.0)


def _solve(basis, target):
    """NNLS per channel; basis (N, K), target (N, C) -> weights (K, C), residual norms (C,)."""
    from scipy.optimize import nnls  # scipy.optimize takes 0.4 s to import: only where a fit runs

    w = np.zeros((basis.shape[1], target.shape[1]))
    res = np.zeros(target.shape[1])
    for c in range(target.shape[1]):
        w[:, c], res[c] = nnls(basis, target[:, c])
    return w, res


def fit_gaussians(
    profile_fn: Callable[[np.ndarray], np.ndarray],
    K: int = 6,
    *,
    r_max: float | None = None,
    n_r: int = 400,
    energy_fraction: float = 0.999,
    optimise: str = "free",
    variances: np.ndarray | None = None,
    tail_weight: float = 0.0,
) -> GaussianFit:
    """Fit R(r) (``profile_fn(r_mm) -> (N, C)`` in 1/mm^2) by K Gaussians with shared variances.

    Least squares on r R(r) (d'Eon & Luebke's criterion) over a uniform grid on [0, r_max]
    (r_max: radius holding ``energy_fraction`` of each channel's energy unless given), with
    non-negative per-channel weights (NNLS). Variances: fixed if ``variances`` is given; else a
    geometric series v_k = v_0 q^k whose v_0, q minimise the summed squared relative error
    (``optimise="geometric"``), then (``optimise="free"``, default) all K log-variances refined
    from there. With ``tail_weight`` > 0 the least squares also asks, per channel, for the
    profile's energy beyond the radii holding TAIL_FRACTIONS of it (a Gaussian of variance v puts
    e^{-R^2/2v} of its energy beyond R: linear in the weights), each as a relative error times
    ``tail_weight``: r R(r) weighs the tail by its density, so a fit to it alone lets the last
    percent of the energy go (the diffusion's glow), which these rows keep. Returns a
    :class:`GaussianFit` with the relative L2 error of r R(r) per channel.
    """
    if int(K) != K or K < 1:
        raise ValueError(f"K: need a positive integer number of Gaussians, got {K!r}")
    if not (np.isfinite(tail_weight) and tail_weight >= 0):
        raise ValueError(f"tail_weight: expected a finite number >= 0, got {tail_weight!r}")
    if optimise not in ("free", "geometric"):
        raise ValueError(f"optimise: expected 'free' or 'geometric', got {optimise!r}")
    K = int(K)
    if r_max is None:
        r_max = _energy_radius(profile_fn, energy_fraction)
    if not (np.isfinite(r_max) and r_max > 0):
        raise ValueError(f"r_max: must be a positive finite radius, got {r_max!r}")
    # midpoints: avoid evaluating singular profiles (Burley) exactly at r = 0
    r = (np.arange(n_r) + 0.5) * (r_max / n_r)
    target = f64(profile_fn(r)).reshape(n_r, -1) * r[:, None]
    norms = np.sqrt(np.sum(target**2, axis=0))
    norms = np.where(norms > 0, norms, 1.0)
    tail_r, tail_e = tail_energies(profile_fn) if tail_weight > 0 else (np.zeros(0), np.zeros((0, target.shape[1])))
    # tail rows, per channel: (energy beyond R_j of each unit Gaussian, the profile's) scaled so a
    # residual is tail_weight x the relative error of that energy, in units of the r R(r) norm
    tail_scale = float(tail_weight) * norms[None, :] / np.maximum(tail_e, 1e-300) / np.sqrt(max(len(tail_r), 1))
    tail_scale = np.where(tail_e > 0, tail_scale, 0.0)

    def solve(logv):
        v = np.exp(np.sort(logv))
        basis = gaussian(v[None, :], r[:, None]) * r[:, None]
        if not len(tail_r):
            w, res = _solve(basis, target)
            return v, w, res / norms
        beyond = np.exp(-(tail_r[:, None] ** 2) / (2.0 * v[None, :]))  # (T, K)
        w = np.zeros((len(v), target.shape[1]))
        res = np.zeros(target.shape[1])
        for c in range(target.shape[1]):
            a = np.vstack([basis, beyond * tail_scale[:, c : c + 1]])
            b = np.concatenate([target[:, c], tail_e[:, c] * tail_scale[:, c]])
            wc, rc = _solve(a, b[:, None])
            w[:, c], res[c] = wc[:, 0], rc[0]
        return v, w, res / norms

    def cost(logv):
        return float(np.sum(solve(logv)[2] ** 2))

    from scipy.optimize import minimize

    if variances is not None:
        v0 = np.log(f64(variances).ravel())
        if v0.size != K:
            raise ValueError(f"variances: expected {K} values, got {v0.size}")
        best = v0
    else:
        # geometric series spanning (r_max/200)^2 .. (r_max/2)^2 initially
        def geo(p):
            return p[0] + np.arange(K) * p[1]

        lo, hi = np.log((r_max / 200.0) ** 2), np.log((r_max / 2.0) ** 2)
        p0 = np.array([lo, (hi - lo) / max(K - 1, 1)])
        pr = minimize(
            lambda p: cost(geo(p)), p0, method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-12, "maxiter": 400}
        )
        best = geo(pr.x)
        if optimise == "free" and K > 1:
            fr = minimize(
                cost,
                best,
                method="Nelder-Mead",
                options={"xatol": 1e-4, "fatol": 1e-14, "maxiter": 300 * K, "adaptive": True},
            )
            if fr.fun < cost(best):
                best = fr.x
    v, w, rel = solve(best)
    if len(tail_r):  # report the shape's error alone
        basis = gaussian(v[None, :], r[:, None]) * r[:, None]
        rel = np.sqrt(np.sum((basis @ w - target) ** 2, axis=0)) / norms
    return GaussianFit(v, w, rel, float(r_max))
