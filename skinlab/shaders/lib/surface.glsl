// The surface inputs a glTF material brings beyond the principled BRDF (skinlab/scene/materials.py):
// occlusion strength, opacity and its mask. NumPy twin: skinlab/scene/optics/surface.py (same names).

// The ambient occlusion a map value gives at glTF's occlusion strength: 1 + strength (map - 1).
float occlusion_at_strength(float map_r, float strength) {
    return 1.0 + clamp(strength, 0.0, 1.0) * (clamp(map_r, 0.0, 1.0) - 1.0);
}

// Opacity: the material's alpha x the colour map's alpha x the vertex colour's alpha, in [0, 1].
float surface_alpha(float alpha, float map_a, float vertex_a) {
    return clamp(alpha * map_a * vertex_a, 0.0, 1.0);
}

// A masked surface is there where its opacity reaches the cutoff (glTF alphaMode MASK).
bool alpha_kept(float a, float cutoff) { return a >= cutoff; }
