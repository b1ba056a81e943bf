// Light through thin parts, shared by every technique that has it: texture-space diffusion's
// irradiance pass (techniques/tsd/irradiance.frag, d'Eon & Luebke 2007) and the forward hooks of the
// techniques without a texture-space pass (screen-space SSS, disk, pre-integrated skin), in the
// manner of Jimenez, Whelan, Sundstedt & Gutierrez 2010 ("Real-Time Realistic Skin Translucency"):
// the distance the light travelled inside the object is its distance from the light minus the
// distance of the first surface it met there (the shadow pass's distance map, passes/shadow.frag),
// looked up at the position shrunk a little along the normal; what comes through is the exact slab
// transmittance of lib/sss_boundary.glsl (sss_slab_through), a sheet crossed at the larger of the
// point's cosine to the light and its entry face's (sss_through_cosine). Only matter counts: where the point lies
// beyond the first part the light crossed (its exit, the map's exit layer), the air between that part
// and the point's own part is left out (passes/shadow.frag SHADOW_LAYER).
// NumPy twin: skinlab/scene/optics/translucency.py. Bound by skinlab/render/translucency.py. Variant
// THROUGH_KERNEL (RenderSettings.through_kernel): the light through thin parts comes from the transfer
// through the medium (skinlab/render/through_kernel.py) as per-vertex bounce light, and the per-light
// functions below bring none; the thickness functions still serve the transfer's senders.
#extension GL_ARB_gpu_shader5 : enable  // textureGather (core in GLSL 4.00): distance_quad's four texels in one
#include "lib/lights.glsl"
#include "lib/sss_boundary.glsl"

#if defined(THROUGH_KERNEL) && !defined(DEFERRED_SURFACE)
in vec4 v_through;      // lib/through_vertex.glsl (the deferred irradiance pass reads them from its G-buffer)
in float v_through_cos;
#endif
uniform sampler2D u_distance0;   // light-space distance (scene units), slot 0: the first surface
uniform sampler2D u_distance1;   // slot 1
// the part layers (fewer texels than the distance maps: skinlab/render/translucency.py part_layer_size)
uniform sampler2D u_exit0;       // slot 0: R the first surface facing away from the light (the first
                                 // part's exit), G its cosine to the light
uniform sampler2D u_exit1;       // slot 1
uniform sampler2D u_entry0;      // slot 0: the entry into the next part (the first surface facing the
                                 // light past the first part's exit by more than u_part_gap)
uniform sampler2D u_entry1;      // slot 1
uniform vec4 u_light_eye[2];     // slot light position (w = 1) or the direction light travels (w = 0)
uniform float u_thickness_shrink;  // scene units: about half a distance-map texel
uniform float u_part_gap;        // scene units: past the first part's exit by more than this is another part

float distance_texel(int slot, ivec2 t) {
    return slot == 0 ? texelFetch(u_distance0, t, 0).r : texelFetch(u_distance1, t, 0).r;
}

// At the part layers' texel containing world (clamped to the layers): x the first part's exit, y its
// cosine to the light, z the entry into the next part (1e30 where there is none).
vec3 part_layers(int slot, vec3 world) {
    vec4 p = u_shadow_matrix[slot] * vec4(world, 1.0);
    ivec2 size = slot == 0 ? textureSize(u_exit0, 0) : textureSize(u_exit1, 0);
    ivec2 t = clamp(ivec2(floor(p.xy / p.w * vec2(size))), ivec2(0), size - 1);
    vec2 e = slot == 0 ? texelFetch(u_exit0, t, 0).rg : texelFetch(u_exit1, t, 0).rg;
    float next = slot == 0 ? texelFetch(u_entry0, t, 0).r : texelFetch(u_entry1, t, 0).r;
    return vec3(e, next);
}

// The four distance-map texel centres around world's light-space position (clamped to the map),
// shared by first_hit_distance and entry_face: uv the position in the map (false outside it), f
// the bilinear fractions, a / b the lower / upper texel (b == a where clamped at the border), d their
// distances (d00, d10, d01, d11).
struct DistanceQuad {
    bool inside;
    vec2 uv;
    vec2 f;
    ivec2 a, b, size;
    vec4 d;
};

