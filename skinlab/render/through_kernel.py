"""Light through thin parts as a transfer through the medium, for every technique (the GPU side of
skinlab/scene/optics/through_kernel.py, which has the model and its NumPy reference).

Planned by the core when ``RenderSettings.through_kernel`` is on and the technique computes light
through thin parts (its translucency: a scattering material, a shadow-casting light). One pass,
``through``, in two draws on vertex-space targets (vertex i of the frame's scattering meshes at texel
(i % 1024, i / 1024), as the interreflection's, skinlab/render/bounce.py):

1. the irradiance entering each vertex (skinlab/shaders/passes/through_entering.frag): the lights with
   their shadows, and where a shadow-casting light is hidden, what reaches the vertex through the
   matter in front of it (the distance maps' slab, lib/sss_translucency.glsl: a part behind another);
2. the transfer: each vertex's light through, a sparse row sum over the vertices its rays into the
   medium met with per-channel weights (skinlab/shaders/passes/through_rows.frag).

The passes that shade light read it per vertex as bounce light (lib/bounce_vertex.glsl, variant
THROUGH_KERNEL, which also takes the distance-map translucency out of lib/sss_translucency.glsl and
texture-space diffusion's irradiance pass): it enters the medium like the light from the scene's
surfaces and texture-space diffusion blurs it. It depends on geometry, lights and materials only, so
an orbiting camera keeps it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from skinlab.gl.uniforms import set_uniform, set_uniforms
from skinlab.scene.interreflection import MAX_RAYS, MIN_RAYS

from .boundary import bind_boundary
from .frame_plan import PlannedPass, shadow_pass_name
from .gpu_resources import node_uniforms
from .lights import bind_shadow_maps, light_defines, set_light_uniforms
from .reuse import light_state, material_state
from .technique import RenderPass
from .texture_units import TextureUnits
from .translucency import bind_translucency
from .vertex_space import (
    RECORD_TEXTURE_WIDTH,
    VERTEX_TEXTURE_WIDTH,
    float_target,
    upload_rows,
    vertex_data_texture,
    vertex_target_size,
)

if TYPE_CHECKING:
    from skinlab.scene.graph import LightNode, MeshNode, Scene
    from skinlab.scene.materials import Material
    from skinlab.scene.optics.through_kernel import ThroughRows

    from .frame import Frame
    from .frame_plan import FramePlan
    from .settings import RenderSettings

DATA_KEY = "through_kernel"  # frame.data: {"offsets": node uid -> first vertex}
PASS_NAME = "through"


@dataclass
class ThroughParams:
    nodes: list[MeshNode]
    rows: dict[int, ThroughRows]  # node uid -> its transfer
    materials: dict[int, Material]  # node uid -> the material it scatters with (the frame's)
    offsets: dict[int, int]  # node uid -> first vertex in the targets
    total: int
    lights: list[LightNode]
    shadow_lights: list[LightNode]
    key: str  # what the rows were computed from (for the GPU copy)


def plan_through(
    scene: Scene,
    settings: RenderSettings,
    meshes: list[MeshNode],
    lights: list[LightNode],
    shadow_lights: list[LightNode],
    plan: FramePlan,
    translucency: bool,
) -> list[PlannedPass]:
    """The ``through`` pass when the technique's translucency is planned and the setting is on."""
    if not translucency:
        return []
    if not settings.through_kernel:
        plan.skipped.append(("through", "the transfer through the medium is off (through_kernel = false)"))
        return []
    from skinlab.scene.optics.through_kernel import fine_enough, medium_rows

    from .scattering import effective_material

    chosen: list[tuple[MeshNode, Material]] = []
    for node in meshes:
        mat = effective_material(node, settings)
        if not mat.has_subsurface:
            continue
        fine, why = fine_enough(node, mat, scene.mm_per_unit)
        if not fine:
            plan.skipped.append((f"through[{node.name}]", f"the distance map's slab instead: {why}"))
            continue
        chosen.append((node, mat))
    if not chosen:
        return []
    vertices = sum(len(n.mesh.positions) for n, _ in chosen)
    rays = min(settings.through_rays, MAX_RAYS // max(vertices, 1))  # the interreflection's ray budget
    if rays < MIN_RAYS:
        plan.warnings.append(
            f"light through thin parts from the distance map's slab: {vertices} vertices need more than "
            f"{MAX_RAYS:,} rays into the medium even at {MIN_RAYS} per vertex (decimate the mesh)"
        )
        return []
    if rays < settings.through_rays:
        plan.warnings.append(
            f"light through thin parts: {rays} rays into the medium per vertex instead of {settings.through_rays} "
            f"for {vertices} vertices (the ray budget is {MAX_RAYS:,} rays)"
        )
    nodes, rows, offsets, materials, total = [], {}, {}, {}, 0
    for node, mat in chosen:
        nodes.append(node)
        materials[node.uid] = mat
        rows[node.uid] = medium_rows(node, mat, scene.mm_per_unit, rays)
        offsets[node.uid] = total
        total += len(node.mesh.positions)
    from skinlab.scene.optics.through_kernel import records_key

    key = "|".join(records_key(n, rays, 0) + str(material_state(materials[n.uid])) for n in nodes)
    entries = sum(len(r.senders) for r in rows.values())
    return [
        PlannedPass(
            PASS_NAME,
            "through",
            "through_irradiance",
            vertex_target_size(total),
            f"light through thin parts: {total} vertices x {rays} rays into the medium ({entries} senders in all)",
            ThroughParams(nodes, rows, materials, offsets, total, list(lights), list(shadow_lights), key),
            inputs=(
                key,
                tuple(light_state(l) for l in lights),
                tuple(material_state(materials[n.uid]) for n in nodes),
                scene.mm_per_unit,
            ),
            after=tuple(shadow_pass_name(l) for l in shadow_lights),
        )
    ]


class ThroughPass(RenderPass):
    """Runs the planned ``through`` pass (module docstring)."""

    def __init__(self, renderer):
        super().__init__(renderer)
        self.entering: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None
        # the transfer's outputs: the light through (rgb, its depth in a), its mean incidence (r), and
        # the framebuffer that writes both
        self.target: moderngl.Texture | None = None
        self.cosine: moderngl.Texture | None = None
        self.rows_fbo: moderngl.Framebuffer | None = None
        self.rows: tuple[str, moderngl.Texture, moderngl.Texture] | None = None
        self._vertex_data: dict[tuple[int, int], moderngl.Texture] = {}

    def _rows(self, prm: ThroughParams):
        """Per vertex (first entry, entries) and per entry (sender, weight r, g, b), all nodes."""
        if self.rows is None or self.rows[0] != prm.key:
            self._release_rows()
            index, entries, first = [], [], 0
            for node in prm.nodes:
                r = prm.rows[node.uid]
                start = r.offsets[:-1][r.welded] + first
                count = np.diff(r.offsets)[r.welded]
                index.append(np.stack([start, count, r.depth_mm[r.welded]], 1))
                entries.append(np.concatenate([(r.senders + prm.offsets[node.uid])[:, None], r.weights], 1))
                first += len(r.senders)
            idx = upload_rows(self.r.ctx, np.concatenate(index).astype(np.float64), VERTEX_TEXTURE_WIDTH)
            ent = upload_rows(self.r.ctx, np.concatenate(entries), RECORD_TEXTURE_WIDTH)
            self.rows = (prm.key, idx, ent)
        return self.rows[1], self.rows[2]

    def _vertices(self, mesh) -> moderngl.Texture:
        """The mesh's vertex texture (skinlab/render/vertex_space.py), once per mesh version."""
        key = (mesh.uid, mesh.version)
        held = self._vertex_data.get(key)
        if held is None:
            for old in [k for k in self._vertex_data if k[0] == mesh.uid]:
                self._vertex_data.pop(old).release()
            held = self._vertex_data[key] = vertex_data_texture(self.r.ctx, mesh)
        return held

    def _release_outputs(self) -> None:
        for obj in (self.rows_fbo, self.target, self.cosine):
            if obj is not None:
                obj.release()
        self.rows_fbo = self.target = self.cosine = None

    def _outputs(self, size) -> tuple[moderngl.Texture, moderngl.Texture, moderngl.Framebuffer]:
        """The transfer's two outputs of `size` and their framebuffer (made once per size)."""
        if self.target is None or self.cosine is None or self.rows_fbo is None or self.target.size != tuple(size):
            self._release_outputs()
            self.target, self.cosine = (self.r.ctx.texture(size, 4, dtype="f4") for _ in range(2))
            for tex in (self.target, self.cosine):
                tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.rows_fbo = self.r.ctx.framebuffer([self.target, self.cosine])
        return self.target, self.cosine, self.rows_fbo

    def _release_rows(self) -> None:
        if self.rows is not None:
            self.rows[1].release()
            self.rows[2].release()
            self.rows = None

    def release(self) -> None:
        if self.entering is not None:
            self.entering[1].release()
            self.entering[0].release()
        self.entering = None
        self._release_outputs()
        self._release_rows()
        for tex in self._vertex_data.values():
            tex.release()
        self._vertex_data.clear()

    def outputs(self, frame, p) -> tuple:
        target, cosine, _ = self._outputs(p.resolution)
        return (target, cosine)

    def publish(self, frame: Frame, p) -> None:
        target, cosine, _ = self._outputs(p.resolution)
        frame.targets["through_irradiance"] = target
        frame.targets["through_cosine"] = cosine
        frame.data[DATA_KEY] = {"offsets": dict(p.params.offsets)}

    def run(self, frame: Frame, p) -> None:
        ctx = self.r.ctx
        prm: ThroughParams = p.params
        self.entering = float_target(ctx, p.resolution, self.entering)
        entering, efbo = self.entering
        efbo.use()
        efbo.clear(0.0, 0.0, 0.0, 0.0)
        nmax = frame.settings.max_lights
        index, entries = self._rows(prm)
        for node in prm.nodes:
            defines = {**light_defines(prm.shadow_lights, nmax)}
            prog = self.r.programs.get("passes/fullscreen.vert", "passes/through_entering.frag", defines)
            units = TextureUnits(ctx)
            bind_shadow_maps(self.r, frame, prog, units)
            set_light_uniforms(prog, frame, prm.lights, prm.shadow_lights, nmax)
            bind_translucency(prog, frame, units, self.r.dummy_texture())
            units.bind(prog, "u_vertex_data", self._vertices(node.mesh))
            units.bind(prog, "u_row_index", index)
            set_uniforms(
                prog,
                {
                    **node_uniforms(node),
                    "u_vertex_offset": prm.offsets[node.uid],
                    "u_vertex_count": len(node.mesh.positions),
                    "u_target_size": np.asarray(p.resolution, np.int32).tobytes(),
                    "u_mm_per_unit": float(frame.scene.mm_per_unit),
                },
            )
            self.r.resources.bind_material(prog, prm.materials[node.uid], units, isotropic=True)
            bind_boundary(prog, prm.materials[node.uid])
            self.r.fullscreen(prog)
            self.r.resources.unbind_samplers()
        tfbo = self._outputs(p.resolution)[2]
        tfbo.use()
        prog = self.r.programs.get("passes/fullscreen.vert", "passes/through_rows.frag")
        units = TextureUnits(ctx)
        for sampler, tex in (("u_source", entering), ("u_row_index", index), ("u_row_entries", entries)):
            units.bind(prog, sampler, tex)
        set_uniforms(prog, {"u_vertices": prm.total})
        self.r.fullscreen(prog)
        self.publish(frame, p)


# -- the receiving side (lib/bounce_vertex.glsl), through skinlab/render/bounce.py's bounce_defines --
def through_defines(frame: Frame, node: MeshNode) -> dict:
    """``THROUGH_KERNEL`` when this frame has the transfer for `node` (lib/through_vertex.glsl)."""
    data = frame.data.get(DATA_KEY)
    return {"THROUGH_KERNEL": 1} if data is not None and node.uid in data["offsets"] else {}


def bind_through(frame: Frame, node: MeshNode, prog, units: TextureUnits) -> None:
    data = frame.data.get(DATA_KEY)
    if data is None or node.uid not in data["offsets"]:
        return
    units.bind(prog, "u_through", frame.targets["through_irradiance"])
    units.bind(prog, "u_through_cos", frame.targets["through_cosine"])
    set_uniform(prog, "u_through_offset", data["offsets"][node.uid])
