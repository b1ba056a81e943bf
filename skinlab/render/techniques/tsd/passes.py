"""Texture-space diffusion passes (d'Eon & Luebke 2007, GPU Gems 3 ch. 14), per subsurface mesh:

  tsd_stretch     world mm per texel along u and v (only when the geometry or scene scale changes)
  tsd_irradiance  light entering the surface, rasterised at the UVs, x albedo^mix; with translucency
                  also the record of the light through thin parts, its gutter then filled across
                  seams and one ring past the other chart borders (through_fill)
  tsd_seams       the seam map: the gutter across UV seams paired with texels of the other chart
                  (seams.py; only for meshes with seams; when the mesh changes)
  tsd_dilate      the gutter across seams filled from the seam map, then irradiance pushed past the
                  remaining chart borders (a few one-texel rings)
  tsd_blur        one Gaussian level of the chain: separable u then v, taps in mm via the stretch map;
                  then the level's gutter filled across seams

The kernel (variances, weights, taps) comes from skinlab/scene/optics/tsd.py, which also holds the NumPy
twin of the blur and gather. The gather is the technique's forward hook
(skinlab/shaders/techniques/tsd/forward.glsl, variant TSD_LEVELS; bound by forward.py here).
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field

import moderngl
import numpy as np

from skinlab.gl.state import gl_state
from skinlab.gl.uniforms import Shader, set_array, set_uniform, set_uniforms
from skinlab.render.ambient import ambient_defines, bind_ambient
from skinlab.render.boundary import bind_boundary
from skinlab.render.compute import bind_images, dispatch, pass_program
from skinlab.render.environment import bind_env_bands
from skinlab.render.gpu_resources import node_uniforms
from skinlab.render.lights import SHADOW_SLOTS, bind_shadow_maps, light_defines, near_defines, set_light_uniforms
from skinlab.render.technique import RenderPass, TechniqueState
from skinlab.render.texture_units import TextureUnits
from skinlab.render.translucency import bind_translucency
from skinlab.scene.optics.tsd import DiffusionKernel, blur_taps

from .plan import TsdBlurParams, TsdIrradianceParams, TsdNodeParams
from .seams import SeamMap, node_border_strips
from .through_split import lit_texels, slot_masks, split_indices

STATE_KEY = "tsd"  # the renderer-side store (shared with technique "exact") and frame.data key

MAX_TAPS = 31  # skinlab/shaders/techniques/tsd/blur.glsl
DILATE_GROUP = 16  # texels per side of a work group of skinlab/shaders/techniques/tsd/dilate.comp


def _texture(ctx, size: int) -> moderngl.Texture:
    t = ctx.texture((size, size), 4, dtype="f4")
    t.filter = (moderngl.LINEAR, moderngl.LINEAR)
    t.repeat_x = t.repeat_y = False
    return t


def _record_textures(ctx, size: int) -> list:
    """The light-through record's textures (TsdNodeTargets.through_record): RGBA, RGBA, RG, nearest."""
    out = []
    for comps in (4, 4, 2):
        t = ctx.texture((size, size), comps, dtype="f4")
        t.filter = (moderngl.NEAREST, moderngl.NEAREST)
        t.repeat_x = t.repeat_y = False
        out.append(t)
    return out


