#version 330 core
// Interreflection, one order (skinlab/render/bounce.py; NumPy twin skinlab/scene/interreflection.py gather):
// the irradiance each vertex receives from the surfaces its rays met, E(i) = sum_k sum_j w_kj M(v_kj)
// with the rays' three vertices v and barycentric weights w / rays (cosine-weighted rays: the
// one-bounce estimator of a Lambertian sender, E = E_cos[M]). One fragment per vertex.
uniform sampler2D u_exitance;      // radiant exitance per vertex (bounce_exitance.frag)
uniform sampler2D u_ray_vertices;  // per ray: the three vertices of the triangle it met
uniform sampler2D u_ray_weights;   // per ray: their barycentric weights / rays (0: it met nothing)
uniform int u_rays;                // rays per vertex
uniform int u_vertices;            // vertices in the target

out vec4 f_irradiance;

vec3 exitance_of(int v, int w) {
    return texelFetch(u_exitance, ivec2(v % w, v / w), 0).rgb;
}

void main() {
    int w = textureSize(u_exitance, 0).x;
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * w + t.x;
    vec3 sum = vec3(0.0);
    if (i < u_vertices) {
        int rw = textureSize(u_ray_vertices, 0).x;
        for (int k = 0; k < u_rays; ++k) {
            int r = i * u_rays + k;
            ivec2 rt = ivec2(r % rw, r / rw);
            vec3 wt = texelFetch(u_ray_weights, rt, 0).rgb;
            ivec3 v = ivec3(texelFetch(u_ray_vertices, rt, 0).rgb + 0.5);
            sum += wt.x * exitance_of(v.x, w) + wt.y * exitance_of(v.y, w) + wt.z * exitance_of(v.z, w);
        }
    }
    f_irradiance = vec4(sum, 1.0);
}
