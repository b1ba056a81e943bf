#version 330 core
// Depth only; with SHADOW_DISTANCE also the distance of the first surface from the light in scene
// units (u_light_eye: position, w = 1, or the direction light travels, w = 0). The part layers for
// light through thin parts (lib/sss_translucency.glsl; each its own depth test, at
// skinlab/render/translucency.py part_layer_size texels per side): SHADOW_LAYER 1, the nearest
// surface facing away from the light (where the light leaves the first part it crossed) and its
// cosine to the light; SHADOW_LAYER 2, the nearest surface facing the light beyond that exit by more
// than u_part_gap (where it enters the next part), from the exit layer u_exit (the same size).
// NumPy twin of their use: skinlab/scene/optics/translucency.py. Variant ALPHA_MASK: a
// masked material's cut-away pixels cast no shadow (lib/alpha_mask.glsl).
#ifdef ALPHA_MASK
#include "lib/alpha_mask.glsl"
#endif
#ifdef SHADOW_DISTANCE
in vec3 v_world;
uniform vec4 u_light_eye;
#ifdef SHADOW_LAYER
in vec3 v_normal;
#if SHADOW_LAYER == 1
out vec2 f_layer;
#else
out float f_layer;
uniform sampler2D u_exit;
uniform float u_part_gap;
#endif
#else
out float f_distance;
#endif
#endif
void main() {
#ifdef ALPHA_MASK
    alpha_mask_test();
#endif
#ifdef SHADOW_DISTANCE
    float dist = u_light_eye.w == 0.0 ? dot(v_world, u_light_eye.xyz) : length(v_world - u_light_eye.xyz);
#ifdef SHADOW_LAYER
    vec3 travel = u_light_eye.w == 0.0 ? u_light_eye.xyz : normalize(v_world - u_light_eye.xyz);
    float c = dot(normalize(v_normal), travel);  // > 0: the surface faces away from the light
#if SHADOW_LAYER == 1
    if (c <= 0.0) discard;
    f_layer = vec2(dist, c);
#else
    if (c > 0.0 || dist <= texelFetch(u_exit, ivec2(gl_FragCoord.xy), 0).r + u_part_gap) discard;
    f_layer = dist;
#endif
#else
    f_distance = dist;
#endif
#endif
}
