"""The forward pass's part of texture-space diffusion: the gather of the irradiance and its blurred
levels (shaders/techniques/tsd/forward.glsl) for every mesh whose irradiance pass ran this frame."""

from __future__ import annotations

from app.gl.uniforms import set_array, set_uniforms
from app.render.technique import ForwardHook, NodeShading

from .passes import frame_nodes

HOOK = "techniques/tsd/forward.glsl"


class TsdForward(ForwardHook):
    def __init__(self, nodes: int, reason: str = "; gather diffusion for {n}"):
        self.reason = reason.format(n=nodes) if nodes else ""

    def shading(self, node, frame):
        t = frame_nodes(frame).get(node.uid)
        if t is None:
            return None
        return NodeShading(
            t.material, HOOK, {"TSD_LEVELS": t.kernel.levels}, lambda prog, units: bind_gather(prog, t, units)
        )


def bind_gather(prog, t, units) -> None:
    """Textures and weights of the gather (the hook's u_tsd_* uniforms)."""
    targets, k = t.targets, t.kernel
    units.bind(prog, "u_tsd_irradiance", targets.irradiance)
    for i in range(k.levels):
        units.bind(prog, f"u_tsd_level{i}", targets.levels[i])
    set_array(prog, "u_tsd_w", k.weights(), 6)
    set_uniforms(prog, {"u_tsd_identity": k.identity, "u_tsd_mix": t.mix})
