// Light arriving from all around a surface, as radiance: the scene's ambient sky (u_ambient) times
// the material's occlusion; with variant ENV_MAP the environment map's diffuse light at the normal
// the pass set (ambient_set_normal; lib/sky_occlusion.glsl: less what the scene hides of the sky,
// variant SKY_OCCLUSION), as the uniform radiance that brings the same irradiance (E / pi); with
// variant BOUNCE the light the scene's surfaces throw onto this one (interreflection,
// skinlab/render/bounce.py; lib/bounce_vertex.glsl hands on v_bounce, an irradiance, taken here as if
// it came evenly from the hemisphere: radiance E / pi). Every pass that shades ambient light uses it,
// so the map's and the bounce light enter the medium and are blurred like the sky's.
#include "skinlab/constants.glsl"
#ifdef ENV_MAP
#include "lib/sky_occlusion.glsl"
#endif
uniform vec3 u_ambient;
#ifdef BOUNCE
#ifdef DEFERRED_SURFACE
vec3 v_bounce;  // read from a G-buffer by the pass (techniques/tsd/surface.glsl), not interpolated
#else
in vec3 v_bounce;
#endif
#endif

vec3 ambient_normal = vec3(0.0, 0.0, 1.0);  // the shading normal for the map's diffuse light

void ambient_set_normal(vec3 n) { ambient_normal = n; }

// The uniform sky and the bounce light (no environment map).
vec3 ambient_uniform(float occlusion) {
    vec3 a = u_ambient * occlusion;
#ifdef BOUNCE
    a += v_bounce * INV_PI;
#endif
    return a;
}

vec3 ambient_radiance(float occlusion) {
    vec3 a = ambient_uniform(occlusion);
#ifdef ENV_MAP
    a += env_diffuse_irradiance(ambient_normal) * (INV_PI * occlusion);
#endif
    return a;
}
