// Photon beam diffusion (Habel et al. 2013 / pbrt-v4 bssrdf.cpp). See skinlab/scene/optics/pbd.py.
#include "lib/profiles_common.glsl"
#include "lib/profiles_single.glsl"

vec3 pbd_ms_profile(float r, vec3 alpha, vec3 mfp, float eta) {
    vec3 valid, inv_l2;
    vec3 x = optical_radius(r, mfp, valid, inv_l2);
    eta = clamp_eta(eta);
    float fm1 = fresnel_moment1(eta), fm2 = fresnel_moment2(eta);
    vec3 Dg = (2.0 - alpha) / 3.0;
    vec3 s = sqrt((1.0 - alpha) / Dg);
    vec3 ze = 2.0 * Dg * (1.0 + 3.0 * fm2) / (1.0 - 2.0 * fm1);   // |z_e|
    float c_phi = 0.25 * (1.0 - 2.0 * fm1);
    float c_e = 0.5 * (1.0 - 3.0 * fm2);
    vec3 acc = vec3(0.0);
    for (int i = 0; i < int(PBD_SAMPLES); ++i) {
        float zr = depth_sample(i);
        vec3 zv = zr + 2.0 * ze;                 // |z_v|
        vec3 dr = sqrt(x * x + zr * zr);
        vec3 dv = sqrt(x * x + zv * zv);
        vec3 delta = 2.0 * ze * (2.0 * zr + 2.0 * ze) / (dr + dv);
        vec3 er = exp(-s * dr);
        vec3 ev = exp(-s * dv);
        vec3 phi = er / dr * (-em1(-(s * delta + l1p(delta / dr)))) / (4.0 * PI * Dg);
        vec3 en = (zr * (s + 1.0 / dr) * er / (dr * dr) + zv * (s + 1.0 / dv) * ev / (dv * dv)) / (4.0 * PI);
        vec3 kappa = -em1(-2.0 * (dr + zr));
        acc += kappa * (phi * c_phi + en * c_e);
    }
    return valid * alpha * alpha * (acc / PBD_SAMPLES) * inv_l2;
}

vec3 pbd_profile(float r, vec3 alpha, vec3 mfp, float eta) {
    return pbd_ms_profile(r, alpha, mfp, eta) + single_scatter_profile(r, alpha, mfp, eta, 0.0);
}
