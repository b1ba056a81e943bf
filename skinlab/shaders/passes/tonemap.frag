#version 330 core
// Exposure, ACES tone mapping and sRGB encoding; background where nothing was drawn (lib/tonemap.glsl;
// variant BACKGROUND_DRAWN: the forward pass drew the environment map there; the compute path:
// passes/tonemap.comp).
#include "lib/tonemap.glsl"
out vec4 f_color;
void main() { f_color = tonemap_pixel(ivec2(gl_FragCoord.xy)); }
