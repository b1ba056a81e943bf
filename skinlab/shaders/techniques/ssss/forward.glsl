// Subsurface hook of technique "ssss" (screen-space separable SSS, Jimenez et al.): the subsurface
// diffuse radiance goes to a second target (f_diffuse, a = the material's profile index + 1, 0 where
// nothing scatters) for the screen-space blur, the rest to f_color. Every mesh uses this hook while
// the technique runs, so the second target is written everywhere. Contract: skinlab/render/technique.py.
#include "lib/sss_local.glsl"

uniform float u_ssss_profile;  // profile index + 1 for a material that scatters, 0 otherwise
layout(location = 1) out vec4 f_diffuse;

float ssss_enabled() { return u_ssss_profile > 0.0 ? 1.0 : 0.0; }

float sss_plain_weight(Surface s) { return 1.0 - s.sss_weight * ssss_enabled(); }

vec3 sss_radiance(Surface s) {
    f_diffuse = vec4(sss_local_radiance(s, s.sss_weight * ssss_enabled()), u_ssss_profile);
    return vec3(0.0);
}
