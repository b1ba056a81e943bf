#version 330 core
// Importance-sampled Burley disk SSS in screen space (techniques/disk/gather.glsl, shared with the
// compute path techniques/disk/gather.comp).
#include "techniques/disk/gather.glsl"
out vec4 f_color;
void main() { f_color = disk_gather_at(gl_FragCoord.xy, gl_FragCoord.xy / u_size); }
