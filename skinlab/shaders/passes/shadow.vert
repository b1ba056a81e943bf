#version 330 core
// Depth pass into a light's shadow map. Variant SHADOW_DISTANCE also passes the world position for
// the distance map (translucency through thin parts, lib/sss_translucency.glsl), and the world
// normal for its layers (SHADOW_LAYER: which surfaces face the light); the UV and vertex colour are
// for a masked material's cut-out (shadow.frag ALPHA_MASK).
in vec3 in_position;
in vec2 in_uv;
in vec4 in_color;
uniform mat4 u_model;
uniform mat4 u_light_view_proj;
out vec3 v_world;
out vec2 v_uv;
out vec4 v_color;
#ifdef SHADOW_LAYER
in vec3 in_normal;
uniform mat3 u_normal_matrix;
out vec3 v_normal;
#endif
void main() {
    vec4 w = u_model * vec4(in_position, 1.0);
    v_world = w.xyz;
    v_uv = in_uv;
    v_color = in_color;
#ifdef SHADOW_LAYER
    v_normal = u_normal_matrix * in_normal;
#endif
    gl_Position = u_light_view_proj * w;
}
