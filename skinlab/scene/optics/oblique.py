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


NEWTON_STEPS = 4  # GLSL sss_near_entry's loop
NEAR_MIN_COS = 1e-4  # GLSL SSS_NEAR_MIN_COS: below it the light touches the surface (the map folds): 1
NEAR_MAX_GAIN = 4.0  # GLSL SSS_NEAR_MAX_GAIN: reached only with the light nearer than about k / 3


def near_entry(d_mm, ng, z0_mm, eta) -> tuple[np.ndarray, np.ndarray]:
    """Oblique entry under a light at a finite distance (a point or spot light): the diffusion leaving
    at x is fed by the irradiance where it entered, s, nearer the light's foot. On the tangent plane
    (the light at height h, x at rho_x from its foot) light entering at rho_s diffuses about
    rho_x = rho_s + k sin(theta_s) = rho_s (1 + k / d_s), k = z0 / eta (Wang & Jacques' shift, above);
    the map's Jacobian J = (1 + k h^2 / d_s^3)(1 + k / d_s) (radial, circumferential), so the
    diffusion's irradiance at x is E(s) mu_s / J, and over the plane it holds the same flux.

    d_mm (N, 3): from the surface point to the light, mm; ng (N, 3) unit geometric normals; z0_mm
    (N, 3) or (3,); eta (N,) or scalar (clamped at 1). Returns g (N, 3) = E(s) mu_s / (J E(x) mu_x)
    = (d_x / d_s)^3 / J, at most NEAR_MAX_GAIN, and mu_s (N, 3), the cosine of incidence at s. Light
    below or in the tangent plane (cosine under NEAR_MIN_COS), at the point itself, or z0 = 0: g = 1.
    GLSL twin: skinlab/shaders/lib/sss_oblique.glsl sss_near_entry."""
    d_mm, ng = np.atleast_2d(np.asarray(d_mm, np.float64)), np.atleast_2d(np.asarray(ng, np.float64))
    h = np.sum(d_mm * ng, -1)
    dx = np.linalg.norm(d_mm, axis=-1)
    ok = (h > NEAR_MIN_COS * dx) & (dx > 1e-6)
    mu0 = np.where(dx > 0, np.clip(h / np.where(dx > 0, dx, 1.0), 0.0, 1.0), 1.0)
    hh = np.where(ok, h, 1.0)[:, None]
    dxx = np.where(ok, dx, 1.0)[:, None]
    rx = np.linalg.norm(d_mm - ng * h[:, None], axis=-1)[:, None]
    k = (
        np.maximum(np.broadcast_to(np.asarray(z0_mm, np.float64), d_mm.shape), 0.0)
        / np.maximum(np.asarray(eta, np.float64), 1.0)[..., None]
    )
    r = rx / (1.0 + k / dxx)
    for _ in range(NEWTON_STEPS):
        d = np.sqrt(r * r + hh * hh)
        r = np.maximum(r - (r + k * r / d - rx) / (1.0 + k * hh * hh / d**3), 0.0)
    ds = np.sqrt(r * r + hh * hh)
    g = np.minimum((dxx / ds) ** 3 / ((1.0 + k * hh * hh / ds**3) * (1.0 + k / ds)), NEAR_MAX_GAIN)
    g = np.where(ok[:, None], g, 1.0)
    mu_s = np.where(ok[:, None], hh / ds, mu0[:, None])
    return g, mu_s


def near_entry_gain(d_mm, ng, z0_mm, eta, entry_table) -> np.ndarray:
    """(N, 3) what the diffusion's entering light of a point or spot light is multiplied by at x:
    near_entry's g times the entry factor at s's incidence over the one at x's (entry_table the
    boundary's (ANGULAR_NODES, 3) entry table, skinlab/scene/optics/boundary.py), at most
    NEAR_MAX_GAIN (a dielectric's entry falls to 0 at grazing: the ratio is large only where almost
    no light enters); 1 where near_entry's g is. GLSL twin:
    skinlab/shaders/lib/sss_near_light.glsl sss_near_entry_gain."""
    from .boundary import table_lookup

    d_mm, ng = np.atleast_2d(np.asarray(d_mm, np.float64)), np.atleast_2d(np.asarray(ng, np.float64))
    g, mu_s = near_entry(d_mm, ng, z0_mm, eta)
    dx = np.linalg.norm(d_mm, axis=-1)
    mu_x = np.clip(np.sum(d_mm * ng, -1) / np.maximum(dx, 1e-30), 0.0, 1.0)
    table = np.asarray(entry_table, np.float64)
    at_s = np.stack([table_lookup(table, mu_s[:, c])[:, c] for c in range(3)], -1)
    at_x = table_lookup(table, mu_x)
    gain = np.minimum(g * at_s / np.maximum(at_x, 1e-6), NEAR_MAX_GAIN)
    return np.where((mu_x > NEAR_MIN_COS)[:, None], gain, 1.0)
