"""Planning screen-space separable SSS: one kernel per frame (Jimenez et al.'s post-process works on
the whole image), taken from the first visible scattering material."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from app.render.scattering import scattering_material
from scene.optics.ssss import ssss_kernel
from scene.optics.tsd import material_medium, profile_fit


@dataclass
class SsssPlan:
    material: object
    offsets_mm: np.ndarray  # (n,)
    weights: np.ndarray  # (n, 3)
    range_mm: float
    scattering: set  # uids of the nodes whose diffuse is blurred


def plan_ssss(meshes, settings, plan, gaussians: int, taps: int) -> SsssPlan | None:
    chosen, uids = None, set()
    for n in meshes:
        mat = scattering_material(n, settings, plan, f"ssss[{n.name}]")
        if mat is None:
            continue
        if chosen is None:
            chosen = mat
        elif mat.values != chosen.values:
            plan.warnings.append(
                f"screen-space SSS blurs the whole image with one kernel: node '{n.name}' "
                f"(material '{mat.name}') is blurred with material '{chosen.name}''s profile"
            )
        uids.add(n.uid)
    if chosen is None:
        plan.skipped.append(("ssss_blur", "no visible material scatters below the surface"))
        return None
    fit = profile_fit(chosen["sss_model"], material_medium(chosen.values), gaussians)
    offsets, weights, rng = ssss_kernel(fit, taps)
    return SsssPlan(chosen, offsets, weights, rng, uids)
