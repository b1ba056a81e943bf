"""OpenPBR Surface's subsurface parameters (docs/references.md#openpbr) as Skinlab material values.

Three of OpenPBR's five names mean exactly what a Skinlab parameter means and are accepted anywhere a
material parameter is: ``subsurface_weight`` (an alias of ``subsurface``), ``subsurface_color`` (the
multiple-scattering albedo) and ``subsurface_scatter_anisotropy`` (the Henyey-Greenstein g). OpenPBR's
radius pair means something else than Skinlab's ``subsurface_radius`` (Blender's artist radius
R = 4 pi l' in millimetres per channel): ``subsurface_radius`` x ``subsurface_radius_scale`` is the
*real* mean free path 1/sigma_t per channel in scene units. So the whole OpenPBR set is read from its
own table, ``[materials.NAME.openpbr]`` (or ``openpbr = { ... }``), where every name has OpenPBR's
meaning, and converted once, here:

    l_c  = subsurface_radius x subsurface_radius_scale_c x mm_per_unit          (real, mm)
    a'   = Skinlab's inversion of the subsurface albedo (photon beam diffusion at the material's index;
           skinlab/scene/optics/media.py invert_surface_albedo)                  (reduced albedo)
    a    = a' / (1 - g + g a')                                                   (similarity)
    R_c  = 4 pi l_c / (1 - a_c g)                                                (Skinlab's radius, mm)

so the medium Skinlab derives (reduced albedo a', reduced mean free path R / 4 pi) has OpenPBR's
extinction, albedo and g. The missing one of the radius pair takes OpenPBR's default (radius 1 scene
unit, scale (1, 0.5, 0.25)); weight, colour and g left out keep the material's values.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

OPENPBR_KEYS = (
    "subsurface_weight",
    "subsurface_color",
    "subsurface_radius",
    "subsurface_radius_scale",
    "subsurface_scatter_anisotropy",
)
OPENPBR_DEFAULT_RADIUS = 1.0
OPENPBR_DEFAULT_SCALE = (1.0, 0.5, 0.25)


def openpbr_to_skinlab(table: dict[str, Any], current: dict[str, Any], mm_per_unit: float, where: str) -> dict:
    """Skinlab values for an OpenPBR subsurface table, given the material's `current` values (for the
    index, the colour map and what the table leaves out) and the scene's millimetres per unit."""
    extra = set(table) - set(OPENPBR_KEYS)
    if extra:
        raise ValueError(
            f"{where}: unknown OpenPBR key(s) {', '.join(sorted(extra))}; expected some of {', '.join(OPENPBR_KEYS)}"
        )
    from .materials import Material

    probe = Material("openpbr", dict(current))
    direct = {
        "subsurface": table.get("subsurface_weight", current["subsurface"]),
        "subsurface_color": table.get("subsurface_color", current["subsurface_color"]),
        "subsurface_scatter_anisotropy": table.get(
            "subsurface_scatter_anisotropy", current.get("subsurface_scatter_anisotropy", 0.0)
        ),
    }
    try:
        probe.update(direct)
    except ValueError as exc:
        raise ValueError(f"{where}: {str(exc).split(': ', 1)[-1]}") from None
    out = {k: probe[k] for k in direct}
    if "subsurface_radius" in table or "subsurface_radius_scale" in table:
        radius = _length(where, table.get("subsurface_radius", OPENPBR_DEFAULT_RADIUS))
        scale = _scale(where, table.get("subsurface_radius_scale", OPENPBR_DEFAULT_SCALE))
        out["subsurface_radius"] = skinlab_radius(radius * scale * mm_per_unit, probe.values)
    return out


def skinlab_radius(mfp_mm, values: dict) -> tuple[float, float, float]:
    """Skinlab's subsurface_radius (4 pi l', mm) for a real mean free path per channel (mm) in the
    medium of `values` (its subsurface albedo, index and g)."""
    from .optics.material_medium import eta_from_specular, subsurface_albedo
    from .optics.media import invert_surface_albedo
    from .optics.similarity import real_albedo

    g = float(values.get("subsurface_scatter_anisotropy", 0.0))
    reduced = invert_surface_albedo(subsurface_albedo(values), eta_from_specular(values["specular"]))
    real = real_albedo(reduced, g)
    r = np.clip(4.0 * math.pi * np.asarray(mfp_mm, np.float64) / np.maximum(1.0 - real * g, 1e-12), 0.0, 1000.0)
    return float(r[0]), float(r[1]), float(r[2])


def _length(where: str, v) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or v < 0:
        raise ValueError(f"{where}.subsurface_radius: expected a length >= 0 in scene units, got {v!r}")
    return float(v)


def _scale(where: str, v) -> np.ndarray:
    items = v if isinstance(v, list | tuple) else [v]
    if not all(isinstance(x, int | float) and not isinstance(x, bool) for x in items):
        raise ValueError(f"{where}.subsurface_radius_scale: expected 1 or 3 numbers >= 0, got {v!r}")
    a = np.asarray(items, np.float64).reshape(-1)
    if a.size == 1:
        a = np.repeat(a, 3)
    if a.size != 3 or not np.isfinite(a).all() or (a < 0).any():
        raise ValueError(f"{where}.subsurface_radius_scale: expected 1 or 3 numbers >= 0, got {v!r}")
    return a
