#version 330 core
// Stretch map: world millimetres per texel along u (r) and v (g); a = coverage (1 on the charts).
// d'Eon & Luebke store 1/|dP/du|; we store its inverse in mm per texel (finite for zero-area
// triangles, which give 0 and are clamped where used). In UV space dFdx moves one texel along u.
// With the material's subsurface radius map, divided by the texel's radius scale: the blurs, whose
// widths are in mm, then spread that much further there (d'Eon & Luebke vary blur width through
// the stretch map; lib/sss_maps.glsl).
#include "skinlab/constants.glsl"
#include "skinlab/material.glsl"
#include "lib/sss_maps.glsl"
in vec3 v_world;
in vec2 v_uv;
uniform float u_mm_per_unit;
out vec4 f_stretch;
void main() {
    vec3 p = v_world * u_mm_per_unit;
    float s = max(sss_radius_scale_at(v_uv), 1e-3);
    f_stretch = vec4(length(dFdx(p)) / s, length(dFdy(p)) / s, 0.0, 1.0);
}
