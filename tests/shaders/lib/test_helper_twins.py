"""Direct GLSL-vs-NumPy comparisons of the library's helper functions (the top-level models that
use them are compared in test_brdf_twins.py / test_profile_twins.py; these pin each helper down on
its own, hard cases included). cheb/fm_cheb_t are the Chebyshev evaluation inside
fresnel_moment1/2 and are covered by those functions' comparison."""

import itertools

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics import brdf, burley, dipole, fresnel, pbd
from skinlab.scene.optics import single_scattering as ss
from skinlab.scene.optics._profile_util import optical


def f32(a):
    return np.asarray(a, np.float32).astype(np.float64)


def grid(*axes):
    m = np.array(list(itertools.product(*axes)), dtype=np.float64)
    return [f32(m[:, i]) for i in range(m.shape[1])]


COS = [-1.0, -0.2, 0.0, 1e-6, 1e-4, 0.01, 0.3, 0.7071, 0.99, 0.9999, 1.0]


def test_brdf_helpers(glsl):
    x = f32(np.concatenate([np.linspace(-1, 2, 61), [0.0, 1.0, 1e-8]]))
    gpu = glsl.evaluate("lib/brdf.glsl", "pow5(x)", {"x": x})[:, 0]
    assert_close_fp32(gpu, brdf.pow5(x), what="pow5")

    rng = np.random.default_rng(3)
    base = f32(rng.uniform(0, 1, (200, 3)))
    m = f32(rng.choice([0.0, 0.3, 1.0], 200))
    s = f32(rng.choice([0.0, 0.5, 1.0], 200))
    gpu = glsl.evaluate("lib/brdf.glsl", "principled_f0(base, m, s)", {"base": base, "m": m, "s": s}, 3)
    assert_close_fp32(gpu, brdf.principled_f0(base, m, s), what="principled_f0")

    nl, nv, nh, r = grid(COS, COS[::2], [0.0, 0.5, 0.99, 0.9999, 1.0], [0.0, 0.05, 0.5, 1.0])
    voh = f32(np.roll(nh, 3))
    f0 = f32(np.tile([0.04, 0.5, 1.0], (len(nl), 1)))
    gpu = glsl.evaluate(
        "lib/brdf.glsl",
        "specular_ggx(NoL, NoV, NoH, VoH, ggx_alpha(r), f0)",
        {"NoL": nl, "NoV": nv, "NoH": nh, "VoH": voh, "r": r, "f0": f0},
        3,
    )
    ref = brdf.specular_ggx(nl, nv, nh, voh, brdf.ggx_alpha(r), f0)
    assert_close_fp32(gpu, ref, what="specular_ggx")
    assert (ref[nl <= 0] == 0).all() and np.isfinite(ref).all()  # back-facing light, grazing view


def test_fresnel_and_refraction_helpers(glsl):
    eta = f32([0.1, 0.3, 0.5, 0.99, 1.0, 1.01, 1.3, 2.5, 5.0, 100.0])
    gpu = glsl.evaluate("lib/profiles_common.glsl", "clamp_eta(eta)", {"eta": eta})[:, 0]
    assert_close_fp32(gpu, fresnel.clamp_eta(eta), what="clamp_eta")
    gpu = glsl.evaluate("lib/profiles_dipole.glsl", "dipole_a(eta)", {"eta": eta})[:, 0]
    assert_close_fp32(gpu, dipole.dipole_a(eta), what="dipole_a")

    ci, e = grid([0.0, 1e-6, 0.1, 0.5, 0.9, 1.0], [0.5, 1.0, 1.3, 2.5])
    gpu = glsl.evaluate("lib/profiles_single.glsl", "refract_cos(ci, e)", {"ci": ci, "e": e})[:, 0]
    assert_close_fp32(gpu, ss.refract_cos(ci, e), what="refract_cos")
    assert ss.refract_cos(1e-6, 1.0) == pytest.approx(1e-6, rel=1e-12)  # eta = 1: straight through
    ct = f32(ss.refract_cos(ci, e))
    # grazing incidence (cos_i = 0) included; total internal reflection appears as cos_t = 0
    gpu = glsl.evaluate(
        "lib/profiles_common.glsl", "fresnel_from_cosines(ci, ct, 1.0, e)", {"ci": ci, "ct": ct, "e": e}
    )[:, 0]
    ref = fresnel.fresnel_from_cosines(ci, ct, 1.0, e)
    assert_close_fp32(gpu, ref, what="fresnel_from_cosines")
    assert ((ref >= 0) & (ref <= 1)).all()


