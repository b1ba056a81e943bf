"""HDR -> display: exposure, ACES, sRGB (shaders/passes/tonemap.frag; twins in scene/optics/color.py)."""

from __future__ import annotations

import moderngl

from app.gl.uniforms import set_uniforms


class TonemapPass:
    def __init__(self, renderer):
        self.r = renderer
        self._target = None

    def release(self) -> None:
        if self._target is not None:
            self._target[1].release()
            self._target[0].release()
            self._target = None

    def run(self, frame, p) -> None:
        ctx = self.r.ctx
        if self._target is None or self._target[0].size != tuple(p.resolution):
            if self._target is not None:
                self._target[1].release()
                self._target[0].release()
            tex = ctx.texture(p.resolution, 4, dtype="f1")
            self._target = (tex, ctx.framebuffer([tex]))
        tex, fbo = self._target
        prog = self.r.programs.get("passes/fullscreen.vert", "passes/tonemap.frag")
        fbo.use()
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        frame.targets["hdr_color"].use(0)
        set_uniforms(
            prog,
            {"u_hdr": 0, "u_exposure": frame.scene.environment.exposure, "u_background": frame.settings.background},
        )
        self.r.fullscreen(prog)
        frame.targets["ldr_color"] = tex
