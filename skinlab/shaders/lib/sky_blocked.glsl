// Sky occlusion's per-vertex record (skinlab/render/environment.py): vertex i's 9 SH coefficients of what
// its rays meet (skinlab/scene/interreflection.py sky_blocked), at texels (3 (i % 1024) + k, i / 1024),
// k = 0, 1, 2. Read by lib/sky_vertex.glsl (per vertex, interpolated on) and by the bounce exitance
// (per vertex texel, passes/bounce_exitance.frag).
uniform sampler2D u_sky_blocked;
uniform int u_sky_offset;  // this mesh's first vertex in it
void sky_blocked_fetch(int vertex, out vec4 b03, out vec4 b47, out float b8) {
    int i = u_sky_offset + vertex;
    ivec2 p = ivec2(3 * (i % 1024), i / 1024);
    b03 = texelFetch(u_sky_blocked, p, 0);
    b47 = texelFetch(u_sky_blocked, p + ivec2(1, 0), 0);
    b8 = texelFetch(u_sky_blocked, p + ivec2(2, 0), 0).x;
}
