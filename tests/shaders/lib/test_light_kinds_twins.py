"""Spot and area lights (skinlab/shaders/lib/lights.glsl light_incidence, lib/area_lights.glsl) against
their NumPy twins (skinlab/scene/optics/lighting.py), hard cases included (on the axis, at the cone's
edges, inner = outer, behind a one-sided rect, inside a sphere, grazing), and against exact integrals."""

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.gl.uniforms import set_array, set_uniforms
from skinlab.render.lights import light_shape
from skinlab.scene import transform as tf
from skinlab.scene.graph import LightNode
from skinlab.scene.optics import lighting

PRELUDE = """
vec3 inc_l(int i, vec3 w, vec3 n) { vec3 l, e; light_incidence(i, w, n, l, e); return l; }
vec3 inc_e(int i, vec3 w, vec3 n) { vec3 l, e; light_incidence(i, w, n, l, e); return e; }
"""


def make(kind, position, direction=(0, 0, -1), **shape):
    light = LightNode(kind, kind, color=(1.0, 0.8, 0.6), intensity=2.0, **shape)
    light.translation = position
    light.rotation = tf.look_at_rotation(np.zeros(3), np.asarray(direction, np.float64))
    return light


def compare(glsl, light, world, n, mm=45.0, what=""):
    vec = np.append(light.world_position, 1.0)
    axis, shape = light_shape(light)

    def setup(prog):
        set_array(prog, "u_light_vec", vec[None], 4)
        set_array(prog, "u_light_radiance", light.radiance[None], 4)
        set_array(prog, "u_light_axis", axis[None], 4)
        set_array(prog, "u_light_shape", shape[None], 4)
        set_uniforms(prog, {"u_mm_per_unit": mm})

    l_ref, e_ref = lighting.light_incidence(vec, light.radiance, world, n, mm, axis, shape)
    for fn, ref in (("inc_l", l_ref), ("inc_e", e_ref)):
        gpu = glsl.evaluate("lib/lights.glsl", f"{fn}(0, w, n)", {"w": world, "n": n}, 3, prelude=PRELUDE, setup=setup)
        # l is a unit vector: its components to 1e-4 (fp32 sums over the rect's edges cancel)
        atol = 1e-4 if fn == "inc_l" else 2e-5 * max(np.abs(ref).max(), 1e-30)
        assert_close_fp32(gpu, ref, rtol=5e-4, atol=atol, what=f"{what} {fn}")
    return l_ref, e_ref


