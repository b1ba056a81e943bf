"""Texture-space diffusion passes (d'Eon & Luebke 2007, GPU Gems 3 ch. 14), per subsurface mesh:

  tsd_stretch     world mm per texel along u and v (only when the geometry or scene scale changes)
  tsd_irradiance  light entering the surface, rasterised at the UVs, x albedo^mix
  tsd_dilate      irradiance pushed past chart borders (a few one-texel rings)
  tsd_blur        one Gaussian level of the chain: separable u then v, taps in mm via the stretch map

The kernel (variances, weights, taps) comes from scene/optics/tsd.py, which also holds the NumPy
twin of the blur and gather. The gather is the forward pass's TSD_LEVELS variant.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import moderngl
import numpy as np

from app.gl.uniforms import set_array, set_uniform, set_uniforms
from app.render.gpu_resources import node_uniforms
from app.render.lights import bind_shadow_maps, set_light_uniforms
from scene.optics.tsd import MAX_TSD_LEVELS, BlurStep, DiffusionKernel, blur_taps, exact_profile_lut, material_medium

MAX_TAPS = 31  # shaders/passes/tsd_blur.frag


def _texture(ctx, size: int) -> moderngl.Texture:
    t = ctx.texture((size, size), 4, dtype="f4")
    t.filter = (moderngl.LINEAR, moderngl.LINEAR)
    t.repeat_x = t.repeat_y = False
    return t


@dataclass
class TsdNodeTargets:
    """The GPU textures of one subsurface mesh node (float32 RGBA, premultiplied by coverage)."""

    size: int
    irradiance: moderngl.Texture
    scratch: moderngl.Texture
    stretch: moderngl.Texture
    levels: list = field(default_factory=list)
    fbos: dict = field(default_factory=dict)
    stretch_key: tuple | None = None

    def fbo(self, ctx, tex: moderngl.Texture) -> moderngl.Framebuffer:
        f = self.fbos.get(id(tex))
        if f is None:
            f = self.fbos[id(tex)] = ctx.framebuffer([tex])
        return f

    def level(self, ctx, k: int) -> moderngl.Texture:
        while len(self.levels) <= k:
            self.levels.append(_texture(ctx, self.size))
        return self.levels[k]

    def release(self) -> None:
        for f in self.fbos.values():
            f.release()
        for t in [self.irradiance, self.scratch, self.stretch, *self.levels]:
            t.release()


@dataclass
class TsdFrameNode:
    """What the gather needs for one node this frame."""

    targets: TsdNodeTargets
    kernel: DiffusionKernel
    material: object
    mix: float


def stretch_key(node, scene, size: int) -> tuple:
    """Everything the stretch map depends on: the mesh (identity, version), its world transform,
    the scene scale and the texture size."""
    return (node.mesh.uid, node.mesh.version, node.world_matrix.round(9).tobytes(), float(scene.mm_per_unit), size)


class TsdStore:
    """Per-node TSD textures, kept across frames (stretch maps are reused while geometry is unchanged)."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.nodes: dict[int, TsdNodeTargets] = {}
        self.stretch_updates = 0

    def targets(self, node, size: int) -> TsdNodeTargets:
        t = self.nodes.get(node.uid)
        if t is None or t.size != size:
            if t is not None:
                t.release()
            c = self.ctx
            t = self.nodes[node.uid] = TsdNodeTargets(size, _texture(c, size), _texture(c, size), _texture(c, size))
        return t

    def retain(self, uids) -> int:
        """Release the textures of nodes not in `uids` (removed nodes, a reloaded scene); returns
        how many were released."""
        gone = [u for u in self.nodes if u not in uids]
        for u in gone:
            self.nodes.pop(u).release()
        return len(gone)

    def stretch_valid(self, node, scene, size: int) -> bool:
        t = self.nodes.get(node.uid)
        return t is not None and t.size == size and t.stretch_key == stretch_key(node, scene, size)

    def release(self) -> None:
        for t in self.nodes.values():
            t.release()
        self.nodes.clear()


