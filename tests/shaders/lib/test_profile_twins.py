"""GLSL profile library (skinlab/shaders/lib/profiles_*.glsl) vs its NumPy twins, hard cases included."""

import itertools

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics import burley, dipole, fresnel, gaussians, pbd
from skinlab.scene.optics import single_scattering as ss
from skinlab.scene.optics.constants import MIN_MFP_MM

F32 = np.float32


def f32(a):
    return np.asarray(a, F32).astype(np.float64)


# radii (mm): 0, tiny, ordinary, huge (underflow), absurd (beyond PROFILE_MAX_OPTICAL_R)
RADII = [0.0, 1e-9, 1e-6, 1e-3, 0.01, 0.1, 0.5, 1.0, 3.0, 10.0, 100.0, 1e4, 1e8, 1e30]
ALPHAS = [0.0, 1e-3, 0.1, 0.5, 0.9, 0.99, 0.9999, 1.0]
MFPS = [0.0, 1e-9, 1e-6, 1e-4, 0.01, 1.0, 100.0, 1e4]
ETAS = [0.3, 0.5, 1.0, 1.3, 1.5, 2.5, 5.0]

# (include, GLSL expression, NumPy reference f(r, a, l, eta) -> (N, 3))
MODELS = {
    "dipole": (
        "lib/profiles_dipole.glsl",
        "dipole_profile(r, a, l, eta)",
        lambda r, a, l, e: dipole.dipole_profile(r, a, l, e),
    ),
    "single": (
        "lib/profiles_single.glsl",
        "single_scatter_profile(r, a, l, eta, 0.0)",
        lambda r, a, l, e: ss.single_scatter_profile(r, a, l, e, 0.0),
    ),
    "pbd": ("lib/profiles_pbd.glsl", "pbd_profile(r, a, l, eta)", lambda r, a, l, e: pbd.pbd_profile(r, a, l, e)),
    "burley": (
        "lib/profiles_burley.glsl",
        "burley_profile(r, a, l, BURLEY_SEARCHLIGHT)",
        lambda r, a, l, e: burley.burley_profile(r, a, l, "searchlight"),
    ),
    "burley-diffuse": (
        "lib/profiles_burley.glsl",
        "burley_profile(r, a, l, BURLEY_DIFFUSE)",
        lambda r, a, l, e: burley.burley_profile(r, a, l, "diffuse"),
    ),
    "burley-dmfp": (
        "lib/profiles_burley.glsl",
        "burley_profile(r, a, l, BURLEY_DMFP)",
        lambda r, a, l, e: burley.burley_profile(r, a, l, "dmfp"),
    ),
    "blender-burley": (
        "lib/profiles_burley.glsl",
        "blender_burley_profile(r, a, l)",
        lambda r, a, l, e: burley.blender_burley_profile(r, a, l),
    ),
    "deon-skin": (
        "lib/profiles_gaussians.glsl",
        "deon_skin_profile(r, a)",
        lambda r, a, l, e: gaussians.deon_skin_profile(r, a),
    ),
}


def numpy_rows(fn, r, a, l, eta):
    """Reference per sample (each row its own parameters)."""
    out = np.empty((len(r), 3))
    params = np.concatenate([a, l, eta[:, None]], axis=1)
    uniq, inv = np.unique(params, axis=0, return_inverse=True)
    for k, p in enumerate(uniq):
        m = inv.ravel() == k
        out[m] = fn(r[m], p[0:3], p[3:6], float(p[6]))
    return out


def run_model(glsl, name, r, a, l, eta):
    inc, expr, fn = MODELS[name]
    gpu = glsl.evaluate(inc, expr, {"r": r, "a": a, "l": l, "eta": eta}, out_components=3)
    ref = numpy_rows(fn, r, a, l, eta)
    return gpu, ref


def hard_grid(radii, alphas, mfps, etas):
    rows = np.array(list(itertools.product(radii, range(len(alphas)), range(len(mfps)), etas)))
    r = f32(rows[:, 0])
    ai, li = rows[:, 1].astype(int), rows[:, 2].astype(int)
    alphas, mfps = np.array(alphas), np.array(mfps)
    # channels get different parameters (rolled) so the vec3 code paths are exercised
    a = f32(np.stack([alphas[ai], alphas[(ai + 3) % len(alphas)], alphas[(ai + 5) % len(alphas)]], 1))
    l = f32(np.stack([mfps[li], mfps[(li + 2) % len(mfps)], mfps[(li + 5) % len(mfps)]], 1))
    return r, a, l, f32(rows[:, 3])


