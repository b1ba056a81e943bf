// Oblique entry (Wang & Jacques 1995): light entering a scattering medium at an angle feeds a
// diffusion displaced along the surface by sin(theta_t) z0 in the direction it travels (z0 = 1/mu_t',
// the dipole's source depth). NumPy twin and derivation: skinlab/scene/optics/oblique.py entry_offset.
// sss_entry_offset: the world offset from a surface point to where the light it re-emits entered:
// ng the unit geometric normal, l the unit direction to the light, z0_mm per channel (one offset for
// all three, weighted by luminance), eta the relative index, mm_per_unit the scene's scale.
// sss_entry_point: where to look the light's shadow up for the diffusion leaving at world: the
// entry point, moved toward the light by the offset's length (a depth bias: on a curved surface the
// offset leaves the surface by up to |offset|^2 / 2R and must not be shadowed by it; for a
// directional light it does not move the point across the map).
#include "skinlab/constants.glsl"

vec3 sss_entry_offset(vec3 ng, vec3 l, vec3 z0_mm, float eta, float mm_per_unit) {
    vec3 lt = l - ng * dot(ng, l);  // |lt| = sin(theta_i); sin(theta_t) = min(sin(theta_i) / eta, 1)
    float z0 = dot(z0_mm, vec3(LUMA_R, LUMA_G, LUMA_B));
    return lt * (z0 / (max(eta, max(length(lt), 1e-6)) * max(mm_per_unit, 1e-30)));
}

// The spread of the entry (skinlab/scene/optics/oblique.py, issue 21): the light re-emitted at a point
// entered upstream by an exponential distance, per channel of mean m b (b the luminance offset's
// length). sss_ramp_point: the lookup point at fraction f of the offset (moved toward the light as
// sss_entry_point is); sss_ramp_means: m per channel, z0_c / z0_luma over k (per channel);
// sss_diffusion_k: the diffusion's k, 1 + sqrt(3 (1 - a')) mu_t (decay = sqrt(3 (1 - a')),
// lib/sss_boundary.glsl's u_sss_slab_decay); sss_single_k: single scattering's, 1 + mu_l / mu_v (refracted
// cosines); sss_ramp_nodes: the three lookups' fractions of b, ENTRY_RAMP_N1..N3 x m's luminance mean;
// sss_ramp_mix: the three lookups weighted per channel by its exponential's spans; sss_single_pair: the
// surface point's own shadow and the one at b, each the half nearer it.
#define SSS_SINGLE_K_MIN_COS 0.05
vec3 sss_ramp_point(vec3 world, vec3 off, vec3 l, float f) {
    return world + off * f + l * (length(off) * f);
}

float sss_inside_cos(float c, float eta) {
    float e = max(eta, 1.0), cc = clamp(abs(c), 0.0, 1.0);
    return sqrt(max(1.0 - (1.0 - cc * cc) / (e * e), 0.0));
}

vec3 sss_ramp_means(vec3 z0_mm, vec3 k) {
    vec3 z0 = max(z0_mm, vec3(0.0));
    float zl = dot(z0, vec3(LUMA_R, LUMA_G, LUMA_B));
    return (zl > 0.0 ? z0 / zl : vec3(1.0)) / max(k, vec3(1.0));
}

vec3 sss_diffusion_k(vec3 decay, float mu_l, float eta) {
    return 1.0 + decay * sss_inside_cos(mu_l, eta);
}

float sss_single_k(float mu_l, float mu_v, float eta) {
    return 1.0 + sss_inside_cos(mu_l, eta) / max(sss_inside_cos(mu_v, eta), SSS_SINGLE_K_MIN_COS);
}

vec3 sss_ramp_nodes(vec3 m) {
    return vec3(ENTRY_RAMP_N1, ENTRY_RAMP_N2, ENTRY_RAMP_N3) * dot(max(m, vec3(1e-9)), vec3(LUMA_R, LUMA_G, LUMA_B));
}

vec3 sss_ramp_mix(vec3 m, float v1, float v2, float v3) {
    vec3 mm = max(m, vec3(1e-9));
    float mbar = dot(mm, vec3(LUMA_R, LUMA_G, LUMA_B));
    vec3 c1 = exp(-ENTRY_RAMP_B1 * mbar / mm), c2 = exp(-ENTRY_RAMP_B2 * mbar / mm);
    return (1.0 - c1) * v1 + (c1 - c2) * v2 + c2 * v3;
}

