#version 330 core
// Brute-force texture-space convolution with the exact radial profile (techniques/exact/gather.glsl,
// shared with the compute path techniques/exact/gather.comp).
#include "techniques/exact/gather.glsl"
out vec4 f_color;
void main() { f_color = exact_gather_at(ivec2(gl_FragCoord.xy)); }
