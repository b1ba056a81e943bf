#version 430 core
// Tone mapping (and with SUPERSAMPLE the box filter of each pixel's samples) as a compute shader: one
// invocation per output pixel, the same per-pixel code as passes/tonemap.frag and
// passes/tonemap_supersample.frag (lib/tonemap.glsl). RenderSettings.compute; skinlab/render/compute.py.
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/tonemap.glsl"
uniform ivec2 u_size;  // output pixels
layout(rgba8) writeonly uniform image2D u_ldr;
#ifdef SUPERSAMPLE
layout(rgba32f) writeonly uniform image2D u_filtered;
#endif
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, u_size))) return;
#ifdef SUPERSAMPLE
    vec4 color, filtered;
    tonemap_supersampled(p, color, filtered);
    imageStore(u_ldr, p, color);
    imageStore(u_filtered, p, filtered);
#else
    imageStore(u_ldr, p, tonemap_pixel(p));
#endif
}
