"""The exact technique's pass: brute-force convolution of the dilated irradiance with the exact
radial profile (skinlab/shaders/techniques/exact/gather.frag; the per-texel code techniques/exact/gather.glsl,
run by techniques/exact/gather.comp with ``TsdExactParams.compute``) into level 0, which the
texture-space gather then reads with weight 1 (plan.UNIT_KERNEL)."""

from __future__ import annotations

import moderngl
import numpy as np

from skinlab.gl.uniforms import set_uniforms
from skinlab.render.compute import pass_program
from skinlab.render.techniques.tsd.passes import TsdPass, store
from skinlab.render.techniques.tsd.plan import TsdExactParams
from skinlab.scene.optics.exact_profile import exact_profile_lut
from skinlab.scene.optics.material_medium import material_medium

EXACT_INNER_HALF = 24  # brute force: texels summed one by one within 24 texels of the centre...
EXACT_RING_RATIO = 1.15  # ...then annuli r -> 1.15 r out to r_max, cells read from the mip pyramid


class TsdExactPass(TsdPass):
    """Brute-force convolution with the exact profile into level 0."""

    def __init__(self, renderer):
        super().__init__(renderer)
        self._luts: dict = {}

    def output(self, t, p):
        return t.level(self.r.ctx, 0)

    def publish(self, frame, p) -> None:
        frame.targets[f"tsd_exact[{p.params.node.name}]"] = self.output(self.node_targets(p), p)

    def lut(self, model, medium):
        key = (model, medium)
        hit = self._luts.get(key)
        if hit is None:
            r_max, R, E = exact_profile_lut(model, medium)
            data = np.zeros((2, len(R), 4), np.float32)
            data[0, :, :3], data[1, :, :3] = R, E
            tex = self.r.ctx.texture((len(R), 2), 4, data.tobytes(), dtype="f4")
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            tex.repeat_x = tex.repeat_y = False
            if len(self._luts) > 32:
                for t, _ in self._luts.values():
                    t.release()
                self._luts.clear()
            hit = self._luts[key] = (tex, r_max)
        return hit

    def release(self) -> None:
        for t, _ in self._luts.values():
            t.release()
        self._luts.clear()

    def run(self, frame, p) -> None:
        prm: TsdExactParams = p.params
        ctx, node, size = self.r.ctx, prm.node, prm.size
        t = store(self.r).targets(node, size)
        lut, r_max = self.lut(prm.model, material_medium(prm.material.values))
        dst = t.level(ctx, 0)
        prog = pass_program(self.r.programs, "techniques/exact/gather", prm.compute)
        set_uniforms(
            prog,
            {
                "u_src": 0,
                "u_stretch": 1,
                "u_lut": 2,
                "u_rmax_mm": r_max,
                "u_inner_half": EXACT_INNER_HALF,
                "u_ring_ratio": EXACT_RING_RATIO,
            },
        )
        t.irradiance.build_mipmaps()  # box-filtered far field (textureLod); the gather keeps
        t.irradiance.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)  # sampling level 0
        t.irradiance.use(0)
        t.stretch.use(1)
        lut.use(2)
        t.draw_into(self.r, prog, dst)
        t.irradiance.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.publish(frame, p)
