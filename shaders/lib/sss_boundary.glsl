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
