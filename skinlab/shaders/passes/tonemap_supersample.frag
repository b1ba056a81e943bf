#version 330 core
// Tone mapping of a supersampled frame (RenderSettings.supersample = SUPERSAMPLE > 1): each output
// pixel the box filter (mean) of its SUPERSAMPLE x SUPERSAMPLE samples, the filtered linear radiance
// and coverage written to f_hdr; f_color is exposure, ACES and sRGB of the mean of the samples
// composited over the background: the pixel's linear radiance is filtered, then tone-mapped
// (lib/tonemap.glsl; the compute path: passes/tonemap.comp). NumPy twin: skinlab/render/supersample.py.
#include "lib/tonemap.glsl"
layout(location = 0) out vec4 f_color;
layout(location = 1) out vec4 f_hdr;
void main() { tonemap_supersampled(ivec2(gl_FragCoord.xy), f_color, f_hdr); }
