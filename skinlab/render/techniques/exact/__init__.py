"""Technique "exact": brute-force texture-space convolution of the irradiance with the material's
exact radial profile (no Gaussian fit) - the slow image reference of the accuracy ledger. It runs
texture-space diffusion's stretch, irradiance and dilation passes and its gather (shared state and
hook from skinlab/render/techniques/tsd/), with one exact convolution in place of the Gaussian blurs."""

from __future__ import annotations

from dataclasses import dataclass

from skinlab.declare import option
from skinlab.render.frame_plan import FramePlan
from skinlab.render.options import TechniqueSettings
from skinlab.render.technique import LedgerStyle, LedgerSweep, PlanContext, Technique, TechniquePlan
from skinlab.render.techniques.tsd import PASSES as TSD_PASSES
from skinlab.render.techniques.tsd.forward import TsdForward
from skinlab.render.techniques.tsd.passes import STATE_KEY, TsdStore
from skinlab.render.techniques.tsd.plan import TsdExactParams, plan_tsd
from skinlab.scene.optics.edges import model_edge, step_edge

from .passes import TsdExactPass

# the node planning and the translucency term use texture-space diffusion's Gaussian fit at its
# default K and automatic taps (only a mesh whose profile is wider than a texel is convolved)
FIT_GAUSSIANS = 6


@dataclass(frozen=True)
class ExactSettings(TechniqueSettings):
    technique = "exact"
    size: int = option(512, "irradiance texels per side", "int", range=(16, 8192), unit="texels")
    albedo_mix: float = option(
        0.5, "pre-/post-scatter texturing: albedo^mix before the convolution", "float", range=(0, 1)
    )
    translucency: bool = option(True, "light through thin parts (needs a shadow-casting light)", "bool")
    seams: bool = option(True, "light crosses UV seams (seam map; off: blurs stop at chart borders)", "bool")


# the path `compute = auto` takes for the convolution on software GL (skinlab/render/compute.py; measured:
# docs/architecture.md "Compute passes")
GATHER_ON_SOFTWARE = "fragment"


class ExactTechnique(Technique[ExactSettings]):
    name = "exact"
    description = "brute-force texture-space convolution with the exact profile (the slow image reference)"
    slow = "the brute-force reference: a frame may take seconds"
    settings_type = ExactSettings
    passes = {**TSD_PASSES, "tsd_exact": TsdExactPass}
    state = (STATE_KEY, TsdStore)  # texture-space diffusion's per-mesh textures, shared
    ledger = LedgerStyle(
        "*",
        "black",
        {"tsd_size": "size"},
        "exact {size}",
        sweep={  # the reference at its base size; the smaller sizes show the irradiance texture's own error
            "full": LedgerSweep({"size": 1024}, {"size": (256, 512)}),
            "quick": LedgerSweep({"size": 256}),
            "tiny": LedgerSweep({"size": 256}),
        },
        reference=True,
        levels="tsd_blur",
    )

    def plan(self, ctx: PlanContext) -> TechniquePlan:
        o = ctx.options
        passes, nodes, translucency, local = plan_tsd(
            ctx,
            o.size,
            FIT_GAUSSIANS,
            None,
            o.albedo_mix,
            o.translucency,
            exact=ctx.path(GATHER_ON_SOFTWARE),
            seams=o.seams,
        )
        return TechniquePlan(
            TsdForward(len(nodes), local, translucency=translucency),
            before_forward=passes,
            shadow_distance=translucency,
        )

    def edge_response(self, model, medium, plan: FramePlan):
        """The material's exact model profile, where the convolution ran."""
        if not any(isinstance(p.params, TsdExactParams) for p in plan.passes):
            return step_edge
        return model_edge(model, medium)


TECHNIQUE = ExactTechnique()
