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
#include "lib/sss_boundary.glsl"
#include "lib/ambient.glsl"
#include "lib/ambient_entering.glsl"
#ifdef SSS_TRANSLUCENCY
#include "lib/sss_translucency.glsl"
#endif
#include "lib/sss_maps.glsl"
#include "lib/sss_oblique.glsl"
#include "lib/preintegrated.glsl"

in float v_curvature;            // 1/scene unit (forward.vert)
uniform sampler2D u_pis_lut;     // columns N.L -1..1, rows curvature 0..u_pis_curv_max; rgb D
uniform vec2 u_pis_lut_size;     // (columns, rows)
uniform float u_pis_curv_scale;  // 1/scene unit -> 1/mm (the node's scale and the scene's mm per unit)
uniform float u_pis_curv_max;    // 1/mm at the last row (0: the table is max(N.L, 0) everywhere)
uniform vec3 u_pis_soften;       // per channel: 0 the normal-mapped normal, 1 the geometric normal

float sss_plain_weight() { return 1.0 - sss_weight_at(v_uv); }

void sss_add_light(vec3 e, float vis, float NoL) {}  // the hook runs its own light loop (below)

vec3 sss_radiance(vec3 base, float NoV, float occlusion, vec2 uv) {
    vec3 ng = normalize(v_normal);
    if (!gl_FrontFacing) ng = -ng;
    vec3 n = ng;
#ifdef HAS_NORMAL_MAP
    n = perturb_normal(ng, vec4(gl_FrontFacing ? v_tangent.xyz : -v_tangent.xyz, v_tangent.w),
                       texture(u_normal_map, uv).rgb, u_normal_scale);
#endif
    float curv = abs(v_curvature) * u_pis_curv_scale;
    float t = u_pis_curv_max > 0.0 ? curv / u_pis_curv_max : 0.0;
#ifdef HAS_NORMAL_MAP
    vec3 nr = normalize(mix(n, ng, u_pis_soften.r));
    vec3 nG = normalize(mix(n, ng, u_pis_soften.g));
    vec3 nb = normalize(mix(n, ng, u_pis_soften.b));
#endif
    vec3 entering = vec3(0.0), through_exit = vec3(0.0);
    for (int i = 0; i < MAX_LIGHTS; ++i) {
        if (i >= u_num_lights) break;
        vec3 l, e;
        light_incidence(i, v_world, ng, l, e);
        float nlg = dot(ng, l);
        // shadow maps only where the light faces the surface; past the terminator the ring's light
        // comes from the lit side
        // (looked up where the light entered: oblique entry, lib/sss_oblique.glsl)
        vec3 z0 = u_sss_mfp * sss_radius_scale_at(v_uv);
        vec3 entry = sss_entry_point(v_world, ng, l, z0, u_sss_eta, u_mm_per_unit);
        float vis = (u_light_shadow[i] >= 0 && nlg > 0.0) ? light_visibility(i, entry, nlg) : 1.0;
#ifdef HAS_NORMAL_MAP
        vec3 D = vec3(pis_lookup(u_pis_lut, u_pis_lut_size, dot(nr, l), t).r,
                      pis_lookup(u_pis_lut, u_pis_lut_size, dot(nG, l), t).g,
                      pis_lookup(u_pis_lut, u_pis_lut_size, dot(nb, l), t).b);
#else
        vec3 D = pis_lookup(u_pis_lut, u_pis_lut_size, nlg, t);  // one normal: one lookup
#endif
        float flat_nl = max(nlg, 0.0);
        entering += e * vis * (flat_nl * sss_entry(flat_nl) + (D - flat_nl) * u_sss_entry_diffuse);
#ifdef SSS_TRANSLUCENCY
        vec3 te;  // light through thin parts leaves with its own angular distribution
        sss_translucent_light_toward(i, v_world, ng, l, e, abs(NoV), te);
        through_exit += te;
#endif
    }
    entering += ambient_entering(occlusion);
    return base * (entering * sss_exit(abs(NoV)) + through_exit) * ((1.0 - u_metallic) * sss_weight_at(v_uv) * INV_PI);
}
