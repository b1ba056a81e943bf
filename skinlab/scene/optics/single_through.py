"""Single scattering along the light's own path through the medium: NumPy twin of
skinlab/shaders/lib/sss_single_through.glsl (issue 21; docs/ground-truth.md "Single scattering along the
light's path").

Jensen et al. 2001's single-scattering term (section 2.3; docs/references.md#jensen-2001) is the integral
along the refracted view ray of the light scattered once toward the viewer,

    L = E_in alpha p(cos) t_out / eta^2  int_0^inf sigma_t e^{-sigma_t (s + d(s))} ds,

E_in = E c ft / ct the directional light inside per unit area of its refracted beam (E its irradiance on a
face toward it, c the entry cosine, ct the refracted one, ft the Fresnel transmission in), s the path
along the view ray and d(s) the path the light travelled inside to the point there. The flat medium's
d = s ct_o / ct gives the closed form the frame uses everywhere (skinlab/scene/optics/single_scattering.py
single_scatter_brdf: alpha ft t_out p / (eta^2 (ct + ct_o)) per unit irradiance c E). On a curved part the
path is not that: below a convex part lit near its terminator the light runs a chord just under the
surface, so points under the lit side near the terminator are reached through less matter than a plane's
(the flat term reads a skin ball's blue there 3 times too dark, docs/ground-truth.md), and points past the
terminator, where the flat term is 0, are reached through the chord in front of them.

Here d(s) is the distance map's (skinlab/scene/optics/translucency.py: the point's distance from the light
less the first surface's) times c / ct (the air path along the light turned into the refracted one, exact
on a plane), read at SINGLE_THROUGH_DEPTHS x the luminance mean free path along the ray (the point itself
first) and taken as piecewise linear, beyond the last depth with its last slope (at least 0). The integral
of each segment is exact (an exponential), so a plane's linear d gives the flat term to rounding. Two uses:

* the lit side (ng.l > 0): the gain, the flat term's factor I(d) / I(flat) per channel,
  at least 1 (a cast shadow stays the shadow lookup's, a concave part the flat term's);
* past a convex part's terminator (ng.l <= 0, the entry face in front within 60 degrees of the point's
  own, SINGLE_THROUGH_MIN_FACE_COS: a smoothly curved bulge, translucency.py through_cosine): the term
  itself for the light entering at that face. A sheet's far side, and a sharp edge's, are left to the
  light through thin parts, whose slab transmittance counts every order of scattering, the first
  included.

Both at once (:func:`single_through`, the samples shared), only for a directional light (eye w = 0) whose
light reached the point through its own part only (not past another part's exit: the part layers);
elsewhere the flat term.
"""

from __future__ import annotations

import numpy as np

from .constants import (
    LUMA_B,
    LUMA_G,
    LUMA_R,
    SINGLE_THROUGH_DEPTHS,
    SINGLE_THROUGH_MAX_SIGMA,
    SINGLE_THROUGH_MIN_FACE_COS,
    SINGLE_THROUGH_ROUNDING,
)
from .fresnel import fresnel_from_cosines, hg_phase
from .single_scattering import refract_cos
from .translucency import NO_SURFACE, _distance_quad, distance_from_light, entry_face, part_layers

LUMA = np.array([LUMA_R, LUMA_G, LUMA_B])
MIN_CT = 1e-4  # refracted cosines are clamped here (GLSL alike)


