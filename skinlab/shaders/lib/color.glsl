// Colour transforms: sRGB transfer (IEC 61966-2-1) and ACES filmic tone mapping
// (Narkowicz 2015 fit). NumPy twin: skinlab/scene/optics/color.py.
#include "skinlab/constants.glsl"

vec3 srgb_encode(vec3 x) {
    x = clamp(x, 0.0, 1.0);
    vec3 lo = 12.92 * x;
    vec3 hi = 1.055 * pow(max(x, vec3(SRGB_LINEAR_THRESHOLD)), vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, vec3(lessThanEqual(x, vec3(SRGB_LINEAR_THRESHOLD))));
}

vec3 srgb_decode(vec3 x) {
    x = clamp(x, 0.0, 1.0);
    vec3 lo = x / 12.92;
    vec3 hi = pow((max(x, vec3(SRGB_ENCODED_THRESHOLD)) + 0.055) / 1.055, vec3(2.4));
    return mix(hi, lo, vec3(lessThanEqual(x, vec3(SRGB_ENCODED_THRESHOLD))));
}

vec3 tonemap_aces(vec3 x) {
    // from x = 7.25 on the curve is clamped to 1; capping x at 1e4 changes nothing there and keeps
    // x * x finite (a huge exposure, 1e30, made inf / inf = NaN: a black image)
    x = clamp(x, vec3(0.0), vec3(1e4));
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}
