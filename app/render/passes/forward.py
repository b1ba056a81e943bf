"""Forward shading of every visible mesh into an HDR target with depth."""
from __future__ import annotations

import moderngl
import numpy as np

from app.gl.uniforms import set_array, set_uniform, set_uniforms


class ForwardPass:
    def __init__(self, renderer):
        self.r = renderer
        self._targets = None

    def targets(self, size):
        t = self._targets
        if t is None or t[0].size != tuple(size):
            if t is not None:
                for x in reversed(t):
                    x.release()
            ctx = self.r.ctx
            color = ctx.texture(size, 4, dtype="f4")
            depth = ctx.depth_texture(size)
            t = self._targets = (color, depth, ctx.framebuffer([color], depth))
        return t

    def run(self, frame, p) -> None:
        ctx = self.r.ctx
        color, depth, fbo = self.targets(p.resolution)
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        lights = p.params["lights"]
        slots = {id(l): i for i, l in enumerate(p.params["shadow_lights"])}
        nmax = frame.settings.max_lights
        light_vec = [np.append(-l.direction, 0.0) if l.kind == "directional" else np.append(l.world_position, 1.0)
                     for l in lights]
        per_frame = {
            "u_view_proj": frame.view_proj,
            "u_camera_pos": frame.camera_pos,
            "u_ambient": frame.scene.environment.ambient,
            "u_mm_per_unit": frame.scene.mm_per_unit,
            "u_num_lights": len(lights),
            "u_shadow0": 5,
            "u_shadow1": 6,
        }
        for slot in (0, 1):
            tex = frame.targets.get(f"shadow_map{slot}")
            if tex is None:
                tex = self.r.dummy_shadow_map()
            tex.use(5 + slot)
        shadow_mats = np.stack([frame.shadow_matrices.get(s, np.eye(4)).T for s in (0, 1)]).astype(np.float32)
        for node in frame.scene.mesh_nodes():
            mat = node.material
            defines = {**mat.defines(("texture",)), "MAX_LIGHTS": nmax}
            prog = self.r.programs.get("passes/forward.vert", "passes/forward.frag", defines)
            set_uniforms(prog, per_frame)
            set_array(prog, "u_light_vec", np.array(light_vec).reshape(-1, 4), nmax)
            set_array(prog, "u_light_radiance", np.array([l.radiance for l in lights]).reshape(-1, 3), nmax)
            if "u_light_shadow" in prog:
                ids = np.full(nmax, -1, np.int32)
                ids[: len(lights)] = [slots.get(id(l), -1) for l in lights]
                prog["u_light_shadow"].write(ids.tobytes())
            if "u_shadow_matrix" in prog:
                prog["u_shadow_matrix"].write(shadow_mats.tobytes())
            model = node.world_matrix
            set_uniform(prog, "u_model", model)
            set_uniform(prog, "u_normal_matrix", np.linalg.inv(model[:3, :3]).T)
            set_uniforms(prog, mat.uniforms())
            for unit, (sampler, (path, cs)) in enumerate(mat.textures().items()):
                self.r.resources.texture(path, cs).use(unit)
                set_uniform(prog, sampler, unit)
            self.r.resources.mesh(node.mesh).vao(prog).render(moderngl.TRIANGLES)
        frame.targets["hdr_color"] = color
        frame.targets["depth"] = depth
