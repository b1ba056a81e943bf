// The diffusion's entering light under a light at a finite distance (point and spot lights): fed by
// the irradiance where it entered, nearer the light's foot (oblique entry, lib/sss_oblique.glsl
// sss_near_entry), with the entry factor at that point's incidence. NumPy twin:
// skinlab/scene/optics/oblique.py near_entry_gain.
#include "lib/lights.glsl"
#include "lib/sss_boundary.glsl"
#include "lib/sss_oblique.glsl"
#include "lib/sss_near_single.glsl"

// Per channel, the factor on e NoL sss_entry(NoL) at a point d_mm (millimetres) from the light:
// sss_near_entry's g x entry(mu_s) / entry(mu_x), mu the cosines to the geometric normal ng, at most
// SSS_NEAR_MAX_GAIN (a dielectric's entry falls to 0 at grazing incidence: the ratio is large only
// where the light entering is nearly none); 1 where sss_near_entry is.
vec3 sss_near_entry_gain(vec3 d_mm, vec3 ng, vec3 z0_mm) {
    float mu_x = clamp(dot(d_mm, ng) / max(length(d_mm), 1e-30), 0.0, 1.0);
    if (mu_x <= SSS_NEAR_MIN_COS) return vec3(1.0);
    vec3 mu_s;
    vec3 g = sss_near_entry(d_mm, ng, z0_mm, u_sss_eta, mu_s);
    vec3 at_s = vec3(sss_entry(mu_s.r).r, sss_entry(mu_s.g).g, sss_entry(mu_s.b).b);
    return min(g * at_s / max(sss_entry(mu_x), vec3(1e-6)), vec3(SSS_NEAR_MAX_GAIN));
}

// That factor for light i at world (z0_mm the mean free path x the radius map): 1 for directional
// and area lights (a directional light's irradiance does not change along the surface: its entry
// is a shift, which only the shadow lookup needs, lib/sss_oblique.glsl sss_entry_point).
// Whether light i is at a finite distance from a point (a point or a spot light; not a directional
// or an area light).
// NEAR_LIGHTS 0 (skinlab/render/lights.py near_defines: the pass's lights hold no point or spot light)
// compiles the near-light factors out, each then its far value 1: a software rasteriser pays for code
// behind a branch no fragment takes (docs/tsd.md, "Fifth round"). Without the define, as with 1, they
// are decided per light.
#ifndef NEAR_LIGHTS
#define NEAR_LIGHTS 1
#endif
#if NEAR_LIGHTS
bool sss_light_is_near(int i) { return u_light_vec[i].w != 0.0 && u_light_axis[i].w <= 1.5; }
#else
bool sss_light_is_near(int i) { return false; }
#endif

vec3 sss_light_near_gain(int i, vec3 world, vec3 ng, vec3 z0_mm) {
    if (!sss_light_is_near(i)) return vec3(1.0);
    return sss_near_entry_gain((u_light_vec[i].xyz - world) * u_mm_per_unit, ng, z0_mm);
}

// The single-scattering term's factor for light i at world (v to the eye, sigma_t the real extinction
// per mm x the radius map; lib/sss_near_single.glsl): 1 for directional and area lights.
vec3 sss_light_near_single(int i, vec3 world, vec3 ng, vec3 v, vec3 sigma_t) {
    if (!sss_light_is_near(i)) return vec3(1.0);
    return sss_near_single_gain((u_light_vec[i].xyz - world) * u_mm_per_unit, ng, v, sigma_t, u_sss_eta, u_sss_g);
}
