// The cut-out of a masked material (alpha_mode "mask", variant ALPHA_MASK) in the passes that write
// depth only (shadow maps, the forward pass's depth pre-pass), so that what the forward pass cuts away
// neither casts a shadow nor hides what lies behind it. Needs v_uv and v_color from the vertex shader.
#include "lib/surface.glsl"
#include "lib/material_uv.glsl"

in vec2 v_uv;
in vec4 v_color;

void alpha_mask_test() {
    float map_a = 1.0;
#ifdef HAS_BASE_COLOR_MAP
    map_a = texture(u_base_color_map, material_uv(v_uv)).a;
#endif
    if (!alpha_kept(surface_alpha(u_alpha, map_a, v_color.a), u_alpha_cutoff)) discard;
}
