// Shadow-map lookups: 3x3 PCF on a depth-compare sampler (compare '<='), with a depth bias sized to
// the map's texel at the receiver (skinlab/scene/optics/constants.py SHADOW_BIAS_TEXELS, ...): a
// constant in normalised depth was far too large at close range and grazing light (light through
// the nose's shadow on the cheek) and too small on a scene many times larger.
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
