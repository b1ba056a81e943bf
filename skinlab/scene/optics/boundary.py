"""How light enters and leaves a scattering medium: the angular factors every subsurface technique
shares (NumPy reference; GLSL twin skinlab/shaders/lib/sss_boundary.glsl).

A technique spreads the light that enters the surface over the surface with a normalised profile
(it redistributes, it does not create or absorb light). What it needs from the boundary is, per
channel, how much of the light arriving at incidence cosine mu0 eventually leaves after multiple
scattering, and in which directions it leaves. For a semi-infinite medium the multiple-scattering
BRDF is, to a good approximation, separable and reciprocal:

    f_ms(mu, mu0) ~= A_ms(mu0) A_ms(mu) / (pi A_ms_d)

A_ms(mu0) the directional albedo of multiple scattering (the fraction of light arriving at mu0 that
leaves after two or more events), A_ms_d = 2 int A_ms(mu) mu dmu its hemispherical (diffuse) mean.
It integrates to exactly A_ms(mu0) over the exit hemisphere, and is reciprocal. Single scattering
is not separable and is added exactly per light (Jensen 2001's term, skinlab/scene/optics/single_scattering.py).
At eta = 1 what the separable form misses of the exact BRDF below (4-5.5 % dark for normal light and
view, 9-10 % bright for light at cosine 0.2) is added per light too (ms_rest_table): it moves light
between directions and keeps the energy.

Index-matched boundary (eta = 1), isotropic scattering, single-scattering albedo a: Chandrasekhar's
exact solution (Radiative Transfer 1960, ch. V; docs/references.md#chandrasekhar-1960):

    f(mu, mu0)  = a/(4 pi) H(mu) H(mu0) / (mu + mu0)         all orders
    f_ss        = a/(4 pi) / (mu + mu0)                      first order (Jensen's term at eta = 1)
    A(mu0)      = 1 - H(mu0) sqrt(1 - a)
    A_ss(mu0)   = (a/2) (1 - mu0 ln(1 + 1/mu0))

so A_ms = A - A_ss exactly. The old exit (a Lambertian profile times Burley 2015's exit weight, the
surface albedo A_colour from photon beam diffusion as the amount) was 14 % too bright at normal
incidence for skin1's red channel (PBD's total 0.463 against Chandrasekhar's 0.405 for the same a)
and darkened grazing exits, where the exact BRDF is brightest.

Dielectric boundary (eta > 1): no closed form. Approximation used here (Saunderson's correction
for internal reflection on top of the exact index-matched medium), continuous at eta = 1: light
enters with T(mu0) (1 - F(mu0) for a smooth boundary, the rough dielectric's transmittance for a
rough one) at the refracted cosine mu_t; the exact medium returns X = A_ms(mu_t; 1) after multiple
and Y = A_ss(mu_t; 1) after single scattering; of what reaches the interface from inside a fraction
R_i is reflected back, T_i leaves, meets the medium as diffuse light (all-order albedo A_d1 at
eta 1), and so on:

    A_ms(mu0; eta) = T(mu0) [X T_i + (X + Y) R_i A_d1 T_i / (1 - R_i A_d1)]

(light once reflected inside counts as multiply scattered; the first single-scattering exit is
Jensen's term). R_i and T_i are the boundary's reflectance and transmittance averaged over the
angular shape of the light arriving from inside, the emergent intensity H(mu) (internal_reflect_
transmit); a smooth boundary has T_i = 1 - R_i, a rough one (the truth's: Mitsuba's
roughdielectric, GGX alpha = roughness^2, skinlab/scene/optics/rough_dielectric.py) loses what its facets
mask, R_i + T_i = 0.90 for skin1 at index 1.3 and roughness 0.45. Against the flat-medium Monte
Carlo (smooth boundary, eta 1.3, a = 0.5-0.96): within 1 % at normal incidence and for diffuse
light (tests/scene/optics/test_boundary.py checks 2 %); the old diffuse average (R_i = Jensen's
F_dr, T_i = 1 - F_dr) read 2-4 % dark there. Against the path tracer's flat skin1 slab at index
1.3 under its rough boundary: within 1.5 % (tests/truth/test_truth_render.py), where a smooth
boundary's internal reflection reads red 10 % bright (docs/ground-truth.md).

The tables handed to the shader are the factors relative to the material's surface colour (the
frame multiplies by the possibly textured base colour): entry(mu0) = A_ms(mu0)/A_colour and
exit(mu) = A_ms(mu)/A_ms_d, sampled at ANGULAR_NODES cosines mu_i = i/(N-1), linear in between.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skinlab.cache import table

from .fresnel import clamp_eta, fresnel_dielectric
from .quadrature import gauss_legendre
from .rough_dielectric import SMOOTH_ALPHA, rough_albedos

ANGULAR_NODES = 17  # table cosines i/16; GLSL SSS_ANGULAR_NODES
_GL_N = 96  # Gauss-Legendre nodes of the hemispherical integrals
_H_N = 800  # nodes of the H-function integral


@table(maxsize=8)
def _gl(n: int = _GL_N):
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


@table(disk=True, maxsize=1)
def _h_quadrature(n: int = _H_N):
    """Nodes theta in (0, pi/2) and weights for Chandrasekhar's integral form of H; theta = (pi/2) t^2
    takes the logarithmic singularity at theta = 0 (conservative scattering) out of the integrand."""
    x, w = gauss_legendre(n)  # not leggauss: an 800 x 800 eigenproblem
    t = 0.5 * (x + 1.0)
    th = 0.5 * np.pi * t * t
    cot_term = np.where(th > 1e-6, th / np.tan(np.maximum(th, 1e-6)), 1.0 - th * th / 3.0)  # theta cot theta
    return th, np.pi * t * 0.5 * w, cot_term


def chandrasekhar_h(a: float, mu) -> np.ndarray:
    """H(mu) for isotropic scattering with single-scattering albedo a in [0, 1]; H(0) = 1. Chandrasekhar's
    closed form, ln H(mu) = -(mu/pi) int_0^{pi/2} ln(1 - a theta cot theta) / (cos^2 theta + mu^2 sin^2 theta)
    dtheta (Radiative Transfer, eq. V.(43)); unlike the iteration it converges at a = 1 too."""
    a = float(np.clip(a, 0.0, 1.0))
    mu = np.clip(np.asarray(mu, np.float64), 0.0, 1.0)
    th, w, tc = _h_quadrature()
    g = np.log(np.maximum(1.0 - a * tc, 1e-300))
    c2, s2 = np.cos(th) ** 2, np.sin(th) ** 2
    integral = np.sum(w * g / (c2 + (mu[..., None] ** 2) * s2), axis=-1)
    return np.exp(-(mu / np.pi) * integral)


def albedo_isotropic(a: float, mu0) -> np.ndarray:
    """Directional albedo of all orders at eta = 1: 1 - H(mu0) sqrt(1 - a)."""
    return 1.0 - chandrasekhar_h(a, mu0) * np.sqrt(max(1.0 - float(a), 0.0))


def single_albedo_isotropic(a: float, mu0) -> np.ndarray:
    """Directional albedo of single scattering at eta = 1: (a/2)(1 - mu0 ln(1 + 1/mu0)) (finite at 0)."""
    mu0 = np.clip(np.asarray(mu0, np.float64), 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(mu0 > 0, mu0 * np.log1p(1.0 / np.where(mu0 > 0, mu0, 1.0)), 0.0)
    return 0.5 * float(a) * (1.0 - t)


def ms_albedo_matched(a: float, mu0) -> np.ndarray:
    """Multiple-scattering directional albedo at eta = 1 (exact): A - A_ss, >= 0."""
    return np.maximum(albedo_isotropic(a, mu0) - single_albedo_isotropic(a, mu0), 0.0)


@table(maxsize=256)
def _diffuse_albedo_matched(a: float) -> float:
    """All-order albedo of the index-matched medium for diffuse light, 2 int A(mu) mu dmu."""
    return hemispherical(lambda m: albedo_isotropic(a, m))


def boundary_transmittance(mu, eta: float, ggx_alpha: float = 0.0) -> np.ndarray:
    """Fraction of the flux arriving from outside at cosine mu that crosses the boundary: 1 - F(mu)
    for a smooth one, the rough dielectric's (skinlab/scene/optics/rough_dielectric.py) from GGX alpha
    SMOOTH_ALPHA on; 1 at eta = 1 (no interface)."""
    mu = np.clip(np.asarray(mu, np.float64), 0.0, 1.0)
    if abs(eta - 1.0) < 1e-9:
        return np.ones_like(mu)
    if ggx_alpha < SMOOTH_ALPHA:
        return 1.0 - fresnel_dielectric(mu, eta)
    nodes, t = _rough_transmittance_table(round(float(ggx_alpha), 9), round(float(eta), 9))
    return np.interp(mu, nodes, t)


@table(disk=True, maxsize=64)
def _rough_transmittance_table(ggx_alpha: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """The rough boundary's transmittance from outside at 257 cosines, linear in between (within
    1e-4 of the direct evaluation from GGX alpha 0.05 on; 7e-3 at grazing incidence for a nearly
    smooth one, where the Fresnel term is steep), so that a material's tables cost one evaluation."""
    nodes = np.linspace(0.0, 1.0, 257)
    return nodes, rough_albedos(nodes, ggx_alpha, eta)[1]


