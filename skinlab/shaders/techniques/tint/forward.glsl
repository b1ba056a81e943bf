// Subsurface hook of technique "tint": the per-pixel profile tint baseline (no convolution). The
// subsurface part of the diffuse term is the locally scattered light times u_sss_tint (the profile
// at one radius, brightest channel = 1). Contract: skinlab/render/technique.py.
#include "lib/sss_local.glsl"
#include "lib/sss_maps.glsl"

uniform vec3 u_sss_tint;

float sss_plain_weight() { return 1.0 - sss_weight_at(v_uv); }

vec3 sss_radiance(vec3 base, float NoV, float occlusion, vec2 uv) {
    return sss_local_radiance(base, NoV, occlusion, sss_weight_at(v_uv)) * u_sss_tint;
}
