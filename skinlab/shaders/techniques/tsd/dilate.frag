#version 330 core
// One texel of dilation past UV chart borders (lib/tsd_dilate.glsl): an empty texel (alpha 0) takes
// the mean of its covered 8-neighbours (alpha > 0) and becomes covered. Run a few times; blurs and the
// final bilinear lookup then never mix empty texels into the border of a chart. The compute path
// (techniques/tsd/dilate.comp) runs every ring in one dispatch.
uniform sampler2D u_src;
out vec4 f_color;
ivec2 src_size;
vec4 dilate_fetch(ivec2 q) {
    return any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, src_size)) ? vec4(0.0) : texelFetch(u_src, q, 0);
}
#define DILATE_FETCH(q) dilate_fetch(q)
#include "lib/tsd_dilate.glsl"
void main() {
    src_size = textureSize(u_src, 0);
    f_color = dilate_texel(ivec2(gl_FragCoord.xy));
}
