// Per-texel subsurface weight and radius scale from the material's maps (skinlab/scene/materials.py:
// subsurface_map, subsurface_radius_map; without a map, the plain values). Needs the material
// uniforms (skinlab/material.glsl); maps are read through the material's texture transform.
#include "lib/material_uv.glsl"

// subsurface x the weight map's R channel at uv.
float sss_weight_at(vec2 uv) {
#ifdef HAS_SUBSURFACE_MAP
    return u_subsurface * texture(u_subsurface_map, material_uv(uv)).r;
#else
    return u_subsurface;
#endif
}

// The radius scale at uv: 2 x the radius map's R channel (mid grey 1), 1 without a map.
float sss_radius_scale_at(vec2 uv) {
#ifdef HAS_SUBSURFACE_RADIUS_MAP
    return 2.0 * texture(u_subsurface_radius_map, material_uv(uv)).r;
#else
    return 1.0;
#endif
}
