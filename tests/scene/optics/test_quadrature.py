"""skinlab/scene/optics/quadrature.py: Gauss-Legendre rules by Newton's method on the recurrence."""

import numpy as np
import pytest

from skinlab.scene.optics.quadrature import gauss_legendre


@pytest.mark.parametrize("n", [1, 2, 3, 7, 64, 800])
def test_the_rule_is_leggauss_within_rounding(n):
    x, w = gauss_legendre(n)
    x0, w0 = np.polynomial.legendre.leggauss(n)
    np.testing.assert_allclose(x, x0, rtol=0, atol=4e-16)
    # the end weights are tiny for large n: relative agreement, a little looser where 1 - x^2 rounds
    np.testing.assert_allclose(w, w0, rtol=1e-8 if n > 100 else 1e-11, atol=0)
    assert np.all(np.diff(x) > 0) and np.all((x > -1) & (x < 1)) and np.all(w > 0)
    assert abs(w.sum() - 2.0) < 1e-13


@pytest.mark.parametrize("n", [2, 5, 20])
def test_polynomials_up_to_degree_2n_minus_1_are_exact(n):
    x, w = gauss_legendre(n)
    for k in range(2 * n):
        exact = 0.0 if k % 2 else 2.0 / (k + 1)
        assert abs(np.sum(w * x**k) - exact) < 1e-13


@pytest.mark.parametrize("bad", [0, -3, 2.5, True, "8"])
def test_a_bad_order_is_named(bad):
    with pytest.raises(ValueError, match="gauss_legendre: n must be a positive integer"):
        gauss_legendre(bad)
