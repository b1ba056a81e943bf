#version 330 core
// Principled shading (Burley diffuse + GGX specular) with up to MAX_LIGHTS lights and two
// shadow maps. Variants: HAS_BASE_COLOR_MAP, HAS_ROUGHNESS_MAP, HAS_NORMAL_MAP, HAS_OCCLUSION_MAP;
// TSD_LEVELS = n (1..6): the texture-space diffusion gather (d'Eon & Luebke 2007): the diffuse term
// is the weighted sum of the blurred irradiance levels x albedo^(1-mix) (post-scatter texturing),
// mixed with plain Burley diffuse by u_subsurface; specular and ambient specular as usual.
// SSS_TINT: the per-pixel profile tint baseline (no convolution): the subsurface part of the diffuse
// term is the Burley diffuse times u_sss_tint (the profile at one radius, brightest channel = 1).
// SSSS_SPLIT: screen-space SSS (Jimenez et al.): the subsurface diffuse radiance goes to a second
// target (f_diffuse, a = 1 where it is) for the screen-space blur, the rest to f_color.
#include "lib/brdf.glsl"
#include "lib/lights.glsl"
#include "lib/subsurface.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;

uniform vec3 u_base_color;
uniform float u_roughness;
uniform float u_metallic;
uniform float u_specular;
uniform float u_normal_scale;
uniform float u_subsurface;
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
uniform vec3 u_camera_pos;
uniform vec3 u_ambient;

#ifdef TSD_LEVELS
uniform float u_tsd_mix;
uniform vec3 u_tsd_identity;         // weight of the unblurred irradiance per channel
uniform vec3 u_tsd_w[6];             // weight of each blurred level per channel
uniform sampler2D u_tsd_irradiance;  // premultiplied by coverage: rgb / a
#if TSD_LEVELS > 0
uniform sampler2D u_tsd_level0;
#endif
#if TSD_LEVELS > 1
uniform sampler2D u_tsd_level1;
#endif
#if TSD_LEVELS > 2
uniform sampler2D u_tsd_level2;
#endif
#if TSD_LEVELS > 3
uniform sampler2D u_tsd_level3;
#endif
#if TSD_LEVELS > 4
uniform sampler2D u_tsd_level4;
#endif
#if TSD_LEVELS > 5
uniform sampler2D u_tsd_level5;
#endif

vec3 unpremultiply(vec4 t) { return t.a > COVERAGE_EPS ? t.rgb / t.a : vec3(0.0); }

// Diffused irradiance (still x albedo^mix) at uv: I E + sum_k W_k level_k.
vec3 tsd_diffused(vec2 uv) {
    vec3 d = u_tsd_identity * unpremultiply(texture(u_tsd_irradiance, uv));
#if TSD_LEVELS > 0
    d += u_tsd_w[0] * unpremultiply(texture(u_tsd_level0, uv));
#endif
#if TSD_LEVELS > 1
    d += u_tsd_w[1] * unpremultiply(texture(u_tsd_level1, uv));
#endif
#if TSD_LEVELS > 2
    d += u_tsd_w[2] * unpremultiply(texture(u_tsd_level2, uv));
#endif
#if TSD_LEVELS > 3
    d += u_tsd_w[3] * unpremultiply(texture(u_tsd_level3, uv));
#endif
#if TSD_LEVELS > 4
    d += u_tsd_w[4] * unpremultiply(texture(u_tsd_level4, uv));
#endif
#if TSD_LEVELS > 5
    d += u_tsd_w[5] * unpremultiply(texture(u_tsd_level5, uv));
#endif
    return d;
}
#endif

#ifdef SSS_TINT
uniform vec3 u_sss_tint;
#endif

layout(location = 0) out vec4 f_color;
#ifdef SSSS_SPLIT
uniform float u_ssss_enabled;        // 1 for a material that scatters, 0 otherwise
layout(location = 1) out vec4 f_diffuse;
#endif

void main() {
    vec3 ng = normalize(v_normal);
    vec3 v = normalize(u_camera_pos - v_world);
    if (!gl_FrontFacing) ng = -ng;
    vec3 n = ng;
#ifdef HAS_NORMAL_MAP
    n = perturb_normal(ng, vec4(gl_FrontFacing ? v_tangent.xyz : -v_tangent.xyz, v_tangent.w),
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
#if defined(TSD_LEVELS)
    float plain = 1.0 - u_subsurface;    // weight of the surface's own Burley diffuse
#elif defined(SSS_TINT) || defined(SSSS_SPLIT)
    // the subsurface part uses the same entry/exit model as texture-space diffusion (irradiance
    // through Fresnel transmission, Burley 2015 exit weight): only the convolution differs
#ifdef SSSS_SPLIT
    float sss_w = u_subsurface * u_ssss_enabled;
#else
    float sss_w = u_subsurface;
#endif
    float plain = 1.0 - sss_w;
    vec3 sss_in = vec3(0.0);             // irradiance entering the medium
    float sss_f0 = SPECULAR_F0_SCALE * u_specular;
#else
    float plain = 1.0;
#endif
    vec3 f0 = principled_f0(base, u_metallic, u_specular);
    float a = ggx_alpha(rough);
    float NoV = dot(n, v);
    vec3 color = vec3(0.0);
    for (int i = 0; i < MAX_LIGHTS; ++i) {
        if (i >= u_num_lights) break;
        vec3 l, e;
        light_incidence(i, v_world, n, l, e);
        float NoL = dot(n, l);
        if (NoL <= 0.0) continue;
        float vis = u_light_shadow[i] >= 0 ? light_visibility(i, v_world, dot(ng, l)) : 1.0;
        vec3 h = half_vector(n, v, l);
        float LoH = dot(l, h);
        vec3 diffuse = base * ((1.0 - u_metallic) * plain * burley_diffuse(NoL, NoV, LoH, rough));
        vec3 spec = specular_ggx(NoL, NoV, dot(n, h), LoH, a, f0);
        color += e * vis * (diffuse + spec) * NoL;
#if defined(SSS_TINT) || defined(SSSS_SPLIT)
        sss_in += e * (vis * NoL * fresnel_transmission(sss_f0, NoL));
#endif
    }
    color += u_ambient * occlusion * (base * ((1.0 - u_metallic) * plain) + f0);
#if defined(SSS_TINT) || defined(SSSS_SPLIT)
    sss_in += PI * u_ambient * occlusion;
    vec3 sss_out = base * sss_in * ((1.0 - u_metallic) * sss_w * INV_PI * sss_exit_weight(abs(NoV)));
#ifdef SSS_TINT
    color += sss_out * u_sss_tint;
#else
    f_diffuse = vec4(sss_out, u_ssss_enabled);
#endif
#endif
#ifdef TSD_LEVELS
    // texture-space diffusion: the diffused light leaving toward the viewer (1/pi: Lambertian exit)
    vec3 post = pow(max(base, vec3(0.0)), vec3(1.0 - u_tsd_mix));
    color += (1.0 - u_metallic) * u_subsurface * post * tsd_diffused(v_uv)
             * (INV_PI * sss_exit_weight(abs(NoV)));
#endif
    f_color = vec4(color, 1.0);
}
