// Shared pieces of the diffusion profiles: well-conditioned expm1/log1p, exact dielectric Fresnel,
// Henyey-Greenstein, diffuse Fresnel fits, optical-unit scaling.
// NumPy twins: skinlab/scene/optics/fresnel.py and skinlab/scene/optics/_profile_util.py (same names, same clamps).
#include "skinlab/constants.glsl"

// expm1 / log1p: GLSL has neither. Taylor series where exp(x) - 1 / log(1 + x) would cancel
// (|x| < 0.05: truncation < 1e-10 relative), the plain form elsewhere (rounding < 2e-6 relative).
float em1(float x) {
    if (abs(x) < 0.05)
        return x * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x / 720.0)))));
    return exp(x) - 1.0;
}
vec3 em1(vec3 x) { return vec3(em1(x.x), em1(x.y), em1(x.z)); }

float l1p(float x) {
    if (abs(x) < 0.05)
        return x * (1.0 - x * (0.5 - x * (1.0 / 3.0 - x * (0.25 - x * (0.2 - x / 6.0)))));
    return log(1.0 + x);
}
vec3 l1p(vec3 x) { return vec3(l1p(x.x), l1p(x.y), l1p(x.z)); }

// Unpolarised Fresnel reflectance from both cosines (sums of positives: no cancellation).
float fresnel_from_cosines(float ci, float ct, float ni, float nt) {
    float rs_d = ni * ci + nt * ct;
    float rp_d = nt * ci + ni * ct;
    float rs = rs_d > 0.0 ? (ni * ci - nt * ct) / rs_d : 1.0;
    float rp = rp_d > 0.0 ? (nt * ci - ni * ct) / rp_d : 1.0;
    return 0.5 * (rs * rs + rp * rp);
}

// Exact dielectric reflectance, pbrt-v4 FrDielectric convention: eta = n_medium / n_outside,
// cos_i < 0 is light inside heading out. Total internal reflection gives 1.
float fresnel_dielectric(float cos_i, float eta) {
    float c = clamp(cos_i, -1.0, 1.0);
    float e = c < 0.0 ? 1.0 / eta : eta;
    c = abs(c);
    float sin2_t = (1.0 - c) * (1.0 + c) / (e * e);
    if (sin2_t >= 1.0) return 1.0;
    float cos_t = sqrt(max(1.0 - sin2_t, 0.0));
    return fresnel_from_cosines(c, cos_t, 1.0, e);
}

// Henyey-Greenstein; cos_theta between propagation directions before/after scattering.
float hg_phase(float cos_theta, float g) {
    float denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g) * (1.0 + g) / (4.0 * PI * denom * sqrt(denom));
}

float clamp_eta(float eta) { return clamp(eta, DIFFUSION_ETA_MIN, DIFFUSION_ETA_MAX); }

// Internal diffuse Fresnel reflectance (Jensen 2001 for eta >= 1, Egan & Hilgeman for eta < 1).
float fdr(float eta) {
    eta = clamp_eta(eta);
    float ie = 1.0 / eta;
    if (eta >= 1.0) return FDR_GT1_0 * ie * ie + FDR_GT1_1 * ie + FDR_GT1_2 + FDR_GT1_3 * eta;
    return FDR_LT1_0 + FDR_LT1_1 * ie + FDR_LT1_2 * ie * ie + FDR_LT1_3 * ie * ie * ie;
}

// pbrt-v4 FresnelMoment1 / FresnelMoment2, evaluated from their Chebyshev re-expansion on
// [DIFFUSION_ETA_MIN, 1] and [1, DIFFUSION_ETA_MAX] (constants.py; the raw pbrt polynomials
// cancel badly in fp32). Clenshaw recurrence.
const int FM_CHEB_N = 22;  // = skinlab/scene/optics/constants.py FM_CHEB_N
float cheb(float t, float c[FM_CHEB_N]) {
    float b1 = 0.0, b2 = 0.0;
    for (int k = FM_CHEB_N - 1; k >= 1; --k) {
        float b0 = 2.0 * t * b1 - b2 + c[k];
        b2 = b1;
        b1 = b0;
    }
    return t * b1 - b2 + c[0];
}

float fm_cheb_t(float eta) {
    return eta < 1.0 ? (2.0 * eta - DIFFUSION_ETA_MIN - 1.0) / (1.0 - DIFFUSION_ETA_MIN)
                     : (2.0 * eta - 1.0 - DIFFUSION_ETA_MAX) / (DIFFUSION_ETA_MAX - 1.0);
}

