"""Planning screen-space separable SSS: one 1-D kernel per distinct profile (material sss_model and
medium) among the visible scattering meshes, up to MAX_SSSS_PROFILES per frame; the forward pass
writes each pixel's profile index, so each pixel is blurred with its own material's kernel (as
HDRP keeps a table of profiles)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from skinlab.render.scattering import scattering_material
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.profile_fit import profile_fit
from skinlab.scene.optics.ssss import ssss_kernel

MAX_SSSS_PROFILES = 16  # skinlab/shaders/techniques/ssss/blur.glsl


@dataclass
class SsssKernel:
    material: object  # the first material using this profile (named in the plan)
    offsets_mm: np.ndarray  # (n,)
    weights: np.ndarray  # (n, 3)
    range_mm: float


@dataclass
class SsssPlan:
    kernels: list[SsssKernel]  # by profile index
    profile: dict = field(default_factory=dict)  # node uid -> profile index (nodes whose diffuse is blurred)

    # the first profile's kernel (a frame with one scattering material has only that one)
    @property
    def material(self):
        return self.kernels[0].material

    @property
    def offsets_mm(self) -> np.ndarray:
        return self.kernels[0].offsets_mm

    @property
    def weights(self) -> np.ndarray:
        return self.kernels[0].weights

    def table(self) -> np.ndarray:
        """(profiles, taps, 4) float32: rgb weight, a offset mm (the blur's u_table)."""
        t = np.zeros((len(self.kernels), len(self.offsets_mm), 4), np.float32)
        for j, k in enumerate(self.kernels):
            t[j, :, :3] = k.weights
            t[j, :, 3] = k.offsets_mm
        return t


def plan_ssss(meshes, settings, plan, gaussians: int, taps: int) -> SsssPlan | None:
    keys, kernels, profile = [], [], {}
    for n in meshes:
        mat = scattering_material(n, settings, plan, f"ssss[{n.name}]")
        if mat is None:
            continue
        key = (mat["sss_model"], material_medium(mat.values))
        if key not in keys:
            if len(keys) == MAX_SSSS_PROFILES:
                plan.warnings.append(
                    f"screen-space SSS keeps {MAX_SSSS_PROFILES} profiles per frame: node '{n.name}' "
                    f"(material '{mat.name}') is blurred with material '{kernels[-1].material.name}''s profile"
                )
                profile[n.uid] = len(keys) - 1
                continue
            keys.append(key)
            offsets, weights, rng = ssss_kernel(profile_fit(key[0], key[1], gaussians), taps)
            kernels.append(SsssKernel(mat, offsets, weights, rng))
        profile[n.uid] = keys.index(key)
    if not kernels:
        plan.skipped.append(("ssss_blur", "no visible material scatters below the surface"))
        return None
    return SsssPlan(kernels, profile)
