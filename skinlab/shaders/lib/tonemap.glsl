// Tone mapping of one output pixel, shared by passes/tonemap.frag, passes/tonemap_supersample.frag
// and passes/tonemap.comp (RenderSettings.compute; skinlab/render/compute.py): exposure, ACES and sRGB
// encoding (lib/color.glsl) of the linear radiance composited over the background (where nothing was
// drawn, alpha 0; with BACKGROUND_DRAWN the environment map the forward pass drew). With SUPERSAMPLE = N > 1, u_hdr holds N x N samples per output pixel: the pixel is
// their box filter (mean) - the filtered linear radiance and coverage (the hdr read-back), and the
// tone-mapped mean of the samples composited over the background. NumPy twins:
// skinlab/scene/optics/color.py, skinlab/render/supersample.py.
#include "lib/color.glsl"
uniform sampler2D u_hdr;
uniform float u_exposure;
uniform vec3 u_background;

vec4 tonemap_display(vec3 shown) { return vec4(srgb_encode(tonemap_aces(shown * u_exposure)), 1.0); }

// the linear radiance shown at a sample: over the background where nothing was drawn (alpha 0), or as
// it is with BACKGROUND_DRAWN (the forward pass drew the environment map where no mesh is)
vec3 tonemap_shown(vec4 s) {
#ifdef BACKGROUND_DRAWN
    return s.rgb;
#else
    return mix(u_background, s.rgb, clamp(s.a, 0.0, 1.0));
#endif
}

#ifndef SUPERSAMPLE
vec4 tonemap_pixel(ivec2 p) {
    vec4 hdr = texelFetch(u_hdr, p, 0);
    return tonemap_display(tonemap_shown(hdr));
}
#else
// output pixel p: its tone-mapped colour and its filtered linear radiance (rgb) and coverage (a)
void tonemap_supersampled(ivec2 p, out vec4 color, out vec4 filtered) {
    ivec2 base = p * SUPERSAMPLE;
    vec4 sum = vec4(0.0);
    vec3 shown = vec3(0.0);
    for (int j = 0; j < SUPERSAMPLE; ++j) {
        for (int i = 0; i < SUPERSAMPLE; ++i) {
            vec4 s = texelFetch(u_hdr, base + ivec2(i, j), 0);
            sum += s;
            shown += tonemap_shown(s);
        }
    }
    float inv = 1.0 / float(SUPERSAMPLE * SUPERSAMPLE);
    filtered = sum * inv;
    color = tonemap_display(shown * inv);
}
#endif
