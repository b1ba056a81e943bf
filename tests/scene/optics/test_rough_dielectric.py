"""The rough dielectric boundary's directional albedos (skinlab/scene/optics/rough_dielectric.py): the smooth
limit, energy bounds, and Mitsuba's own roughdielectric (the truth's boundary) sampled directly."""

from __future__ import annotations

import numpy as np
import pytest

from skinlab.scene.optics.fresnel import fresnel_dielectric
from skinlab.scene.optics.rough_dielectric import SMOOTH_ALPHA, ggx_g1, rough_albedos, rough_diffuse_albedos

MU = np.array([1.0, 0.9, 0.7, 0.5, 0.3, 0.1, 0.01, 0.0])


@pytest.mark.parametrize("eta", [1.3, 1 / 1.3, 1.5])
def test_smooth_limit_is_fresnel(eta):
    r, t = rough_albedos(MU, 0.5 * SMOOTH_ALPHA, eta)
    np.testing.assert_allclose(r, fresnel_dielectric(MU, eta), atol=1e-12)
    np.testing.assert_allclose(r + t, 1.0, atol=1e-12)
    # just rough: close to the smooth boundary wherever the Fresnel term is not at its critical edge
    r2, t2 = rough_albedos(MU[:4], 2 * SMOOTH_ALPHA, eta)
    np.testing.assert_allclose(r2, fresnel_dielectric(MU[:4], eta), atol=0.02)


@pytest.mark.parametrize("alpha", [0.01, 0.2025, 0.5, 1.0])
@pytest.mark.parametrize("eta", [1.3, 1 / 1.3])
def test_albedos_are_finite_bounded_and_lose_light_toward_grazing(alpha, eta):
    r, t = rough_albedos(MU, alpha, eta)
    assert np.all(np.isfinite(r)) and np.all(np.isfinite(t))
    assert np.all(r >= 0) and np.all(t >= 0) and np.all(r + t <= 1 + 1e-9)
    # the single-scattering microfacet model loses what its facets mask: more at grazing incidence
    assert (r + t)[0] >= (r + t)[5] - 1e-9
    rd, td = rough_diffuse_albedos(alpha, eta)
    assert 0 <= rd and 0 <= td and rd + td <= 1 + 1e-9
    assert np.all(ggx_g1(MU, alpha) <= 1.0) and ggx_g1(1.0, alpha) == pytest.approx(1.0)


def test_skin_boundary_inside_reflects_less_than_smooth():
    """At roughness 0.45 (alpha 0.2025) and index 1.3, light inside meeting the boundary diffusely is
    reflected 0.34 (smooth: 0.45) and let out 0.56 (smooth 0.55): a tenth is lost per meeting."""
    rd, td = rough_diffuse_albedos(0.2025, 1 / 1.3)
    rs, ts = rough_diffuse_albedos(0.0, 1 / 1.3)
    assert rs == pytest.approx(0.4466, abs=2e-3) and rs + ts == pytest.approx(1.0)
    assert 0.30 < rd < 0.38 and abs(td - ts) < 0.02


def test_matches_mitsubas_roughdielectric():
    """Mitsuba's roughdielectric (GGX, visible-normal sampling): the mean sample weight is the
    directional albedo; its transmission weight is in radiance (divided by the squared index ratio)."""
    mi = pytest.importorskip("mitsuba")
    mi.set_variant("scalar_rgb")
    alpha, eta, n = 0.2025, 1.3, 3000
    bsdf = mi.load_dict(
        {"type": "roughdielectric", "distribution": "ggx", "alpha": alpha, "int_ior": eta, "ext_ior": 1.0}
    )
    ctx = mi.BSDFContext()
    rng = np.random.default_rng(2)
    for inside in (False, True):
        for mu in (1.0, 0.6, 0.2):
            si = mi.SurfaceInteraction3f()
            si.sh_frame = mi.Frame3f([0.0, 0.0, 1.0])
            si.wi = mi.Vector3f(np.sqrt(1 - mu * mu), 0.0, -mu if inside else mu)
            wr, wt = [], []
            for u in rng.random((n, 3)):
                bs, w = bsdf.sample(ctx, si, float(u[0]), mi.Point2f(float(u[1]), float(u[2])))
                w = float(w[0])
                refl = mi.Frame3f.cos_theta(bs.wo) * mi.Frame3f.cos_theta(si.wi) > 0
                wr.append(w if refl else 0.0)
                wt.append(0.0 if refl else w * (1 / eta**2 if inside else eta**2))
            r, t = rough_albedos(mu, alpha, 1 / eta if inside else eta)
            for got, want in ((np.mean(wr), r), (np.mean(wt), t)):
                se = np.std(wr if want is r else wt) / np.sqrt(n)
                assert abs(got - want) < 4 * se + 3e-3, (inside, mu, got, want, se)


def test_rough_albedos_in_blocks_are_each_cosines_own_numbers():
    """rough_albedos works through long lists of cosines a block at a time (memory, not maths): every
    entry is what the cosine alone gives, shapes kept, an empty list empty."""
    mu = np.linspace(0.0, 1.0, 131)  # two blocks and a part
    r, t = rough_albedos(mu, 0.3, 1.3)
    alone = np.array([rough_albedos(m, 0.3, 1.3) for m in mu[::13]])
    np.testing.assert_array_equal(r[::13], alone[:, 0])
    np.testing.assert_array_equal(t[::13], alone[:, 1])
    r2, t2 = rough_albedos(mu.reshape(1, -1), 0.3, 1.3)
    assert r2.shape == (1, 131) and np.array_equal(r2[0], r) and np.array_equal(t2[0], t)
    empty = rough_albedos(np.zeros(0), 0.3, 1.3)
    assert empty[0].shape == (0,) and empty[1].shape == (0,)
