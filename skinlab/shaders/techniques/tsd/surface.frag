#version 330 core
// Texture-space diffusion's surface G-buffer, the writing side: the mesh rasterised at its UVs
// (techniques/tsd/uv.vert), each texel's interpolated vertex outputs written as they are, for the
// irradiance pass's variant DEFERRED_SURFACE to shade each texel once (techniques/tsd/surface.glsl);
// with SKY_OCCLUSION the vertex's sky occlusion too (lib/sky_vertex.glsl), with THROUGH_KERNEL the
// light through thin parts (lib/through_vertex.glsl).
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;
in vec4 v_color;
#ifdef BOUNCE
in vec3 v_bounce;
#endif
#ifdef SKY_OCCLUSION
in vec4 v_sky;
#endif
#ifdef THROUGH_KERNEL
in vec4 v_through;
in float v_through_cos;
#endif
layout(location = 0) out vec4 f_surface0;
layout(location = 1) out vec4 f_surface1;
layout(location = 2) out vec4 f_surface2;
layout(location = 3) out vec4 f_surface3;
#if defined(BOUNCE) || defined(SKY_OCCLUSION) || defined(THROUGH_KERNEL)
layout(location = 4) out vec4 f_surface4;
#endif
#if defined(SKY_OCCLUSION) || defined(THROUGH_KERNEL)
layout(location = 5) out vec4 f_surface5;
#endif
#ifdef THROUGH_KERNEL
layout(location = 6) out vec4 f_surface6;  // the light through thin parts (lib/through_vertex.glsl)
layout(location = 7) out vec4 f_surface7;  // r: its mean incidence cosine
#endif
void main() {
    f_surface0 = vec4(v_world, 1.0);
    f_surface1 = vec4(v_normal, v_tangent.w);
    f_surface3 = v_color;
#ifdef BOUNCE
    f_surface4 = vec4(v_bounce, 0.0);
#elif defined(SKY_OCCLUSION) || defined(THROUGH_KERNEL)
    f_surface4 = vec4(0.0);
#endif
    f_surface2 = vec4(v_tangent.xyz, 0.0);
#ifdef SKY_OCCLUSION
    f_surface5 = v_sky;
#elif defined(THROUGH_KERNEL)
    f_surface5 = vec4(0.0);
#endif
#ifdef THROUGH_KERNEL
    f_surface6 = v_through;
    f_surface7 = vec4(v_through_cos, 0.0, 0.0, 0.0);
#endif
}
