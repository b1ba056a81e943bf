"""The forward pass's part of texture-space diffusion: the gather of the irradiance and its blurred
levels (skinlab/shaders/techniques/tsd/forward.glsl) for every mesh whose irradiance pass ran this frame, and
local scattering (skinlab/shaders/techniques/tsd/local.glsl: entry, exit and single scattering without a
blur) for a scattering mesh whose profile is narrower than a texel. Where the irradiance pass recorded light
through thin parts, the mesh is drawn in groups (NodeShading.parts, through_split.py): each group of
triangles with the exit factor of the light through of only the shadow slots whose record it can read
holding light (TSD_THROUGH_READ, a mask; the others add exactly 0 there), the same image."""

from __future__ import annotations

from skinlab.gl.uniforms import set_array, set_uniforms
from skinlab.render.technique import DrawPart, ForwardHook, NodeShading

from .passes import frame_nodes

HOOK = "techniques/tsd/forward.glsl"
LOCAL_HOOK = "techniques/tsd/local.glsl"
# light through thin parts leaves with its own angular distribution (skinlab/shaders/techniques/tsd/forward.glsl)
EXIT_REASON = "light through thin parts leaves with its own angular distribution (per texel record)"


class TsdForward(ForwardHook):
    def __init__(
        self,
        nodes: int,
        local: dict | None = None,
        reason: str = "; gather diffusion for {n}",
        translucency: bool = False,
    ):
        self.local = dict(local or {})  # uid -> effective material, scattered locally
        self.translucency = translucency  # some node's irradiance gathered light through thin parts
        self.reason = reason.format(n=nodes) if nodes else ""
        if nodes and translucency:
            self.reason += f"; {EXIT_REASON}"
        if self.local:
            self.reason += f"; local scattering (profile narrower than a texel) for {len(self.local)}"

    def shading(self, node, frame):
        t = frame_nodes(frame).get(node.uid)
        if t is None:
            mat = self.local.get(node.uid)
            return None if mat is None else NodeShading(mat, LOCAL_HOOK)
        defines = {"TSD_LEVELS": t.kernel.levels}
        parts: tuple[DrawPart, ...] = ()
        if t.translucency and t.through_slots > 0:
            defines["TSD_THROUGH"] = t.through_slots
            if t.targets.through_faces:  # each group of triangles with the slots whose light through it can read
                ibo, groups = t.targets.through_faces
                every = (1 << t.through_slots) - 1
                parts = tuple(
                    DrawPart(ibo, first, count, {} if m == every else {"TSD_THROUGH_READ": m})
                    for m, first, count in groups
                )

        def bind(prog, units):
            bind_gather(prog, t, units)

        return NodeShading(t.material, HOOK, defines, bind, parts=parts)


def bind_gather(prog, t, units) -> None:
    """Textures and weights of the gather (the hook's u_tsd_* uniforms)."""
    targets, k = t.targets, t.kernel
    units.bind(prog, "u_tsd_irradiance", targets.irradiance)
    for i in range(k.levels):
        units.bind(prog, f"u_tsd_level{i}", targets.levels[i])
    if t.translucency and t.through_slots > 0:  # the irradiance pass's record of the light through thin parts
        if not targets.through:
            raise RuntimeError("tsd gather: the irradiance pass wrote no light-through record for this mesh")
        for name, tex in zip(("u_tsd_through0", "u_tsd_through1", "u_tsd_through_cos"), targets.through):
            units.bind(prog, name, tex)
    set_array(prog, "u_tsd_w", k.weights(), 6)
    set_uniforms(prog, {"u_tsd_identity": k.identity, "u_tsd_mix": t.mix})
