// Light arriving from all around a surface, as radiance: the scene's ambient sky (u_ambient) times
// the material's occlusion, plus, with variant BOUNCE, the light the scene's surfaces throw onto
// this one (interreflection, skinlab/render/bounce.py; lib/bounce_vertex.glsl hands on v_bounce, an
// irradiance, taken here as if it came evenly from the hemisphere: radiance E / pi). Every pass
// that shades ambient light uses it, so bounce light enters the medium and is blurred like the sky's.
#include "skinlab/constants.glsl"
uniform vec3 u_ambient;
#ifdef BOUNCE
#ifdef DEFERRED_SURFACE
vec3 v_bounce;  // read from a G-buffer by the pass (techniques/tsd/surface.glsl), not interpolated
#else
in vec3 v_bounce;
#endif
#endif

vec3 ambient_radiance(float occlusion) {
    vec3 a = u_ambient * occlusion;
#ifdef BOUNCE
    a += v_bounce * INV_PI;
#endif
    return a;
}
