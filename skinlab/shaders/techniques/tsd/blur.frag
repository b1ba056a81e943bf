#version 330 core
// One separable step of the texture-space diffusion chain (techniques/tsd/blur.glsl, shared with the
// compute path techniques/tsd/blur.comp).
#include "techniques/tsd/blur.glsl"
out vec4 f_color;
void main() { f_color = tsd_blur_at(ivec2(gl_FragCoord.xy)); }
