"""The frame plan's data: planned passes with their reasons and typed parameters, what was skipped
and why, warnings. Planning itself is skinlab/render/plan.py."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from skinlab.scene.graph import LightNode

    from .shadow_fit import ShadowWindow
    from .vertex_streams import VertexStream


@dataclass
class PlannedPass:
    name: str
    kind: str  # the pass class that runs it: shadow | forward | tonemap, or a technique's (registry)
    target: str
    resolution: tuple[int, int]
    reason: str
    params: Any = None  # the kind's typed parameters (ShadowParams, ForwardParams, a technique's own)
    # What the pass's output depends on besides the passes named in `after` (skinlab/render/reuse.py): a
    # hashable value built from the scene's geometry versions and transforms, lights, materials,
    # settings and scale. None: the pass runs every frame (it depends on the camera).
    inputs: Any = None
    after: tuple[str, ...] = ()  # names of this plan's passes whose results it reads
    # a kept pass of a technique that reads ambient light (bounce, environment map): the core adds the
    # passes making that light to its `after`; False for one that depends on geometry alone (a
    # stretch map), so that turning an environment map does not re-run it
    reads_light: bool = True
    reused_since: int | None = None  # set by the renderer: not run, its result is frame N's


def shadow_pass_name(light: LightNode) -> str:
    """The name of the pass that renders `light`'s shadow map (a pass reading it names it in ``after``)."""
    return f"shadow[{light.name}]"


def shadow_fit_pass_name(light: LightNode) -> str:
    """The name of the pass that renders `light`'s map fitted to the view (skinlab/render/shadow_fit.py)."""
    return f"shadow_fit[{light.name}]"


@dataclass
class ShadowParams:
    light: LightNode
    slot: int  # shadow map slot 0 or 1
    distance: bool  # also a light-space distance map of the first surface (translucency, soft shadows)
    layers: bool = False  # and the part layers, the first part's exit and the next entry (translucency)
    fine: ShadowWindow | None = None  # a second map fitted to what the camera sees (shadow_fit.py)


@dataclass
class TonemapParams:
    compute: bool = False  # the compute shader (skinlab/render/compute.py), else the fragment shader


@dataclass
class FramePlan:
    passes: list[PlannedPass]
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (what, why not)
    warnings: list[str] = field(default_factory=list)
    # hints a user should see beside the result (the render summary prints them): what a setting costs
    # the image and what would change it; not problems
    notes: list[str] = field(default_factory=list)
    # the extra vertex streams the frame's technique shades with (Technique.vertex_streams)
    vertex_streams: tuple[VertexStream, ...] = ()

    def names(self) -> list[str]:
        return [p.name for p in self.passes]

    def ran(self) -> list[str]:
        """The passes the renderer ran (not reused from an earlier frame)."""
        return [p.name for p in self.passes if p.reused_since is None]

    def reused(self) -> list[str]:
        return [p.name for p in self.passes if p.reused_since is not None]

    def explain(self, warnings: bool = True) -> str:
        """The plan as text; ``warnings=False`` leaves out the warnings (for a caller that prints them)."""
        lines = ["frame plan:"]
        for i, p in enumerate(self.passes, 1):
            why = p.reason if p.reused_since is None else f"reused: inputs unchanged since frame {p.reused_since}"
            lines.append(f"  {i}. {p.name:<18} -> {p.target} {p.resolution[0]}x{p.resolution[1]}: {why}")
        for what, why in self.skipped:
            lines.append(f"  -  {what:<18} skipped: {why}")
        for n in self.notes:
            lines.append(f"  *  note: {n}")
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
                    "reused_since": p.reused_since,
                }
                for p in self.passes
            ],
            "skipped": [{"what": w, "why": y} for w, y in self.skipped],
            "warnings": list(self.warnings),
            "notes": list(self.notes),
        }
