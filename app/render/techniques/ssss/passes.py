"""Screen-space separable SSS (Jimenez et al.): blur the forward pass's subsurface diffuse target
horizontally then vertically with the profile's 1-D kernel (scene/optics/ssss.py) and add it back."""

from __future__ import annotations

import math
from dataclasses import dataclass

import moderngl
import numpy as np

from app.gl.uniforms import set_array, set_uniforms

from .plan import SsssPlan

MAX_SSSS_TAPS = 63  # shaders/passes/ssss_blur.frag


@dataclass
class SsssBlurParams:
    ssss: SsssPlan


class SsssBlurPass:
    def __init__(self, renderer):
        self.r = renderer
        self._targets = None

    def targets(self, size):
        t = self._targets
        if t is None or t[0].size != tuple(size):
            self.release()
            ctx = self.r.ctx
            texs = [ctx.texture(size, 4, dtype="f4") for _ in range(3)]  # tmp, blurred, composite
            for x in texs:
                x.repeat_x = x.repeat_y = False
            self._fbos = [ctx.framebuffer([x]) for x in texs]
            t = self._targets = tuple(texs)
        return t

    def release(self) -> None:
        if self._targets is not None:
            for x in (*self._fbos, *self._targets):
                x.release()
            self._targets, self._fbos = None, []

    def run(self, frame, p) -> None:
        ctx, plan = self.r.ctx, p.params.ssss
        w, h = p.resolution
        tmp, blurred, out = self.targets((w, h))
        ftmp, fblur, fout = self._fbos
        cam = frame.scene.camera
        # pixels per scene unit at view depth 1: rows span 2 tan(yfov/2), columns the same times aspect
        ppu_y = h / (2.0 * math.tan(cam.yfov / 2.0))
        ppu_x = ppu_y  # square pixels (aspect = w / h)
        prog = self.r.programs.get("passes/fullscreen.vert", "passes/ssss_blur.frag")
        n = len(plan.offsets_mm)
        set_array(prog, "u_offset_mm", plan.offsets_mm.astype(np.float32), MAX_SSSS_TAPS)
        set_array(prog, "u_weight", plan.weights.astype(np.float32), MAX_SSSS_TAPS)
        set_uniforms(
            prog,
            {
                "u_src": 0,
                "u_depth": 1,
                "u_taps": n,
                "u_range_mm": plan.range_mm,
                "u_mm_per_unit": frame.scene.mm_per_unit,
                "u_near_far": (cam.znear, cam.zfar),
            },
        )
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        frame.targets["depth"].use(1)
        for src, fbo, d, ppu in (
            (frame.targets["ssss_diffuse"], ftmp, (1.0 / w, 0.0), ppu_x),
            (tmp, fblur, (0.0, 1.0 / h), ppu_y),
        ):
            fbo.use()
            src.use(0)
            set_uniforms(prog, {"u_dir": d, "u_pixels_per_unit": ppu})
            self.r.fullscreen(prog)
        comp = self.r.programs.get("passes/fullscreen.vert", "passes/ssss_composite.frag")
        fout.use()
        frame.targets["hdr_color"].use(0)
        blurred.use(1)
        set_uniforms(comp, {"u_color": 0, "u_blurred": 1})
        self.r.fullscreen(comp)
        frame.targets["ssss_blurred"] = blurred
        frame.targets["hdr_color_unblurred"] = frame.targets["hdr_color"]
        frame.targets["hdr_color"] = out
