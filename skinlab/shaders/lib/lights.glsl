// Scene lights shared by every pass that lights a surface (forward / gather, irradiance):
// up to MAX_LIGHTS lights, two shadow-map slots. Python side: skinlab/render/lights.py
// set_light_uniforms(); NumPy twin of light_incidence: skinlab/scene/optics/lighting.py.
// Directional lights bring their irradiance; point and spot lights fall off with the inverse square of
// the distance in metres (lib/lighting.glsl inverse_square), a spot also linearly in angle from its
// inner to its outer half-angle (Mitsuba's spot); area lights (a sphere, a one-sided rectangle) of
// radiance L bring their exact irradiance while the whole light is above the surface's horizon, as a
// light from one direction l (the direction of their vector irradiance: lib/area_lights.glsl).
#include "lib/lighting.glsl"
#include "lib/shadow.glsl"
#include "lib/area_lights.glsl"
#if defined(SHADOW_SOFT0) || defined(SHADOW_SOFT1)
#include "lib/shadow_soft.glsl"
uniform sampler2D u_shadow_distance0;  // a soft slot's distance map (skinlab/render/lights.py)
uniform sampler2D u_shadow_distance1;
uniform vec4 u_shadow_soft[2];         // lib/shadow_soft.glsl shadow_soft's `soft`, per slot
uniform vec4 u_shadow_eye[2];          // each slot's light position (w = 1) or direction (w = 0)
#endif

#ifndef MAX_LIGHTS
#define MAX_LIGHTS 4
#endif

uniform int u_num_lights;
uniform vec4 u_light_vec[MAX_LIGHTS];        // w = 0: direction to the light; w = 1: position (centre)
uniform vec3 u_light_radiance[MAX_LIGHTS];   // colour * intensity
uniform vec4 u_light_axis[MAX_LIGHTS];       // xyz: the way it shines; w: 0 plain, 1 spot, 2 rect, 3 sphere
uniform vec4 u_light_shape[MAX_LIGHTS];      // spot: (outer, 1 / (outer - inner)); sphere: (radius);
                                             // rect: (half-width vector, half-height), world units
uniform int u_light_shadow[MAX_LIGHTS];      // shadow slot, or -1
uniform sampler2DShadow u_shadow0;
uniform sampler2DShadow u_shadow1;
uniform mat4 u_shadow_matrix[2];
#ifdef SHADOW_FINE0  // a slot's map fitted to what the camera sees (skinlab/render/shadow_fit.py)
uniform sampler2DShadow u_shadow_fine0;
#endif
#ifdef SHADOW_FINE1
uniform sampler2DShadow u_shadow_fine1;
#endif
#if defined(SHADOW_FINE0) || defined(SHADOW_FINE1)
uniform mat4 u_shadow_fine_matrix[2];
// A screen pass's sample footprint on the surface (world vectors across one sample along x and y; the
// pass sets them from its position's derivatives where control flow is uniform, passes/forward.frag):
// the fitted map's lookups average over it, the pixel's box filter of a sharp shadow (the truth's
// pixel filter); zero (a texture-space pass): the 3x3 PCF.
vec3 g_shadow_du = vec3(0.0);
vec3 g_shadow_dv = vec3(0.0);

float shadow_fitted(sampler2DShadow fine, mat4 mf, sampler2DShadow map, mat4 m, vec3 world, float NoL) {
    if (g_shadow_du == vec3(0.0) && g_shadow_dv == vec3(0.0)) return shadow_pcf_fitted(fine, mf, map, m, world, NoL);
    return shadow_box_fitted(fine, mf, map, m, world, NoL, g_shadow_du, g_shadow_dv);
}
#endif
uniform float u_mm_per_unit;

