#version 330 core
// Interreflection, one order (skinlab/render/bounce.py): a sparse row sum over the vertex-space target,
// out(i) = sum_k w_k source(v_k) over row i's entries (vertex v_k, weight w_k), one fragment per vertex.
// Twice per order: the gather, E(i) = sum of the summed ray weights x the radiant exitance M of each
// distinct sender the vertex's rays met (skinlab/scene/interreflection.py gather, sender_rows; cosine-
// weighted rays: the one-bounce estimator of a Lambertian sender, E = E_cos[M]), then the one-ring
// average of those estimates on the welded mesh (area weights summing to 1; interreflection.py smooth).
uniform sampler2D u_source;       // per vertex: what is summed (the exitance, or the gathered irradiance)
uniform sampler2D u_row_index;    // per vertex: (first entry, entries)
uniform sampler2D u_row_entries;  // per entry: (vertex, weight)
uniform int u_vertices;

out vec4 f_irradiance;

void main() {
    int w = textureSize(u_source, 0).x;
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * w + t.x;
    vec3 sum = vec3(0.0);
    if (i < u_vertices) {
        vec2 row = texelFetch(u_row_index, t, 0).rg;
        int first = int(row.x + 0.5), count = int(row.y + 0.5);
        int ew = textureSize(u_row_entries, 0).x;
        for (int k = 0; k < count; ++k) {
            int e = first + k;
            vec2 entry = texelFetch(u_row_entries, ivec2(e % ew, e / ew), 0).rg;
            int v = int(entry.x + 0.5);
            sum += entry.y * texelFetch(u_source, ivec2(v % w, v / w), 0).rgb;
        }
    }
    f_irradiance = vec4(sum, 1.0);
}
