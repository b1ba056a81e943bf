"""Profile error: a technique's edge response against the Monte Carlo random walk's (and the material's
own model profile's), as the relative L1 over +-EDGE_RANGE_MFP mean free paths per channel."""

from __future__ import annotations

import io
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from skinlab.atomic_write import write_bytes_atomic
from skinlab.scene.optics.edges import model_edge, step, step_edge

EDGE_RANGE_MFP = 50.0  # the edge-response integral spans +-50 mean free paths per channel
MC_SEED = 1


def mc_profile(alpha: float, eta: float, photons: int, cache_dir: Path | None, seed: int = MC_SEED):
    """(r_edges, R, total) of the random walk in mean-free-path units (normal incidence, isotropic
    reduced phase function, per entering photon), cached as .npz under cache_dir."""
    from skinlab.scene.optics.montecarlo import simulate

    path = None
    if cache_dir is not None:
        path = Path(cache_dir) / f"mc-a{alpha:.8f}-eta{eta:.6f}-n{photons}-s{seed}.npz"
        if path.is_file():
            try:
                d = np.load(path)
                return d["r_edges"], d["R"], float(d["total"])
            except Exception:
                pass  # a corrupt cache entry is recomputed
    res = simulate(alpha, eta, 0.0, "normal", photons, seed, progress=False, workers=min(2, os.cpu_count() or 1))
    if path is not None:
        buf = io.BytesIO()
        np.savez(buf, r_edges=res.r_edges, R=res.R, R_se=res.R_se, total=res.total, total_se=res.total_se)
        write_bytes_atomic(path, buf.getvalue())
    return res.r_edges, res.R, res.total


@dataclass
class ProfileReference:
    """Monte Carlo edge responses of one medium, per scattering channel, on a fixed x grid (mm)."""

    medium: object
    scatter: np.ndarray  # (3,) bool
    x: list  # per channel: x grid (mm) or None
    e_mc: list  # per channel: MC edge response on x
    denom: list  # per channel: int |H - E_mc| dx
    photons: int
    cache: dict = field(default_factory=dict)


def _edge_grid(mfp: float) -> np.ndarray:
    pos = np.geomspace(1e-3, EDGE_RANGE_MFP, 700) * mfp
    return np.concatenate([-pos[::-1], [0.0], pos])


def _reference(medium, edge_of_channel, photons: int = 0) -> ProfileReference:
    """Edge responses of a reference per scattering channel: edge_of_channel(c, x_mm) -> (N,)."""
    scatter = medium.scattering
    xs, es, dens = [], [], []
    for c in range(3):
        if not scatter[c]:
            xs.append(None), es.append(None), dens.append(None)
            continue
        x = _edge_grid(float(medium.mfp_arr[c]))
        e = np.asarray(edge_of_channel(c, x), np.float64)
        xs.append(x), es.append(e), dens.append(float(np.trapezoid(np.abs(step(x) - e), x)))
    return ProfileReference(medium, scatter, xs, es, dens, photons)


def profile_reference(medium, photons: int, cache_dir: Path | None) -> ProfileReference:
    """The Monte Carlo edge responses of `medium` (one random walk per scattering channel)."""
    from skinlab.scene.optics.edges import edge_response

    def edge(c, x):
        mfp = float(medium.mfp_arr[c])
        edges, R, _ = mc_profile(float(medium.alpha_arr[c]), float(medium.eta), photons, cache_dir)
        r_mid = np.sqrt(0.5 * (edges[:-1] ** 2 + edges[1:] ** 2)) * mfp
        R_mm = R / mfp**2
        r_max = edges[-1] * mfp
        fn = lambda r: np.where(np.asarray(r) <= r_max, np.interp(r, r_mid, R_mm), 0.0)[:, None]
        return edge_response(x, fn, "profile")[:, 0]

    return _reference(medium, edge, photons)


def model_reference(model: str, medium) -> ProfileReference | None:
    """The edge responses of the material's exact model profile (what the techniques approximate)."""
    fn = model_edge(model, medium)
    if fn is None:
        return None
    return _reference(medium, lambda c, x: fn(x)[:, c])


def edge_error(ref: ProfileReference, edge_fn) -> float:
    """Mean over scattering channels of int |E - E_mc| dx / int |H - E_mc| dx, where
    edge_fn(x_mm) -> (N, 3) is the technique's edge response."""
    errs = []
    for c in range(3):
        if ref.x[c] is None or not ref.denom[c] > 0:
            continue
        e = np.asarray(edge_fn(ref.x[c]), np.float64)[:, c]
        errs.append(float(np.trapezoid(np.abs(e - ref.e_mc[c]), ref.x[c])) / ref.denom[c])
    return float(np.mean(errs)) if errs else math.nan


def edge_response(technique: str, model: str, medium, plan):
    """The edge response x_mm -> (N, 3) of a registered technique as the frame `plan` rendered a
    material of `model` (none: no scattering, a step), or None where the technique has none."""
    from skinlab.render.registry import get_technique

    if model == "none":
        return step_edge
    return get_technique(technique).edge_response(model, medium, plan)


def fit_kernel(model: str, medium, K: int):
    """The K-Gaussian fit as a kernel with every Gaussian kept (no texel folding)."""
    from skinlab.scene.optics.profile_fit import profile_fit
    from skinlab.scene.optics.tsd import design_kernel

    return design_kernel(profile_fit(model, medium, K), 1e-12, 1e-12)
