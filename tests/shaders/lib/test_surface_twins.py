"""lib/surface.glsl (occlusion strength, opacity, the alpha mask) against its NumPy twin
skinlab/scene/optics/surface.py, hard cases included (strength and alpha at 0 and 1, values out of range)."""

import itertools

import numpy as np

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics import surface


def f32(a):
    return np.asarray(a, np.float32).astype(np.float64)


def grid(*axes):
    m = np.array(list(itertools.product(*axes)), dtype=np.float64)
    return [f32(m[:, i]) for i in range(m.shape[1])]


EDGES = [-0.5, 0.0, 1e-6, 0.25, 0.5, 0.999999, 1.0, 1.5]


def test_occlusion_at_strength(glsl):
    m, s = grid(EDGES, EDGES)
    gpu = glsl.evaluate("lib/surface.glsl", "occlusion_at_strength(m, s)", {"m": m, "s": s})[:, 0]
    want = surface.occlusion_at_strength(m, s)
    assert_close_fp32(gpu, want, what="occlusion_at_strength")
    assert np.all(want[s == 0] == 1.0) and np.allclose(
        want[(s == 1) & (m >= 0) & (m <= 1)], m[(s == 1) & (m >= 0) & (m <= 1)]
    )


def test_surface_alpha_and_mask(glsl):
    a, t, v = grid(EDGES, EDGES[1:7], [0.0, 0.5, 1.0])
    gpu = glsl.evaluate("lib/surface.glsl", "surface_alpha(a, t, v)", {"a": a, "t": t, "v": v})[:, 0]
    assert_close_fp32(gpu, surface.surface_alpha(a, t, v), what="surface_alpha")
    x, c = grid(EDGES, EDGES)
    gpu = glsl.evaluate("lib/surface.glsl", "alpha_kept(x, c) ? 1.0 : 0.0", {"x": x, "c": c})[:, 0]
    assert np.array_equal(gpu == 1.0, surface.alpha_kept(x, c))
    assert surface.alpha_kept(0.5, 0.5) and not surface.alpha_kept(0.4999, 0.5)  # the cutoff itself is kept