@table(maxsize=512)
def internal_reflect_transmit(a: float, eta: float, ggx_alpha: float = 0.0) -> tuple[float, float]:
    """(R_i, T_i): what the boundary reflects back into the medium and lets out of the light that
    reaches it from inside after scattering. That light arrives with the angular shape of the
    medium's emergent intensity, H(mu) (Chandrasekhar's H for albedo a: more of it near the normal
    than a diffuse flux, and a grazing flux is what total internal reflection sends back), so
    R_i = int R(mu) H(mu) mu dmu / int H(mu) mu dmu, likewise T_i. A smooth boundary has
    R + T = 1; a rough one (GGX alpha >= SMOOTH_ALPHA) loses the light its facets mask
    (skinlab/scene/optics/rough_dielectric.py). Against the truth's flat slab (Mitsuba, skin1 at index 1.3,
    docs/ground-truth.md) this weighting halves to removes the model's error where a diffuse flux
    (Jensen's F_dr) read 2-3 % dark (smooth) or the rough boundary's loss 3 % too large."""
    m, w = _gl()
    r, t = _inside_albedos(float(ggx_alpha), float(eta))
    ww = w * m * chandrasekhar_h(a, m)
    ww = ww / ww.sum()
    return float(np.sum(ww * r)), float(np.sum(ww * t))


