#version 330 core
// Brute-force texture-space convolution with the exact radial profile (the image reference for the
// realtime techniques; slow on purpose). Every texel within r_max (from a table of R(r)) contributes
// R(r) x its area; the centre cell contributes the profile's energy inside its own area (the
// cumulative table E, so a profile singular at r = 0 is integrated, not sampled). Distances use this
// texel's stretch (mm per texel along u, v). Coverage-normalised like the Gaussian blurs.
// Tables: scene/optics/tsd.py exact_profile_lut; NumPy counterpart: exact_profile_convolution.
#include "skinlab/constants.glsl"
uniform sampler2D u_src;         // premultiplied irradiance (rgb E a, a), with mipmaps
uniform sampler2D u_stretch;
uniform sampler2D u_lut;         // row 0: R(r) per channel (normalised), row 1: E(r); r = x * r_max
uniform float u_rmax_mm;
uniform int u_inner_half;        // texels summed one by one around the centre (in each direction)
uniform int u_outer_half;        // cells per direction beyond that
out vec4 f_color;

vec3 lut(float r_mm, float row) {
    float x = clamp(r_mm / u_rmax_mm, 0.0, 1.0);
    float n = float(textureSize(u_lut, 0).x);
    return texture(u_lut, vec2((x * (n - 1.0) + 0.5) / n, row)).rgb;
}

// Texels within +-(k s + s/2) one by one (R(r) x texel area; the centre texel gets the energy inside
// its own area), then cells of s x s texels (s a power of two, sampled from mip level log2 s at the
// cell centre) out to r_max: the far field of a smooth tail at a fraction of the cost.
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(u_src, 0);
    ivec2 last = size - 1;
    vec2 mm = max(texelFetch(u_stretch, p, 0).rg, vec2(TSD_MIN_MM_PER_TEXEL));
    float area = mm.x * mm.y;
    int half_t = int(min(ceil(u_rmax_mm / min(mm.x, mm.y)), float(max(size.x, size.y))));
    // cell size: the smallest power of two keeping the far field within u_outer_half cells
    int s = 1;
    while (half_t > u_outer_half * s) s *= 2;
    int k = s == 1 ? half_t : max((u_inner_half - s / 2) / s, 0);
    int inner = s == 1 ? half_t : k * s + s / 2;          // texels [-inner, inner - (s == 1 ? -1 : 1) + ...]
    int inner_lo = -inner, inner_hi = s == 1 ? inner : inner - 1;
    vec4 c = texelFetch(u_src, p, 0);
    vec3 centre_w = lut(sqrt(area / PI), 0.75);
    vec3 num = centre_w * c.rgb;
    vec3 den = centre_w * c.a;
    for (int j = inner_lo; j <= inner_hi; ++j)
        for (int i = inner_lo; i <= inner_hi; ++i) {
            if (i == 0 && j == 0) continue;
            float r = length(vec2(float(i), float(j)) * mm);
            if (r > u_rmax_mm) continue;
            vec3 w = lut(r, 0.25) * area;
            vec4 t = texelFetch(u_src, clamp(p + ivec2(i, j), ivec2(0), last), 0);
            num += w * t.rgb;
            den += w * t.a;
        }
    if (s > 1) {
        float lod = log2(float(s));
        int n = (half_t + s / 2) / s;
        vec2 texel = 1.0 / vec2(size);
        for (int j = -n; j <= n; ++j)
            for (int i = -n; i <= n; ++i) {
                if (abs(i) <= k && abs(j) <= k) continue;     // inside the one-by-one window
                vec2 off = vec2(float(i * s) - 0.5, float(j * s) - 0.5);   // cell centre, texels
                float r = length(off * mm);
                if (r > u_rmax_mm) continue;
                vec3 w = lut(r, 0.25) * (area * float(s * s));
                vec4 t = textureLod(u_src, (vec2(p) + 0.5 + off) * texel, lod);
                num += w * t.rgb;
                den += w * t.a;
            }
    }
    // the gather reads rgb / a per channel: store the normalised value with a = 1
    vec3 v = vec3(den.r > COVERAGE_EPS ? num.r / den.r : 0.0, den.g > COVERAGE_EPS ? num.g / den.g : 0.0,
                  den.b > COVERAGE_EPS ? num.b / den.b : 0.0);
    f_color = vec4(v, c.a > 0.0 ? 1.0 : 0.0);
}
