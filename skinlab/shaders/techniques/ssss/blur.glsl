// Screen-space separable SSS (Jimenez et al. 2009/2015) at one pixel, shared by techniques/ssss/blur.frag
// and techniques/ssss/blur.comp (RenderSettings.compute): one 1-D pass of the pixel's profile's kernel
// along u_dir over the subsurface diffuse target (its alpha: the profile index + 1, 0 where nothing
// scatters; the kernels are rows of u_table). Offsets are in millimetres on the surface; a pixel at
// view depth z spans z * u_mm_per_unit / u_pixels_per_unit_at_1 mm. Depth-aware ("follow the
// surface"): a sample whose depth differs by more than the kernel's range, or that is not
// scattering material of the same profile, is replaced by the centre sample. Kernel:
// skinlab/scene/optics/ssss.py. Fetches at level 0 (the targets have no mipmaps): the same in both stages.
#include "skinlab/constants.glsl"
#define MAX_SSSS_TAPS 63
#define MAX_SSSS_PROFILES 16
uniform sampler2D u_src;            // rgb: subsurface diffuse radiance, a: profile index + 1
uniform sampler2D u_depth;          // the forward pass's depth buffer
uniform vec2 u_dir;                 // (1/width, 0) or (0, 1/height)
uniform int u_taps;
uniform sampler2D u_table;          // (taps x profiles): rgb weight, a offset mm
uniform float u_range_mm[MAX_SSSS_PROFILES];
uniform float u_mm_per_unit;
uniform float u_pixels_per_unit;    // along u_dir, for a surface at view depth 1
uniform vec2 u_near_far;

float ssss_view_depth(vec2 uv) {
    float z = textureLod(u_depth, uv, 0.0).r * 2.0 - 1.0;
    float n = u_near_far.x, f = u_near_far.y;
    return 2.0 * n * f / (f + n - z * (f - n));
}

vec4 ssss_blur_at(vec2 uv0) {
    vec4 c = textureLod(u_src, uv0, 0.0);
    int prof = int(c.a + 0.5) - 1;
    if (prof < 0) return c;
    float range_mm = u_range_mm[prof];
    float z = ssss_view_depth(uv0);
    float px_per_mm = u_pixels_per_unit / (z * u_mm_per_unit);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < MAX_SSSS_TAPS; ++i) {
        if (i >= u_taps) break;
        vec4 k = texelFetch(u_table, ivec2(i, prof), 0);
        vec2 uv = uv0 + u_dir * (k.a * px_per_mm);
        vec4 s = textureLod(u_src, uv, 0.0);
        float dz_mm = abs(ssss_view_depth(uv) - z) * u_mm_per_unit;
        // another profile (or none): the centre. A filtered fetch on a border blends the indices:
        // within 1 of the pixel's own it is accepted (as the single-profile blur always did)
        float follow = abs(s.a - c.a) < 1.0 ? clamp(dz_mm / max(range_mm, 1e-6), 0.0, 1.0) : 1.0;
        sum += k.rgb * mix(s.rgb, c.rgb, follow);
    }
    return vec4(sum, c.a);
}
