// How light enters and leaves a scattering medium, shared by every subsurface technique.
// NumPy twin: skinlab/scene/optics/boundary.py (the tables, table_lookup) and
// skinlab/scene/optics/single_scattering.py (single_scatter_brdf). Bound per mesh by the forward pass
// (skinlab/render/boundary.py); a mesh the technique does not shade gets zeros.
//
// Multiple scattering, separable and reciprocal: f_ms = A_ms(mu0) A_ms(mu) / (pi A_ms_d).
//   entry(mu0) = A_ms(mu0) / A_colour  multiplies base colour x irradiance entering the profile
//   exit(mu)   = A_ms(mu) / A_ms_d     the angular distribution of what leaves (hemispherical mean 1)
//   at eta = 1 plus its non-separable rest (sss_ms_rest), the exact BRDF's, added per light
// Single scattering (Jensen 2001): alpha F_t F_t p / (|n.T_i| + |n.T_o|), added per light, unblurred.
#include "lib/profiles_single.glsl"

#define SSS_ANGULAR_NODES 17
uniform vec3 u_sss_entry[SSS_ANGULAR_NODES];  // at cosines i / (SSS_ANGULAR_NODES - 1)
uniform vec3 u_sss_exit[SSS_ANGULAR_NODES];
uniform vec3 u_sss_single_ambient[SSS_ANGULAR_NODES];  // A_ss(mu) / A_colour: single scattering of a uniform sky
uniform vec3 u_sss_entry_diffuse;  // A_ms_d / A_colour: uniform (ambient) light
uniform vec3 u_sss_single;         // alpha / A_colour (0: no single-scattering term)
uniform float u_sss_eta;           // relative index of the boundary (1: index-matched)
uniform float u_sss_g;             // Henyey-Greenstein g of the medium (material subsurface_scatter_anisotropy)
uniform vec3 u_sss_sigma_t;        // the real extinction 1 / l per channel, per mm (single scattering of near lights)

vec3 sss_entry(float mu) {
    float x = clamp(mu, 0.0, 1.0) * float(SSS_ANGULAR_NODES - 1);
    int i = min(int(floor(x)), SSS_ANGULAR_NODES - 2);
    return mix(u_sss_entry[i], u_sss_entry[i + 1], x - float(i));
}

// What the separable multiple-scattering BRDF misses, per unit base colour (NumPy twin:
// skinlab/scene/optics/boundary.py ms_rest_table, ms_rest_lookup): at eta = 1 Chandrasekhar's exact
// f_ms(mu, mu0) less entry(mu0) exit(mu) / pi, rows the view's cosine mu_i, columns the light's mu0_j,
// at i / (SSS_MS_REST_NODES - 1), bilinear in between; zero at eta > 1. Added per light where the
// light lands, as single scattering is (passes/forward.frag): it moves light between directions
// only (for every mu0 it integrates to 0 over the exit).
#define SSS_MS_REST_NODES 9
uniform vec3 u_sss_ms_rest[SSS_MS_REST_NODES * SSS_MS_REST_NODES];
uniform float u_sss_ms_rest_on;  // 1 where the table is not all zero (the material's own: no divergence)

vec3 sss_ms_rest(float mu, float mu0) {
    float x = clamp(mu, 0.0, 1.0) * float(SSS_MS_REST_NODES - 1);
    float y = clamp(mu0, 0.0, 1.0) * float(SSS_MS_REST_NODES - 1);
    int i = min(int(floor(x)), SSS_MS_REST_NODES - 2);
    int j = min(int(floor(y)), SSS_MS_REST_NODES - 2);
    float fx = x - float(i), fy = y - float(j);
    int r = i * SSS_MS_REST_NODES + j;
    vec3 lo = mix(u_sss_ms_rest[r], u_sss_ms_rest[r + 1], fy);
    vec3 hi = mix(u_sss_ms_rest[r + SSS_MS_REST_NODES], u_sss_ms_rest[r + SSS_MS_REST_NODES + 1], fy);
    return mix(lo, hi, fx);
}

vec3 sss_exit(float mu) {
    float x = clamp(mu, 0.0, 1.0) * float(SSS_ANGULAR_NODES - 1);
    int i = min(int(floor(x)), SSS_ANGULAR_NODES - 2);
    return mix(u_sss_exit[i], u_sss_exit[i + 1], x - float(i));
}

// Single scattering of uniform (ambient) light of radiance 1 toward a view at cosine mu, per unit base
// colour (NumPy twin: skinlab/scene/optics/boundary.py single_ambient_albedo, table_lookup).
vec3 sss_single_ambient(float mu) {
    float x = clamp(mu, 0.0, 1.0) * float(SSS_ANGULAR_NODES - 1);
    int i = min(int(floor(x)), SSS_ANGULAR_NODES - 2);
    return mix(u_sss_single_ambient[i], u_sss_single_ambient[i + 1], x - float(i));
}

