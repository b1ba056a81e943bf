#version 330 core
// The environment map behind the scene (passes/background.frag): a fullscreen triangle on the far
// plane, drawn with the depth test '<=' after the meshes, so it fills only where nothing was drawn.
in vec2 in_pos;
out vec2 v_ndc;
void main() {
    v_ndc = in_pos;
    gl_Position = vec4(in_pos, 1.0, 1.0);
}
