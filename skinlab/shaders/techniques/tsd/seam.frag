#version 330 core
// Seam map texel: RG = the UV (in the other chart) whose value belongs here, A = 1 where an extension
// triangle lies in the gutter; 0 on the real charts and where nothing is.
in vec2 v_src;
in float v_real;
out vec4 f_seam;
void main() {
    f_seam = v_real > 0.5 ? vec4(0.0) : vec4(v_src, 0.0, 1.0);
}
