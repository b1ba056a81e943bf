#version 330 core
// Exposure, ACES tone mapping and sRGB encoding; background where nothing was drawn (variant
// BACKGROUND_DRAWN: the forward pass drew the environment map there).
#include "lib/color.glsl"
in vec2 v_uv;
uniform sampler2D u_hdr;
uniform float u_exposure;
uniform vec3 u_background;
out vec4 f_color;
void main() {
    vec4 hdr = texture(u_hdr, v_uv);
#ifdef BACKGROUND_DRAWN
    vec3 c = hdr.rgb;  // the environment map is drawn where no mesh is (alpha 0)
#else
    vec3 c = mix(u_background, hdr.rgb, clamp(hdr.a, 0.0, 1.0));
#endif
    f_color = vec4(srgb_encode(tonemap_aces(c * u_exposure)), 1.0);
}
