// Shadow-map lookups: 3x3 PCF of bilinear taps on a depth-compare sampler (compare '<='; four
// textureGather calls where GLSL 4.00 or ARB_gpu_shader5 has them, 16 texel compares instead of the
// nine taps' 36; the same filter), with a depth bias sized to
// the map's texel at the receiver (skinlab/scene/optics/constants.py SHADOW_BIAS_TEXELS, ...): a
// constant in normalised depth was far too large at close range and grazing light (light through
// the nose's shadow on the cheek) and too small on a scene many times larger.
// shadow_pcf_area: the same lookup averaged over a receiver's footprint wider than the 3x3 PCF (a
// texture-space texel's: techniques/tsd/irradiance.frag).
// NumPy twin: skinlab/scene/optics/shadow.py (the gathered 3x3 PCF to fp32 rounding, whatever the
// texture's filter mode; the other taps exact for NEAREST compare filtering).
#include "skinlab/constants.glsl"

// (skinlab/gl/shader_source.py moves the #extension up to the #version: GLSL wants it before any code)
#extension GL_ARB_gpu_shader5 : enable  // textureGather with a compare (core in GLSL 4.00)
#if defined(GL_ARB_gpu_shader5) || __VERSION__ >= 400
#define SHADOW_GATHER 1
#endif

// At p = shadow_matrix * (world, 1): x, the side of the map's texel there in world units (the larger
// of its two sides); y, texture depth per world unit along the light. From the matrix's rows: exact
// for an orthographic map, the local scale of a perspective one (d(a / w) = (da - (a / w) dw) / w).
vec2 shadow_texel_scale(mat4 m, vec4 p, vec2 size) {
    vec3 r0 = vec3(m[0][0], m[1][0], m[2][0]);
    vec3 r1 = vec3(m[0][1], m[1][1], m[2][1]);
    vec3 r2 = vec3(m[0][2], m[1][2], m[2][2]);
    vec3 r3 = vec3(m[0][3], m[1][3], m[2][3]);
    vec3 c = p.xyz / p.w;
    float w = abs(p.w);
    float per_unit = min(length(r0 - c.x * r3) * size.x, length(r1 - c.y * r3) * size.y) / w;  // texels
    return vec2(1.0 / max(per_unit, 1e-30), length(r2 - c.z * r3) / w);
}

// Depth bias (texture depth units) for a receiver whose geometric normal makes cosine NoL with the
// light: texel x (SHADOW_BIAS_TEXELS + SHADOW_SLOPE_TEXELS x min(tan theta, SHADOW_SLOPE_MAX)).
float shadow_bias(mat4 m, vec4 p, vec2 size, float NoL) {
    float cosl = clamp(NoL, 1e-3, 1.0);
    float slope = min(sqrt(1.0 - cosl * cosl) / cosl, SHADOW_SLOPE_MAX);
    vec2 s = shadow_texel_scale(m, p, size);
    return s.x * s.y * (SHADOW_BIAS_TEXELS + SHADOW_SLOPE_TEXELS * slope);
}

float shadow_pcf(sampler2DShadow map, mat4 shadow_matrix, vec3 world, float NoL) {
    vec4 p = shadow_matrix * vec4(world, 1.0);
    vec3 c = p.xyz / p.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    vec2 size = vec2(textureSize(map, 0));
    float bias = shadow_bias(shadow_matrix, p, size, NoL);
#ifdef MEASURE_PCF_1TAP  // a measurement variant (tools/irradiance_cost.py): one compare, no filter
    return texture(map, vec3(c.xy, c.z - bias));
#elif defined(SHADOW_GATHER)
    // The nine bilinear taps at offsets -1, 0, +1 texel read the 4 x 4 texels from b - 1 to b + 2
    // (b the texel below the point after the half-texel shift to texel centres, f its fraction),
    // weighted per axis 1 - f, 1, 1, f (the taps' bilinear weights summed): four gathers of 2 x 2
    // compares, each at the corner its four texels share (the map's own addressing at its edges).
    // A gather's components: x (i0, j1), y (i1, j1), z (i1, j0), w (i0, j0), i0 the lower column.
    // The outer weights as lerps (a + f (b - a)), so that a wholly lit or shadowed footprint reads
    // exactly 1 or 0, as the hardware's bilinear taps do.
    vec2 t = c.xy * size - 0.5;
    vec2 b = floor(t);
    vec2 f = t - b;
    float z = c.z - bias;
    vec4 s00 = textureGather(map, b / size, z);                     // columns b-1, b; rows b-1, b
    vec4 s10 = textureGather(map, (b + vec2(2.0, 0.0)) / size, z);  // columns b+1, b+2
    vec4 s01 = textureGather(map, (b + vec2(0.0, 2.0)) / size, z);  // rows b+1, b+2
    vec4 s11 = textureGather(map, (b + 2.0) / size, z);
    vec4 c0 = vec4(s00.w, s00.x, s01.w, s01.x);  // column b-1, rows b-1 .. b+2
    vec4 c1 = vec4(s00.z, s00.y, s01.z, s01.y);
    vec4 c2 = vec4(s10.w, s10.x, s11.w, s11.x);
    vec4 c3 = vec4(s10.z, s10.y, s11.z, s11.y);
    vec4 rows = (c1 + c2) + (c0 + f.x * (c3 - c0));  // each row's 1 - f, 1, 1, f
    return ((rows.y + rows.z) + (rows.x + f.y * (rows.w - rows.x))) / 9.0;
#else
    vec2 texel = 1.0 / size;
    float sum = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            sum += texture(map, vec3(c.xy + vec2(x, y) * texel, c.z - bias));
    return sum / 9.0;
#endif
}