DistanceQuad distance_quad(int slot, vec3 world) {
    DistanceQuad q;
    vec4 p = u_shadow_matrix[slot] * vec4(world, 1.0);
    q.uv = p.xy / p.w;
    q.inside = !(any(lessThan(q.uv, vec2(0.0))) || any(greaterThan(q.uv, vec2(1.0))));
    q.size = slot == 0 ? textureSize(u_distance0, 0) : textureSize(u_distance1, 0);
    vec2 x = q.uv * vec2(q.size) - 0.5;
    ivec2 i0 = ivec2(floor(x));
    q.f = x - vec2(i0);
    ivec2 hi = q.size - 1;
    q.a = clamp(i0, ivec2(0), hi);
    q.b = clamp(i0 + 1, ivec2(0), hi);
#if defined(GL_ARB_gpu_shader5) || __VERSION__ >= 400
    // one gather of the same four texels (its footprint at the corner they share; the maps clamp to their
    // edge as the indices do): components x (i0, j1), y (i1, j1), z (i1, j0), w (i0, j0)
    vec2 corner = (vec2(i0) + 1.0) / vec2(q.size);
    vec4 g = slot == 0 ? textureGather(u_distance0, corner) : textureGather(u_distance1, corner);
    q.d = g.wzxy;
#else
    q.d = vec4(distance_texel(slot, q.a), distance_texel(slot, ivec2(q.b.x, q.a.y)),
               distance_texel(slot, ivec2(q.a.x, q.b.y)), distance_texel(slot, q.b));
#endif
    return q;
}

// Distance from the light of the first surface it meets on the way to world (first_hit_quad: from its
// distance_quad); false outside the map
// or where the map holds no surface. Bilinear between the four nearest texel centres (a plane's
// distance exactly; the nearest texel alone is off by up to half a texel times the surface's slope,
// which through 3 mm of skin is +-3 % of the blue light), or the texel containing the point where
// one of the four holds no surface (a silhouette in the light's view).
bool first_hit_quad(int slot, DistanceQuad q, out float first) {
    first = 0.0;
    if (!q.inside) return false;
    vec4 d = q.d;
    if (max(max(d.x, d.y), max(d.z, d.w)) < 1e29) {
        first = mix(mix(d.x, d.y, q.f.x), mix(d.z, d.w, q.f.x), q.f.y);
        return true;
    }
    first = distance_texel(slot, clamp(ivec2(floor(q.uv * vec2(q.size))), ivec2(0), q.size - 1));
    return first < 1e29;  // cleared texels: no surface
}

bool first_hit_distance(int slot, vec3 world, out float first) {
    return first_hit_quad(slot, distance_quad(slot, world), first);
}

// The face where a directional light entered the part in front of world (entry_face_quad: from its
// distance_quad; the first surface it meets
// on the way there): xyz its outward normal (toward the light), w its cosine to the light; from the
// distance map's slope across the four texel centres first_hit_distance interpolates (the bilinear's
// gradient; a plane's exactly): the distance z over the light's orthographic view (x, y) is a surface
// z(x, y) with normal (grad z, -1) / sqrt(1 + |grad z|^2) in the view's frame (x, y, the direction
// the light travels). w = 0 where it is not known: a point or spot light, outside the map, or one of
// the four texels without a surface (a silhouette in the light's view).
vec4 entry_face_quad(int slot, DistanceQuad q) {
    if (u_light_eye[slot].w != 0.0) return vec4(0.0);
    mat4 m = u_shadow_matrix[slot];
    if (!q.inside) return vec4(0.0);
    float d00 = q.d.x, d10 = q.d.y, d01 = q.d.z, d11 = q.d.w;
    vec2 f = q.f;
    ivec2 a = q.a, b = q.b, size = q.size;
    if (max(max(d00, d10), max(d01, d11)) >= 1e29) return vec4(0.0);
    // the view's x and y in the world, and scene units per texel along them: the matrix's rows
    // scale world to uv
    vec3 r0 = vec3(m[0][0], m[1][0], m[2][0]), r1 = vec3(m[0][1], m[1][1], m[2][1]);
    vec2 texel = 1.0 / (vec2(size) * vec2(length(r0), length(r1)));
    vec2 g = vec2(mix(d10 - d00, d11 - d01, f.y), mix(d01 - d00, d11 - d10, f.x)) / texel;
    g = mix(vec2(0.0), g, greaterThan(b, a));  // a clamped neighbour (the map's border): no slope
    float c = inversesqrt(1.0 + dot(g, g));
    vec3 n = (g.x * normalize(r0) + g.y * normalize(r1) - u_light_eye[slot].xyz) * c;
    return vec4(n, c);
}

vec4 entry_face(int slot, vec3 world) {
    return entry_face_quad(slot, distance_quad(slot, world));
}

