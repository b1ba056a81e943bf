"""Monte Carlo reference: exactness against Chandrasekhar, conservation, seeds, error scaling,
and agreement of the analytic profiles with it."""

import numpy as np
import pytest

from skinlab.scene.optics import montecarlo as mc
from skinlab.scene.optics.dipole import dipole_profile, dipole_total
from skinlab.scene.optics.pbd import pbd_profile, pbd_total
from skinlab.scene.optics.single_scattering import single_scatter_profile


def test_matches_chandrasekhar_exact_reflectance_eta1():
    # semi-infinite isotropic medium, no Fresnel: A(mu0) = 1 - H(mu0) sqrt(1 - a)
    for a, mu in ((0.5, 1.0), (0.9, 1.0)):
        r = mc.simulate(a, 1.0, photons=60_000, seed=1, progress=False)
        exact = mc.exact_albedo_isotropic(a, mu)
        assert abs(r.total - exact) < 4 * r.total_se, (a, r.total, exact, r.total_se)
    # diffuse incidence: spherical albedo = 2 int A(mu) mu dmu
    a = 0.8
    x, w = np.polynomial.legendre.leggauss(64)
    m, w = 0.5 * (x + 1), 0.5 * w
    sph = 2 * np.sum(w * m * (1 - mc.chandrasekhar_h(a, m) * np.sqrt(1 - a)))
    r = mc.simulate(a, 1.0, incidence="diffuse", photons=60_000, seed=2, progress=False)
    assert abs(r.total - sph) < 4 * r.total_se


def test_h_function_identity():
    # zeroth moment: int_0^1 H dmu = (2/a)(1 - sqrt(1 - a))
    a = 0.7
    x, w = np.polynomial.legendre.leggauss(64)
    m = 0.5 * (x + 1)
    assert np.sum(0.5 * w * mc.chandrasekhar_h(a, m)) == pytest.approx(2 / a * (1 - np.sqrt(1 - a)), rel=1e-8)


def test_energy_conservation_without_absorption():
    # albedo 1, eta 1: every photon leaves eventually; what has not left by the step cap is
    # reported as `capped`, so total + capped = 1 exactly (all weights are 1), and the capped
    # fraction shrinks like 1/sqrt(cap) (random-walk return time tail).
    r1 = mc.simulate(1.0, 1.0, photons=4000, seed=3, max_steps=100, progress=False)
    r2 = mc.simulate(1.0, 1.0, photons=4000, seed=3, max_steps=3000, progress=False)
    for r in (r1, r2):
        assert r.total + r.capped == pytest.approx(1.0, abs=1e-12)
    assert r1.capped / r2.capped == pytest.approx(np.sqrt(3000 / 100), rel=0.25) and r2.total > 0.96
    # with Fresnel (TIR traps light longer) the same accounting holds
    r3 = mc.simulate(1.0, 1.4, photons=2000, seed=4, max_steps=2000, progress=False)
    assert r3.total + r3.capped == pytest.approx(1.0, abs=1e-12)
    # the binned profile integrates to the total (all exits within the last edge here)
    e = np.concatenate([[0], np.geomspace(1e-3, 1e6, 200)])
    r4 = mc.simulate(0.9, 1.3, photons=5000, seed=5, r_edges=e, progress=False)
    area = np.pi * np.diff(e**2)
    assert np.sum(r4.R * area) == pytest.approx(r4.total, rel=1e-12)


def test_seed_reproducible_and_workers_independent():
    a = mc.simulate(0.95, 1.3, g=0.5, photons=3000, seed=7, progress=False)
    b = mc.simulate(0.95, 1.3, g=0.5, photons=3000, seed=7, progress=False)
    c = mc.simulate(0.95, 1.3, g=0.5, photons=3000, seed=8, progress=False)
    assert a.total == b.total and np.array_equal(a.R, b.R)
    assert a.total != c.total
    big = dict(albedo=0.9, eta=1.3, photons=2 * mc.BATCH + 10, seed=9, progress=False)
    assert mc.simulate(**big).total == mc.simulate(**big, workers=2).total


def test_standard_error_shrinks_like_inverse_sqrt_n():
    small = mc.simulate(0.9, 1.3, photons=4000, seed=10, progress=False)
    large = mc.simulate(0.9, 1.3, photons=64000, seed=11, progress=False)
    assert large.total_se / small.total_se == pytest.approx(0.25, rel=0.15)
    mid = (small.R > 0) & (large.R > 0) & (small.r_mid > 0.1) & (small.r_mid < 3)
    ratio = np.median(large.R_se[mid] / small.R_se[mid])
    assert ratio == pytest.approx(0.25, rel=0.2)
    # and the two runs agree within their errors
    assert abs(large.total - small.total) < 4 * np.hypot(small.total_se, large.total_se)


