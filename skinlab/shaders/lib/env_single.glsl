// Single scattering of the environment map's light (variant ENV_MAP; tables bound by
// skinlab/render/environment.py bind_env_bands). Jensen's single scattering with an isotropic phase
// function depends on the incident direction only through its cosine with the normal, so a sky of SH
// radiance sum L_lm Y_lm scatters sum_l lambda_l(mu) sum_m L_lm Y_lm(n) toward a view at cosine mu
// (Funk-Hecke; lambda_0 the uniform sky's table sss_single_ambient; lambda_1, lambda_2 per material:
// skinlab/scene/optics/boundary.py single_ambient_band), applied as a ratio to the irradiance map's E(n)
// (lib/environment.glsl env_band_ratio).
#include "lib/sss_boundary.glsl"
#include "lib/sky_occlusion.glsl"

uniform vec3 u_sss_single_band1[SSS_ANGULAR_NODES];  // lambda_1(mu) / A_colour
uniform vec3 u_sss_single_band2[SSS_ANGULAR_NODES];  // lambda_2(mu) / A_colour

// The map's single scattering toward a view at cosine mu, per unit base colour (unoccluded).
vec3 env_single(vec3 n, float mu) {
    float x = clamp(mu, 0.0, 1.0) * float(SSS_ANGULAR_NODES - 1);
    int i = min(int(floor(x)), SSS_ANGULAR_NODES - 2);
    float f = x - float(i);
    vec3 l0 = sss_single_ambient(mu);
    vec3 l1 = mix(u_sss_single_band1[i], u_sss_single_band1[i + 1], f);
    vec3 l2 = mix(u_sss_single_band2[i], u_sss_single_band2[i + 1], f);
    return env_map_irradiance(n) * env_band_ratio(n, l0, l1, l2, l0 * INV_PI);
}
