import numpy as np

from app.gl.glsl_eval import assert_close_fp32
from scene.optics import lighting


def test_perturb_normal_matches_numpy_including_degenerate_frames(glsl):
    rng = np.random.default_rng(1)
    n = rng.normal(size=(500, 3))
    t = np.concatenate([rng.normal(size=(500, 3)), rng.choice([-1.0, 1.0], (500, 1))], 1)
    tex = rng.uniform(0, 1, (500, 3))
    scale = rng.uniform(0, 4, 500)
    # hard cases: tangent parallel to the normal, zero tangent, flat map, zero-length normal
    t[0, :3] = n[0]; t[1, :3] = 0; tex[2] = [0.5, 0.5, 1.0]; n[3] = 0; scale[4] = 0
    n, t, tex, scale = (a.astype(np.float32).astype(np.float64) for a in (n, t, tex, scale))
    gpu = glsl.evaluate("lib/lighting.glsl", "perturb_normal(n, t, tex, s)", {"n": n, "t": t, "tex": tex, "s": scale}, 3)
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
