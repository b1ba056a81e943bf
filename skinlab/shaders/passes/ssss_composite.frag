#version 330 core
// Screen-space SSS composite: the lit image without the subsurface diffuse plus its blurred version
// (texel by texel, as the compute paths write it: techniques/ssss/blur.comp, techniques/disk/gather.comp).
uniform sampler2D u_color;
uniform sampler2D u_blurred;
out vec4 f_color;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(u_color, p, 0);
    f_color = vec4(c.rgb + texelFetch(u_blurred, p, 0).rgb, c.a);
}
