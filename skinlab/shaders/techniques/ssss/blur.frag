#version 330 core
// Screen-space separable SSS: one 1-D pass of each pixel's profile's kernel (techniques/ssss/blur.glsl,
// shared with the compute path techniques/ssss/blur.comp).
#include "techniques/ssss/blur.glsl"
out vec4 f_color;
// the pixel's centre (as the compute path: the same coordinates to the last bit)
void main() { f_color = ssss_blur_at(gl_FragCoord.xy / vec2(textureSize(u_src, 0))); }
