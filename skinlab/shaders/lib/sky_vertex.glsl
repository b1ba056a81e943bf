// Sky occlusion, the vertex side (skinlab/render/environment.py): variant SKY_OCCLUSION reads this
// vertex's 9 SH coefficients of what its rays meet (lib/sky_blocked.glsl) and hands them on to
// lib/sky_occlusion.glsl. Without SKY_OCCLUSION nothing is declared.
#ifdef SKY_OCCLUSION
#include "lib/sky_blocked.glsl"
out vec4 v_sky03;
out vec4 v_sky47;
out float v_sky8;
void sky_vertex() { sky_blocked_fetch(gl_VertexID, v_sky03, v_sky47, v_sky8); }
#else
void sky_vertex() {}
#endif
