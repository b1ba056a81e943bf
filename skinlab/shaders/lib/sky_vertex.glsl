// Sky occlusion, the vertex side (skinlab/render/environment.py): variant SKY_OCCLUSION reads this
// vertex's 9 SH coefficients of what its rays meet (skinlab/scene/interreflection.py sky_blocked;
// vertex i of the frame's meshes at texels (3 (i % 1024) + k, i / 1024), k = 0, 1, 2) and hands them
// on to lib/sky_occlusion.glsl. Without SKY_OCCLUSION nothing is declared.
#ifdef SKY_OCCLUSION
uniform sampler2D u_sky_blocked;
uniform int u_sky_offset;  // this mesh's first vertex in it
out vec4 v_sky03;
out vec4 v_sky47;
out float v_sky8;
void sky_vertex() {
    int i = u_sky_offset + gl_VertexID;
    ivec2 p = ivec2(3 * (i % 1024), i / 1024);
    v_sky03 = texelFetch(u_sky_blocked, p, 0);
    v_sky47 = texelFetch(u_sky_blocked, p + ivec2(1, 0), 0);
    v_sky8 = texelFetch(u_sky_blocked, p + ivec2(2, 0), 0).x;
}
#else
void sky_vertex() {}
#endif
