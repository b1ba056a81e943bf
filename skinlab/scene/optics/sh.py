"""Spherical harmonics to order 2 (9 coefficients): projecting an environment's radiance, its
irradiance on a surface of any normal, and rotating the coefficients. NumPy twin of
skinlab/shaders/lib/environment.glsl ``sh9_basis`` / ``env_sh_irradiance``.

Irradiance from the first nine coefficients of the radiance: E(n) = sum_lm A_l L_lm Y_lm(n) with
A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4, the clamped cosine's own coefficients (Ramamoorthi &
Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps";
docs/references.md#environment-lighting). The basis is the real one with the usual normalisation
(Sloan 2008, "Stupid Spherical Harmonics Tricks", appendix A2), in world axes: index k = l (l + 1) + m.
"""

from __future__ import annotations

import numpy as np

from .constants import PI, SH_A, SH_C0, SH_C1, SH_C2, SH_C3, SH_C4

SH_BAND = (0, 1, 1, 1, 2, 2, 2, 2, 2)  # the band l of each of the 9 coefficients


def sh9_basis(d) -> np.ndarray:
    """(..., 9) real SH basis at unit directions d (..., 3)."""
    d = np.asarray(d, np.float64)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack(
        [
            np.full_like(x, SH_C0),
            SH_C1 * y,
            SH_C1 * z,
            SH_C1 * x,
            SH_C2 * x * y,
            SH_C2 * y * z,
            SH_C3 * (3.0 * z * z - 1.0),
            SH_C2 * x * z,
            SH_C4 * (x * x - y * y),
        ],
        -1,
    )


def band_factors() -> np.ndarray:
    """(9,) A_l per coefficient: radiance coefficients times these are irradiance coefficients."""
    return np.array([SH_A[b] for b in SH_BAND])


def project(radiance: np.ndarray, directions: np.ndarray, solid_angles: np.ndarray) -> np.ndarray:
    """(9, C) coefficients of radiance (N, C) given at unit directions (N, 3) of solid angles (N,)."""
    y = sh9_basis(directions) * np.asarray(solid_angles, np.float64)[:, None]
    return y.T @ np.asarray(radiance, np.float64)


def irradiance(coeffs: np.ndarray, n) -> np.ndarray:
    """(..., C) irradiance on surfaces of unit normals n (..., 3) under radiance coefficients (9, C)."""
    c = np.asarray(coeffs, np.float64) * band_factors()[:, None]
    return sh9_basis(n) @ c


def radiance(coeffs: np.ndarray, d) -> np.ndarray:
    """(..., C) the band-limited radiance the coefficients stand for, toward directions d."""
    return sh9_basis(d) @ np.asarray(coeffs, np.float64)


def rotation(matrix: np.ndarray) -> np.ndarray:
    """(9, 9) M with Y(R d) = M Y(d) for the rotation R: coefficients of L(R^T w) are M @ coefficients
    of L(w) (a radiance turned by R). Each band is closed under rotation, so M is found exactly by
    least squares on a fixed set of directions."""
    r = np.asarray(matrix, np.float64)
    d = _fit_directions()
    y, yr = sh9_basis(d), sh9_basis(d @ r.T)
    m, *_ = np.linalg.lstsq(y, yr, rcond=None)  # y @ m = yr  ->  Y(R d) = m^T Y(d)
    return m.T


def _fit_directions() -> np.ndarray:
    k = np.arange(64) + 0.5
    z = 1.0 - 2.0 * k / 64
    phi = k * PI * (3.0 - np.sqrt(5.0))  # a Fibonacci sphere
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], 1)
