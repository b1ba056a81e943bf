// Oblique entry (Wang & Jacques 1995): light entering a scattering medium at an angle feeds a
// diffusion displaced along the surface by sin(theta_t) z0 in the direction it travels (z0 = 1/mu_t',
// the dipole's source depth). NumPy twin and derivation: skinlab/scene/optics/oblique.py entry_offset.
// sss_entry_offset: the world offset from a surface point to where the light it re-emits entered:
// ng the unit geometric normal, l the unit direction to the light, z0_mm per channel (one offset for
// all three, weighted by luminance), eta the relative index, mm_per_unit the scene's scale.
// sss_entry_point: where to look the light's shadow up for the diffusion leaving at world: the
// entry point, moved toward the light by the offset's length (a depth bias: on a curved surface the
// offset leaves the surface by up to |offset|^2 / 2R and must not be shadowed by it; for a
// directional light it does not move the point across the map).
#include "skinlab/constants.glsl"

vec3 sss_entry_offset(vec3 ng, vec3 l, vec3 z0_mm, float eta, float mm_per_unit) {
    vec3 lt = l - ng * dot(ng, l);  // |lt| = sin(theta_i); sin(theta_t) = min(sin(theta_i) / eta, 1)
    float z0 = dot(z0_mm, vec3(LUMA_R, LUMA_G, LUMA_B));
    return lt * (z0 / (max(eta, max(length(lt), 1e-6)) * max(mm_per_unit, 1e-30)));
}

vec3 sss_entry_point(vec3 world, vec3 ng, vec3 l, vec3 z0_mm, float eta, float mm_per_unit) {
    vec3 off = sss_entry_offset(ng, l, z0_mm, eta, mm_per_unit);
    return world + off + l * length(off);
}
