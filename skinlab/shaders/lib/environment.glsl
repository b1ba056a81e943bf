// Light from an HDR environment map (skinlab/render/environment.py; the map and its preparation:
// skinlab/scene/envmap.py). NumPy twins: skinlab/scene/optics/sh.py (sh9_basis, irradiance) and
// skinlab/scene/optics/split_sum.py (equirect_uv, sample_levels, table_lookup, specular_occlusion).
// Diffuse: the irradiance of the map (without its bright sources, which are lights of their own) on
// every normal, from a 64 x 32 irradiance map (an exact cosine convolution); the map's radiance in nine
// spherical-harmonic coefficients, world axes, x intensity (Ramamoorthi & Hanrahan 2001) for the
// band ratio of the single scattering at a real index (env_band_ratio). Specular: the split sum (Karis 2013): the
// radiance prefiltered with the GGX lobe of each roughness (level k of u_env_radiance: roughness
// k / u_env_max_lod) times F0 A + B from the BRDF table. docs/references.md#environment-lighting.
#include "skinlab/constants.glsl"

uniform vec3 u_env_sh[9];          // radiance SH coefficients, world axes, x intensity
uniform mat3 u_env_to_map;         // world direction -> the map's frame (the rotation about +Y undone)
uniform sampler2D u_env_radiance;  // prefiltered levels (mip chain), the map's frame, intensity 1
uniform float u_env_max_lod;       // levels - 1
uniform float u_env_intensity;
uniform sampler2D u_env_brdf;      // split-sum table: x n.v, y roughness; (A, B)
uniform sampler2D u_env_irradiance;  // the irradiance for each normal (the map's frame, intensity 1)
uniform sampler2DArray u_env_kernels;  // the map's zonal kernel maps per normal (split_sum.kernel_maps)
#define ENV_KERNEL_NODES 17           // single-scattering layers (view cosines j / 16); then t^2, t^3

// The real SH basis at a unit direction (skinlab/scene/optics/sh.py sh9_basis), as 9 values.
void sh9_basis(vec3 d, out float y[9]) {
    y[0] = SH_C0;
    y[1] = SH_C1 * d.y;
    y[2] = SH_C1 * d.z;
    y[3] = SH_C1 * d.x;
    y[4] = SH_C2 * d.x * d.y;
    y[5] = SH_C2 * d.y * d.z;
    y[6] = SH_C3 * (3.0 * d.z * d.z - 1.0);
    y[7] = SH_C2 * d.x * d.z;
    y[8] = SH_C4 * (d.x * d.x - d.y * d.y);
}

// Irradiance on a surface of unit normal n from the map's SH radiance (unoccluded).
vec3 env_sh_irradiance(vec3 n) {
    float y[9];
    sh9_basis(n, y);
    vec3 e = SH_A0 * y[0] * u_env_sh[0];
    for (int k = 1; k < 4; ++k) e += SH_A1 * y[k] * u_env_sh[k];
    for (int k = 4; k < 9; ++k) e += SH_A2 * y[k] * u_env_sh[k];
    return e;
}

// Texture coordinates of a direction in the map's frame (Mitsuba's axes): u = atan2(x, -z) / 2 pi in
// [0, 1), v = theta / pi with theta = atan2(|(x, z)|, y) (= acos(y) for a unit direction, and better
// conditioned in fp32); along the poles' axis u = 0.
vec2 equirect_uv(vec3 d) {
    float u = (abs(d.x) + abs(d.z) > 1e-12) ? fract(atan(d.x, -d.z) * (0.5 * INV_PI)) : 0.0;
    return vec2(u, atan(length(d.xz), d.y) * INV_PI);
}

// The map's irradiance on a surface of world normal n (exact, from the irradiance map; unoccluded).
vec3 env_map_irradiance(vec3 n) {
    return u_env_intensity * textureLod(u_env_irradiance, equirect_uv(u_env_to_map * n), 0.0).rgb;
}

// Layer `layer` of the map's kernel maps at world normal n, x intensity (unoccluded): layers j < 17 the
// single scattering toward a view at cosine j / 16 per unit albedo of an index-matched medium,
// int L t / (4 pi (mu_j + t)) dw; then int L t^2 dw and int L t^3 dw (t = max(n.w, 0)).
// NumPy twin: skinlab/scene/optics/split_sum.py kernel_lookup.
vec3 env_kernel(vec3 n, int layer) {
    vec2 uv = equirect_uv(u_env_to_map * n);
    return u_env_intensity * textureLod(u_env_kernels, vec3(uv, float(layer)), 0.0).rgb;
}

// The prefiltered radiance arriving along world direction w for a lobe of this roughness.
vec3 env_radiance(vec3 w, float roughness) {
    vec2 uv = equirect_uv(u_env_to_map * w);
    return u_env_intensity * textureLod(u_env_radiance, uv, clamp(roughness, 0.0, 1.0) * u_env_max_lod).rgb;
}

// The split-sum table at (n.v, roughness): the GGX specular's directional albedo is F0 A + B.
vec2 env_brdf(float NoV, float roughness) {
    vec2 size = vec2(textureSize(u_env_brdf, 0));
    vec2 x = clamp(vec2(NoV, roughness), 0.0, 1.0) * (size - 1.0) + 0.5;
    return texture(u_env_brdf, x / size).rg;
}

// Specular occlusion from the sky's visibility (Lagarde & de Rousiers 2014, sec. 4.10.2).
float env_specular_occlusion(float NoV, float visibility, float roughness) {
    float nv = clamp(NoV, 0.0, 1.0), ao = clamp(visibility, 0.0, 1.0);
    return clamp(pow(nv + ao, exp2(-16.0 * roughness - 1.0)) - 1.0 + ao, 0.0, 1.0);
}

// What a zonal kernel with SH band factors l0, l1, l2 gathers from the map's radiance at normal n, per
// unit of the SH irradiance there (Funk-Hecke: sum_l lambda_l sum_m L_lm Y_lm(n) / sum_l A_l sum_m
// L_lm Y_lm(n)), clamped to [0, 4 x uniform]; `uniform` where the SH irradiance vanishes. Applied to
// the irradiance map's exact E(n), the ratio is robust to the 9 coefficients' ringing.
// NumPy twin: skinlab/render/environment.py env_band_ratio.
vec3 env_band_ratio(vec3 n, vec3 l0, vec3 l1, vec3 l2, vec3 uniform_ratio) {
    float y[9];
    sh9_basis(n, y);
    vec3 s0 = u_env_sh[0] * y[0];
    vec3 s1 = u_env_sh[1] * y[1] + u_env_sh[2] * y[2] + u_env_sh[3] * y[3];
    vec3 s2 = u_env_sh[4] * y[4] + u_env_sh[5] * y[5] + u_env_sh[6] * y[6] + u_env_sh[7] * y[7] + u_env_sh[8] * y[8];
    vec3 got = l0 * s0 + l1 * s1 + l2 * s2;
    vec3 irr = SH_A0 * s0 + SH_A1 * s1 + SH_A2 * s2;
    vec3 ratio;
    for (int c = 0; c < 3; ++c)
        ratio[c] = irr[c] > 1e-6 * max(s0[c], 1e-20) ? clamp(got[c] / irr[c], 0.0, 4.0 * uniform_ratio[c])
                                                     : uniform_ratio[c];
    return ratio;
}