@pytest.mark.parametrize("name", list(MODELS))
def test_profile_twin_hard_cases(glsl, name):
    radii = RADII if name not in ("pbd", "single") else RADII[::2] + [RADII[-1]]
    etas = ETAS if name not in ("pbd", "single") else [0.5, 1.0, 1.3, 2.5, 5.0]
    r, a, l, eta = hard_grid(radii, ALPHAS, MFPS, etas)
    gpu, ref = run_model(glsl, name, r, a, l, eta)
    assert_close_fp32(gpu, ref, what=name)
    assert (ref >= 0).all() and (gpu >= 0).all()
    # no scattering: mfp below MIN_MFP_MM gives exactly 0 on both sides
    if name != "deon-skin":
        none = l < MIN_MFP_MM
        assert (gpu[none] == 0).all() and (ref[none] == 0).all()
    # huge radii: exactly 0 beyond PROFILE_MAX_OPTICAL_R mean free paths; with absorption the
    # exponential underflows to 0 in fp32 (and is negligible in float64) long before that
    if name != "deon-skin":
        x = r[:, None] / np.maximum(l, 1e-30)
        far = x >= 2e6
        assert (gpu[far] == 0).all() and (ref[far] == 0).all()
        absorbing = (x >= 1e4) & (a <= 0.99) & (l >= MIN_MFP_MM)
        assert absorbing.any() and (gpu[absorbing] == 0).all() and (ref[absorbing] < 1e-30).all()
    else:
        assert (gpu[r >= 1e4] == 0).all()


