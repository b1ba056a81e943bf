#version 330 core
// One texel of dilation past UV chart borders: an empty texel (alpha 0) takes the mean of its
// covered 8-neighbours (alpha > 0) and becomes covered. Run a few times; blurs and the final
// bilinear lookup then never mix empty texels into the border of a chart.
#include "skinlab/constants.glsl"
uniform sampler2D u_src;
out vec4 f_color;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(u_src, p, 0);
    if (c.a > COVERAGE_EPS) { f_color = c; return; }
    ivec2 size = textureSize(u_src, 0);
    vec4 sum = vec4(0.0);
    float n = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            ivec2 q = p + ivec2(x, y);
            if (q.x < 0 || q.y < 0 || q.x >= size.x || q.y >= size.y) continue;
            vec4 s = texelFetch(u_src, q, 0);
            if (s.a > COVERAGE_EPS) { sum += s / s.a; n += 1.0; }
        }
    f_color = n > 0.0 ? sum / n : vec4(0.0);
}
