"""Technique "ssss": screen-space separable subsurface scattering (Jimenez et al., "Separable
Subsurface Scattering", 2015; docs/references.md). The forward pass writes the subsurface diffuse
radiance and each pixel's profile index to a second target; one post-process blurs it horizontally
then vertically with the pixel's own profile's 1-D kernel (skinlab/scene/optics/ssss.py; a table of up to 16
profiles per frame) and adds it back. With `translucency` the forward pass adds the light through
thin parts (skinlab/render/translucency.py, as texture-space diffusion's irradiance pass does) to the
light that gets blurred."""

from __future__ import annotations

from dataclasses import dataclass

from skinlab.declare import option
from skinlab.render.frame_plan import FramePlan, PlannedPass
from skinlab.render.options import TechniqueSettings
from skinlab.render.profile_table import ProfileIndexForward
from skinlab.render.technique import LedgerStyle, LedgerSweep, PlanContext, Technique, TechniquePlan
from skinlab.render.translucency import OPTION_DOC, plan_translucency
from skinlab.scene.optics.edges import separable_edge

from .passes import MAX_SSSS_TAPS, SsssBlurParams, SsssBlurPass
from .plan import plan_ssss

HOOK = "techniques/ssss/forward.glsl"
# the path `compute = auto` takes for the blur on software GL (skinlab/render/compute.py; measured:
# docs/architecture.md "Compute passes")
BLUR_ON_SOFTWARE = "fragment"
DIFFUSE_TARGET = "ssss_diffuse"


@dataclass(frozen=True)
class SsssSettings(TechniqueSettings):
    technique = "ssss"
    taps: int = option(
        17, "screen-space kernel samples (Jimenez presets: 11, 17, 25)", "int", range=(3, MAX_SSSS_TAPS), odd=True
    )
    gaussians: int = option(6, "Gaussians fitted to the profile the kernel is sampled from", "int", range=(1, 6))
    translucency: bool = option(True, OPTION_DOC, "bool")


class SsssTechnique(Technique[SsssSettings]):
    name = "ssss"
    description = "screen-space separable SSS (Jimenez et al.): a post-process blur of the diffuse light"
    settings_type = SsssSettings
    passes = {"ssss_blur": SsssBlurPass}
    ledger = LedgerStyle(
        "s",
        "tab:orange",
        {"ssss_taps": "taps"},
        "ssss {taps}",
        sweep={"full": LedgerSweep(axes={"taps": (11, 17, 25)}), "quick": LedgerSweep(axes={"taps": (11, 25)})},
    )

    def plan(self, ctx: PlanContext) -> TechniquePlan:
        o = ctx.options
        ssss = plan_ssss(ctx.meshes, ctx.settings, ctx.plan, o.gaussians, o.taps)
        if ssss is None:
            return TechniquePlan()
        names = ", ".join(f"'{k.material.name}' ({k.material['sss_model']})" for k in ssss.kernels)
        path = ctx.path(BLUR_ON_SOFTWARE)
        blur = PlannedPass(
            "ssss_blur",
            "ssss_blur",
            "hdr_color",
            ctx.settings.render_size,
            f"screen-space separable SSS (Jimenez et al.): {o.taps}-tap kernel per pixel's profile "
            f"({len(ssss.kernels)}: {names}), horizontal then vertical, depth-aware" + path.note,
            SsssBlurParams(ssss, o.gaussians, path.compute),
        )
        through = plan_translucency(ctx, True, o.translucency)
        # the node's own material binds (an sss_model override changes no uniform)
        profiles = {n.uid: (n.material, ssss.profile[n.uid]) for n in ctx.meshes if n.uid in ssss.profile}
        what = "to a second target for the screen-space blur"
        hook = ProfileIndexForward(HOOK, "u_ssss_profile", DIFFUSE_TARGET, what, profiles, through)
        return TechniquePlan(hook, after_forward=[blur], shadow_distance=through)

    def edge_response(self, model, medium, plan: FramePlan):
        """The 1-D kernel of the material's profile across an edge along a screen axis (the separable
        kernel's best case), at the frame's tap count."""
        for p in plan.passes:
            if isinstance(p.params, SsssBlurParams):
                from skinlab.scene.optics.profile_fit import profile_fit
                from skinlab.scene.optics.ssss import ssss_kernel

                offsets, weights, _ = ssss_kernel(profile_fit(model, medium, p.params.gaussians), p.params.ssss.taps)
                return separable_edge(offsets, weights)
        return super().edge_response(model, medium, plan)


TECHNIQUE = SsssTechnique()
