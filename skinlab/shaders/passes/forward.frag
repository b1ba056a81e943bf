#version 330 core
// Principled shading (Burley diffuse + GGX specular) with up to MAX_LIGHTS lights and two
// shadow maps. Variants: HAS_<MAP> per map set (skinlab/material.glsl, generated from the material's
// parameter declarations), ALPHA_MASK (pixels below the alpha cutoff discarded) and ALPHA_BLEND
// (premultiplied colour and alpha, blended by passes/forward.py); the surface inputs (normals, the
// material's maps, the subsurface weight) are built once, lib/surface_inputs.glsl; the vertex colour
// multiplies the base colour and alpha; emission is added. The subsurface part
// of the diffuse term is the technique's hook (skinlab/sss_hook.glsl, resolved per program to
// skinlab/shaders/techniques/<name>/forward.glsl; the contract is in skinlab/render/technique.py), handed
// the surface inputs: plain Burley diffuse weighted by sss_plain_weight(s), the hook told about each
// light, and its radiance added after the lights. Specular and ambient specular as usual. Single scattering (Jensen 2001,
// lib/sss_boundary.glsl) is added per light, and for ambient light, for a mesh whose technique
// scatters (u_sss_single > 0): it leaves within about a mean free path of where it entered, so no
// technique blurs it. Ambient light is the sky and, with variant BOUNCE, the light the scene's
// surfaces throw onto this one (interreflection, lib/ambient.glsl); with variant ENV_MAP the
// environment map's diffuse light (lib/ambient.glsl, every hook's entering light too) and its
// specular light by the split sum (lib/sky_occlusion.glsl env_specular). Variant SSS_MS_REST
// (skinlab/render/boundary.py boundary_defines): the material's non-separable rest is not all zero;
// NEAR_LIGHTS 0 (skinlab/render/lights.py near_defines): no point or spot light, the near-light
// factors compiled out (lib/sss_near_light.glsl). Each light is shaded by shade_light: the lights
// without a shadow map in the loop, each filled shadow slot's light once with its slot a constant
// (u_slot_light), so no light pays for a slot's lookups it does not read (docs/tsd.md "Sixth round").
// Variant SSS_SINGLE_THROUGH (RenderSettings.single_through, where the frame has distance maps): the
// single scattering of a slot's directional light along its path through the medium as the distance map
// gives it, past a convex part's terminator too (lib/sss_single_through.glsl).
#include "lib/brdf.glsl"
#include "lib/sss_boundary.glsl"
#include "lib/sss_oblique.glsl"
#include "lib/lights.glsl"
#include "lib/ambient.glsl"
#include "lib/surface.glsl"
#include "lib/surface_inputs.glsl"
#include "skinlab/material.glsl"
#ifdef ENV_MAP
#include "lib/env_single.glsl"
#endif
#include "lib/sss_single_through.glsl"  // unconditional: a file is included once, whatever #ifdef surrounds it

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;
in vec4 v_color;  // the vertex colour (1 where the mesh has none)

uniform vec3 u_camera_pos;

layout(location = 0) out vec4 f_color;

#include "skinlab/sss_hook.glsl"

// What the frame shades once per fragment and every light reads (main below).
struct Shading {
    vec3 base;    // the plain diffuse part's albedo, a metal's F0
    float rough, metal, plain, a;  // roughness, metallic, sss_plain_weight, GGX alpha
    vec3 f0;
    bool single;  // single scattering on (u_sss_single > 0)
    vec3 single_w;
    SingleView single_view;
};