def _uv_raster_setup(ctx, fbo, size: int) -> None:
    fbo.use()
    ctx.viewport = (0, 0, size, size)
    ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE | moderngl.BLEND)


def _dilate(renderer, t: TsdNodeTargets, tex: moderngl.Texture, rings: int) -> None:
    """`rings` one-texel dilation steps of `tex`, ping-ponging with the scratch texture (even count
    ends in `tex`)."""
    ctx = renderer.ctx
    prog = renderer.programs.get("passes/fullscreen.vert", "passes/tsd_dilate.frag")
    src, dst = tex, t.scratch
    for _ in range(rings + (rings % 2)):
        t.fbo(ctx, dst).use()
        ctx.viewport = (0, 0, t.size, t.size)
        src.use(0)
        set_uniform(prog, "u_src", 0)
        renderer.fullscreen(prog)
        src, dst = dst, src


class TsdStretchPass:
    def __init__(self, renderer):
        self.r = renderer

    def run(self, frame, p) -> None:
        ctx, node, size = self.r.ctx, p.params["node"], p.params["size"]
        t = self.r.tsd.targets(node, size)
        fbo = t.fbo(ctx, t.stretch)
        _uv_raster_setup(ctx, fbo, size)
        fbo.clear(0.0, 0.0, 0.0, 0.0)
        prog = self.r.programs.get("passes/tsd_uv.vert", "passes/tsd_stretch.frag")
        set_uniforms(prog, {**node_uniforms(node), "u_mm_per_unit": frame.scene.mm_per_unit})
        self.r.resources.mesh(node.mesh).vao(prog).render(moderngl.TRIANGLES)
        _dilate(self.r, t, t.stretch, p.params["dilate"])
        t.stretch_key = stretch_key(node, frame.scene, size)
        self.r.tsd.stretch_updates += 1


class TsdIrradiancePass:
    def __init__(self, renderer):
        self.r = renderer

    def run(self, frame, p) -> None:
        ctx, node, size = self.r.ctx, p.params["node"], p.params["size"]
        mat, kernel = p.params["material"], p.params["kernel"]
        t = self.r.tsd.targets(node, size)
        fbo = t.fbo(ctx, t.irradiance)
        _uv_raster_setup(ctx, fbo, size)
        fbo.clear(0.0, 0.0, 0.0, 0.0)
        lights, shadow_lights = p.params["lights"], p.params["shadow_lights"]
        translucency = p.params.get("translucency", False)
        nmax = frame.settings.max_lights
        defines = {**mat.defines(("texture",)), "MAX_LIGHTS": nmax}
        if translucency:
            defines["TSD_TRANSLUCENCY"] = 1
        prog = self.r.programs.get("passes/tsd_uv.vert", "passes/tsd_irradiance.frag", defines)
        bind_shadow_maps(self.r, frame)
        set_light_uniforms(prog, frame, lights, shadow_lights, nmax)
        set_uniforms(
            prog, {**node_uniforms(node), "u_ambient": frame.scene.environment.ambient, "u_tsd_mix": p.params["mix"]}
        )
        self.r.resources.bind_material(prog, mat)
        if translucency:
            for slot in (0, 1):
                d = frame.targets.get(f"shadow_distance{slot}")
                if d is not None:
                    d.use(7 + slot)
                set_uniform(prog, f"u_distance{slot}", 7 + slot)
            eyes = np.stack([frame.shadow_eyes.get(s, np.zeros(4)) for s in (0, 1)])
            set_array(prog, "u_light_eye", eyes, 2)
            set_array(prog, "u_tsd_var", np.array([s.variance_mm2 for s in kernel.steps]), MAX_TSD_LEVELS)
            set_array(prog, "u_tsd_w", kernel.weights(), MAX_TSD_LEVELS)
            set_uniform(prog, "u_tsd_levels", kernel.levels)
        self.r.resources.mesh(node.mesh).vao(prog).render(moderngl.TRIANGLES)
        frame.tsd[id(node)] = TsdFrameNode(t, kernel, mat, p.params["mix"])
        frame.targets[f"tsd_irradiance_raw[{node.name}]"] = t.irradiance


