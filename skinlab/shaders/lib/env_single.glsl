// Single scattering of the environment map's light (variant ENV_MAP; tables bound by
// skinlab/render/environment.py bind_env_bands). Jensen's single scattering with an isotropic phase
// function depends on the incident direction only through its cosine with the normal, so a sky of SH
// radiance sum L_lm Y_lm scatters sum_l lambda_l(mu) sum_m L_lm Y_lm(n) toward a view at cosine mu
// (Funk-Hecke; lambda_0 the uniform sky's table sss_single_ambient; lambda_1, lambda_2 per material:
// skinlab/scene/optics/boundary.py single_ambient_band), applied as a ratio to the irradiance map's E(n)
// (lib/environment.glsl env_band_ratio). Index-matched (u_sss_eta = 1), where the kernel t / (mu + t) is
// nearly a step toward grazing views and nine bands are far from it (the ratio read 7-20 % off per
// normal under the studio map's rest), the map's own kernel maps instead: exact, linear in mu between
// the 17 view cosines (u_sss_env_single x lib/environment.glsl env_kernel; NumPy twin
// skinlab/render/environment.py env_single).
#include "lib/sss_boundary.glsl"
#include "lib/sky_occlusion.glsl"

uniform vec3 u_sss_single_band1[SSS_ANGULAR_NODES];  // lambda_1(mu) / A_colour
uniform vec3 u_sss_single_band2[SSS_ANGULAR_NODES];  // lambda_2(mu) / A_colour
uniform vec3 u_sss_env_single;  // alpha / A_colour of the (reduced, isotropic) medium, as u_sss_single_ambient

// The map's single scattering toward a view at cosine mu, per unit base colour (unoccluded).
vec3 env_single(vec3 n, float mu) {
    float x = clamp(mu, 0.0, 1.0) * float(SSS_ANGULAR_NODES - 1);
    int i = min(int(floor(x)), SSS_ANGULAR_NODES - 2);
    float f = x - float(i);
    if (u_sss_eta <= 1.0 + 1e-6) return u_sss_env_single * mix(env_kernel(n, i), env_kernel(n, i + 1), f);
    vec3 l0 = sss_single_ambient(mu);
    vec3 l1 = mix(u_sss_single_band1[i], u_sss_single_band1[i + 1], f);
    vec3 l2 = mix(u_sss_single_band2[i], u_sss_single_band2[i + 1], f);
    return env_map_irradiance(n) * env_band_ratio(n, l0, l1, l2, l0 * INV_PI);
}
