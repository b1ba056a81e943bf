// Subsurface hook of technique "tsd" (and "exact"): the texture-space diffusion gather (d'Eon &
// Luebke 2007): the subsurface diffuse term is the weighted sum of the blurred irradiance levels x
// albedo^(1-mix) (post-scatter texturing), mixed with plain Burley diffuse by the subsurface weight
// (x its map, lib/sss_maps.glsl). Variant: TSD_LEVELS = n (0..6) blurred levels. Variant
// TSD_THROUGH (the mesh's irradiance pass gathered light through thin parts): the blurred light left
// with the reflected light's exit factor sss_exit, but light that came through leaves with its own
// (lib/sss_boundary.glsl sss_slab_exit: more along the normal through a few mean free paths), so the
// hook adds the difference for the light through this texel, unblurred, from the irradiance pass's
// record (per shadow slot: the light through, its thickness and cosine; TSD_THROUGH = slots):
// exact where that light varies slowly across the profile (a flat part), linear in the lights; at a
// sharp edge of the light through (a rim where the thickness drops) it can take a little more than
// the blur brought there (at least 0). TSD_THROUGH_READ (a mask of the slots, default all): triangles
// that read no texel of the other slots' records holding light (skinlab/render/techniques/tsd/through_split.py),
// for which their difference is exactly 0: those records are not read. Contract: skinlab/render/technique.py.
// The separable boundary's non-separable rest is added by the forward pass where the light lands
// (passes/forward.frag): this hook does not spread it with its diffusion.
#define SSS_MS_REST_LANDS
#include "lib/sss_boundary.glsl"
#include "skinlab/constants.glsl"
#include "lib/surface_inputs.glsl"

uniform float u_tsd_mix;
uniform vec3 u_tsd_identity;         // weight of the unblurred irradiance per channel
uniform vec3 u_tsd_w[6];             // weight of each blurred level per channel
uniform sampler2D u_tsd_irradiance;  // premultiplied by coverage: rgb / a
#ifdef TSD_THROUGH
#ifndef TSD_THROUGH_READ
#define TSD_THROUGH_READ 3
#endif
uniform sampler2D u_tsd_through0;     // slot 0's light through (rgb), its thickness in mm (a); nearest
uniform sampler2D u_tsd_through1;     // slot 1's
uniform sampler2D u_tsd_through_cos;  // their cosines on the far face (r, g)

// The difference the exit factor of light that came through makes for one slot's record.
vec3 tsd_through_exit(vec4 rec, float back, float mu, vec3 exit_) {
    return rec.rgb * (sss_slab_exit(mu, back, rec.a) - exit_);
}
#endif
#if TSD_LEVELS > 0
uniform sampler2D u_tsd_level0;
#endif
#if TSD_LEVELS > 1
uniform sampler2D u_tsd_level1;
#endif
#if TSD_LEVELS > 2
uniform sampler2D u_tsd_level2;
#endif
#if TSD_LEVELS > 3
uniform sampler2D u_tsd_level3;
#endif
#if TSD_LEVELS > 4
uniform sampler2D u_tsd_level4;
#endif
#if TSD_LEVELS > 5
uniform sampler2D u_tsd_level5;
#endif

vec3 unpremultiply(vec4 t) { return t.a > COVERAGE_EPS ? t.rgb / t.a : vec3(0.0); }

// Diffused irradiance (still x albedo^mix) at uv: I E + sum_k W_k level_k.
vec3 tsd_diffused(vec2 uv) {
#ifdef MEASURE_NO_GATHER  // a measurement variant (tools/orbit_cost.py): no irradiance or level fetched
    return vec3(uv, 0.5);
#endif
    vec3 d = u_tsd_identity * unpremultiply(texture(u_tsd_irradiance, uv));
#if TSD_LEVELS > 0
    d += u_tsd_w[0] * unpremultiply(texture(u_tsd_level0, uv));
#endif
#if TSD_LEVELS > 1
    d += u_tsd_w[1] * unpremultiply(texture(u_tsd_level1, uv));
#endif
#if TSD_LEVELS > 2
    d += u_tsd_w[2] * unpremultiply(texture(u_tsd_level2, uv));
#endif
#if TSD_LEVELS > 3
    d += u_tsd_w[3] * unpremultiply(texture(u_tsd_level3, uv));
#endif
#if TSD_LEVELS > 4
    d += u_tsd_w[4] * unpremultiply(texture(u_tsd_level4, uv));
#endif
#if TSD_LEVELS > 5
    d += u_tsd_w[5] * unpremultiply(texture(u_tsd_level5, uv));
#endif
    return d;
}

float sss_plain_weight(Surface s) { return 1.0 - s.sss_weight; }

void sss_add_light(Surface s, vec3 e, vec3 vis, float NoL) {}  // the irradiance pass gathered the light

vec3 sss_radiance(Surface s) {
    vec3 base = s.m.sss_albedo;
    float NoV = s.NoV;
    vec2 uv = s.uv;
    // the diffused light leaving toward the viewer: the angular distribution of what leaves the
    // medium (lib/sss_boundary.glsl; the irradiance pass applied the entry factor)
    vec3 post = pow(max(base, vec3(0.0)), vec3(1.0 - u_tsd_mix));
    vec3 exit_ = sss_exit(abs(NoV));
#ifdef MEASURE_NO_EXIT  // a measurement variant (tools/orbit_cost.py): the exit table not read
    exit_ = vec3(NoV);
#endif
    vec3 leaving = post * tsd_diffused(uv) * exit_;
#if defined(TSD_THROUGH) && !defined(MEASURE_NO_THROUGH)  // MEASURE_NO_THROUGH: tools/orbit_cost.py
    vec3 diff = vec3(0.0);
#if TSD_THROUGH_READ != 0
    vec2 backs = texture(u_tsd_through_cos, uv).rg;
#endif
#if TSD_THROUGH_READ == 1 || TSD_THROUGH_READ == 3
    diff = tsd_through_exit(texture(u_tsd_through0, uv), backs.r, abs(NoV), exit_);
#endif
#if TSD_THROUGH > 1 && TSD_THROUGH_READ >= 2
    diff += tsd_through_exit(texture(u_tsd_through1, uv), backs.g, abs(NoV), exit_);
#endif
    leaving = max(leaving + max(base, vec3(0.0)) * diff, vec3(0.0));
#endif
    return (1.0 - u_metallic) * s.sss_weight * INV_PI * leaving;
}