// Light i's share of the fragment's radiance at s, its shadow from slot `slot` (-1: none). Every call
// passes the slot as a constant (main below), so a slot's lookups are compiled where they are read and
// never for a light without a map (a software rasteriser runs a branch's masked side: lib/lights.glsl).
vec3 shade_light(int i, int slot, Surface s, Shading sh) {
    vec3 color = vec3(0.0);
    vec3 ng = s.ng, n = s.n, v = s.v, base = sh.base, f0 = sh.f0, single_w = sh.single_w;
    float rough = sh.rough, metal = sh.metal, plain = sh.plain, a = sh.a, NoV = s.NoV;
    bool single = sh.single;
    SingleView single_view = sh.single_view;
    vec3 l, e;
    light_incidence(i, v_world, n, l, e);
    float NoL = dot(n, l);
#ifdef DIFFUSE_TRANSMISSION
    // a thin surface lit from behind: its Lambertian transmission (lib/surface.glsl), shadowed as the far face
    if (NoL < 0.0) {
        float back = slot_visibility(slot, v_world, -dot(ng, l));
        color += e * (back * -NoL) * (1.0 - metal) * plain
                 * diffuse_transmission_btdf(NoL, u_diffuse_transmission, u_diffuse_transmission_color);
    }
#endif
#ifdef SSS_SINGLE_THROUGH  // single scattering along the light's path inside (lib/sss_single_through.glsl)
    vec3 sgain = vec3(1.0), f_st = vec3(0.0);  // the lit side's gain, the light past a terminator
    if (single && slot >= 0)
        sss_single_through(slot, v_world, ng, l, single_view, u_sss_sigma_t / max(s.sss_radius_scale, 1e-6), sgain, f_st);
    color += e * single_w * f_st;  // past a convex part's terminator, where the flat term is 0
#else
    const vec3 sgain = vec3(1.0);  // the flat term alone
#endif
    if (NoL <= 0.0) return color;
    float vis = slot_visibility(slot, v_world, dot(ng, l));
    vec3 h = half_vector(n, v, l);
    float LoH = dot(l, h);
    vec3 diffuse = base * ((1.0 - metal) * plain * burley_diffuse(NoL, NoV, LoH, rough));
#ifdef MEASURE_NO_PLAIN_DIFFUSE  // a measurement variant (tools/orbit_cost.py): no Burley diffuse per light
    diffuse = vec3(0.0);
#endif
#ifdef DIFFUSE_TRANSMISSION
    diffuse *= 1.0 - u_diffuse_transmission;  // what is not sent through
#endif
#ifdef AREA_LIGHTS
    // an area light's specular from its representative point, with a widened lobe (lib/lights.glsl)
    float a_s, energy;
    vec3 ls = light_specular_direction(i, v_world, n, v, l, a, a_s, energy);
    vec3 hs = half_vector(n, v, ls);
    float NoLs = max(dot(n, ls), 0.0);
    vec3 spec = specular_ggx(NoLs, NoV, dot(n, hs), dot(ls, hs), a_s, f0) * energy;
    color += e * vis * (diffuse * NoL + spec * NoLs);
#else
    vec3 spec = specular_ggx(NoL, NoV, dot(n, h), LoH, a, f0);
    color += e * vis * (diffuse + spec) * NoL;
#endif
    // single scattering where the light lands (a near light's seen from below, lib/surface_inputs.glsl
    // sss_near_single), and there too, for a hook of the separable boundary that does not spread it
    // with its diffusion (SSS_MS_REST_LANDS: tsd, exact, preintegrated), the multiple scattering's
    // non-separable rest (lib/sss_boundary.glsl sss_ms_rest)
    // (shadowed where their light entered, spread upstream: lib/surface_inputs.glsl
    // sss_single_visibility, one bilinear tap more per light)
    vec3 svis = vec3(vis);
#ifndef SSS_HOOK_PLAIN  // a mesh that does not scatter (techniques/none/forward.glsl) has no single scattering
    svis = sss_single_visibility(s, slot, l, NoL, vis);
#endif
    if (single) color += e * (svis * sgain * NoL) * single_w * sss_single_brdf_view(n, l, single_view) * sss_near_single(s, i);
#if defined(SSS_MS_REST_LANDS) && defined(SSS_MS_REST) && !defined(MEASURE_NO_MS_REST)  // MEASURE_NO_MS_REST: tools/orbit_cost.py
    if (u_sss_ms_rest_on > 0.0) color += e * (svis * NoL) * single_w * sss_ms_rest(abs(NoV), NoL);
#endif
    // the technique's diffusion: shadowed where it entered (oblique entry, spread upstream per
    // channel, for a hook that gathers its light here: SSS_HOOK_GATHERS_LIGHT, lib/sss_local.glsl;
    // lib/surface_inputs.glsl sss_entry_ramp) and fed by the irradiance where it entered (a point
    // or spot light's, lib/surface_inputs.glsl)
#ifndef MEASURE_NO_ADD_LIGHT  // a measurement variant (tools/orbit_cost.py): the hook told of no light
#ifdef SSS_HOOK_GATHERS_LIGHT
    sss_add_light(s, e * sss_near_gain(s, i), sss_entry_ramp(s, slot, l, u_sss_slab_decay), NoL);
#else
    sss_add_light(s, e * sss_near_gain(s, i), vec3(sss_entry_visibility(s, slot, l)), NoL);
#endif
#endif
    return color;
}

