#version 330 core
// Seam map (skinlab/render/techniques/tsd/seams.py, skinlab/scene/uv_seams.py): extension triangles - the surface
// across a UV seam, unfolded into the owner chart's frame - rasterised at their UVs in that frame,
// carrying their own UVs (where their irradiance is); the chart borders' own strips of gutter
// (in_src < 0: claimed, not filled); then the real charts on top (in_depth < 0).
// Depth: the distance past the seam edge (UV units, / u_depth_range), so where bands overlap the
// nearest edge's extension wins; the real charts at depth 0 always win.
in vec2 in_uv;
in vec2 in_src;
in float in_depth;
uniform float u_depth_range;
out vec2 v_src;
out float v_real;
void main() {
    v_src = in_src;
    v_real = in_depth < 0.0 || in_src.x < 0.0 ? 1.0 : 0.0;  // a real chart, or a border's own strip
    float z = in_depth < 0.0 ? -1.0 : clamp(in_depth / u_depth_range, 0.0, 1.0) * 0.998 - 0.997;
    gl_Position = vec4(in_uv * 2.0 - 1.0, z, 1.0);
}
