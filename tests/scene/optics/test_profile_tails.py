"""Profile tails: the energy beyond a radius, the Gaussian fit's tail rows (fit_gaussians(tail_weight)),
and the kernels' support chosen from the profile's energy (the exact convolution's LUT, the disk's reach)
reaching where a long-mean-free-path profile's line spread has fallen to 1e-3 of its peak."""

import numpy as np
import pytest

from skinlab.scene.optics import gaussians
from skinlab.scene.optics.disk import SAMPLE_ENERGY, disk_kernel
from skinlab.scene.optics.exact_profile import EXACT_ENERGY, exact_profile_lut
from skinlab.scene.optics.media import Medium, preset
from skinlab.scene.optics.profiles import get_profile


def burley(name):
    m, prof = preset(name), get_profile("burley")
    return m, lambda r: np.asarray(prof.evaluate(np.asarray(r, np.float64), m), np.float64)


def energy_beyond(fn, radius):
    """(C,) int_radius^inf R 2 pi r dr by a fine log-spaced quadrature, independent of gaussians'."""
    r = np.geomspace(radius, 1e4, 20001)
    f = fn(r) * 2 * np.pi * r[:, None]
    return np.trapezoid(f, r, axis=0)


def line_spread(fn, x):
    """(len(x), C) the line spread L(x) = int R(sqrt(x^2 + y^2)) dy (the slit scenes' profile)."""
    y = np.concatenate([[0.0], np.geomspace(1e-4, 400.0, 6000)])
    return np.stack([2 * np.trapezoid(fn(np.hypot(xx, y)), y, axis=0) for xx in x])


def testtail_energies_of_one_gaussian_are_its_closed_form():
    v = 4.0  # one unit Gaussian of variance v puts e^{-R^2 / 2v} of its energy beyond R
    fn = lambda r: gaussians.gaussian_sum_profile(r, [v], [[1.0, 0.5, 0.0]])
    radii, beyond = gaussians.tail_energies(fn)
    assert radii.shape == (len(gaussians.TAIL_FRACTIONS),) and beyond.shape == (len(radii), 3)
    assert np.all(np.diff(radii) > 0)
    closed = np.exp(-(radii**2) / (2 * v))
    assert np.allclose(beyond[:, 0], closed, rtol=2e-2, atol=1e-6)
    assert np.allclose(beyond[:, 1], 0.5 * closed, rtol=2e-2, atol=1e-6)
    assert np.all(beyond[:, 2] == 0.0)  # a channel without light has no tail
    # the radii hold the fractions: 1 - fraction is left beyond each (the radius grid steps 1 %)
    assert np.allclose(beyond[:, 0], 1 - np.array(gaussians.TAIL_FRACTIONS), rtol=0.15)
    assert np.all(beyond[:, 0] <= 1 - np.array(gaussians.TAIL_FRACTIONS))


def test_tail_weight_keeps_marble_energy_beyond_the_diffusion_length():
    m, fn = burley("marble")
    plain = gaussians.fit_gaussians(fn, 6)
    tailed = gaussians.fit_gaussians(fn, 6, tail_weight=1.0)
    assert (tailed.weights >= 0).all() and np.isfinite(tailed.rel_error).all()
    radii, _ = gaussians.tail_energies(fn)
    for R in radii[:3]:  # the radii holding 90, 99, 99.9 % of the energy (2.8, 6.0, 9.1 mm)
        truth = energy_beyond(fn, R)
        kept = energy_beyond(tailed.profile, R) / truth
        assert np.all(np.abs(kept - 1) < 0.15), (R, kept)
    # the plain fit to r R(r) lets most of the energy beyond the 99 % radius go: why the rows exist
    lost = energy_beyond(plain.profile, radii[1]) / energy_beyond(fn, radii[1])
    assert np.all(lost < 0.5), lost
    # the price: the shape's error (r R(r), reported alone) grows, but stays bounded
    assert np.all(plain.rel_error < tailed.rel_error) and np.all(tailed.rel_error < 0.2), tailed.rel_error


def test_tail_weight_zero_is_the_plain_fit_and_bad_weights_are_refused():
    _, fn = burley("skin1")
    a = gaussians.fit_gaussians(fn, 4, optimise="geometric")
    b = gaussians.fit_gaussians(fn, 4, optimise="geometric", tail_weight=0.0)
    assert np.array_equal(a.weights, b.weights) and np.array_equal(a.variances_mm2, b.variances_mm2)
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="tail_weight"):
            gaussians.fit_gaussians(fn, 4, tail_weight=bad)


def test_tail_weight_with_a_dark_channel():
    fn = lambda r: gaussians.gaussian_sum_profile(r, [1.0, 9.0], [[0.7, 0.0], [0.3, 0.0]])
    fit = gaussians.fit_gaussians(fn, 2, tail_weight=1.0)
    assert np.all(fit.weights[:, 1] == 0.0) and np.isfinite(fit.weights).all()
    assert fit.rel_error[0] < 0.05


@pytest.mark.parametrize("name", ["marble", "skin1"])
def test_exact_support_keeps_the_tail_to_1e3_of_the_peak(name):
    """The exact convolution's support (the radius holding EXACT_ENERGY of every channel's energy)
    reaches where the line spread has fallen below 1e-3 of its peak in every channel: marble's long
    mean free path sets a wide support, not a fixed radius."""
    m, fn = burley(name)
    r_max, R, E = exact_profile_lut("burley", m, n=64)
    held = 1 - energy_beyond(fn, r_max) / energy_beyond(fn, 1e-9)
    assert np.all(held >= EXACT_ENERGY - 2e-4), held
    L = line_spread(fn, np.array([0.0, r_max]))
    assert np.all(L[1] / L[0] <= 1e-3), L[1] / L[0]
    assert np.allclose(E[-1], 1.0, atol=1e-3) and np.all(np.diff(E, axis=0) >= -1e-12)
    # the disk's reach is chosen the same way, at its own fraction
    k = disk_kernel("burley", m, 16)
    held_disk = 1 - energy_beyond(fn, k.reach_mm) / energy_beyond(fn, 1e-9)
    assert np.all(held_disk >= SAMPLE_ENERGY - 2e-3), held_disk


def test_exact_support_follows_the_medium_scale():
    """Support from energy scales with the medium: marble with every mean free path doubled gets a
    support twice as wide (a fixed radius would not); an albedo near 0 a narrow one."""
    m, _ = burley("marble")
    r1 = exact_profile_lut("burley", m, n=16)[0]
    wide = Medium(m.alpha, tuple(2 * x for x in m.mfp_mm), m.eta)
    assert exact_profile_lut("burley", wide, n=16)[0] == pytest.approx(2 * r1, rel=0.02)
    dark = Medium((0.05, 0.05, 0.05), m.mfp_mm, m.eta)
    assert exact_profile_lut("burley", dark, n=16)[0] < r1
