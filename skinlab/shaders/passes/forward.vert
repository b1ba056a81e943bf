#version 330 core
// Mesh vertices to world space for shading; UV and tangent frame for maps.
in vec3 in_position;
in vec3 in_normal;
in vec2 in_uv;
in vec4 in_tangent;
in float in_curvature;  // pre-integrated skin's vertex stream (1/scene unit); 0 in frames of other techniques
in vec4 in_color;       // the vertex colour (glTF COLOR_0, linear; 1 where the mesh has none)
#include "lib/bounce_vertex.glsl"
#include "lib/through_vertex.glsl"
#include "lib/sky_vertex.glsl"
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_proj;
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_tangent;
out float v_curvature;
out vec4 v_color;
void main() {
    vec4 w = u_model * vec4(in_position, 1.0);
    v_world = w.xyz;
    v_normal = u_normal_matrix * in_normal;
    v_tangent = vec4(mat3(u_model) * in_tangent.xyz, in_tangent.w);
    v_uv = in_uv;
    v_curvature = in_curvature;
    v_color = in_color;
    bounce_vertex();
    through_vertex();
    sky_vertex();
    gl_Position = u_view_proj * w;
}
