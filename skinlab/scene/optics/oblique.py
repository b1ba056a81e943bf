"""Where light that leaves a scattering medium by diffusion entered it, for light arriving at an angle.

Light entering a turbid medium obliquely is first scattered along its refracted direction, so the
diffusion it feeds is centred not below the point of entry but displaced along the surface, in the
direction the light travels, by

    delta = sin(theta_t) / mu_t'     (docs/references.md#wang-jacques-1995; mu_t' = mu_a + mu_s')

with sin(theta_t) = sin(theta_i) / eta (Snell; clamped at 1), i.e. the dipole's source depth
z0 = 1 / mu_t' (Jensen 2001) times sin(theta_t). A surface point x therefore re-emits the diffusion
of the light that entered at x - delta t (t: the light's travel direction along the surface): at a
shadow edge the light diffuses less far into the shadow when it travels away from it, further when
toward it. Skinlab applies this where light enters the diffusion: the shadow lookup of the light
feeding the subsurface term is made at x + offset, offset = (l - n (n.l)) z0 / max(eta, sin theta_i)
(l toward the light, so l's tangential part points against the travel direction).

One offset for the three channels: z0 weighted by luminance (one shadow lookup, not three).
GLSL twin: skinlab/shaders/lib/sss_oblique.glsl sss_entry_offset. Measured against the path-traced truth on
the slab's shadow edge in docs/ground-truth.md.
"""

from __future__ import annotations

import numpy as np

from .constants import LUMA_B, LUMA_G, LUMA_R

LUMA = np.array([LUMA_R, LUMA_G, LUMA_B])


def entry_offset(ng, l, z0_mm, eta, mm_per_unit) -> np.ndarray:
    """(N, 3) world offset from a surface point to where the light it re-emits entered, for unit
    geometric normals ng (N, 3), unit directions to the light l (N, 3), per-channel source depths
    z0_mm (N, 3) or (3,), relative index eta (N,) or scalar, mm per scene unit (N,) or scalar > 0."""
    ng, l = np.asarray(ng, np.float64), np.asarray(l, np.float64)
    lt = l - ng * np.sum(ng * l, -1, keepdims=True)
    sin_i = np.linalg.norm(lt, axis=-1)
    z0 = np.asarray(z0_mm, np.float64) @ LUMA
    eta = np.asarray(eta, np.float64)
    scale = z0 / (np.maximum(eta, np.maximum(sin_i, 1e-6)) * np.maximum(np.asarray(mm_per_unit, np.float64), 1e-30))
    return lt * np.asarray(scale)[..., None]


def entry_point(world, ng, l, z0_mm, eta, mm_per_unit) -> np.ndarray:
    """Where the light's shadow is looked up for the diffusion leaving at world (N, 3): the entry
    point world + offset, moved toward the light by the offset's length (a depth bias: on a curved
    surface the offset leaves the surface by up to |offset|^2 / 2R; across a directional light's
    map it does not move)."""
    off = entry_offset(ng, l, z0_mm, eta, mm_per_unit)
    return np.asarray(world, np.float64) + off + np.asarray(l, np.float64) * np.linalg.norm(off, axis=-1, keepdims=True)
