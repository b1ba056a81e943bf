// Shadow-map lookups: 3x3 PCF on a depth-compare sampler (compare '<='), slope-scaled bias.
// NumPy twin: skinlab/scene/optics/shadow.py (exact for NEAREST compare filtering).
#include "skinlab/constants.glsl"

float shadow_pcf(sampler2DShadow map, mat4 shadow_matrix, vec3 world, float NoL) {
    vec4 p = shadow_matrix * vec4(world, 1.0);
    vec3 c = p.xyz / p.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    float cosl = clamp(NoL, 0.05, 1.0);
    float bias = SHADOW_BIAS * (1.0 + 3.0 * sqrt(1.0 - cosl * cosl) / cosl);
    vec2 texel = 1.0 / vec2(textureSize(map, 0));
    float sum = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            sum += texture(map, vec3(c.xy + vec2(x, y) * texel, c.z - bias));
    return sum / 9.0;
}
