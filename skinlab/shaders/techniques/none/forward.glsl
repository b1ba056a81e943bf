// Subsurface hook of technique "none" (and of every mesh that does not scatter): no subsurface
// term, the surface's own Burley diffuse carries all of the diffuse light. The hook's contract is in
// skinlab/render/technique.py.

float sss_plain_weight() { return 1.0; }

void sss_add_light(vec3 e, float vis, float NoL) {}

vec3 sss_radiance(vec3 base, float NoV, float occlusion, vec2 uv) { return vec3(0.0); }
