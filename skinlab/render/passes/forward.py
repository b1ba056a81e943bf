"""Forward shading of every visible mesh into an HDR target with depth. The subsurface part of the
diffuse term is the technique's hook (ForwardParams.hook; skinlab/render/technique.py): per mesh it
names the material, the hook's GLSL file and variant, and binds the hook's uniforms and textures.

The entry/exit factors and single scattering every technique shares (skinlab/render/boundary.py) are
bound here for a mesh the hook shades as scattering, zeros for the others.

With ``RenderSettings.depth_prepass`` the meshes are first drawn depth-only (forward.vert with an
empty fragment shader), then shaded with the depth test ``<=`` and no depth writes: each pixel is
shaded once, however many surfaces lie behind it (the same image; where two surfaces have exactly
the same depth, the one drawn last shows instead of the one drawn first)."""

from __future__ import annotations

from contextlib import ExitStack

import moderngl
import numpy as np

from skinlab.gl.state import gl_state
from skinlab.gl.uniforms import set_uniforms
from skinlab.render.alpha import bind_mask, blended, draw_order, mask_defines
from skinlab.render.ambient import ambient_defines, bind_ambient
from skinlab.render.boundary import bind_boundary, boundary_defines
from skinlab.render.environment import DATA_KEY as ENV_DATA
from skinlab.render.environment import bind_env_bands, env_uniforms
from skinlab.render.gpu_resources import node_uniforms
from skinlab.render.lights import area_defines, bind_shadow_maps, light_defines, near_defines, set_light_uniforms
from skinlab.render.technique import HOOK_INCLUDE, PLAIN_HOOK, ForwardParams, NodeShading, RenderPass
from skinlab.render.texture_units import TextureUnits
from skinlab.render.translucency import bind_translucency

SINGLE_THROUGH = "SSS_SINGLE_THROUGH"  # passes/forward.frag's variant (lib/sss_single_through.glsl)


def single_through_defines(frame, scatters: bool) -> dict:
    """SSS_SINGLE_THROUGH for a mesh that scatters in a frame with a distance map (a technique's
    translucency) and RenderSettings.single_through on: single scattering along the light's path inside."""
    has_map = any(f"shadow_exit{slot}" in frame.targets for slot in (0, 1))  # its part layers too
    return {SINGLE_THROUGH: 1} if scatters and frame.settings.single_through and has_map else {}