@table(disk=True, maxsize=64)
def _inside_albedos(ggx_alpha: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """The boundary's reflectance and transmittance for light from inside, at the quadrature nodes."""
    m, _ = _gl()
    if ggx_alpha < SMOOTH_ALPHA:
        r = fresnel_dielectric(m, 1.0 / eta)
        return r, 1.0 - r
    return rough_albedos(m, ggx_alpha, 1.0 / eta)


def ms_albedo(a: float, eta: float, mu0, ggx_alpha: float = 0.0) -> np.ndarray:
    """Multiple-scattering directional albedo for light arriving at cosine mu0 (see the module);
    ggx_alpha the roughness of the boundary (GGX alpha = roughness^2; 0: smooth)."""
    mu0 = np.clip(np.asarray(mu0, np.float64), 0.0, 1.0)
    eta = float(clamp_eta(eta))
    if abs(eta - 1.0) < 1e-9:
        return ms_albedo_matched(a, mu0)
    ct = np.sqrt(np.maximum((eta - 1.0) * (eta + 1.0) + mu0 * mu0, 0.0)) / eta
    t_in = boundary_transmittance(mu0, eta, ggx_alpha)
    x = ms_albedo_matched(a, ct)
    y = single_albedo_isotropic(a, ct)
    a_key = round(float(a), 12)
    rho, tau = internal_reflect_transmit(a_key, round(eta, 9), round(float(ggx_alpha), 9))
    ad = _diffuse_albedo_matched(a_key)
    return t_in * (x * tau + (x + y) * rho * ad * tau / (1.0 - rho * ad))


def single_ambient_albedo(a: float, eta: float, mu) -> np.ndarray:
    """Single scattering under a uniform sky of radiance 1, toward cosine mu: Jensen's term (isotropic
    phase, 1/eta^2) integrated over the incident hemisphere, which by reciprocity is its directional
    albedo, A_ss(mu) = a (1 - F(mu)) / (2 eta^2) int_0^1 (1 - F(m)) m / (mu_t(m) + mu_t(mu)) dm
    (mu_t the refracted cosines); at eta = 1 Chandrasekhar's (a/2)(1 - mu ln(1 + 1/mu))."""
    mu = np.clip(np.asarray(mu, np.float64), 0.0, 1.0)
    eta = float(clamp_eta(eta))
    m, w = _gl()

    def t_and_ct(c):
        ct = np.sqrt(np.maximum((eta - 1.0) * (eta + 1.0) + c * c, 0.0)) / eta
        if eta == 1.0:  # no interface: nothing reflected, even at grazing incidence
            return np.ones_like(c), ct
        return 1.0 - fresnel_dielectric(c, eta), ct

    tm, ctm = t_and_ct(m)
    tu, ctu = t_and_ct(mu)
    integral = np.sum(w * tm * m / np.maximum(ctm + ctu[..., None], 1e-12), axis=-1)
    return float(a) * tu * integral / (2.0 * eta * eta)


def single_ambient_band(a: float, eta: float, mu, band: int) -> np.ndarray:
    """The single scattering of band `band` (0, 1, 2) of a sky's spherical harmonics toward cosine mu:
    Jensen's term with an isotropic phase function depends on the incident direction only through its
    cosine m with the normal, so by the Funk-Hecke theorem a sky of radiance sum L_lm Y_lm scatters
    sum_l lambda_l(mu) sum_m L_lm Y_lm(n) toward the viewer, lambda_l(mu) = a (1 - F(mu)) / (2 eta^2)
    int_0^1 (1 - F(m)) m P_l(m) / (mu_t(m) + mu_t(mu)) dm (P_l Legendre's polynomial; band 0 is
    single_ambient_albedo, the uniform sky's)."""
    if band == 0:
        return single_ambient_albedo(a, eta, mu)
    mu = np.clip(np.asarray(mu, np.float64), 0.0, 1.0)
    eta = float(clamp_eta(eta))
    m, w = _gl()
    legendre = {1: m, 2: 0.5 * (3.0 * m * m - 1.0)}[band]

    def t_and_ct(c):
        ct = np.sqrt(np.maximum((eta - 1.0) * (eta + 1.0) + c * c, 0.0)) / eta
        if eta == 1.0:
            return np.ones_like(c), ct
        return 1.0 - fresnel_dielectric(c, eta), ct

    tm, ctm = t_and_ct(m)
    tu, ctu = t_and_ct(mu)
    integral = np.sum(w * tm * m * legendre / np.maximum(ctm + ctu[..., None], 1e-12), axis=-1)
    return float(a) * tu * integral / (2.0 * eta * eta)


def single_band_tables(alpha, colour, eta) -> np.ndarray:
    """(3 bands, ANGULAR_NODES, 3 channels) lambda_l(mu) / A_colour (single_ambient_band) at the
    angular nodes, per unit base colour as the other tables."""
    mu = angular_nodes()
    out = np.zeros((3, ANGULAR_NODES, 3))
    for c in range(3):
        a, col = float(np.ravel(alpha)[c]), float(np.ravel(colour)[c])
        if col <= 0.0 or a <= 0.0:
            continue
        for band in range(3):
            out[band, :, c] = single_ambient_band(a, eta, mu, band) / col
    return out


ENTRY_TERMS = 3  # A_ms(t) ~ c_0 + c_1 t + c_2 t^2: kernels t, t^2, t^3 (split_sum.KERNEL_POWERS after the irradiance)


def entry_kernel_coefficients(alpha, colour, eta, ggx_alpha: float = 0.0) -> np.ndarray:
    """(ENTRY_TERMS, 3 channels) c_k with A_ms(t) / A_colour ~ sum_k c_k t^k: the light a map brings
    into the multiple scattering at normal n, int L(w) A_ms(n.w) (n.w) dw / A_colour, is then
    sum_k c_k int L (n.w)^(k+1) dw, the irradiance map and the map's t^2, t^3 kernel maps
    (skinlab/scene/optics/split_sum.py kernel_maps): exact for any map up to the fit, where nine SH
    bands with per-band factors were 2-5 % off per normal under the studio map's rest. Least squares
    in t weighted by t (the kernel's own cosine), the constant then set so that the uniform sky's
    entry, pi A_ms_d, is exact."""
    m, w = _gl()
    v = np.stack([m**k for k in range(ENTRY_TERMS)], 1)
    wt = w * m
    out = np.zeros((ENTRY_TERMS, 3))
    for c in range(3):
        a, col = float(np.ravel(alpha)[c]), float(np.ravel(colour)[c])
        if col <= 0.0 or a <= 0.0:
            continue
        f = ms_albedo(a, eta, m, ggx_alpha)
        coef = np.linalg.lstsq(v * np.sqrt(wt)[:, None], f * np.sqrt(wt), rcond=None)[0]
        coef[0] += float(np.sum(wt * (f - v @ coef)) / np.sum(wt))
        out[:, c] = coef / col
    return out


def hemispherical(f) -> float:
    """2 int_0^1 f(mu) mu dmu."""
    m, w = _gl()
    return float(2.0 * np.sum(w * m * f(m)))


def separable_ms_brdf(a: float, eta: float, mu, mu0, ggx_alpha: float = 0.0) -> np.ndarray:
    """The separable multiple-scattering BRDF A_ms(mu0) A_ms(mu) / (pi A_ms_d) (0 where A_ms_d = 0)."""
    d = hemispherical(lambda m: ms_albedo(a, eta, m, ggx_alpha))
    if d <= 0:
        return np.zeros(np.broadcast(np.asarray(mu), np.asarray(mu0)).shape)
    return ms_albedo(a, eta, mu0, ggx_alpha) * ms_albedo(a, eta, mu, ggx_alpha) / (np.pi * d)


def exact_ms_brdf_matched(a: float, mu, mu0) -> np.ndarray:
    """Chandrasekhar's multiple-scattering BRDF at eta = 1: a/(4 pi) (H(mu) H(mu0) - 1)/(mu + mu0)."""
    mu, mu0 = np.asarray(mu, np.float64), np.asarray(mu0, np.float64)
    hh = chandrasekhar_h(a, mu) * chandrasekhar_h(a, mu0)
    return float(a) / (4.0 * np.pi) * (hh - 1.0) / np.maximum(mu + mu0, 1e-12)


@dataclass(frozen=True)
class BoundaryTables:
    """Per-channel angular factors for a material (rows: the ANGULAR_NODES cosines)."""

    entry: np.ndarray  # (N, 3) A_ms(mu0) / A_colour: multiplies base colour x irradiance
    exit: np.ndarray  # (N, 3) A_ms(mu) / A_ms_d: hemispherical mean 1
    entry_diffuse: np.ndarray  # (3,) A_ms_d / A_colour: for uniform (ambient) light
    single: np.ndarray  # (3,) alpha / A_colour: Jensen's single-scattering term per base colour
    eta: float
    single_ambient: np.ndarray  # (N, 3) A_ss(mu) / A_colour: single scattering of a uniform sky
    ms_diffuse: np.ndarray  # (3,) A_ms_d (for reports)


def angular_nodes() -> np.ndarray:
    return np.linspace(0.0, 1.0, ANGULAR_NODES)


@table(disk=True, maxsize=256)
def _tables(alpha: tuple, colour: tuple, eta: float, ggx_alpha: float) -> BoundaryTables:
    mu = angular_nodes()
    entry = np.zeros((ANGULAR_NODES, 3))
    exit_ = np.zeros((ANGULAR_NODES, 3))
    ent_d = np.zeros(3)
    single = np.zeros(3)
    single_amb = np.zeros((ANGULAR_NODES, 3))
    msd = np.zeros(3)
    for c in range(3):
        a, col = float(alpha[c]), float(colour[c])
        if col <= 0.0 or a <= 0.0:
            continue
        f = lambda m, a=a: ms_albedo(a, eta, m, ggx_alpha)
        d = hemispherical(f)
        table = f(mu)
        msd[c] = d
        entry[:, c] = table / col
        ent_d[c] = d / col
        single[c] = a / col
        single_amb[:, c] = single_ambient_albedo(a, eta, mu) / col
        if d > 0:
            exit_[:, c] = table / d
    return BoundaryTables(entry, exit_, ent_d, single, eta, single_amb, msd)


def boundary_tables(alpha, colour, eta, ggx_alpha: float = 0.0) -> BoundaryTables:
    """Tables for a medium of single-scattering albedo `alpha` (3,) and surface colour `colour` (3,)
    (the material's subsurface colour, what the frame's base colour stands for) at index eta, under
    a boundary of GGX roughness ggx_alpha (the material's roughness^2; below SMOOTH_ALPHA smooth)."""
    al = tuple(round(float(x), 9) for x in np.clip(np.asarray(alpha, np.float64).reshape(3), 0.0, 1.0))
    col = tuple(round(float(x), 9) for x in np.clip(np.asarray(colour, np.float64).reshape(3), 0.0, 1.0))
    ga = float(ggx_alpha) if ggx_alpha >= SMOOTH_ALPHA else 0.0
    return _tables(al, col, round(float(clamp_eta(eta)), 6), round(ga, 9))


# The multiple-scattering BRDF's non-separable rest (ms_rest_table): nodes per cosine axis, cosines i / (N - 1).
# GLSL SSS_MS_REST_NODES. Coarser than the entry and exit tables: the rest is smooth but for the
# grazing corner, where the light's cosine that multiplies it vanishes.
MS_REST_NODES = 9


def ms_rest_nodes() -> np.ndarray:
    return np.linspace(0.0, 1.0, MS_REST_NODES)


@table(disk=True, maxsize=256)
def _ms_rest(alpha: tuple, colour: tuple, eta: float, ggx_alpha: float) -> np.ndarray:
    t = _tables(alpha, colour, eta, ggx_alpha)
    out = np.zeros((MS_REST_NODES, MS_REST_NODES, 3))
    if eta != 1.0:
        return out
    mu = ms_rest_nodes()
    view, light = mu[:, None], mu[None, :]
    for c in range(3):
        a, col = float(alpha[c]), float(colour[c])
        if col <= 0.0 or a <= 0.0:
            continue
        separable = table_lookup(t.entry, light)[..., c] * table_lookup(t.exit, view)[..., c] / np.pi
        out[..., c] = exact_ms_brdf_matched(a, view, light) / col - separable
    return out


def ms_rest_table(alpha, colour, eta, ggx_alpha: float = 0.0) -> np.ndarray:
    """What the separable multiple-scattering BRDF misses, per unit surface colour: (N, N, 3) at view
    cosines mu_i (rows) and light cosines mu0_j (columns), i / (MS_REST_NODES - 1). At eta = 1 it is
    Chandrasekhar's exact f_ms(mu, mu0) = a/(4 pi) (H(mu) H(mu0) - 1) / (mu + mu0) less the frame's
    separable entry(mu0) exit(mu) / pi (the tables as the shader interpolates them); added per light
    where the light lands, as single scattering is, it makes the light that left toward each view the
    exact half-space's. It leaves the energy as it was: for every mu0 the exact and the separable
    BRDF both integrate to A_ms(mu0) over the exit, and under uniform light both give A_ms(mu)
    (reciprocity), so the rest moves light between directions only. The separable form is 4-5.5 %
    dark for light and view along the normal and 9-10 % bright for light at cosine 0.2 (skin1,
    marble). Zero at eta > 1: no exact solution is known there (the entry and exit tables carry
    Saunderson's correction on the index-matched medium, which keeps the separable form)."""
    al = tuple(round(float(x), 9) for x in np.clip(np.asarray(alpha, np.float64).reshape(3), 0.0, 1.0))
    col = tuple(round(float(x), 9) for x in np.clip(np.asarray(colour, np.float64).reshape(3), 0.0, 1.0))
    ga = float(ggx_alpha) if ggx_alpha >= SMOOTH_ALPHA else 0.0
    return _ms_rest(al, col, round(float(clamp_eta(eta)), 6), round(ga, 9))


def ms_rest_lookup(table: np.ndarray, mu, mu0) -> np.ndarray:
    """Bilinear interpolation in a (N, N, 3) ms_rest_table at view cosines mu and light cosines mu0
    (clamped to [0, 1]): (..., 3). The shader's sss_ms_rest."""
    n = table.shape[0]
    x = np.clip(np.asarray(mu, np.float64), 0.0, 1.0) * (n - 1)
    y = np.clip(np.asarray(mu0, np.float64), 0.0, 1.0) * (n - 1)
    i = np.minimum(np.floor(x).astype(int), n - 2)
    j = np.minimum(np.floor(y).astype(int), n - 2)
    fx, fy = (x - i)[..., None], (y - j)[..., None]
    lo = table[i, j] * (1.0 - fy) + table[i, j + 1] * fy
    hi = table[i + 1, j] * (1.0 - fy) + table[i + 1, j + 1] * fy
    return lo * (1.0 - fx) + hi * fx


def table_lookup(table: np.ndarray, mu) -> np.ndarray:
    """Linear interpolation in a (N, 3) table at cosines mu (clamped to [0, 1]): (..., 3). The
    shader's sss_table_lookup."""
    mu = np.clip(np.asarray(mu, np.float64), 0.0, 1.0)
    x = mu * (ANGULAR_NODES - 1)
    i = np.minimum(np.floor(x).astype(int), ANGULAR_NODES - 2)
    f = (x - i)[..., None]
    return table[i] * (1.0 - f) + table[i + 1] * f