// Direction to light i (l) and the irradiance it brings to a surface facing it (e) at world.
void light_incidence(int i, vec3 world, vec3 n, out vec3 l, out vec3 e) {
    e = u_light_radiance[i];
    float kind = u_light_axis[i].w;
    if (u_light_vec[i].w == 0.0) {
        l = u_light_vec[i].xyz;
    } else if (kind < 1.5) {  // point or spot
        vec3 d = u_light_vec[i].xyz - world;
        float dist = length(d);
        l = dist > 0.0 ? d / dist : n;
        e *= inverse_square(dist * u_mm_per_unit);
        if (kind > 0.5) e *= spot_falloff(u_light_axis[i].xyz, l, u_light_shape[i].x, u_light_shape[i].y);
    } else if (kind < 2.5) {  // rect
        vec4 s = u_light_shape[i];
        vec3 ey = normalize(cross(u_light_axis[i].xyz, s.xyz)) * s.w;
        vec3 f = rect_vector_irradiance(u_light_vec[i].xyz, s.xyz, ey, u_light_axis[i].xyz, world);
        float len = length(f);
        l = len > 0.0 ? f / len : n;
        e *= len;
    } else {  // sphere
        vec3 d = u_light_vec[i].xyz - world;
        float dist = length(d);
        l = dist > 0.0 ? d / dist : n;
        e *= sphere_irradiance(u_light_shape[i].x, dist);
    }
}

// SHADOW_SLOTS: how many shadow-map slots the frame fills (0, 1 or 2; skinlab/render/lights.py
// light_defines). A slot the frame leaves empty is compiled out: a software rasteriser (llvmpipe)
// runs a branch's arithmetic with the lanes masked even where no fragment of a group takes it (a
// loop in it stops after one masked turn: docs/tsd.md "Third round", corrected in the "Fifth
// round"); compiled out, an unused slot costs nothing for certain (measured when this was written: the plain frame without shadows took 1.9x as
// long with them in).
#ifndef SHADOW_SLOTS
#define SHADOW_SLOTS 2
#endif

// The light each shadow slot holds (an index into the arrays above, -1 for a slot no light fills;
// skinlab/render/lights.py set_light_uniforms). A pass that shades the lights with a shadow map per slot
// (the slot a compile-time constant: passes/forward.frag, techniques/tsd/irradiance.frag) compiles each
// slot's lookups once, never for a light without a map.
uniform int u_slot_light[2];

// Shadow-map visibility at world from shadow slot `slot` (-1 or a slot the frame does not fill: 1);
// NoL_geom the geometric normal's cosine for the slope bias.
float slot_visibility(int slot, vec3 world, float NoL_geom) {
#if SHADOW_SLOTS > 0
#ifdef SHADOW_SOFT0  // a light with a size: soft shadows (lib/shadow_soft.glsl)
    if (slot == 0) return shadow_soft(u_shadow0, u_shadow_distance0, u_shadow_matrix[0], u_shadow_soft[0], u_shadow_eye[0], world, NoL_geom);
#elif defined(SHADOW_FINE0)
    if (slot == 0) return shadow_fitted(u_shadow_fine0, u_shadow_fine_matrix[0], u_shadow0, u_shadow_matrix[0], world, NoL_geom);
#else
    if (slot == 0) return shadow_pcf(u_shadow0, u_shadow_matrix[0], world, NoL_geom);
#endif
#if SHADOW_SLOTS > 1
#ifdef SHADOW_SOFT1
    if (slot == 1) return shadow_soft(u_shadow1, u_shadow_distance1, u_shadow_matrix[1], u_shadow_soft[1], u_shadow_eye[1], world, NoL_geom);
#elif defined(SHADOW_FINE1)
    if (slot == 1) return shadow_fitted(u_shadow_fine1, u_shadow_fine_matrix[1], u_shadow1, u_shadow_matrix[1], world, NoL_geom);
#else
    if (slot == 1) return shadow_pcf(u_shadow1, u_shadow_matrix[1], world, NoL_geom);
#endif
#endif
#endif
    return 1.0;
}

// Shadow-map visibility of light i at world (geometric normal's cosine for the slope bias).
float light_visibility(int i, vec3 world, float NoL_geom) {
#if SHADOW_SLOTS > 0
    return slot_visibility(u_light_shadow[i], world, NoL_geom);
#else
    return 1.0;
#endif
}

