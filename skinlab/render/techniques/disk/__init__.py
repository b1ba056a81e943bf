"""Technique "disk": importance-sampled Burley disk SSS in screen space (Golubev, SIGGRAPH 2018
"Efficient Screen-Space Subsurface Scattering Using Burley's Normalized Diffusion in Real-Time"; as
Unity HDRP and Blender EEVEE Next ship it). The forward pass writes the subsurface diffuse radiance
and each pixel's profile index to a second target; one post-process gathers, per pixel, samples on
a disc whose radii follow the Burley CDF (millimetres on the surface, from the pixel's depth),
weighted by the pixel's own profile (a table of up to 16 profiles per frame: many media in one
frame), with depth-aware rejection and a per-pixel rotation. NumPy model: skinlab/scene/optics/disk.py. With
`translucency` the forward pass adds the light through thin parts (skinlab/render/translucency.py, as
texture-space diffusion's irradiance pass does) to the light the disk pass gathers."""

from __future__ import annotations

from dataclasses import dataclass

from skinlab.declare import option
from skinlab.render.frame_plan import FramePlan, PlannedPass
from skinlab.render.options import TechniqueSettings
from skinlab.render.profile_table import ProfileIndexForward, plan_profile_table
from skinlab.render.technique import LedgerStyle, LedgerSweep, PlanContext, Technique, TechniquePlan
from skinlab.render.translucency import OPTION_DOC, plan_translucency
from skinlab.scene.optics.disk import MAX_DISK_SAMPLES, disk_edge_response, disk_kernel

from .passes import DIFFUSE_TARGET, DiskParams, DiskPass

# the path `compute = auto` takes for the gather on software GL (skinlab/render/compute.py; measured:
# docs/architecture.md "Compute passes")
GATHER_ON_SOFTWARE = "fragment"

HOOK = "techniques/disk/forward.glsl"


@dataclass(frozen=True)
class DiskSettings(TechniqueSettings):
    technique = "disk"
    samples: int = option(
        32, "disk samples per pixel, radii from the Burley CDF (Golubev 2018)", "int", range=(8, MAX_DISK_SAMPLES)
    )
    rotate: bool = option(True, "rotate each pixel's sample spiral (noise instead of banding)", "bool")
    translucency: bool = option(True, OPTION_DOC, "bool")


class DiskTechnique(Technique[DiskSettings]):
    name = "disk"
    description = "importance-sampled Burley disk SSS in screen space (Golubev 2018; HDRP, EEVEE Next)"
    settings_type = DiskSettings
    passes = {"disk_sss": DiskPass}
    ledger = LedgerStyle(
        "P",
        "tab:cyan",
        {"disk_samples": "samples"},
        "disk {samples}",
        sweep={"full": LedgerSweep(axes={"samples": (8, 16, 32, 64)}), "quick": LedgerSweep(axes={"samples": (8, 32)})},
    )

    def plan(self, ctx: PlanContext) -> TechniquePlan:
        o = ctx.options
        table = plan_profile_table(ctx.meshes, ctx.settings, ctx.plan, self.name)
        nodes, keys, labels = table.nodes, table.keys, [m.name for m in table.materials]
        if not keys:
            ctx.plan.skipped.append(("disk_sss", "no visible material scatters below the surface"))
            return TechniquePlan()
        kernels = [disk_kernel(model, medium, o.samples) for model, medium in keys]
        names = ", ".join(f"'{lab}' ({m})" for lab, (m, _) in zip(labels, keys))
        path = ctx.path(GATHER_ON_SOFTWARE)
        p = PlannedPass(
            "disk_sss",
            "disk_sss",
            "hdr_color",
            ctx.settings.render_size,
            f"Burley disk SSS (Golubev 2018): {o.samples} samples per pixel"
            f"{', rotated per pixel' if o.rotate else ''}, depth-aware; {len(keys)} profile(s): {names}" + path.note,
            DiskParams(o.samples, o.rotate, kernels, path.compute),
        )
        through = plan_translucency(ctx, True, o.translucency)
        what = "and profile index to a second target for the disk pass"
        hook = ProfileIndexForward(HOOK, "u_disk_profile", DIFFUSE_TARGET, what, nodes, through)
        return TechniquePlan(hook, after_forward=[p], shadow_distance=through)

    def edge_response(self, model, medium, plan: FramePlan):
        """The disk kernel's edge response averaged over the per-pixel rotation."""
        for p in plan.passes:
            if isinstance(p.params, DiskParams):
                k = disk_kernel(model, medium, p.params.samples)
                return lambda x: disk_edge_response(x, k)
        return super().edge_response(model, medium, plan)


TECHNIQUE = DiskTechnique()
