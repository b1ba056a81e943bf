// The surface inputs a glTF material brings beyond the principled BRDF (skinlab/scene/materials.py):
// occlusion strength, opacity and its mask, the texture transform, diffuse transmission. NumPy twin:
// skinlab/scene/optics/surface.py (same names).
#include "skinlab/constants.glsl"

// The ambient occlusion a map value gives at glTF's occlusion strength: 1 + strength (map - 1).
float occlusion_at_strength(float map_r, float strength) {
    return 1.0 + clamp(strength, 0.0, 1.0) * (clamp(map_r, 0.0, 1.0) - 1.0);
}

// Opacity: the material's alpha x the colour map's alpha x the vertex colour's alpha, in [0, 1].
float surface_alpha(float alpha, float map_a, float vertex_a) {
    return clamp(alpha * map_a * vertex_a, 0.0, 1.0);
}

// A masked surface is there where its opacity reaches the cutoff (glTF alphaMode MASK).
bool alpha_kept(float a, float cutoff) { return a >= cutoff; }

// glTF KHR_texture_transform of an OpenGL-convention uv (v up): in glTF's convention g = (u, 1 - v),
// g' = offset + R S g with R = [[cos, sin], [-sin, cos]] (the UVs turned counter-clockwise by
// `rotation`) and S = diag(scale); back as (g'.x, 1 - g'.y).
vec2 texture_transform(vec2 uv, vec2 offset, vec2 scale, float rotation) {
    vec2 g = vec2(uv.x, 1.0 - uv.y) * scale;
    float c = cos(rotation), s = sin(rotation);
    vec2 t = offset + vec2(c * g.x + s * g.y, -s * g.x + c * g.y);
    return vec2(t.x, 1.0 - t.y);
}

// Diffuse transmission (glTF KHR_materials_diffuse_transmission): the Lambertian BTDF a thin surface
// sends light from behind through with, per unit irradiance on the far side: colour x weight / pi for
// light from the other side (NoL < 0), else 0.
vec3 diffuse_transmission_btdf(float NoL, float weight, vec3 colour) {
    return NoL < 0.0 ? colour * (clamp(weight, 0.0, 1.0) * INV_PI) : vec3(0.0);
}