def test_hg_anisotropy_and_entry_fresnel():
    # forward scattering sends light deeper: lower reflectance than isotropic at equal albedo
    iso = mc.simulate(0.99, 1.0, g=0.0, photons=8000, seed=12, progress=False)
    fwd = mc.simulate(0.99, 1.0, g=0.8, photons=8000, seed=12, progress=False)
    assert fwd.total < iso.total - 5 * np.hypot(iso.total_se, fwd.total_se)
    # entry Fresnel at normal incidence: exactly (1 - F(1)) times the entering-flux result
    a = mc.simulate(0.8, 1.5, photons=4000, seed=13, progress=False)
    b = mc.simulate(0.8, 1.5, photons=4000, seed=13, entry_fresnel=True, progress=False)
    assert b.total == pytest.approx(a.total * (1 - 0.04), rel=1e-12)


@pytest.mark.parametrize(
    "bad,msg",
    [
        (dict(albedo=1.2), "albedo"),
        (dict(albedo=-0.1), "albedo"),
        (dict(eta=0.0), "eta"),
        (dict(g=1.0), "g"),
        (dict(incidence="oblique"), "incidence"),
        (dict(photons=1), "photons"),
    ],
)
def test_invalid_parameters_name_the_parameter(bad, msg):
    args = dict(albedo=0.5, eta=1.3, photons=100, progress=False)
    args.update(bad)
    with pytest.raises(ValueError, match=msg):
        mc.simulate(**args)


def test_models_agree_with_monte_carlo_mid_albedo():
    """alpha' = 0.8, eta = 1.3, normal incidence, per entering photon. Stated tolerances (measured
    model error + 4 standard errors; docs/accuracy.md has the full table):
    total reflectance: PBD and the dipole within 12 % (both measured ~ +8-9 % high here); adding
    Jensen's single-scattering term to the dipole over-counts (+43 %): the dipole's diffusion
    source already holds the first scattering, so that sum is only checked to be too high;
    profile between 0.3 and 3 mfp: PBD within 20 % per bin, area-weighted mean error < 12 %
    (measured: 5-15 %, mean 10 %)."""
    a, eta = 0.8, 1.3
    edges = np.concatenate([[0.0], np.geomspace(0.05, 5.0, 16)])
    r = mc.simulate(a, eta, photons=80_000, seed=14, r_edges=edges, progress=False)
    pbd_t = pbd_total([a], eta)[0]
    assert abs(pbd_t - r.total) < 0.12 * r.total + 4 * r.total_se
    assert abs(dipole_total(a, eta) - r.total) < 0.12 * r.total + 4 * r.total_se
    ss_t = (
        2
        * np.pi
        * np.trapezoid(
            single_scatter_profile(np.linspace(0, 60, 20001), a, 1.0, eta)[:, 0] * np.linspace(0, 60, 20001),
            np.linspace(0, 60, 20001),
        )
    )
    jensen_t = dipole_total(a, eta) + ss_t
    assert jensen_t > r.total + 4 * r.total_se
    # bin averages of the analytic profile (fine quadrature in each annulus)
    sel = (edges[:-1] >= 0.3) & (edges[1:] <= 3.0)
    model = []
    for r0, r1 in zip(edges[:-1][sel], edges[1:][sel]):
        rr = np.linspace(r0, r1, 41)
        f = pbd_profile(rr, a, 1.0, eta)[:, 0] * 2 * np.pi * rr
        model.append(np.trapezoid(f, rr) / (np.pi * (r1**2 - r0**2)))
    model = np.array(model)
    rel = np.abs(model - r.R[sel]) / r.R[sel]
    assert (rel < 0.20 + 4 * r.R_se[sel] / r.R[sel]).all(), rel
    w = r.R[sel] * np.diff(edges**2)[sel]
    assert np.sum(rel * w) / np.sum(w) < 0.12
    # the dipole's shape is poor at this albedo (sigma_tr = 0.77 per mfp: diffusion is a weak
    # approximation); it is only required to be in the right range (docs/accuracy.md has numbers)
    d = dipole_profile(r.r_mid[sel], a, 1.0, eta)[:, 0]
    assert (np.abs(d - r.R[sel]) / r.R[sel] < 1.0).all()
