// Interreflection (skinlab/render/bounce.py, NumPy twin skinlab/scene/interreflection.py): what a surface sends
// back out of the light it receives, as the bounce counts it.
#include "lib/brdf.glsl"

// Diffuse albedo plus the specular reflectance at normal incidence, both as if Lambertian
// (skinlab/scene/interreflection.py sender_albedo).
vec3 bounce_sender_albedo(vec3 base, float metallic, float specular) {
    return base * (1.0 - metallic) + principled_f0(base, metallic, specular);
}
