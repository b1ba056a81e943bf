// Pre-integrated skin (Penner & Borshukov 2011): the lookup in the N.L x curvature table.
// NumPy twin: skinlab/scene/optics/preintegrated.py lut_lookup.

// The table at N.L and row coordinate t = curvature / curv_max, through texel centres (linear
// filter; size = (columns, rows)); both clamped to the table.
vec3 pis_lookup(sampler2D lut, vec2 size, float nol, float t) {
    vec2 uv = (vec2(clamp(nol, -1.0, 1.0) * 0.5 + 0.5, clamp(t, 0.0, 1.0)) * (size - 1.0) + 0.5) / size;
    return texture(lut, uv).rgb;
}
