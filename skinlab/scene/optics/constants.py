"""The one source of numeric constants shared by the NumPy references and the GLSL shaders.

`GLSL_CONSTANTS` is turned into the virtual include file ``skinlab/constants.glsl`` by
:func:`glsl_header`; shaders never spell these numbers themselves.
"""

from __future__ import annotations

import math

PI = math.pi
INV_PI = 1.0 / math.pi

# Smallest GGX alpha (= roughness^2). Roughness 0 is a mirror; alpha is clamped so that the
# D term stays finite in fp32 (peak 1/(pi alpha^2) ~ 3.2e5 at alpha=1e-3).
MIN_GGX_ALPHA = 1.0e-3
# Cosines are clamped to at least this before they divide anything (grazing angles n.v -> 0).
MIN_COS = 1.0e-4
# Dielectric F0 for specular = 0.5 (Burley 2012: specular 0.5 <=> F0 = 0.04); F0 = 0.08 * specular.
SPECULAR_F0_SCALE = 0.08

# sRGB transfer function (IEC 61966-2-1)
SRGB_LINEAR_THRESHOLD = 0.0031308
SRGB_ENCODED_THRESHOLD = 0.04045

# Point lights: distances are clamped to at least this (metres) before the inverse square.
MIN_LIGHT_DISTANCE_M = 1.0e-3

# Shadow-map depth bias, sized to the map's texel at the receiver (skinlab/shaders/lib/shadow.glsl,
# skinlab/scene/optics/shadow.py): bias = texel x (SHADOW_BIAS_TEXELS + SHADOW_SLOPE_TEXELS x
# min(tan theta, SHADOW_SLOPE_MAX)), theta the angle between the receiver's normal and the light. The
# 3x3 PCF taps and their bilinear footprints reach 2 sqrt 2 texels from the receiver, over which a
# plane tilted by theta changes depth by 2.83 texel tan theta: 3 texels of slope keep a lit plane lit.
# The clamp bounds how far behind an occluder light can leak (16 texels at most, 3.2 mm on the head
# with a 2048 map); past it (NoL < 0.2) a surface may shadow itself a little where it receives almost
# no light anyway.
SHADOW_BIAS_TEXELS = 1.0
SHADOW_SLOPE_TEXELS = 3.0
SHADOW_SLOPE_MAX = 5.0
# A footprint's shadow (shadow.py shadow_pcf_area: a texture-space texel's) is averaged over it where
# it spans more than SHADOW_AREA_MIN_TEXELS of the map's texels (the 3x3 PCF's width; below, the 3x3
# PCF), with a tap per texel along each side, at most SHADOW_AREA_TAPS (wider: taps further apart).
SHADOW_AREA_MIN_TEXELS = 3.0
SHADOW_AREA_TAPS = 16
# A map fitted to what the camera sees (skinlab/render/shadow_fit.py) answers a lookup whose texels lie
# SHADOW_FIT_REACH of its texels inside its edge (the 3x3 PCF's bilinear taps read 2 texels each way:
# a half-texel shift, one tap and its bilinear neighbour); beyond, the full map does.
SHADOW_FIT_REACH = 2.5
# A screen pass's lookup in a fitted map averages it over the sample's footprint (its bounding box in the
# map, at least a texel): nine gathers of 2 x 2 compares cover a box up to SHADOW_BOX_TEXELS wide
# (lib/shadow.glsl shadow_box); wider, shadow_pcf_area's taps.
SHADOW_BOX_TEXELS = 5.0
SHADOW_BOX_CELLS = 3  # a wider box: sampled by a gather in each of these many cells per side

GLSL_CONSTANTS: dict[str, float] = {
    "PI": PI,
    "INV_PI": INV_PI,
    "MIN_GGX_ALPHA": MIN_GGX_ALPHA,
    "MIN_COS": MIN_COS,
    "SPECULAR_F0_SCALE": SPECULAR_F0_SCALE,
    "SRGB_LINEAR_THRESHOLD": SRGB_LINEAR_THRESHOLD,
    "SRGB_ENCODED_THRESHOLD": SRGB_ENCODED_THRESHOLD,
    "SHADOW_BIAS_TEXELS": SHADOW_BIAS_TEXELS,
    "SHADOW_SLOPE_TEXELS": SHADOW_SLOPE_TEXELS,
    "SHADOW_SLOPE_MAX": SHADOW_SLOPE_MAX,
    "SHADOW_AREA_MIN_TEXELS": SHADOW_AREA_MIN_TEXELS,
    "SHADOW_AREA_TAPS": float(SHADOW_AREA_TAPS),
    "SHADOW_FIT_REACH": SHADOW_FIT_REACH,
    "SHADOW_BOX_TEXELS": SHADOW_BOX_TEXELS,
    "SHADOW_BOX_CELLS": float(SHADOW_BOX_CELLS),
    "MIN_LIGHT_DISTANCE_M": MIN_LIGHT_DISTANCE_M,
}


