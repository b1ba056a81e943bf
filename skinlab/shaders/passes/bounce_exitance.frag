#version 330 core
// Interreflection, one order (skinlab/render/bounce.py; NumPy twin skinlab/scene/interreflection.py): the
// radiant exitance of a mesh vertex, M = sender albedo x (the lights with their shadows + the sky
// + the environment map, variant ENV_MAP + the previous order's bounce light). The colour map is read at the mip level whose texel spans
// about one vertex's share of the UV area (a vertex stands for the surface around it).
// Drawn fullscreen over the vertex-space target (vertex i of the frame's meshes at texel
// (i % width, i / width)), once per mesh: a texel outside the mesh's vertices is left as it is; the
// vertex's position, normal and UV are read from the mesh's vertex texture (u_vertex_data: vertex j
// at texels (3 (j % 1024) + k, j / 1024), k = 0 position, 1 normal, 2 uv), so every texel of a block
// is a vertex (one point per vertex left a software rasteriser shading a block for each).
#define VERTEX_TEXELS 1
#include "lib/brdf.glsl"
#include "lib/lights.glsl"
#include "lib/bounce.glsl"
uniform float u_albedo_lod;           // mip level of the colour map for one vertex's area
#define MATERIAL_LOD u_albedo_lod      // the maps read at it (lib/material_sample.glsl)
#include "lib/material_sample.glsl"

#ifdef ENV_MAP
#include "lib/sky_occlusion.glsl"
#ifdef SKY_OCCLUSION
#include "lib/sky_blocked.glsl"
#endif
#endif

uniform sampler2D u_vertex_data;  // this mesh's vertices (above)
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform int u_vertex_offset;      // this mesh's first vertex in the target
uniform int u_vertex_count;       // its vertices
uniform ivec2 u_target_size;      // the vertex-space target's
vec3 v_world;
vec3 v_normal;
vec2 v_uv;

uniform vec3 u_ambient;
uniform sampler2D u_bounce_previous;  // the previous order's irradiance per vertex
uniform int u_has_previous;           // 0 for the first order

out vec4 f_exitance;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int j = t.y * u_target_size.x + t.x - u_vertex_offset;  // this mesh's vertex
    if (j < 0 || j >= u_vertex_count) discard;
    ivec2 d = ivec2(3 * (j % 1024), j / 1024);
    v_world = (u_model * vec4(texelFetch(u_vertex_data, d, 0).xyz, 1.0)).xyz;
    v_normal = u_normal_matrix * texelFetch(u_vertex_data, d + ivec2(1, 0), 0).xyz;
    v_uv = texelFetch(u_vertex_data, d + ivec2(2, 0), 0).xy;
#if defined(ENV_MAP) && defined(SKY_OCCLUSION)
    sky_blocked_fetch(j, v_sky);
#endif
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
    if (u_has_previous != 0) e += texelFetch(u_bounce_previous, t, 0).rgb;
    f_exitance = vec4(bounce_sender_albedo(base, u_metallic, u_specular) * e, 1.0);
}
