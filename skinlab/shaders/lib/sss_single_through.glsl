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
// Two uses (passes/forward.frag, variant SSS_SINGLE_THROUGH; RenderSettings.single_through):
// - the lit side: the flat term times sss_single_through_gain, I(d from the map) / I(flat), at least 1
//   (a cast shadow stays the shadow lookup's, a concave part the flat term's);
// - the shadow side of a convex part's terminator (the entry face the map shows in front on the point's
//   own side: a bulge, lib/sss_translucency.glsl sss_through_cosine), sss_single_through_shadow: the
//   light entered at that face (its cosine and normal). A sheet's far side is left to the light through
//   thin parts (its slab transmittance counts every order of scattering, the first included).
// Only a directional light, and only where the light reached the point through its own part (no air: the
// map's part layers); elsewhere the flat term. NumPy twin: skinlab/scene/optics/single_through.py.
#include "lib/sss_translucency.glsl"
#include "skinlab/constants.glsl"

const float SSS_SINGLE_THROUGH_DEPTHS[4] = float[4](SINGLE_THROUGH_D0, SINGLE_THROUGH_D1, SINGLE_THROUGH_D2, SINGLE_THROUGH_D3);

// int_0^inf sig e^{-sig (s + d(s))} ds for d piecewise linear through (s[j], d[j]), per channel: on a
// segment of rate k = 1 + its slope, (e_j - e_j+1) / k with e_j = e^{-sig (s_j + d_j)} (both at most 1:
// finite however steep the segment), its series where sig k ds is small; beyond the last point e_3 / (1 + m).
vec3 sss_single_through_integral(vec3 sig, float s[4], float d[4]) {
    vec3 e[4];
    for (int j = 0; j < 4; ++j) e[j] = exp(-sig * (s[j] + d[j]));
    vec3 tot = vec3(0.0);
    for (int j = 0; j < 3; ++j) {
        float ds = s[j + 1] - s[j];
        float k = 1.0 + (d[j + 1] - d[j]) / ds;
        vec3 x = sig * (k * ds);
        vec3 series = sig * ds * e[j] * (1.0 - 0.5 * x);
        tot += mix((e[j] - e[j + 1]) / (abs(k) > 0.0 ? k : 1.0), series, lessThan(abs(x), vec3(1e-2)));
    }
    float m = max((d[3] - d[2]) / (s[3] - s[2]), 0.0);
    return tot + e[3] / (1.0 + m);
}

// The path inside (mm, refracted) to the points at SSS_SINGLE_THROUGH_DEPTHS x mfp_l along the refracted
// view ray from world; d[0] = d0 (the point itself). Where the map has no surface in front of a point, the
// flat medium's path there.
void sss_single_through_path(int slot, vec3 world, SingleView sv, float ct, float ratio, float mfp_l, float d0,
                             out float s[4], out float d[4]) {
    s[0] = 0.0;
    d[0] = d0;
    for (int j = 1; j < 4; ++j) {
        s[j] = SSS_SINGLE_THROUGH_DEPTHS[j] * mfp_l;
        vec3 x = world + sv.to * (s[j] / u_mm_per_unit);
        float first;
        float dj = s[j] * sv.cto / ct;
        if (first_hit_distance(slot, x, first)) dj = max(distance_from_light(slot, x) - first, 0.0) * u_mm_per_unit * ratio;
        d[j] = dj;
    }
}

float sss_single_mfp(vec3 sigma_t) {
    return dot(1.0 / max(sigma_t, vec3(1e-6)), vec3(LUMA_R, LUMA_G, LUMA_B));
}

// Both uses for slot `slot`'s light at world (geometric normal ng, unit direction to the light l; the
// view's half sv, from the shading normal; sigma_t the real extinction per mm, the radius map's scale
// applied), the path's samples shared: gain, the lit side's factor on the flat term (ng.l > 0; at least
// 1, and 1 where it does not apply), and f, past a convex part's terminator (ng.l <= 0) the term itself
// per unit light (0 where it does not apply: a sheet, the map without a surface or its slope there).
void sss_single_through(int slot, vec3 world, vec3 ng, vec3 l, SingleView sv, vec3 sigma_t, out vec3 gain, out vec3 f) {
    gain = vec3(1.0);
    f = vec3(0.0);
    if (u_light_eye[slot].w != 0.0 || sv.co <= 0.0) return;
    vec3 p = world - u_thickness_shrink * ng;
    float at = distance_from_light(slot, p);
    vec3 layers = part_layers(slot, p);
    if (layers.x < 1e29 && at > layers.x + u_part_gap) return;  // past another part: the flat term's
    float cg = dot(ng, l);
    DistanceQuad q = distance_quad(slot, p);
    vec4 ef = entry_face_quad(slot, q);
    float first;
    bool hit = first_hit_quad(slot, q, first);
    bool lit = cg > 0.0;
    // past a terminator: the entry face within 60 degrees of the point's own (a sheet's faces are opposed,
    // a sharp edge's at 90 degrees: the slab transmittance carries their light), and known
    if (!lit && (ef.w <= 0.0 || dot(ng, ef.xyz) < SINGLE_THROUGH_MIN_FACE_COS || !hit)) return;
    float eta = max(u_sss_eta, 1.0);
    float c = lit ? cg : ef.w;
    float ct = max(refract_cos(c, eta), 1e-4);
    float ratio = c / ct;
    float d0 = lit ? 0.0 : max(at - first, 0.0) * u_mm_per_unit * ratio;
    float s[4];
    float d[4];
    sss_single_through_path(slot, world, sv, ct, ratio, sss_single_mfp(sigma_t), d0, s, d);
    vec3 integral = sss_single_through_integral(sigma_t, s, d);
    if (lit) {
        gain = max(integral * ((ct + sv.cto) / ct), vec3(1.0));
#ifdef MEASURE_ST_FLAT_LIT  // measurement variants (tools/closeup_variants.py): one side's term alone
        gain = vec3(1.0);
#endif
        return;
    }
#ifdef MEASURE_ST_NO_SHADOW
    return;
#endif
    float ft = 1.0 - fresnel_from_cosines(c, ct, 1.0, eta);
    vec3 ti = -l / eta + (c / eta - ct) * ef.xyz;  // the beam refracted at the entry face
    float cos_s = clamp(-dot(ti, sv.to), -1.0, 1.0);
    f = u_sss_single * (ft * sv.t_out * hg_phase(cos_s, u_sss_g) / (eta * eta) * ratio) * integral;
}