def register(name: str, value: float) -> float:
    """Add a constant to the shared table (for optics modules defined elsewhere) and return it."""
    if name in GLSL_CONSTANTS and GLSL_CONSTANTS[name] != value:
        raise ValueError(f"constant {name} registered twice with different values")
    GLSL_CONSTANTS[name] = float(value)
    return float(value)


def glsl_header() -> str:
    """GLSL source for the shared constants (included as "skinlab/constants.glsl")."""
    lines = ["// Generated from skinlab/scene/optics/constants.py - do not edit."]
    for name, value in GLSL_CONSTANTS.items():
        lines.append(f"const float {name} = {float(value)!r};")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------------------
# Diffusion profiles (issue 3). Appended as a block so the dict order above is unchanged.
# Sources (docs/references.md): jensen-2001, christensen-burley-2015, blender-burley, habel-2013
# (pbrt-v4 src/pbrt/bssrdf.cpp + util/scattering.h, Fresnel moments), deon-luebke-2007 (GPU Gems 3, 14).
# ---------------------------------------------------------------------------------------------
# Mean free paths (mm) below this are "no scattering": every profile returns 0 (the delta at r = 0
# is the renderer's plain diffuse term). Keeps 1/l^2 far from fp32 overflow. A power of two so
# that fp32 and float64 agree on which side of it a value lies.
MIN_MFP_MM = 2.0**-20
# Burley-type profiles diverge like 1/r at r = 0. They are evaluated at max(r, BURLEY_R0_EPS d):
# the analytic value at the rim of a disc of radius 1e-3 d (continuous; finite at r = 0; the energy
# inside that disc is underestimated by about A * BURLEY_R0_EPS / 4, i.e. 2.5e-4 A).
BURLEY_R0_EPS = 2.0**-10
# Blender (Cycles/EEVEE) Burley: truncation radius in units of d and the CDF there.
BURLEY_TRUNCATE = 16.0
BURLEY_TRUNCATE_CDF = 1.0 - 0.25 * math.exp(-16.0) - 0.75 * math.exp(-16.0 / 3.0)
# Profiles are exactly 0 beyond this many mean free paths (far below fp32 range anyway; avoids
# inf/inf in d = sqrt(r^2 + z^2) for absurd radii).
PROFILE_MAX_OPTICAL_R = 1.0e6
# Photon beam diffusion: depth samples per evaluation (pbrt-v4 bssrdf.cpp uses 100).
PBD_SAMPLES = 100
# Jensen 2001 / Egan & Hilgeman 1979 diffuse Fresnel reflectance fits (eta >= 1 and eta < 1).
FDR_GT1 = (-1.440, 0.710, 0.668, 0.0636)  # c0/eta^2 + c1/eta + c2 + c3 eta
FDR_LT1 = (-0.4399, 0.7099, -0.3319, 0.0636)  # c0 + c1/eta + c2/eta^2 + c3/eta^3
# The eta fits above and below are only meaningful over a limited range (Egan's eta < 1 fit
# diverges below ~0.4; the pbrt moment fits make 1 - 2 FM1 negative above ~2.8): diffusion
# models clamp eta to [DIFFUSION_ETA_MIN, DIFFUSION_ETA_MAX] before using them.
DIFFUSION_ETA_MIN = 0.5
DIFFUSION_ETA_MAX = 2.5
# pbrt-v4 FresnelMoment1/2 polynomial fits (util/scattering.cpp).
FM1_LT1 = (0.45966, -1.73965, 3.37668, -3.904945, 2.49277, -0.68441)  # powers eta^0..5
FM1_GE1 = (-4.61686, 11.1136, -10.4646, 5.11455, -1.27198, 0.12746)  # powers eta^0..5
FM2_LT1 = (0.27614, -0.87350, 1.12077, -0.65095, 0.07883, 0.04860)  # powers eta^0..5
FM2_GE1 = (
    -547.033,
    458.843,
    -218.725,
    45.3087,  # eta^0, eta^-1..-3
    404.557,
    -189.519,
    54.9327,
    -9.00603,
    0.63942,
)  # eta^1..5