@dataclass
class TsdNodeTargets:
    """The GPU textures of one subsurface mesh node (float32 RGBA, premultiplied by coverage): the
    irradiance as rasterised (raw) and dilated, a scratch texture for ping-ponging, the stretch map
    and the blurred levels. Each pass's result stays in its own texture, so a pass whose inputs
    did not change can be reused on later frames (skinlab/render/reuse.py)."""

    size: int
    irradiance: moderngl.Texture
    scratch: moderngl.Texture
    stretch: moderngl.Texture
    raw: moderngl.Texture
    levels: list = field(default_factory=list)
    fbos: dict = field(default_factory=dict)
    seam: SeamMap | None = None  # the seam map (meshes with UV seams)
    through: list = field(default_factory=list)  # the light-through record, filled (through_record)
    through_raw: list = field(default_factory=list)  # as the irradiance pass wrote it
    strips: tuple = ()  # (source array, depth renderbuffer): where the record's fill runs (strip_mask)
    surface: list = field(default_factory=list)  # the surface G-buffer (surface_buffer), RGBA32F, nearest
    masks: dict = field(default_factory=dict)  # coverage masks by what was rasterised (coverage_mask)
    # (index buffer, [(slot mask, first, count), ...]): the mesh's triangles grouped by the slots of the
    # record whose light they can read (record_split); () where it was not made
    through_faces: tuple = ()

    def fbo(self, ctx, tex: moderngl.Texture, *more: moderngl.Texture, depth=None) -> moderngl.Framebuffer:
        key = (id(tex), *(id(m) for m in more), id(depth))
        f = self.fbos.get(key)
        if f is None:
            f = self.fbos[key] = ctx.framebuffer([tex, *more], depth)
        return f

    def draw_into(self, renderer, prog: Shader, dst: moderngl.Texture) -> None:
        """Run `prog` over every texel of `dst` (this node's size): a compute shader writing image
        `u_dst`, or a fullscreen fragment pass into `dst` (the two paths of a blur or a gather)."""
        if isinstance(prog, moderngl.ComputeShader):
            bind_images(prog, {"u_dst": dst})
            dispatch(prog, (self.size, self.size))
        else:
            self.fbo(renderer.ctx, dst).use()
            renderer.ctx.viewport = (0, 0, self.size, self.size)
            renderer.fullscreen(prog)

    def strip_mask(self, renderer, strips: np.ndarray):
        """`strips` (seams.node_border_strips) drawn once into a depth renderbuffer (0.5 on them, 0
        elsewhere), kept until they change (a new mesh version or size): a fullscreen pass tested
        against it with "<=" shades only the strips. One draw of the strips per frame cost more on
        llvmpipe (thousands of sliver triangles: 20 ms on the bunny) than the early depth test of
        every texel."""
        if not self.strips or self.strips[0] is not strips:
            ctx = renderer.ctx
            mask = self.strips[1] if self.strips else ctx.depth_renderbuffer((self.size, self.size))
            fbo = ctx.framebuffer(depth_attachment=mask)
            fbo.use()
            ctx.viewport = (0, 0, self.size, self.size)
            fbo.clear(depth=0.0)
            if len(strips):
                prog = renderer.programs.get("passes/fullscreen.vert", "passes/depth_only.frag")
                vbo = ctx.buffer(strips.tobytes())
                vao = ctx.vertex_array(prog, [(vbo, "2f", "in_pos")])
                with gl_state(ctx, moderngl.DEPTH_TEST, depth_func="1"):  # always: every strip texel gets depth 0.5
                    vao.render(moderngl.TRIANGLES)
                vao.release()
                vbo.release()
            fbo.release()
            self.strips = (strips, mask)
        return self.strips[1]

    def through_record(self, ctx) -> list:
        """The irradiance pass's record of the light through thin parts, per texel and shadow slot,
        unblurred (for the gather's exit factor of that light, skinlab/shaders/techniques/tsd/forward.glsl):
        RGBA per slot (the light entering through, the thickness in mm) and RG (each slot's cosine on
        the far face), its gutter filled (through_fill). Nearest filtering: a texel's record belongs
        to it alone."""
        if not self.through:
            self.through = _record_textures(ctx, self.size)
        return self.through

    def coverage_mask(self, ctx, what: str):
        """A depth renderbuffer the UV raster of `what` ("stretch", "irradiance") writes (0.5 where a
        triangle covers the texel, 1 elsewhere: raster_mask), read by the dilation of its result: a
        fullscreen ring tested against it with "<" shades only the texels no triangle covers, the
        only ones a ring can change (mask_ready says whether it holds the current raster)."""
        m = self.masks.get(what)
        if m is None:
            m = self.masks[what] = [ctx.depth_renderbuffer((self.size, self.size)), False]
        return m[0]

    def mask_ready(self, what: str):
        """`what`'s coverage mask when its raster wrote it, else None (dilate every texel)."""
        m = self.masks.get(what)
        return m[0] if m is not None and m[1] else None

    def surface_buffer(self, ctx, bounce: bool, sky: bool = False, through: bool = False) -> list:
        """The irradiance pass's surface G-buffer (deferred shading, techniques/tsd/surface.glsl): world
        position and coverage, normal and the tangent's handedness, tangent, the vertex colour, with
        `bounce` the interreflection's irradiance, with `sky` the sky occlusion's record (one more;
        the bounce slot is kept so the layout is fixed), with `through` the light through thin parts
        from the transfer through the medium and its incidence (the seventh and eighth), as the UV
        raster interpolates them. Nearest filtering."""
        want = 8 if through else 6 if sky else 5 if bounce else 4
        while len(self.surface) < want:
            t = ctx.texture((self.size, self.size), 4, dtype="f4")
            t.filter = (moderngl.NEAREST, moderngl.NEAREST)
            t.repeat_x = t.repeat_y = False
            self.surface.append(t)
        return self.surface[:want]

    def through_raw_record(self, ctx) -> list:
        """The same record as the irradiance pass rasterised it (empty in the gutter)."""
        if not self.through_raw:
            self.through_raw = _record_textures(ctx, self.size)
        return self.through_raw

    def level(self, ctx, k: int) -> moderngl.Texture:
        while len(self.levels) <= k:
            self.levels.append(_texture(ctx, self.size))
        return self.levels[k]

    def seam_map(self, ctx) -> SeamMap:
        if self.seam is None:
            self.seam = SeamMap(ctx, self.size)
        return self.seam

    def release(self) -> None:
        for f in self.fbos.values():
            f.release()
        for t in [
            self.irradiance,
            self.scratch,
            self.stretch,
            self.raw,
            *self.levels,
            *self.through,
            *self.through_raw,
            *self.surface,
            *(m[0] for m in self.masks.values()),
        ]:
            t.release()
        if self.seam is not None:
            self.seam.release()
        if self.strips:
            self.strips[1].release()
        if self.through_faces:
            self.through_faces[0].release()


