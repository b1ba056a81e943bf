// Subsurface hook of technique "tint": the per-pixel profile tint baseline (no convolution). The
// subsurface part of the diffuse term is the locally scattered light times u_sss_tint (the profile
// at one radius, brightest channel = 1). Contract: skinlab/render/technique.py.
#include "lib/sss_local.glsl"

uniform vec3 u_sss_tint;

float sss_plain_weight(Surface s) { return 1.0 - s.sss_weight; }

vec3 sss_radiance(Surface s) {
    return sss_local_radiance(s, s.sss_weight) * u_sss_tint;
}
