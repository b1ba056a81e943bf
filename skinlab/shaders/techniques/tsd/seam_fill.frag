#version 330 core
// Fill the gutter across UV seams: a texel the seam map marks (an extension texel: the surface across
// a seam, unfolded; never a real chart texel) takes u_src at the seam map's UV in the other chart
// (lib/tsd_seams.glsl); every other texel is copied. Run on the raw irradiance (then dilation pushes
// the charts past the remaining borders) and on every blurred level, so the next blur - and the
// gather's bilinear lookup at a chart border - reads the light from across the seam.
#include "lib/tsd_seams.glsl"
uniform sampler2D u_src;
uniform sampler2D u_seam;
out vec4 f_color;
void main() {
    f_color = seam_fetch(u_src, u_seam, ivec2(gl_FragCoord.xy));
}
