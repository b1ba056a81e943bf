// Shadow-map lookups: 3x3 PCF on a depth-compare sampler (compare '<='), with a depth bias sized to
// the map's texel at the receiver (skinlab/scene/optics/constants.py SHADOW_BIAS_TEXELS, ...): a
// constant in normalised depth was far too large at close range and grazing light (light through
// the nose's shadow on the cheek) and too small on a scene many times larger.
// shadow_pcf_area: the same lookup averaged over a receiver's footprint wider than the 3x3 PCF (a
// texture-space texel's: techniques/tsd/irradiance.frag).
// NumPy twin: skinlab/scene/optics/shadow.py (exact for NEAREST compare filtering).
#include "skinlab/constants.glsl"

// At p = shadow_matrix * (world, 1): x, the side of the map's texel there in world units (the larger
// of its two sides); y, texture depth per world unit along the light. From the matrix's rows: exact
// for an orthographic map, the local scale of a perspective one (d(a / w) = (da - (a / w) dw) / w).
vec2 shadow_texel_scale(mat4 m, vec4 p, vec2 size) {
    vec3 r0 = vec3(m[0][0], m[1][0], m[2][0]);
    vec3 r1 = vec3(m[0][1], m[1][1], m[2][1]);
    vec3 r2 = vec3(m[0][2], m[1][2], m[2][2]);
    vec3 r3 = vec3(m[0][3], m[1][3], m[2][3]);
    vec3 c = p.xyz / p.w;
    float w = abs(p.w);
    float per_unit = min(length(r0 - c.x * r3) * size.x, length(r1 - c.y * r3) * size.y) / w;  // texels
    return vec2(1.0 / max(per_unit, 1e-30), length(r2 - c.z * r3) / w);
}

// Depth bias (texture depth units) for a receiver whose geometric normal makes cosine NoL with the
// light: texel x (SHADOW_BIAS_TEXELS + SHADOW_SLOPE_TEXELS x min(tan theta, SHADOW_SLOPE_MAX)).
float shadow_bias(mat4 m, vec4 p, vec2 size, float NoL) {
    float cosl = clamp(NoL, 1e-3, 1.0);
    float slope = min(sqrt(1.0 - cosl * cosl) / cosl, SHADOW_SLOPE_MAX);
    vec2 s = shadow_texel_scale(m, p, size);
    return s.x * s.y * (SHADOW_BIAS_TEXELS + SHADOW_SLOPE_TEXELS * slope);
}

float shadow_pcf(sampler2DShadow map, mat4 shadow_matrix, vec3 world, float NoL) {
    vec4 p = shadow_matrix * vec4(world, 1.0);
    vec3 c = p.xyz / p.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    vec2 size = vec2(textureSize(map, 0));
    float bias = shadow_bias(shadow_matrix, p, size, NoL);
#ifdef MEASURE_PCF_1TAP  // a measurement variant (tools/irradiance_cost.py): one compare, no filter
    return texture(map, vec3(c.xy, c.z - bias));
#else
    vec2 texel = 1.0 / size;
    float sum = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            sum += texture(map, vec3(c.xy + vec2(x, y) * texel, c.z - bias));
    return sum / 9.0;
#endif
}

// The visibility averaged over a receiver's footprint: the parallelogram spanned by the world vectors
// du and dv centred on world (a texture-space texel's, one texel along u and along v). A texel's
// irradiance is then its square's mean, as the gather's bilinear reading of it needs for the light in
// the texture to be the light on the surface; one point's visibility (the 3x3 PCF, a few shadow-map
// texels wide) aliases a shadow's edge to the texel grid, which a straight edge along the grid
// (a slit of light along u or v) turns into up to half a texel of light too much or too little per
// edge (docs/ground-truth.md "Close-ups": +8 % on marble's 2 mm slit at 0.8 mm per texel). The
// footprint projected into the map spans e_a x e_b texels; where both are at most 3 (the 3x3 PCF's
// width), shadow_pcf as it is; else ceil(e) taps along each side (at most SHADOW_AREA_TAPS), their
// depths on the footprint's plane (exact on a flat receiver), the bias as shadow_pcf's.
const int AREA_TAPS = int(SHADOW_AREA_TAPS);
float shadow_pcf_area(sampler2DShadow map, mat4 m, vec3 world, float NoL, vec3 du, vec3 dv) {
    vec4 p = m * vec4(world, 1.0);
    vec3 c = p.xyz / p.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    vec2 size = vec2(textureSize(map, 0));
    vec4 pa = m * vec4(world + du, 1.0);
    vec4 pb = m * vec4(world + dv, 1.0);
    vec3 a = pa.xyz / pa.w - c;
    vec3 b = pb.xyz / pb.w - c;
    float ea = length(a.xy * size);
    float eb = length(b.xy * size);
    if (max(ea, eb) <= SHADOW_AREA_MIN_TEXELS) return shadow_pcf(map, m, world, NoL);
    int na = clamp(int(ceil(ea)), 1, AREA_TAPS);
    int nb = clamp(int(ceil(eb)), 1, AREA_TAPS);
    float bias = shadow_bias(m, p, size, NoL);
    float sum = 0.0;
    for (int j = 0; j < AREA_TAPS; ++j) {
        if (j >= nb) break;
        vec3 row = c + ((float(j) + 0.5) / float(nb) - 0.5) * b;
        for (int i = 0; i < AREA_TAPS; ++i) {
            if (i >= na) break;
            vec3 q = row + ((float(i) + 0.5) / float(na) - 0.5) * a;
            sum += texture(map, vec3(q.xy, q.z - bias));
        }
    }
    return sum / float(na * nb);
}
