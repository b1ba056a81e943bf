// The forward pass's surface inputs at a fragment, built once (passes/forward.frag) and handed to the
// technique's hook (the contract: skinlab/render/technique.py): where it is, its normals and tangent
// frame turned to the side seen, the view direction, the material sample (lib/material_sample.glsl)
// and the subsurface weight and radius scale from their maps (lib/sss_maps.glsl). A hook reads these
// instead of forward.frag's varyings and computes none of them again. NumPy twin of the parts that
// are not map reads: skinlab/scene/optics/surface.py surface_inputs.
#include "lib/lighting.glsl"
#include "lib/lights.glsl"
#include "lib/material_sample.glsl"
#include "lib/sss_boundary.glsl"
#include "lib/sss_maps.glsl"
#include "lib/sss_oblique.glsl"
#include "lib/sss_near_light.glsl"

struct Surface {
    vec3 position;            // world space
    vec3 ng;                  // the geometric normal, turned to the side seen
    vec3 n;                   // the shading normal: ng through the normal map (variant HAS_NORMAL_MAP)
    vec4 tangent;             // the tangent (xyz, turned with ng) and its handedness (w)
    vec3 v;                   // toward the camera
    float NoV;                // dot(n, v)
    vec2 uv;                  // the mesh's uv (the maps are read at m.uv, through the texture transform)
    MaterialSample m;
    float sss_weight;         // subsurface x its map: the subsurface share of the diffuse term
    float sss_radius_scale;   // the radius map's scale of the profile and the mean free path (1 without)
};

Surface surface_inputs(vec3 world, vec3 normal, vec2 uv, vec4 tangent, vec4 color, vec3 camera, bool front) {
    Surface s;
    s.position = world;
    s.uv = uv;
    s.m = material_sample(uv, color);
    s.ng = normalize(normal);
    s.v = normalize(camera - world);
    if (!front) s.ng = -s.ng;
    s.tangent = vec4(front ? tangent.xyz : -tangent.xyz, tangent.w);
    s.n = s.ng;
#ifdef HAS_NORMAL_MAP
    s.n = perturb_normal(s.ng, s.tangent, texture(u_normal_map, s.m.uv).rgb, u_normal_scale);
#endif
    s.NoV = dot(s.n, s.v);
    s.sss_weight = sss_weight_at(uv);
    s.sss_radius_scale = sss_radius_scale_at(uv);
    return s;
}

// The shadow from slot `slot` (a light's u_light_shadow) where the diffusion leaving at s entered on
// average (oblique entry, lib/sss_oblique.glsl: the mean free path x the radius map toward the light l);
// 1 for a light without a shadow map (slot -1).
float sss_entry_visibility(Surface s, int slot, vec3 l) {
    if (slot < 0) return 1.0;
    vec3 entry = sss_entry_point(s.position, s.ng, l, u_sss_mfp * s.sss_radius_scale, u_sss_eta, u_mm_per_unit);
    return slot_visibility(slot, entry, dot(s.ng, l));
}

// The shadow from slot `slot` per channel where the diffusion leaving at s entered, spread as the entry
// is (an exponential distance upstream, per channel, lib/sss_oblique.glsl): three lookups along the
// luminance offset; decay per channel sqrt(3 (1 - a')) (lib/sss_boundary.glsl u_sss_slab_decay); 1
// for a light without a shadow map (slot -1).
// Without SSS_ENTRY_SPREAD (RenderSettings.entry_spread off): the shadow at the mean entry point.
vec3 sss_entry_ramp(Surface s, int slot, vec3 l, vec3 decay) {
#ifndef SSS_ENTRY_SPREAD
    return vec3(sss_entry_visibility(s, slot, l));
#endif
    if (slot < 0) return vec3(1.0);
    vec3 p1, p2, p3;
    vec3 m = sss_ramp_setup(s.position, s.ng, l, u_sss_mfp * s.sss_radius_scale, decay, u_sss_eta, u_mm_per_unit,
                            p1, p2, p3);
    float c = dot(s.ng, l);
    return sss_ramp_mix(m, slot_visibility(slot, p1, c), slot_visibility(slot, p2, c), slot_visibility(slot, p3, c));
}

// The shadow from slot `slot` per channel for single scattering at s (lib/sss_oblique.glsl
// sss_single_pair): its light entered upstream by the diffusion's offset over k = 1 + mu_l / mu_v, read
// from the point's own shadow vis and one bilinear tap at the whole offset (lights.glsl
// slot_visibility_tap: the pair's weights smooth it); vis where the light has no map (slot -1).
uniform vec3 u_sss_single_ramp;  // skinlab/scene/optics/oblique.py single_pair_rate (skinlab/render/boundary.py)
vec3 sss_single_visibility(Surface s, int slot, vec3 l, float NoL, float vis) {
#ifndef SSS_ENTRY_SPREAD  // RenderSettings.entry_spread off: the point's own shadow
    return vec3(vis);
#endif
    if (slot < 0) return vec3(vis);
    vec3 at = sss_entry_point(s.position, s.ng, l, u_sss_mfp * s.sss_radius_scale, u_sss_eta, u_mm_per_unit);
    return sss_single_pair(sss_single_k(NoL, s.NoV, u_sss_eta), u_sss_single_ramp, vis,
                           slot_visibility_tap(slot, at, dot(s.ng, l)));
}

// Light i's irradiance feeding the diffusion at s relative to its own (a point or spot light's
// falls off along the surface: the diffusion leaving at s entered nearer the light,
// lib/sss_near_light.glsl); 1 for directional and area lights.
vec3 sss_near_gain(Surface s, int i) {
    return sss_light_near_gain(i, s.position, s.ng, u_sss_mfp * s.sss_radius_scale);
}

// Light i's single scattering at s relative to a far light's (a point or spot light is seen from
// other directions and distances by the points below s, lib/sss_near_single.glsl); 1 for
// directional and area lights. The radius map scales the mean free path, so divides the extinction.
vec3 sss_near_single(Surface s, int i) {
#ifdef MEASURE_FAR_SINGLE  // a measurement variant (tests/render/test_near_single_frame.py): the far light's term
    return vec3(1.0);
#endif
    return sss_light_near_single(i, s.position, s.ng, s.v, u_sss_sigma_t / max(s.sss_radius_scale, 1e-6));
}
