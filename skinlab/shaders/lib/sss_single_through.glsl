// Single scattering along the light's own path through the medium (issue 21: the small ball's terminator).
// Jensen et al. 2001's single-scattering integral (section 2.3) along the refracted view ray, for the
// light of a shadow slot with a distance map:
//     L = E_in alpha p(cos) t_out / eta^2  int_0^inf sigma_t e^{-sigma_t (s + d(s))} ds,
// E_in the light per unit area of the refracted beam (E c / ct: irradiance on a face toward the light,
// the entry cosine c and its refracted ct, times the Fresnel transmission in), d(s) the path the light
// travelled inside to the point s along the ray: the distance map's air path (lib/sss_translucency.glsl:
// the point's distance from the light less the first surface's) times c / ct, for the refraction at the
// entry face. The frame's flat term (lib/profiles_single.glsl) takes d = s ct_o / ct_i, a plane's; on a
// curved part the light skims nearer the surface (a convex part's grazing light runs a chord just below
// it, and past the terminator, where the flat term is 0). d is read at SSS_SINGLE_THROUGH_DEPTHS x the
// luminance mean free path and taken as piecewise linear, beyond the last depth with its last slope (at
// least 0); each segment's integral is exact, so a plane's linear d gives the flat term exactly.
// Two uses, both from sss_single_through (passes/forward.frag, variant SSS_SINGLE_THROUGH;
// RenderSettings.single_through):
// - the lit side: the flat term times its gain, I(d from the map) / I(flat), at least 1 (a cast shadow
//   stays the shadow lookup's, a concave part the flat term's);
// - past a smoothly curved part's terminator (the entry face the map shows in front within 60 degrees of
//   the point's own, SINGLE_THROUGH_MIN_FACE_COS): the term itself for the light that entered at that face
//   (its cosine and normal). A sheet's far side and a sharp edge's are left to the light through thin
//   parts (its slab transmittance counts every order of scattering, the first included).
// Only a directional light, and only where the light reached the point through its own part (no air: the
// map's part layers); elsewhere the flat term. NumPy twin: skinlab/scene/optics/single_through.py.
#include "lib/sss_translucency.glsl"
#include "skinlab/constants.glsl"

const float SSS_SINGLE_THROUGH_DEPTHS[4] = float[4](SINGLE_THROUGH_D0, SINGLE_THROUGH_D1, SINGLE_THROUGH_D2, SINGLE_THROUGH_D3);

// One segment's part of the integral below: rate k = 1 + its slope, length ds, e0 and e1 its ends'
// exponentials: (e0 - e1) / k (both at most 1: finite however steep the segment), its series where
// sig k ds is small.
vec3 sss_single_through_segment(vec3 sig, float ds, float k, vec3 e0, vec3 e1) {
    vec3 x = sig * (k * ds);
    vec3 series = sig * ds * e0 * (1.0 - 0.5 * x);
    return mix((e0 - e1) / (abs(k) > 0.0 ? k : 1.0), series, lessThan(abs(x), vec3(1e-2)));
}

// int_0^inf sig e^{-sig (s + d(s))} ds for d piecewise linear through (s[j], d[j]), per channel (sig finite),
// e_j = e^{-sig (s_j + d_j)}; beyond the last point e_3 / (1 + its slope, at least 0).
vec3 sss_single_through_integral(vec3 sig, float s[4], float d[4]) {
    vec3 e[4];
    for (int j = 0; j < 4; ++j) e[j] = exp(-sig * (s[j] + d[j]));
    vec3 tot = vec3(0.0);
    for (int j = 0; j < 3; ++j) {
        float ds = s[j + 1] - s[j];
        tot += sss_single_through_segment(sig, ds, 1.0 + (d[j + 1] - d[j]) / ds, e[j], e[j + 1]);
    }
    float m = max((d[3] - d[2]) / (s[3] - s[2]), 0.0);
    return tot + e[3] / (1.0 + m);
}

float sss_single_mfp(vec3 sigma_t) {
    return dot(1.0 / max(sigma_t, vec3(1e-6)), vec3(LUMA_R, LUMA_G, LUMA_B));
}

// The quad's bilinear first surface where all four texels hold one (first_hit_quad without its fallback to
// the containing texel: at a silhouette in the light's view, no hit).
bool sss_single_through_first(DistanceQuad q, out float first) {
    first = mix(mix(q.d.x, q.d.y, q.f.x), mix(q.d.z, q.d.w, q.f.x), q.f.y);
    return q.inside && max(max(q.d.x, q.d.y), max(q.d.z, q.d.w)) < 1e29;
}

