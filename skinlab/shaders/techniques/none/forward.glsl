// Subsurface hook of technique "none" (and of every mesh that does not scatter): no subsurface
// term, the surface's own Burley diffuse carries all of the diffuse light. The hook's contract is in
// skinlab/render/technique.py.

#define SSS_HOOK_PLAIN  // passes/forward.frag: no single scattering to shade
float sss_plain_weight(Surface s) { return 1.0; }

void sss_add_light(Surface s, vec3 e, vec3 vis, float NoL) {}

vec3 sss_radiance(Surface s) { return vec3(0.0); }
