#version 330 core
// Stretch map: world millimetres per texel along u (r) and v (g); a = coverage (1 on the charts).
// d'Eon & Luebke store 1/|dP/du|; we store its inverse in mm per texel (finite for zero-area
// triangles, which give 0 and are clamped where used). In UV space dFdx moves one texel along u.
#include "skinlab/constants.glsl"
in vec3 v_world;
uniform float u_mm_per_unit;
out vec4 f_stretch;
void main() {
    vec3 p = v_world * u_mm_per_unit;
    f_stretch = vec4(length(dFdx(p)), length(dFdy(p)), 0.0, 1.0);
}
