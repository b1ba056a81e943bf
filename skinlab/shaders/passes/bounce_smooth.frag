#version 330 core
// Interreflection, one order (skinlab/render/bounce.py; NumPy twin skinlab/scene/interreflection.py smooth): each
// vertex's gathered irradiance averaged over its one-ring on the welded mesh (area weights summing to
// 1): about a third of the variance of one vertex's rays, for a bias of about an edge length.
uniform sampler2D u_gathered;      // per-vertex irradiance from bounce_gather.frag
uniform sampler2D u_ring_index;    // per vertex: (first entry, entries)
uniform sampler2D u_ring_entries;  // per entry: (vertex, weight)
uniform int u_vertices;

out vec4 f_irradiance;

void main() {
    int w = textureSize(u_gathered, 0).x;
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * w + t.x;
    vec3 sum = vec3(0.0);
    if (i < u_vertices) {
        vec2 ring = texelFetch(u_ring_index, t, 0).rg;
        int first = int(ring.x + 0.5), count = int(ring.y + 0.5);
        int ew = textureSize(u_ring_entries, 0).x;
        for (int k = 0; k < count; ++k) {
            int e = first + k;
            vec2 entry = texelFetch(u_ring_entries, ivec2(e % ew, e / ew), 0).rg;
            int v = int(entry.x + 0.5);
            sum += entry.y * texelFetch(u_gathered, ivec2(v % w, v / w), 0).rgb;
        }
    }
    f_irradiance = vec4(sum, 1.0);
}
