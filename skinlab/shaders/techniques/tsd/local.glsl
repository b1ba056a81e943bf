// Subsurface hook of techniques "tsd" and "exact" for a mesh whose profile is narrower than a texel
// (the planner's fallback, skinlab/render/techniques/tsd/plan.py): no blur, but the same boundary as the
// blurred case - each light enters with the multiple-scattering albedo at its incidence and leaves
// with the exit distribution (lib/sss_local.glsl), single scattering is added by the forward pass -
// mixed with plain Burley diffuse by the subsurface weight (x its map). Contract:
// skinlab/render/technique.py.
#include "lib/sss_local.glsl"

float sss_plain_weight(Surface s) { return 1.0 - s.sss_weight; }

vec3 sss_radiance(Surface s) {
    return sss_local_radiance(s, s.sss_weight);
}