float fresnel_moment1(float eta) {
    eta = clamp_eta(eta);
    float t = fm_cheb_t(eta);
    if (eta < 1.0) return cheb(t, float[FM_CHEB_N](FM1_CHEB_LT1_0, FM1_CHEB_LT1_1, FM1_CHEB_LT1_2, FM1_CHEB_LT1_3, FM1_CHEB_LT1_4, FM1_CHEB_LT1_5, FM1_CHEB_LT1_6, FM1_CHEB_LT1_7, FM1_CHEB_LT1_8, FM1_CHEB_LT1_9, FM1_CHEB_LT1_10, FM1_CHEB_LT1_11, FM1_CHEB_LT1_12, FM1_CHEB_LT1_13, FM1_CHEB_LT1_14, FM1_CHEB_LT1_15, FM1_CHEB_LT1_16, FM1_CHEB_LT1_17, FM1_CHEB_LT1_18, FM1_CHEB_LT1_19, FM1_CHEB_LT1_20, FM1_CHEB_LT1_21));
    return cheb(t, float[FM_CHEB_N](FM1_CHEB_GE1_0, FM1_CHEB_GE1_1, FM1_CHEB_GE1_2, FM1_CHEB_GE1_3, FM1_CHEB_GE1_4, FM1_CHEB_GE1_5, FM1_CHEB_GE1_6, FM1_CHEB_GE1_7, FM1_CHEB_GE1_8, FM1_CHEB_GE1_9, FM1_CHEB_GE1_10, FM1_CHEB_GE1_11, FM1_CHEB_GE1_12, FM1_CHEB_GE1_13, FM1_CHEB_GE1_14, FM1_CHEB_GE1_15, FM1_CHEB_GE1_16, FM1_CHEB_GE1_17, FM1_CHEB_GE1_18, FM1_CHEB_GE1_19, FM1_CHEB_GE1_20, FM1_CHEB_GE1_21));
}

float fresnel_moment2(float eta) {
    eta = clamp_eta(eta);
    float t = fm_cheb_t(eta);
    if (eta < 1.0) return cheb(t, float[FM_CHEB_N](FM2_CHEB_LT1_0, FM2_CHEB_LT1_1, FM2_CHEB_LT1_2, FM2_CHEB_LT1_3, FM2_CHEB_LT1_4, FM2_CHEB_LT1_5, FM2_CHEB_LT1_6, FM2_CHEB_LT1_7, FM2_CHEB_LT1_8, FM2_CHEB_LT1_9, FM2_CHEB_LT1_10, FM2_CHEB_LT1_11, FM2_CHEB_LT1_12, FM2_CHEB_LT1_13, FM2_CHEB_LT1_14, FM2_CHEB_LT1_15, FM2_CHEB_LT1_16, FM2_CHEB_LT1_17, FM2_CHEB_LT1_18, FM2_CHEB_LT1_19, FM2_CHEB_LT1_20, FM2_CHEB_LT1_21));
    return cheb(t, float[FM_CHEB_N](FM2_CHEB_GE1_0, FM2_CHEB_GE1_1, FM2_CHEB_GE1_2, FM2_CHEB_GE1_3, FM2_CHEB_GE1_4, FM2_CHEB_GE1_5, FM2_CHEB_GE1_6, FM2_CHEB_GE1_7, FM2_CHEB_GE1_8, FM2_CHEB_GE1_9, FM2_CHEB_GE1_10, FM2_CHEB_GE1_11, FM2_CHEB_GE1_12, FM2_CHEB_GE1_13, FM2_CHEB_GE1_14, FM2_CHEB_GE1_15, FM2_CHEB_GE1_16, FM2_CHEB_GE1_17, FM2_CHEB_GE1_18, FM2_CHEB_GE1_19, FM2_CHEB_GE1_20, FM2_CHEB_GE1_21));
}

// Optical radius x = r / l per channel. valid = 0 where l < MIN_MFP_MM (no scattering) or
// x >= PROFILE_MAX_OPTICAL_R; there x = 0 and l = 1 so the caller computes finite values and
// multiplies them by valid (never NaN * 0).
vec3 optical_radius(float r, vec3 mfp, out vec3 valid, out vec3 inv_l2) {
    bvec3 ok_l = greaterThanEqual(mfp, vec3(MIN_MFP_MM));
    vec3 l = mix(vec3(1.0), mfp, ok_l);            // bvec3 mix selects: no inf * 0
    vec3 x = abs(r) / l;
    bvec3 ok = bvec3(vec3(ok_l) * vec3(lessThan(x, vec3(PROFILE_MAX_OPTICAL_R))));
    valid = vec3(ok);
    inv_l2 = 1.0 / (l * l);
    return mix(vec3(0.0), x, ok);
}

// Depth sample i of the beam integrals: -ln(1 - (i + 1/2)/N) = -ln((N - i - 1/2)/N).
float depth_sample(int i) { return -log((PBD_SAMPLES - float(i) - 0.5) / PBD_SAMPLES); }
