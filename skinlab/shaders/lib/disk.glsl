// Importance-sampled Burley disk SSS (Golubev 2018): the per-sample helpers of
// skinlab/shaders/techniques/disk/gather.frag. NumPy twins: skinlab/scene/optics/disk.py; docs/references.md#golubev-2018.
#include "skinlab/constants.glsl"

const float GOLDEN_ANGLE = 2.399963229728653;  // PI (3 - sqrt 5)

// Jimenez 2014 interleaved gradient noise in [0, 1) at a pixel centre p (pixels).
float interleaved_gradient_noise(vec2 p) {
    return fract(52.9829189 * fract(0.06711056 * p.x + 0.00583715 * p.y));
}

// Sample i's angle on the golden-angle spiral, rotated by the pixel's phi (radians).
float disk_angle(float i, float phi) { return i * GOLDEN_ANGLE + phi; }

// Sample i's offset (mm) at radius r (mm).
vec2 disk_offset(float i, float r, float phi) {
    float a = disk_angle(i, phi);
    return r * vec2(cos(a), sin(a));
}
