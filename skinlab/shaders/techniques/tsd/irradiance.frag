#version 330 core
// Texture-space irradiance (d'Eon & Luebke 2007): per texel of the mesh's UV layout, the light that
// enters the surface's multiple scattering - each light times the entry factor at its incidence
// (lib/sss_boundary.glsl: A_ms(mu0) / A_colour), shadows, the normal map, ambient x occlusion
// (pi L_ambient x A_ms_d / A_colour; variant BOUNCE: the scene's bounce light too, lib/ambient.glsl) - times albedo^mix (pre-scatter texturing). a = 1: covered.
// Each light's shadow is looked up where the diffusion that leaves at the texel entered (oblique
// incidence, lib/sss_oblique.glsl: about 0.7 mm toward the light on skin lit at 45 degrees).
// Variant TSD_TRANSLUCENCY: light reaching back faces through thin parts: the exact diffuse
// transmittance of a slab (all orders of scattering) at the light's incidence on the far side
// (lib/sss_boundary.glsl sss_slab_through; the thickness along the light from the shadow pass's
// distance map, times the cosine to the normal: a flat slab's own thickness); lib/sss_translucency.glsl,
// shared with the forward hooks of the screen-space techniques. It also records that light per texel
// and shadow slot, unblurred, with its thickness and cosine (f_through0/1, f_through_cos): the gather
// gives it the exit factor of light that came through. Variant DEFERRED_SURFACE: drawn fullscreen
// over the UV layout, the inputs read from the surface G-buffer (techniques/tsd/surface.glsl).
// Variant THROUGH_KERNEL (RenderSettings.through_kernel): the light through thin parts is the transfer
// through the medium's (skinlab/render/through_kernel.py, per vertex: v_through), in slot 0's record.
#include "lib/brdf.glsl"
#include "lib/lights.glsl"
#include "lib/ambient.glsl"
#include "lib/sss_boundary.glsl"
#include "lib/ambient_entering.glsl"
#include "lib/sss_oblique.glsl"
#include "lib/sss_near_light.glsl"
#include "skinlab/material.glsl"
#include "lib/sss_maps.glsl"
#include "lib/material_sample.glsl"

#ifdef DEFERRED_SURFACE
#include "techniques/tsd/surface.glsl"  // the inputs from the surface G-buffer, one fragment per texel
#else
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;
in vec4 v_color;  // the vertex colour (1 where the mesh has none)
#endif

uniform float u_tsd_mix;
uniform sampler2D u_tsd_stretch;  // mm per texel along u (r) and v (g) / the radius scale (techniques/tsd/stretch.frag)
vec3 v_du;  // the texel's footprint on the surface: world vectors of one texel along u and v
vec3 v_dv;