def through_integral(sigma_t, s, d) -> np.ndarray:
    """(N, 3): int_0^inf sigma e^{-sigma (x + d(x))} dx per channel, d piecewise linear through the points
    (s[:, j], d[:, j]) (N, J) with s increasing from 0, beyond the last with its last slope (at least 0).
    On a segment of rate k = 1 + its slope it is (e_j - e_j+1) / k, e_j = e^{-sigma (s_j + d_j)} (both at
    most 1: finite however steep the segment), its series where sigma k ds < 1e-2; beyond, e_J / (1 + m).
    Exact for a linear d: 1 / (1 + slope). sigma_t (3,) or (N, 3), per mm like s and d; d >= 0."""
    s, d = np.atleast_2d(np.asarray(s, np.float64)), np.atleast_2d(np.asarray(d, np.float64))
    sig = np.atleast_2d(np.asarray(sigma_t, np.float64))
    e = [np.exp(-sig * (s[:, j] + d[:, j])[:, None]) for j in range(s.shape[1])]
    tot = np.zeros(np.broadcast_shapes(sig.shape, (len(s), 3)))
    for j in range(s.shape[1] - 1):
        ds = (s[:, j + 1] - s[:, j])[:, None]
        k = 1.0 + (d[:, j + 1] - d[:, j])[:, None] / ds
        x = sig * (k * ds)
        series = sig * ds * e[j] * (1.0 - 0.5 * x)
        with np.errstate(divide="ignore", invalid="ignore"):
            tot = tot + np.where(np.abs(x) < 1e-2, series, (e[j] - e[j + 1]) / np.where(k != 0, k, 1.0))
    m = np.maximum((d[:, -1] - d[:, -2]) / (s[:, -1] - s[:, -2]), 0.0)[:, None]
    return tot + e[-1] / (1.0 + m)


def mean_free_path(sigma_t) -> np.ndarray:
    """The luminance mean of 1 / sigma_t (mm): the unit of the depths."""
    return (1.0 / np.maximum(np.atleast_2d(np.asarray(sigma_t, np.float64)), 1e-6)) @ LUMA


def view(n, v, eta):
    """The view's half of single scattering (GLSL single_scatter_view): (co, cto, to, t_out) for unit
    normals n and directions to the viewer v (N, 3), eta >= 1."""
    n, v = np.atleast_2d(np.asarray(n, np.float64)), np.atleast_2d(np.asarray(v, np.float64))
    co = np.sum(n * v, -1)
    cto = refract_cos(co, eta)
    to = -v / eta + (co / eta - cto)[:, None] * n
    t_out = 1.0 - fresnel_from_cosines(co, cto, 1.0, eta)
    return co, cto, to, t_out


def bilinear_first(distance_map, shadow_matrix, world) -> tuple[np.ndarray, np.ndarray]:
    """(first, hit): the distance map's bilinear first surface where all four texels around each point hold
    one (translucency.first_hit_distance without its fallback to the containing texel: at a silhouette in
    the light's view, no hit). GLSL: the turns of sss_single_through."""
    dist = np.asarray(distance_map, np.float64)
    inside, _, (fx, fy), _, (d00, d10, d01, d11) = _distance_quad(dist, shadow_matrix, np.atleast_2d(world))
    hit = inside & (np.maximum(np.maximum(d00, d10), np.maximum(d01, d11)) < NO_SURFACE)
    with np.errstate(invalid="ignore", over="ignore"):
        first = (d00 * (1 - fx) + d10 * fx) * (1 - fy) + (d01 * (1 - fx) + d11 * fx) * fy
    return np.where(hit, first, 0.0), hit


def path_mm(distance_map, shadow_matrix, eye, world, to, cto, ct, ratio, mfp, d0, mm_per_unit):
    """(s, d), each (N, 4): the depths along the refracted view ray `to` from each point and the path
    inside to them (mm), d[:, 0] = d0; where the map has no surface in front, the flat medium's path."""
    world = np.atleast_2d(np.asarray(world, np.float64))
    s = np.asarray(SINGLE_THROUGH_DEPTHS, np.float64)[None, :] * np.asarray(mfp, np.float64).reshape(-1, 1)
    s = np.broadcast_to(s, (len(world), len(SINGLE_THROUGH_DEPTHS))).copy()
    d = np.zeros_like(s)
    d[:, 0] = d0
    for j in range(1, s.shape[1]):
        x = world + to * (s[:, j] / mm_per_unit)[:, None]
        first, hit = bilinear_first(distance_map, shadow_matrix, x)
        air = np.maximum(distance_from_light(eye, x) - first, 0.0) * mm_per_unit
        d[:, j] = np.where(hit, air * ratio, s[:, j] * cto / ct)
    return s, d


def own_part(distance_map, exit_map, shadow_matrix, eye, world, ng, shrink, part_gap) -> np.ndarray:
    """(N,) bool: the light reached each point through its own part only (not past another part's exit by
    more than the part gap; exit_map None: one part everywhere). GLSL sss_single_own_part."""
    p = np.atleast_2d(np.asarray(world, np.float64)) - float(shrink) * np.atleast_2d(np.asarray(ng, np.float64))
    if exit_map is None:
        return np.ones(len(p), bool)
    layers = part_layers(exit_map, shadow_matrix, p)
    return ~((layers[:, 0] < 1e29) & (distance_from_light(eye, p) > layers[:, 0] + part_gap))


