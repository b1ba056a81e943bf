// Disney principled BRDF pieces (Burley 2012, "Physically Based Shading at Disney"):
// Burley diffuse with retro-reflection, GGX D, height-correlated Smith G, Schlick Fresnel.
// NumPy twin: skinlab/scene/optics/brdf.py (same names, same clamps). Formulas: docs/references.md#burley-2012.
#include "skinlab/constants.glsl"

float pow5(float x) { float x2 = x * x; return x2 * x2 * x; }

// alpha = roughness^2, clamped so roughness 0 stays finite in fp32.
float ggx_alpha(float roughness) { return max(roughness * roughness, MIN_GGX_ALPHA); }

// GGX / Trowbridge-Reitz normal distribution. d = NoH^2 (a^2 - 1) + 1 written as
// sin^2 + NoH^2 a^2 with sin^2 = (1 - NoH)(1 + NoH): no cancellation near the peak.
float ggx_d(float NoH, float a) {
    NoH = clamp(NoH, 0.0, 1.0);
    float a2 = a * a;
    float s2 = (1.0 - NoH) * (1.0 + NoH);
    float d = s2 + NoH * NoH * a2;
    return a2 / (PI * d * d);
}

// Smith Lambda for GGX: (sqrt(1 + a^2 tan^2) - 1) / 2 = x / (2 (sqrt(1 + x) + 1)), x = a^2 tan^2.
float smith_lambda(float NoX, float a) {
    float c = clamp(NoX, MIN_COS, 1.0);
    float t2 = (1.0 - c) * (1.0 + c) / (c * c);
    float x = a * a * t2;
    return 0.5 * x / (sqrt(1.0 + x) + 1.0);
}

// Height-correlated masking-shadowing G2 = 1 / (1 + Lambda(l) + Lambda(v)).
float smith_g2(float NoL, float NoV, float a) {
    return 1.0 / (1.0 + smith_lambda(NoL, a) + smith_lambda(NoV, a));
}

// Schlick's Fresnel toward F90 = min(50 F0, 1) at grazing (Karis 2013: a reflectance below 2 % is no
// real interface): an index-matched boundary (specular 0, F0 = 0) reflects nothing at any angle, as
// the true Fresnel at index 1 (and the path-traced truth's null boundary); every real dielectric
// (F0 >= 0.02, specular >= 0.25) and every metal keeps Schlick's whole edge.
vec3 fresnel_schlick(vec3 f0, float VoH) {
    return f0 + (clamp(50.0 * f0, 0.0, 1.0) - f0) * pow5(1.0 - clamp(VoH, 0.0, 1.0));
}

// Burley diffuse factor (multiply by base colour): includes 1/pi and the retro-reflection.
float burley_diffuse(float NoL, float NoV, float LoH, float roughness) {
    float fd90 = 0.5 + 2.0 * roughness * LoH * LoH;
    float fl = 1.0 + (fd90 - 1.0) * pow5(1.0 - clamp(NoL, 0.0, 1.0));
    float fv = 1.0 + (fd90 - 1.0) * pow5(1.0 - clamp(NoV, 0.0, 1.0));
    return fl * fv * INV_PI;
}

// GGX microfacet specular BRDF D G F / (4 NoL NoV); zero for light below the surface.
vec3 specular_ggx(float NoL, float NoV, float NoH, float VoH, float a, vec3 f0) {
    if (NoL <= 0.0) return vec3(0.0);
    float nl = max(NoL, MIN_COS);
    float nv = max(NoV, MIN_COS);
    return ggx_d(NoH, a) * smith_g2(nl, nv, a) * fresnel_schlick(f0, VoH) / (4.0 * nl * nv);
}

// Dielectric/metal F0 from the principled parameters.
vec3 principled_f0(vec3 base, float metallic, float specular) {
    return mix(vec3(SPECULAR_F0_SCALE * specular), base, metallic);
}

// Half vector; falls back to n when l = -v (h undefined).
vec3 half_vector(vec3 n, vec3 v, vec3 l) {
    vec3 h = v + l;
    float len = length(h);
    return len > 1e-6 ? h / len : n;
}

// BRDF times cosine (outgoing radiance per unit irradiance along l) for unit n, v, l.
vec3 principled_brdf_cos(vec3 n, vec3 v, vec3 l, vec3 base, float roughness, float metallic,
                         float specular) {
    float NoL = dot(n, l);
    if (NoL <= 0.0) return vec3(0.0);
    vec3 h = half_vector(n, v, l);
    float NoV = dot(n, v);
    float NoH = dot(n, h);
    float LoH = dot(l, h);
    float a = ggx_alpha(roughness);
    vec3 diffuse = base * ((1.0 - metallic) * burley_diffuse(NoL, NoV, LoH, roughness));
    vec3 spec = specular_ggx(NoL, NoV, NoH, LoH, a, principled_f0(base, metallic, specular));
    return (diffuse + spec) * NoL;
}
