"""Interreflection: the light the scene's surfaces throw onto each other, for every technique.

Planned by the core (skinlab/render/plan.py) when ``RenderSettings.bounces`` > 0 and some ray from some
vertex meets the front of a surface (a convex mesh alone has nothing to gather: the pass is skipped
and the plan says so). Each order is one pass, ``bounce[N]``, in three draws on small vertex-space
targets (vertex i of the frame's meshes at texel (i % 1024, i / 1024)):

1. radiant exitance per vertex (skinlab/shaders/passes/bounce_exitance.frag, drawn fullscreen over the
   target once per mesh, its vertices read from a texture of them): sender albedo x (the lights with
   their shadow maps + the sky + the previous order's bounce);
2. gather: each vertex's irradiance from what its rays met, with the ray records of
   skinlab/scene/interreflection.py (computed once per geometry on the CPU, cached) collapsed into each
   vertex's distinct senders and their summed weights (``BounceTransfer.sender_*``: on the head about a
   tenth of the 3 x 64 corner fetches a vertex had, the rays that met nothing left out);
3. the one-ring average of those estimates.
Both are sparse row sums over the vertex-space target (skinlab/shaders/passes/bounce_rows.frag).

The last order's target holds all orders' light (each order's senders carry the previous ones). The
passes that shade ambient light read it per vertex (lib/bounce_vertex.glsl in forward.vert and
techniques/tsd/uv.vert, lib/ambient.glsl in the fragment shaders: variant ``BOUNCE``) and treat it like the
sky's light: it enters the medium (texture-space diffusion blurs it) and is reflected. The passes
only depend on geometry, lights and materials, so an orbiting camera reuses them. How, what it changes
against the truth and what it costs: docs/interreflection.md; sources: docs/references.md#interreflection.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from skinlab.cache import in_background
from skinlab.gl.uniforms import set_uniform, set_uniforms
from skinlab.scene.interreflection import MAX_RAYS, MIN_RAYS, BounceTransfer, build_transfer

from .environment import bind_environment, environment_defines, environment_state
from .frame_plan import PlannedPass, shadow_pass_name
from .gpu_resources import node_uniforms
from .lights import bind_shadow_maps, light_defines, set_light_uniforms
from .reuse import light_state, material_state
from .technique import RenderPass
from .texture_units import TextureUnits
from .through_kernel import bind_through, through_defines
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
    from skinlab.scene.mesh import Mesh

    from .frame import Frame
    from .frame_plan import FramePlan
    from .settings import RenderSettings

DATA_KEY = "bounce"  # frame.data: {"offsets": node uid -> first vertex}
# the ray budget per frame's geometry (skinlab/scene/interreflection.py: MAX_RAYS, MIN_RAYS)


@dataclass
class BounceParams:
    transfer: BounceTransfer
    order: int  # 1: light that bounced once
    lights: list[LightNode]
    shadow_lights: list[LightNode]
    nodes: list[MeshNode]


def bounce_pass_name(order: int) -> str:
    return f"bounce[{order}]"


def bounce_rays(
    scene: Scene, settings: RenderSettings, meshes: list[MeshNode], lights: list[LightNode]
) -> tuple[int | None, str]:
    """(rays per vertex the frame's interreflection casts, or None when it casts none; why not)."""
    if settings.bounces == 0:
        return None, "interreflection off (bounces = 0)"
    if not meshes:
        return None, ""
    if not lights and not np.any(np.asarray(scene.environment.ambient) > 0) and scene.environment.map is None:
        return None, "no light to bounce (no lights, no ambient, no environment map)"
    vertices = sum(len(n.mesh.positions) for n in meshes)
    return min(settings.bounce_rays, MAX_RAYS // max(vertices, 1)), ""


def prefetch_bounce(scene: Scene, settings: RenderSettings, meshes: list[MeshNode], lights: list[LightNode]) -> None:
    """Start casting the frame's interreflection rays on a worker thread (skinlab/cache.py
    in_background), so that they are cast while the technique plans; plan_bounce then waits for
    them. Nothing when the records are cached or the frame casts none."""
    rays, _ = bounce_rays(scene, settings, meshes, lights)
    if rays is not None and rays >= MIN_RAYS:
        in_background(build_transfer, list(meshes), rays)


def plan_bounce(
    scene: Scene,
    settings: RenderSettings,
    meshes: list[MeshNode],
    lights: list[LightNode],
    shadow_lights: list[LightNode],
    plan: FramePlan,
) -> list[PlannedPass]:
    """The interreflection passes this frame needs (none when off, or nothing sees anything)."""
    rays, why = bounce_rays(scene, settings, meshes, lights)
    if why:
        plan.skipped.append(("bounce", why))
    if rays is None:
        return []
    vertices = sum(len(n.mesh.positions) for n in meshes)
    if rays < MIN_RAYS:
        plan.warnings.append(
            f"interreflection skipped: {vertices} vertices need more than {MAX_RAYS:,} rays even at {MIN_RAYS} "
            "per vertex (decimate the mesh, or render with bounces = 0 to silence this)"
        )
        plan.skipped.append(("bounce", f"{vertices} vertices: over the ray budget ({MAX_RAYS:,} rays)"))
        return []
    if rays < settings.bounce_rays:
        plan.warnings.append(
            f"interreflection: {rays} rays per vertex instead of {settings.bounce_rays} for {vertices} vertices "
            f"(the ray budget is {MAX_RAYS:,} rays: casting time and the records' memory grow with it)"
        )
    transfer = build_transfer(meshes, rays)
    if not transfer.any_hit:
        plan.skipped.append(("bounce", "no surface sees another: every ray from every vertex leaves the scene"))
        return []
    seen = sum(transfer.hit_fraction[n.uid] * transfer.counts[n.uid] for n in meshes) / transfer.total_vertices
    inputs = (
        transfer.key,
        tuple(light_state(l) for l in lights),
        tuple(material_state(n.material) for n in meshes),
        environment_state(scene),
        scene.mm_per_unit,
    )
    shadows = tuple(shadow_pass_name(l) for l in shadow_lights)
    out = []
    for order in range(1, settings.bounces + 1):
        previous = (bounce_pass_name(order - 1),) if order > 1 else ()
        out.append(
            PlannedPass(
                bounce_pass_name(order),
                "bounce",
                "bounce_irradiance",
                vertex_target_size(transfer.total_vertices),
                f"interreflection, order {order} of {settings.bounces}: {transfer.total_vertices} vertices x "
                f"{transfer.rays} rays, {100 * seen:.1f} % of them meet a surface",
                BounceParams(transfer, order, lights, shadow_lights, list(meshes)),
                inputs=(*inputs, order),
                after=(*shadows, *previous),
            )
        )
    return out


def uv_footprint(mesh: Mesh) -> float:
    """The side of one vertex's share of the mesh's UV area (UV units; 0 without UVs)."""
    if mesh.uvs is None:
        return 0.0
    uv = mesh.uvs.astype(np.float64)[mesh.indices.astype(np.int64)]
    a, b = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    area = 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum()
    return math.sqrt(area / len(mesh.positions))


class BouncePass(RenderPass):
    """Runs each planned ``bounce[N]`` (module docstring)."""

    def __init__(self, renderer):
        super().__init__(renderer)
        self.targets: dict[int, tuple[moderngl.Texture, moderngl.Framebuffer]] = {}  # order -> irradiance
        self.exitance: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None
        self.gathered: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None  # before the one-ring average
        # (transfer key, sender index, sender entries, ring index, ring entries)
        self.records: tuple | None = None
        # (mesh uid, version) -> its vertices as a texture (bounce_exitance.frag u_vertex_data)
        self._vertex_data: dict[tuple[int, int], moderngl.Texture] = {}
        self._footprints: dict[tuple[int, int], float] = {}  # (mesh uid, version) -> uv_footprint

    # -- GPU objects ---------------------------------------------------------------------
    def _target(self, size, order: int | str):
        """The vertex-space target of an order (int), or the scratch "exitance" / "gathered" one."""
        held = self.targets.get(order) if isinstance(order, int) else getattr(self, order)
        held = float_target(self.r.ctx, size, held)
        if isinstance(order, int):
            self.targets[order] = held
        else:
            setattr(self, order, held)
        return held

    def _records(self, transfer: BounceTransfer):
        """The transfer's ray records and one-rings on the GPU (uploaded once per transfer)."""
        if self.records is None or self.records[0] != transfer.key:
            self._release_records()
            rows = []
            for offsets, vertices, weights in (
                (transfer.sender_offsets, transfer.sender_vertices, transfer.sender_weights),
                (transfer.ring_offsets, transfer.ring_vertices, transfer.ring_weights),
            ):
                index = np.stack([offsets[:-1], np.diff(offsets)], 1)
                rows.append(upload_rows(self.r.ctx, index, VERTEX_TEXTURE_WIDTH))
                rows.append(upload_rows(self.r.ctx, np.stack([vertices, weights], 1), RECORD_TEXTURE_WIDTH))
            self.records = (transfer.key, *rows)
        return self.records[1:]

    def _vertices(self, mesh) -> moderngl.Texture:
        """The mesh's positions, normals and UVs as a texture, vertex j at texels (3 (j % 1024) + k, j / 1024),
        k = 0, 1, 2 (uploaded once per mesh version)."""
        key = (mesh.uid, mesh.version)
        held = self._vertex_data.get(key)
        if held is None:
            tex = vertex_data_texture(self.r.ctx, mesh)
            for old_key in [k for k in self._vertex_data if k[0] == mesh.uid]:
                self._vertex_data.pop(old_key).release()
            held = self._vertex_data[key] = tex
        return held

    def _release_records(self) -> None:
        if self.records is not None:
            for tex in self.records[1:]:
                tex.release()
            self.records = None

    def release(self) -> None:
        for tex, fbo in [*self.targets.values(), *(x for x in (self.exitance, self.gathered) if x is not None)]:
            fbo.release()
            tex.release()
        self.targets.clear()
        self.exitance = self.gathered = None
        self._release_records()
        for tex in self._vertex_data.values():
            tex.release()
        self._vertex_data.clear()

    # -- the pass ------------------------------------------------------------------------
    def outputs(self, frame, p) -> tuple:
        return (self._target(p.resolution, p.params.order)[0],)

    def publish(self, frame: Frame, p) -> None:
        prm: BounceParams = p.params
        frame.targets["bounce_irradiance"] = self._target(p.resolution, prm.order)[0]
        frame.data[DATA_KEY] = {"offsets": dict(prm.transfer.offsets), "order": prm.order}

    def run(self, frame: Frame, p) -> None:
        ctx = self.r.ctx
        prm: BounceParams = p.params
        tr = prm.transfer
        exitance, efbo = self._target(p.resolution, "exitance")
        efbo.use()
        efbo.clear(0.0, 0.0, 0.0, 0.0)
        previous = self.targets.get(prm.order - 1) if prm.order > 1 else None
        nmax = frame.settings.max_lights
        for node in prm.nodes:
            mat = node.material
            defines = {
                **mat.defines(),
                **light_defines(prm.shadow_lights, nmax),
                **environment_defines(frame, node),
            }
            prog = self.r.programs.get("passes/fullscreen.vert", "passes/bounce_exitance.frag", defines)
            units = TextureUnits(ctx)
            bind_shadow_maps(self.r, frame, prog, units)
            set_light_uniforms(prog, frame, prm.lights, prm.shadow_lights, nmax)
            # the maps read trilinearly at the vertex's level: llvmpipe's anisotropic filter takes its
            # ellipse from the derivatives even at an explicit level, and neighbouring texels here are
            # unrelated vertices
            self.r.resources.bind_material(prog, mat, units, isotropic=True)
            bind_environment(frame, node, prog, units)
            lod = 0.0
            maps = mat.textures()
            if "u_base_color_map" in maps:
                tex = self.r.resources.texture(*maps["u_base_color_map"])
                key = (node.mesh.uid, node.mesh.version)
                if key not in self._footprints:
                    self._footprints[key] = uv_footprint(node.mesh)
                lod = max(0.0, math.log2(max(max(tex.size) * self._footprints[key], 1e-30)))
            units.bind(prog, "u_bounce_previous", previous[0] if previous is not None else self.r.dummy_texture())
            units.bind(prog, "u_vertex_data", self._vertices(node.mesh))
            set_uniforms(
                prog,
                {
                    **node_uniforms(node),
                    "u_vertex_offset": tr.offsets[node.uid],
                    "u_vertex_count": tr.counts[node.uid],
                    "u_target_size": np.asarray(p.resolution, np.int32).tobytes(),
                    "u_ambient": frame.scene.environment.ambient,
                    "u_albedo_lod": lod,
                    "u_has_previous": int(previous is not None),
                },
            )
            self.r.fullscreen(prog)
            self.r.resources.unbind_samplers()
        sender_index, sender_entries, ring_index, ring_entries = self._records(tr)
        gathered = self._target(p.resolution, "gathered")
        self._rows(gathered[1], exitance, sender_index, sender_entries, tr.total_vertices)  # the gather
        self._rows(self._target(p.resolution, prm.order)[1], gathered[0], ring_index, ring_entries, tr.total_vertices)
        self.publish(frame, p)

    def _rows(self, fbo, source, index, entries, vertices: int) -> None:
        """One sparse row sum (skinlab/shaders/passes/bounce_rows.frag) of the per-vertex `source` into
        `fbo` (a vertex-space target): the gather or the one-ring average."""
        fbo.use()
        prog = self.r.programs.get("passes/fullscreen.vert", "passes/bounce_rows.frag")
        units = TextureUnits(self.r.ctx)
        for sampler, tex in (("u_source", source), ("u_row_index", index), ("u_row_entries", entries)):
            units.bind(prog, sampler, tex)
        set_uniforms(prog, {"u_vertices": vertices})
        self.r.fullscreen(prog)


# -- the receiving side: every pass that shades ambient light -----------------------------
def bounce_defines(frame: Frame, node: MeshNode) -> dict:
    """``BOUNCE`` when this frame has interreflection light for `node` (lib/bounce_vertex.glsl,
    lib/ambient.glsl); ``THROUGH_KERNEL`` when it has light through thin parts from the transfer
    through the medium, carried per vertex beside it (skinlab/render/through_kernel.py,
    lib/through_vertex.glsl)."""
    data = frame.data.get(DATA_KEY)
    scene = {"BOUNCE": 1} if data is not None and node.uid in data["offsets"] else {}
    return {**scene, **through_defines(frame, node)}


def bind_bounce(frame: Frame, node: MeshNode, prog, units: TextureUnits) -> None:
    """The per-vertex bounce light for a program compiled with :func:`bounce_defines`."""
    bind_through(frame, node, prog, units)
    data = frame.data.get(DATA_KEY)
    if data is None or node.uid not in data["offsets"]:
        return
    units.bind(prog, "u_bounce", frame.targets["bounce_irradiance"])
    set_uniform(prog, "u_bounce_offset", data["offsets"][node.uid])
