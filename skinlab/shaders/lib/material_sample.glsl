// The material at a fragment: its plain values times its maps, read once through the texture
// transform (lib/material_uv.glsl), and the vertex colour (the colour rule, docs/scenes.md: the colour
// map and the vertex colour multiply the base colour, the subsurface colour and the opacity). Shared
// by the passes that shade a surface (passes/forward.frag, techniques/tsd/irradiance.frag,
// passes/bounce_exitance.frag). Variant MATERIAL_LOD (a float expression): the maps read at that
// mip level (textureLod), for a pass whose fragment stands for more than a texel (the bounce
// pass's vertices). NumPy twin: skinlab/scene/optics/surface.py material_sample (without maps).
#include "lib/surface.glsl"
#include "lib/material_uv.glsl"
#include "skinlab/material.glsl"

#ifdef MATERIAL_LOD
#define MATERIAL_TEXTURE(map, uv) textureLod(map, uv, MATERIAL_LOD)
#else
#define MATERIAL_TEXTURE(map, uv) texture(map, uv)
#endif

struct MaterialSample {
    vec2 uv;          // where the maps were read (the mesh uv through the texture transform)
    vec3 base;        // the plain diffuse part's albedo, a metal's F0: base colour x map x vertex colour
    vec3 sss_albedo;  // the subsurface albedo: subsurface colour x colour map x vertex colour
    float alpha;      // opacity (lib/surface.glsl surface_alpha)
    float roughness;
    float metallic;
    float occlusion;  // ambient occlusion at the material's strength (1 without a map)
};

MaterialSample material_sample(vec2 uv, vec4 vertex_color) {
    MaterialSample m;
    m.uv = material_uv(uv);
    vec4 base_map = vec4(1.0);
#ifdef HAS_BASE_COLOR_MAP
    base_map = MATERIAL_TEXTURE(u_base_color_map, m.uv);
#endif
    m.base = u_base_color * base_map.rgb * vertex_color.rgb;
    m.sss_albedo = u_subsurface_color * base_map.rgb * vertex_color.rgb;
    m.alpha = surface_alpha(u_alpha, base_map.a, vertex_color.a);
    m.roughness = u_roughness;
#ifdef HAS_ROUGHNESS_MAP
    m.roughness *= MATERIAL_TEXTURE(u_roughness_map, m.uv).r;
#endif
    m.metallic = u_metallic;  // the subsurface hooks weigh their term by u_metallic (no map)
#ifdef HAS_METALLIC_MAP
    m.metallic *= MATERIAL_TEXTURE(u_metallic_map, m.uv).r;
#endif
    m.occlusion = 1.0;
#ifdef HAS_OCCLUSION_MAP
    m.occlusion = occlusion_at_strength(MATERIAL_TEXTURE(u_occlusion_map, m.uv).r, u_occlusion_strength);
#endif
    return m;
}