@dataclass
class TsdFrameNode:
    """What the gather needs for one node this frame."""

    targets: TsdNodeTargets
    kernel: DiffusionKernel  # the gather's weights (UNIT_KERNEL after the exact convolution)
    material: object
    mix: float
    translucency: bool = False  # the irradiance gathered light through thin parts
    through_slots: int = 0  # the shadow slots whose light through it recorded (TsdNodeTargets.through_record)


class TsdStore(TechniqueState):
    """Per-node TSD textures, kept across frames (the renderer reuses the results of passes whose
    inputs did not change). The renderer keeps one per renderer (Renderer.state) and calls
    begin_frame with each frame plan."""

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
            irradiance, scratch, stretch, raw = (_texture(c, size) for _ in range(4))
            t = self.nodes[node.uid] = TsdNodeTargets(size, irradiance, scratch, stretch, raw)
        return t

    def retain(self, uids) -> int:
        """Release the textures of nodes not in `uids` (removed nodes, a reloaded scene); returns
        how many were released."""
        gone = [u for u in self.nodes if u not in uids]
        for u in gone:
            self.nodes.pop(u).release()
        return len(gone)

    def begin_frame(self, plan) -> None:
        """Keep the textures of the nodes this frame's passes use; release the rest."""
        self.retain({p.params.node.uid for p in plan.passes if isinstance(p.params, TsdNodeParams)})

    def release(self) -> None:
        for t in self.nodes.values():
            t.release()
        self.nodes.clear()


def store(renderer) -> TsdStore:
    """The renderer's TSD store."""
    return renderer.state(STATE_KEY, TsdStore)


def frame_nodes(frame) -> dict:
    """This frame's TsdFrameNode per node uid (written by the irradiance pass, read by the gather)."""
    return frame.data.setdefault(STATE_KEY, {})


def _uv_raster_setup(ctx, fbo, size: int) -> None:
    """`fbo` drawn into at `size` (the pass's scope has no depth test, culling or blending)."""
    fbo.use()
    ctx.viewport = (0, 0, size, size)


