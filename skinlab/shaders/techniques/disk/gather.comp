#version 430 core
// Disk SSS as a compute shader (RenderSettings.compute; skinlab/render/compute.py): one invocation per
// pixel, the per-pixel code of techniques/disk/gather.frag (techniques/disk/gather.glsl) at the pixel's
// centre, and the lit image with the filtered subsurface light added back (passes/ssss_composite.frag).
layout(local_size_x = 8, local_size_y = 8) in;
#include "techniques/disk/gather.glsl"
uniform sampler2D u_color;  // the lit image without the subsurface diffuse
layout(rgba32f) writeonly uniform image2D u_dst;
layout(rgba32f) writeonly uniform image2D u_composite;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, ivec2(u_size)))) return;
    vec2 frag = vec2(p) + 0.5;
    vec4 b = disk_gather_at(frag, frag / u_size);
    imageStore(u_dst, p, b);
    vec4 c = texelFetch(u_color, p, 0);
    imageStore(u_composite, p, vec4(c.rgb + b.rgb, c.a));
}
