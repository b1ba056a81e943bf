"""Screen-space separable SSS (Jimenez et al.): blur the forward pass's subsurface diffuse target
horizontally then vertically with the profile's 1-D kernel (skinlab/scene/optics/ssss.py) and add it back."""

from __future__ import annotations

import math
from dataclasses import dataclass

import moderngl
import numpy as np

from skinlab.gl.uniforms import set_array, set_uniforms
from skinlab.render.passes.screen_targets import ScreenTargets, composite

from .plan import MAX_SSSS_PROFILES, SsssPlan

MAX_SSSS_TAPS = 63  # skinlab/shaders/passes/ssss_blur.frag


@dataclass
class SsssBlurParams:
    ssss: SsssPlan
    gaussians: int = 6  # the Gaussian fit the kernels were sampled from


class SsssBlurPass:
    def __init__(self, renderer):
        self.r = renderer
        self._gpu = ScreenTargets(renderer.ctx, 3)  # tmp, blurred, composite

    def release(self) -> None:
        self._gpu.release()

    def run(self, frame, p) -> None:
        ctx, plan = self.r.ctx, p.params.ssss
        w, h = p.resolution
        tmp, blurred, out = self._gpu.at((w, h))
        ftmp, fblur, fout = self._gpu.fbos
        cam = frame.scene.camera
        # pixels per scene unit at view depth 1: rows span 2 tan(yfov/2), columns the same times aspect
        ppu_y = h / (2.0 * math.tan(cam.yfov / 2.0))
        ppu_x = ppu_y  # square pixels (aspect = w / h)
        prog = self.r.programs.get("passes/fullscreen.vert", "passes/ssss_blur.frag")
        n = len(plan.offsets_mm)
        table = self._gpu.table(plan.table())
        ranges = np.array([k.range_mm for k in plan.kernels], np.float32)
        set_array(prog, "u_range_mm", ranges, MAX_SSSS_PROFILES)
        set_uniforms(
            prog,
            {
                "u_src": 0,
                "u_depth": 1,
                "u_table": 2,
                "u_taps": n,
                "u_mm_per_unit": frame.scene.mm_per_unit,
                "u_near_far": (cam.znear, cam.zfar),
            },
        )
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        frame.targets["depth"].use(1)
        table.use(2)
        for src, fbo, d, ppu in (
            (frame.targets["ssss_diffuse"], ftmp, (1.0 / w, 0.0), ppu_x),
            (tmp, fblur, (0.0, 1.0 / h), ppu_y),
        ):
            fbo.use()
            src.use(0)
            set_uniforms(prog, {"u_dir": d, "u_pixels_per_unit": ppu})
            self.r.fullscreen(prog)
        composite(self.r, frame, fout, out, blurred, "ssss_blurred")