float distance_from_light(int slot, vec3 world) {
    vec4 e = u_light_eye[slot];
    return e.w == 0.0 ? dot(world, e.xyz) : length(world - e.xyz);
}

// Thickness (mm, along the normal ng) of the matter between the light of `slot` and world, for a
// surface whose normal makes cosine `back` with the direction the light travels: the distance
// inside along the light times that cosine (a flat slab's own thickness). The lookup point is
// world - shrink ng (Jimenez et al. 2010): a fragment that is itself the first surface (within the
// map's texel) or lies less than the shrink behind it reads 0, not the map's quantisation noise;
// behind that, the shrink is added back, so a flat part keeps its exact thickness. Where the point
// lies past the first part's exit by more than the part gap, its light crossed that part and then
// air: the thickness is the first part's (its chord times the cosine at its exit) plus the point's
// own part's (from the next entry, times `back`); index-matched parallel slabs transmit exactly as
// one slab of their summed thickness. False where the map has no surface in front.
bool sss_thickness_mm(int slot, vec3 world, vec3 ng, float back, out float d_mm) {
    vec3 p = world - u_thickness_shrink * ng;
    float first;
    d_mm = 0.0;
    if (!first_hit_distance(slot, p, first)) return false;
    float at = distance_from_light(slot, p);
    float inside = at - first;
    vec3 layers = part_layers(slot, p);
    if (layers.x < 1e29 && at > layers.x + u_part_gap) {
        float own = layers.z < at ? at - layers.z : 0.0;
        inside = max(layers.x - first, 0.0) * layers.y + own * back;
        d_mm = (inside + u_thickness_shrink) * u_mm_per_unit;
        return true;
    }
#ifdef MEASURE_BULGE_CHORD  // a measurement variant (tools/closeup_variants.py): a bulge's chord x cosine^k
    vec4 ent = entry_face(slot, p);
    if (ent.w > 0.0 && dot(ng, ent.xyz) >= 0.0) back = pow(back, MEASURE_BULGE_CHORD);
#endif
    d_mm = inside > 0.0 ? (inside * back + u_thickness_shrink) * u_mm_per_unit : 0.0;
    return true;
}

// The cosine at which light through the part in front of world is taken to cross it, for a surface
// whose own normal ng makes cosine `back` with the direction the light travels. Where the part is a
// sheet (the face where the light entered it, entry_face at the lookup point sss_thickness_mm uses,
// faces away from the point's own face: their normals opposed), the larger of `back` and the entry
// face's cosine: of the two local slabs (parallel to the point's face, parallel to the entry face) the
// thicker, lit at its cosine; the thickness is the chord times it and the light enters at it (the
// irradiance projected on that face, the slab transmittance and its exit at that cosine). The two are
// the same on a flat part. On a curved sheet the point's own face grazes the light where the entry
// face does not, and the chord times the point's cosine alone read the sheet thin there: the back-lit
// ear's blue 3.8 times the truth's (issue 21, docs/ground-truth.md; tools/translucency_check.py). Where
// the light skims through a bulge instead (the two normals on one side: the nose's and the head's
// shadowed sides), a thicker reading took light the truth has, so `back` itself; and where the entry
// face is not known (entry_face's w = 0) or the point lies past the first part's exit (the layered
// case: its own part's entry is not in the map). NumPy twin: translucency.py through_cosine.
float sss_through_cosine(int slot, vec3 world, vec3 ng, float back) {
    vec3 p = world - u_thickness_shrink * ng;
    vec3 layers = part_layers(slot, p);
    if (layers.x < 1e29 && distance_from_light(slot, p) > layers.x + u_part_gap) return back;
    vec4 entry = entry_face(slot, p);
    if (entry.w <= 0.0 || dot(ng, entry.xyz) >= 0.0) return back;
    return max(entry.w, back);
}

// What crosses a slab d_mm thick from its far side, lit there at cosine `back`, and leaves through
// this side, per unit irradiance on a surface facing the light and per unit base colour: the exact
// slab transmittance (lib/sss_boundary.glsl sss_slab_through: all orders of scattering, Fresnel in
// and out; NumPy skinlab/scene/optics/slab.py slab_through).
vec3 sss_through(float back, float d_mm) {
    return sss_slab_through(back, d_mm);
}

