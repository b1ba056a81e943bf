"""HDR -> display: exposure, ACES, sRGB (skinlab/shaders/passes/tonemap.frag; twins in skinlab/scene/optics/color.py).

With ``RenderSettings.supersample`` N > 1 the forward HDR holds N x N samples per output pixel: this
pass box-filters them (the mean of linear radiance and coverage) into ``hdr_filtered`` at the output
size, what the ``hdr`` read-back returns, and tone-maps the filtered radiance
(skinlab/shaders/passes/tonemap_supersample.frag; NumPy twin: skinlab/render/supersample.py). With
``TonemapParams.compute`` the same per-pixel code runs as a compute shader (passes/tonemap.comp)."""

from __future__ import annotations

from typing import cast

import moderngl
import numpy as np

from skinlab.gl.uniforms import set_uniform, set_uniforms
from skinlab.render.compute import bind_images, dispatch
from skinlab.render.technique import RenderPass


class TonemapPass(RenderPass):
    def __init__(self, renderer):
        super().__init__(renderer)
        self._target = None  # (ldr, framebuffer, filtered hdr or None)

    def release(self) -> None:
        if self._target is not None:
            for x in self._target:
                if x is not None:
                    x.release()
            self._target = None

    def targets(self, size, filtered: bool):
        t = self._target
        if t is None or t[0].size != tuple(size) or (t[2] is not None) != filtered:
            self.release()
            ctx = self.r.ctx
            tex = ctx.texture(size, 4, dtype="f1")
            hdr = ctx.texture(size, 4, dtype="f4") if filtered else None
            self._target = (tex, ctx.framebuffer([tex] if hdr is None else [tex, hdr]), hdr)
        return self._target

    def run(self, frame, p) -> None:
        n = frame.settings.supersample
        tex, fbo, hdr = self.targets(p.resolution, n > 1)
        env = frame.data.get("environment")
        drawn = {"BACKGROUND_DRAWN": 1} if env is not None and env["background"] is not None else {}
        defines = {**({"SUPERSAMPLE": n} if n > 1 else {}), **drawn}
        compute = p.params is not None and p.params.compute
        prog: moderngl.Program | moderngl.ComputeShader
        if compute:
            prog = self.r.programs.compute("passes/tonemap.comp", defines)
        elif n > 1:
            prog = self.r.programs.get("passes/fullscreen.vert", "passes/tonemap_supersample.frag", defines)
        else:
            prog = self.r.programs.get("passes/fullscreen.vert", "passes/tonemap.frag", defines or None)
        frame.targets["hdr_color"].use(0)
        set_uniforms(
            prog,
            {"u_hdr": 0, "u_exposure": frame.scene.environment.exposure, "u_background": frame.settings.background},
        )
        if compute:
            set_uniform(prog, "u_size", np.asarray(p.resolution, np.int32).tobytes())
            cs = cast(moderngl.ComputeShader, prog)
            bind_images(cs, {"u_ldr": tex, **({"u_filtered": hdr} if hdr is not None else {})})
            dispatch(cs, p.resolution)
        else:
            fbo.use()
            self.r.fullscreen(cast(moderngl.Program, prog))
        frame.targets["ldr_color"] = tex
        if hdr is not None:
            frame.targets["hdr_filtered"] = hdr