// The light's path inside (mm, refracted: the air path times `ratio`) to x, for a point on the view ray at
// s mm; where the map has no surface in front, the flat medium's path s cto / ct.
float sss_single_through_path(int slot, vec3 x, float s, float cto, float ct, float ratio) {
    float first;
    bool hit = sss_single_through_first(distance_quad(slot, x), first);
    return hit ? max(distance_from_light(slot, x) - first, 0.0) * u_mm_per_unit * ratio : s * cto / ct;
}

// Both uses for slot `slot`'s light at world (geometric normal ng, unit direction to the light l; the
// view's half sv, from the shading normal; sigma_t the real extinction per mm, the radius map's scale
// applied), the path's samples shared: gain, the lit side's factor on the flat term (ng.l > 0; at least
// 1, and 1 where it does not apply), and f, past a convex part's terminator (ng.l <= 0) the term itself
// per unit light (0 where it does not apply: a sheet, a sharp edge, the map without a surface or its slope
// there). Straight-line code (a software rasteriser runs a branch's masked side anyway).
void sss_single_through(int slot, vec3 world, vec3 ng, vec3 l, SingleView sv, vec3 sigma_extinction, out vec3 gain,
                        out vec3 f) {
    gain = vec3(1.0);
    f = vec3(0.0);
    // finite: a radius of 0 (or a denormal) makes the extinction infinite, and inf x 0 at the point a NaN
    vec3 sigma_t = min(sigma_extinction, vec3(SINGLE_THROUGH_MAX_SIGMA));
    float cg = dot(ng, l);
    bool lit = cg > 0.0;
    float eta = max(u_sss_eta, 1.0);
    vec3 p = world - u_thickness_shrink * ng;
    DistanceQuad q = distance_quad(slot, p);
    float first;
    bool hit = sss_single_through_first(q, first);
    vec4 ef = entry_face_quad(slot, q);
    float c = lit ? cg : max(ef.w, 1e-4);  // the entry cosine: the point's own on the lit side
    float ct = max(refract_cos(c, eta), 1e-4);
    float ratio = c / ct;
    float at = distance_from_light(slot, p);
    float mfp_l = sss_single_mfp(sigma_t);
    float s[4];
    float d[4];
    s[0] = 0.0;
    d[0] = lit ? 0.0 : max(at - first, 0.0) * u_mm_per_unit * ratio;
    for (int j = 1; j < 4; ++j) {  // unrolled: straight-line
        s[j] = SSS_SINGLE_THROUGH_DEPTHS[j] * mfp_l;
        d[j] = sss_single_through_path(slot, world + sv.to * (s[j] / u_mm_per_unit), s[j], sv.cto, ct, ratio);
    }
    vec3 integral = sss_single_through_integral(sigma_t, s, d);
    vec3 layers = part_layers(slot, p);
    bool own = !(layers.x < 1e29 && at > layers.x + u_part_gap);  // not past another part: else the flat term's
    if (u_light_eye[slot].w != 0.0 || sv.co <= 0.0 || !own) return;
    if (lit) {
        // at least 1; and 1 where it is within SINGLE_THROUGH_ROUNDING of it: a plane's, to fp32 rounding
        gain = integral * ((ct + sv.cto) / ct);
        gain = mix(gain, vec3(1.0), lessThan(gain, vec3(1.0 + SINGLE_THROUGH_ROUNDING)));
#ifdef MEASURE_ST_FLAT_LIT  // measurement variants (tools/closeup_variants.py): one side's term alone
        gain = vec3(1.0);
#endif
        return;
    }
#ifdef MEASURE_ST_NO_SHADOW
    return;
#endif
    // past a terminator: the entry face within 60 degrees of the point's own (a sheet's faces are opposed,
    // a sharp edge's at 90 degrees: the slab transmittance carries their light), and known
    if (ef.w <= 0.0 || dot(ng, ef.xyz) < SINGLE_THROUGH_MIN_FACE_COS || !hit) return;
    float ft = 1.0 - fresnel_from_cosines(c, ct, 1.0, eta);
    vec3 ti = -l / eta + (c / eta - ct) * ef.xyz;  // the beam refracted at the entry face
    float cos_s = clamp(-dot(ti, sv.to), -1.0, 1.0);
    f = u_sss_single * (ft * sv.t_out * hg_phase(cos_s, u_sss_g) / (eta * eta) * ratio) * integral;
}