// One bilinear compare tap, the bias as shadow_pcf's: a point's visibility at a quarter of the 3x3
// PCF's fetches, for lookups that a wider weighting smooths anyway (single scattering's shadow where its
// light entered, lib/surface_inputs.glsl sss_single_visibility).
float shadow_tap(sampler2DShadow map, mat4 shadow_matrix, vec3 world, float NoL) {
    vec4 p = shadow_matrix * vec4(world, 1.0);
    vec3 c = p.xyz / p.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    return texture(map, vec3(c.xy, c.z - shadow_bias(shadow_matrix, p, vec2(textureSize(map, 0)), NoL)));
}

// The visibility averaged over a receiver's footprint: the parallelogram spanned by the world vectors
// du and dv centred on world (a texture-space texel's, one texel along u and along v). A texel's
// irradiance is then its square's mean, as the gather's bilinear reading of it needs for the light in
// the texture to be the light on the surface; one point's visibility (the 3x3 PCF, a few shadow-map
// texels wide) aliases a shadow's edge to the texel grid, which a straight edge along the grid
// (a slit of light along u or v) turns into up to half a texel of light too much or too little per
// edge (docs/ground-truth.md "Close-ups": +8 % on marble's 2 mm slit at 0.8 mm per texel). The
// footprint projected into the map spans e_a x e_b texels; where both are at most 3 (the 3x3 PCF's
// width), shadow_pcf as it is; else ceil(e) taps along each side (at most SHADOW_AREA_TAPS), their
// depths on the footprint's plane (exact on a flat receiver), the bias as shadow_pcf's.
const int AREA_TAPS = int(SHADOW_AREA_TAPS);
float shadow_pcf_area(sampler2DShadow map, mat4 m, vec3 world, float NoL, vec3 du, vec3 dv) {
    vec4 p = m * vec4(world, 1.0);
    vec3 c = p.xyz / p.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    vec2 size = vec2(textureSize(map, 0));
    vec4 pa = m * vec4(world + du, 1.0);
    vec4 pb = m * vec4(world + dv, 1.0);
    vec3 a = pa.xyz / pa.w - c;
    vec3 b = pb.xyz / pb.w - c;
    float ea = length(a.xy * size);
    float eb = length(b.xy * size);
    if (max(ea, eb) <= SHADOW_AREA_MIN_TEXELS) return shadow_pcf(map, m, world, NoL);
    int na = clamp(int(ceil(ea)), 1, AREA_TAPS);
    int nb = clamp(int(ceil(eb)), 1, AREA_TAPS);
    float bias = shadow_bias(m, p, size, NoL);
    float sum = 0.0;
    for (int j = 0; j < AREA_TAPS; ++j) {
        if (j >= nb) break;
        vec3 row = c + ((float(j) + 0.5) / float(nb) - 0.5) * b;
        for (int i = 0; i < AREA_TAPS; ++i) {
            if (i >= na) break;
            vec3 q = row + ((float(i) + 0.5) / float(na) - 0.5) * a;
            sum += texture(map, vec3(q.xy, q.z - bias));
        }
    }
    return sum / float(na * nb);
}

// A map fitted to what the camera sees (skinlab/render/shadow_fit.py): the fine map m_f where the
// lookup's texels lie within it, the full map m elsewhere. `reach`: how far from p the lookup reads,
// in the fine map's texels (the 3x3 PCF's 1.5, and a footprint's half-extent); NumPy twin
// skinlab/scene/optics/shadow.py in_window.
bool shadow_in_window(mat4 m_f, vec3 world, vec2 size, float reach) {
    vec4 p = m_f * vec4(world, 1.0);
    if (p.w <= 0.0) return false;
    vec2 c = p.xy / p.w * size;
    return all(greaterThanEqual(c, vec2(reach))) && all(lessThanEqual(c, size - reach));
}

float shadow_pcf_fitted(sampler2DShadow fine, mat4 m_f, sampler2DShadow map, mat4 m, vec3 world, float NoL) {
    if (shadow_in_window(m_f, world, vec2(textureSize(fine, 0)), SHADOW_FIT_REACH))
        return shadow_pcf(fine, m_f, world, NoL);
    return shadow_pcf(map, m, world, NoL);
}

