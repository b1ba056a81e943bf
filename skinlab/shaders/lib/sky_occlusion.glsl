// Environment light as the surface receives it (skinlab/render/environment.py): the map's irradiance at
// the shading normal (lib/environment.glsl env_map_irradiance), times the share of it the scene leaves
// visible at this point (variant SKY_OCCLUSION): per channel, the vertex's open rays' sum of the map's
// radiance against all its rays' (skinlab/scene/interreflection.py sky_visible_share; lib/sky_vertex.glsl,
// interpolated), in [0, 1]. The light the hidden surfaces send instead is the interreflection's
// (lib/ambient.glsl). NumPy twin: skinlab/render/environment.py env_diffuse.
#include "lib/environment.glsl"
#ifdef SKY_OCCLUSION
#if defined(DEFERRED_SURFACE) || defined(VERTEX_TEXELS)
// read by the pass, not interpolated: from a G-buffer (techniques/tsd/surface.glsl) or per vertex
// (passes/bounce_exitance.frag)
vec4 v_sky;
#else
in vec4 v_sky;
#endif
#endif

// The sky occlusion's record (lib/sky_blocked.glsl): the share of the map's light seen, per channel,
// and the share of the rays that leave the scene, each in [0, 1].
vec3 env_sky_share(vec4 sky) { return clamp(sky.rgb, 0.0, 1.0); }
float env_sky_rays(vec4 sky) { return clamp(sky.a, 0.0, 1.0); }

// The share of the map's light at normal n that this point sees (1 without SKY_OCCLUSION).
vec3 env_visible_share(vec3 n) {
#ifdef SKY_OCCLUSION
    return env_sky_share(v_sky);
#else
    return vec3(1.0);
#endif
}

vec3 env_diffuse_irradiance(vec3 n) {
    return env_map_irradiance(n) * env_visible_share(n);
}

// The share of the sky this point sees (1 - its rays' blocked share).
float env_sky_visibility() {
#ifdef SKY_OCCLUSION
    return env_sky_rays(v_sky);
#else
    return 1.0;
#endif
}

// The map's specular light toward v at a surface of normal n (split sum), occluded by the sky's
// visibility and the material's occlusion. The grazing term B is weighted by F90 = min(50 F0, 1)
// (Karis 2013: a reflectance below 2 % is no real interface): an index-matched boundary (F0 = 0)
// reflects nothing at any angle, as the true Fresnel at index 1 and the path-traced truth's null
// boundary; every real dielectric (F0 >= 0.02) keeps the whole of Schlick's edge.
vec3 env_specular(vec3 n, vec3 v, float roughness, vec3 f0, float occlusion) {
    float NoV = clamp(dot(n, v), 0.0, 1.0);
    vec2 ab = env_brdf(NoV, roughness);
    float so = env_specular_occlusion(NoV, env_sky_visibility() * occlusion, roughness);
    vec3 f90 = clamp(50.0 * f0, 0.0, 1.0);
    return env_radiance(reflect(-v, n), roughness) * (f0 * ab.x + f90 * ab.y) * so;
}
