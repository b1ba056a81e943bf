// UV seams in texture-space diffusion (skinlab/render/techniques/tsd/seams.py): a gutter texel that the
// seam map marks (a = 1) stands for the surface across a seam, whose value is read at the seam map's
// UV (rg, in the other chart). Bilinear by hand (four texelFetch, clamped), so the NumPy twin
// (skinlab/scene/optics/tsd.py seam_bilinear_reference) agrees to fp32 rounding. Premultiplied values.
vec4 seam_bilinear(sampler2D src, vec2 uv) {
    ivec2 last = textureSize(src, 0) - 1;
    vec2 x = uv * vec2(textureSize(src, 0)) - 0.5;
    vec2 fl = floor(x);
    vec2 f = x - fl;
    ivec2 i = ivec2(fl);
    vec4 a = texelFetch(src, clamp(i, ivec2(0), last), 0);
    vec4 b = texelFetch(src, clamp(i + ivec2(1, 0), ivec2(0), last), 0);
    vec4 c = texelFetch(src, clamp(i + ivec2(0, 1), ivec2(0), last), 0);
    vec4 d = texelFetch(src, clamp(i + ivec2(1, 1), ivec2(0), last), 0);
    vec4 lo = a + (b - a) * f.x;
    vec4 hi = c + (d - c) * f.x;
    return lo + (hi - lo) * f.y;
}

// src's texel p, or across the seam where the seam map marks p.
vec4 seam_fetch(sampler2D src, sampler2D seam, ivec2 p) {
    vec4 s = texelFetch(seam, p, 0);
    return s.a > 0.5 ? seam_bilinear(src, s.rg) : texelFetch(src, p, 0);
}
