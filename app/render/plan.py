"""The frame is planned from the scene: a pass runs only when something visible needs it."""

from __future__ import annotations

from dataclasses import dataclass, field

from scene.graph import LightNode, Scene
from scene.optics.tsd import material_medium, profile_tint

from .plan_ssss import plan_ssss
from .plan_tsd import DILATE_RINGS, plan_tsd_node, scattering_material
from .settings import RenderSettings


@dataclass
class PlannedPass:
    name: str
    kind: str  # shadow | tsd_stretch | tsd_irradiance | tsd_dilate | tsd_blur | forward | tonemap
    target: str
    resolution: tuple[int, int]
    reason: str
    params: dict = field(default_factory=dict)


@dataclass
class FramePlan:
    passes: list[PlannedPass]
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (what, why not)
    warnings: list[str] = field(default_factory=list)

    def names(self) -> list[str]:
        return [p.name for p in self.passes]

    def explain(self, warnings: bool = True) -> str:
        """The plan as text; ``warnings=False`` leaves out the warnings (for a caller that prints them)."""
        lines = ["frame plan:"]
        for i, p in enumerate(self.passes, 1):
            lines.append(f"  {i}. {p.name:<18} -> {p.target} {p.resolution[0]}x{p.resolution[1]}: {p.reason}")
        for what, why in self.skipped:
            lines.append(f"  -  {what:<18} skipped: {why}")
        for w in self.warnings if warnings else ():
            lines.append(f"  !  warning: {w}")
        return "\n".join(lines)

    def as_dict(self) -> dict:
        return {
            "passes": [
                {
                    "name": p.name,
                    "kind": p.kind,
                    "target": p.target,
                    "resolution": list(p.resolution),
                    "reason": p.reason,
                }
                for p in self.passes
            ],
            "skipped": [{"what": w, "why": y} for w, y in self.skipped],
            "warnings": list(self.warnings),
        }


def plan_frame(scene: Scene, settings: RenderSettings, stretch_valid=None) -> FramePlan:
    """Passes for this frame. ``stretch_valid(node, scene, size)`` tells whether a node's stretch map
    is still current (the renderer's TSD store); without it every stretch map is planned."""
    meshes = scene.mesh_nodes()
    lights = scene.lights()
    plan = FramePlan([])
    if len(lights) > settings.max_lights:
        plan.skipped.append(
            (
                f"{len(lights) - settings.max_lights} light(s)",
                f"more than {settings.max_lights} lights; the first {settings.max_lights} are used",
            )
        )
        lights = lights[: settings.max_lights]
    shadow_lights: list[LightNode] = [l for l in lights if l.cast_shadow]
    for l in lights:
        if not l.cast_shadow:
            plan.skipped.append((f"shadow[{l.name}]", "light does not cast shadows"))
    if not meshes:
        plan.skipped.append(("shadows", "no visible mesh"))
        shadow_lights = []
    technique = settings.technique
    tsd_nodes, tint, ssss = [], {}, None
    if technique in ("tsd", "exact"):
        tsd_nodes = [t for t in (plan_tsd_node(n, settings, scene, plan) for n in meshes) if t is not None]
    elif technique == "tint":
        for n in meshes:
            mat = scattering_material(n, settings, plan, f"tint[{n.name}]")
            if mat is not None:
                tint[n.uid] = (mat, profile_tint(mat["sss_model"], material_medium(mat.values)))
    elif technique == "ssss":
        ssss = plan_ssss(meshes, settings, plan)
    translucency = bool(tsd_nodes) and settings.translucency and bool(shadow_lights)
    if tsd_nodes and not translucency:
        plan.skipped.append(
            ("translucency", "disabled in the settings" if not settings.translucency else "no shadow-casting light")
        )
    for slot, l in enumerate(shadow_lights[:2]):
        plan.passes.append(
            PlannedPass(
                f"shadow[{l.name}]",
                "shadow",
                f"shadow_map{slot}" + (f"+shadow_distance{slot}" if translucency else ""),
                (settings.shadow_size, settings.shadow_size),
                f"{l.kind} light '{l.name}' casts shadows on {len(meshes)} visible mesh(es)"
                + ("; distance map for translucency" if translucency else ""),
                {"light": l, "slot": slot, "distance": translucency},
            )
        )
    for l in shadow_lights[2:]:
        plan.skipped.append((f"shadow[{l.name}]", "at most 2 shadow-casting lights"))
    if not tsd_nodes:
        plan.skipped.append(
            (
                "texture-space diffusion",
                "no visible material needs it" if technique in ("tsd", "exact") else f"technique is {technique}",
            )
        )
    for t in tsd_nodes:
        _plan_tsd_passes(plan, t, scene, settings, lights, shadow_lights[:2], translucency, stretch_valid)
    what = (
        f"; gather diffusion for {len(tsd_nodes)}"
        if tsd_nodes
        else f"; profile tint (no convolution) for {len(tint)}"
        if tint
        else "; subsurface diffuse to a second target for the screen-space blur"
        if ssss
        else ""
    )
    plan.passes.append(
        PlannedPass(
            "forward",
            "forward",
            "hdr_color+depth" + ("+diffuse" if ssss else ""),
            settings.size,
            f"shade {len(meshes)} visible mesh(es) with {len(lights)} light(s)" + what,
            {"lights": lights, "shadow_lights": shadow_lights[:2], "tint": tint, "ssss": ssss},
        )
    )
    if ssss is not None:
        plan.passes.append(
            PlannedPass(
                "ssss_blur",
                "ssss_blur",
                "hdr_color",
                settings.size,
                f"screen-space separable SSS (Jimenez et al.): {settings.ssss_taps}-tap kernel of "
                f"'{ssss.material.name}' ({ssss.material['sss_model']}), horizontal then vertical, depth-aware",
                {"ssss": ssss},
            )
        )
    plan.passes.append(
        PlannedPass(
            "tonemap", "tonemap", "ldr_color", settings.size, "ACES tone mapping and sRGB encoding for display/PNG"
        )
    )
    return plan


