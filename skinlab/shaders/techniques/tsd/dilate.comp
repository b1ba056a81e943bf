#version 430 core
// Dilation past UV chart borders as a compute shader (RenderSettings.compute; skinlab/render/compute.py):
// RINGS rings of techniques/tsd/dilate.frag (lib/tsd_dilate.glsl, the same per-texel code) in one dispatch.
// Each work group loads its 16 x 16 texels and RINGS texels around them into shared memory and runs
// the rings there, ring r on the texels r or more from the tile's edge (they read only texels ring
// r - 1 computed), so the result is the fragment path's, texel for texel. Variant TSD_SEAMS: the
// texels are loaded through the seam map (lib/tsd_seams.glsl seam_fetch: the gutter across UV seams
// read from the other chart), which is techniques/tsd/seam_fill.frag run first.
layout(local_size_x = 16, local_size_y = 16) in;
#define GROUP 16
#define TILE (GROUP + 2 * RINGS)
#define TILE_TEXELS (TILE * TILE)
uniform sampler2D u_src;
#ifdef TSD_SEAMS
#include "lib/tsd_seams.glsl"
uniform sampler2D u_seam;
#endif
layout(rgba32f) writeonly uniform image2D u_dst;

shared vec4 tile[2 * TILE_TEXELS];  // two buffers: ring r reads one and writes the other
int read_at = 0;
#define DILATE_FETCH(q) tile[read_at + (q).y * TILE + (q).x]
#include "lib/tsd_dilate.glsl"

void main() {
    ivec2 size = textureSize(u_src, 0);
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * GROUP - RINGS;  // the tile's texel (0, 0)
    int lid = int(gl_LocalInvocationIndex);
    for (int i = lid; i < TILE_TEXELS; i += GROUP * GROUP) {
        ivec2 q = origin + ivec2(i % TILE, i / TILE);
        bool inside = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size));
#ifdef TSD_SEAMS
        tile[i] = inside ? seam_fetch(u_src, u_seam, q) : vec4(0.0);
#else
        tile[i] = inside ? texelFetch(u_src, q, 0) : vec4(0.0);
#endif
    }
    barrier();
    for (int r = 1; r <= RINGS; ++r) {
        int write_at = TILE_TEXELS - read_at;
        for (int i = lid; i < TILE_TEXELS; i += GROUP * GROUP) {
            ivec2 t = ivec2(i % TILE, i / TILE);
            if (any(lessThan(t, ivec2(r))) || any(greaterThanEqual(t, ivec2(TILE - r)))) continue;
            ivec2 q = origin + t;
            bool inside = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size));
            tile[write_at + i] = inside ? dilate_texel(t) : vec4(0.0);  // outside the texture stays empty
        }
        read_at = write_at;
        barrier();
    }
    ivec2 p = ivec2(gl_WorkGroupID.xy) * GROUP + ivec2(gl_LocalInvocationID.xy);
    if (all(lessThan(p, size))) imageStore(u_dst, p, DILATE_FETCH(ivec2(gl_LocalInvocationID.xy) + RINGS));
}
