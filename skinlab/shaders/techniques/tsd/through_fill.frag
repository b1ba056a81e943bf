#version 330 core
// The light-through records of the irradiance pass (techniques/tsd/irradiance.frag f_through0/1,
// f_through_cos: per texel and shadow slot the light through thin parts, its thickness, its cosine
// on the far face) with their gutter filled like the irradiance's, so that the gather's nearest
// lookup at a chart border (techniques/tsd/forward.glsl) never reads an empty record where the
// surface continues. Drawn over thin strips around the chart borders (skinlab/render/techniques/tsd/
// passes.py through_fill, after the records were copied), or over every texel:
// - a texel a triangle covers (u_raw's a > 0) keeps its record (copied before; discarded here);
// - variant TSD_SEAMS: a gutter texel the seam map marks (lib/tsd_seams.glsl: the surface across a
//   UV seam) takes the record at the seam map's UV in the other chart: the four texels of the
//   bilinear footprint, weighted like seam_bilinear but only the covered ones;
// - any other gutter texel next to a chart (and a marked one whose footprint has no covered texel)
//   takes its covered 8-neighbours, equally weighted: one ring of dilation, as the irradiance has.
// The light through (rgb) is averaged over the covered texels (zero where no light came through);
// the thickness and the cosine of a slot only over the texels whose record holds light of that slot
// (cosine > 0), so a rim is not made thinner by the texels beside it. Variant TSD_THROUGH_SLOTS = 1:
// slot 1 is not read (its record holds no light; written as zero). NumPy twin:
// skinlab/scene/optics/tsd.py through_fill_reference.
#include "skinlab/constants.glsl"
uniform sampler2D u_raw;          // the raw irradiance: a > 0 where a triangle covers the texel
uniform sampler2D u_through0;     // the raw records (nearest)
uniform sampler2D u_through1;
uniform sampler2D u_through_cos;
#ifdef TSD_SEAMS
uniform sampler2D u_seam;         // the seam map (skinlab/render/techniques/tsd/seams.py)
#endif
layout(location = 0) out vec4 f_through0;
layout(location = 1) out vec4 f_through1;
layout(location = 2) out vec2 f_through_cos;

// The weighted sums of the records: s0, s1 the slots' (light, thickness), sc their cosines, w the
// weights (x: covered, y: slot 0 holds light, z: slot 1 holds light).
vec4 s0, s1;
vec2 sc;
vec3 w;

void add_record(ivec2 q, float weight) {
    if (texelFetch(u_raw, q, 0).a <= COVERAGE_EPS) return;
    vec4 r0 = texelFetch(u_through0, q, 0);
#if TSD_THROUGH_SLOTS > 1
    vec4 r1 = texelFetch(u_through1, q, 0);
#else
    vec4 r1 = vec4(0.0);  // (slot 1 holds no light this frame: the gather does not read it)
#endif
    vec2 c = texelFetch(u_through_cos, q, 0).rg;
    vec2 lit = vec2(greaterThan(c, vec2(0.0))) * weight;
    s0 += vec4(r0.rgb * weight, r0.a * lit.x);
    s1 += vec4(r1.rgb * weight, r1.a * lit.y);
    sc += c * lit;
    w += vec3(weight, lit);
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (texelFetch(u_raw, p, 0).a > COVERAGE_EPS) discard;  // covered: keeps its record (copied)
    s0 = s1 = vec4(0.0);
    sc = vec2(0.0);
    w = vec3(0.0);
    ivec2 last = textureSize(u_raw, 0) - 1;
#ifdef TSD_SEAMS
    vec4 s = texelFetch(u_seam, p, 0);
    if (s.a > 0.5) {  // the footprint of seam_bilinear (clamped at the edges), covered texels only
        vec2 x = s.rg * vec2(textureSize(u_raw, 0)) - 0.5;
        vec2 fl = floor(x);
        vec2 f = x - fl;
        ivec2 i = ivec2(fl);
        add_record(clamp(i, ivec2(0), last), (1.0 - f.x) * (1.0 - f.y));
        add_record(clamp(i + ivec2(1, 0), ivec2(0), last), f.x * (1.0 - f.y));
        add_record(clamp(i + ivec2(0, 1), ivec2(0), last), (1.0 - f.x) * f.y);
        add_record(clamp(i + ivec2(1, 1), ivec2(0), last), f.x * f.y);
    }
#endif
    if (w.x <= 0.0) {  // one ring of dilation
        for (int y = -1; y <= 1; ++y)
            for (int x = -1; x <= 1; ++x) {
                ivec2 q = p + ivec2(x, y);
                if ((x != 0 || y != 0) && all(greaterThanEqual(q, ivec2(0))) && all(lessThanEqual(q, last)))
                    add_record(q, 1.0);
            }
    }
    vec3 inv = vec3(1.0) / max(w, vec3(1e-30));
    f_through0 = w.x > 0.0 ? vec4(s0.rgb * inv.x, s0.a * inv.y) : vec4(0.0);
    f_through1 = w.x > 0.0 ? vec4(s1.rgb * inv.x, s1.a * inv.z) : vec4(0.0);
    f_through_cos = sc * inv.yz;
}