def _plan_tsd_passes(plan, t, scene, settings, lights, shadow_lights, translucency, stretch_valid) -> None:
    node, n, k = t.node, t.size, t.kernel
    base = {"node": node, "size": n, "material": t.material, "kernel": k, "dilate": DILATE_RINGS}
    res = (n, n)
    if stretch_valid is not None and stretch_valid(node, scene, n):
        plan.skipped.append(
            (f"tsd_stretch[{node.name}]", f"geometry unchanged (mesh version {node.mesh.version}); stretch map reused")
        )
    else:
        plan.passes.append(
            PlannedPass(
                f"tsd_stretch[{node.name}]",
                "tsd_stretch",
                "tsd_stretch",
                res,
                f"mm per texel of '{node.mesh.name}' (new or changed geometry / scale)",
                base,
            )
        )
    plan.passes.append(
        PlannedPass(
            f"tsd_irradiance[{node.name}]",
            "tsd_irradiance",
            "tsd_irradiance",
            res,
            f"material '{t.material.name}' scatters ({t.material['sss_model']}): light entering the surface in UV space"
            + (", translucency through thin parts" if translucency else ""),
            {
                **base,
                "lights": lights,
                "shadow_lights": shadow_lights,
                "translucency": translucency,
                "mix": settings.tsd_albedo_mix,
            },
        )
    )
    plan.passes.append(
        PlannedPass(
            f"tsd_dilate[{node.name}]",
            "tsd_dilate",
            "tsd_irradiance",
            res,
            f"push irradiance {DILATE_RINGS} texels past UV chart borders (seams)",
            base,
        )
    )
    if settings.technique == "exact":
        plan.passes.append(
            PlannedPass(
                f"tsd_exact[{node.name}]",
                "tsd_exact",
                "tsd_level0",
                res,
                f"brute-force convolution with the exact {t.material['sss_model']} profile (image reference; slow "
                "on purpose)",
                {**base, "model": t.material["sss_model"]},
            )
        )
        return
    for s in k.steps:
        w = ", ".join(f"{x:.3f}" for x in s.weight)
        plan.passes.append(
            PlannedPass(
                f"tsd_blur[{node.name}]{s.level}",
                "tsd_blur",
                f"tsd_level{s.level}",
                res,
                f"Gaussian v={s.variance_mm2:.4g} mm2 (step sigma {s.sigma_mm:.3g} mm, {s.taps} taps), "
                f"weight RGB ({w})",
                {**base, "step": s},
            )
        )
