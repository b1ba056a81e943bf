// Sky occlusion's per-vertex record (skinlab/render/environment.py): vertex i's share of the map's light
// its rays see, per channel, and the share of its rays that leave the scene (a)
// (skinlab/scene/interreflection.py sky_visible_share), at texel (i % 1024, i / 1024). Read by
// lib/sky_vertex.glsl (per vertex, interpolated on) and by the bounce exitance (per vertex texel,
// passes/bounce_exitance.frag).
uniform sampler2D u_sky_blocked;
uniform int u_sky_offset;  // this mesh's first vertex in it
void sky_blocked_fetch(int vertex, out vec4 sky) {
    int i = u_sky_offset + vertex;
    sky = texelFetch(u_sky_blocked, ivec2(i % 1024, i / 1024), 0);
}
