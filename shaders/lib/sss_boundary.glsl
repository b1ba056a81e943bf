// How light enters and leaves a scattering medium, shared by every subsurface technique.
// NumPy twin: scene/optics/boundary.py (the tables, table_lookup) and
// scene/optics/single_scattering.py (single_scatter_brdf). Bound per mesh by the forward pass
// (app/render/boundary.py); a mesh the technique does not shade gets zeros.
//
// Multiple scattering, separable and reciprocal: f_ms = A_ms(mu0) A_ms(mu) / (pi A_ms_d).
//   entry(mu0) = A_ms(mu0) / A_colour  multiplies base colour x irradiance entering the profile
//   exit(mu)   = A_ms(mu) / A_ms_d     the angular distribution of what leaves (hemispherical mean 1)
// Single scattering (Jensen 2001): alpha F_t F_t p / (|n.T_i| + |n.T_o|), added per light, unblurred.
#include "lib/profiles_single.glsl"

#define SSS_ANGULAR_NODES 17
uniform vec3 u_sss_entry[SSS_ANGULAR_NODES];  // at cosines i / (SSS_ANGULAR_NODES - 1)
uniform vec3 u_sss_exit[SSS_ANGULAR_NODES];
uniform vec3 u_sss_entry_diffuse;  // A_ms_d / A_colour: uniform (ambient) light
uniform vec3 u_sss_single;         // alpha / A_colour (0: no single-scattering term)
uniform float u_sss_eta;           // relative index of the boundary (1: index-matched)

vec3 sss_entry(float mu) {
    float x = clamp(mu, 0.0, 1.0) * float(SSS_ANGULAR_NODES - 1);
    int i = min(int(floor(x)), SSS_ANGULAR_NODES - 2);
    return mix(u_sss_entry[i], u_sss_entry[i + 1], x - float(i));
}

vec3 sss_exit(float mu) {
    float x = clamp(mu, 0.0, 1.0) * float(SSS_ANGULAR_NODES - 1);
    int i = min(int(floor(x)), SSS_ANGULAR_NODES - 2);
    return mix(u_sss_exit[i], u_sss_exit[i + 1], x - float(i));
}

// Single scattering toward v of light from l (per unit irradiance on a surface facing the light,
// i.e. multiply by e NoL), per unit base colour.
vec3 sss_single_brdf(vec3 n, vec3 l, vec3 v) {
    return single_scatter_brdf(n, l, v, u_sss_single, max(u_sss_eta, 1.0), 0.0);
}

// Light through thin parts (NumPy twin: scene/optics/boundary.py slab_transmittance): what crosses a
// slab d mm thick and leaves through its far side, relative to what the entry factor says a
// semi-infinite medium returns (diffusion between extrapolated boundaries, times 1 - e^{-d/l}).
uniform vec3 u_sss_sigma_tr;  // 1/mm
uniform vec3 u_sss_z0;        // source depth: the mean free path, mm
uniform vec3 u_sss_zb;        // extrapolation distance 2 A D, mm

vec3 sss_slab_transmittance(float d_mm) {
    float d = max(d_mm, 0.0);
    vec3 a = u_sss_z0 + u_sss_zb;
    vec3 b = vec3(d) + 2.0 * u_sss_zb;
    vec3 s = u_sss_sigma_tr;
    vec3 num = vec3(s.x > 0.0 ? -em1(-2.0 * s.x * a.x) : 2.0 * a.x, s.y > 0.0 ? -em1(-2.0 * s.y * a.y) : 2.0 * a.y,
                    s.z > 0.0 ? -em1(-2.0 * s.z * a.z) : 2.0 * a.z);
    vec3 den = vec3(s.x > 0.0 ? -em1(-2.0 * s.x * b.x) : 2.0 * b.x, s.y > 0.0 ? -em1(-2.0 * s.y * b.y) : 2.0 * b.y,
                    s.z > 0.0 ? -em1(-2.0 * s.z * b.z) : 2.0 * b.z);
    vec3 hit = -em1(-d / max(u_sss_z0, vec3(1e-30)));  // the light that collides in the slab at all
    vec3 t = hit * exp(s * (2.0 * a - b)) * vec3(den.x > 0.0 ? num.x / den.x : 0.0, den.y > 0.0 ? num.y / den.y : 0.0,
                                           den.z > 0.0 ? num.z / den.z : 0.0);
    return vec3(u_sss_z0.x > 0.0 ? t.x : 0.0, u_sss_z0.y > 0.0 ? t.y : 0.0, u_sss_z0.z > 0.0 ? t.z : 0.0);
}

// Single scattering through a slab d mm thick, index-matched, for light at (refracted) cosine mu_i,
// per unit base colour (u_sss_single = alpha / A_colour), over all exit directions. NumPy twin:
// scene/optics/boundary.py slab_single_transmittance (same 8 Gauss-Legendre nodes).
uniform vec3 u_sss_mfp;  // mean free path l per channel, mm (0: no scattering)
const float SLAB_MU[8] = float[8](0.019855071751231912, 0.10166676129318664, 0.2372337950418355, 0.4082826787521751,
                                  0.5917173212478248, 0.7627662049581645, 0.8983332387068134, 0.9801449282487681);
const float SLAB_W[8] = float[8](0.05061426814518853, 0.11119051722668721, 0.15685332293894344, 0.18134189168918083,
                                 0.18134189168918083, 0.15685332293894344, 0.11119051722668721, 0.05061426814518853);

vec3 sss_slab_single(float mu_i, float d_mm) {
    float mi = clamp(mu_i, 1e-4, 1.0);
    vec3 valid = vec3(greaterThan(u_sss_mfp, vec3(0.0)));
    vec3 tau = max(d_mm, 0.0) / max(u_sss_mfp, vec3(1e-30));
    vec3 acc = vec3(0.0);
    for (int k = 0; k < 8; ++k) {
        float mu = SLAB_MU[k];
        float diff = mi - mu;
        vec3 r = abs(diff) < 1e-3 ? tau * exp(-tau / mu) / (mu * mu) : (exp(-tau / mi) - exp(-tau / mu)) / diff;
        acc += SLAB_W[k] * mu * r;
    }
    return valid * 0.5 * u_sss_single * acc;
}
