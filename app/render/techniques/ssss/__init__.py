"""Technique "ssss": screen-space separable subsurface scattering (Jimenez et al., "Separable
Subsurface Scattering", 2015; docs/references.md). The forward pass writes the subsurface diffuse
radiance to a second target; one post-process blurs it horizontally then vertically with the
profile's 1-D kernel (scene/optics/ssss.py) and adds it back."""

from __future__ import annotations

from dataclasses import dataclass

from app.gl.uniforms import set_uniform
from app.render.frame_plan import FramePlan, PlannedPass
from app.render.options import TechniqueSettings, option
from app.render.technique import ForwardHook, LedgerStyle, NodeShading, PlanContext, Technique, TechniquePlan
from scene.optics.edges import separable_edge

from .passes import MAX_SSSS_TAPS, SsssBlurParams, SsssBlurPass
from .plan import SsssPlan, plan_ssss

HOOK = "techniques/ssss/forward.glsl"
DIFFUSE_TARGET = "ssss_diffuse"


@dataclass(frozen=True)
class SsssSettings(TechniqueSettings):
    technique = "ssss"
    taps: int = option(
        17, "screen-space kernel samples (Jimenez presets: 11, 17, 25)", "int", range=(3, MAX_SSSS_TAPS), odd=True
    )
    gaussians: int = option(6, "Gaussians fitted to the profile the kernel is sampled from", "int", range=(1, 6))


@dataclass
class SsssForward(ForwardHook):
    ssss: SsssPlan

    outputs = (DIFFUSE_TARGET,)
    reason = "; subsurface diffuse to a second target for the screen-space blur"

    def shading(self, node, frame):
        # every mesh writes the second target; the node's own values apply (sss_model overrides
        # change no uniform)
        enabled = float(node.uid in self.ssss.scattering)
        return NodeShading(
            node.material,
            HOOK,
            bind=lambda prog, units: set_uniform(prog, "u_ssss_enabled", enabled),
            subsurface=bool(enabled),
        )


class SsssTechnique(Technique):
    name = "ssss"
    description = "screen-space separable SSS (Jimenez et al.): a post-process blur of the diffuse light"
    settings_type = SsssSettings
    passes = {"ssss_blur": SsssBlurPass}
    ledger = LedgerStyle("s", "tab:orange", {"ssss_taps": "taps"}, "ssss {ssss_taps}")

    def plan(self, ctx: PlanContext) -> TechniquePlan:
        o = ctx.options
        ssss = plan_ssss(ctx.meshes, ctx.settings, ctx.plan, o.gaussians, o.taps)
        if ssss is None:
            return TechniquePlan()
        blur = PlannedPass(
            "ssss_blur",
            "ssss_blur",
            "hdr_color",
            ctx.settings.size,
            f"screen-space separable SSS (Jimenez et al.): {o.taps}-tap kernel of "
            f"'{ssss.material.name}' ({ssss.material['sss_model']}), horizontal then vertical, depth-aware",
            SsssBlurParams(ssss),
        )
        return TechniquePlan(SsssForward(ssss), after_forward=[blur])

    def edge_response(self, model, medium, plan: FramePlan):
        """The frame's 1-D kernel across an edge along a screen axis (the separable kernel's best case)."""
        for p in plan.passes:
            if isinstance(p.params, SsssBlurParams):
                return separable_edge(p.params.ssss.offsets_mm, p.params.ssss.weights)
        return super().edge_response(model, medium, plan)


TECHNIQUE = SsssTechnique()