@contextmanager
def raster_mask(ctx, t: TsdNodeTargets, what: str, fbo):
    """Around a UV raster into `fbo` (its depth attachment t.coverage_mask(what), cleared to 1): every
    triangle writes its depth (0.5) whatever is there, so the mask marks the covered texels."""
    with gl_state(ctx, enable=moderngl.DEPTH_TEST, depth_func="1"):  # always: the last triangle wins
        yield
    t.masks[what][1] = True


def dilate(
    renderer,
    t: TsdNodeTargets,
    src: moderngl.Texture,
    dst: moderngl.Texture,
    rings: int,
    compute: bool = False,
    mask=None,
) -> None:
    """`rings` one-texel dilation steps from `src` into `dst`, ping-ponging with the scratch
    texture (in place, src is dst, the count is rounded up to an even one). With `compute` every
    ring in one dispatch (techniques/tsd/dilate.comp; in place through the scratch texture). With
    `mask` (TsdNodeTargets.coverage_mask, the raster `src` came from) each ring shades only the texels
    no triangle covered, through an early depth test: a covered texel never changes, so the targets
    start as copies of `src` and the rings give the same texels as shading every one (on llvmpipe a
    ring over every texel cost about 7 ms at 512 x 512, whatever it changed)."""
    ctx = renderer.ctx
    steps = rings + (rings % 2) if src is dst else max(rings, 1)
    if compute:
        dilate_compute(renderer, t, src, dst, steps)
        return
    outs = [dst if (steps - 1 - i) % 2 == 0 else t.scratch for i in range(steps)]
    if mask is not None:  # what the rings do not shade is src's
        for out in {id(o): o for o in outs}.values():
            if out is not src:
                ctx.copy_framebuffer(t.fbo(ctx, out), t.fbo(ctx, src))
    prog = renderer.programs.get("passes/fullscreen.vert", "techniques/tsd/dilate.frag")
    # with the mask, the fullscreen triangle's 0.5 passes "<" only where no triangle was
    with gl_state(ctx, enable=moderngl.DEPTH_TEST if mask is not None else 0, depth_func="<"):
        for out in outs:
            fbo = t.fbo(ctx, out, depth=mask)
            fbo.depth_mask = False
            fbo.use()
            ctx.viewport = (0, 0, t.size, t.size)
            src.use(0)
            set_uniform(prog, "u_src", 0)
            renderer.fullscreen(prog)
            src = out


def dilate_compute(
    renderer, t: TsdNodeTargets, src: moderngl.Texture, dst: moderngl.Texture, rings: int, seams: bool = False
) -> None:
    """`rings` rings of dilation from `src` into `dst` in one dispatch (techniques/tsd/dilate.comp);
    with `seams` the texels are read through the node's seam map first (the seam fill)."""
    ctx = renderer.ctx
    cs = renderer.programs.compute("techniques/tsd/dilate.comp", {"RINGS": rings, "TSD_SEAMS": seams})
    out = t.scratch if src is dst else dst
    units = TextureUnits(ctx)
    units.bind(cs, "u_src", src)
    if seams:
        units.bind(cs, "u_seam", t.seam_map(ctx).texture)
    bind_images(cs, {"u_dst": out})
    groups = (t.size + DILATE_GROUP - 1) // DILATE_GROUP
    cs.run(groups, groups, 1)
    ctx.memory_barrier()
    if out is not dst:
        ctx.copy_framebuffer(t.fbo(ctx, dst), t.fbo(ctx, out))


class TsdPass(RenderPass):
    """A texture-space pass of one mesh node; ``output`` names the node texture holding its result."""

    def output(self, t: TsdNodeTargets, p) -> moderngl.Texture:
        """The texture of `t` the pass writes its result into (each kind says which)."""
        raise NotImplementedError

    def node_targets(self, p) -> TsdNodeTargets:
        return store(self.r).targets(p.params.node, p.params.size)

    def outputs(self, frame, p) -> tuple:
        """The texture holding the pass's result (reuse across frames, skinlab/render/reuse.py)."""
        return (self.output(self.node_targets(p), p),)

    def publish(self, frame, p) -> None:
        """Hand the result to the frame (after run, or when reused)."""


