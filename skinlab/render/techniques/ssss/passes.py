"""Screen-space separable SSS (Jimenez et al.): blur the forward pass's subsurface diffuse target
horizontally then vertically with the profile's 1-D kernel (skinlab/scene/optics/ssss.py) and add it back.
The per-pixel code is techniques/ssss/blur.glsl, run by techniques/ssss/blur.frag or, with
``SsssBlurParams.compute``, by techniques/ssss/blur.comp (the vertical pass writing the composite too)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import moderngl
import numpy as np

from skinlab.gl.uniforms import set_array, set_uniforms
from skinlab.render.compute import bind_images, dispatch, pass_program
from skinlab.render.passes.screen_targets import ScreenTargets, composite, publish_composite
from skinlab.render.profile_table import MAX_PROFILES
from skinlab.render.technique import RenderPass

from .plan import SsssPlan

MAX_SSSS_TAPS = 63  # skinlab/shaders/techniques/ssss/blur.glsl


@dataclass
class SsssBlurParams:
    ssss: SsssPlan
    gaussians: int = 6  # the Gaussian fit the kernels were sampled from
    compute: bool = False  # the compute shader (techniques/ssss/blur.comp), else the fragment shader


class SsssBlurPass(RenderPass):
    def __init__(self, renderer):
        super().__init__(renderer)
        self._gpu = ScreenTargets(renderer.ctx, 3)  # tmp, blurred, composite

    def release(self) -> None:
        self._gpu.release()

    def run(self, frame, p) -> None:
        plan = p.params.ssss
        w, h = p.resolution
        tmp, blurred, out = self._gpu.at((w, h))
        ftmp, fblur, fout = self._gpu.fbos
        cam = frame.scene.camera
        # pixels per scene unit at view depth 1: rows span 2 tan(yfov/2), columns the same times aspect
        ppu_y = h / (2.0 * math.tan(cam.yfov / 2.0))
        ppu_x = ppu_y  # square pixels (aspect = w / h)
        prog = pass_program(self.r.programs, "techniques/ssss/blur", p.params.compute)
        n = plan.taps
        table = self._gpu.table(plan.table())
        ranges = np.array([k.range_mm for k in plan.kernels], np.float32)
        set_array(prog, "u_range_mm", ranges, MAX_PROFILES)
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
        frame.targets["depth"].use(1)
        table.use(2)
        steps = (
            (frame.targets["ssss_diffuse"], tmp, ftmp, (1.0 / w, 0.0), ppu_x),
            (tmp, blurred, fblur, (0.0, 1.0 / h), ppu_y),
        )
        if isinstance(prog, moderngl.ComputeShader):  # horizontal, then vertical with the composite
            horizontal = steps[0]
            horizontal[0].use(0)
            set_uniforms(prog, {"u_dir": horizontal[3], "u_pixels_per_unit": horizontal[4]})
            bind_images(prog, {"u_dst": tmp})
            dispatch(prog, (w, h))
            vertical = self.r.programs.compute("techniques/ssss/blur.comp", {"SSSS_COMPOSITE": 1})
            set_array(vertical, "u_range_mm", ranges, MAX_PROFILES)
            tmp.use(0)
            frame.targets["hdr_color"].use(3)
            set_uniforms(
                vertical,
                {
                    "u_src": 0,
                    "u_depth": 1,
                    "u_table": 2,
                    "u_color": 3,
                    "u_taps": n,
                    "u_mm_per_unit": frame.scene.mm_per_unit,
                    "u_near_far": (cam.znear, cam.zfar),
                    "u_dir": steps[1][3],
                    "u_pixels_per_unit": steps[1][4],
                },
            )
            bind_images(vertical, {"u_dst": blurred, "u_composite": out})
            dispatch(vertical, (w, h))
            publish_composite(frame, out, blurred, "ssss_blurred")
            return
        for src, _, fbo, d, ppu in steps:
            fbo.use()
            src.use(0)
            set_uniforms(prog, {"u_dir": d, "u_pixels_per_unit": ppu})
            self.r.fullscreen(prog)
        composite(self.r, frame, fout, out, blurred, "ssss_blurred")
