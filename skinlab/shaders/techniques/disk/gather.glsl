// Importance-sampled Burley disk SSS in screen space at one pixel (Golubev 2018; skinlab/scene/optics/disk.py),
// shared by techniques/disk/gather.frag and techniques/disk/gather.comp (RenderSettings.compute): per pixel,
// u_samples samples on a disc, radii drawn from the Burley profile's CDF (mm on the surface, turned
// into pixels with the pixel's view depth), angles on a golden-angle spiral rotated per pixel
// (interleaved gradient noise), each weighted by the pixel's own profile over the sampling pdf
// (the profile table: row = profile index, column = sample; rgb weight, a radius mm). A sample off
// the image, on a pixel that is not scattering material of the same profile (light entering
// another medium scatters by that medium's profile), or whose depth differs by more than the
// profile's reach is rejected; the sum is divided by the accepted weight per channel (a channel
// with no accepted weight keeps the centre).
#include "skinlab/constants.glsl"
#include "lib/disk.glsl"
#define MAX_DISK_PROFILES 16
uniform sampler2D u_src;        // rgb: subsurface diffuse, a: profile index + 1 (0: not scattering)
                                // + radius scale / 2 (the material's radius map; 0.5 without one)
uniform sampler2D u_depth;      // the forward pass's depth buffer
uniform sampler2D u_table;      // (samples x profiles) rgb weight, a radius mm
uniform int u_samples;
uniform float u_reach_mm[MAX_DISK_PROFILES];
uniform float u_mm_per_unit;
uniform float u_pixels_per_unit; // pixels per scene unit for a surface at view depth 1
uniform vec2 u_size;             // target size in pixels
uniform vec2 u_near_far;
uniform float u_rotate;          // 1: per-pixel rotation, 0: the same spiral everywhere

float depth_to_view(float d) {
    float z = d * 2.0 - 1.0;
    float n = u_near_far.x, f = u_near_far.y;
    return 2.0 * n * f / (f + n - z * (f - n));
}
float view_depth(ivec2 texel) { return depth_to_view(texelFetch(u_depth, texel, 0).r); }

// frag: the pixel centre in pixels (gl_FragCoord.xy), uv0 = frag / u_size
vec4 disk_gather_at(vec2 frag, vec2 uv0) {
    ivec2 centre = ivec2(frag);
    vec4 c = texelFetch(u_src, centre, 0);
    float prof_id = floor(c.a);
    int prof = int(prof_id) - 1;
    if (prof < 0) return c;
    float scale = 2.0 * (c.a - prof_id);  // the pixel's radius scale: radii and reach scale with it
    float z = view_depth(centre);
    float px_per_mm = u_pixels_per_unit / (z * u_mm_per_unit);
    float reach = u_reach_mm[prof] * scale;
    float phi = u_rotate * 2.0 * PI * interleaved_gradient_noise(frag);
    vec3 sum = vec3(0.0), wsum = vec3(0.0);
    for (int i = 0; i < u_samples; ++i) {
        vec4 t = texelFetch(u_table, ivec2(i, prof), 0);
        vec2 uv = uv0 + disk_offset(float(i), t.a * scale, phi) * px_per_mm / u_size;
        if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0)))) continue;
        ivec2 texel = ivec2(uv * u_size);  // nearest: a filtered fetch would blend profile indices
        vec4 s = texelFetch(u_src, texel, 0);
        if (floor(s.a) != prof_id) continue;  // another profile's (or no) scattering material
        if (abs(view_depth(texel) - z) * u_mm_per_unit > reach) continue;
        sum += t.rgb * s.rgb;
        wsum += t.rgb;
    }
    vec3 safe = max(wsum, vec3(1e-30));
    return vec4(mix(c.rgb, sum / safe, vec3(greaterThan(wsum, vec3(0.0)))), c.a);
}
