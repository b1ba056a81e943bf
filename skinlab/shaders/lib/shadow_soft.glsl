// Soft shadows of lights with a size (percentage-closer soft shadows, Fernando 2005; sources:
// docs/references.md#soft-shadows): a directional light of angular radius theta (a source of an
// environment map), a sphere or rect light of radius R. A blocker search (8 taps) in the slot's distance map
// (passes/shadow.frag SHADOW_DISTANCE: each texel's first surface, scene units from the light) over
// the widest penumbra the scene allows finds the mean distance d_b of what lies between; the penumbra
// at the receiver (distance d_r) is 2 tan(theta) (d_r - d_b) for a directional light, 2 R (d_r - d_b) / d_b
// for a local one; the shadow map is then filtered over that width (12 PCF taps on a Vogel disk, each the
// depth-compare sampler's own). Fully lit where the search finds no blocker; at least the 3 x 3 PCF's
// width. NumPy twin: skinlab/scene/optics/shadow.py shadow_soft (exact for NEAREST compare filtering).
#include "skinlab/constants.glsl"
#include "lib/shadow.glsl"  // shadow_bias

#define SOFT_SEARCH_TAPS 8   // blocker search taps
#define SOFT_TAPS 12          // filter taps
#define SOFT_SEARCH_TEXELS 96.0  // the blocker search spans at most this radius (texels)

// Tap k of n on a Vogel (golden-angle) disk of radius 1.
vec2 vogel_tap(int k, int n) {
    float r = sqrt((float(k) + 0.5) / float(n));
    float a = float(k) * 2.399963229728653;
    return r * vec2(cos(a), sin(a));
}

// soft: x the light's size (tan theta, or R in scene units), y 0 directional / 1 local, z uv per scene
// unit (directional) or at unit distance (local), w the scene's diameter (scene units). eye: the
// light's position (w = 1) or the direction its light travels (w = 0). spread2: a receiver's own
// footprint, the squared radius (uv) of the disk its filter grows by in quadrature (0: a point;
// shadow_soft_area).
float shadow_soft_spread(sampler2DShadow map, sampler2D dist, mat4 m, vec4 soft, vec4 eye, vec3 world, float NoL, float spread2) {
    vec4 p = m * vec4(world, 1.0);
    vec3 c = p.xyz / p.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    float d_r = eye.w == 0.0 ? dot(world, eye.xyz) : length(world - eye.xyz);
    bool local = soft.y > 0.5;
    float k = local ? soft.z / max(d_r, 1e-20) : soft.z;  // uv per scene unit at the receiver
    vec2 size = vec2(textureSize(map, 0));
    float texel = 1.0 / size.x;
    // the widest penumbra: a blocker as near the light as the scene allows
    float nearest = local ? max(d_r - soft.w, 0.05 * d_r) : d_r - soft.w;
    float widest = local ? 2.0 * soft.x * (d_r - nearest) / nearest : 2.0 * soft.x * soft.w;
    float search = max(clamp(0.5 * widest * k, texel, SOFT_SEARCH_TEXELS * texel), sqrt(spread2));
    float bias = 2.0 * texel / k;  // scene units: two texels
    float sum = 0.0;
    float n = 0.0;
    for (int t = 0; t < SOFT_SEARCH_TAPS; ++t) {
        float d = texture(dist, c.xy + vogel_tap(t, SOFT_SEARCH_TAPS) * search).r;
        if (d < d_r - bias) {
            sum += d;
            n += 1.0;
        }
    }
    if (n == 0.0) return 1.0;
    float d_b = sum / n;
    float w = local ? 2.0 * soft.x * (d_r - d_b) / max(d_b, 1e-20) : 2.0 * soft.x * (d_r - d_b);
    float radius = max(0.5 * w * k, 1.5 * texel);
    radius = sqrt(radius * radius + spread2);
    // lib/shadow.glsl's bias, sized to the texel at the receiver, grown with the filter's reach: a tap
    // `radius` away on a sloped receiver sees its own surface that much nearer the light
    float zbias = shadow_bias(m, p, size, NoL) * max(1.0, radius / (1.5 * texel));
    float lit = 0.0;
    for (int t = 0; t < SOFT_TAPS; ++t)
        lit += texture(map, vec3(c.xy + vogel_tap(t, SOFT_TAPS) * radius, c.z - zbias));
    return lit / float(SOFT_TAPS);
}

float shadow_soft(sampler2DShadow map, sampler2D dist, mat4 m, vec4 soft, vec4 eye, vec3 world, float NoL) {
    return shadow_soft_spread(map, dist, m, soft, eye, world, NoL, 0.0);
}

// shadow_soft averaged over a receiver's footprint, the parallelogram spanned by the world vectors du
// and dv centred on world (a texture-space texel's; the hard shadow's lib/shadow.glsl
// shadow_pcf_area): the filter's disk grows in quadrature by the disk with the footprint's second
// moments, r^2 = (|a|^2 + |b|^2) / 6 for the footprint's sides a, b in the map (a box of sides a, b
// has variance (|a|^2 + |b|^2) / 12 summed over two axes, a disk of radius r r^2 / 2), so a penumbra
// narrower than the texel is not sampled at one point per texel (the shadow's edge aliased to the
// texel grid) and a wide one is hardly changed.
float shadow_soft_area(sampler2DShadow map, sampler2D dist, mat4 m, vec4 soft, vec4 eye, vec3 world, float NoL, vec3 du, vec3 dv) {
    vec4 p = m * vec4(world, 1.0);
    vec4 pa = m * vec4(world + du, 1.0);
    vec4 pb = m * vec4(world + dv, 1.0);
    vec2 a = pa.xy / pa.w - p.xy / p.w;
    vec2 b = pb.xy / pb.w - p.xy / p.w;
    return shadow_soft_spread(map, dist, m, soft, eye, world, NoL, (dot(a, a) + dot(b, b)) / 6.0);
}