class TsdStretchPass(TsdPass):
    def output(self, t, p):
        return t.stretch

    def run(self, frame, p) -> None:
        prm: TsdNodeParams = p.params
        ctx, node, size = self.r.ctx, prm.node, prm.size
        t = self.node_targets(p)
        mask = t.coverage_mask(ctx, "stretch")
        fbo = t.fbo(ctx, t.stretch, depth=mask)
        _uv_raster_setup(ctx, fbo, size)
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        radius_map = {k: v for k, v in node.material.textures().items() if k == "u_subsurface_radius_map"}
        defines = {"HAS_SUBSURFACE_RADIUS_MAP": "1"} if radius_map else {}
        prog = self.r.programs.get("techniques/tsd/uv.vert", "techniques/tsd/stretch.frag", defines)
        set_uniforms(prog, {**node_uniforms(node), "u_mm_per_unit": frame.scene.mm_per_unit})
        units = TextureUnits(ctx)
        for sampler, (path, cs) in radius_map.items():
            units.bind(prog, sampler, self.r.resources.texture(path, cs))
        with raster_mask(ctx, t, "stretch", fbo):
            if prm.seams is not None:  # the surface across seams, in the gutter: drawn first, the charts win
                self.r.resources.mesh(prm.seams.mesh()).vao(prog).render(moderngl.TRIANGLES)
            self.r.resources.mesh(node.mesh).vao(prog).render(moderngl.TRIANGLES)
        dilate(self.r, t, t.stretch, t.stretch, prm.dilate, prm.compute, t.mask_ready("stretch"))
        store(self.r).stretch_updates += 1


class TsdIrradiancePass(TsdPass):
    def output(self, t, p):
        return t.raw

    def outputs(self, frame, p) -> tuple:
        t = self.node_targets(p)
        return (t.raw, *(t.through_record(self.r.ctx) if p.params.translucency else ()))

    def publish(self, frame, p) -> None:
        prm: TsdIrradianceParams = p.params
        t = self.node_targets(p)
        gather = prm.gather if prm.gather is not None else prm.kernel
        frame_nodes(frame)[prm.node.uid] = TsdFrameNode(
            t, gather, prm.material, prm.mix, prm.translucency, min(len(prm.shadow_lights), SHADOW_SLOTS)
        )
        frame.targets[f"tsd_irradiance_raw[{prm.node.name}]"] = t.raw

    def run(self, frame, p) -> None:
        prm: TsdIrradianceParams = p.params
        ctx, node, size, mat = self.r.ctx, prm.node, prm.size, prm.material
        t = self.node_targets(p)
        nmax = frame.settings.max_lights
        ambient = ambient_defines(frame, node)
        # what the surface G-buffer carries besides the geometry: the vertex's bounce light and sky occlusion
        carried = {k: v for k, v in ambient.items() if k in ("BOUNCE", "THROUGH_KERNEL", "SKY_OCCLUSION")}
        surface = []
        if prm.deferred:  # the mesh's vertex outputs rasterised into the G-buffer, then shaded per texel
            surface = t.surface_buffer(
                ctx, "BOUNCE" in carried, "SKY_OCCLUSION" in carried, "THROUGH_KERNEL" in carried
            )
            mask = t.coverage_mask(ctx, "irradiance")
            # only the coverage (surface0's a) is read where no triangle wrote: the rest is cleared
            # by the raster wherever it is read (techniques/tsd/surface.glsl load_surface)
            t.fbo(ctx, surface[0], depth=mask).clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            gbuf = t.fbo(ctx, *surface, depth=mask)
            _uv_raster_setup(ctx, gbuf, size)
            raster = self.r.programs.get("techniques/tsd/uv.vert", "techniques/tsd/surface.frag", carried)
            set_uniforms(raster, node_uniforms(node))
            bind_ambient(frame, node, raster, TextureUnits(ctx))
            with raster_mask(ctx, t, "irradiance", gbuf):  # the dilation's mask
                self.r.resources.mesh(node.mesh).vao(raster).render(moderngl.TRIANGLES)
        elif "irradiance" in t.masks:
            t.masks["irradiance"][1] = False
        slots = min(len(prm.shadow_lights), SHADOW_SLOTS)
        # the light-through record: slot 1's only where two slots are filled (irradiance.frag's outputs)
        record = t.through_raw_record(ctx) if prm.translucency else []
        fbo = t.fbo(ctx, t.raw, *(record if slots > 1 else record[0::2]))
        _uv_raster_setup(ctx, fbo, size)
        fbo.clear(0.0, 0.0, 0.0, 0.0)
        defines = {
            **mat.defines(),
            **light_defines(prm.shadow_lights, nmax, frame),
            **near_defines(prm.lights),
            **ambient,
        }
        if prm.translucency:
            defines["TSD_TRANSLUCENCY"] = 1
        if prm.deferred:
            defines["DEFERRED_SURFACE"] = 1
            prog = self.r.programs.get("passes/fullscreen.vert", "techniques/tsd/irradiance.frag", defines)
        else:
            prog = self.r.programs.get("techniques/tsd/uv.vert", "techniques/tsd/irradiance.frag", defines)
        units = TextureUnits(ctx)
        for k, tex in enumerate(surface):
            units.bind(prog, f"u_surface{k}", tex)
        bind_shadow_maps(self.r, frame, prog, units)
        units.bind(prog, "u_tsd_stretch", t.stretch)  # the texel's footprint for the shadow's average
        set_light_uniforms(prog, frame, prm.lights, prm.shadow_lights, nmax)
        set_uniforms(prog, {**node_uniforms(node), "u_ambient": frame.scene.environment.ambient, "u_tsd_mix": prm.mix})
        self.r.resources.bind_material(prog, mat, units, isotropic=square_footprint(mat))
        bind_ambient(frame, node, prog, units)
        bind_boundary(prog, mat)
        bind_env_bands(prog, mat)
        if prm.translucency:
            bind_translucency(prog, frame, units, self.r.dummy_texture())
        if prm.deferred:
            self.r.fullscreen(prog)
        else:
            self.r.resources.mesh(node.mesh).vao(prog).render(moderngl.TRIANGLES)
        self.r.resources.unbind_samplers()
        if prm.translucency:  # the record's gutter by the chart borders: across the seams, else dilated
            through_fill(self.r, t, prm.seams is not None, node_border_strips(node.mesh, size), slots)
            record_split(ctx, t, node.mesh, slots)
        self.publish(frame, p)


