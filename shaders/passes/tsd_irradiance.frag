#version 330 core
// Texture-space irradiance (d'Eon & Luebke 2007): per texel of the mesh's UV layout, the light that
// enters the surface's multiple scattering - each light times the entry factor at its incidence
// (lib/sss_boundary.glsl: A_ms(mu0) / A_colour), shadows, the normal map, ambient x occlusion
// (pi L_ambient x A_ms_d / A_colour) - times albedo^mix (pre-scatter texturing). a = 1: covered.
// Variant TSD_TRANSLUCENCY: light reaching back faces through thin parts: the exact diffuse
// transmittance of a slab (all orders of scattering) at the light's incidence on the far side
// (lib/sss_boundary.glsl sss_slab_through; the thickness along the light from the shadow pass's
// distance map, times the cosine to the normal: a flat slab's own thickness).
#include "lib/brdf.glsl"
#include "lib/lights.glsl"
#include "lib/sss_boundary.glsl"
#include "skinlab/material.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;

uniform vec3 u_ambient;
uniform float u_tsd_mix;
#ifdef TSD_TRANSLUCENCY
uniform sampler2D u_distance0;            // light-space distance of the first surface (scene units)
uniform sampler2D u_distance1;
uniform vec4 u_light_eye[2];              // slot light position (w = 1) or the direction light travels (w = 0)

// Distance from the light of the first surface it meets on the way to world; false outside the map.
bool first_hit_distance(int slot, vec3 world, out float first) {
    vec4 p = u_shadow_matrix[slot] * vec4(world, 1.0);
    vec2 uv = p.xy / p.w;
    first = 0.0;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return false;
    first = slot == 0 ? texture(u_distance0, uv).r : texture(u_distance1, uv).r;
    return first < 1e29;   // cleared texels: no surface
}

float distance_from_light(int slot, vec3 world) {
    vec4 e = u_light_eye[slot];
    return e.w == 0.0 ? dot(world, e.xyz) : length(world - e.xyz);
}
#endif

out vec4 f_irradiance;

void main() {
    vec3 ng = normalize(v_normal);
    vec3 n = ng;
#ifdef HAS_NORMAL_MAP
    n = perturb_normal(ng, v_tangent, texture(u_normal_map, v_uv).rgb, u_normal_scale);
#endif
    vec3 base = u_base_color;
#ifdef HAS_BASE_COLOR_MAP
    base *= texture(u_base_color_map, v_uv).rgb;
#endif
    float occlusion = 1.0;
#ifdef HAS_OCCLUSION_MAP
    occlusion = texture(u_occlusion_map, v_uv).r;
#endif
    vec3 e_in = vec3(0.0);
    for (int i = 0; i < MAX_LIGHTS; ++i) {
        if (i >= u_num_lights) break;
        vec3 l, e;
        light_incidence(i, v_world, n, l, e);
        float NoL = dot(n, l);
        if (NoL > 0.0) {
            float vis = u_light_shadow[i] >= 0 ? light_visibility(i, v_world, dot(ng, l)) : 1.0;
            e_in += e * (vis * NoL) * sss_entry(NoL);
        }
#ifdef TSD_TRANSLUCENCY
        int slot = u_light_shadow[i];
        float back = -dot(ng, l);
        if (slot >= 0 && back > 0.0) {
            float first;
            if (first_hit_distance(slot, v_world, first)) {
                float d_mm = max(distance_from_light(slot, v_world) - first, 0.0) * u_mm_per_unit * back;
                e_in += e * back * sss_slab_through(back, d_mm);
            }
        }
#endif
    }
    e_in += PI * u_ambient * occlusion * u_sss_entry_diffuse;
    f_irradiance = vec4(e_in * pow(max(base, vec3(0.0)), vec3(u_tsd_mix)), 1.0);
}
