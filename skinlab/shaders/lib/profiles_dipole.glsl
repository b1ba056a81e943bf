// Jensen et al. 2001 dipole (skinlab/scene/optics/dipole.py, docs/references.md#jensen-2001).
// alpha = sigma_s'/sigma_t', mfp = 1/sigma_t' (mm), eta relative index; r in mm; result 1/mm^2.
#include "lib/profiles_common.glsl"

float dipole_a(float eta) { float f = fdr(eta); return (1.0 + f) / (1.0 - f); }

vec3 sigma_tr_optical(vec3 alpha) { return sqrt(3.0 * max(1.0 - alpha, 0.0)); }

// z (s + 1/d) e^{-s d} / d^2 : the (s d + 1) e^{-s d}/d^3 of the paper, finite as d -> inf.
vec3 dipole_pole(float z, vec3 d, vec3 s) { return z * (s + 1.0 / d) * exp(-s * d) / (d * d); }

vec3 dipole_profile(float r, vec3 alpha, vec3 mfp, float eta) {
    vec3 valid, inv_l2;
    vec3 x = optical_radius(r, mfp, valid, inv_l2);
    vec3 s = sigma_tr_optical(alpha);
    float zv = 1.0 + 4.0 / 3.0 * dipole_a(eta);
    vec3 dr = sqrt(x * x + 1.0);
    vec3 dv = sqrt(x * x + zv * zv);
    return valid * alpha / (4.0 * PI) * (dipole_pole(1.0, dr, s) + dipole_pole(zv, dv, s)) * inv_l2;
}

vec3 dipole_total(vec3 alpha, float eta) {
    vec3 s = sigma_tr_optical(alpha);
    return 0.5 * alpha * (1.0 + exp(-4.0 / 3.0 * dipole_a(eta) * s)) * exp(-s);
}
