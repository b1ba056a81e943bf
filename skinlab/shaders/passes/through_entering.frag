#version 330 core
// Light through thin parts as a transfer through the medium (skinlab/render/through_kernel.py; NumPy
// twin skinlab/scene/optics/through_kernel.py): the irradiance entering a mesh vertex, the senders'
// side. Each light at the vertex's cosine with its shadow, times what its cosine changes of the light
// through the part's thickness there (the slab transmittance at it over that at normal incidence: the
// transfer's weights are for light entering along the normal), and where a shadow-casting light is
// hidden, what reaches the vertex through the matter in front of it (the distance maps' slab,
// lib/sss_translucency.glsl: a part lit through another part in front of it, at the vertex's
// cosine). Drawn fullscreen over the vertex-space target once per mesh, the vertex read from the
// mesh's vertex texture (u_vertex_data: vertex j at texels (3 (j % 1024) + k, j / 1024), k = 0
// position, 1 normal, 2 uv; skinlab/render/vertex_space.py), as passes/bounce_exitance.frag. Alpha: the green light entering times its
// cosine, so that the transfer gives each vertex its light's mean incidence (the exit factor of light
// that came through depends on it: lib/sss_boundary.glsl sss_slab_exit).
#include "lib/brdf.glsl"
#include "lib/lights.glsl"
#include "lib/sss_translucency.glsl"

uniform sampler2D u_vertex_data;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform int u_vertex_offset;
uniform int u_vertex_count;
uniform ivec2 u_target_size;
uniform sampler2D u_row_index;  // per vertex: (first entry, entries, its depth in mm: the part's thickness here)

out vec4 f_entering;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int j = t.y * u_target_size.x + t.x - u_vertex_offset;
    if (j < 0 || j >= u_vertex_count) discard;
    ivec2 d = ivec2(3 * (j % 1024), j / 1024);
    vec3 world = (u_model * vec4(texelFetch(u_vertex_data, d, 0).xyz, 1.0)).xyz;
    vec3 nv = u_normal_matrix * texelFetch(u_vertex_data, d + ivec2(1, 0), 0).xyz;
    if (dot(nv, nv) == 0.0) {  // a vertex without a normal (no triangle uses it) takes in nothing
        f_entering = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec3 n = normalize(nv);
    vec3 e = vec3(0.0);
    float e_cos = 0.0;  // the green light entering x its cosine: the light's mean incidence (its exit factor)
    // the transfer's weights carry light entering along the normal; light entering at cosine c goes
    // less deep (lib/sss_boundary.glsl sss_slab_through), by its ratio through the part's own thickness
    float depth = texelFetch(u_row_index, t, 0).b;  // the row index has the target's layout
    for (int i = 0; i < MAX_LIGHTS; ++i) {
        if (i >= u_num_lights) break;
        vec3 l, li;
        light_incidence(i, world, n, l, li);
        float NoL = dot(n, l);
        if (NoL <= 0.0) continue;
        int slot = u_light_shadow[i];
        float vis = slot >= 0 ? light_visibility(i, world, NoL) : 1.0;
        vec3 through = vec3(0.0);
        float d_mm;
        if (slot >= 0 && vis < 1.0 && sss_thickness_mm(slot, world, n, NoL, d_mm)) through = sss_through(NoL, d_mm);
        vec3 in_i = li * NoL * (vis + (1.0 - vis) * through) * sss_through_incidence(NoL, depth);
        e += in_i;
        e_cos += in_i.g * NoL;
    }
    f_entering = vec4(e, e_cos);
}
