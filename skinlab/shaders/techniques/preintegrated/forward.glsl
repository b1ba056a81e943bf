// Subsurface hook of technique "preintegrated" (Penner & Borshukov 2011, pre-integrated skin): the
// subsurface diffuse term of each light is a lookup in a table of the material's profile integrated
// around a ring of curvature c, D(N.L, c) per channel (skinlab/scene/optics/preintegrated.py), instead of
// max(N.L, 0); the light scatters past the terminator where the surface is curved. Curvature is the
// mesh's per-vertex mean curvature (v_curvature, precomputed), the normal per channel a blend of the
// normal-mapped and the geometric normal (the "softened normal": wide channels lose the map's
// detail). No pass of its own: the cheapest technique. How light enters and leaves is the shared
// boundary (lib/sss_boundary.glsl): the light a flat surface would take in, max(N.L, 0), enters by
// sss_entry(N.L) as in every technique; what the ring moves, D - max(N.L, 0), enters at every angle
// around it, so by the diffuse entry factor. Variant SSS_TRANSLUCENCY: plus the light through thin
// parts per light (lib/sss_translucency.glsl, as texture-space diffusion gathers it). Contract:
// skinlab/render/technique.py.
// The separable boundary's non-separable rest is added by the forward pass where the light lands
// (passes/forward.frag): this hook does not spread it with its diffusion.
#define SSS_MS_REST_LANDS
#include "lib/sss_boundary.glsl"
#include "lib/ambient.glsl"
#include "lib/ambient_entering.glsl"
#ifdef SSS_TRANSLUCENCY
#include "lib/sss_translucency.glsl"
#endif
#include "lib/surface_inputs.glsl"
#include "lib/preintegrated.glsl"

in float v_curvature;            // 1/scene unit (forward.vert)
uniform sampler2D u_pis_lut;     // columns N.L -1..1, rows curvature 0..u_pis_curv_max; rgb D
uniform vec2 u_pis_lut_size;     // (columns, rows)
uniform float u_pis_curv_scale;  // 1/scene unit -> 1/mm (the node's scale and the scene's mm per unit)
uniform float u_pis_curv_max;    // 1/mm at the last row (0: the table is max(N.L, 0) everywhere)
uniform vec3 u_pis_soften;       // per channel: 0 the normal-mapped normal, 1 the geometric normal

float sss_plain_weight(Surface s) { return 1.0 - s.sss_weight; }

void sss_add_light(Surface s, vec3 e, vec3 vis, float NoL) {}  // the hook runs its own light loop (below)

// Light i's light entering at s (through_exit: the light through thin parts leaving toward the viewer),
// its shadow from slot `slot` (-1: none), looked up past the terminator too (the forward pass's loop
// skips lights behind the shading normal) and by the geometric normal (the table is over it); t the
// curvature's row, nr / nG / nb the softened normals. Every call passes the slot as a constant
// (sss_radiance below), so a light without a shadow map compiles no lookup.
vec3 pis_light(Surface s, int i, int slot, float t, vec3 nr, vec3 nG, vec3 nb, inout vec3 through_exit) {
    vec3 ng = s.ng;
    vec3 l, e;
    light_incidence(i, s.position, ng, l, e);
    float nlg = dot(ng, l);
    // shadow maps only where the light faces the surface; past the terminator the ring's light
    // comes from the lit side (looked up where the light entered, spread per channel as the
    // entry is: lib/surface_inputs.glsl sss_entry_ramp)
    vec3 vis = nlg > 0.0 ? sss_entry_ramp(s, slot, l, u_sss_slab_decay) : vec3(1.0);
#ifdef HAS_NORMAL_MAP
    vec3 D = vec3(pis_lookup(u_pis_lut, u_pis_lut_size, dot(nr, l), t).r,
                  pis_lookup(u_pis_lut, u_pis_lut_size, dot(nG, l), t).g,
                  pis_lookup(u_pis_lut, u_pis_lut_size, dot(nb, l), t).b);
#else
    vec3 D = pis_lookup(u_pis_lut, u_pis_lut_size, nlg, t);  // one normal: one lookup
#endif
    float flat_nl = max(nlg, 0.0);
#ifdef SSS_TRANSLUCENCY
    if (slot >= 0) {  // light through thin parts leaves with its own angular distribution
        vec3 te;
        sss_translucent_light_toward(slot, s.position, ng, l, e, abs(s.NoV), te);
        through_exit += te;
    }
#endif
    return e * sss_near_gain(s, i) * vis * (flat_nl * sss_entry(flat_nl) + (D - flat_nl) * u_sss_entry_diffuse);
}

// Its own light loop (pis_light), with the shared surface inputs (normals, weight) and the shared shadow
// at the entry point: the lights without a shadow map, then each filled slot's.
vec3 sss_radiance(Surface s) {
    vec3 ng = s.ng, n = s.n;
    float curv = abs(v_curvature) * u_pis_curv_scale;
    float t = u_pis_curv_max > 0.0 ? curv / u_pis_curv_max : 0.0;
    vec3 nr = ng, nG = ng, nb = ng;
#ifdef HAS_NORMAL_MAP
    nr = normalize(mix(n, ng, u_pis_soften.r));
    nG = normalize(mix(n, ng, u_pis_soften.g));
    nb = normalize(mix(n, ng, u_pis_soften.b));
#endif
    vec3 entering = vec3(0.0), through_exit = vec3(0.0);
    for (int i = 0; i < MAX_LIGHTS; ++i) {
        if (i >= u_num_lights) break;
        if (u_light_shadow[i] >= 0 && u_light_shadow[i] < SHADOW_SLOTS) continue;  // below, per slot
        entering += pis_light(s, i, -1, t, nr, nG, nb, through_exit);
    }
#if SHADOW_SLOTS > 0
    if (u_slot_light[0] >= 0) entering += pis_light(s, u_slot_light[0], 0, t, nr, nG, nb, through_exit);
#endif
#if SHADOW_SLOTS > 1
    if (u_slot_light[1] >= 0) entering += pis_light(s, u_slot_light[1], 1, t, nr, nG, nb, through_exit);
#endif
    entering += ambient_entering(s.m.occlusion);
#if defined(SSS_TRANSLUCENCY) && defined(THROUGH_KERNEL)  // the transfer through the medium's, once
    vec3 kernel_in;
    through_exit += sss_translucent_toward(s.position, ng, abs(s.NoV), kernel_in);
#endif
    return s.m.sss_albedo * (entering * sss_exit(abs(s.NoV)) + through_exit)
           * ((1.0 - u_metallic) * s.sss_weight * INV_PI);
}
