#version 330 core
// Light through thin parts as a transfer through the medium (skinlab/render/through_kernel.py): a
// sparse row sum over the vertex-space target with a weight per channel, out(i) = sum_k w_k x
// entering(v_k) over row i's entries (sender vertex v_k, weights w_k in rgb), one fragment per vertex
// (NumPy twin skinlab/scene/optics/through_kernel.py gather; the scalar-weight sum of the
// interreflection is passes/bounce_rows.frag).
uniform sampler2D u_source;       // per vertex: the irradiance entering it (passes/through_entering.frag)
uniform sampler2D u_row_index;    // per vertex: (first entry, entries, the depth the light came through in mm)
uniform sampler2D u_row_entries;  // per entry: (vertex, weight r, g, b)
uniform int u_vertices;

layout(location = 0) out vec4 f_through;
layout(location = 1) out vec4 f_through_cos;  // r: the light's mean incidence cosine at its entry

void main() {
    int w = textureSize(u_source, 0).x;
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * w + t.x;
    vec3 sum = vec3(0.0);
    float depth = 0.0;
    float green_cos = 0.0;
    if (i < u_vertices) {
        vec3 row = texelFetch(u_row_index, t, 0).rgb;
        depth = row.z;
        int first = int(row.x + 0.5), count = int(row.y + 0.5);
        int ew = textureSize(u_row_entries, 0).x;
        for (int k = 0; k < count; ++k) {
            int e = first + k;
            vec4 entry = texelFetch(u_row_entries, ivec2(e % ew, e / ew), 0);
            int v = int(entry.x + 0.5);
            vec4 src = texelFetch(u_source, ivec2(v % w, v / w), 0);
            sum += entry.yzw * src.rgb;
            green_cos += entry.z * src.a;
        }
    }
    f_through = vec4(sum, depth);
    f_through_cos = vec4(sum.g > 0.0 ? clamp(green_cos / sum.g, 1e-3, 1.0) : 1.0, 0.0, 0.0, 1.0);
}