void main() {
#ifdef MEASURE_RASTER_ONLY  // a measurement variant (tools/forward_cost.py): the interpolated inputs alone
    f_color = vec4(v_world + v_normal + v_tangent.xyz + vec3(v_uv, 0.0), 1.0);
    return;
#endif
#if defined(SHADOW_FINE0) || defined(SHADOW_FINE1)
    // the sample's footprint for the fitted shadow maps' lookups (lib/lights.glsl), before any branch
    g_shadow_du = dFdx(v_world);
    g_shadow_dv = dFdy(v_world);
#endif
    // the surface inputs, once: normals, view direction, the material's maps, the subsurface weight
    Surface s = surface_inputs(v_world, v_normal, v_uv, v_tangent, v_color, u_camera_pos, gl_FrontFacing);
#ifdef ALPHA_MASK
    if (!alpha_kept(s.m.alpha, u_alpha_cutoff)) discard;
#endif
    vec3 ng = s.ng, n = s.n, v = s.v;
    vec3 base = s.m.base;  // the plain diffuse part's albedo, a metal's F0
    float rough = s.m.roughness, metal = s.m.metallic, occlusion = s.m.occlusion;
    ambient_set_normal(n);               // the environment map's diffuse light at this normal
    float plain = sss_plain_weight(s);   // weight of the surface's own Burley diffuse
    vec3 f0 = principled_f0(base, metal, u_specular);
    float a = ggx_alpha(rough);
    float NoV = s.NoV;
    vec3 color = vec3(0.0);
    bool single = any(greaterThan(u_sss_single, vec3(0.0)));
#ifdef MEASURE_NO_SINGLE  // a measurement variant (tools/orbit_cost.py): no single scattering
    single = false;
#endif
    vec3 single_w = s.m.sss_albedo * ((1.0 - metal) * s.sss_weight);  // x the weight map
    SingleView single_view;  // single scattering's half that no light changes, made once
    if (single) single_view = sss_single_view(n, v);
    Shading sh;
    sh.base = base;
    sh.rough = rough;
    sh.metal = metal;
    sh.plain = plain;
    sh.a = a;
    sh.f0 = f0;
    sh.single = single;
    sh.single_w = single_w;
    sh.single_view = single_view;
    for (int i = 0; i < MAX_LIGHTS; ++i) {  // the lights without a shadow map
        if (i >= u_num_lights) break;
        if (u_light_shadow[i] >= 0 && u_light_shadow[i] < SHADOW_SLOTS) continue;  // below, per slot
        color += shade_light(i, -1, s, sh);
    }
#if SHADOW_SLOTS > 0  // each filled slot's light, its slot a constant
    if (u_slot_light[0] >= 0) color += shade_light(u_slot_light[0], 0, s, sh);
#endif
#if SHADOW_SLOTS > 1
    if (u_slot_light[1] >= 0) color += shade_light(u_slot_light[1], 1, s, sh);
#endif
    vec3 ambient = ambient_radiance(occlusion);  // the sky, and the scene's bounce light (lib/ambient.glsl)
    float kept = 1.0;
#ifdef DIFFUSE_TRANSMISSION
    kept = 1.0 - u_diffuse_transmission;  // the sky behind shows through as much as the front one is sent away
#endif
#ifdef ENV_MAP
    color += ambient * (base * ((1.0 - metal) * plain * kept)) + ambient_uniform(occlusion) * f0
           + env_specular(n, v, rough, f0, occlusion);
    // the uniform sky's and the bounce light's single scattering, and the map's by its SH bands
    if (single) color += single_w * (ambient_uniform(occlusion) * sss_single_ambient(NoV)
                                     + env_single(n, NoV) * (occlusion * env_visible_share(n)));
#else
    color += ambient * (base * ((1.0 - metal) * plain * kept) + f0);
    if (single) color += ambient * single_w * sss_single_ambient(NoV);  // its single scattering
#endif
#ifndef MEASURE_NO_SSS_RADIANCE  // a measurement variant (tools/orbit_cost.py): the hook's radiance left out
    color += sss_radiance(s);
#endif
    vec3 emission = u_emissive;
#ifdef HAS_EMISSIVE_MAP
    emission *= texture(u_emissive_map, s.m.uv).rgb;
#endif
    color += emission;
#ifdef ALPHA_BLEND
    f_color = vec4(color * s.m.alpha, s.m.alpha);  // premultiplied: blended over what lies behind (passes/forward.py)
#else
    f_color = vec4(color, 1.0);
#endif
}
