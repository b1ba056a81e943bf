// The ambient light entering a medium's multiple scattering, per unit base colour (every technique's
// entering light: techniques/tsd/irradiance.frag, lib/sss_local.glsl, techniques/preintegrated). The
// uniform sky and the bounce light enter as light from all around, pi L x u_sss_entry_diffuse; with
// variant ENV_MAP the map's light (at the normal set with ambient_set_normal, less what the scene
// hides) enters by its SH bands: a sky sum L_lm Y_lm brings sum_l eps_l sum_m L_lm Y_lm(n) into the
// profile, eps_l = 2 pi int_0^1 A_ms(m) m P_l(m) dm / A_colour (skinlab/scene/optics/boundary.py
// entry_band_tables; eps_0 = pi u_sss_entry_diffuse), applied as a ratio to the irradiance map's E(n).
// Light from near the normal enters differently from grazing light; a uniform sky's average is exact
// only for a uniform sky.
#include "lib/ambient.glsl"
#include "lib/sss_boundary.glsl"
#ifdef ENV_MAP
uniform vec3 u_sss_entry_bands[3];  // eps_0, eps_1, eps_2 per channel
#endif

vec3 ambient_entering(float occlusion) {
#ifdef ENV_MAP
    vec3 n = ambient_normal;
    vec3 ratio = env_band_ratio(n, u_sss_entry_bands[0], u_sss_entry_bands[1], u_sss_entry_bands[2],
                                u_sss_entry_diffuse);
    return PI * ambient_uniform(occlusion) * u_sss_entry_diffuse + env_diffuse_irradiance(n) * (occlusion * ratio);
#else
    return PI * ambient_radiance(occlusion) * u_sss_entry_diffuse;
#endif
}
