#version 330 core
// Depth pre-pass (skinlab/render/passes/forward.py): forward.vert's positions, depth only, no colour.
// The forward pass then shades each visible pixel once (depth test <=, no depth writes). Variant
// ALPHA_MASK: a masked material's cut-away pixels write no depth (lib/alpha_mask.glsl). Also the
// strip mask of texture-space diffusion's light-through record fill (with fullscreen.vert's in_pos:
// skinlab/render/techniques/tsd/passes.py strip_mask).
#ifdef ALPHA_MASK
#include "lib/alpha_mask.glsl"
#endif
void main() {
#ifdef ALPHA_MASK
    alpha_mask_test();
#endif
}
