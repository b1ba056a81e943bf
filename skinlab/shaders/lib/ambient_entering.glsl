// The ambient light entering a medium's multiple scattering, per unit base colour (every technique's
// entering light: techniques/tsd/irradiance.frag, lib/sss_local.glsl, techniques/preintegrated). The
// uniform sky and the bounce light enter as light from all around, pi L x u_sss_entry_diffuse; with
// variant ENV_MAP the map's light (at the normal set with ambient_set_normal, less what the scene
// hides) enters as int L A_ms(n.w) (n.w) dw / A_colour with A_ms / A_colour fitted by c_0 + c_1 t + c_2 t^2
// (skinlab/scene/optics/boundary.py entry_kernel_coefficients): c_0 E(n) + c_1 int L t^2 dw + c_2 int L
// t^3 dw from the irradiance map and the map's kernel maps (lib/environment.glsl env_kernel). Light
// from near the normal enters differently from grazing light; a uniform sky's average is exact only for
// a uniform sky, and nine SH bands with per-band factors were 2-5 % off per normal under the studio
// map's rest. NumPy twin: skinlab/render/environment.py env_entering.
#include "lib/ambient.glsl"
#include "lib/sss_boundary.glsl"
#ifdef ENV_MAP
uniform vec3 u_sss_entry_kernel[3];  // c_0, c_1, c_2 per channel
#endif

vec3 ambient_entering(float occlusion) {
#ifdef ENV_MAP
    vec3 n = ambient_normal;
    vec3 entering = u_sss_entry_kernel[0] * env_map_irradiance(n)
                  + u_sss_entry_kernel[1] * env_kernel(n, ENV_KERNEL_NODES)
                  + u_sss_entry_kernel[2] * env_kernel(n, ENV_KERNEL_NODES + 1);
    return PI * ambient_uniform(occlusion) * u_sss_entry_diffuse
         + max(entering, 0.0) * (occlusion * env_visible_share(n));
#else
    return PI * ambient_radiance(occlusion) * u_sss_entry_diffuse;
#endif
}
