// Scene lights shared by every pass that lights a surface (forward / gather, irradiance):
// up to MAX_LIGHTS directional or point lights, two shadow-map slots. Python side:
// skinlab/render/lights.py set_light_uniforms(). Point lights fall off with the inverse square of the
// distance in metres (lib/lighting.glsl inverse_square).
#include "lib/lighting.glsl"
#include "lib/shadow.glsl"

#ifndef MAX_LIGHTS
#define MAX_LIGHTS 4
#endif

uniform int u_num_lights;
uniform vec4 u_light_vec[MAX_LIGHTS];        // w = 0: direction to the light; w = 1: position
uniform vec3 u_light_radiance[MAX_LIGHTS];   // colour * intensity
uniform int u_light_shadow[MAX_LIGHTS];      // shadow slot, or -1
uniform sampler2DShadow u_shadow0;
uniform sampler2DShadow u_shadow1;
uniform mat4 u_shadow_matrix[2];
uniform float u_mm_per_unit;

// Direction to light i (l) and the irradiance it brings to a surface facing it (e) at world.
void light_incidence(int i, vec3 world, vec3 n, out vec3 l, out vec3 e) {
    e = u_light_radiance[i];
    if (u_light_vec[i].w == 0.0) {
        l = u_light_vec[i].xyz;
    } else {
        vec3 d = u_light_vec[i].xyz - world;
        float dist = length(d);
        l = dist > 0.0 ? d / dist : n;
        e *= inverse_square(dist * u_mm_per_unit);
    }
}

// SHADOW_SLOTS: how many shadow-map slots the frame fills (0, 1 or 2; skinlab/render/lights.py
// light_defines). A slot the frame leaves empty is compiled out: a software rasteriser (llvmpipe)
// runs both sides of every branch with the lanes masked, so an unused slot's PCF taps would cost as
// much as a used one's (measured: the plain frame without shadows took 1.9x as long with them in).
#ifndef SHADOW_SLOTS
#define SHADOW_SLOTS 2
#endif

// Shadow-map visibility of light i at world (geometric normal's cosine for the slope bias).
float light_visibility(int i, vec3 world, float NoL_geom) {
#if SHADOW_SLOTS > 0
    int slot = u_light_shadow[i];
    if (slot == 0) return shadow_pcf(u_shadow0, u_shadow_matrix[0], world, NoL_geom);
#if SHADOW_SLOTS > 1
    if (slot == 1) return shadow_pcf(u_shadow1, u_shadow_matrix[1], world, NoL_geom);
#endif
#endif
    return 1.0;
}
