"""Planning screen-space separable SSS: one 1-D kernel per row of the frame's profile table (the
distinct material sss_model and medium among the visible scattering meshes, up to MAX_PROFILES:
skinlab/render/profile_table.py); the forward pass writes each pixel's profile index, so each pixel
is blurred with its own material's kernel (as HDRP keeps a table of profiles)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from skinlab.render.profile_table import plan_profile_table
from skinlab.scene.optics.profile_fit import profile_fit
from skinlab.scene.optics.ssss import ssss_kernel

if TYPE_CHECKING:
    from skinlab.scene.materials import Material


@dataclass
class SsssKernel:
    material: Material  # the first material using this profile (named in the plan)
    offsets_mm: np.ndarray  # (n,)
    weights: np.ndarray  # (n, 3)
    range_mm: float


@dataclass
class SsssPlan:
    kernels: list[SsssKernel]  # by profile index
    profile: dict = field(default_factory=dict)  # node uid -> profile index (nodes whose diffuse is blurred)

    @property
    def taps(self) -> int:
        """Taps per kernel (every profile's kernel has as many)."""
        return len(self.kernels[0].offsets_mm)

    def table(self) -> np.ndarray:
        """(profiles, taps, 4) float32: rgb weight, a offset mm (the blur's u_table)."""
        t = np.zeros((len(self.kernels), self.taps, 4), np.float32)
        for j, k in enumerate(self.kernels):
            t[j, :, :3] = k.weights
            t[j, :, 3] = k.offsets_mm
        return t


def plan_ssss(meshes, settings, plan, gaussians: int, taps: int) -> SsssPlan | None:
    table = plan_profile_table(meshes, settings, plan, "ssss")
    if not table.keys:
        plan.skipped.append(("ssss_blur", "no visible material scatters below the surface"))
        return None
    kernels = []
    for mat, (model, medium) in zip(table.materials, table.keys):
        offsets, weights, rng = ssss_kernel(profile_fit(model, medium, gaussians), taps)
        kernels.append(SsssKernel(mat, offsets, weights, rng))
    return SsssPlan(kernels, {uid: index for uid, (_, index) in table.nodes.items()})
