#version 430 core
// The exact convolution as a compute shader (RenderSettings.compute; skinlab/render/compute.py): one
// invocation per texel, the per-texel code of techniques/exact/gather.frag (techniques/exact/gather.glsl).
layout(local_size_x = 8, local_size_y = 8) in;
#include "techniques/exact/gather.glsl"
layout(rgba32f) writeonly uniform image2D u_dst;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, textureSize(u_src, 0)))) return;
    imageStore(u_dst, p, exact_gather_at(p));
}
