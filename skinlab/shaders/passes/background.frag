#version 330 core
// The environment map seen behind the scene (skinlab/render/passes/forward.py): the map itself, its
// sources included, along each pixel's view ray, x intensity. Alpha 0: the frame's alpha stays the
// meshes' coverage (the tone mapping shows these texels with variant BACKGROUND_DRAWN).
#include "lib/environment.glsl"
in vec2 v_ndc;
uniform mat4 u_inv_view_proj;
uniform vec3 u_camera_pos;
uniform sampler2D u_env_background;
out vec4 f_color;
void main() {
    vec4 far = u_inv_view_proj * vec4(v_ndc, 1.0, 1.0);
    vec3 d = normalize(far.xyz / far.w - u_camera_pos);
    vec3 c = u_env_intensity * textureLod(u_env_background, equirect_uv(u_env_to_map * d), 0.0).rgb;
    f_color = vec4(c, 0.0);
}
