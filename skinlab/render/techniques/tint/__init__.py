"""Technique "tint": the per-pixel profile tint, no convolution (the original study's baseline).
The subsurface part of each scattering material's diffuse term is tinted by its profile at one
radius (skinlab/scene/optics/profile_tint.py); no light moves across the surface."""

from __future__ import annotations

from dataclasses import dataclass, field

from skinlab.gl.uniforms import set_uniform
from skinlab.render.options import TechniqueSettings
from skinlab.render.scattering import scattering_material
from skinlab.render.technique import (
    ForwardHook,
    LedgerStyle,
    LedgerSweep,
    NodeShading,
    PlanContext,
    Technique,
    TechniquePlan,
)
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.profile_tint import profile_tint

HOOK = "techniques/tint/forward.glsl"


@dataclass(frozen=True)
class TintSettings(TechniqueSettings):
    technique = "tint"


@dataclass
class TintForward(ForwardHook):
    tints: dict = field(default_factory=dict)  # node uid -> (effective material, RGB tint)

    def __post_init__(self) -> None:
        self.reason = f"; profile tint (no convolution) for {len(self.tints)}" if self.tints else ""

    def shading(self, node, frame):
        hit = self.tints.get(node.uid)
        if hit is None:
            return None
        mat, tint = hit
        return NodeShading(mat, HOOK, bind=lambda prog, units: set_uniform(prog, "u_sss_tint", tint))


class TintTechnique(Technique[TintSettings]):
    name = "tint"
    description = (
        "a baseline to compare the others against, not a look: each pixel's subsurface light times the "
        "profile's colour at one radius, no light moved across the surface (the original study's; it shifts "
        "the colour toward the channels that scatter least far, e.g. a skin head turns yellow)"
    )
    settings_type = TintSettings
    ledger = LedgerStyle("^", "tab:green", sweep={"tiny": LedgerSweep()})  # tiny too: the baselines

    def plan(self, ctx: PlanContext) -> TechniquePlan:
        tints = {}
        for n in ctx.meshes:
            mat = scattering_material(n, ctx.settings, ctx.plan, f"tint[{n.name}]")
            if mat is not None:
                tints[n.uid] = (mat, profile_tint(mat["sss_model"], material_medium(mat.values)))
        return TechniquePlan(TintForward(tints))


TECHNIQUE = TintTechnique()
