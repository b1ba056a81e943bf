"""Technique "tsd": texture-space diffusion (d'Eon & Luebke 2007, GPU Gems 3 ch. 14;
docs/references.md). Per scattering mesh: the light entering the surface rasterised in UV space,
blurred by a chain of separable Gaussians fitted to the diffusion profile, gathered in the forward
pass. The default technique; its defaults come from the accuracy/time ledger (docs/ledger.md)."""

from __future__ import annotations

from dataclasses import dataclass

from skinlab.declare import option
from skinlab.render.frame_plan import FramePlan
from skinlab.render.options import TechniqueSettings
from skinlab.render.technique import LedgerStyle, LedgerSweep, PlanContext, Technique, TechniquePlan
from skinlab.scene.optics.edges import gaussians_edge, step_edge

from .forward import TsdForward
from .passes import (
    MAX_TAPS,
    STATE_KEY,
    TsdBlurPass,
    TsdDilatePass,
    TsdIrradiancePass,
    TsdSeamPass,
    TsdStore,
    TsdStretchPass,
)
from .plan import TsdBlurParams, TsdIrradianceParams, plan_tsd

PASSES = {
    "tsd_stretch": TsdStretchPass,
    "tsd_irradiance": TsdIrradiancePass,
    "tsd_seams": TsdSeamPass,
    "tsd_dilate": TsdDilatePass,
    "tsd_blur": TsdBlurPass,
}


@dataclass(frozen=True)
class TsdSettings(TechniqueSettings):
    # defaults from the accuracy/time ledger (docs/ledger.md): the cheapest setting within 1 % image
    # error of the exact reference on the head and the bunny
    technique = "tsd"
    size: int = option(
        512,
        "irradiance texels per side (with fit_size: the most a mesh gets)",
        "int",
        range=(16, 8192),
        unit="texels",
        flags=("--tsd-size",),
    )
    fit_size: bool = option(
        True,
        "size each mesh's texture space from its area and its size on screen, 2 texels a pixel, at most `size` "
        "(off: every mesh gets `size`)",
        "bool",
    )
    gaussians: int = option(
        6, "K: Gaussians fitted to the diffusion profile", "int", range=(1, 6), flags=("--gaussians",)
    )
    taps: int | None = option(
        None,
        "blur taps per Gaussian",
        "int",
        range=(7, MAX_TAPS),
        odd=True,
        none="from each blur's width in texels",
        flags=("--taps",),
    )
    albedo_mix: float = option(0.5, "pre-/post-scatter texturing: albedo^mix before the blur", "float", range=(0, 1))
    translucency: bool = option(True, "light through thin parts (needs a shadow-casting light)", "bool")
    seams: bool = option(True, "light crosses UV seams (seam map; off: blurs stop at chart borders)", "bool")


class TsdTechnique(Technique[TsdSettings]):
    name = "tsd"
    description = "texture-space diffusion with the Gaussian fit (d'Eon & Luebke 2007; the default)"
    settings_type = TsdSettings
    passes = PASSES
    state = (STATE_KEY, TsdStore)
    ledger = LedgerStyle(
        "o",
        "tab:blue",
        {"K": "gaussians", "tsd_size": "size", "taps": "taps"},
        "tsd K{gaussians} {size} {taps}",
        sweep={
            "full": LedgerSweep(
                {"size": 1024, "gaussians": 6},
                {"gaussians": (1, 2, 3, 4, 5, 6), "size": (256, 512, 1024, 2048), "taps": (None, 7, 15, 31)},
            ),
            "quick": LedgerSweep(
                {"size": 256, "gaussians": 6}, {"gaussians": (1, 3, 6), "size": (256, 512), "taps": (None, 7)}
            ),
            "tiny": LedgerSweep({"size": 256, "gaussians": 6}, {"gaussians": (1, 6)}),
        },
        proxy=("size", "gaussians", "taps"),
        cost_axes={"size": ("texels", 2.0), "gaussians": ("K", 1.0)},
        levels="tsd_blur",
    )

    def plan(self, ctx: PlanContext) -> TechniquePlan:
        o = ctx.options
        passes, nodes, translucency, local = plan_tsd(
            ctx, o.size, o.gaussians, o.taps, o.albedo_mix, o.translucency, seams=o.seams, fit_size=o.fit_size
        )
        return TechniquePlan(
            TsdForward(len(nodes), local, translucency=translucency),
            before_forward=passes,
            shadow_distance=translucency,
        )

    def edge_response(self, model, medium, plan: FramePlan):
        """The Gaussian kernel the frame used (after the planner folded sub-texel Gaussians into the
        unblurred term); no blur pass at all: a step (plain diffuse)."""
        if not any(isinstance(p.params, TsdBlurParams) for p in plan.passes):
            return step_edge
        k = next(p.params.kernel for p in plan.passes if isinstance(p.params, TsdIrradianceParams))
        return gaussians_edge(k)


TECHNIQUE = TsdTechnique()
