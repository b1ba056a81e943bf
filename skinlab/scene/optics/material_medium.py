"""The homogeneous medium of a principled material, and its relative index: what every subsurface
technique (skinlab/render/techniques/*), the path-traced truth's exporter (skinlab/truth/export.py) and
the accuracy benchmarks read from a material's values (subsurface_color, subsurface_radius, specular,
base_color_map; docs/scenes.md, the colour rule)."""

from __future__ import annotations

import math

import numpy as np

from .constants import SPECULAR_F0_SCALE
from .media import Medium


def eta_from_specular(specular: float) -> float:
    """Relative index from the principled specular (F0 = 0.08 specular; eta = (1+sqrt F0)/(1-sqrt F0)),
    clamped to [1, 2.5] (specular 0 would mean eta = 1: no interface)."""
    f0 = SPECULAR_F0_SCALE * float(specular)
    s = math.sqrt(max(f0, 0.0))
    return float(min(max((1.0 + s) / (1.0 - s), 1.0), 2.5))


def subsurface_albedo(values) -> np.ndarray:
    """The medium's surface albedo (the colour the scattering part shows from afar, on average): the
    subsurface colour x the mean of the colour map, if the material has one (docs/scenes.md, the colour
    rule: the map multiplies the subsurface colour per texel; one homogeneous medium per material)."""
    albedo = np.asarray(values["subsurface_color"], np.float64).reshape(3)
    cmap = values.get("base_color_map")
    if cmap is not None:
        from skinlab.scene.textures import texture_mean

        albedo = albedo * texture_mean(cmap, "srgb")
    return np.clip(albedo, 0.0, 1.0)


def material_medium(values) -> Medium:
    """The homogeneous medium of a principled material: its subsurface albedo (:func:`subsurface_albedo`)
    is the surface albedo, subsurface_radius the artist radius per channel (Blender's convention,
    l = R / 4 pi): the reduced medium (similarity), whatever subsurface_scatter_anisotropy is."""
    return Medium.from_artist_radius(
        subsurface_albedo(values), values["subsurface_radius"], eta=eta_from_specular(values["specular"])
    )
