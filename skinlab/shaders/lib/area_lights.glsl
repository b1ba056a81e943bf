// Spot and area lights' geometry (NumPy twins: skinlab/scene/optics/lighting.py). Units cancel: the
// irradiance of an area light of radiance L is L times a solid-angle factor of the light's shape.
// Sources: docs/references.md#area-lights.
#include "skinlab/constants.glsl"

// A spot's falloff toward a point in direction -l from it: 1 within the inner half-angle, 0 beyond
// the outer, linear in angle between (Mitsuba's spot). axis: the way it shines; inv = 1 / (outer - inner).
float spot_falloff(vec3 axis, vec3 l, float outer, float inv) {
    float c = dot(axis, -l);
    float angle = atan(length(cross(axis, -l)), c);
    return clamp((outer - angle) * inv, 0.0, 1.0);
}

// Irradiance at normal incidence from a sphere of radiance 1 and radius r whose centre is `dist` away:
// pi sin^2(alpha), sin(alpha) = r / dist (pi inside it). Times n.l it is exact while the whole sphere is
// above the horizon.
float sphere_irradiance(float r, float dist) {
    float s = dist > r ? r / dist : 1.0;
    return PI * s * s;
}

// The angle between two unit vectors (well conditioned near 0 and pi).
float angle_between(vec3 a, vec3 b) {
    return atan(length(cross(a, b)), dot(a, b));
}

// The vector irradiance of a one-sided rectangle of radiance 1 (centre c, half-width and half-height
// vectors ex, ey, shining along `axis`) at p: F with F.n the irradiance on any normal n that sees the
// whole rectangle above its horizon (Lambert's polygon formula: 1/2 sum over edges of the edge's angle
// times the unit normal of the plane through p and the edge). Zero behind the rectangle.
vec3 rect_vector_irradiance(vec3 c, vec3 ex, vec3 ey, vec3 axis, vec3 p) {
    if (dot(p - c, axis) <= 0.0) return vec3(0.0);
    vec3 q[4];
    q[0] = normalize(c - ex - ey - p);
    q[1] = normalize(c + ex - ey - p);
    q[2] = normalize(c + ex + ey - p);
    q[3] = normalize(c - ex + ey - p);
    vec3 f = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        vec3 a = q[k], b = q[(k + 1) % 4];
        vec3 m = cross(a, b);
        float len = length(m);
        if (len > 1e-12) f += angle_between(a, b) * (m / len);
    }
    f *= 0.5;
    return dot(f, c - p) < 0.0 ? -f : f;  // toward the light, whichever way the corners turn
}

// The specular of an area light by a representative point (Karis 2013): the point of the light nearest
// the mirror ray r = reflect(-v, n) from p, and the GGX alpha widened by the light's angular radius,
// a' = min(a + radius / (2 distance), 1), with the energy factor (a / a')^2. Sphere of radius `radius`
// centred on c; returns the direction to the point (ls) and writes a' and the factor.
vec3 sphere_specular_point(vec3 c, float radius, vec3 p, vec3 r, float a, out float a_wide, out float energy) {
    vec3 d = c - p;
    vec3 to_ray = dot(d, r) * r - d;
    float len = length(to_ray);
    vec3 q = d + to_ray * (len > 0.0 ? clamp(radius / len, 0.0, 1.0) : 0.0);
    float dist = max(length(q), 1e-20);
    a_wide = min(a + radius / (2.0 * max(length(d), 1e-20)), 1.0);
    energy = (a / a_wide) * (a / a_wide);
    return q / dist;
}

// The same for a rectangle (centre c, half-width and half-height vectors ex, ey): where the mirror ray
// meets the rectangle's plane, clamped to the rectangle (its centre when the ray runs away from the
// plane), widened as a sphere of the same area would widen it.
vec3 rect_specular_point(vec3 c, vec3 ex, vec3 ey, vec3 p, vec3 r, float a, out float a_wide, out float energy) {
    vec3 nrm = cross(ex, ey);
    float den = dot(r, nrm);
    float t = abs(den) > 1e-20 ? dot(c - p, nrm) / den : -1.0;
    vec3 hit = t > 0.0 ? p + r * t : c;
    vec3 off = hit - c;
    float lx = dot(ex, ex), ly = dot(ey, ey);
    vec3 q = c + ex * clamp(dot(off, ex) / lx, -1.0, 1.0) + ey * clamp(dot(off, ey) / ly, -1.0, 1.0) - p;
    float radius = sqrt(4.0 * sqrt(lx * ly) / PI);  // the sphere of the rectangle's area (4 |ex| |ey|)
    a_wide = min(a + radius / (2.0 * max(length(c - p), 1e-20)), 1.0);
    energy = (a / a_wide) * (a / a_wide);
    return q / max(length(q), 1e-20);
}