// Single scattering toward v of light from l (per unit irradiance on a surface facing the light,
// i.e. multiply by e NoL), per unit subsurface albedo; the medium's phase function has g = u_sss_g (its
// real single-scattering albedo is in u_sss_single: skinlab/render/boundary.py single_scattering_factor).
vec3 sss_single_brdf(vec3 n, vec3 l, vec3 v) {
    return single_scatter_brdf(n, l, v, u_sss_single, max(u_sss_eta, 1.0), u_sss_g);
}

// The same in two halves: the view's (sss_single_view, once per fragment) and each light's.
SingleView sss_single_view(vec3 n, vec3 v) { return single_scatter_view(n, v, max(u_sss_eta, 1.0)); }

vec3 sss_single_brdf_view(vec3 n, vec3 l, SingleView sv) {
    return single_scatter_brdf_view(n, l, sv, u_sss_single, max(u_sss_eta, 1.0), u_sss_g);
}

// Light through thin parts (NumPy twin: skinlab/scene/optics/slab.py slab_through): of the irradiance (normal
// to the light) arriving at cosine `back` on the far face of a part d_mm thick, what leaves the near
// face after scattering inside, per unit base colour: the exact diffuse transmittance of the
// index-matched slab (doubling method, all orders) from a table in the cosine (i / 8) and the optical
// thickness tau = d / l (half octaves from 1/16 to 64 mean free paths; ln T - ln(tau / (1 + tau))
// linear in tau and in the cosine); thinner: linear in tau to 0, thicker: e^{-k (tau - 64)} 64 / tau. At eta > 1 Fresnel
// transmission in, the table at the refracted cosine, and u_sss_slab_out = 1 - F_dr out.
#define SSS_SLAB_MU 9
#define SSS_SLAB_TAU 21
#define SSS_SLAB_LOG2_TAU_MIN (-4.0)
uniform vec3 u_sss_slab[SSS_SLAB_MU * SSS_SLAB_TAU];  // ln(T / A_colour), row i * SSS_SLAB_TAU + j
uniform vec3 u_sss_mfp;         // mean free path l per channel, mm (0: no scattering)
uniform vec3 u_sss_slab_decay;  // k = sqrt(3 (1 - a)) per mean free path beyond the table
uniform float u_sss_slab_out;   // 1 - F_dr(eta): diffuse Fresnel transmission out (1 at eta 1)

float sss_slab_channel(int i, float fm, float tau, int c, float k) {
    float tmin = exp2(SSS_SLAB_LOG2_TAU_MIN);
    float tmax = exp2(SSS_SLAB_LOG2_TAU_MIN + 0.5 * float(SSS_SLAB_TAU - 1));
    float tc = clamp(tau, tmin, tmax);
    int j = min(int(floor((log2(tc) - SSS_SLAB_LOG2_TAU_MIN) * 2.0)), SSS_SLAB_TAU - 2);
    j = max(j, 0);
    float t0 = exp2(SSS_SLAB_LOG2_TAU_MIN + 0.5 * float(j));
    float ft = clamp((tc - t0) / (t0 * (sqrt(2.0) - 1.0)), 0.0, 1.0);
    int r0 = i * SSS_SLAB_TAU + j;
    int r1 = r0 + SSS_SLAB_TAU;
    // ln T - ln(tau / (1 + tau)) linear in tau between the nodes (slab.py _knee: the knee taken out)
    float k0 = log(t0 / (1.0 + t0)), t1 = t0 * sqrt(2.0), k1 = log(t1 / (1.0 + t1)), kc = log(tc / (1.0 + tc));
    float v0 = mix(u_sss_slab[r0][c] - k0, u_sss_slab[r0 + 1][c] - k1, ft) + kc;
    float v1 = mix(u_sss_slab[r1][c] - k0, u_sss_slab[r1 + 1][c] - k1, ft) + kc;
    float v = exp(mix(v0, v1, fm));  // ln T linear in the cosine too
    if (tau < tmin) v *= tau / tmin;
    else if (tau > tmax) v *= exp(-k * (tau - tmax)) * tmax / tau;
    return v;
}

vec3 sss_slab_through(float back, float d_mm) {
    float eta = max(u_sss_eta, 1.0);
    float b = clamp(back, 0.0, 1.0);
    float t_in = 1.0;
    if (eta > 1.0) {
        t_in = 1.0 - fresnel_dielectric(b, eta);
        b = refract_cos(b, eta);
    }
    float xm = b * float(SSS_SLAB_MU - 1);
    int i = min(int(floor(xm)), SSS_SLAB_MU - 2);
    float fm = xm - float(i);
    float d = max(d_mm, 0.0);
    vec3 out_ = vec3(0.0);
    for (int c = 0; c < 3; ++c) {
        float l = u_sss_mfp[c];
        if (l > 0.0 && d > 0.0) out_[c] = sss_slab_channel(i, fm, d / l, c, u_sss_slab_decay[c]);
    }
    return (t_in * u_sss_slab_out) * out_;
}

