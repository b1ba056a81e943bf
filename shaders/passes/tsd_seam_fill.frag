#version 330 core
// Fill the gutter across UV seams: a texel no real triangle covers (a = 0) that the seam map marks
// takes the irradiance at the seam map's UV in the other chart (lib/tsd_seams.glsl); real texels and
// the rest are copied. The dilation then pushes the charts past the remaining borders.
#include "skinlab/constants.glsl"
#include "lib/tsd_seams.glsl"
uniform sampler2D u_src;
uniform sampler2D u_seam;
out vec4 f_color;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(u_src, p, 0);
    f_color = c.a > COVERAGE_EPS ? c : seam_fetch(u_src, u_seam, p);
}
