import numpy as np

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics import lighting


def test_perturb_normal_matches_numpy_including_degenerate_frames(glsl):
    rng = np.random.default_rng(1)
    n = rng.normal(size=(500, 3))
    t = np.concatenate([rng.normal(size=(500, 3)), rng.choice([-1.0, 1.0], (500, 1))], 1)
    tex = rng.uniform(0, 1, (500, 3))
    scale = rng.uniform(0, 4, 500)
    # hard cases: tangent parallel to the normal, zero tangent, flat map, zero-length normal
    t[0, :3] = n[0]
    t[1, :3] = 0
    tex[2] = [0.5, 0.5, 1.0]
    n[3] = 0
    scale[4] = 0
    n, t, tex, scale = (a.astype(np.float32).astype(np.float64) for a in (n, t, tex, scale))
    gpu = glsl.evaluate(
        "lib/lighting.glsl", "perturb_normal(n, t, tex, s)", {"n": n, "t": t, "tex": tex, "s": scale}, 3
    )
    ref = lighting.perturb_normal(n, t, tex, scale)
    # tangent exactly parallel to n: both sides fall back to n; compare away from the 1e-6 switch
    assert_close_fp32(gpu, ref, rtol=1e-4, atol=2e-6, what="perturb_normal")
    assert np.allclose(np.linalg.norm(ref, axis=1), 1.0)
    assert np.allclose(ref[2], n[2] / np.linalg.norm(n[2]))  # flat normal map leaves n unchanged


def test_inverse_square_matches_and_stays_finite_at_zero(glsl):
    d = np.concatenate([[0.0, 1e-9, 1e-3, 1.0], np.geomspace(1e-2, 1e5, 100)])
    gpu = glsl.evaluate("lib/lighting.glsl", "inverse_square(d)", {"d": d})[:, 0]
    assert_close_fp32(gpu, lighting.inverse_square(d), what="inverse_square")
    assert lighting.inverse_square(1000.0) == 1.0  # 1 m


def test_light_incidence_matches_numpy_for_directional_and_point_lights(glsl):
    from skinlab.gl.uniforms import set_array, set_uniforms

    rng = np.random.default_rng(7)
    world = rng.normal(size=(300, 3)) * 2.0
    n = rng.normal(size=(300, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    lights = np.array([[0.6, 0.0, 0.8, 0.0], [0.5, 1.0, -0.25, 1.0]])
    world[0] = lights[1, :3]  # at the point light itself: finite, l falls back to n
    world[1] = lights[1, :3] + 1e-7
    world, n = (a.astype(np.float32).astype(np.float64) for a in (world, n))
    radiance = np.array([[1.0, 0.9, 0.8], [2.0, 3.0, 4.0]])
    mm = 45.0

    def setup(prog):
        set_array(prog, "u_light_vec", lights, 4)
        set_array(prog, "u_light_radiance", radiance, 4)
        set_uniforms(prog, {"u_mm_per_unit": mm})

    prelude = """
vec3 inc_l(int i, vec3 w, vec3 n) { vec3 l, e; light_incidence(i, w, n, l, e); return l; }
vec3 inc_e(int i, vec3 w, vec3 n) { vec3 l, e; light_incidence(i, w, n, l, e); return e; }
"""
    for i in (0, 1):
        l_ref, e_ref = lighting.light_incidence(lights[i], radiance[i], world, n, mm)
        for fn, ref in (("inc_l", l_ref), ("inc_e", e_ref)):
            gpu = glsl.evaluate(
                "lib/lights.glsl", f"{fn}({i}, w, n)", {"w": world, "n": n}, 3, prelude=prelude, setup=setup
            )
            assert_close_fp32(gpu, ref, rtol=2e-4, atol=1e-5 * np.abs(ref).max(), what=f"light {i} {fn}")
    l_ref, e_ref = lighting.light_incidence(lights[1], radiance[1], world[:1], n[:1], mm)
    assert np.allclose(l_ref, n[:1]) and np.isfinite(e_ref).all()
