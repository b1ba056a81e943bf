"""Forward shading of every visible mesh into an HDR target with depth."""

from __future__ import annotations

import moderngl

from app.gl.uniforms import set_array, set_uniform, set_uniforms
from app.render.gpu_resources import node_uniforms
from app.render.lights import bind_shadow_maps, set_light_uniforms


class ForwardPass:
    def __init__(self, renderer):
        self.r = renderer
        self._targets = None

    def targets(self, size, split: bool = False):
        """(colour, depth, framebuffer, diffuse or None): `split` adds the screen-space SSS target."""
        t = self._targets
        if t is None or t[0].size != tuple(size) or (t[3] is not None) != split:
            if t is not None:
                for x in (t[2], t[1], t[0], t[3]):
                    if x is not None:
                        x.release()
            ctx = self.r.ctx
            color = ctx.texture(size, 4, dtype="f4")
            depth = ctx.depth_texture(size)
            depth.compare_func = ""  # sampled as plain depth (screen-space SSS)
            diffuse = ctx.texture(size, 4, dtype="f4") if split else None
            for x in (color, diffuse):
                if x is not None:
                    x.repeat_x = x.repeat_y = False
            fbo = ctx.framebuffer([color] + ([diffuse] if split else []), depth)
            t = self._targets = (color, depth, fbo, diffuse)
        return t

    def run(self, frame, p) -> None:
        ctx = self.r.ctx
        ssss, tint = p.params.get("ssss"), p.params.get("tint") or {}
        color, depth, fbo, diffuse = self.targets(p.resolution, ssss is not None)
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        lights = p.params["lights"]
        nmax = frame.settings.max_lights
        per_frame = {
            "u_view_proj": frame.view_proj,
            "u_camera_pos": frame.camera_pos,
            "u_ambient": frame.scene.environment.ambient,
        }
        bind_shadow_maps(self.r, frame)
        for node in frame.scene.mesh_nodes():
            tsd = frame.tsd.get(id(node))
            tinted = tint.get(node.uid)
            mat = tsd.material if tsd is not None else tinted[0] if tinted is not None else node.material
            defines = {**mat.defines(("texture",)), "MAX_LIGHTS": nmax}
            if tsd is not None:
                defines["TSD_LEVELS"] = tsd.kernel.levels
            elif tinted is not None:
                defines["SSS_TINT"] = 1
            elif ssss is not None:
                defines["SSSS_SPLIT"] = 1
            prog = self.r.programs.get("passes/forward.vert", "passes/forward.frag", defines)
            set_uniforms(prog, per_frame)
            set_light_uniforms(prog, frame, lights, p.params["shadow_lights"], nmax)
            set_uniforms(prog, node_uniforms(node))
            self.r.resources.bind_material(prog, mat)
            if tsd is not None:
                bind_tsd(prog, tsd)
            if tinted is not None:
                set_uniform(prog, "u_sss_tint", tinted[1])
            if ssss is not None:  # (sss_model overrides change no uniform: the node's own values apply)
                set_uniform(prog, "u_ssss_enabled", float(node.uid in ssss.scattering))
            self.r.resources.mesh(node.mesh).vao(prog).render(moderngl.TRIANGLES)
        frame.targets["hdr_color"] = color
        frame.targets["depth"] = depth
        if diffuse is not None:
            frame.targets["ssss_diffuse"] = diffuse


TSD_UNITS = 7  # irradiance at 7, levels at 8..13 (material maps 0..4, shadow maps 5, 6)


def bind_tsd(prog, tsd) -> None:
    """Textures and weights of the texture-space diffusion gather (forward.frag TSD_LEVELS)."""
    t, k = tsd.targets, tsd.kernel
    t.irradiance.use(TSD_UNITS)
    set_uniform(prog, "u_tsd_irradiance", TSD_UNITS)
    for i in range(k.levels):
        t.levels[i].use(TSD_UNITS + 1 + i)
        set_uniform(prog, f"u_tsd_level{i}", TSD_UNITS + 1 + i)
    set_array(prog, "u_tsd_w", k.weights(), 6)
    set_uniforms(prog, {"u_tsd_identity": k.identity, "u_tsd_mix": tsd.mix})
