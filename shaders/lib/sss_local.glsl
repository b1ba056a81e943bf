// The subsurface part of the diffuse term without a convolution, for the hooks of techniques that
// scatter locally or in screen space (tint, ssss): the same entry/exit model as texture-space
// diffusion - irradiance through Fresnel transmission in, Burley 2015's exit weight out - so that
// only the convolution differs between the techniques. Needs the material uniforms and u_ambient.
#include "lib/subsurface.glsl"

vec3 sss_in = vec3(0.0);  // irradiance entering the medium (this fragment)

void sss_add_light(vec3 e, float vis, float NoL) {
    sss_in += e * (vis * NoL * fresnel_transmission(SPECULAR_F0_SCALE * u_specular, NoL));
}

// The radiance leaving the medium toward the viewer for subsurface weight sss_w (ambient included).
vec3 sss_local_radiance(vec3 base, float NoV, float occlusion, float sss_w) {
    vec3 entering = sss_in + PI * u_ambient * occlusion;
    return base * entering * ((1.0 - u_metallic) * sss_w * INV_PI * sss_exit_weight(abs(NoV)));
}
