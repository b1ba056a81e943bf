// Single scattering under a light at a finite distance (point and spot lights): the factor on the
// BRDF-like single-scattering term (lib/profiles_single.glsl single_scatter_brdf), from the points on
// the refracted view ray seeing the light from their own direction and distance, through their own
// path inside (Gauss-Laguerre on NEAR_SINGLE_T / NEAR_SINGLE_W, the far light's decay the weight).
// NumPy twin and derivation: skinlab/scene/optics/near_single.py near_single_gain.
#include "lib/profiles_single.glsl"

const float SSS_NEAR_SINGLE_T[4] = float[4](NEAR_SINGLE_T0, NEAR_SINGLE_T1, NEAR_SINGLE_T2, NEAR_SINGLE_T3);
const float SSS_NEAR_SINGLE_W[4] = float[4](NEAR_SINGLE_W0, NEAR_SINGLE_W1, NEAR_SINGLE_W2, NEAR_SINGLE_W3);

// The direction inside the medium, pointing out, of light crossing the plane (normal ng) along the
// unit w (pointing out); mu_t its cosine to ng.
vec3 sss_refracted_up(vec3 w, vec3 ng, float eta, out float mu_t) {
    float mu = clamp(dot(w, ng), 0.0, 1.0);
    mu_t = refract_cos(mu, eta);
    vec3 t = (w - mu * ng) / eta + mu_t * ng;
    return t / max(length(t), 1e-30);
}

// d_mm: from the point to the light, millimetres; ng, v: unit geometric normal and direction to the
// eye; sigma_t: the real extinction per millimetre; eta: the relative index (at least 1); g: HG's
// anisotropy. 1 where the light grazes the plane; at most NEAR_SINGLE_MAX_GAIN.
vec3 sss_near_single_gain(vec3 d_mm, vec3 ng, vec3 v, vec3 sigma_t, float eta, float g) {
    float dist = length(d_mm);
    if (dist <= 0.0) return vec3(1.0);
    vec3 l = d_mm / dist;
    if (dot(l, ng) <= MIN_COS) return vec3(1.0);
    eta = max(eta, 1.0);
    float mu_ti, mu_to;
    vec3 tl = sss_refracted_up(l, ng, eta, mu_ti);
    vec3 tv = sss_refracted_up(v, ng, eta, mu_to);
    mu_ti = max(mu_ti, MIN_COS);
    mu_to = max(mu_to, MIN_COS);
    // distances in units of the (virtual) source's distance eta D; q = sigma_t eta D
    vec3 q = max(sigma_t * (eta * dist), vec3(NEAR_SINGLE_MIN_OPTICAL));
    float c = dot(tl, tv);
    float p0 = hg_phase(-c, g);
    float ratio = mu_to / mu_ti;
    vec3 qk = q * (1.0 + ratio);
    vec3 gain = vec3(0.0);
    for (int j = 0; j < 4; ++j) {
        vec3 s = SSS_NEAR_SINGLE_T[j] / qk;  // the path length on the view ray
        vec3 z = s * mu_to;                   // its depth
        vec3 r = sqrt(max(1.0 + s * (2.0 * c + s), vec3(1e-12)));  // |tl + tv s|: to the source
        vec3 s_in = r * z / (z + mu_ti);      // the part of it inside (the source's height: mu_ti)
        vec3 cos_s = -(c + s) / r;
        vec3 ph = vec3(hg_phase(cos_s.x, g), hg_phase(cos_s.y, g), hg_phase(cos_s.z, g));
        gain += SSS_NEAR_SINGLE_W[j] * (ph / p0) * exp(-q * (s_in - s * ratio)) / (r * r);
    }
    return min(gain, vec3(NEAR_SINGLE_MAX_GAIN));
}
