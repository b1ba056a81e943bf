// Light through thin parts as a transfer through the medium, the receiving side in a vertex shader
// (skinlab/render/through_kernel.py): variant THROUGH_KERNEL reads this vertex's light through from
// the through pass's vertex-space target (vertex i of the frame's scattering meshes at texel
// (i % width, i / width)) and hands it on as v_through: rgb the light entering through, per unit base
// colour (as lib/sss_translucency.glsl's sss_translucent_light), a the depth it came through (mm, for
// its exit factor), and v_through_cos the light's mean incidence cosine where it entered (its exit
// factor too). Without THROUGH_KERNEL, neither is declared.
#ifdef THROUGH_KERNEL
uniform sampler2D u_through;      // per-vertex light through thin parts
uniform sampler2D u_through_cos;  // per-vertex: r its mean incidence cosine
uniform int u_through_offset;     // this mesh's first vertex in them
out vec4 v_through;
out float v_through_cos;
void through_vertex() {
    int i = u_through_offset + gl_VertexID;
    int w = textureSize(u_through, 0).x;
    v_through = texelFetch(u_through, ivec2(i % w, i / w), 0);
    v_through_cos = texelFetch(u_through_cos, ivec2(i % w, i / w), 0).r;
}
#else
void through_vertex() {}
#endif
