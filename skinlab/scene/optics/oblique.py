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

The offset is a mean: the first scattering lies an exponentially distributed path s (mean 1 / mu_t')
along the refracted beam, so the point where that light entered lies s sin(theta_t) upstream. Not every
source counts alike: one at depth z = s mu_t (mu_t the refracted cosine) returns to the surface in
proportion to e^{-mu_tr z} (the diffusion's decay, mu_tr / mu_t' = sqrt(3 (1 - a')), the dipole's total
reflectance of a buried source), so the light the surface re-emits entered upstream by an exponential
distance of mean

    m = sin(theta_t) / (mu_t' + mu_tr mu_t) = offset / (1 + sqrt(3 (1 - a')) mu_t)    per channel.

A shadow edge the light crosses is therefore not moved but spread (issue 21: at a grazing key light on
the nose, one shift for every channel left the lit side of the edge 25-30 % too bright and the shadow
side too dark). The frame looks the shadow up at three points along the luminance offset, at
ENTRY_RAMP_N1..N3 times the luminance mean of m (the conditional means of an exponential's terciles),
each weighted per channel by the probability that the channel's exponential falls in its tercile's span
(entry_ramp_weights). Single scattering, which leaves from a depth of 1 / (mu_t (1 / mu_l + 1 / mu_v))
along the beam, entered upstream by a mean of the offset / (1 + mu_l / mu_v) (refracted cosines), read
from the surface point's own shadow and the one at the whole offset (entry_pair_weights: one lookup).
"""

from __future__ import annotations

import numpy as np

from .constants import (
    ENTRY_RAMP_B1,
    ENTRY_RAMP_B2,
    ENTRY_RAMP_N1,
    ENTRY_RAMP_N2,
    ENTRY_RAMP_N3,
    LUMA_B,
    LUMA_G,
    LUMA_R,
)

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


def entry_ramp_means(z0_mm, k=1.0) -> np.ndarray:
    """(..., 3) each channel's mean upstream distance of the entry in units of the luminance offset b
    (the length of entry_offset): z0_c / z0_luma over k, k per channel or one (the diffusion:
    entry_diffusion_k; single scattering: single_entry_k, at least 1); 1 / k where z0_luma is 0. GLSL
    twin sss_ramp_means."""
    z0 = np.maximum(np.asarray(z0_mm, np.float64), 0.0)
    zl = z0 @ LUMA
    k = np.asarray(k, np.float64)
    if k.ndim < z0.ndim:
        k = k[..., None]
    m = np.where((zl > 0)[..., None], z0 / np.where(zl > 0, zl, 1.0)[..., None], 1.0)
    return m / np.maximum(k, 1.0)


def entry_diffusion_k(alpha, mu_l, eta) -> np.ndarray:
    """(..., 3) 1 + sqrt(3 (1 - a')) mu_t per channel (a' the reduced albedo, mu_t the refracted cosine
    of the light, eta clamped at 1): the diffusion's entry lies upstream by the offset over this. GLSL:
    the shaders pass sqrt(3 (1 - a')) as u_sss_slab_decay (skinlab/scene/optics/slab.py slab_decay)."""
    a = np.clip(np.asarray(alpha, np.float64), 0.0, 1.0)
    mu = _inside(mu_l, eta)
    return 1.0 + np.sqrt(3.0 * (1.0 - a)) * np.asarray(mu)[..., None]


def entry_ramp_nodes(m) -> np.ndarray:
    """(..., 3) the three lookups' fractions of the luminance offset: ENTRY_RAMP_N1..N3 x the luminance
    mean of m (entry_ramp_means). GLSL twin sss_ramp_nodes."""
    mbar = np.maximum(np.asarray(m, np.float64), 1e-9) @ LUMA
    return np.asarray(mbar)[..., None] * np.array([ENTRY_RAMP_N1, ENTRY_RAMP_N2, ENTRY_RAMP_N3])


def entry_ramp_points(world, ng, l, z0_mm, alpha, eta, mm_per_unit) -> tuple[np.ndarray, np.ndarray]:
    """The diffusion's spread entry at each point (N, 3): the per-channel means m (N, 3; entry_ramp_means
    with entry_diffusion_k at the light's cosine) and the three shadow lookup points (N, 3 lookups, 3):
    the luminance offset (entry_offset) at the fractions entry_ramp_nodes(m), each moved toward the light
    by its length (as entry_point). GLSL twin sss_ramp_setup."""
    world, ng, l = (np.atleast_2d(np.asarray(x, np.float64)) for x in (world, ng, l))
    off = entry_offset(ng, l, z0_mm, eta, mm_per_unit)
    mu_l = np.sum(ng * l, -1)
    m = entry_ramp_means(np.broadcast_to(np.asarray(z0_mm, np.float64), ng.shape), entry_diffusion_k(alpha, mu_l, eta))
    f = entry_ramp_nodes(m)[..., None]  # (N, 3 lookups, 1)
    size = np.linalg.norm(off, axis=-1)[:, None, None]
    return m, world[:, None, :] + off[:, None, :] * f + l[:, None, :] * (size * f)


def entry_ramp_weights(m) -> np.ndarray:
    """(..., 3 channels, 3 nodes) the weights of the shadow lookups at ENTRY_RAMP_N1..N3 x the
    luminance mean of m (in units of b) for channels whose entry lies upstream by an exponential
    distance of mean m b (entry_ramp_means): the probabilities of [0, B1 mbar b), [B1 mbar b, B2 mbar b)
    and beyond, mbar = m . LUMA. Sum 1; a third each for a channel at mbar; all on the first as m -> 0.
    GLSL twin sss_ramp_mix."""
    m = np.maximum(np.asarray(m, np.float64), 1e-9)
    mbar = (m @ LUMA)[..., None]
    c1, c2 = np.exp(-ENTRY_RAMP_B1 * mbar / m), np.exp(-ENTRY_RAMP_B2 * mbar / m)
    return np.stack([1.0 - c1, c1 - c2, c2], -1)


def entry_pair_weights(m) -> np.ndarray:
    """(..., 3 channels, 2) the weights of the surface point's own shadow and the one at b for
    channels whose entry lies upstream by an exponential distance of mean m b: the probabilities of
    [0, b / 2) and beyond (each point takes the half nearer it). GLSL: sss_single_pair (from single_pair_rate)."""
    m = np.maximum(np.asarray(m, np.float64), 1e-9)
    w0 = 1.0 - np.exp(-0.5 / m)
    return np.stack([w0, 1.0 - w0], -1)


def _inside(c, eta):
    """The refracted cosine of a direction at cosine c outside (eta clamped at 1)."""
    eta = np.maximum(np.asarray(eta, np.float64), 1.0)
    c = np.clip(np.abs(np.asarray(c, np.float64)), 0.0, 1.0)
    return np.sqrt(np.maximum(1.0 - (1.0 - c * c) / (eta * eta), 0.0))


def single_pair_rate(z0_mm) -> np.ndarray:
    """(3,) per channel 0.5 log2(e) z0_luma / z0_c (at most 1e4): single scattering's pair weight is
    w0 = 1 - 2^(-k rate) = entry_pair_weights(entry_ramp_means(z0, k))[..., 0], one exp2 per fragment;
    the ratio does not change with the radius map (it scales z0_c and z0_luma alike), so the frame binds
    it per material (u_sss_single_ramp, skinlab/render/boundary.py). GLSL sss_single_pair."""
    z0 = np.maximum(np.asarray(z0_mm, np.float64).reshape(3), 0.0)
    zl = float(z0 @ LUMA)
    with np.errstate(divide="ignore"):
        r = np.where(z0 > 0, 0.5 * np.log2(np.e) * zl / np.where(z0 > 0, z0, 1.0), 1e4)
    return np.minimum(r, 1e4)


def single_entry_k(mu_l, mu_v, eta) -> np.ndarray:
    """1 + mu_l / mu_v at the refracted cosines (eta clamped at 1; mu_v at least SINGLE_K_MIN_COS):
    single scattering's entry lies upstream by the offset over this. GLSL sss_single_k."""
    return 1.0 + _inside(mu_l, eta) / np.maximum(_inside(mu_v, eta), SINGLE_K_MIN_COS)


SINGLE_K_MIN_COS = 0.05  # GLSL SSS_SINGLE_K_MIN_COS: a viewer at grazing does not make k unbounded
