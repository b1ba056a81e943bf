"""NumPy profile models: closed forms, normalisation, sampling, limits, scale invariance, fitter, registry."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.polynomial import chebyshev as C
from scipy.integrate import quad
from scipy.stats import kstest

from skinlab.scene.optics import burley, constants, dipole, fresnel, gaussians, pbd, profiles
from skinlab.scene.optics import single_scattering as ss
from skinlab.scene.optics.media import Medium, preset


def plane_integral(fn, upper=np.inf, points=None):
    f = lambda r: fn(np.array([r]))[0, 0] * 2 * np.pi * r
    if points is not None and np.isfinite(upper):
        return quad(f, 0, upper, limit=400, points=points)[0]
    return quad(f, 0, upper, limit=400)[0]


@pytest.mark.parametrize("alpha", [0.0, 0.2, 0.8, 0.99, 1.0])
@pytest.mark.parametrize("eta", [1.0, 1.3, 1.5])
def test_dipole_integral_matches_closed_form(alpha, eta):
    got = plane_integral(lambda r: dipole.dipole_profile(r, alpha, 0.7, eta))
    assert got == pytest.approx(float(dipole.dipole_total(alpha, eta)), rel=1e-6, abs=1e-12)


def test_dipole_fdr_matches_fresnel_integral():
    # F_dr fit vs the exact hemispherical average of the internal Fresnel reflectance
    mu = np.linspace(0, 1, 200001)
    for eta in (1.2, 1.3, 1.4, 1.5):
        exact = 2 * np.trapezoid(fresnel.fresnel_dielectric(-mu, eta) * mu, mu)
        assert float(fresnel.fdr(eta)) == pytest.approx(exact, abs=5e-3)


def test_fresnel_moment_chebyshev_matches_pbrt_polynomials():
    for lo, hi, c1, c2 in (
        (constants.DIFFUSION_ETA_MIN, 1.0, constants.FM1_CHEB_LT1, constants.FM2_CHEB_LT1),
        (1.0, constants.DIFFUSION_ETA_MAX, constants.FM1_CHEB_GE1, constants.FM2_CHEB_GE1),
    ):
        e = np.linspace(lo, hi, 2001)[:-1] if hi == 1.0 else np.linspace(lo, hi, 2001)
        t = (2 * e - lo - hi) / (hi - lo)
        assert np.abs(C.chebval(t, c1) - fresnel.fresnel_moment1(e)).max() < 1e-10
        assert np.abs(C.chebval(t, c2) - fresnel.fresnel_moment2(e)).max() < 1e-10


def test_single_scattering_matches_analytic_eta1():
    # normal incidence, isotropic, eta = 1: R1 = (alpha/2)(1 - ln 2)
    got = plane_integral(lambda r: ss.single_scatter_profile(r, 0.9, 1.0, 1.0))
    assert got == pytest.approx(0.45 * (1 - np.log(2)), rel=2e-3)


def test_single_scatter_brdf_reciprocal_and_bounded():
    rng = np.random.default_rng(0)
    v = rng.normal(size=(500, 2, 3))
    v[..., 2] = np.abs(v[..., 2])
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    n = np.array([0, 0, 1.0])
    f1 = ss.single_scatter_brdf(n, v[:, 0], v[:, 1], [0.5, 0.8, 1.0], 1.3, 0.3)
    f2 = ss.single_scatter_brdf(n, v[:, 1], v[:, 0], [0.5, 0.8, 1.0], 1.3, 0.3)
    assert np.allclose(f1, f2) and np.isfinite(f1).all() and (f1 >= 0).all()


@pytest.mark.parametrize("A", [0.05, 0.5, 0.9, 1.0])
@pytest.mark.parametrize("variant", burley.SCALING_VARIANTS)
def test_burley_integrates_to_albedo(A, variant):
    l = 0.8
    d = l / float(burley.burley_s(A, variant))
    got = plane_integral(lambda r: burley.burley_profile(r, A, l, variant), 200 * d, points=[1e-3 * d, d])
    # the r < 1e-3 d clamp removes ~2.5e-4 A (constants.BURLEY_R0_EPS)
    assert got == pytest.approx(A, rel=5e-4)


def test_blender_burley_truncated_normalised_and_conventions():
    A, R = 0.6, 2.0
    d = float(burley.blender_d(A, R))
    assert d == pytest.approx(R / (4 * np.pi) / (1.9 - A + 3.5 * (A - 0.8) ** 2))
    got = plane_integral(lambda r: burley.blender_burley_profile(r, A, R), 16 * d, points=[1e-3 * d, d])
    assert got == pytest.approx(A, rel=5e-4)
    assert burley.blender_burley_profile([16 * d * 1.0001, 1e9], A, R).max() == 0
    assert constants.BURLEY_TRUNCATE_CDF == pytest.approx(0.9963790093708328, abs=1e-15)
    r = np.linspace(0, 16 * d, 100001)
    assert np.trapezoid(burley.blender_burley_pdf(r, d), r) == pytest.approx(1.0, rel=1e-6)


def test_burley_sampling_matches_cdf():
    rng = np.random.default_rng(1)
    xi = rng.random(20000)
    d = 0.37
    rg = burley.burley_sample_golubev(xi, d)
    assert kstest(rg, lambda r: burley.burley_cdf(r, d)).pvalue > 1e-3
    # exact inverse: CDF(sample(xi)) = xi
    assert np.abs(burley.burley_cdf(rg, d) - xi).max() < 1e-12
    rn = burley.blender_burley_sample(xi, d)
    assert rn.max() <= 16 * d + 1e-9
    assert kstest(rn, lambda r: burley.blender_burley_cdf(r, d)).pvalue > 1e-3
    # Newton stops at |f| < 1e-6 in CDF units
    assert np.abs(burley.blender_burley_cdf(rn, d) - xi).max() < 2e-6
    rg2 = burley.blender_burley_sample(xi, d, method="golubev")
    assert np.abs(burley.blender_burley_cdf(rg2, d) - xi).max() < 1e-9
    with pytest.raises(ValueError, match="method"):
        burley.blender_burley_sample(xi, d, method="bisection")
    with pytest.raises(ValueError, match="variant"):
        burley.burley_s(0.5, "oblique")


def test_skin_table_and_gaussian_normalisation():
    assert np.allclose(gaussians.SKIN6_W.sum(0), 1.0, atol=1e-12)
    got = plane_integral(lambda r: gaussians.deon_skin_profile(r))
    assert got == pytest.approx(1.0, rel=1e-6)
    # chained blurs: G(v1) * G(v2) = G(v1 + v2) (2-D convolution at the origin)
    x = np.linspace(-6, 6, 601)
    X, Y = np.meshgrid(x, x)
    g1, g2 = gaussians.gaussian(0.3, np.hypot(X, Y)), gaussians.gaussian(0.5, np.hypot(X, Y))
    h = x[1] - x[0]
    assert np.sum(g1 * g2) * h * h == pytest.approx(float(gaussians.gaussian(0.8, 0.0)), rel=1e-6)


def test_fit_recovers_skin_profile_with_fixed_variances():
    fit = gaussians.fit_gaussians(gaussians.deon_skin_profile, 6, variances=gaussians.SKIN6_V)
    assert fit.weights.shape == (6, 3) and fit.variances_mm2.shape == (6,) and fit.rel_error.shape == (3,)
    assert np.allclose(fit.weights, gaussians.SKIN6_W, atol=2e-3)
    assert (fit.rel_error < 1e-3).all()


def test_fit_shared_variances_to_pbd_profile():
    m = preset("skin1")
    fn = lambda r: pbd.pbd_profile(r, m.alpha_arr, m.mfp_arr, m.eta)
    fit = gaussians.fit_gaussians(fn, 6)
    assert (fit.weights >= 0).all() and np.all(np.diff(fit.variances_mm2) > 0)
    assert (fit.rel_error < 0.05).all(), fit.rel_error
    fewer = gaussians.fit_gaussians(fn, 3, optimise="geometric")
    assert (fewer.rel_error >= fit.rel_error - 1e-9).all()
    with pytest.raises(ValueError, match="K"):
        gaussians.fit_gaussians(fn, 0)


@pytest.mark.parametrize(
    "name", ["dipole", "dipole+ss", "burley", "blender-burley", "pbd", "gaussians", "deon-skin", "none"]
)
def test_registry_models(name):
    m = preset("skin2")
    r = np.concatenate([[0.0], np.geomspace(1e-4, 1e3, 200), [1e30]])
    R = profiles.evaluate_profile(name, r, m)
    assert R.shape == (len(r), 3) and np.isfinite(R).all() and (R >= 0).all()
    T = profiles.total_reflectance(name, m)
    assert T.shape == (3,) and ((T >= 0) & (T <= 1.1)).all()
    if name not in ("none", "deon-skin"):
        # R(r) integrates to the reported total (log grid; the r < 1e-4 disc is negligible)
        x = np.geomspace(1e-5, 2e3, 4000)
        integ = np.trapezoid(profiles.evaluate_profile(name, x, m) * 2 * np.pi * x[:, None] ** 2, np.log(x), axis=0)
        assert integ == pytest.approx(T, rel=0.01)


def test_registry_errors():
    with pytest.raises(ValueError, match="model"):
        profiles.get_profile("diffusion")
    with pytest.raises(ValueError, match="r"):
        profiles.evaluate_profile("dipole", [-1.0], preset("apple"))


def test_no_scattering_limits_and_extremes():
    # mean free path (or Blender radius) -> 0: no scattering, zeros, no NaN
    m = Medium((0.5, 0.9, 1.0), (0.0, 1e-12, 1e-30), 1.3)
    for name in profiles.profile_names():
        R = profiles.evaluate_profile(name, [0.0, 1e-9, 1.0], m)
        assert np.isfinite(R).all() and np.all(R == 0), name
    assert (burley.blender_burley_profile([0.0, 1e-9], [0.5] * 3, [0.0, 1e-20, 1e-9]) == 0).all()
    # albedo 0: nothing comes back; albedo 1 / sigma_a = 0 (spectralon): finite and positive
    z = Medium((0.0,) * 3, (1.0,) * 3, 1.3)
    for name in ("dipole", "pbd", "burley"):
        assert np.all(profiles.evaluate_profile(name, [0.0, 0.5], z) == 0)
    s = preset("spectralon")
    assert s.alpha == (1.0, 1.0, 1.0)
    for name in ("dipole", "pbd", "burley", "blender-burley"):
        R = profiles.evaluate_profile(name, [0.0, 0.1, 1e3], s)
        assert np.isfinite(R).all() and (R[:2] > 0).all()
    assert np.allclose(profiles.total_reflectance("dipole", s), 1.0)


@settings(deadline=None)
@given(k=st.floats(1e-2, 1e4), a=st.floats(0, 1), l=st.floats(0.01, 10), eta=st.floats(0.2, 4.0), x=st.floats(0, 50))
def test_scale_invariance_and_domain(k, a, l, eta, x):
    """R(k r; k l) = R(r; l) / k^2 for every model (very small and very large scene scales)."""
    r = x * l
    for fn in (
        lambda r, l: dipole.dipole_profile(r, a, l, eta),
        lambda r, l: pbd.pbd_profile(r, a, l, eta),
        lambda r, l: burley.burley_profile(r, a, l),
        lambda r, l: burley.blender_burley_profile(r, a, l),
    ):
        base = fn(r, l)
        scaled = fn(k * r, k * l)
        assert np.isfinite(base).all() and (base >= 0).all()
        assert scaled * k * k == pytest.approx(base, rel=1e-9, abs=1e-300)


def test_radial_integral_in_chunks_is_the_same_sum():
    """pbd_total evaluates its log grid a chunk of radii at a time (memory, not maths): the sum is
    the one a single evaluation of the whole grid gives, and a chunk that does not divide the grid
    loses no radius."""
    alpha = np.array([0.0, 0.3, 0.9, 0.999, 1.0])

    def fn(x):
        return pbd.pbd_profile(x, alpha, 1.0, 1.4)

    whole = pbd.radial_integral(fn, n=600, chunk=600)
    np.testing.assert_allclose(pbd.radial_integral(fn, n=600), whole, rtol=1e-12, atol=0)
    np.testing.assert_allclose(pbd.radial_integral(fn, n=600, chunk=7), whole, rtol=1e-12, atol=0)
    assert np.all(np.isfinite(whole)) and whole[0] == 0.0 and np.all(np.diff(whole) > 0)
    # pbd_total's coarser grid (the albedo table's cost) stays within 1e-6 of the 600-radius sum
    np.testing.assert_allclose(pbd.pbd_total(alpha, 1.4), whole, rtol=0, atol=1e-6)
    assert pbd.PBD_TOTAL_RADII < 600
