// Light transport helpers shared by passes. NumPy twin: skinlab/scene/optics/lighting.py.
#include "skinlab/constants.glsl"

// Tangent-space normal mapping. n: interpolated normal, t: tangent (xyz) + handedness (w),
// tex: normal-map texel in [0, 1], scale: strength. Degenerate frames fall back to n.
vec3 perturb_normal(vec3 n, vec4 t, vec3 tex, float scale) {
    float ln = length(n);
    n = ln > 1e-8 ? n / ln : vec3(0.0, 0.0, 1.0);
    vec3 tt = t.xyz - n * dot(n, t.xyz);
    float lt = length(tt);
    if (lt < 1e-6) return n;
    tt /= lt;
    vec3 b = cross(n, tt) * (t.w < 0.0 ? -1.0 : 1.0);
    vec3 m = tex * 2.0 - 1.0;
    vec3 p = tt * (m.x * scale) + b * (m.y * scale) + n * m.z;
    float lp = length(p);
    return lp > 1e-6 ? p / lp : n;
}

// Irradiance factor of a point light of unit intensity at distance d_mm (millimetres).
float inverse_square(float d_mm) {
    float d = max(d_mm * 1e-3, MIN_LIGHT_DISTANCE_M);
    return 1.0 / (d * d);
}
