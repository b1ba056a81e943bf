"""The disk pass: importance-sampled Burley disk SSS over the forward pass's subsurface diffuse
target (skinlab/shaders/techniques/disk/gather.frag, the per-pixel code in techniques/disk/gather.glsl), then the
composite with the rest of the lit image; with ``DiskParams.compute`` both in one compute dispatch
(techniques/disk/gather.comp)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import moderngl
import numpy as np

from skinlab.gl.uniforms import set_array, set_uniform, set_uniforms
from skinlab.render.compute import bind_images, dispatch, pass_program
from skinlab.render.passes.screen_targets import ScreenTargets, composite, publish_composite
from skinlab.render.profile_table import MAX_PROFILES
from skinlab.render.technique import RenderPass

DIFFUSE_TARGET = "disk_diffuse"


@dataclass
class DiskParams:
    samples: int
    rotate: bool
    kernels: list  # skinlab.scene.optics.disk.DiskKernel per profile index
    compute: bool = False  # the compute shader (techniques/disk/gather.comp), else the fragment shader

    def table(self) -> np.ndarray:
        """(profiles, samples, 4) float32: rgb weight, a radius mm (the shader's u_table)."""
        t = np.zeros((len(self.kernels), self.samples, 4), np.float32)
        for j, k in enumerate(self.kernels):
            t[j, :, :3] = k.weights
            t[j, :, 3] = k.radii_mm
        return t


class DiskPass(RenderPass):
    def __init__(self, renderer):
        super().__init__(renderer)
        self._gpu = ScreenTargets(renderer.ctx, 2)  # filtered, composite

    def release(self) -> None:
        self._gpu.release()

    def run(self, frame, p) -> None:
        prm = p.params
        w, h = p.resolution
        filtered, out = self._gpu.at((w, h))
        ffilt, fout = self._gpu.fbos
        cam = frame.scene.camera
        table = self._gpu.table(prm.table())
        prog = pass_program(self.r.programs, "techniques/disk/gather", prm.compute)
        reach = np.array([k.reach_mm for k in prm.kernels], np.float32)
        set_array(prog, "u_reach_mm", reach, MAX_PROFILES)
        set_uniforms(
            prog,
            {
                "u_src": 0,
                "u_depth": 1,
                "u_table": 2,
                "u_samples": prm.samples,
                "u_mm_per_unit": frame.scene.mm_per_unit,
                "u_pixels_per_unit": h / (2.0 * math.tan(cam.yfov / 2.0)),
                "u_size": (float(w), float(h)),
                "u_near_far": (cam.znear, cam.zfar),
                "u_rotate": 1.0 if prm.rotate else 0.0,
            },
        )
        frame.targets[DIFFUSE_TARGET].use(0)
        frame.targets["depth"].use(1)
        table.use(2)
        if isinstance(prog, moderngl.ComputeShader):  # the gather and the composite in one dispatch
            frame.targets["hdr_color"].use(3)
            set_uniform(prog, "u_color", 3)
            bind_images(prog, {"u_dst": filtered, "u_composite": out})
            dispatch(prog, (w, h))
            publish_composite(frame, out, filtered, "disk_filtered")
            return
        ffilt.use()
        self.r.fullscreen(prog)
        composite(self.r, frame, fout, out, filtered, "disk_filtered")
