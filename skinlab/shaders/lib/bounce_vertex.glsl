// Interreflection, the receiving side in a vertex shader (skinlab/render/bounce.py): variant BOUNCE
// reads this vertex's irradiance from the scene's surfaces (the last bounce pass's vertex-space
// target: vertex i of the frame's meshes at texel (i % width, i / width)) and hands it on as
// v_bounce (W/m^2 equivalent, like the lights' e). Without BOUNCE, v_bounce is not declared.
#ifdef BOUNCE
uniform sampler2D u_bounce;   // per-vertex irradiance from interreflection (rgb)
uniform int u_bounce_offset;  // this mesh's first vertex in it
out vec3 v_bounce;
void bounce_vertex() {
    int i = u_bounce_offset + gl_VertexID;
    int w = textureSize(u_bounce, 0).x;
    v_bounce = texelFetch(u_bounce, ivec2(i % w, i / w), 0).rgb;
}
#else
void bounce_vertex() {}
#endif