// The exit factor of light that came through a part d_mm thick, arriving on its far face at cosine
// mu0 and leaving at cosine mu (cosine-weighted hemispherical mean 1 over mu, like sss_exit):
// (1 - F(mu)) [u(mu_t) - h(mu_t) q] / (A - B q), q = h(mu0_t) / u(mu0_t), u = T / T_d the slab's own
// directional transmittance over its mean, h the leading eigenfunction of the rest of the reciprocal
// transmitted radiance (skinlab/scene/optics/slab.py: within 2 % of the exact slab for albedos >= 0.5 up to
// 8 mean free paths). tau = d / l clamped to the table; 1 where a channel does not scatter.
// NumPy twin: skinlab/scene/optics/slab.py slab_exit.
#define SSS_EXIT_Q_MAX 2.0
uniform vec3 u_sss_slab_norm[SSS_SLAB_TAU];            // ln T_d per thickness node
uniform vec3 u_sss_slab_h[SSS_SLAB_MU * SSS_SLAB_TAU];  // h, rows as u_sss_slab
uniform vec3 u_sss_slab_ab[2 * SSS_SLAB_TAU];           // A per thickness node, then B

vec2 sss_slab_uh(float x, int j, float ft, float lnn, int c) {
    float xm = x * float(SSS_SLAB_MU - 1);
    int i = min(int(floor(xm)), SSS_SLAB_MU - 2);
#ifdef MEASURE_SLAB_CONST_INDEX
    i = 3;
#endif
    float fm = xm - float(i);
    int r0 = i * SSS_SLAB_TAU + j;
    int r1 = r0 + SSS_SLAB_TAU;
    float u0 = exp(mix(u_sss_slab[r0][c], u_sss_slab[r0 + 1][c], ft) - lnn);
    float u1 = exp(mix(u_sss_slab[r1][c], u_sss_slab[r1 + 1][c], ft) - lnn);
    float h0 = mix(u_sss_slab_h[r0][c], u_sss_slab_h[r0 + 1][c], ft);
    float h1 = mix(u_sss_slab_h[r1][c], u_sss_slab_h[r1 + 1][c], ft);
    return vec2(mix(u0, u1, fm), mix(h0, h1, fm));
}

vec3 sss_slab_exit(float mu, float mu0, float d_mm) {
    float eta = max(u_sss_eta, 1.0);
    float m = clamp(mu, 0.0, 1.0), m0 = clamp(mu0, 0.0, 1.0);
    float t_out = 1.0;
    if (eta > 1.0) {
        t_out = 1.0 - fresnel_dielectric(m, eta);
        m = refract_cos(m, eta);
        m0 = refract_cos(m0, eta);
    }
    float d = max(d_mm, 0.0);
    float tmin = exp2(SSS_SLAB_LOG2_TAU_MIN);
    float tmax = exp2(SSS_SLAB_LOG2_TAU_MIN + 0.5 * float(SSS_SLAB_TAU - 1));
    vec3 out_ = vec3(1.0);
    for (int c = 0; c < 3; ++c) {
        float l = u_sss_mfp[c];
        if (l <= 0.0) continue;
        float tc = clamp(d / l, tmin, tmax);
        int j = max(min(int(floor((log2(tc) - SSS_SLAB_LOG2_TAU_MIN) * 2.0)), SSS_SLAB_TAU - 2), 0);
#ifdef MEASURE_SLAB_CONST_INDEX  // a measurement variant (tools/orbit_cost.py): the tables read at fixed rows
        j = 5;
#endif
        float t0 = exp2(SSS_SLAB_LOG2_TAU_MIN + 0.5 * float(j));
#ifdef MEASURE_SLAB_NO_LOG  // a measurement variant (tools/orbit_cost.py): no log2 or exp2 for the node
        j = 5;
        t0 = 0.4;
#endif
        float ft = clamp((tc - t0) / (t0 * (sqrt(2.0) - 1.0)), 0.0, 1.0);
        float lnn = mix(u_sss_slab_norm[j][c], u_sss_slab_norm[j + 1][c], ft);
        float a = mix(u_sss_slab_ab[j][c], u_sss_slab_ab[j + 1][c], ft);
        float b = mix(u_sss_slab_ab[SSS_SLAB_TAU + j][c], u_sss_slab_ab[SSS_SLAB_TAU + j + 1][c], ft);
        vec2 uh = sss_slab_uh(m, j, ft, lnn, c);
#ifdef MEASURE_SLAB_VIEW_ONLY  // a measurement variant (tools/orbit_cost.py): only the view's half computed
        float q = m0 * d;
        a = 1.0 + q;
        b = q;
#else
        vec2 uh0 = sss_slab_uh(m0, j, ft, lnn, c);
        float q = clamp(uh0.y / max(uh0.x, 1e-30), -SSS_EXIT_Q_MAX, SSS_EXIT_Q_MAX);
#endif
        out_[c] = t_out * max(uh.x - uh.y * q, 0.0) / max(max(a - b * q, 0.5 * a), 1e-30);
    }
    return out_;
}