def square_footprint(material) -> bool:
    """Whether a UV texel's footprint on the material's maps is a square: always, unless its texture
    transform scales u and v differently (the maps are then filtered anisotropically, as elsewhere)."""
    sx, sy = (abs(float(x)) for x in material.values.get("uv_scale", (1.0, 1.0)))
    return sx == sy


def through_fill(renderer, t: TsdNodeTargets, seams: bool, strips: np.ndarray | None = None, slots: int = 2) -> None:
    """The irradiance pass's light-through record (t.through_raw_record, read with t.raw's coverage)
    into t.through_record with its gutter filled (skinlab/shaders/techniques/tsd/through_fill.frag): the texels
    the seam map marks from across the seam (`seams`: the node's seam map is drawn), the others one
    ring from their covered neighbours. The gather reads the record with nearest filtering, so a
    fragment by a chart border reads the gutter texels whose square overlaps the chart: without the
    fill, a ring along every border left the light through with the reflected light's exit.
    The covered texels' records are copied (blits; slot 1's only for `slots` > 1: the gather reads
    only the slots the frame filled, variant TSD_THROUGH_SLOTS); the fill shades only `strips`
    (seams.node_border_strips: every texel a fragment inside a chart can read, and a few more),
    through an early depth test against their mask (TsdNodeTargets.strip_mask, drawn once per mesh),
    or every texel (None). On llvmpipe a fill of every texel cost 20 % of the irradiance pass on the
    head and 2.6x it on the back-lit slab (a sparse layout), drawing the strips every frame 20 ms
    on the bunny (thousands of sliver triangles); docs/tsd.md has the cost as shipped."""
    ctx = renderer.ctx
    for k, (src, dst) in enumerate(zip(t.through_raw_record(ctx), t.through_record(ctx))):
        if k != 1 or slots > 1:  # the covered texels' records
            ctx.copy_framebuffer(t.fbo(ctx, dst), t.fbo(ctx, src))
    defines = {"TSD_THROUGH_SLOTS": 2 if slots > 1 else 1, **({"TSD_SEAMS": 1} if seams else {})}
    prog = renderer.programs.get("passes/fullscreen.vert", "techniques/tsd/through_fill.frag", defines)
    mask = t.strip_mask(renderer, strips) if strips is not None else None
    fbo = t.fbo(ctx, *t.through_record(ctx), depth=mask)
    fbo.depth_mask = False
    fbo.use()
    ctx.viewport = (0, 0, t.size, t.size)
    units = TextureUnits(ctx)
    for name, tex in zip(("u_raw", "u_through0", "u_through1", "u_through_cos"), (t.raw, *t.through_raw_record(ctx))):
        units.bind(prog, name, tex)
    if seams:
        units.bind(prog, "u_seam", t.seam_map(ctx).texture)
    # with the mask only the strips (0.5 <= their depth 0.5; 0 elsewhere): an early depth test
    with gl_state(ctx, enable=moderngl.DEPTH_TEST if mask is not None else 0, depth_func="<="):
        renderer.fullscreen(prog)


