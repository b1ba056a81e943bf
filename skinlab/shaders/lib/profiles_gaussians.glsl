// Sums of Gaussians (d'Eon & Luebke 2007). See skinlab/scene/optics/gaussians.py.
#include "skinlab/constants.glsl"

#ifndef GAUSS_MAX
#define GAUSS_MAX 8
#endif

// G(v, r) = e^{-r^2/2v} / (2 pi v); a variance below 1e-12 mm^2 is a delta: 0.
float gaussian(float v, float r) {
    if (v < 1e-12) return 0.0;
    return exp(-(r * r) / (2.0 * v)) / (2.0 * PI * v);
}

vec3 gaussian_sum(float r, float v[GAUSS_MAX], vec3 w[GAUSS_MAX], int k) {
    vec3 acc = vec3(0.0);
    for (int i = 0; i < GAUSS_MAX; ++i) {
        if (i >= k) break;
        acc += w[i] * gaussian(v[i], r);
    }
    return acc;
}

vec3 deon_skin_profile(float r, vec3 albedo) {
    return albedo * (
        vec3(SKIN6_WR_0, SKIN6_WG_0, SKIN6_WB_0) * gaussian(SKIN6_VAR_0, r) +
        vec3(SKIN6_WR_1, SKIN6_WG_1, SKIN6_WB_1) * gaussian(SKIN6_VAR_1, r) +
        vec3(SKIN6_WR_2, SKIN6_WG_2, SKIN6_WB_2) * gaussian(SKIN6_VAR_2, r) +
        vec3(SKIN6_WR_3, SKIN6_WG_3, SKIN6_WB_3) * gaussian(SKIN6_VAR_3, r) +
        vec3(SKIN6_WR_4, SKIN6_WG_4, SKIN6_WB_4) * gaussian(SKIN6_VAR_4, r) +
        vec3(SKIN6_WR_5, SKIN6_WG_5, SKIN6_WB_5) * gaussian(SKIN6_VAR_5, r));
}
