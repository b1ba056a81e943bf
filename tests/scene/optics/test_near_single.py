"""Single scattering under a near light (skinlab/scene/optics/near_single.py, its GLSL twin
lib/sss_near_single.glsl): the gain on the far-light single-scattering term against an independent
brute-force integral along the view ray (eta 1, where the model is exact), its far-light limit,
hard cases finite, and the twin within fp32."""

import numpy as np
import pytest
from scipy import integrate

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics.constants import NEAR_SINGLE_MAX_GAIN, NEAR_SINGLE_T, NEAR_SINGLE_W
from skinlab.scene.optics.fresnel import hg_phase
from skinlab.scene.optics.near_single import near_single_gain

UP = np.array([0.0, 0.0, 1.0])


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def brute_gain(d, v, sigma_t, g):
    """The near light's single scattering over the far light's, index-matched, the plane z = 0, by
    adaptive quadrature along the view ray: sigma_s p(theta(s)) I / R^2 e^{-sigma_t (s + s_in)}, with
    the path inside found from the straight line to the light (no refraction at eta 1)."""
    dist = np.linalg.norm(d)
    l = d / dist
    mu_i, mu_o = l[2], v[2]
    far = hg_phase(np.dot(-l, v), g) * mu_i / (mu_i + mu_o)  # per unit albedo and irradiance at x_o

    def f(s):
        p = -v * s  # the point on the view ray, s below x_o along it
        r = d - p
        big_r = np.linalg.norm(r)
        # the line from p to the light crosses z = 0 at the fraction depth / (depth + height) of it
        s_in = big_r * (-p[2]) / (-p[2] + d[2])
        return sigma_t * np.exp(-sigma_t * (s + s_in)) * hg_phase(np.dot(-r / big_r, v), g) * (dist / big_r) ** 2

    val, _ = integrate.quad(f, 0.0, np.inf, limit=400, epsabs=1e-12, epsrel=1e-10)
    return val / far


def test_nodes_are_gauss_laguerre():
    t, w = np.polynomial.laguerre.laggauss(len(NEAR_SINGLE_T))
    assert np.allclose(NEAR_SINGLE_T, t, rtol=1e-14) and np.allclose(NEAR_SINGLE_W, w, rtol=1e-13)


@pytest.mark.parametrize("sigma_t", [0.77, 1.05, 1.49])  # about skin1's per mm
def test_point_light_scene_against_brute_force(sigma_t):
    """point-light-skin1: the light 2 mm above the slab, the camera straight down, 0-12 mm from its foot."""
    for r in (0.0, 1.0, 2.5, 5.0, 8.6, 12.0):
        d = np.array([-r, 0.0, 2.0])
        got = near_single_gain(d, UP, UP, [sigma_t] * 3, 1.0, 0.0)[0]
        ref = brute_gain(d, UP, sigma_t, 0.0)
        assert got == pytest.approx([ref] * 3, rel=2e-3), r
    # below the light the deeper points are farther from it (gain < 1); far from its foot they are
    # nearer to it and see it through less tissue than the far light's z / mu_i (gain > 1)
    assert near_single_gain([0.0, 0.0, 2.0], UP, UP, [sigma_t] * 3, 1.0, 0.0)[0, 0] < 0.8
    assert near_single_gain([-8.0, 0.0, 2.0], UP, UP, [sigma_t] * 3, 1.0, 0.0)[0, 0] > 1.05


def test_random_geometry_against_brute_force():
    """Within 1.5 % where the light is at least 0.2 from grazing, the view within 60 degrees of the
    normal and the light at least a mean free path away (the domain docs/ground-truth.md states)."""
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(60):
        l = _unit(rng.normal(size=3))
        l[2] = abs(l[2])
        v = _unit(rng.normal(size=3))
        v[2] = abs(v[2])
        if l[2] < 0.2 or v[2] < 0.5:
            continue
        sigma_t, dist, g = rng.uniform(0.3, 3.0), rng.uniform(1.0, 30.0), rng.choice([0.0, 0.5, 0.9, -0.3])
        dist = max(dist, 1.0 / sigma_t)
        got = near_single_gain(l * dist, UP, v, [sigma_t] * 3, 1.0, g)[0, 0]
        worst = max(worst, abs(got / brute_gain(l * dist, v, sigma_t, g) - 1.0))
    assert worst < 0.015