# the share of the slot records' reads by triangles that grouping must save for the mesh to be drawn in groups
MIN_SPLIT_SHARE = 0.1


def record_split(ctx, t: TsdNodeTargets, mesh, slots: int) -> None:
    """t.through_faces from the filled records of the `slots` the gather reads (at most 2): the mesh's
    triangles grouped by the slots whose light through they can read (through_split.py; the forward pass
    draws each group without the exit factor of the other slots' light, the same image); none where
    that saves less than MIN_SPLIT_SHARE of the reads (a draw per group is not worth it)."""
    if t.through_faces:
        t.through_faces[0].release()
        t.through_faces = ()
    n = min(slots, SHADOW_SLOTS)
    if mesh.uvs is None or n < 1:
        return
    lits = [lit_texels(tex.read(), t.size) for tex in t.through_record(ctx)[:n]]
    mask = slot_masks(mesh.uvs, mesh.indices, lits)
    reads = sum(int(np.count_nonzero(mask & (1 << k))) for k in range(n))
    if reads <= (1.0 - MIN_SPLIT_SHARE) * n * len(mask):
        flat, groups = split_indices(mesh.indices, mask)
        t.through_faces = (ctx.buffer(flat.tobytes()), groups)


class TsdDilatePass(TsdPass):
    def output(self, t, p):
        return t.irradiance

    def publish(self, frame, p) -> None:
        name = p.params.node.name
        t = self.node_targets(p)
        frame.targets.pop(f"tsd_irradiance_raw[{name}]", None)
        frame.targets[f"tsd_irradiance[{name}]"] = t.irradiance
        frame.targets[f"tsd_stretch[{name}]"] = t.stretch

    def run(self, frame, p) -> None:
        t, prm = self.node_targets(p), p.params
        if prm.compute:  # the seam fill and every ring in one dispatch
            dilate_compute(self.r, t, t.raw, t.irradiance, max(prm.dilate, 1), prm.seams is not None)
        elif prm.seams is not None:  # the gutter across seams, then dilation for the rest
            seam_fill(self.r, t, t.raw, t.irradiance)
            dilate(self.r, t, t.irradiance, t.irradiance, prm.dilate, mask=t.mask_ready("irradiance"))
        else:
            dilate(self.r, t, t.raw, t.irradiance, prm.dilate, mask=t.mask_ready("irradiance"))
        self.publish(frame, p)


class TsdSeamPass(TsdPass):
    """The seam map of one node (seams.py)."""

    def output(self, t, p):
        return t.seam_map(self.r.ctx).texture

    def publish(self, frame, p) -> None:
        frame.targets[f"tsd_seams[{p.params.node.name}]"] = self.output(self.node_targets(p), p)

    def run(self, frame, p) -> None:
        t = self.node_targets(p)
        prog = self.r.programs.get("techniques/tsd/seam.vert", "techniques/tsd/seam.frag")
        seam = t.seam_map(self.r.ctx)
        seam.draw(prog, p.params.seams, p.params.node.mesh)
        seam.mark(self.r, self.r.programs.get("passes/fullscreen.vert", "techniques/tsd/seam_mark.frag"))
        self.publish(frame, p)


