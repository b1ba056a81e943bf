// Brute-force texture-space convolution with the exact radial profile at one texel (the image reference
// for the realtime techniques; slow on purpose), shared by techniques/exact/gather.frag and
// techniques/exact/gather.comp (RenderSettings.compute). Every texel within r_max (from a table of R(r)) contributes
// R(r) x its area; the centre cell contributes the profile's energy inside its own area (the
// cumulative table E, so a profile singular at r = 0 is integrated, not sampled). Distances use this
// texel's stretch (mm per texel along u, v). Coverage-normalised like the Gaussian blurs.
// Tables: skinlab/scene/optics/exact_profile.py exact_profile_lut; NumPy counterpart: exact_profile_convolution there.
#include "skinlab/constants.glsl"
uniform sampler2D u_src;         // premultiplied irradiance (rgb E a, a), with mipmaps
uniform sampler2D u_stretch;
uniform sampler2D u_lut;         // row 0: R(r) per channel (normalised), row 1: E(r); r = x * r_max
uniform float u_rmax_mm;
uniform int u_inner_half;        // texels summed one by one around the centre (in each direction)
uniform float u_ring_ratio;      // far field: outer / inner radius of each annulus

vec3 lut(float r_mm, float row) {
    float x = clamp(r_mm / u_rmax_mm, 0.0, 1.0);
    float n = float(textureSize(u_lut, 0).x);
    return textureLod(u_lut, vec2((x * (n - 1.0) + 0.5) / n, row), 0.0).rgb;
}

// Near field: every texel within u_inner_half texels one by one (R(r) x texel area; the centre
// texel gets the profile's energy inside its own area, E). Far field, out to r_max: annuli in
// millimetres growing geometrically (ratio u_ring_ratio), each cut into cells about as long as the
// annulus is wide; a cell weighs R(r) x its exact area (r dr dtheta) and reads the irradiance
// box-filtered over its size (mip level log2 of its width in texels). The annuli tile the plane
// exactly, so the quadrature converges as the texture grows (a square cell grid did not).
vec4 exact_gather_at(ivec2 p) {
    ivec2 size = textureSize(u_src, 0);
    ivec2 last = size - 1;
    vec2 mm = max(texelFetch(u_stretch, p, 0).rg, vec2(TSD_MIN_MM_PER_TEXEL));
    float area = mm.x * mm.y;
    float r_in = min(float(u_inner_half) * min(mm.x, mm.y), u_rmax_mm);
    ivec2 n = ivec2(min(ceil(vec2(r_in) / mm), vec2(float(u_inner_half))));
    vec4 c = texelFetch(u_src, p, 0);
    vec3 centre_w = lut(sqrt(area / PI), 0.75);
    vec3 num = centre_w * c.rgb;
    vec3 den = centre_w * c.a;
    for (int j = -n.y; j <= n.y; ++j)
        for (int i = -n.x; i <= n.x; ++i) {
            if (i == 0 && j == 0) continue;
            float r = length(vec2(float(i), float(j)) * mm);
            if (r > r_in) continue;
            vec3 w = lut(r, 0.25) * area;
            vec4 t = texelFetch(u_src, clamp(p + ivec2(i, j), ivec2(0), last), 0);
            num += w * t.rgb;
            den += w * t.a;
        }
    vec2 texel = 1.0 / vec2(size);
    float r0 = r_in;
    for (int ring = 0; ring < 256; ++ring) {
        if (r0 >= u_rmax_mm) break;
        float r1 = min(r0 * u_ring_ratio, u_rmax_mm);
        float rm = 0.5 * (r0 + r1);
        float dr = r1 - r0;
        int cells = max(8, int(ceil(2.0 * PI * rm / dr)));
        float dtheta = 2.0 * PI / float(cells);
        vec3 w = lut(rm, 0.25) * (rm * dr * dtheta);
        float lod = log2(max(dr / min(mm.x, mm.y), 1.0));
        for (int k = 0; k < 4096; ++k) {
            if (k >= cells) break;
            float th = (float(k) + 0.5) * dtheta;
            vec2 off = rm * vec2(cos(th), sin(th)) / mm;          // texels
            vec4 t = textureLod(u_src, (vec2(p) + 0.5 + off) * texel, lod);
            num += w * t.rgb;
            den += w * t.a;
        }
        r0 = r1;
    }
    // the gather reads rgb / a per channel: store the normalised value with a = 1
    vec3 v = vec3(den.r > COVERAGE_EPS ? num.r / den.r : 0.0, den.g > COVERAGE_EPS ? num.g / den.g : 0.0,
                  den.b > COVERAGE_EPS ? num.b / den.b : 0.0);
    return vec4(v, c.a > 0.0 ? 1.0 : 0.0);
}
