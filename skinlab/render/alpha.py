"""A material's opacity in the passes that draw meshes: the cut-out of alpha_mode "mask" in the
depth-only passes (shadow maps, the depth pre-pass: skinlab/shaders/lib/alpha_mask.glsl) and the
drawing order of alpha_mode "blend" in the forward pass (opaque meshes first, then the blended ones
from far to near)."""

from __future__ import annotations

import numpy as np

from skinlab.gl.uniforms import set_uniforms


def masked(material) -> bool:
    return material is not None and material.values.get("alpha_mode") == "mask"


def blended(material) -> bool:
    return material is not None and material.values.get("alpha_mode") == "blend"


def mask_defines(material) -> dict:
    """The variant of a depth-only pass for `material`: ALPHA_MASK (and its colour map) or nothing."""
    if not masked(material):
        return {}
    out = {"ALPHA_MASK": "1"}
    if material.values.get("base_color_map") is not None:
        out["HAS_BASE_COLOR_MAP"] = "1"
    return out


def bind_mask(resources, prog, material, units) -> None:
    """The uniforms and the colour map lib/alpha_mask.glsl reads (a masked material only)."""
    if not masked(material):
        return
    set_uniforms(prog, {"u_alpha": material["alpha"], "u_alpha_cutoff": material["alpha_cutoff"]})
    path = material.values.get("base_color_map")
    if path is not None:
        units.bind(prog, "u_base_color_map", resources.texture(path, "srgb"))


def draw_order(nodes, camera_pos) -> list:
    """Opaque and masked meshes in scene order, then the blended ones far to near (by the distance
    from the camera to the centre of their world bounds)."""
    opaque = [n for n in nodes if not blended(n.material)]
    glass = [n for n in nodes if blended(n.material)]

    def distance(n):
        lo, hi = n.mesh.bounds
        c = n.world_matrix @ np.append((lo + hi) / 2, 1.0)
        return -float(np.linalg.norm(c[:3] - np.asarray(camera_pos, np.float64)))

    return opaque + sorted(glass, key=distance)
