#version 330 core
// Depth pass into a light's shadow map. Variant SHADOW_DISTANCE also passes the world position for
// the distance map (translucency through thin parts, passes/tsd_irradiance.frag); the UV and vertex
// colour are for a masked material's cut-out (shadow.frag ALPHA_MASK).
in vec3 in_position;
in vec2 in_uv;
in vec4 in_color;
uniform mat4 u_model;
uniform mat4 u_light_view_proj;
out vec3 v_world;
out vec2 v_uv;
out vec4 v_color;
void main() {
    vec4 w = u_model * vec4(in_position, 1.0);
    v_world = w.xyz;
    v_uv = in_uv;
    v_color = in_color;
    gl_Position = u_light_view_proj * w;
}
