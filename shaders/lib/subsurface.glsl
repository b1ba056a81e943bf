// Fresnel factors of the specular layer over a subsurface medium (texture-space diffusion).
// NumPy twin: scene/optics/tsd.py (fresnel_transmission, sss_exit_weight). Sources:
// docs/references.md#burley-2012 (Schlick), #burley-2015 (exit weight).
#include "lib/brdf.glsl"

// Fraction of light crossing the interface at incidence cosine c: 1 - Schlick F.
float fresnel_transmission(float f0, float c) {
    return 1.0 - (f0 + (1.0 - f0) * pow5(1.0 - clamp(c, 0.0, 1.0)));
}

// Exit weight toward the viewer: Burley 2015's diffuse transmission factor 1 - F_V/2 with
// F_V = (1 - NoV)^5 ("Extending the Disney BRDF to a BSDF with integrated subsurface scattering"),
// over its cosine-weighted hemispherical mean 1 - 1/42 (2 int (1-mu)^5 mu dmu = 1/21), so the light
// leaving the medium is redistributed over angles, not lost. A Schlick exit (1 - F) would go to 0 at
// grazing angles and draw a dark rim along silhouettes.
float sss_exit_weight(float NoV) {
    return (1.0 - 0.5 * pow5(1.0 - clamp(NoV, 0.0, 1.0))) / (1.0 - 1.0 / 42.0);
}