class ForwardPass(RenderPass):
    def __init__(self, renderer):
        super().__init__(renderer)
        # (colour, depth, framebuffer, extra colour targets)
        self._targets: tuple[moderngl.Texture, moderngl.Texture, moderngl.Framebuffer, list[moderngl.Texture]] | None
        self._targets = None
        self._depth_fbo: moderngl.Framebuffer | None = None  # the depth target alone, for the depth pre-pass
        # (colour target, framebuffer of it and the depth): the environment behind
        self._bg_fbo: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None

    def targets(self, size, outputs: tuple[str, ...] = ()):
        """(colour, depth, framebuffer, extra colour targets): one more float target per name in
        `outputs` (a technique's, e.g. screen-space SSS's subsurface diffuse)."""
        t = self._targets
        if t is None or t[0].size != tuple(size) or len(t[3]) != len(outputs):
            if t is not None:
                t[2].release()
                for tex in (t[1], t[0], *t[3]):
                    tex.release()
            ctx = self.r.ctx
            color = ctx.texture(size, 4, dtype="f4")
            depth = ctx.depth_texture(size)
            depth.compare_func = ""  # sampled as plain depth (screen-space SSS)
            extra = [ctx.texture(size, 4, dtype="f4") for _ in outputs]
            for x in (color, *extra):
                x.repeat_x = x.repeat_y = False
            fbo = ctx.framebuffer([color, *extra], depth)
            t = self._targets = (color, depth, fbo, extra)
            if self._depth_fbo is not None:
                self._depth_fbo.release()
            self._depth_fbo = ctx.framebuffer(depth_attachment=depth)
        return t

    def release(self) -> None:
        if self._targets is not None:
            color, depth, fbo, extra = self._targets
            if self._depth_fbo is not None:
                self._depth_fbo.release()
            fbo.release()
            for tex in (color, depth, *extra):
                tex.release()
            self._targets = self._depth_fbo = None
        if self._bg_fbo is not None:
            self._bg_fbo[1].release()
            self._bg_fbo = None

    def run(self, frame, p) -> None:
        ctx = self.r.ctx
        prm: ForwardParams = p.params
        hook = prm.hook
        color, depth, fbo, extra = self.targets(p.resolution, hook.outputs)
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        per_frame = {
            "u_view_proj": frame.view_proj,
            "u_camera_pos": frame.camera_pos,
            "u_ambient": frame.scene.environment.ambient,
        }
        prepass = frame.settings.depth_prepass
        with gl_state(ctx, moderngl.DEPTH_TEST):
            if prepass:
                self.depth_prepass(frame, per_frame)
                fbo.use()
            # after the pre-pass: each visible pixel shaded once, where its depth equals the pre-pass's
            with gl_state(ctx, depth_func="<=" if prepass else "<"):
                fbo.depth_mask = not prepass
                try:
                    self.shade(frame, prm, per_frame)
                finally:
                    fbo.depth_mask = True
            self.background(frame, color, depth, per_frame)
        frame.targets["hdr_color"] = color
        frame.targets["depth"] = depth
        for name, tex in zip(hook.outputs, extra):
            frame.targets[name] = tex

    def background(self, frame, color, depth, per_frame) -> None:
        """The environment map where no mesh was drawn (``[environment] show_background``): the colour
        target alone (a technique's extra targets keep their clear value), depth test '<=', no writes."""
        data = frame.data.get(ENV_DATA)
        if data is None or data["background"] is None:
            return
        ctx = self.r.ctx
        if self._bg_fbo is None or self._bg_fbo[0] is not color:
            if self._bg_fbo is not None:
                self._bg_fbo[1].release()
            self._bg_fbo = (color, ctx.framebuffer([color], depth))
        fbo = self._bg_fbo[1]
        fbo.use()
        fbo.depth_mask = False
        try:
            prog = self.r.programs.get("passes/background.vert", "passes/background.frag")
            units = TextureUnits(ctx)
            set_uniforms(
                prog, {**env_uniforms(frame.scene, data["prepared"]), "u_camera_pos": per_frame["u_camera_pos"]}
            )
            set_uniforms(prog, {"u_inv_view_proj": np.linalg.inv(per_frame["u_view_proj"])})
            units.bind(prog, "u_env_background", data["background"])
            with gl_state(ctx, depth_func="<="):
                self.r.fullscreen(prog)
        finally:
            fbo.depth_mask = True

    def depth_prepass(self, frame, per_frame) -> None:
        assert self._depth_fbo is not None  # made with the targets
        self._depth_fbo.use()
        for node in frame.scene.mesh_nodes():
            if blended(node.material):
                continue  # seen through: it hides nothing behind it
            # a masked material's cut-away pixels write no depth (skinlab/render/alpha.py)
            prog = self.r.programs.get("passes/forward.vert", "passes/depth_only.frag", mask_defines(node.material))
            set_uniforms(prog, {"u_view_proj": per_frame["u_view_proj"]})
            set_uniforms(prog, node_uniforms(node))
            bind_mask(self.r.resources, prog, node.material, TextureUnits(self.r.ctx))
            self.r.resources.mesh(node.mesh).vao(prog).render(moderngl.TRIANGLES)

    def shade(self, frame, prm: ForwardParams, per_frame) -> None:
        """Every visible mesh: the opaque and masked ones first, then those with alpha_mode "blend" far
        to near, premultiplied over what is behind them without writing depth (skinlab/render/alpha.py)."""
        ctx = self.r.ctx
        assert self._targets is not None  # made by run
        fbo = self._targets[2]
        depth_mask = fbo.depth_mask
        blending = False
        with ExitStack() as scope:
            for node in draw_order(frame.scene.mesh_nodes(), frame.camera_pos):
                if blended(node.material) and not blending:  # premultiplied over what is behind
                    scope.enter_context(
                        gl_state(ctx, enable=moderngl.BLEND, blend_func=(moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA))
                    )
                    scope.callback(setattr, fbo, "depth_mask", depth_mask)
                    fbo.depth_mask, blending = False, True
                self.shade_node(frame, prm, per_frame, node)

    def shade_node(self, frame, prm: ForwardParams, per_frame, node) -> None:
        hook, nmax = prm.hook, frame.settings.max_lights
        sh = hook.shading(node, frame) or NodeShading(node.material)
        scatters = sh.hook != PLAIN_HOOK and sh.subsurface
        defines = {
            **sh.material.defines(),
            **light_defines(prm.shadow_lights, nmax, frame),
            **area_defines(prm.lights),
            **near_defines(prm.lights),
            **boundary_defines(sh.material if scatters else None),
            **ambient_defines(frame, node),
            **single_through_defines(frame, scatters),
            **sh.defines,
        }
        # the hook's parts of the triangles, each with its own variant (an opaque mesh's), or all at once
        parts = [q for q in sh.parts if q.count > 0] if sh.parts and not blended(node.material) else [None]
        for part in parts:
            variant = defines if part is None else {**defines, **part.defines}
            self.draw_node(frame, prm, per_frame, node, sh, variant, part)

    def draw_node(self, frame, prm: ForwardParams, per_frame, node, sh: NodeShading, defines, part) -> None:
        """Bind and draw `node`'s triangles (those of DrawPart `part`, or all: None) with variant `defines`."""
        ctx, nmax = self.r.ctx, frame.settings.max_lights
        scatters = sh.hook != PLAIN_HOOK and sh.subsurface
        prog = self.r.programs.get(
            "passes/forward.vert", "passes/forward.frag", defines, includes={HOOK_INCLUDE: sh.hook}
        )
        units = TextureUnits(ctx)
        set_uniforms(prog, per_frame)
        bind_shadow_maps(self.r, frame, prog, units)
        set_light_uniforms(prog, frame, prm.lights, prm.shadow_lights, nmax)
        set_uniforms(prog, node_uniforms(node))
        bind_ambient(frame, node, prog, units)
        self.r.resources.bind_material(prog, sh.material, units)
        bind_boundary(prog, sh.material if scatters else None)
        bind_env_bands(prog, sh.material if scatters else None)
        if sh.bind is not None:
            sh.bind(prog, units)
        if SINGLE_THROUGH in defines:  # the distance maps (the hook of a technique with translucency binds them too)
            bind_translucency(prog, frame, units)
        mesh = self.r.resources.mesh(node.mesh)
        if part is None:
            mesh.vao(prog).render(moderngl.TRIANGLES)
        else:
            mesh.vao(prog, part.indices).render(moderngl.TRIANGLES, part.count, part.first)