def test_far_light_gain_is_one():
    rng = np.random.default_rng(4)
    ng = _unit(rng.normal(size=(200, 3)))
    l = _unit(ng + 0.8 * _unit(rng.normal(size=(200, 3))))
    v = _unit(ng + 0.8 * _unit(rng.normal(size=(200, 3))))
    keep = (np.sum(l * ng, -1) > 0.2) & (np.sum(v * ng, -1) > 0.2)
    for eta in (1.0, 1.4):
        got = near_single_gain(l[keep] * 1e5, ng[keep], v[keep], [1.0, 2.0, 3.0], eta, 0.3)
        assert got == pytest.approx(np.ones_like(got), abs=2e-3)


def test_channels_apart_and_scale_free():
    """Each channel its own extinction; only sigma_t x distance matters (mm or metres alike)."""
    d, v = np.array([3.0, 0.0, 2.0]), _unit(np.array([0.2, 0.1, 1.0]))
    got = near_single_gain(d, UP, v, [0.5, 1.0, 2.0], 1.3, 0.2)[0]
    for c, s in enumerate((0.5, 1.0, 2.0)):
        assert got[c] == pytest.approx(near_single_gain(d, UP, v, [s] * 3, 1.3, 0.2)[0, 0])
        assert got[c] == pytest.approx(near_single_gain(d * 10.0, UP, v, [s / 10.0] * 3, 1.3, 0.2)[0, 0])
    assert got[0] < got[1] < got[2] < 1.0  # right below the light: a thinner medium sees it farther off


def test_hard_cases_finite():
    cases = {
        "light at the point": ([0.0, 0.0, 0.0], UP),
        "light grazing": ([1.0, 0.0, 0.0], UP),
        "light below": ([0.0, 0.0, -1.0], UP),
        "view grazing": ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        "view below": ([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
        "light huge": ([0.0, 0.0, 1e30], UP),
        "light tiny": ([1e-30, 0.0, 1e-30], UP),
    }
    for name, (d, v) in cases.items():
        for sigma_t in ([0.0] * 3, [1e-30] * 3, [1.0] * 3, [1e30] * 3):
            for eta, g in ((1.0, 0.0), (0.5, 0.99), (1.4, -0.99)):
                got = near_single_gain(d, UP, v, sigma_t, eta, g)
                assert np.isfinite(got).all() and (got >= 0).all() and (got <= NEAR_SINGLE_MAX_GAIN).all(), name
    assert (near_single_gain([1.0, 0.0, 0.0], UP, UP, [1.0] * 3, 1.0, 0.0) == 1.0).all()  # grazing: the far term
    assert near_single_gain([0.0, 0.0, 1.0], UP, UP, [0.0] * 3, 1.0, 0.0).max() < 1e-2  # no extinction: ~0


def test_glsl_twin(glsl):
    rng = np.random.default_rng(5)
    n = 600
    ng = _unit(rng.normal(size=(n, 3)))
    d = (ng + rng.normal(size=(n, 3))) * 10 ** rng.uniform(-1, 3, (n, 1))
    v = _unit(ng + rng.normal(size=(n, 3)))
    sig = 10 ** rng.uniform(-1, 0.7, (n, 3))
    eta = rng.uniform(1.0, 1.6, n)
    eta[:100] = 1.0
    g = 0.4
    d[:5], sig[5:10], v[10:15] = 0.0, 0.0, np.cross(ng[10:15], rng.normal(size=(5, 3)))  # hard cases
    v = _unit(v)
    gpu = glsl.evaluate(
        "lib/sss_near_single.glsl",
        f"sss_near_single_gain(d, ng, v, sig, eta, {g})",
        {"d": d, "ng": ng, "v": v, "sig": sig, "eta": eta},
        out_components=3,
    )
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)  # the inputs the GPU sees
    ref = near_single_gain(f32(d), f32(ng), f32(v), f32(sig), f32(eta), g)
    assert np.isfinite(gpu).all()
    assert_close_fp32(gpu, ref, rtol=2e-4, atol=2e-5, what="sss_near_single_gain")
