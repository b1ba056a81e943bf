// Subsurface hook of technique "disk" (importance-sampled Burley disk SSS, Golubev 2018): the
// subsurface diffuse radiance goes to a second target for the screen-space disk pass, its alpha the
// pixel's profile and radius scale: index + 1 into the frame's profile table (0: not scattering)
// plus half the radius map's scale (0..1.98) as the fraction. Every mesh uses
// this hook while the technique runs, so the second target is written everywhere.
// Contract: skinlab/render/technique.py.
#include "lib/sss_local.glsl"
#include "lib/sss_maps.glsl"

uniform float u_disk_profile;  // profile index + 1, 0 for a material that does not scatter
layout(location = 1) out vec4 f_diffuse;

float sss_plain_weight() { return u_disk_profile > 0.0 ? 1.0 - sss_weight_at(v_uv) : 1.0; }

vec3 sss_radiance(vec3 base, float NoV, float occlusion, vec2 uv) {
    float w = u_disk_profile > 0.0 ? sss_weight_at(v_uv) : 0.0;
    float scale = u_disk_profile > 0.0 ? 0.5 * clamp(sss_radius_scale_at(uv), 0.0, 1.98) : 0.0;
    f_diffuse = vec4(sss_local_radiance(base, NoV, occlusion, w), u_disk_profile + scale);
    return vec3(0.0);
}
