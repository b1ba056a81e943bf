"""Anisotropic scattering through similarity theory, and the albedo inversions OpenPBR Surface names.

A Henyey-Greenstein medium of single-scattering albedo a, extinction sigma_t and anisotropy g diffuses
like the isotropic medium of the *reduced* coefficients (similarity theory; Wyman, Patterson & Wilson
1989; docs/references.md#similarity):

    sigma_s' = sigma_s (1 - g)      sigma_t' = sigma_a + sigma_s' = sigma_t (1 - a g)
    a' = sigma_s' / sigma_t' = a (1 - g) / (1 - a g)   and back   a = a' / (1 - g + g a')

Skinlab's materials hold the reduced medium (skinlab/scene/optics/media.py: alpha = a', l = 1/sigma_t'),
so the diffusion profiles never see g; the single-scattering term and the path-traced truth use the
real coefficients these functions give back.

OpenPBR Surface (docs/references.md#openpbr) parametrises subsurface colour C as the multiple-scattering
albedo and suggests van de Hulst's fit (Kulla & Conty 2017, index-matched boundary):

    C = (1 - s)(1 - 0.139 s) / (1 + 1.17 s),    s = sqrt((1 - a) / (1 - a g)) = sqrt(1 - a')

inverted as s = 4.09712 + 4.20863 C - sqrt(9.59217 + 41.6808 C + 17.7126 C^2), a = (1 - s^2)/(1 - g s^2).
Skinlab inverts C with photon beam diffusion at the material's own index instead (it accounts for the
boundary, as OpenPBR recommends); :func:`van_de_hulst_albedo` is kept for comparison and tests.
"""

from __future__ import annotations

import numpy as np


def real_albedo(reduced, g):
    """a from the reduced albedo a' and g: a' / (1 - g + g a') (a' = 1 stays 1)."""
    ar = np.clip(np.asarray(reduced, np.float64), 0.0, 1.0)
    g = float(g)
    return np.clip(ar / np.maximum(1.0 - g + g * ar, 1e-300), 0.0, 1.0)


def reduced_albedo(real, g):
    """a' = a (1 - g) / (1 - a g)."""
    a = np.clip(np.asarray(real, np.float64), 0.0, 1.0)
    g = float(g)
    return np.clip(a * (1.0 - g) / np.maximum(1.0 - a * g, 1e-300), 0.0, 1.0)


def reduced_mfp(mfp, real, g):
    """The reduced mean free path 1/sigma_t' = l / (1 - a g) from the real one l = 1/sigma_t."""
    return np.asarray(mfp, np.float64) / np.maximum(1.0 - np.asarray(real, np.float64) * float(g), 1e-300)


def real_mfp(reduced_mfp_, reduced, g):
    """The real mean free path 1/sigma_t = l' (1 - a g) from the reduced one l' = 1/sigma_t'."""
    a = real_albedo(reduced, g)
    return np.asarray(reduced_mfp_, np.float64) * (1.0 - a * float(g))


def van_de_hulst_colour(a, g=0.0):
    """The multiple-scattering albedo C of van de Hulst's fit for single-scattering albedo a and g."""
    a = np.clip(np.asarray(a, np.float64), 0.0, 1.0)
    s = np.sqrt(np.maximum((1.0 - a) / np.maximum(1.0 - a * float(g), 1e-300), 0.0))
    return (1.0 - s) * (1.0 - 0.139 * s) / (1.0 + 1.17 * s)


def van_de_hulst_albedo(colour, g=0.0):
    """Its inverse (OpenPBR Surface, Kulla & Conty 2017): the single-scattering albedo a for C and g."""
    c = np.clip(np.asarray(colour, np.float64), 0.0, 1.0)
    s = 4.09712 + 4.20863 * c - np.sqrt(9.59217 + 41.6808 * c + 17.7126 * c * c)
    s2 = np.clip(s, 0.0, 1.0) ** 2
    return np.clip((1.0 - s2) / np.maximum(1.0 - float(g) * s2, 1e-300), 0.0, 1.0)
