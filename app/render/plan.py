"""The frame is planned from the scene: a pass runs only when something visible needs it."""
from __future__ import annotations

from dataclasses import dataclass, field

from scene.graph import LightNode, Scene

from .settings import RenderSettings


@dataclass
class PlannedPass:
    name: str
    kind: str                        # shadow | forward | tonemap | (issue 4: irradiance, stretch, blur, ...)
    target: str
    resolution: tuple[int, int]
    reason: str
    params: dict = field(default_factory=dict)


@dataclass
class FramePlan:
    passes: list[PlannedPass]
    skipped: list[tuple[str, str]] = field(default_factory=list)   # (what, why not)

    def names(self) -> list[str]:
        return [p.name for p in self.passes]

    def explain(self) -> str:
        lines = ["frame plan:"]
        for i, p in enumerate(self.passes, 1):
            lines.append(f"  {i}. {p.name:<18} -> {p.target} {p.resolution[0]}x{p.resolution[1]}: {p.reason}")
        for what, why in self.skipped:
            lines.append(f"  -  {what:<18} skipped: {why}")
        return "\n".join(lines)

    def as_dict(self) -> dict:
        return {"passes": [{"name": p.name, "kind": p.kind, "target": p.target, "resolution": list(p.resolution),
                            "reason": p.reason} for p in self.passes],
                "skipped": [{"what": w, "why": y} for w, y in self.skipped]}


def plan_frame(scene: Scene, settings: RenderSettings) -> FramePlan:
    meshes = scene.mesh_nodes()
    lights = scene.lights()
    plan = FramePlan([])
    if len(lights) > settings.max_lights:
        plan.skipped.append((f"{len(lights) - settings.max_lights} light(s)",
                             f"more than {settings.max_lights} lights; the first {settings.max_lights} are used"))
        lights = lights[: settings.max_lights]
    shadow_lights: list[LightNode] = [l for l in lights if l.cast_shadow]
    for l in lights:
        if not l.cast_shadow:
            plan.skipped.append((f"shadow[{l.name}]", "light does not cast shadows"))
    if not meshes:
        plan.skipped.append(("shadows", "no visible mesh"))
        shadow_lights = []
    for slot, l in enumerate(shadow_lights[:2]):
        plan.passes.append(PlannedPass(
            f"shadow[{l.name}]", "shadow", f"shadow_map{slot}", (settings.shadow_size, settings.shadow_size),
            f"{l.kind} light '{l.name}' casts shadows on {len(meshes)} visible mesh(es)",
            {"light": l, "slot": slot}))
    for l in shadow_lights[2:]:
        plan.skipped.append((f"shadow[{l.name}]", "at most 2 shadow-casting lights"))
    plan.passes.append(PlannedPass("forward", "forward", "hdr_color+depth", settings.size,
                                   f"shade {len(meshes)} visible mesh(es) with {len(lights)} light(s)",
                                   {"lights": lights, "shadow_lights": shadow_lights[:2]}))
    plan.passes.append(PlannedPass("tonemap", "tonemap", "ldr_color", settings.size,
                                   "ACES tone mapping and sRGB encoding for display/PNG"))
    return plan