def points(rng, n=300, spread=3.0):
    w = rng.normal(size=(n, 3)) * spread
    nrm = rng.normal(size=(n, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    return w, nrm


@pytest.mark.parametrize("inner, outer", [(20.0, 40.0), (30.0, 30.0), (0.0, 90.0)])
def test_spot_matches_numpy_and_fades_linearly_in_angle(glsl, inner, outer):
    rng = np.random.default_rng(1)
    light = make("spot", (0.0, 2.0, 0.0), (0.0, -1.0, 0.0), inner_deg=inner, outer_deg=outer)
    w, n = points(rng)
    # on the axis, just inside and outside both edges
    for k, ang in enumerate([0.0, inner - 0.5, inner + 0.5, outer - 0.5, outer + 0.5, 89.9]):
        a = np.radians(max(ang, 0.0))
        w[k] = [np.sin(a) * 2.0, 0.0, 0.0]
        w[k, 1] = 2.0 - np.cos(a) * 2.0
    w = w.astype(np.float32).astype(np.float64)
    l, e = compare(glsl, light, w, n, what=f"spot {inner}/{outer}")
    d = np.linalg.norm(w - light.world_position, axis=1)
    point_e = light.radiance * lighting.inverse_square(d * 45.0)[:, None]
    f = e[:, 0] / point_e[:, 0]
    angle = np.degrees(np.arccos(np.clip(-l @ light.direction, -1, 1)))
    full = angle <= inner
    assert np.allclose(f[full], 1.0) and np.allclose(f[angle >= outer], 0.0)
    mid = (angle > inner + 1e-6) & (angle < outer - 1e-6)
    if mid.any():
        assert np.allclose(f[mid], (outer - angle[mid]) / (outer - inner), atol=1e-6)


def test_sphere_light_matches_numpy_and_the_exact_form_factor(glsl):
    rng = np.random.default_rng(2)
    light = make("sphere", (0.25, 1.0, -0.25), radius=0.4)  # exact in fp32: the centre itself is a case
    w, n = points(rng)
    w[0] = light.world_position  # at the centre
    w[1] = light.world_position + [0.0, 0.375, 0.0]  # inside
    w = w.astype(np.float32).astype(np.float64)
    l, e = compare(glsl, light, w, n, what="sphere")
    d = np.linalg.norm(w - light.world_position, axis=1)
    outside = d > 0.4
    # a sphere of radiance L seen from d: E at normal incidence = pi L (r / d)^2 (exact)
    assert np.allclose(e[outside], light.radiance * np.pi * (0.4 / d[outside, None]) ** 2)
    assert np.allclose(e[:2], light.radiance * np.pi)


def test_rect_light_matches_numpy_and_brute_force_integration(glsl):
    rng = np.random.default_rng(3)
    light = make("rect", (0.0, 1.5, 0.0), (0.2, -1.0, 0.1), width=1.2, height=0.6)
    w, n = points(rng, spread=1.0)
    w[0] = light.world_position + light.direction * 1e-3  # just in front of its centre
    w[1] = light.world_position - light.direction * 0.5  # behind it: nothing
    w = w.astype(np.float32).astype(np.float64)
    l, e = compare(glsl, light, w, n, what="rect")
    assert np.abs(e[1]).max() == 0.0
    # just in front of the centre: a whole hemisphere of radiance L facing it -> pi L
    assert np.allclose(e[0], light.radiance * np.pi, rtol=2e-3)
    # irradiance on the normal facing the rect's centre, against a sum over the rect's area elements
    hx, hy = light.half_extents()
    u, v = np.meshgrid((np.arange(200) + 0.5) / 100 - 1, (np.arange(200) + 0.5) / 100 - 1)
    pts = light.world_position + u.reshape(-1, 1) * hx + v.reshape(-1, 1) * hy
    da = np.linalg.norm(hx) * np.linalg.norm(hy) * 4 / pts.shape[0]
    for k in range(2, 12):
        p = w[k]
        if (p - light.world_position) @ light.direction <= 0.05:
            continue
        nn = light.world_position - p
        nn /= np.linalg.norm(nn)
        r = pts - p
        dist = np.linalg.norm(r, axis=1)
        cos_r = np.clip(r @ nn / dist, 0, None)
        cos_l = np.clip(-(r @ light.direction) / dist, 0, None)
        exact = (cos_r * cos_l / dist**2).sum() * da
        got = e[k, 0] / light.radiance[0] * max(nn @ l[k], 0.0)
        assert got == pytest.approx(exact, rel=2e-3), k


def test_light_shape_rejects_bad_cones_and_sizes():
    with pytest.raises(ValueError, match="inner_deg <= outer_deg"):
        LightNode("s", "spot", inner_deg=50.0, outer_deg=40.0)
    with pytest.raises(ValueError, match="radius must be"):
        LightNode("s", "sphere", radius=0.0)
    with pytest.raises(ValueError, match="width must be"):
        LightNode("s", "rect", width=-1.0)


def test_area_specular_points_match_numpy(glsl):
    rng = np.random.default_rng(5)
    p = rng.normal(size=(200, 3)) * 2.0
    r = rng.normal(size=(200, 3))
    r /= np.linalg.norm(r, axis=1, keepdims=True)
    c, ex, ey = np.array([0.0, 2.0, 0.0]), np.array([0.5, 0.0, 0.0]), np.array([0.0, 0.0, 0.25])
    r[0] = (c - p[0]) / np.linalg.norm(c - p[0])  # the mirror ray through the centre
    a = 0.2
    prelude = """
const vec3 C = vec3(0.0, 2.0, 0.0);
vec4 sph(vec3 p, vec3 r) {
    float aw, en; vec3 l = sphere_specular_point(C, 0.4, p, r, 0.2, aw, en); return vec4(l, aw * 10.0 + en);
}
vec4 rct(vec3 p, vec3 r) {
    float aw, en; vec3 l = rect_specular_point(C, vec3(0.5, 0.0, 0.0), vec3(0.0, 0.0, 0.25), p, r, 0.2, aw, en);
    return vec4(l, aw * 10.0 + en);
}
"""
    for fn, ref in (
        ("sph", lighting.sphere_specular_point(c, 0.4, p, r, a)),
        ("rct", lighting.rect_specular_point(c, ex, ey, p, r, a)),
    ):
        gpu = glsl.evaluate("lib/area_lights.glsl", f"{fn}(w, r)", {"w": p, "r": r}, 4, prelude=prelude)
        ls, aw, en = ref
        assert_close_fp32(gpu[:, :3], ls, rtol=1e-4, atol=1e-4, what=f"{fn} direction")
        assert_close_fp32(gpu[:, 3], aw * 10 + en, rtol=1e-4, atol=1e-5, what=f"{fn} alpha, energy")
        assert np.all(aw >= a) and np.all((en > 0) & (en <= 1))
    # the mirror ray through the sphere's centre: the point is the centre's direction
    ls, _, _ = lighting.sphere_specular_point(c, 0.4, p[:1], r[:1], a)
    assert np.allclose(ls[0], r[0])
