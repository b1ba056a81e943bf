#version 330 core
// Interreflection (skinlab/render/bounce.py): one point per mesh vertex, drawn at that vertex's texel of
// the vertex-space target (vertex i of the frame's meshes at texel (i % width, i / width)), with its
// world position, normal and UV for bounce_exitance.frag.
in vec3 in_position;
in vec3 in_normal;
in vec2 in_uv;
#include "lib/sky_vertex.glsl"
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform int u_vertex_offset;   // this mesh's first vertex in the target
uniform ivec2 u_target_size;
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
void main() {
    int i = u_vertex_offset + gl_VertexID;
    v_world = (u_model * vec4(in_position, 1.0)).xyz;
    v_normal = u_normal_matrix * in_normal;
    v_uv = in_uv;
    vec2 texel = vec2(i % u_target_size.x, i / u_target_size.x) + 0.5;
    gl_Position = vec4(texel / vec2(u_target_size) * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 1.0;
    sky_vertex();
}
