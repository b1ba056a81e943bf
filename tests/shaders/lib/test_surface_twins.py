"""lib/surface.glsl (occlusion strength, opacity, the alpha mask) against its NumPy twin
skinlab/scene/optics/surface.py, hard cases included (strength and alpha at 0 and 1, values out of range)."""

import itertools

import numpy as np
import pytest

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


def test_texture_transform(glsl):
    rng = np.random.default_rng(5)
    uv = f32(np.concatenate([rng.uniform(-1, 2, (60, 2)), [[0, 0], [1, 1], [0, 1], [1, 0]]]))
    cases = [
        ((0, 0), (1, 1), 0.0),
        ((0.25, -0.5), (2, 0.5), 0.3),
        ((0, 1), (0.5, 0.5), np.pi / 2),
        ((1, 0), (-1, 1), -2.0),
    ]
    for off, sc, rot in cases:
        gpu = glsl.evaluate(
            "lib/surface.glsl",
            "texture_transform(uv, u_off, u_sc, u_rot)",
            {"uv": uv},
            2,
            uniforms={"u_off": ("vec2", f32(off)), "u_sc": ("vec2", f32(sc)), "u_rot": ("float", float(rot))},
        )
        assert_close_fp32(gpu, surface.texture_transform(uv, off, sc, rot), what=f"texture_transform {off} {sc} {rot}")
    # identity; the glTF spec's example: offset (0, 1), rotation pi/2, scale 0.5 reads the lower-left
    # quadrant of the image (glTF v down: v in [0.5, 1]; here, v up: [0, 0.5])
    assert surface.texture_transform(uv, (0, 0), (1, 1), 0.0) == pytest.approx(uv)
    q = surface.texture_transform(np.array([[0, 0], [1, 0], [0, 1], [1, 1.0]]), (0, 1), (0.5, 0.5), np.pi / 2)
    assert q[:, 0].min() == pytest.approx(0) and q[:, 0].max() == pytest.approx(0.5)
    assert q[:, 1].min() == pytest.approx(0, abs=1e-12) and q[:, 1].max() == pytest.approx(0.5)


def test_diffuse_transmission_btdf(glsl):
    nol, w = grid([-1.0, -0.5, -1e-6, 0.0, 1e-6, 0.5, 1.0], [0.0, 0.3, 1.0, 1.5])
    colour = np.tile([0.2, 0.6, 1.0], (len(nol), 1))
    gpu = glsl.evaluate(
        "lib/surface.glsl", "diffuse_transmission_btdf(NoL, w, c)", {"NoL": nol, "w": w, "c": f32(colour)}, 3
    )
    want = surface.diffuse_transmission_btdf(nol, w, colour)
    assert_close_fp32(gpu, want, what="diffuse_transmission_btdf")
    assert np.all(want[nol >= 0] == 0) and want[(nol < 0) & (w == 1.0)][0] == pytest.approx(
        np.array([0.2, 0.6, 1.0]) / np.pi
    )
