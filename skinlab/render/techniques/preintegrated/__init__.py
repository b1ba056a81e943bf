"""Technique "preintegrated": pre-integrated skin shading (Penner & Borshukov, GPU Pro 2, 2011). Each
scattering material's profile is integrated around rings of curvature 1/r into a lookup table over
N.L x curvature (skinlab/scene/optics/preintegrated.py, built in NumPy, cached per medium, uploaded as a
texture); the forward hook looks it up per light with the mesh's per-vertex curvature and a
softened normal. No pass of its own: the cheapest technique that moves light past the terminator.
With `translucency` the hook adds the light through thin parts per light (skinlab/render/translucency.py,
as texture-space diffusion's irradiance pass does)."""

from __future__ import annotations

from dataclasses import dataclass, field

import moderngl
import numpy as np

from skinlab.declare import option
from skinlab.gl.uniforms import set_uniforms
from skinlab.render.options import TechniqueSettings
from skinlab.render.scattering import scattering_material
from skinlab.render.technique import (
    ForwardHook,
    LedgerStyle,
    PlanContext,
    Technique,
    TechniquePlan,
    TechniqueState,
)
from skinlab.render.translucency import OPTION_DOC, REASON, plan_translucency, translucent_shading
from skinlab.render.vertex_streams import VertexStream
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.preintegrated import LUT_CURV, LUT_NOL, preintegrated_lut, vertex_curvature
from skinlab.scene.optics.profile_fit import profile_fit

HOOK = "techniques/preintegrated/forward.glsl"


def mesh_curvature(mesh) -> np.ndarray:
    """(n, 1) per-vertex mean curvature, 1/scene unit (the hook's in_curvature)."""
    return vertex_curvature(mesh.positions, mesh.normals, mesh.indices)[:, None]


# the hook looks the table up with it (forward.vert's in_curvature -> v_curvature)
CURVATURE = VertexStream("in_curvature", "1f", mesh_curvature)


@dataclass(frozen=True)
class PreintegratedSettings(TechniqueSettings):
    technique = "preintegrated"
    softening: float = option(
        1.0,
        "how far the widest channel's normal goes from the normal map to the geometric normal "
        "(narrower channels in proportion to their profile width); 0 = the normal map for all",
        "float",
        range=(0, 1),
    )
    translucency: bool = option(True, OPTION_DOC, "bool")


class LutTextures(TechniqueState):
    """The lookup tables as textures, one per (model, medium), kept across frames (at most 32)."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.textures: dict = {}

    def get(self, key, lut) -> moderngl.Texture:
        tex = self.textures.get(key)
        if tex is None:
            if len(self.textures) >= 32:
                self.release()
            data = np.ascontiguousarray(lut.table.astype(np.float32))  # (rows = curvature, columns = N.L, 3)
            tex = self.ctx.texture((LUT_NOL, LUT_CURV), 3, data.tobytes(), dtype="f4")
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            tex.repeat_x = tex.repeat_y = False
            self.textures[key] = tex
        return tex

    def release(self) -> None:
        for t in self.textures.values():
            t.release()
        self.textures.clear()


def channel_softening(model, medium, softening: float) -> np.ndarray:
    """(3,) per channel: softening x the channel's profile width (rms of its Gaussian fit) over the
    widest channel's."""
    fit = profile_fit(model, medium, 6)
    w = np.asarray(fit.weights).reshape(-1, 3)
    sig = np.sqrt(np.maximum((w * np.asarray(fit.variances_mm2)[:, None]).sum(axis=0), 0.0)) if len(w) else np.zeros(3)
    return softening * (sig / sig.max() if sig.max() > 0 else np.zeros(3))


@dataclass
class PreintegratedForward(ForwardHook):
    nodes: dict = field(default_factory=dict)  # node uid -> (material, key, lut, soften)
    state: LutTextures | None = None
    translucency: bool = False  # add the light through thin parts (shadow distance maps) per light

    def __post_init__(self) -> None:
        if self.nodes:
            self.reason = (
                "; pre-integrated skin lookup (N.L x curvature)"
                + (f" and {REASON}" if self.translucency else "")
                + (f" for {len(self.nodes)}")
            )

    def shading(self, node, frame):
        hit = self.nodes.get(node.uid)
        if hit is None:
            return None
        mat, key, lut, soften = hit
        scale = abs(float(np.linalg.det(node.world_matrix[:3, :3]))) ** (1.0 / 3.0)
        curv_scale = 1.0 / (frame.scene.mm_per_unit * max(scale, 1e-12))
        state, through = self.state, self.translucency

        def bind(prog, units):
            tex = state.get(key, lut) if state is not None else None
            if tex is not None:
                units.bind(prog, "u_pis_lut", tex)
            set_uniforms(
                prog,
                {
                    "u_pis_lut_size": (float(LUT_NOL), float(LUT_CURV)),
                    "u_pis_curv_scale": curv_scale,
                    "u_pis_curv_max": lut.curv_max,
                    "u_pis_soften": tuple(float(x) for x in soften),
                },
            )

        return translucent_shading(mat, HOOK, frame, through, bind)


class PreintegratedTechnique(Technique[PreintegratedSettings]):
    name = "preintegrated"
    description = "pre-integrated skin (Penner & Borshukov 2011): a N.L x curvature lookup, no extra pass"
    settings_type = PreintegratedSettings
    state = ("preintegrated_luts", LutTextures)
    ledger = LedgerStyle("v", "tab:brown")
    vertex_streams = (CURVATURE,)

    def plan(self, ctx: PlanContext) -> TechniquePlan:
        nodes = {}
        for n in ctx.meshes:
            mat = scattering_material(n, ctx.settings, ctx.plan, f"preintegrated[{n.name}]")
            if mat is None:
                continue
            key = (mat["sss_model"], material_medium(mat.values))
            lut = preintegrated_lut(*key)
            nodes[n.uid] = (mat, key, lut, channel_softening(*key, ctx.options.softening))
        through = plan_translucency(ctx, bool(nodes), ctx.options.translucency)
        return TechniquePlan(PreintegratedForward(nodes, ctx.state, through), shadow_distance=through)


TECHNIQUE = PreintegratedTechnique()