def _fm_reference(eta: float, which: int) -> float:
    """pbrt-v4 FresnelMoment1 (which = 1) / FresnelMoment2 (which = 2) in float64."""
    if which == 1:
        c = FM1_LT1 if eta < 1.0 else FM1_GE1
        return sum(ck * eta**k for k, ck in enumerate(c))
    if eta < 1.0:
        return sum(ck * eta**k for k, ck in enumerate(FM2_LT1))
    g = FM2_GE1
    return g[0] + g[1] / eta + g[2] / eta**2 + g[3] / eta**3 + sum(g[4 + k] * eta ** (k + 1) for k in range(5))


def _chebyshev_fit(fn, lo: float, hi: float, n: int = 14) -> tuple[float, ...]:
    """Chebyshev coefficients of fn on [lo, hi] (interpolation at n Chebyshev nodes)."""
    nodes = [math.cos(math.pi * (j + 0.5) / n) for j in range(n)]
    vals = [fn(lo + (hi - lo) * 0.5 * (t + 1.0)) for t in nodes]
    return tuple(
        (2.0 if k else 1.0) / n * sum(v * math.cos(math.pi * k * (j + 0.5) / n) for j, v in enumerate(vals))
        for k in range(n)
    )


# The pbrt moment polynomials cancel badly in fp32 (FM2 for eta >= 1 sums terms of +-500 to
# get ~0.1). GLSL evaluates the same functions re-expanded as Chebyshev series on the two eta
# intervals (Clenshaw: well conditioned); truncation error < 1e-10 (tests/scene/optics/test_profile_models.py).
FM_CHEB_N = 22
FM1_CHEB_LT1 = _chebyshev_fit(lambda e: _fm_reference(e, 1), DIFFUSION_ETA_MIN, 1.0, FM_CHEB_N)
FM1_CHEB_GE1 = _chebyshev_fit(lambda e: _fm_reference(e, 1), 1.0, DIFFUSION_ETA_MAX, FM_CHEB_N)
FM2_CHEB_LT1 = _chebyshev_fit(lambda e: _fm_reference(e, 2), DIFFUSION_ETA_MIN, 1.0, FM_CHEB_N)
FM2_CHEB_GE1 = _chebyshev_fit(lambda e: _fm_reference(e, 2), 1.0, DIFFUSION_ETA_MAX, FM_CHEB_N)

# d'Eon & Luebke 2007 six-Gaussian skin profile: variances (mm^2) and RGB weights.
SKIN6_VARIANCES = (0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41)
SKIN6_WEIGHTS = (
    (0.233, 0.455, 0.649),
    (0.100, 0.336, 0.344),
    (0.118, 0.198, 0.0),
    (0.113, 0.007, 0.007),
    (0.358, 0.004, 0.0),
    (0.078, 0.0, 0.0),
)

GLSL_CONSTANTS.update(
    {
        "MIN_MFP_MM": MIN_MFP_MM,
        "BURLEY_R0_EPS": BURLEY_R0_EPS,
        "BURLEY_TRUNCATE": BURLEY_TRUNCATE,
        "BURLEY_TRUNCATE_CDF": BURLEY_TRUNCATE_CDF,
        "PBD_SAMPLES": float(PBD_SAMPLES),
        "PROFILE_MAX_OPTICAL_R": PROFILE_MAX_OPTICAL_R,
        "DIFFUSION_ETA_MIN": DIFFUSION_ETA_MIN,
        "DIFFUSION_ETA_MAX": DIFFUSION_ETA_MAX,
        **{f"FDR_GT1_{i}": v for i, v in enumerate(FDR_GT1)},
        **{f"FDR_LT1_{i}": v for i, v in enumerate(FDR_LT1)},
        **{f"FM1_CHEB_LT1_{i}": v for i, v in enumerate(FM1_CHEB_LT1)},
        **{f"FM1_CHEB_GE1_{i}": v for i, v in enumerate(FM1_CHEB_GE1)},
        **{f"FM2_CHEB_LT1_{i}": v for i, v in enumerate(FM2_CHEB_LT1)},
        **{f"FM2_CHEB_GE1_{i}": v for i, v in enumerate(FM2_CHEB_GE1)},
        **{f"SKIN6_VAR_{i}": v for i, v in enumerate(SKIN6_VARIANCES)},
        **{f"SKIN6_W{c}_{i}": w[j] for j, c in enumerate("RGB") for i, w in enumerate(SKIN6_WEIGHTS)},
    }
)

