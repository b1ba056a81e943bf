// One separable step of the texture-space diffusion chain at one texel, shared by
// techniques/tsd/blur.frag and techniques/tsd/blur.comp (RenderSettings.compute): a 1-D Gaussian of
// u_sigma_mm millimetres along u_axis (0 = u, 1 = v), the step in texels from the stretch map (mm per
// texel) at this texel. Taps at t_i sigma with weights from skinlab/scene/optics/tsd.py blur_taps();
// linear interpolation between the two nearest texels by hand (two fetches), so the NumPy twin
// (blur_axis_reference) agrees to fp32 rounding. Input and output are premultiplied by coverage
// (rgb = E a, a = coverage).
#include "skinlab/constants.glsl"
#define MAX_TAPS 31
#ifndef TSD_TAPS
#error "techniques/tsd/blur.glsl needs TSD_TAPS (the step's tap count, odd, at most MAX_TAPS)"
#endif
uniform sampler2D u_src;
uniform sampler2D u_stretch;
uniform int u_axis;
uniform float u_sigma_mm;
uniform float u_tap_t[MAX_TAPS];
uniform float u_tap_w[MAX_TAPS];

vec4 tsd_blur_at(ivec2 p) {
    ivec2 last = textureSize(u_src, 0) - 1;
    ivec2 dir = u_axis == 0 ? ivec2(1, 0) : ivec2(0, 1);
    float mm = max(texelFetch(u_stretch, p, 0)[u_axis], TSD_MIN_MM_PER_TEXEL);
    float step_texels = min(u_sigma_mm / mm, TSD_MAX_STEP_TEXELS);
    vec4 sum = vec4(0.0);
    for (int i = 0; i < TSD_TAPS; ++i) {  // the pass's tap count, a compile-time constant: the loop unrolls
        float x = u_tap_t[i] * step_texels;
        float fl = floor(x);
        float f = x - fl;
        int i0 = int(fl);
        vec4 a = texelFetch(u_src, clamp(p + dir * i0, ivec2(0), last), 0);
        vec4 b = texelFetch(u_src, clamp(p + dir * (i0 + 1), ivec2(0), last), 0);
        sum += u_tap_w[i] * (a + (b - a) * f);
    }
    return sum;
}