def seam_fill(renderer, t: TsdNodeTargets, src: moderngl.Texture, dst: moderngl.Texture, compute: bool = False) -> None:
    """`src` into `dst` (another texture), the texels the seam map marks read across the seam
    (skinlab/shaders/techniques/tsd/seam_fill.frag; `compute`: techniques/tsd/blur.comp's TSD_SEAM_FILL)."""
    ctx = renderer.ctx
    if compute:
        cs = renderer.programs.compute("techniques/tsd/blur.comp", {"TSD_SEAM_FILL": 1})
        src.use(0)
        t.seam_map(ctx).texture.use(1)
        set_uniforms(cs, {"u_src": 0, "u_seam": 1})
        bind_images(cs, {"u_dst": dst})
        dispatch(cs, (t.size, t.size))
        return
    prog = renderer.programs.get("passes/fullscreen.vert", "techniques/tsd/seam_fill.frag")
    seam = t.seam_map(ctx)
    # every texel but the marked ones is a copy: a blit, then the fill over the marked texels alone
    # (an early depth test against the seam map's mask; 0.5 <= 0.5 there, 0 elsewhere)
    ctx.copy_framebuffer(t.fbo(ctx, dst), t.fbo(ctx, src))
    fbo = t.fbo(ctx, dst, depth=seam.mask)
    fbo.depth_mask = False
    fbo.use()
    ctx.viewport = (0, 0, t.size, t.size)
    src.use(0)
    seam.texture.use(1)
    set_uniforms(prog, {"u_src": 0, "u_seam": 1})
    with gl_state(ctx, enable=moderngl.DEPTH_TEST if seam.mask is not None else 0, depth_func="<="):
        renderer.fullscreen(prog)


class TsdBlurPass(TsdPass):
    def output(self, t, p):
        return t.level(self.r.ctx, p.params.step.level)

    def publish(self, frame, p) -> None:
        prm: TsdBlurParams = p.params
        frame.targets[f"tsd_level{prm.step.level}[{prm.node.name}]"] = self.output(self.node_targets(p), p)

    def run(self, frame, p) -> None:
        prm: TsdBlurParams = p.params
        ctx, step = self.r.ctx, prm.step
        t = self.node_targets(p)
        src = t.irradiance if step.level == 0 else t.level(ctx, step.level - 1)
        dst = t.level(ctx, step.level)
        seams = prm.seams is not None
        # u then v; with seams the v step goes to the scratch texture and the seam fill from there
        # into the level (its gutter across the seams, for the next blur and the gather)
        steps = ((src, dst), (dst, t.scratch)) if seams else ((src, t.scratch), (t.scratch, dst))
        prog = pass_program(self.r.programs, "techniques/tsd/blur", prm.compute, {"TSD_TAPS": step.taps})
        taps_t, taps_w = blur_taps(step.taps)
        set_array(prog, "u_tap_t", taps_t.astype(np.float32), MAX_TAPS)
        set_array(prog, "u_tap_w", taps_w.astype(np.float32), MAX_TAPS)
        set_uniforms(prog, {"u_src": 0, "u_stretch": 1, "u_sigma_mm": step.sigma_mm})
        t.stretch.use(1)
        for axis, (a, b) in enumerate(steps):
            a.use(0)
            set_uniform(prog, "u_axis", axis)
            t.draw_into(self.r, prog, b)
        if seams:
            seam_fill(self.r, t, t.scratch, dst, prm.compute)
        self.publish(frame, p)


def read_texture(tex: moderngl.Texture) -> np.ndarray:
    """A float texture as (H, W, C) float32, row 0 at v = 0 (the UV layout's bottom) - the layout the
    NumPy twins in skinlab/scene/optics/tsd.py use."""
    w, h = tex.size
    return np.frombuffer(tex.read(), np.float32).reshape(h, w, tex.components).copy()
