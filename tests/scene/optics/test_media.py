"""Media: presets, conversions, albedo inversion, validation."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skinlab.scene.optics import media
from skinlab.scene.optics.dipole import dipole_total
from skinlab.scene.optics.media import Medium


def test_all_twelve_presets_load_with_table_values():
    names = media.preset_names()
    assert len(names) == 12 and {"skin1", "skin2", "marble", "spectralon", "ketchup"} <= set(names)
    skin1 = media.preset("skin1")
    assert np.allclose(skin1.sigma_s, [0.74, 0.88, 1.01]) and np.allclose(skin1.sigma_a, [0.032, 0.17, 0.48])
    assert skin1.eta == 1.3 and media.preset("marble").eta == 1.5
    sp = media.preset("spectralon")
    assert np.all(sp.sigma_a == 0) and sp.alpha == (1.0, 1.0, 1.0)
    text = media.PRESET_FILE.read_text()
    assert "Jensen" in text and "SIGGRAPH 2001" in text
    with pytest.raises(ValueError, match="preset"):
        media.preset("jade")


def test_coefficient_round_trip_and_derived_quantities():
    m = Medium.from_coefficients([1.0, 2.0, 0.5], [0.1, 0.0, 0.5], 1.4)
    assert np.allclose(m.sigma_s, [1.0, 2.0, 0.5]) and np.allclose(m.sigma_a, [0.1, 0.0, 0.5])
    assert np.allclose(m.mfp_arr, 1 / np.array([1.1, 2.0, 1.0]))
    assert np.allclose(m.sigma_tr, np.sqrt(3 * np.array([0.1, 0.0, 0.5]) * [1.1, 2.0, 1.0]))
    assert np.allclose(media.radius_to_mfp(m.artist_radius_mm), m.mfp_arr)
    assert np.allclose(m.scaled(10).mfp_arr, 10 * m.mfp_arr)
    # l = 0: infinite coefficients, no NaN
    ss, sa = media.albedo_mfp_to_coefficients([1.0, 0.5, 0.0], [0.0, 0.0, 0.0])
    assert not np.isnan(ss).any() and not np.isnan(sa).any() and sa[0] == 0 and ss[2] == 0


@pytest.mark.parametrize("method", media.ALBEDO_METHODS)
def test_albedo_inversion_round_trip(method):
    A = np.array([0.02, 0.4, 0.85])
    alpha = media.invert_surface_albedo(A, 1.3, method)
    assert ((alpha >= 0) & (alpha <= 1)).all()
    assert np.allclose(media.surface_albedo(alpha, 1.3, method), A, atol=2e-4)
    m = Medium.from_surface_albedo(A, [1.0, 0.5, 0.2], 1.3, method=method)
    assert np.allclose(m.surface_albedo(method), A, atol=2e-4)
    # edge albedos
    e = media.invert_surface_albedo([0.0, 1.0, 1.0], 1.3, method)
    # (the Cycles fit gives alpha(1) = 1 - e^{-6.80023} = 0.9989)
    assert e[0] == pytest.approx(0.0, abs=1e-6) and e[1] == pytest.approx(1.0, abs=2e-3)


def test_dipole_inversion_is_exact_against_closed_form():
    A = np.array([0.1, 0.5, 0.9])
    alpha = media.invert_surface_albedo(A, 1.4, "dipole")
    assert np.allclose(dipole_total(alpha, 1.4), A, atol=1e-12)


def test_artist_radius_convention():
    m = Medium.from_artist_radius([0.8, 0.4, 0.2], [4 * np.pi, 2 * np.pi, np.pi])
    assert np.allclose(m.mfp_arr, [1.0, 0.5, 0.25])


@pytest.mark.parametrize(
    "call,name",
    [
        (lambda: Medium.from_coefficients([-1, 1, 1], [0, 0, 0]), "sigma_s"),
        (lambda: Medium.from_coefficients([1, 1, 1], [0, -0.1, 0]), "sigma_a"),
        (lambda: Medium.from_coefficients([0, 1, 1], [0, 0, 0]), "sigma_s \\+ sigma_a"),
        (lambda: Medium.from_coefficients([1, 1, 1], [0, 0, 0], eta=0.0), "eta"),
        (lambda: Medium.from_coefficients([1, 1, 1], [0, 0, 0], eta=-1.3), "eta"),
        (lambda: Medium.from_surface_albedo([1.2, 0.5, 0.5], 1.0), "albedo"),
        (lambda: Medium.from_surface_albedo([0.5, -0.01, 0.5], 1.0), "albedo"),
        (lambda: Medium.from_surface_albedo(0.5, [1, -1, 1]), "mfp"),
        (lambda: Medium((0.5, 0.5, 1.5), (1, 1, 1)), "alpha"),
        (lambda: Medium.from_artist_radius(0.5, -2.0), "radius"),
        (lambda: Medium.from_coefficients([1, np.nan, 1], [0, 0, 0]), "sigma_s"),
        (lambda: Medium.from_coefficients([1, 1], [0, 0]), "sigma_s"),
        (lambda: media.surface_albedo(0.5, 1.3, method="magic"), "method"),
    ],
)
def test_invalid_parameters_raise_naming_the_parameter(call, name):
    with pytest.raises(ValueError, match=name):
        call()


@settings(deadline=None)
@given(ss=st.tuples(*[st.floats(0, 1e3)] * 3), sa=st.tuples(*[st.floats(0, 1e3)] * 3), eta=st.floats(0.05, 5.0))
def test_conversions_over_domain(ss, sa, eta):
    t_min = min(a + b for a, b in zip(ss, sa))
    if t_min <= 0 or not np.isfinite(1.0 / t_min):  # no medium, or a mean free path beyond float64
        with pytest.raises(ValueError, match="sigma_s \\+ sigma_a"):
            Medium.from_coefficients(ss, sa, eta)
        return
    m = Medium.from_coefficients(ss, sa, eta)
    A = m.surface_albedo("dipole")
    assert np.isfinite(A).all() and ((A >= 0) & (A <= 1)).all()
    back = media.albedo_mfp_to_coefficients(m.alpha, m.mfp_mm)
    assert np.allclose(back[0], ss, rtol=1e-9, atol=1e-12) and np.allclose(back[1], sa, rtol=1e-9, atol=1e-12)


def test_subnormal_extinction_is_a_clear_error_not_an_infinite_mfp():
    # found by hypothesis: sigma_t = 5e-324 made 1/sigma_t = inf
    with pytest.raises(ValueError, match=r"sigma_s \+ sigma_a: .* too small; its mean free path"):
        Medium.from_coefficients((0.0, 0.0, 0.0), (1.0, 1.0, 5e-324), 1.0)
