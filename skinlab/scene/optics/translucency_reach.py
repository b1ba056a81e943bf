"""How thick a part a material's light can still shine through: the thickness beyond which the light
that translucency lets through a slab (lib/sss_translucency.glsl: e back T(back, d), T the exact slab
transmittance of skinlab/scene/optics/slab.py, `slab_through`, GLSL sss_slab_through) stays below a fraction
of what the same light brings to a surface facing it, e E(1) (E the entry factor).

T is the table's value interpolated linearly in the (refracted) cosine between its nodes, times
Fresnel transmissions <= 1, so over every incidence back <= 1

    r(d) = back T(back, d) / E(1) <= max_i T_i(d) / E(1)     per channel,

T_i the index-matched table at its cosine nodes (the same tau interpolation and extrapolation as the
shader). T rises from 0 at d = 0 and falls (exponentially in an absorbing medium) beyond a mean free
path or so; the reach is the smallest d past which r(d) < eps for good (inf when the fall is too
slow, e.g. no absorption). The planner skips a mesh's translucency when no part of it is thinner
(skinlab/scene/mesh_thickness.py).
"""

from __future__ import annotations

import numpy as np

from skinlab.cache import table
from skinlab.scene.optics.boundary import boundary_tables
from skinlab.scene.optics.slab import SLAB_MU_NODES, slab_table, slab_through

REACH_EPS = 1e-4  # of the light a surface facing it receives: below this, translucency is left out
_GRID = np.geomspace(1e-3, 1e5, 481)  # thicknesses in mean free paths (ratio 1.04 between points)


def transmission_bound(d_mm, alpha, mfp_mm, eta, colour) -> np.ndarray:
    """r(d) of the module docstring for thicknesses d_mm (N,): (N, 3)."""
    front = boundary_tables(alpha, colour, eta).entry[-1]  # E at normal incidence
    table = slab_table(alpha, colour)
    d = np.atleast_1d(np.asarray(d_mm, np.float64))
    nodes = np.linspace(0.0, 1.0, SLAB_MU_NODES)
    t = slab_through(nodes[None, :], d[:, None], table, mfp_mm, alpha, 1.0).max(axis=1)  # (N, nodes, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = t / front
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


@table(disk=True, maxsize=256)
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
