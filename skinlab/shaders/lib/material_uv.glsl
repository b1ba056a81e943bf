// Where the material's maps are read: the mesh's uv through the material's texture transform
// (variant UV_TRANSFORM: uv_offset, uv_scale, uv_rotation; lib/surface.glsl texture_transform).
#include "lib/surface.glsl"
#include "skinlab/material.glsl"

vec2 material_uv(vec2 uv) {
#ifdef UV_TRANSFORM
    return texture_transform(uv, u_uv_offset, u_uv_scale, u_uv_rotation);
#else
    return uv;
#endif
}
