// Texture-space diffusion's surface G-buffer, the reading side (variant DEFERRED_SURFACE of
// techniques/tsd/irradiance.frag, drawn as one fullscreen triangle over the UV layout): the vertex
// outputs of techniques/tsd/uv.vert at each texel, as techniques/tsd/surface.frag rasterised them, become the
// globals the irradiance code reads (v_world, v_normal, v_uv, v_tangent, v_color, v_bounce for
// lib/ambient.glsl and v_sky for lib/sky_occlusion.glsl). A vertex output added to techniques/tsd/uv.vert must be carried here too (the fullscreen
// pass would not link without it). The same values, so the same light, as rasterising the mesh with the shading in
// the fragment shader, but each texel shaded once: a software rasteriser shades whole blocks of
// pixels for every small UV triangle that touches them (about 2.4x the covered texels on the head).
// v_uv is the texel's centre, the point the rasteriser interpolates at; its derivatives (the maps'
// filtering) are one texel, as in UV space.
uniform sampler2D u_surface0;  // world position, a = 1 where a triangle covers the texel (0: none)
uniform sampler2D u_surface1;  // normal (as interpolated), a = the tangent's handedness
uniform sampler2D u_surface2;  // tangent (as interpolated)
uniform sampler2D u_surface3;  // the vertex colour
#ifdef BOUNCE
uniform sampler2D u_surface4;  // the interreflection's irradiance (lib/bounce_vertex.glsl)
#endif
#ifdef SKY_OCCLUSION
uniform sampler2D u_surface5;  // the sky occlusion's record (lib/sky_vertex.glsl)
#endif
#ifdef THROUGH_KERNEL
uniform sampler2D u_surface6;  // the light through thin parts (lib/through_vertex.glsl)
uniform sampler2D u_surface7;  // r: its mean incidence cosine
vec4 v_through;
float v_through_cos;
#endif
vec3 v_world;
vec3 v_normal;
vec2 v_uv;
vec4 v_tangent;
vec4 v_color;

// False where no triangle covers the texel (nothing to shade: the targets keep their cleared zeros).
bool load_surface() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 s0 = texelFetch(u_surface0, p, 0);
    v_uv = gl_FragCoord.xy / vec2(textureSize(u_surface0, 0));
    if (s0.a == 0.0) return false;
    vec4 s1 = texelFetch(u_surface1, p, 0);
    v_world = s0.xyz;
    v_normal = s1.xyz;
    vec4 s2 = texelFetch(u_surface2, p, 0);
    v_tangent = vec4(s2.xyz, s1.a);
    v_color = texelFetch(u_surface3, p, 0);
#ifdef BOUNCE
    v_bounce = texelFetch(u_surface4, p, 0).rgb;
#endif
#ifdef SKY_OCCLUSION
    v_sky = texelFetch(u_surface5, p, 0);
#endif
#ifdef THROUGH_KERNEL
    v_through = texelFetch(u_surface6, p, 0);
    v_through_cos = texelFetch(u_surface7, p, 0).r;
#endif
    return true;
}
