// Single scattering (Jensen 2001 BRDF-like term; pbrt-v4 BeamDiffusionSS radial form).
// See skinlab/scene/optics/single_scattering.py for the conventions.
#include "lib/profiles_common.glsl"

// cos_t^2 = 1 - (1 - c^2)/eta^2 = ((eta - 1)(eta + 1) + c^2)/eta^2: no cancellation at grazing
// incidence (exact c at eta = 1; a sum of non-negative terms for eta >= 1).
float refract_cos(float cos_i, float eta) {
    float c = clamp(cos_i, 0.0, 1.0);
    return sqrt(max((eta - 1.0) * (eta + 1.0) + c * c, 0.0)) / eta;
}

// The view's half of single_scatter_brdf, the same for every light (a pass with several lights makes it
// once): the view's cosine co, its refracted cosine cto and direction to inside, and the Fresnel
// transmission out t_out. single_scatter_brdf_view with it is single_scatter_brdf, operation for
// operation.
struct SingleView {
    float co;
    float cto;
    vec3 to;
    float t_out;
};

SingleView single_scatter_view(vec3 n, vec3 wo, float eta) {
    SingleView sv;
    sv.co = dot(n, wo);
    sv.cto = refract_cos(sv.co, eta);
    sv.to = -wo / eta + (sv.co / eta - sv.cto) * n;
    sv.t_out = 1.0 - fresnel_from_cosines(sv.co, sv.cto, 1.0, eta);
    return sv;
}

vec3 single_scatter_brdf_view(vec3 n, vec3 wi, SingleView sv, vec3 alpha, float eta, float g) {
    float ci = dot(n, wi);
    if (ci <= 0.0 || sv.co <= 0.0) return vec3(0.0);
    float cti = refract_cos(ci, eta);
    vec3 ti = -wi / eta + (ci / eta - cti) * n;
    float cos_s = clamp(-dot(ti, sv.to), -1.0, 1.0);
    float ft = (1.0 - fresnel_from_cosines(ci, cti, 1.0, eta)) * sv.t_out;
    return alpha * (ft * hg_phase(cos_s, g) / (max(cti + sv.cto, 1e-4) * eta * eta));  // 1/eta^2: solid angle
}

vec3 single_scatter_brdf(vec3 n, vec3 wi, vec3 wo, vec3 alpha, float eta, float g) {
    return single_scatter_brdf_view(n, wi, single_scatter_view(n, wo, eta), alpha, eta, g);
}

vec3 single_scatter_profile(float r, vec3 alpha, vec3 mfp, float eta, float g) {
    vec3 valid, inv_l2;
    vec3 x = optical_radius(r, mfp, valid, inv_l2);
    eta = clamp_eta(eta);
    float k = eta > 1.0 ? sqrt((eta - 1.0) * (eta + 1.0)) : 0.0;
    float m = eta > 1.0 ? 0.0 : (1.0 - eta) * (1.0 + eta);
    vec3 tc = x * k;
    vec3 acc = vec3(0.0);
    for (int i = 0; i < int(PBD_SAMPLES); ++i) {
        float q = depth_sample(i);
        vec3 t = tc + q;
        vec3 d2 = x * x + t * t;
        vec3 d = sqrt(d2);
        vec3 cos_o = t / d;
        vec3 ct2 = (eta > 1.0) ? q * (q + 2.0 * tc) : t * t + m * x * x;
        vec3 cos_t = sqrt(ct2 / d2);
        vec3 tr = vec3(1.0 - fresnel_from_cosines(cos_o.x, cos_t.x, eta, 1.0),
                       1.0 - fresnel_from_cosines(cos_o.y, cos_t.y, eta, 1.0),
                       1.0 - fresnel_from_cosines(cos_o.z, cos_t.z, eta, 1.0));
        vec3 ph = vec3(hg_phase(-cos_o.x, g), hg_phase(-cos_o.y, g), hg_phase(-cos_o.z, g));
        acc += exp(-(d + tc)) / d2 * ph * tr * cos_o;
    }
    return valid * alpha * (acc / PBD_SAMPLES) * inv_l2;
}
