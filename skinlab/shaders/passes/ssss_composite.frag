#version 330 core
// Screen-space SSS composite: the lit image without the subsurface diffuse plus its blurred version.
in vec2 v_uv;
uniform sampler2D u_color;
uniform sampler2D u_blurred;
out vec4 f_color;
void main() {
    vec4 c = texture(u_color, v_uv);
    f_color = vec4(c.rgb + texture(u_blurred, v_uv).rgb, c.a);
}
