#version 330 core
// Depth only; with SHADOW_DISTANCE also the distance of the first surface from the light in scene
// units (u_light_eye: position, w = 1, or the direction light travels, w = 0). Variant ALPHA_MASK:
// a masked material's cut-away pixels cast no shadow (lib/alpha_mask.glsl).
#ifdef ALPHA_MASK
#include "lib/alpha_mask.glsl"
#endif
#ifdef SHADOW_DISTANCE
in vec3 v_world;
uniform vec4 u_light_eye;
out float f_distance;
#endif
void main() {
#ifdef ALPHA_MASK
    alpha_mask_test();
#endif
#ifdef SHADOW_DISTANCE
    f_distance = u_light_eye.w == 0.0 ? dot(v_world, u_light_eye.xyz) : length(v_world - u_light_eye.xyz);
#endif
}
