#version 330 core
// Tone mapping of a supersampled frame (RenderSettings.supersample = SUPERSAMPLE > 1): u_hdr holds
// SUPERSAMPLE x SUPERSAMPLE samples per output pixel. Each output pixel is their box filter (mean),
// the filtered linear radiance and coverage written to f_hdr; f_color is exposure, ACES and sRGB (as
// tonemap.frag) of the mean of the samples composited over the background: the pixel's linear
// radiance is filtered, then tone-mapped. NumPy twin: skinlab/render/supersample.py.
#include "lib/color.glsl"
uniform sampler2D u_hdr;
uniform float u_exposure;
uniform vec3 u_background;
layout(location = 0) out vec4 f_color;
layout(location = 1) out vec4 f_hdr;
void main() {
    ivec2 base = ivec2(gl_FragCoord.xy) * SUPERSAMPLE;
    vec4 sum = vec4(0.0);
    vec3 shown = vec3(0.0);
    for (int j = 0; j < SUPERSAMPLE; ++j) {
        for (int i = 0; i < SUPERSAMPLE; ++i) {
            vec4 s = texelFetch(u_hdr, base + ivec2(i, j), 0);
            sum += s;
#ifdef BACKGROUND_DRAWN
            shown += s.rgb;  // the environment map is drawn where no mesh is (alpha 0)
#else
            shown += mix(u_background, s.rgb, clamp(s.a, 0.0, 1.0));
#endif
        }
    }
    float inv = 1.0 / float(SUPERSAMPLE * SUPERSAMPLE);
    f_hdr = sum * inv;
    f_color = vec4(srgb_encode(tonemap_aces(shown * inv * u_exposure)), 1.0);
}