float shadow_pcf_area_fitted(sampler2DShadow fine, mat4 m_f, sampler2DShadow map, mat4 m, vec3 world, float NoL,
                             vec3 du, vec3 dv) {
    vec2 size = vec2(textureSize(fine, 0));
    vec4 p = m_f * vec4(world, 1.0);
    vec4 pa = m_f * vec4(world + du, 1.0);
    vec4 pb = m_f * vec4(world + dv, 1.0);
    // the footprint's half-extent in the fine map's texels (the parallelogram's corners about p)
    vec2 half_extent = 0.5 * (abs(pa.xy / pa.w - p.xy / p.w) + abs(pb.xy / pb.w - p.xy / p.w)) * size;
    if (shadow_in_window(m_f, world, size, SHADOW_FIT_REACH + max(half_extent.x, half_extent.y)))
        return shadow_pcf_area(fine, m_f, world, NoL, du, dv);
    return shadow_pcf_area(map, m, world, NoL, du, dv);
}

#ifdef SHADOW_GATHER
// The share of texel j's [j, j + 1] within [lo, hi] (texel units).
float shadow_overlap(float lo, float hi, float j) { return max(0.0, min(hi, j + 1.0) - max(lo, j)); }

// The depth compares averaged over a box `w` texels wide (at least 1 per axis) centred where world
// falls. Up to SHADOW_BOX_TEXELS wide: each texel's compare weighted by its share of the box, the
// exact box filter of the map's texels (a 1-texel box: bilinear filtering), from nine gathers of
// 2 x 2 compares over the 6 x 6 texels such a box can touch. Wider: the box in SHADOW_BOX_CELLS x SHADOW_BOX_CELLS cells, each
// the mean of the 2 x 2 texels around the texel corner nearest its centre (a gather each: a sampled
// box, not every texel). The bias as shadow_pcf's. NumPy twin: skinlab/scene/optics/shadow.py shadow_box.
const int BOX_CELLS = int(SHADOW_BOX_CELLS);
float shadow_box(sampler2DShadow map, mat4 m, vec3 world, float NoL, vec2 w) {
    vec4 p = m * vec4(world, 1.0);
    vec3 c = p.xyz / p.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    vec2 size = vec2(textureSize(map, 0));
    float z = c.z - shadow_bias(m, p, size, NoL);
    vec2 lo = c.xy * size - 0.5 * w;
    vec2 hi = lo + w;
    float sum = 0.0;
    if (max(w.x, w.y) > SHADOW_BOX_TEXELS) {
        for (int gy = 0; gy < BOX_CELLS; ++gy)
            for (int gx = 0; gx < BOX_CELLS; ++gx) {
                vec2 k = floor(lo + (vec2(float(gx), float(gy)) + 0.5) * w / float(BOX_CELLS) + 0.5);
                sum += dot(textureGather(map, k / size, z), vec4(0.25));
            }
        return sum / float(BOX_CELLS * BOX_CELLS);
    }
    vec2 j0 = floor(lo);
    for (int gy = 0; gy < 3; ++gy) {
        for (int gx = 0; gx < 3; ++gx) {
            // a gather at the corner k returns texels k - 1 (i0, j0) and k (i1, j1) along each axis;
            // components x (i0, j1), y (i1, j1), z (i1, j0), w (i0, j0)
            vec2 k = j0 + vec2(float(2 * gx + 1), float(2 * gy + 1));
            vec4 s = textureGather(map, k / size, z);
            float x0 = shadow_overlap(lo.x, hi.x, k.x - 1.0), x1 = shadow_overlap(lo.x, hi.x, k.x);
            float y0 = shadow_overlap(lo.y, hi.y, k.y - 1.0), y1 = shadow_overlap(lo.y, hi.y, k.y);
            sum += (s.w * x0 + s.z * x1) * y0 + (s.x * x0 + s.y * x1) * y1;
        }
    }
    return sum / (w.x * w.y);
}
#endif

// A screen sample's shadow in a fitted map: shadow_box over the bounding box of its footprint (the world
// vectors du, dv across one sample) in the fitted map's texels where the lookup lies within it; the full
// map's 3x3 PCF elsewhere, as without one. Without gathers, shadow_pcf_area in the fitted map.
vec2 shadow_footprint_texels(mat4 m, vec3 world, vec3 du, vec3 dv, vec2 size) {
    vec4 p = m * vec4(world, 1.0);
    vec4 pa = m * vec4(world + du, 1.0);
    vec4 pb = m * vec4(world + dv, 1.0);
    vec2 c = p.xy / p.w;
    return (abs(pa.xy / pa.w - c) + abs(pb.xy / pb.w - c)) * size;
}

float shadow_box_fitted(sampler2DShadow fine, mat4 m_f, sampler2DShadow map, mat4 m, vec3 world, float NoL,
                        vec3 du, vec3 dv) {
    vec2 size = vec2(textureSize(fine, 0));
    vec2 w = max(shadow_footprint_texels(m_f, world, du, dv, size), vec2(1.0));
    if (!shadow_in_window(m_f, world, size, SHADOW_FIT_REACH + 0.5 * max(w.x, w.y)))
        return shadow_pcf(map, m, world, NoL);
#ifdef SHADOW_GATHER
    return shadow_box(fine, m_f, world, NoL, w);
#else
    return shadow_pcf_area(fine, m_f, world, NoL, du, dv);
#endif
}
