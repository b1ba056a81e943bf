import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics import color


@pytest.fixture(scope="module")
def values():
    x = np.concatenate([np.linspace(-0.5, 1.5, 301), np.geomspace(1e-7, 1e3, 200), [0.0031308, 0.04045, 0.0, 1.0]])
    x = x.astype(np.float32).astype(np.float64)
    return np.stack([x, x[::-1], np.roll(x, 7)], axis=1)


def test_srgb_round_trip_and_twins(glsl, values):
    gpu = glsl.evaluate("lib/color.glsl", "srgb_encode(x)", {"x": values}, out_components=3)
    assert_close_fp32(gpu, color.srgb_encode(values), what="srgb_encode")
    gpu = glsl.evaluate("lib/color.glsl", "srgb_decode(x)", {"x": values}, out_components=3)
    assert_close_fp32(gpu, color.srgb_decode(values), what="srgb_decode")
    inside = np.clip(values, 0, 1)
    assert np.allclose(color.srgb_decode(color.srgb_encode(inside)), inside, atol=1e-12)


def test_tonemap_twin_is_monotonic_and_bounded(glsl, values):
    gpu = glsl.evaluate("lib/color.glsl", "tonemap_aces(x)", {"x": values}, out_components=3)
    assert_close_fp32(gpu, color.tonemap_aces(values), what="tonemap_aces")
    x = np.geomspace(1e-6, 1e4, 1000)
    y = color.tonemap_aces(x)
    assert (np.diff(y) >= 0).all() and y.min() >= 0 and y.max() <= 1


def test_tonemap_of_huge_values_is_white_not_nan(glsl):
    """An exposure of 1e30 (or a light that bright): x * x overflowed float32, inf / inf = NaN, black."""
    x = np.array([[7.3, 1e4, 1e5], [1e19, 1e30, 3e38], [1e20, 1e25, 0.5]])
    gpu = glsl.evaluate("lib/color.glsl", "tonemap_aces(x)", {"x": x}, out_components=3)
    assert np.isfinite(gpu).all()
    assert_close_fp32(gpu, color.tonemap_aces(x), what="tonemap_aces (huge)")
    assert (color.tonemap_aces(x)[:, :2] == 1.0).all() and color.tonemap_aces(x)[2, 2] < 1.0