def single_through(
    distance_map,
    exit_map,
    shadow_matrix,
    eye,
    world,
    ng,
    l,
    v,
    sigma_t,
    alpha,
    eta,
    g,
    shrink,
    mm_per_unit,
    part_gap=0.0,
    n=None,
) -> tuple[np.ndarray, np.ndarray]:
    """(gain, f), each (N, 3), for one light (GLSL sss_single_through): gain, on the lit side (ng.l > 0),
    the flat single-scattering term's factor I(d from the map) / I(flat), at least 1; f, past a convex
    part's terminator (ng.l <= 0, the entry face the map shows in front, translucency.entry_face at the
    point moved `shrink` inward, on the point's own side), the term itself per unit light irradiance for
    the light that entered there (its cosine and normal). gain 1 and f 0 where they do not apply: not a
    directional light (eye w != 0), the view below the surface, another part in front (the part layers
    exit_map; None: one part everywhere), a sheet's far side, or the map without a surface or its slope
    at the point. l: unit direction to the light (3,); v: to the viewer (N, 3); sigma_t: the real
    extinction per mm (3,); alpha: the single-scattering albedo over the colour (u_sss_single, (3,)); g: the
    phase's; n: the shading normals the view is refracted at (the frame's single_view; default ng)."""
    world = np.atleast_2d(np.asarray(world, np.float64))
    ng = np.atleast_2d(np.asarray(ng, np.float64))
    l = np.asarray(l, np.float64).reshape(3)
    eta = max(float(eta), 1.0)
    sigma_t = np.minimum(np.asarray(sigma_t, np.float64), SINGLE_THROUGH_MAX_SIGMA)  # finite (a radius of 0)
    count = len(world)
    gain, f = np.ones((count, 3)), np.zeros((count, 3))
    if np.asarray(eye, np.float64).reshape(4)[3] != 0.0:
        return gain, f
    co, cto, to, t_out = view(ng if n is None else n, v, eta)
    p = world - float(shrink) * ng
    cg = ng @ l
    ok = co > 0
    ok &= own_part(distance_map, exit_map, shadow_matrix, eye, world, ng, shrink, part_gap)
    ef = entry_face(distance_map, shadow_matrix, eye, p)
    first, hit = bilinear_first(distance_map, shadow_matrix, p)
    lit = cg > 0
    ok &= lit | ((ef[:, 3] > 0) & (np.sum(ng * ef[:, :3], -1) >= SINGLE_THROUGH_MIN_FACE_COS) & hit)
    c = np.where(ok, np.where(lit, cg, ef[:, 3]), 1.0)  # (the others are not used)
    ct = np.maximum(refract_cos(c, eta), MIN_CT)
    ratio = c / ct
    d0 = np.where(lit, 0.0, np.maximum(distance_from_light(eye, p) - first, 0.0) * mm_per_unit * ratio)
    s, d = path_mm(
        distance_map, shadow_matrix, eye, world, to, cto, ct, ratio, mean_free_path(sigma_t), d0, mm_per_unit
    )
    integral = through_integral(sigma_t, s, d)
    lit_gain = integral * ((ct + cto) / ct)[:, None]
    lit_gain = np.where(lit_gain < 1.0 + SINGLE_THROUGH_ROUNDING, 1.0, lit_gain)  # a plane's 1, to rounding
    gain = np.where((ok & lit)[:, None], lit_gain, gain)
    ft = 1.0 - fresnel_from_cosines(c, ct, 1.0, eta)
    ti = -l / eta + (c / eta - ct)[:, None] * ef[:, :3]
    cos_s = np.clip(-np.sum(ti * to, -1), -1.0, 1.0)
    amp = ft * t_out * hg_phase(cos_s, g) / (eta * eta) * ratio
    shadow = np.asarray(alpha, np.float64)[None, :] * amp[:, None] * integral
    f = np.where((ok & ~lit)[:, None], shadow, f)
    return gain, f