def test_dipole_and_depth_helpers(glsl):
    a = f32(np.array([[0.0, 1e-4, 0.5], [0.9, 0.9999, 1.0]]).repeat(3, 0))
    gpu = glsl.evaluate("lib/profiles_dipole.glsl", "sigma_tr_optical(a)", {"a": a}, 3)
    assert_close_fp32(gpu, dipole.sigma_tr_optical(a), what="sigma_tr_optical")

    z, d, s = grid([1.0, 2.3], [1.0, 1.5, 10.0, 1e3, 1e6, 1e30], [0.0, 1e-3, 0.5, 1.7])
    d3, s3 = np.stack([d] * 3, 1), np.stack([s] * 3, 1)
    gpu = glsl.evaluate("lib/profiles_dipole.glsl", "dipole_pole(z, d, s)", {"z": z, "d": d3, "s": s3}, 3)
    assert_close_fp32(gpu, dipole.dipole_pole(z[:, None], d3, s3), what="dipole_pole")

    i = np.arange(len(ss.depth_samples()), dtype=np.float64)
    gpu = glsl.evaluate("lib/profiles_common.glsl", "depth_sample(int(i))", {"i": i})[:, 0]
    assert_close_fp32(gpu, ss.depth_samples(), what="depth_sample")


def test_optical_radius_including_zero_and_absurd_mfp(glsl):
    r, l = grid([0.0, 1e-9, 0.5, 10.0, 1e8, 1e30], [0.0, 1e-9, 1e-4, 1.0, 1e4])
    l3 = np.stack([l, l * 2, l / 2], 1)
    prelude = (
        "vec3 ox(float r, vec3 m) { vec3 v, il; return optical_radius(r, m, v, il); }\n"
        "vec3 ov(float r, vec3 m) { vec3 v, il; optical_radius(r, m, v, il); return v; }\n"
        "vec3 oi(float r, vec3 m) { vec3 v, il; optical_radius(r, m, v, il); return il; }\n"
    )
    x, inv_l2, valid = optical(r[:, None], l3)
    for fn, ref in (("ox", x), ("ov", valid.astype(float)), ("oi", inv_l2)):
        gpu = glsl.evaluate("lib/profiles_common.glsl", f"{fn}(r, l)", {"r": r, "l": l3}, 3, prelude=prelude)
        assert_close_fp32(gpu, ref, what=f"optical_radius ({fn})")


@pytest.mark.parametrize("A, d", [((0.0, 0.5, 1.0), (1.0, 0.1, 3.0)), ((0.8, 0.8, 0.8), (0.0, 1e-9, 1e4))])
def test_burley_helpers(glsl, A, d):
    r = f32([0.0, 1e-9, 1e-4, 0.01, 0.3, 1.0, 5.0, 50.0, 1e6, 1e30])
    gpu = glsl.evaluate(
        "lib/profiles_burley.glsl",
        "burley_profile_d(r, u_A, u_d)",
        {"r": r},
        3,
        uniforms={"u_A": ("vec3", f32(A)), "u_d": ("vec3", f32(d))},
    )
    assert_close_fp32(gpu, burley.burley_profile_d(r, f32(A), f32(d)), what="burley_profile_d")
    xi = f32([0.0, 1e-6, 0.1, 0.5, 0.9, 0.90001, 0.95, 0.999, 0.999999])
    gpu = glsl.evaluate("lib/profiles_burley.glsl", "burley_root_find(xi)", {"xi": xi})[:, 0]
    ref = burley.burley_root_find(xi)
    # Newton stops at |CDF(x) - xi| < 1e-6 on both sides; compare through the CDF, which is what
    # the tolerance controls (x itself is ill-conditioned where the CDF is flat, xi -> 1)
    cdf = lambda x: 1 - 0.25 * np.exp(-x) - 0.75 * np.exp(-x / 3)
    assert np.isfinite(gpu).all() and (gpu >= 0).all()
    assert np.abs(cdf(gpu) - cdf(ref)).max() < 3e-6
    # x itself is pinned down only where the absolute 1e-6 CDF tolerance is small against xi
    pinned = (xi >= 1e-3) & (xi <= 0.95)
    assert_close_fp32(gpu[pinned], ref[pinned], rtol=1e-3, what="burley_root_find")


@pytest.mark.parametrize(
    "alpha, mfp, eta", [((0.0, 0.5, 1.0), (1.0, 0.3, 2.0), 1.3), ((0.99, 0.9, 0.2), (0.0, 1e-9, 1e3), 1.0)]
)
def test_pbd_multiple_scattering_term(glsl, alpha, mfp, eta):
    r = f32([0.0, 1e-6, 0.01, 0.2, 1.0, 4.0, 30.0, 1e5, 1e30])
    gpu = glsl.evaluate(
        "lib/profiles_pbd.glsl",
        "pbd_ms_profile(r, u_a, u_l, u_eta)",
        {"r": r},
        3,
        uniforms={"u_a": ("vec3", f32(alpha)), "u_l": ("vec3", f32(mfp)), "u_eta": ("float", eta)},
    )
    ref = pbd.pbd_ms_profile(r, f32(alpha), f32(mfp), eta)
    assert_close_fp32(gpu, ref, what="pbd_ms_profile")
    assert (ref >= 0).all()
