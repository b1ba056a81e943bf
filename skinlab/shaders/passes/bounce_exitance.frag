#version 330 core
// Interreflection, one order (skinlab/render/bounce.py; NumPy twin skinlab/scene/interreflection.py): the
// radiant exitance of a mesh vertex, M = sender albedo x (the lights with their shadows + the sky
// + the environment map, variant ENV_MAP + the previous order's bounce light). The colour map is read at the mip level whose texel spans
// about one vertex's share of the UV area (a vertex stands for the surface around it).
#include "lib/brdf.glsl"
#include "lib/lights.glsl"
#include "lib/bounce.glsl"
uniform float u_albedo_lod;           // mip level of the colour map for one vertex's area
#define MATERIAL_LOD u_albedo_lod      // the maps read at it (lib/material_sample.glsl)
#include "lib/material_sample.glsl"

#ifdef ENV_MAP
#include "lib/sky_occlusion.glsl"
#endif

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;

uniform vec3 u_ambient;
uniform sampler2D u_bounce_previous;  // the previous order's irradiance per vertex
uniform int u_has_previous;           // 0 for the first order

out vec4 f_exitance;

void main() {
    if (dot(v_normal, v_normal) == 0.0) {  // a vertex without a normal (no triangle uses it) sends nothing
        f_exitance = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec3 n = normalize(v_normal);
    // the diffuse albedo seen: the plain part's base colour and the scattering part's subsurface
    // colour, by the subsurface weight, both x the colour map (the colour rule, docs/scenes.md)
    // (the bounce pass carries no vertex colour: 1)
    MaterialSample m = material_sample(v_uv, vec4(1.0));
    vec3 base = mix(m.base, m.sss_albedo, clamp(u_subsurface, 0.0, 1.0));
    vec3 e = PI * u_ambient;
#ifdef ENV_MAP
    e += env_diffuse_irradiance(n);  // the environment map, less what the scene hides of it here
#endif
    for (int i = 0; i < MAX_LIGHTS; ++i) {
        if (i >= u_num_lights) break;
        vec3 l, li;
        light_incidence(i, v_world, n, l, li);
        float NoL = dot(n, l);
        if (NoL <= 0.0) continue;
        float vis = u_light_shadow[i] >= 0 ? light_visibility(i, v_world, NoL) : 1.0;
        e += li * (vis * NoL);
    }
    if (u_has_previous != 0) e += texelFetch(u_bounce_previous, ivec2(gl_FragCoord.xy), 0).rgb;
    f_exitance = vec4(bounce_sender_albedo(base, u_metallic, u_specular) * e, 1.0);
}
