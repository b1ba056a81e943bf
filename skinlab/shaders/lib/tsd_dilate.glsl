// One texel of one ring of dilation past UV chart borders, shared by techniques/tsd/dilate.frag and
// techniques/tsd/dilate.comp (RenderSettings.compute): an empty texel (alpha <= COVERAGE_EPS) takes
// the mean of its covered 8-neighbours (s / s.a) and becomes covered; a covered one is kept. The
// includer defines DILATE_FETCH(q): the texel q's value, vec4(0.0) outside the texture. NumPy twin:
// skinlab/scene/optics/tsd.py dilate_reference.
#include "skinlab/constants.glsl"

vec4 dilate_texel(ivec2 p) {
    vec4 c = DILATE_FETCH(p);
    if (c.a > COVERAGE_EPS) return c;
    vec4 sum = vec4(0.0);
    float n = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            vec4 s = DILATE_FETCH(p + ivec2(x, y));
            if (s.a > COVERAGE_EPS) { sum += s / s.a; n += 1.0; }
        }
    return n > 0.0 ? sum / n : vec4(0.0);
}