// What light entering at cosine c changes of the light a part depth_mm thick lets through, for weights
// made for light entering along the normal (the transfer through the medium's, passes/through_entering.frag):
// sss_through(c, d) / sss_through(1, d), and 1 where sss_through(1, d) is not above 1e-30 (no depth: a
// vertex whose rays met nothing, where the slab lets nothing through; or too thick for a float). NumPy twin:
// skinlab/scene/optics/translucency.py through_incidence.
vec3 sss_through_incidence(float c, float depth_mm) {
    vec3 normal_in = sss_through(1.0, depth_mm);
    return mix(vec3(1.0), sss_through(c, depth_mm) / max(normal_in, vec3(1e-30)), greaterThan(normal_in, vec3(1e-30)));
}

// Irradiance entering the medium at world through thin parts from the light of shadow slot `slot` (a
// light's u_light_shadow; direction to it l, its irradiance e on a surface facing it); ng: the
// surface's outward geometric normal; the part crossed at sss_through_cosine's cosine. Zero for a light
// without a distance map (slot -1) or in front of the surface.
vec3 sss_translucent_light(int slot, vec3 world, vec3 ng, vec3 l, vec3 e) {
#ifdef THROUGH_KERNEL  // the transfer through the medium brings it instead (lib/bounce_vertex.glsl)
    return vec3(0.0);
#endif
    float back = -dot(ng, l);
    float d_mm;
    if (slot < 0 || back <= 0.0) return vec3(0.0);
    float c = sss_through_cosine(slot, world, ng, back);
    if (!sss_thickness_mm(slot, world, ng, c, d_mm)) return vec3(0.0);
    return e * c * sss_through(c, d_mm);
}

// The same light leaving toward a viewer at cosine mu, times the exit factor of light that came
// through (lib/sss_boundary.glsl sss_slab_exit, at the light's cosine `back` on the far face;
// reflected light leaves with sss_exit instead): times base colour / pi it is radiance, as the
// reflected light's entering x sss_exit. `through_exit` returns it; the value is the light entering
// (as sss_translucent_light). NumPy twin: skinlab/scene/optics/translucency.py translucent_exit.
vec3 sss_translucent_light_toward(int slot, vec3 world, vec3 ng, vec3 l, vec3 e, float mu, out vec3 through_exit) {
    float back = -dot(ng, l);
    float d_mm;
    through_exit = vec3(0.0);
#ifdef THROUGH_KERNEL  // the transfer through the medium brings it instead (lib/bounce_vertex.glsl)
    return vec3(0.0);
#endif
    if (slot < 0 || back <= 0.0) return vec3(0.0);
#ifdef MEASURE_NO_THICKNESS  // measurement variants (tools/forward_cost.py --translucency): a part taken out
    float c = back;
    d_mm = 3.0;
#else
    float c = sss_through_cosine(slot, world, ng, back);
    if (!sss_thickness_mm(slot, world, ng, c, d_mm)) return vec3(0.0);
#endif
#ifdef MEASURE_NO_SLAB_THROUGH
    vec3 entering = e * (c * d_mm);
#else
    vec3 entering = e * c * sss_through(c, d_mm);
#endif
#ifdef MEASURE_NO_SLAB_EXIT
    through_exit = entering * mu;
#else
    through_exit = entering * sss_slab_exit(mu, c, d_mm);
#endif
    return entering;
}

// The sum over the lights of the light through thin parts leaving toward a viewer at cosine mu
// (sss_translucent_light_toward's through_exit); `entering` gets the light entering. With
// THROUGH_KERNEL: the transfer's light at this point (v_through), leaving as through a slab of its
// depth lit at its mean incidence (v_through_cos).
vec3 sss_translucent_toward(vec3 world, vec3 ng, float mu, out vec3 entering) {
#ifdef THROUGH_KERNEL
    entering = v_through.rgb;
    return v_through.rgb * sss_slab_exit(mu, v_through_cos, v_through.a);
#endif
    vec3 acc = vec3(0.0);
    entering = vec3(0.0);
#if SHADOW_SLOTS > 0  // only a light with a distance map shines through: each filled slot's, the slot a constant
    vec3 l, e, te;
    if (u_slot_light[0] >= 0) {
        light_incidence(u_slot_light[0], world, ng, l, e);
        entering += sss_translucent_light_toward(0, world, ng, l, e, mu, te);
        acc += te;
    }
#endif
#if SHADOW_SLOTS > 1
    if (u_slot_light[1] >= 0) {
        light_incidence(u_slot_light[1], world, ng, l, e);
        entering += sss_translucent_light_toward(1, world, ng, l, e, mu, te);
        acc += te;
    }
#endif
    return acc;
}
