#version 330 core
// Principled shading (Burley diffuse + GGX specular) with up to MAX_LIGHTS lights and two
// shadow maps. Variants: HAS_BASE_COLOR_MAP, HAS_ROUGHNESS_MAP, HAS_NORMAL_MAP, HAS_OCCLUSION_MAP.
#include "lib/brdf.glsl"
#include "lib/lighting.glsl"
#include "lib/shadow.glsl"

#ifndef MAX_LIGHTS
#define MAX_LIGHTS 4
#endif

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;

uniform vec3 u_base_color;
uniform float u_roughness;
uniform float u_metallic;
uniform float u_specular;
uniform float u_normal_scale;
#ifdef HAS_BASE_COLOR_MAP
uniform sampler2D u_base_color_map;
#endif
#ifdef HAS_ROUGHNESS_MAP
uniform sampler2D u_roughness_map;
#endif
#ifdef HAS_NORMAL_MAP
uniform sampler2D u_normal_map;
#endif
#ifdef HAS_OCCLUSION_MAP
uniform sampler2D u_occlusion_map;
#endif

uniform int u_num_lights;
uniform vec4 u_light_vec[MAX_LIGHTS];        // w = 0: direction to the light; w = 1: position
uniform vec3 u_light_radiance[MAX_LIGHTS];   // colour * intensity
uniform int u_light_shadow[MAX_LIGHTS];      // shadow slot, or -1
uniform sampler2DShadow u_shadow0;
uniform sampler2DShadow u_shadow1;
uniform mat4 u_shadow_matrix[2];
uniform vec3 u_camera_pos;
uniform vec3 u_ambient;
uniform float u_mm_per_unit;

out vec4 f_color;

float shadow_slot(int slot, vec3 world, float NoL) {
    if (slot == 0) return shadow_pcf(u_shadow0, u_shadow_matrix[0], world, NoL);
    if (slot == 1) return shadow_pcf(u_shadow1, u_shadow_matrix[1], world, NoL);
    return 1.0;
}

void main() {
    vec3 n = normalize(v_normal);
    vec3 v = normalize(u_camera_pos - v_world);
    if (!gl_FrontFacing) n = -n;
#ifdef HAS_NORMAL_MAP
    n = perturb_normal(n, vec4(gl_FrontFacing ? v_tangent.xyz : -v_tangent.xyz, v_tangent.w),
                       texture(u_normal_map, v_uv).rgb, u_normal_scale);
#endif
    vec3 base = u_base_color;
#ifdef HAS_BASE_COLOR_MAP
    base *= texture(u_base_color_map, v_uv).rgb;
#endif
    float rough = u_roughness;
#ifdef HAS_ROUGHNESS_MAP
    rough *= texture(u_roughness_map, v_uv).r;
#endif
    float occlusion = 1.0;
#ifdef HAS_OCCLUSION_MAP
    occlusion = texture(u_occlusion_map, v_uv).r;
#endif
    vec3 color = vec3(0.0);
    for (int i = 0; i < MAX_LIGHTS; ++i) {
        if (i >= u_num_lights) break;
        vec3 l;
        vec3 e = u_light_radiance[i];
        if (u_light_vec[i].w == 0.0) {
            l = u_light_vec[i].xyz;
        } else {
            vec3 d = u_light_vec[i].xyz - v_world;
            float dist = length(d);
            l = dist > 0.0 ? d / dist : n;
            e *= inverse_square(dist * u_mm_per_unit);
        }
        float NoL = dot(n, l);
        if (NoL <= 0.0) continue;
        float vis = u_light_shadow[i] >= 0 ? shadow_slot(u_light_shadow[i], v_world, dot(normalize(v_normal), l)) : 1.0;
        color += e * vis * principled_brdf_cos(n, v, l, base, rough, u_metallic, u_specular);
    }
    vec3 f0 = principled_f0(base, u_metallic, u_specular);
    color += u_ambient * occlusion * (base * (1.0 - u_metallic) + f0);
    f_color = vec4(color, 1.0);
}
