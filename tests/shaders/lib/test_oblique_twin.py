"""Oblique entry (skinlab/shaders/lib/sss_oblique.glsl vs skinlab/scene/optics/oblique.py): the diffusion of light
arriving at an angle is centred sin(theta_t) z0 along the surface from where it entered (Wang &
Jacques 1995), and the shadow lookup point built from it. Twins within 1e-4, hard cases finite."""

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics.constants import LUMA_B, LUMA_G, LUMA_R
from skinlab.scene.optics.oblique import LUMA, entry_offset, entry_point


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _cases(n=600, seed=5):
    rng = np.random.default_rng(seed)
    ng = _unit(rng.normal(size=(n, 3)))
    l = _unit(rng.normal(size=(n, 3)))
    z0 = rng.uniform(0.0, 3.0, (n, 3))
    eta = rng.uniform(0.7, 1.6, n)
    mpu = np.full(n, 1.0)
    mpu[n // 2 :] = 1000.0  # a scene in metres
    # hard cases: normal incidence, exactly grazing, light from below, no scattering, eta 1 and < 1
    l[:10] = ng[:10]
    l[10:20] = _unit(np.cross(ng[10:20], rng.normal(size=(10, 3))))
    l[20:30] = -ng[20:30]
    z0[30:40] = 0.0
    eta[40:50] = 1.0
    eta[50:60] = 0.5
    return ng, l, z0, eta, mpu


def test_entry_offset_twin(glsl):
    ng, l, z0, eta, mpu = _cases()
    gpu = glsl.evaluate(
        "lib/sss_oblique.glsl",
        "sss_entry_offset(ng, l, z0, eta, mpu)",
        {"ng": ng, "l": l, "z0": z0, "eta": eta, "mpu": mpu},
        out_components=3,
    )
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)  # the inputs the GPU sees
    ref = entry_offset(f32(ng), f32(l), f32(z0), f32(eta), mpu)
    assert np.isfinite(ref).all() and np.abs(ref[:10]).max() < 1e-6 and (ref[30:40] == 0).all()
    # in millimetres: the same absolute accuracy whatever the scene's unit
    assert_close_fp32(gpu * mpu[:, None], ref * mpu[:, None], rtol=1e-4, atol=1e-5, what="sss_entry_offset")


def test_entry_point_twin(glsl):
    ng, l, z0, eta, _ = _cases(seed=6)
    world = np.random.default_rng(7).uniform(-5, 5, ng.shape)
    gpu = glsl.evaluate(
        "lib/sss_oblique.glsl",
        "sss_entry_point(w, ng, l, z0, eta, 1.0)",
        {"w": world, "ng": ng, "l": l, "z0": z0, "eta": eta},
        out_components=3,
    )
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)
    ref = entry_point(f32(world), f32(ng), f32(l), f32(z0), f32(eta), 1.0)
    assert_close_fp32(gpu, ref, rtol=1e-4, atol=2e-5, what="sss_entry_point")


def test_offset_is_wang_and_jacques_shift():
    """sin(theta_t) z0 against the light's travel along the surface, z0 weighted by luminance."""
    ng = np.array([[0.0, 0.0, 1.0]])
    z0 = np.array([1.3, 0.95, 0.67])  # skin1's 1 / mu_t' (mm)
    lum = z0 @ [LUMA_R, LUMA_G, LUMA_B]
    assert np.allclose(LUMA, [0.2126, 0.7152, 0.0722]) and LUMA.sum() == pytest.approx(1.0)
    for deg in (0.0, 30.0, 45.0, 80.0, 90.0):
        t = np.radians(deg)
        l = np.array([[0.0, -np.sin(t), np.cos(t)]])  # light from -y: it travels toward +y
        for eta in (1.0, 1.4):
            off = entry_offset(ng, l, z0, eta, 1.0)[0]
            sin_t = np.sin(t) / eta
            assert off == pytest.approx([0.0, -sin_t * lum, 0.0], abs=1e-12)  # toward the light, in the plane
    # a scene in metres: the same millimetres, in scene units
    l = _unit(np.array([[0.0, -1.0, 1.0]]))
    assert entry_offset(ng, l, z0, 1.0, 1000.0) == pytest.approx(entry_offset(ng, l, z0, 1.0, 1.0) / 1000.0)
    # total internal reflection side (eta < 1): sin(theta_t) is clamped at 1, |offset| <= z0
    grazing = np.array([[0.0, -1.0, 0.0]])
    assert np.linalg.norm(entry_offset(ng, grazing, z0, 0.5, 1.0)) == pytest.approx(lum)
    # the lookup point moves toward the light by the offset's length: for a directional light the
    # point's place across the shadow map is that of the offset alone
    p = entry_point(np.zeros((1, 3)), ng, l, z0, 1.0, 1.0)[0]
    off = entry_offset(ng, l, z0, 1.0, 1.0)[0]
    across = lambda x: x - l[0] * (x @ l[0])
    assert across(p) == pytest.approx(across(off)) and (p - off) @ l[0] == pytest.approx(np.linalg.norm(off))
