"""NumPy twins of skinlab/shaders/lib/surface.glsl: the surface inputs a glTF material brings beyond the
principled BRDF (occlusion strength, opacity and its mask). Same names, same clamps."""

from __future__ import annotations

import numpy as np


def occlusion_at_strength(map_r, strength):
    """1 + strength (map - 1): glTF's occlusionTexture.strength (0: no occlusion, 1: the map)."""
    return 1.0 + np.clip(strength, 0.0, 1.0) * (np.clip(map_r, 0.0, 1.0) - 1.0)


def surface_alpha(alpha, map_a, vertex_a):
    """Opacity: the material's alpha x the colour map's alpha x the vertex colour's alpha, in [0, 1]."""
    return np.clip(np.asarray(alpha, np.float64) * map_a * vertex_a, 0.0, 1.0)


def alpha_kept(a, cutoff):
    """A masked surface is there where its opacity reaches the cutoff (glTF alphaMode MASK)."""
    return np.asarray(a) >= cutoff