# ---------------------------------------------------------------------------------------------
# Texture-space diffusion (d'Eon & Luebke 2007; skinlab/scene/optics/tsd.py, skinlab/shaders/techniques/tsd/*.frag)
TSD_TAP_RANGE = 3.0  # blur taps span +-3 sigma
TSD_MIN_MM_PER_TEXEL = 1e-6  # zero-area triangles (infinite stretch) clamp to this
TSD_MAX_STEP_TEXELS = 4096.0  # one sigma never spans more texels than this (finite for any stretch)
COVERAGE_EPS = 1e-6  # premultiplied coverage below this is "no surface"
GLSL_CONSTANTS.update(
    {
        "TSD_MIN_MM_PER_TEXEL": TSD_MIN_MM_PER_TEXEL,
        "TSD_MAX_STEP_TEXELS": TSD_MAX_STEP_TEXELS,
        "COVERAGE_EPS": COVERAGE_EPS,
    }
)

# Luminance weights of linear Rec. 709 / sRGB primaries (ITU-R BT.709-6, item 3.2): one figure
# from three channels where a single value must stand for all (the oblique entry offset,
# skinlab/scene/optics/oblique.py).
LUMA_R, LUMA_G, LUMA_B = 0.2126, 0.7152, 0.0722
GLSL_CONSTANTS.update({"LUMA_R": LUMA_R, "LUMA_G": LUMA_G, "LUMA_B": LUMA_B})

# The spread of where obliquely entering light entered (issue 21; skinlab/scene/optics/oblique.py
# entry_ramp_weights): the first scattering lies an exponentially distributed path along the refracted
# beam, so the entry point lies upstream by an exponential distance. Three shadow lookups stand for it,
# at the conditional means of the terciles of Exp(1) (in units of the luminance offset), each weighted by
# its channel's probability of the tercile's span: bounds ln 3/2 and ln 3.
ENTRY_RAMP_B1, ENTRY_RAMP_B2 = math.log(1.5), math.log(3.0)
ENTRY_RAMP_N1 = 1.0 - ENTRY_RAMP_B1 * 2.0  # E[x | x < ln 3/2] = (1 - (1 + b) e^-b) / (1 - e^-b), e^-b = 2/3
ENTRY_RAMP_N2 = (ENTRY_RAMP_B1 * 2.0 / 3.0 - ENTRY_RAMP_B2 / 3.0 + 1.0 / 3.0) * 3.0
ENTRY_RAMP_N3 = 1.0 + ENTRY_RAMP_B2  # memorylessness: E[x | x > b] = b + 1
GLSL_CONSTANTS.update(
    {
        "ENTRY_RAMP_B1": ENTRY_RAMP_B1,
        "ENTRY_RAMP_B2": ENTRY_RAMP_B2,
        "ENTRY_RAMP_N1": ENTRY_RAMP_N1,
        "ENTRY_RAMP_N2": ENTRY_RAMP_N2,
        "ENTRY_RAMP_N3": ENTRY_RAMP_N3,
    }
)

