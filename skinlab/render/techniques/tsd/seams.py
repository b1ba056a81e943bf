"""UV seams in texture-space diffusion: light crosses chart borders.

Per mesh, once (cached by mesh identity, geometry version and band width), skinlab/scene/uv_seams.py unfolds
the surface across every UV seam into the gutter of each chart ("extension triangles"). Here:

- ``seam_band_texels``: how far past a seam the blurs read, from the kernel (in texels at the
  stretch's 10th percentile, where the kernel is widest in texels), capped at SEAM_BAND_MAX_TEXELS;
- ``node_seams``: the cached extension of a node's mesh for a band (None where the mesh has no seam);
- the pass ``tsd_seams``: the seam map (RG = the UV in the other chart, A = 1 where the gutter stands
  for the surface across a seam), drawn with a depth test - the distance from the edge: where
  bands overlap, the nearest seam edge's extension wins, and every chart border's own strip keeps
  the gutter nearest it (not filled: dilation) where no extension is nearer - under the real
  charts (which always win). View- and light-independent: reused until the
  mesh or the band changes.

The stretch pass also draws the extension triangles (their own mm per texel in this chart's frame);
the dilation pass first fills the gutter from the seam map (skinlab/shaders/techniques/tsd/seam_fill.frag), and
so does every blur pass after its v step: the next blur's u step then reads, in the gutter, the
previous level across the seam (its v step reads the u step's gutter texels as they are: the u blur
in this chart's frame, continued), and the gather's bilinear lookup at a border reads across too.
"""

from __future__ import annotations

import math

import moderngl
import numpy as np

from skinlab.cache import content_key, stored
from skinlab.gl.state import gl_state
from skinlab.gl.uniforms import set_uniforms
from skinlab.scene.mesh import mesh_key
from skinlab.scene.optics.constants import TSD_TAP_RANGE
from skinlab.scene.uv_seams import SeamExtension, border_strips, seam_extension

SEAM_BAND_MAX_TEXELS = 64  # widest extension band past a seam (texels); wider kernels read dilation beyond
BORDER_BIAS = 1e-3  # a border strip's depth offset (x the band): its own extension wins a tie
SEAM_BAND_ROUND = 8  # bands are rounded up to a multiple of this (a small kernel change keeps the cache)

_CACHE: dict = {}


def seam_band_texels(kernel, mm_per_texel_p10: float) -> int:
    """Texels past a seam the blurs need: the widest Gaussian's +-3 sigma reach (its total
    variance, which also covers a blur step's u-then-v reach into the gutter) at the 10th percentile
    of mm per texel, plus two texels of bilinear footprint; rounded up to SEAM_BAND_ROUND, at most
    SEAM_BAND_MAX_TEXELS."""
    v = max((s.variance_mm2 for s in kernel.steps), default=0.0)
    reach = TSD_TAP_RANGE * math.sqrt(max(v, 0.0)) / max(float(mm_per_texel_p10), 1e-9) + 2.0
    band = SEAM_BAND_ROUND * math.ceil(reach / SEAM_BAND_ROUND)
    return int(min(max(band, SEAM_BAND_ROUND), SEAM_BAND_MAX_TEXELS))


def node_seams(mesh, band_texels: int, size: int) -> SeamExtension | None:
    """The mesh's seam extension reaching `band_texels` texels (of a `size` texture) past each seam,
    built once per (mesh, version, band in UV units); None when the mesh has no seam edge."""
    band_uv = band_texels / float(size)
    key = (mesh.uid, mesh.version, round(band_uv, 9))
    hit = _CACHE.get(key, False)
    if hit is False:
        if len(_CACHE) > 32:
            _CACHE.clear()
        ext = stored(  # on disk too: unfolding the head's seams takes 0.4 s
            "seams",
            content_key(mesh_key(mesh), round(band_uv, 9)),
            lambda: seam_extension(mesh, band_uv),
            f"the UV seams of mesh {mesh.name!r}",
            code="skinlab.scene.uv_seams",
        )
        hit = _CACHE[key] = ext if ext.triangles else None
    return hit


def node_border_strips(mesh, size: int) -> np.ndarray:
    """The thin rectangles around every chart border of the mesh (skinlab/scene/uv_seams.py border_strips:
    0.75 texel outside, over half a texel's diagonal, and a quarter inside, of a `size` texture) as
    float32 clip-space triangle corners (K * 3, 2): where the light-through record's fill runs
    (passes.through_fill). Cached by mesh identity, geometry version and size."""
    key = ("strips", mesh.uid, mesh.version, size)
    hit = _CACHE.get(key)
    if hit is None:
        if len(_CACHE) > 32:
            _CACHE.clear()
        tri = border_strips(mesh, 0.75 / size, 0.25 / size)
        hit = _CACHE[key] = np.ascontiguousarray((tri * 2.0 - 1.0).reshape(-1, 2), np.float32)
    return hit


