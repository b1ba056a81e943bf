"""How thick a part a material's light can still shine through: the thickness beyond which the light
that texture-space translucency lets through a slab (shaders/passes/tsd_irradiance.frag: the entry
factor at the far side's incidence x the diffusion slab transmittance, plus single scattering
through the slab) stays below a fraction of what the same light brings to a surface facing it.

Per unit irradiance e along the light, the translucency adds e back [E(back) T(d) + t_in S(mu_t, d)]
with T = slab_transmittance, S = slab_single_transmittance x (u_sss_single / alpha) (the shader's
sss_slab_single per unit base colour), t_in <= 1 the Fresnel transmission in; a surface facing the
light receives e E(1). Single scattering through a slab tau = d / l mean free paths thick is the
light that reaches depth t at cosine mu_i and leaves through the far face, alpha/2 int_0^tau
e^{-t/mu_i}/mu_i E_2(tau - t) dt <= alpha/2 e^{-tau} min(tau/mu_i, 1/(1 - mu_i)) <= alpha/2 (1 + tau)
e^{-tau} for every mu_i (E_2(x) <= e^{-x}; a test checks it against slab_single_transmittance).
Bounded over every cosine (back <= 1, E(back) <= max E, the worst mu_i), the ratio is

    r(d) <= [max_mu E(mu) T(d) + (u_sss_single / 2) (1 + tau) e^{-tau}] / E(1)     per channel.

T and S rise from 0 at d = 0 and fall (exponentially in an absorbing medium) beyond a mean free
path or so; the reach is the smallest d past which r(d) < eps for good (inf when the fall is too
slow, e.g. no absorption). The planner skips a mesh's translucency when no part of it is thinner
(scene/mesh_thickness.py).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from scene.optics.boundary import boundary_tables, slab_transmittance

REACH_EPS = 1e-4  # of the light a surface facing it receives: below this, translucency is left out
_GRID = np.geomspace(1e-3, 1e5, 481)  # thicknesses in mean free paths (ratio 1.04 between points)


def transmission_bound(d_mm, alpha, mfp_mm, eta, colour) -> np.ndarray:
    """r(d) of the module docstring for thicknesses d_mm (N,): (N, 3)."""
    t = boundary_tables(alpha, colour, eta)
    front = t.entry[-1]  # E at normal incidence
    d = np.atleast_1d(np.asarray(d_mm, np.float64))
    al = np.clip(np.asarray(alpha, np.float64).reshape(3), 0.0, 1.0)
    per_alpha = np.where(al > 0, t.single / np.where(al > 0, al, 1.0), 0.0)
    diffusion = t.entry.max(0) * slab_transmittance(d, alpha, mfp_mm, eta)
    tau = d[:, None] / np.maximum(np.asarray(mfp_mm, np.float64).reshape(3), 1e-30)
    single = np.where(al > 0, 0.5 * al, 0.0) * (1.0 + tau) * np.exp(-tau)  # >= slab_single_transmittance
    with np.errstate(divide="ignore", invalid="ignore"):
        r = (diffusion + single * per_alpha) / front
    return np.where(front > 0, r, 0.0)


def translucency_reach_mm(alpha, mfp_mm, eta, colour, eps: float = REACH_EPS) -> float:
    """The smallest thickness (mm) past which r(d) < eps at every larger d (grid of _GRID mean free
    paths); 0 when the material lets through less than eps at every thickness, inf when r has not
    fallen below eps by the end of the grid."""
    return _reach(
        tuple(np.round(np.asarray(alpha, np.float64).reshape(3), 9)),
        tuple(np.round(np.asarray(mfp_mm, np.float64).reshape(3), 9)),
        round(float(eta), 6),
        tuple(np.round(np.asarray(colour, np.float64).reshape(3), 9)),
        float(eps),
    )


@lru_cache(maxsize=256)
def _reach(alpha, mfp, eta, colour, eps) -> float:
    scale = max(max(mfp), 1e-9)
    d = _GRID * scale
    r = transmission_bound(d, np.array(alpha), np.array(mfp), eta, np.array(colour)).max(1)
    above = np.flatnonzero(~(r < eps))  # NaN counts as above
    if len(above) == 0:
        return 0.0
    if above[-1] == len(d) - 1:
        return float("inf")
    return float(d[above[-1] + 1])
