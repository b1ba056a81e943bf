"""The frame plan's data: planned passes with their reasons and typed parameters, what was skipped
and why, warnings. Planning itself is app/render/plan.py."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from scene.graph import LightNode

    from .technique import ForwardHook


@dataclass
class PlannedPass:
    name: str
    kind: str  # the pass class that runs it: shadow | forward | tonemap, or a technique's (registry)
    target: str
    resolution: tuple[int, int]
    reason: str
    params: Any = None  # the kind's typed parameters (ShadowParams, ForwardParams, a technique's own)


@dataclass
class ShadowParams:
    light: LightNode
    slot: int  # shadow map slot 0 or 1
    distance: bool  # also a light-space distance map (a technique's translucency)


@dataclass
class ForwardParams:
    lights: list[LightNode]
    shadow_lights: list[LightNode]
    hook: ForwardHook  # the technique's shading of each mesh


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