// slot_visibility from one bilinear tap of the slot's full map (lib/shadow.glsl shadow_tap); a light
// with a size as slot_visibility (its penumbra's filter).
float slot_visibility_tap(int slot, vec3 world, float NoL_geom) {
#if SHADOW_SLOTS > 0
#ifdef SHADOW_SOFT0
    if (slot == 0) return shadow_soft(u_shadow0, u_shadow_distance0, u_shadow_matrix[0], u_shadow_soft[0], u_shadow_eye[0], world, NoL_geom);
#else
    if (slot == 0) return shadow_tap(u_shadow0, u_shadow_matrix[0], world, NoL_geom);
#endif
#if SHADOW_SLOTS > 1
#ifdef SHADOW_SOFT1
    if (slot == 1) return shadow_soft(u_shadow1, u_shadow_distance1, u_shadow_matrix[1], u_shadow_soft[1], u_shadow_eye[1], world, NoL_geom);
#else
    if (slot == 1) return shadow_tap(u_shadow1, u_shadow_matrix[1], world, NoL_geom);
#endif
#endif
#endif
    return 1.0;
}

// slot_visibility averaged over a receiver's footprint (world vectors du, dv: one texture-space
// texel along u and v; lib/shadow.glsl shadow_pcf_area, a soft slot's lib/shadow_soft.glsl
// shadow_soft_area).
float slot_visibility_area(int slot, vec3 world, float NoL_geom, vec3 du, vec3 dv) {
#if SHADOW_SLOTS > 0
#ifdef SHADOW_SOFT0
    if (slot == 0) return shadow_soft_area(u_shadow0, u_shadow_distance0, u_shadow_matrix[0], u_shadow_soft[0], u_shadow_eye[0], world, NoL_geom, du, dv);
#elif defined(SHADOW_FINE0)
    if (slot == 0) return shadow_pcf_area_fitted(u_shadow_fine0, u_shadow_fine_matrix[0], u_shadow0, u_shadow_matrix[0], world, NoL_geom, du, dv);
#else
    if (slot == 0) return shadow_pcf_area(u_shadow0, u_shadow_matrix[0], world, NoL_geom, du, dv);
#endif
#if SHADOW_SLOTS > 1
#ifdef SHADOW_SOFT1
    if (slot == 1) return shadow_soft_area(u_shadow1, u_shadow_distance1, u_shadow_matrix[1], u_shadow_soft[1], u_shadow_eye[1], world, NoL_geom, du, dv);
#elif defined(SHADOW_FINE1)
    if (slot == 1) return shadow_pcf_area_fitted(u_shadow_fine1, u_shadow_fine_matrix[1], u_shadow1, u_shadow_matrix[1], world, NoL_geom, du, dv);
#else
    if (slot == 1) return shadow_pcf_area(u_shadow1, u_shadow_matrix[1], world, NoL_geom, du, dv);
#endif
#endif
#endif
    return 1.0;
}

// The direction (ls) and GGX alpha of light i's specular at world toward v (n the shading normal):
// an area light's representative point (lib/area_lights.glsl), widened alpha and its energy factor;
// for the other kinds l, a and 1.
vec3 light_specular_direction(int i, vec3 world, vec3 n, vec3 v, vec3 l, float a, out float a_spec, out float energy) {
    a_spec = a;
    energy = 1.0;
    float kind = u_light_axis[i].w;
    if (u_light_vec[i].w == 0.0 || kind < 1.5) return l;
    vec3 r = reflect(-v, n);
    vec3 c = u_light_vec[i].xyz;
    vec4 s = u_light_shape[i];
    if (kind < 2.5) {
        vec3 ey = normalize(cross(u_light_axis[i].xyz, s.xyz)) * s.w;
        return rect_specular_point(c, s.xyz, ey, world, r, a, a_spec, energy);
    }
    return sphere_specular_point(c, s.x, world, r, a, a_spec, energy);
}
