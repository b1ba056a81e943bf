#version 330 core
// Seam map texel: B = the chart (1-based) the texel belongs to: a real chart's, or in the gutter the
// chart an extension triangle continues (0: nobody's); RG = the UV (in the other chart) whose value
// belongs here and A = 1 where an extension triangle lies; RG = A = 0 on the real charts.
in vec2 v_src;
in float v_real;
flat in float v_chart;
out vec4 f_seam;
void main() {
    f_seam = v_real > 0.5 ? vec4(0.0, 0.0, v_chart, 0.0) : vec4(v_src, v_chart, 1.0);
}
