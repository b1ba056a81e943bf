#version 430 core
// One separable step of the texture-space diffusion chain as a compute shader (RenderSettings.compute;
// skinlab/render/compute.py): one invocation per texel, the per-texel code of techniques/tsd/blur.frag
// (techniques/tsd/blur.glsl). Variant TSD_SEAM_FILL: instead, the gutter across UV seams filled
// (lib/tsd_seams.glsl, as techniques/tsd/seam_fill.frag).
layout(local_size_x = 8, local_size_y = 8) in;
#ifdef TSD_SEAM_FILL
#include "lib/tsd_seams.glsl"
uniform sampler2D u_src;
uniform sampler2D u_seam;
#else
#include "techniques/tsd/blur.glsl"
#endif
layout(rgba32f) writeonly uniform image2D u_dst;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, textureSize(u_src, 0)))) return;
#ifdef TSD_SEAM_FILL
    imageStore(u_dst, p, seam_fetch(u_src, u_seam, p));
#else
    imageStore(u_dst, p, tsd_blur_at(p));
#endif
}
