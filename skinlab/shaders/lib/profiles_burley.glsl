// Christensen & Burley 2015 normalized diffusion and Blender's truncated variant with samplers.
// See skinlab/scene/optics/burley.py and docs/references.md#christensen-burley-2015 for the formulas; r, l, d in mm, result 1/mm^2.
#include "lib/profiles_common.glsl"

const int BURLEY_DIFFUSE = 0;      // diffuse surface transmission, l = mean free path
const int BURLEY_SEARCHLIGHT = 1;  // perpendicular incidence, l = mean free path
const int BURLEY_DMFP = 2;         // l = diffuse mean free path

vec3 burley_s(vec3 A, int variant) {
    if (variant == BURLEY_DIFFUSE) return 1.9 - A + 3.5 * (A - 0.8) * (A - 0.8);
    if (variant == BURLEY_SEARCHLIGHT) { vec3 t = abs(A - 0.8); return 1.85 - A + 7.0 * t * t * t; }
    vec3 u = A - 0.33; u *= u; return 3.5 + 100.0 * u * u;
}

// In terms of d = l / s. Evaluated at max(r, BURLEY_R0_EPS d): finite and continuous at r = 0.
vec3 burley_profile_d(float r, vec3 A, vec3 d) {
    vec3 valid, inv_d2;
    vec3 x = optical_radius(r, d, valid, inv_d2);
    vec3 xs = max(x, vec3(BURLEY_R0_EPS));
    vec3 body = (exp(-xs) + exp(-xs / 3.0)) / (8.0 * PI * xs);
    return valid * A * body * inv_d2;
}

vec3 burley_profile(float r, vec3 A, vec3 mfp, int variant) {
    return burley_profile_d(r, A, mfp / burley_s(A, variant));
}

float burley_cdf(float r, float d) {
    float x = r / d;
    return 1.0 - 0.25 * exp(-x) - 0.75 * exp(-x / 3.0);
}

float burley_sample_golubev(float xi, float d) {
    float u = 1.0 - xi;
    float G = 1.0 + 4.0 * u * (2.0 * u + sqrt(1.0 + 4.0 * u * u));
    float g3 = pow(G, 1.0 / 3.0);
    return 3.0 * d * log((1.0 + 1.0 / g3 + g3) / (4.0 * u));
}

vec3 blender_d(vec3 A, vec3 radius) { return radius / (4.0 * PI) / burley_s(A, BURLEY_DIFFUSE); }

vec3 blender_burley_profile(float r, vec3 A, vec3 radius) {
    vec3 d = blender_d(A, radius);
    vec3 inside = vec3(lessThan(vec3(abs(r)), BURLEY_TRUNCATE * d));
    return inside * burley_profile_d(r, A, d) / BURLEY_TRUNCATE_CDF;
}

// Cycles bssrdf_burley_root_find: Newton on 1 - e^{-x}/4 - 3 e^{-x/3}/4 = xi.
float burley_root_find(float xi) {
    float x = xi <= 0.9 ? exp(2.4 * xi * xi) - 1.0 : 15.0;
    for (int i = 0; i < 10; ++i) {
        float e3 = exp(-x / 3.0);
        float e1 = e3 * e3 * e3;
        float f = 1.0 - 0.25 * e1 - 0.75 * e3 - xi;
        float fp = 0.25 * e1 + 0.25 * e3;
        if (abs(f) < 1e-6 || fp == 0.0) break;
        x = max(x - f / fp, 0.0);
    }
    return x;
}

float blender_burley_sample(float xi, float d) { return burley_root_find(xi * BURLEY_TRUNCATE_CDF) * d; }
