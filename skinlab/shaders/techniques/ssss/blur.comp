#version 430 core
// Screen-space separable SSS as a compute shader (RenderSettings.compute; skinlab/render/compute.py):
// one invocation per pixel, the per-pixel code of techniques/ssss/blur.frag (techniques/ssss/blur.glsl) at
// the pixel's centre. Variant SSSS_COMPOSITE (the vertical pass): also the lit image with its blurred
// subsurface light added back (passes/ssss_composite.frag), into u_composite.
layout(local_size_x = 8, local_size_y = 8) in;
#include "techniques/ssss/blur.glsl"
layout(rgba32f) writeonly uniform image2D u_dst;
#ifdef SSSS_COMPOSITE
uniform sampler2D u_color;  // the lit image without the subsurface diffuse
layout(rgba32f) writeonly uniform image2D u_composite;
#endif
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(u_src, 0);
    if (any(greaterThanEqual(p, size))) return;
    vec4 b = ssss_blur_at((vec2(p) + 0.5) / vec2(size));  // gl_FragCoord.xy / size in the fragment path
    imageStore(u_dst, p, b);
#ifdef SSSS_COMPOSITE
    vec4 c = texelFetch(u_color, p, 0);
    imageStore(u_composite, p, vec4(c.rgb + b.rgb, c.a));
#endif
}
