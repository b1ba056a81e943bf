#version 330 core
// Exposure, ACES tone mapping and sRGB encoding; background where nothing was drawn.
// With SUPERSAMPLE = N > 1 (RenderSettings.supersample) u_hdr holds N x N samples per output pixel:
// each output pixel is their box filter (mean), the filtered linear radiance also written to f_hdr,
// and the tone mapping applies to the mean of the samples composited over the background (a pixel's
// linear radiance is filtered, then tone-mapped; NumPy twin: app/render/supersample.py).
#include "lib/color.glsl"
in vec2 v_uv;
uniform sampler2D u_hdr;
uniform float u_exposure;
uniform vec3 u_background;
#if defined(SUPERSAMPLE) && SUPERSAMPLE > 1
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
            shown += mix(u_background, s.rgb, clamp(s.a, 0.0, 1.0));
        }
    }
    float inv = 1.0 / float(SUPERSAMPLE * SUPERSAMPLE);
    f_hdr = sum * inv;
    f_color = vec4(srgb_encode(tonemap_aces(shown * inv * u_exposure)), 1.0);
}
#else
out vec4 f_color;
void main() {
    vec4 hdr = texture(u_hdr, v_uv);
    vec3 c = mix(u_background, hdr.rgb, clamp(hdr.a, 0.0, 1.0));
    f_color = vec4(srgb_encode(tonemap_aces(c * u_exposure)), 1.0);
}
#endif