# Single scattering along the light's path through the medium (skinlab/scene/optics/single_through.py,
# lib/sss_single_through.glsl): the depths along the refracted view ray where the path inside is read
# from the distance map, in units of the luminance mean free path (real extinction), the point itself
# first. Chosen against a brute-force integral over a skin1 ball of radius 8 mm lit near its terminator
# (docs/ground-truth.md "Single scattering along the light's path"): denser near the surface, where a
# convex part's path grows like a square root.
SINGLE_THROUGH_DEPTHS = (0.0, 0.15, 0.6, 2.0)
GLSL_CONSTANTS.update({f"SINGLE_THROUGH_D{k}": v for k, v in enumerate(SINGLE_THROUGH_DEPTHS)})
# Past a terminator the term applies where the entry face the distance map shows in front is within 60
# degrees of the point's own face (cosine between their normals at least this): a smoothly curved part,
# whose light skims under its surface. A sheet's faces are opposed, a box's edge has them at 90 degrees:
# there the slab transmittance, which counts the first order of scattering too, carries that light (the
# two back-lit slabs' rims read 0.4 points worse on 4x4 blocks with the term at a 90-degree edge).
SINGLE_THROUGH_MIN_FACE_COS = 0.5
GLSL_CONSTANTS["SINGLE_THROUGH_MIN_FACE_COS"] = SINGLE_THROUGH_MIN_FACE_COS
# The lit side's gain is 1 where it comes within this of 1: a flat part's, whose piecewise-linear integral
# is exact but for fp32 rounding (a few 1e-7), renders as the flat term bit for bit.
SINGLE_THROUGH_ROUNDING = 1e-4
GLSL_CONSTANTS["SINGLE_THROUGH_ROUNDING"] = SINGLE_THROUGH_ROUNDING
# The extinction it integrates with is at most this (per mm): a radius of 0 gives an infinite one, whose
# product with the point's own path of 0 would be a NaN; the light then leaves at the point, as it should.
SINGLE_THROUGH_MAX_SIGMA = 1e30
GLSL_CONSTANTS["SINGLE_THROUGH_MAX_SIGMA"] = SINGLE_THROUGH_MAX_SIGMA

# ---------------------------------------------------------------------------------------------
# Environment lighting (issue 22; skinlab/scene/optics/sh.py, skinlab/scene/envmap.py,
# skinlab/shaders/lib/environment.glsl). Real spherical harmonics to order 2 (Sloan 2008, appendix
# A2) and the clamped cosine's zonal coefficients (Ramamoorthi & Hanrahan 2001, eq. 8).
SH_C0 = 0.28209479177387814  # 1 / (2 sqrt(pi))
SH_C1 = 0.4886025119029199  # sqrt(3 / (4 pi))
SH_C2 = 1.0925484305920792  # sqrt(15 / (4 pi))
SH_C3 = 0.31539156525252005  # sqrt(5 / (16 pi))
SH_C4 = 0.5462742152960396  # sqrt(15 / (16 pi))
SH_A = (PI, 2.0 * PI / 3.0, PI / 4.0)
GLSL_CONSTANTS.update({"SH_C0": SH_C0, "SH_C1": SH_C1, "SH_C2": SH_C2, "SH_C3": SH_C3, "SH_C4": SH_C4})
GLSL_CONSTANTS.update({f"SH_A{band}": a for band, a in enumerate(SH_A)})

# ---------------------------------------------------------------------------------------------
# Single scattering under a near (point or spot) light (issue 21; skinlab/scene/optics/near_single.py,
# skinlab/shaders/lib/sss_near_single.glsl): Gauss-Laguerre nodes and weights (weight e^{-t} on
# [0, inf); numpy.polynomial.laguerre.laggauss(4), checked in tests/scene/optics/test_near_single.py).
NEAR_SINGLE_T = (0.3225476896193924, 1.7457611011583465, 4.536620296921128, 9.395070912301133)
NEAR_SINGLE_W = (0.6031541043416337, 0.35741869243779956, 0.038887908515005405, 0.0005392947055613296)
# The gain is at most this (a light nearer than its height allows: the ratio of inverse squares grows
# as 1 / mu_i^2 at the light's foot, where the far term it multiplies falls as mu_i).
NEAR_SINGLE_MAX_GAIN = 8.0
# sigma_t x the light's distance is taken as at least this (no extinction: the points that scatter lie
# farther than the light is from the surface, the gain is about 0; finite in fp32).
NEAR_SINGLE_MIN_OPTICAL = 1.0e-3
GLSL_CONSTANTS.update({f"NEAR_SINGLE_T{i}": t for i, t in enumerate(NEAR_SINGLE_T)})
GLSL_CONSTANTS.update({f"NEAR_SINGLE_W{i}": w for i, w in enumerate(NEAR_SINGLE_W)})
GLSL_CONSTANTS.update({"NEAR_SINGLE_MAX_GAIN": NEAR_SINGLE_MAX_GAIN})
GLSL_CONSTANTS.update({"NEAR_SINGLE_MIN_OPTICAL": NEAR_SINGLE_MIN_OPTICAL})
