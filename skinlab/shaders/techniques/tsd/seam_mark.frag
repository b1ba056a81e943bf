#version 330 core
// The seam map's marked texels (a > 0.5: the extension across a seam, techniques/tsd/seam_fill.frag's
// only texels that differ from a copy) into a depth mask: a fullscreen pass at depth 0.5 with the
// depth test always passing writes 0.5 where a texel is marked and leaves the clear (0) elsewhere, so
// the seam fill's early depth test ("<=") shades only the marked texels
// (skinlab/render/techniques/tsd/seams.py SeamMap.mark).
uniform sampler2D u_seam;
out vec4 f_color;
void main() {
    if (texelFetch(u_seam, ivec2(gl_FragCoord.xy), 0).a <= 0.5) discard;
    f_color = vec4(0.0);
}