class TsdDilatePass:
    def __init__(self, renderer):
        self.r = renderer

    def run(self, frame, p) -> None:
        node = p.params["node"]
        t = self.r.tsd.targets(node, p.params["size"])
        _dilate(self.r, t, t.irradiance, p.params["dilate"])
        frame.targets.pop(f"tsd_irradiance_raw[{node.name}]", None)
        frame.targets[f"tsd_irradiance[{node.name}]"] = t.irradiance
        frame.targets[f"tsd_stretch[{node.name}]"] = t.stretch


class TsdBlurPass:
    def __init__(self, renderer):
        self.r = renderer

    def run(self, frame, p) -> None:
        ctx, node, size = self.r.ctx, p.params["node"], p.params["size"]
        step = p.params["step"]
        t = self.r.tsd.targets(node, size)
        src = t.irradiance if step.level == 0 else t.level(ctx, step.level - 1)
        dst = t.level(ctx, step.level)
        prog = self.r.programs.get("passes/fullscreen.vert", "passes/tsd_blur.frag")
        taps_t, taps_w = blur_taps(step.taps)
        set_array(prog, "u_tap_t", taps_t.astype(np.float32), MAX_TAPS)
        set_array(prog, "u_tap_w", taps_w.astype(np.float32), MAX_TAPS)
        set_uniforms(prog, {"u_src": 0, "u_stretch": 1, "u_sigma_mm": step.sigma_mm, "u_taps": step.taps})
        t.stretch.use(1)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE | moderngl.BLEND)
        for axis, (a, b) in enumerate(((src, t.scratch), (t.scratch, dst))):
            t.fbo(ctx, b).use()
            ctx.viewport = (0, 0, size, size)
            a.use(0)
            set_uniform(prog, "u_axis", axis)
            self.r.fullscreen(prog)
        frame.targets[f"tsd_level{step.level}[{node.name}]"] = dst


EXACT_INNER_HALF = 24  # brute force: texels summed one by one within 24 texels of the centre...
EXACT_RING_RATIO = 1.15  # ...then annuli r -> 1.15 r out to r_max, cells read from the mip pyramid
UNIT_KERNEL = DiffusionKernel((BlurStep(0, 0.0, 0.0, 0, (1.0, 1.0, 1.0)),), np.zeros(3))


class TsdExactPass:
    """Brute-force convolution with the exact profile into level 0; the gather then reads that level
    with weight 1 (UNIT_KERNEL)."""

    def __init__(self, renderer):
        self.r = renderer
        self._luts: dict = {}

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

    def run(self, frame, p) -> None:
        ctx, node, size = self.r.ctx, p.params["node"], p.params["size"]
        t = self.r.tsd.targets(node, size)
        lut, r_max = self.lut(p.params["model"], material_medium(p.params["material"].values))
        dst = t.level(ctx, 0)
        prog = self.r.programs.get("passes/fullscreen.vert", "passes/tsd_exact.frag")
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
        ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE | moderngl.BLEND)
        t.fbo(ctx, dst).use()
        ctx.viewport = (0, 0, size, size)
        self.r.fullscreen(prog)
        t.irradiance.filter = (moderngl.LINEAR, moderngl.LINEAR)
        fn = frame.tsd.get(id(node))
        if fn is not None:
            fn.kernel = UNIT_KERNEL
        frame.targets[f"tsd_exact[{node.name}]"] = dst


def read_texture(tex: moderngl.Texture) -> np.ndarray:
    """A float texture as (H, W, C) float32, row 0 at v = 0 (the UV layout's bottom) - the layout the
    NumPy twins in scene/optics/tsd.py use."""
    w, h = tex.size
    return np.frombuffer(tex.read(), np.float32).reshape(h, w, tex.components).copy()