// The texel's footprint from the stretch map (the surface's mm per texel, dilated past the charts)
// along the tangent frame (u along the tangent, v along the bitangent: the UV layout's axes where it
// is not sheared); the same in both variants (the deferred one has no derivatives across the charts).
void texel_footprint(vec3 ng, vec4 t) {
    vec2 mm = texelFetch(u_tsd_stretch, ivec2(gl_FragCoord.xy), 0).rg * max(sss_radius_scale_at(v_uv), 1e-3);
    vec3 tt = t.xyz - ng * dot(ng, t.xyz);
    float lt = length(tt);
    tt = lt > 1e-6 ? tt / lt : normalize(cross(ng, abs(ng.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    vec3 b = cross(ng, tt) * (t.w < 0.0 ? -1.0 : 1.0);
    v_du = tt * (mm.x / u_mm_per_unit);
    v_dv = b * (mm.y / u_mm_per_unit);
}
#ifdef TSD_TRANSLUCENCY
#include "lib/sss_translucency.glsl"
#endif

out vec4 f_irradiance;
#ifdef TSD_TRANSLUCENCY
// the light through thin parts per shadow slot, unblurred, for the gather's exit factor
// (techniques/tsd/forward.glsl): rgb the light entering through, a the thickness (mm); f_through_cos
// each slot's cosine on the far face. Slot 1's record only where the frame fills two slots (the pass
// attaches it only then).
layout(location = 1) out vec4 f_through0;
#if SHADOW_SLOTS > 1
layout(location = 2) out vec4 f_through1;
layout(location = 3) out vec2 f_through_cos;
#else
layout(location = 2) out vec2 f_through_cos;
#endif
vec4 through_rec[2] = vec4[2](vec4(0.0), vec4(0.0));
vec2 through_back = vec2(0.0);
#endif

// What the light in shadow slot `slot` (a compile-time constant) brings: direct light through the
// shadow map, and with TSD_TRANSLUCENCY the light through thin parts. Only shadow-casting lights
// can shine through (the thickness comes from their distance map), so the translucency runs once
// per filled slot, never for the other lights (a software rasteriser runs a branch's masked side).
vec3 shadowed_light(int slot, vec3 n, vec3 ng) {
    int i = u_slot_light[slot];
    vec3 l, e;
    light_incidence(i, v_world, n, l, e);
    vec3 sum = vec3(0.0);
    float NoL = dot(n, l);
    if (NoL > 0.0) {
        // the shadow where this texel's diffusion entered: oblique entry (lib/sss_oblique.glsl)
        vec3 z0 = u_sss_mfp * sss_radius_scale_at(v_uv);  // the radius map scales the mean free path
#ifdef SSS_ENTRY_SPREAD  // RenderSettings.entry_spread
        // spread as the entry is: three lookups along the luminance offset, weighted per channel by
        // its exponential's terciles (lib/sss_oblique.glsl sss_ramp_mix; skinlab/scene/optics/oblique.py)
        // each averaged over the texel's footprint (lib/shadow.glsl shadow_pcf_area): the texel holds
        // its square's mean, not its centre's, so a shadow edge along the layout's grid does not alias
        vec3 p1, p2, p3;
        vec3 m = sss_ramp_setup(v_world, ng, l, z0, u_sss_slab_decay, u_sss_eta, u_mm_per_unit, p1, p2, p3);
        float c = dot(ng, l);
        vec3 vis = sss_ramp_mix(m, slot_visibility_area(slot, p1, c, v_du, v_dv), slot_visibility_area(slot, p2, c, v_du, v_dv),
                                slot_visibility_area(slot, p3, c, v_du, v_dv));
#else  // one lookup at the mean entry point
        vec3 vis = vec3(slot_visibility_area(slot, sss_entry_point(v_world, ng, l, z0, u_sss_eta, u_mm_per_unit), dot(ng, l), v_du, v_dv));
#endif
        // a point or spot light's irradiance there too (lib/sss_near_light.glsl)
        sum += e * (vis * NoL) * sss_entry(NoL)
               * sss_light_near_gain(i, v_world, ng, z0);
    }
#if defined(TSD_TRANSLUCENCY) && !defined(THROUGH_KERNEL)  // (with it: per-vertex bounce light)
    float back = -dot(ng, l);
    float d_mm;
    if (back > 0.0) back = sss_through_cosine(slot, v_world, ng, back);  // the part's (lib/sss_translucency.glsl)
    if (back > 0.0 && sss_thickness_mm(slot, v_world, ng, back, d_mm)) {
        vec3 through = e * back * sss_through(back, d_mm);
        sum += through;
        through_rec[slot] = vec4(through, d_mm);
        through_back[slot] = back;
    }
#endif
    return sum;
}

void main() {
#ifdef DEFERRED_SURFACE
    if (!load_surface()) discard;
#endif
#ifdef MEASURE_RASTER_ONLY  // a measurement variant (tools/irradiance_cost.py): the inputs alone
    f_irradiance = vec4(v_world + v_normal + v_tangent.xyz + vec3(v_uv, 0.0), 1.0);
    return;
#endif
    MaterialSample m = material_sample(v_uv, v_color);  // the material's maps, as the forward pass reads them
    vec3 ng = normalize(v_normal);
    vec3 n = ng;
    texel_footprint(ng, v_tangent);
#ifdef HAS_NORMAL_MAP
    n = perturb_normal(ng, v_tangent, texture(u_normal_map, m.uv).rgb, u_normal_scale);
#endif
    vec3 base = m.sss_albedo;  // the subsurface albedo (the colour rule, docs/scenes.md)
    float occlusion = m.occlusion;
    ambient_set_normal(n);  // the environment map's diffuse light at this normal (lib/ambient.glsl)
    vec3 e_in = vec3(0.0);
    for (int i = 0; i < MAX_LIGHTS; ++i) {   // the lights without a shadow map
        if (i >= u_num_lights) break;
        if (u_light_shadow[i] >= 0 && u_light_shadow[i] < SHADOW_SLOTS) continue;  // below, per slot
        vec3 l, e;
        light_incidence(i, v_world, n, l, e);
        float NoL = dot(n, l);
        // a point or spot light's irradiance where this texel's diffusion entered (lib/sss_near_light.glsl)
        if (NoL > 0.0) e_in += e * NoL * sss_entry(NoL) * sss_light_near_gain(i, v_world, ng, u_sss_mfp * sss_radius_scale_at(v_uv));
    }
#if SHADOW_SLOTS > 0
    if (u_slot_light[0] >= 0) e_in += shadowed_light(0, n, ng);
#endif
#if SHADOW_SLOTS > 1
    if (u_slot_light[1] >= 0) e_in += shadowed_light(1, n, ng);
#endif
    e_in += ambient_entering(occlusion);  // the sky and bounce light
#ifdef THROUGH_KERNEL  // the light through thin parts from the transfer through the medium, one record
    e_in += v_through.rgb;
    through_rec[0] = v_through;
    through_back[0] = v_through_cos;
#endif
    f_irradiance = vec4(e_in * pow(max(base, vec3(0.0)), vec3(u_tsd_mix)), 1.0);
#ifdef TSD_TRANSLUCENCY
    f_through0 = through_rec[0];
#if SHADOW_SLOTS > 1
    f_through1 = through_rec[1];
#endif
    f_through_cos = through_back;
#endif
}