def seams_summary(ext: SeamExtension, band_texels: int) -> str:
    return (
        f"{len(ext.seam_pairs)} seam edges, {ext.triangles} extension triangles reaching {band_texels} texels past them"
    )


class SeamMap:
    """The seam map texture of one node (float32 RGBA) with its depth buffer and the vertex data of
    the extension (kept until the extension changes)."""

    def __init__(self, ctx, size: int):
        self.ctx = ctx
        self.texture = ctx.texture((size, size), 4, dtype="f4")
        self.texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.texture.repeat_x = self.texture.repeat_y = False
        self.depth = ctx.depth_renderbuffer((size, size))
        self.fbo = ctx.framebuffer([self.texture], self.depth)
        self.vertices: tuple[moderngl.Buffer, moderngl.VertexArray] | None = None  # the extension's
        self.source: tuple | None = None  # (id of the extension, id of the program) the vertices are for
        # the marked texels as a depth mask (mark): 0.5 where marked, 0 elsewhere; None until marked
        self.mask: moderngl.Renderbuffer | None = None
        self._mask_fbo: moderngl.Framebuffer | None = None
        self._mask_color: moderngl.Renderbuffer | None = None

    def mark(self, renderer, prog) -> None:
        """The mask of the marked texels for seam_fill's early depth test (prog: techniques/tsd/
        seam_mark.frag over a fullscreen triangle); after every draw of the map."""
        size = self.texture.size
        if self.mask is None:
            self.mask = self.ctx.depth_renderbuffer(size)
            self._mask_color = self.ctx.renderbuffer(size, 1, dtype="f1")
            self._mask_fbo = self.ctx.framebuffer([self._mask_color], self.mask)
        assert self._mask_fbo is not None
        self._mask_fbo.use()
        self.ctx.viewport = (0, 0, *size)
        self._mask_fbo.clear(0.0, 0.0, 0.0, 0.0, depth=0.0)
        self.texture.use(0)
        set_uniforms(prog, {"u_seam": 0})
        with gl_state(self.ctx, moderngl.DEPTH_TEST, depth_func="1"):  # always: write 0.5 where kept
            renderer.fullscreen(prog)

    def draw(self, prog, ext: SeamExtension, mesh) -> None:
        key = (id(ext), id(prog), mesh.uid, mesh.version)
        if self.source != key:
            self.release_vertices()
            real = mesh.uvs[mesh.indices.reshape(-1)]
            n_ext, n_border = 3 * ext.triangles, ext.border_uv.shape[0] * 3
            data = np.zeros((n_ext + n_border + len(real), 5), np.float32)
            data[:n_ext, 0:2] = ext.uv.reshape(-1, 2)
            data[:n_ext, 2:4] = ext.src_uv.reshape(-1, 2)
            data[:n_ext, 4] = np.maximum(ext.depth.reshape(-1), 0.0)
            # the borders' own strips: no source (src < 0: not filled), a hair behind an extension
            # at the same distance (an edge's own extension wins over its own strip)
            b = slice(n_ext, n_ext + n_border)
            data[b, 0:2] = ext.border_uv.reshape(-1, 2)
            data[b, 2:4] = -1.0
            data[b, 4] = ext.border_depth.reshape(-1) + BORDER_BIAS * ext.band_uv
            data[n_ext + n_border :, 0:2] = real
            data[n_ext + n_border :, 4] = -1.0  # the real charts: always in front
            vbo = self.ctx.buffer(data.tobytes())
            vao = self.ctx.vertex_array(prog, [(vbo, "2f 2f 1f", "in_uv", "in_src", "in_depth")])
            self.vertices, self.source = (vbo, vao), key
        assert self.vertices is not None
        size = self.texture.size[0]
        self.fbo.use()
        self.ctx.viewport = (0, 0, size, size)
        self.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        set_uniforms(prog, {"u_depth_range": float(ext.band_uv) * 2.0})
        with gl_state(self.ctx, moderngl.DEPTH_TEST, depth_func="<"):
            self.vertices[1].render(moderngl.TRIANGLES)

    def release_vertices(self) -> None:
        if self.vertices is not None:
            vbo, vao = self.vertices
            vao.release()
            vbo.release()
        self.vertices = self.source = None

    def release(self) -> None:
        self.release_vertices()
        for x in (self._mask_fbo, self._mask_color, self.mask):
            if x is not None:
                x.release()
        self.fbo.release()
        self.depth.release()
        self.texture.release()
