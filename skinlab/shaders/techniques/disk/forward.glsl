// Subsurface hook of technique "disk" (importance-sampled Burley disk SSS, Golubev 2018): the
// subsurface diffuse radiance goes to a second target for the screen-space disk pass, its alpha the
// pixel's profile and radius scale: index + 1 into the frame's profile table (0: not scattering)
// plus half the radius map's scale (0..1.98) as the fraction. Every mesh uses
// this hook while the technique runs, so the second target is written everywhere.
// Contract: skinlab/render/technique.py.
#include "lib/sss_local.glsl"

uniform float u_disk_profile;  // profile index + 1, 0 for a material that does not scatter
layout(location = 1) out vec4 f_diffuse;

float sss_plain_weight(Surface s) { return u_disk_profile > 0.0 ? 1.0 - s.sss_weight : 1.0; }

vec3 sss_radiance(Surface s) {
    float w = u_disk_profile > 0.0 ? s.sss_weight : 0.0;
    float scale = u_disk_profile > 0.0 ? 0.5 * clamp(s.sss_radius_scale, 0.0, 1.98) : 0.0;
    f_diffuse = vec4(sss_local_radiance(s, w), u_disk_profile + scale);
    return vec3(0.0);
}