def test_totals_and_fresnel_twins(glsl):
    a = f32(np.stack([np.linspace(0, 1, 101)] * 3, 1))
    eta = f32(np.repeat([0.3, 0.8, 1.0, 1.3, 1.5, 2.0, 2.5, 4.0], 101 // 8 + 1)[:101])
    gpu = glsl.evaluate("lib/profiles_dipole.glsl", "dipole_total(a, eta)", {"a": a, "eta": eta}, 3)
    assert_close_fp32(gpu, np.stack([dipole.dipole_total(a[i], eta[i]) for i in range(len(a))]), what="dipole_total")
    gpu = glsl.evaluate(
        "lib/profiles_common.glsl", "vec3(fdr(eta), fresnel_moment1(eta), fresnel_moment2(eta))", {"eta": eta}, 3
    )
    ref = np.stack([fresnel.fdr(eta), fresnel.fresnel_moment1(eta), fresnel.fresnel_moment2(eta)], 1)
    assert_close_fp32(gpu, ref, what="fresnel fits")
    c, e = (x.ravel() for x in np.meshgrid(f32(np.linspace(-1, 1, 81)), f32([0.5, 1.0, 1.33, 1.5, 2.4]), indexing="ij"))
    gpu = glsl.evaluate(
        "lib/profiles_common.glsl", "vec2(fresnel_dielectric(c, e), hg_phase(c, e - 1.2))", {"c": c, "e": e}, 2
    )
    assert_close_fp32(gpu[:, 0], fresnel.fresnel_dielectric(c, e), what="fresnel_dielectric")
    assert_close_fp32(gpu[:, 1], fresnel.hg_phase(c, e - 1.2), what="hg_phase")


def test_expm1_log1p_are_well_conditioned(glsl):
    x = f32(np.concatenate([-np.geomspace(1e-8, 0.9, 200), np.geomspace(1e-8, 10, 200), [0.0, 0.05, -0.05]]))
    gpu = glsl.evaluate("lib/profiles_common.glsl", "vec2(em1(x), l1p(x))", {"x": x}, 2)
    assert_close_fp32(gpu[:, 0], np.expm1(x), rtol=1e-5, atol=0, what="em1")
    assert_close_fp32(gpu[:, 1], np.log1p(x), rtol=1e-5, atol=0, what="l1p")


def test_single_scatter_brdf_twin(glsl):
    th = np.radians([0, 20, 45, 70, 89, 90, 120])
    ph = np.radians([0, 90, 180])
    dirs = np.array([[np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)] for t in th for p in ph])
    dirs[np.abs(dirs) < 1e-12] = 0
    i, j, k = (x.ravel() for x in np.meshgrid(range(len(dirs)), range(len(dirs)), range(4), indexing="ij"))
    wi, wo = f32(dirs[i]), f32(dirs[j])
    g = f32(np.array([0.0, 0.8, -0.5, 0.3])[k])
    eta = f32(np.array([1.3, 1.0, 1.5, 2.0])[k])
    n = np.tile([0.0, 0.0, 1.0], (len(wi), 1))
    alpha = np.tile(f32([0.2, 0.7, 1.0]), (len(wi), 1))
    gpu = glsl.evaluate(
        "lib/profiles_single.glsl",
        "single_scatter_brdf(n, wi, wo, a, eta, g)",
        {"n": n, "wi": wi, "wo": wo, "a": alpha, "eta": eta, "g": g},
        3,
    )
    ref = ss.single_scatter_brdf(n, wi, wo, alpha[0], eta, g)
    assert_close_fp32(gpu, ref, what="single_scatter_brdf")
    assert (ref >= 0).all()
    below = (wi[:, 2] <= 0) | (wo[:, 2] <= 0)
    assert (gpu[below] == 0).all()


def test_burley_samplers_twin(glsl):
    xi = f32(np.concatenate([np.linspace(0, 0.999, 400), [0.9, 0.9999, 0.99999]]))
    d = f32(np.geomspace(1e-3, 10, len(xi)))
    gpu = glsl.evaluate(
        "lib/profiles_burley.glsl",
        "vec3(blender_burley_sample(xi, d), burley_sample_golubev(xi, d), burley_cdf(d, d))",
        {"xi": xi, "d": d},
        3,
    )
    ref_n = burley.blender_burley_sample(xi, d)
    ref_g = burley.burley_sample_golubev(xi, d)
    # The samplers invert a CDF whose slope -> 0 at the tail: compare through the CDF (the
    # quantity they are accurate in), which is well conditioned, plus radii where not in the tail.
    cdf = lambda r: burley.burley_cdf(r, d)
    assert np.abs(cdf(gpu[:, 0]) - cdf(ref_n)).max() < 2e-6
    assert np.abs(cdf(gpu[:, 1]) - cdf(ref_g)).max() < 2e-6
    body = xi < 0.99
    assert_close_fp32(gpu[body, 1], ref_g[body], rtol=2e-4, what="golubev")
    assert_close_fp32(gpu[:, 2], burley.burley_cdf(d, d), what="burley_cdf")


def test_gaussian_sum_twin_with_a_fit(glsl):
    fit = gaussians.fit_gaussians(
        lambda r: burley.burley_profile(r, [0.8, 0.5, 0.2], [1.0, 0.5, 0.25]), 5, optimise="geometric"
    )
    v, w = f32(fit.variances_mm2), f32(fit.weights)
    prelude = (
        "const float V[GAUSS_MAX] = float[GAUSS_MAX]("
        + ", ".join(f"{float(x)!r}" for x in list(v) + [0.0] * 3)
        + ");\n"
        "const vec3 W[GAUSS_MAX] = vec3[GAUSS_MAX]("
        + ", ".join(
            f"vec3({float(a)!r}, {float(b)!r}, {float(c)!r})" for a, b, c in list(map(tuple, w)) + [(0.0, 0.0, 0.0)] * 3
        )
        + ");"
    )
    r = f32(np.concatenate([[0.0], np.geomspace(1e-4, 1e3, 300)]))
    gpu = glsl.evaluate("lib/profiles_gaussians.glsl", "gaussian_sum(r, V, W, 5)", {"r": r}, 3, prelude=prelude)
    assert_close_fp32(gpu, gaussians.gaussian_sum_profile(r, v, w), what="gaussian_sum")


finite = dict(allow_nan=False, allow_infinity=False)
params = st.tuples(
    st.one_of(st.floats(0, 1e3, **finite), st.sampled_from([0.0, 1e-30, 1e38])),  # r
    st.tuples(*[st.floats(0, 1, **finite)] * 3),  # alpha
    st.tuples(*[st.one_of(st.floats(0, 1e4, **finite), st.floats(0, 1e-5, **finite))] * 3),  # mfp
    st.floats(0.01, 10, **finite),  # eta
)


@settings(deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rows=st.lists(params, min_size=1, max_size=24))
def test_profiles_property_finite_nonnegative_and_twins(glsl, rows):
    r = f32([x[0] for x in rows])
    a = f32([x[1] for x in rows])
    l = f32([x[2] for x in rows])
    eta = f32([x[3] for x in rows])
    for name in ("dipole", "burley", "blender-burley", "pbd"):
        gpu, ref = run_model(glsl, name, r, a, l, eta)
        assert np.isfinite(ref).all() and (ref >= 0).all(), name
        assert_close_fp32(gpu, ref, what=name)
