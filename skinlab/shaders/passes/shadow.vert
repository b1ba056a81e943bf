#version 330 core
// Depth pass into a light's shadow map. Variant SHADOW_DISTANCE also passes the world position for
// the distance map (translucency through thin parts, passes/tsd_irradiance.frag).
in vec3 in_position;
uniform mat4 u_model;
uniform mat4 u_light_view_proj;
out vec3 v_world;
void main() {
    vec4 w = u_model * vec4(in_position, 1.0);
    v_world = w.xyz;
    gl_Position = u_light_view_proj * w;
}
