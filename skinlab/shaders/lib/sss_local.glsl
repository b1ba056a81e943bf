// The subsurface part of the diffuse term without a convolution, for the hooks of techniques that
// scatter locally or in screen space (tint, ssss, disk, tsd's narrow fallback): the same entry/exit
// model as texture-space
// diffusion (lib/sss_boundary.glsl: the multiple-scattering albedo at the light's incidence in, its
// angular distribution out) so that only the convolution differs between the techniques. Needs the
// material uniforms and lib/ambient.glsl. Variant SSS_TRANSLUCENCY: plus the light through thin parts
// (lib/sss_translucency.glsl, the same term texture-space diffusion gathers in its irradiance
// pass), entering with the rest, so a screen-space blur spreads it as texture-space diffusion's does.
#include "lib/sss_boundary.glsl"
#include "lib/surface_inputs.glsl"
#include "lib/ambient.glsl"
#include "lib/ambient_entering.glsl"
#ifdef SSS_TRANSLUCENCY
#include "lib/sss_translucency.glsl"
#endif

// This hook takes each light's entering light in the forward pass: that pass gives it the shadow per
// channel, spread as the entry is (passes/forward.frag, lib/surface_inputs.glsl sss_entry_ramp).
#define SSS_HOOK_GATHERS_LIGHT
vec3 sss_in = vec3(0.0);  // irradiance entering the medium (this fragment)
// The multiple scattering's non-separable rest (lib/sss_boundary.glsl sss_ms_rest) goes with the light
// into the technique's diffusion (for a screen-space blur: spread with it); a hook of the separable
// boundary that cannot spread it has the forward pass add it where the light lands instead
// (SSS_MS_REST_LANDS, passes/forward.frag).
vec3 sss_rest = vec3(0.0);  // sum of e NoL rest(mu, mu0) over the lights (radiance x pi per base colour)

void sss_add_light(Surface s, vec3 e, vec3 vis, float NoL) {
    sss_in += e * (vis * NoL) * sss_entry(NoL);
#ifdef SSS_MS_REST  // the material's rest is not all zero (skinlab/render/boundary.py boundary_defines)
    if (u_sss_ms_rest_on > 0.0) sss_rest += e * (vis * NoL) * sss_ms_rest(abs(s.NoV), NoL);
#endif
}

// The radiance leaving the medium toward the viewer at s for subsurface weight sss_w (ambient
// included), with the subsurface albedo s.m.sss_albedo.
vec3 sss_local_radiance(Surface s, float sss_w) {
    vec3 entering = sss_in + ambient_entering(s.m.occlusion);
    vec3 leaving = entering * sss_exit(abs(s.NoV)) + PI * sss_rest;
#ifdef SSS_TRANSLUCENCY
    // light through thin parts leaves with its own angular distribution (lib/sss_boundary.glsl sss_slab_exit)
    vec3 through_in;
    leaving += sss_translucent_toward(s.position, s.ng, abs(s.NoV), through_in);
#endif
    return s.m.sss_albedo * leaving * ((1.0 - u_metallic) * sss_w * INV_PI);
}
