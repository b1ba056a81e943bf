// Sky occlusion, the vertex side (skinlab/render/environment.py): variant SKY_OCCLUSION reads this
// vertex's visible share of the map's light and of its rays (lib/sky_blocked.glsl) and hands them on to
// lib/sky_occlusion.glsl. Without SKY_OCCLUSION nothing is declared.
#ifdef SKY_OCCLUSION
#include "lib/sky_blocked.glsl"
out vec4 v_sky;
void sky_vertex() { sky_blocked_fetch(gl_VertexID, v_sky); }
#else
void sky_vertex() {}
#endif
