#version 330 core
// Depth-only pass into a light's shadow map.
in vec3 in_position;
uniform mat4 u_model;
uniform mat4 u_light_view_proj;
void main() {
    gl_Position = u_light_view_proj * (u_model * vec4(in_position, 1.0));
}