// The three lookup points of the diffusion's spread entry and its per-channel means m (returned): the
// luminance offset (sss_entry_offset) at the fractions sss_ramp_nodes, each moved toward the light by
// its length (sss_ramp_point); decay per channel sqrt(3 (1 - a')). Shared by the texture-space
// irradiance and lib/surface_inputs.glsl sss_entry_ramp, which look each point up in their own way.
// NumPy twin: oblique.py entry_ramp_points.
vec3 sss_ramp_setup(vec3 world, vec3 ng, vec3 l, vec3 z0_mm, vec3 decay, float eta, float mm_per_unit,
                    out vec3 p1, out vec3 p2, out vec3 p3) {
    vec3 off = sss_entry_offset(ng, l, z0_mm, eta, mm_per_unit);
    vec3 m = sss_ramp_means(z0_mm, sss_diffusion_k(decay, dot(ng, l), eta));
    vec3 f = sss_ramp_nodes(m);
    p1 = sss_ramp_point(world, off, l, f.x);
    p2 = sss_ramp_point(world, off, l, f.y);
    p3 = sss_ramp_point(world, off, l, f.z);
    return m;
}

// single scattering's pair from its k and the material's rate (oblique.py single_pair_rate, bound as
// u_sss_single_ramp): the weights of oblique.py entry_pair_weights, one exp2.
vec3 sss_single_pair(float k, vec3 rate, float v0, float vb) {
    vec3 w0 = 1.0 - exp2(-k * rate);
    return w0 * v0 + (1.0 - w0) * vb;
}

vec3 sss_entry_point(vec3 world, vec3 ng, vec3 l, vec3 z0_mm, float eta, float mm_per_unit) {
    vec3 off = sss_entry_offset(ng, l, z0_mm, eta, mm_per_unit);
    return world + off + l * length(off);
}

// A light at a finite distance (point, spot): its irradiance changes along the surface, so the
// diffusion leaving at x is fed by the irradiance where it entered, s, nearer the foot of the light,
// spread over the area the shift maps s's neighbourhood onto. On the surface's tangent plane (height
// h of the light, rho from its foot), the diffusion of light entering at rho_s is centred at
// rho_x = rho_s + k sin(theta_s), k = z0 / eta (sin(theta_t) = sin(theta_s) / eta); the map's
// Jacobian (radial x circumferential stretch) J = (1 + k h^2 / d_s^3) (1 + k / d_s), d_s the
// distance from s to the light, so the diffusion's irradiance at x is E(s) mu_s / J: the light that
// entered is kept (it integrates to the same flux), moved away from the light. Returns per channel
// g = E(s) mu_s / (J E(x) mu_x) = (d_x / d_s)^3 / J and the cosine at s (mu_s, for the entry factor);
// d_mm from the surface point to the light in millimetres, ng the unit geometric normal, z0_mm per
// channel, eta the relative index (clamped at 1). Light below or in the plane (cosine under
// SSS_NEAR_MIN_COS: the light touches the surface, where the map folds), at the point, or z0 = 0: 1;
// g at most SSS_NEAR_MAX_GAIN (reached only with the light nearer than about k / 3 to the surface: g
// peaks at 1.39 with the light 2 mm above skin1's red, 2.9 at 0.5 mm). NumPy twin:
// skinlab/scene/optics/oblique.py near_entry.
#define SSS_NEAR_MIN_COS 1e-4
#define SSS_NEAR_MAX_GAIN 4.0
vec3 sss_near_entry(vec3 d_mm, vec3 ng, vec3 z0_mm, float eta, out vec3 mu_s) {
    float h = dot(d_mm, ng);
    float dx = length(d_mm);
    mu_s = vec3(dx > 0.0 ? clamp(h / dx, 0.0, 1.0) : 1.0);
    if (h <= SSS_NEAR_MIN_COS * dx || dx <= 1e-6) return vec3(1.0);
    float rx = length(d_mm - ng * h);
    vec3 k = max(z0_mm, vec3(0.0)) / max(eta, 1.0);
    vec3 r = rx / (1.0 + k / dx);  // at or past the root of rho + k rho / d(rho) = rx
    for (int it = 0; it < 4; ++it) {  // Newton, monotone from the first step (the map is concave)
        vec3 d = sqrt(r * r + h * h);
        r = max(r - (r + k * r / d - rx) / (1.0 + k * h * h / (d * d * d)), vec3(0.0));
    }
    vec3 ds = sqrt(r * r + h * h);
    mu_s = h / ds;
    vec3 jac = (1.0 + k * h * h / (ds * ds * ds)) * (1.0 + k / ds);
    vec3 q = dx / ds;
    return min(q * q * q / jac, vec3(SSS_NEAR_MAX_GAIN));
}
