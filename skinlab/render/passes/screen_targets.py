"""GPU targets of a screen-space pass (any technique that filters the forward pass's output): float32
colour targets at the frame's size with their framebuffers, remade when the size changes, and a
per-frame table texture (nearest filtering, reallocated only when its shape changes)."""

from __future__ import annotations

import moderngl
import numpy as np

from skinlab.gl.uniforms import set_uniforms


class ScreenTargets:
    def __init__(self, ctx: moderngl.Context, count: int):
        self.ctx, self.count = ctx, count
        self.textures: tuple = ()
        self.fbos: list = []
        self._table: moderngl.Texture | None = None

    def at(self, size) -> tuple:
        """`count` RGBA float32 textures of `size` (clamped at the border), remade on a new size."""
        if not self.textures or self.textures[0].size != tuple(size):
            self.release_targets()
            self.textures = tuple(self.ctx.texture(tuple(size), 4, dtype="f4") for _ in range(self.count))
            for x in self.textures:
                x.repeat_x = x.repeat_y = False
            self.fbos = [self.ctx.framebuffer([x]) for x in self.textures]
        return self.textures

    def table(self, data: np.ndarray):
        """`data` (rows, columns, 4) float32 uploaded to the table texture."""
        h, w = data.shape[:2]
        t = self._table
        if t is None or t.size != (w, h):
            if t is not None:
                t.release()
            t = self._table = self.ctx.texture((w, h), 4, dtype="f4")
            t.filter = (moderngl.NEAREST, moderngl.NEAREST)
        t.write(np.ascontiguousarray(data, np.float32).tobytes())
        return t

    def release_targets(self) -> None:
        for x in (*self.fbos, *self.textures):
            x.release()
        self.textures, self.fbos = (), []

    def release(self) -> None:
        self.release_targets()
        if self._table is not None:
            self._table.release()
            self._table = None


def composite(renderer, frame, out_fbo, out_tex, filtered, name: str) -> None:
    """Add a screen-space pass's filtered subsurface light back onto the lit image
    (passes/ssss_composite.frag) into `out_tex`; the frame's targets then show `filtered` as
    `name`, the image before as hdr_color_unblurred and the composite as hdr_color."""
    comp = renderer.programs.get("passes/fullscreen.vert", "passes/ssss_composite.frag")
    out_fbo.use()
    frame.targets["hdr_color"].use(0)
    filtered.use(1)
    set_uniforms(comp, {"u_color": 0, "u_blurred": 1})
    renderer.fullscreen(comp)
    publish_composite(frame, out_tex, filtered, name)


def publish_composite(frame, out_tex, filtered, name: str) -> None:
    """The frame's targets after a screen-space pass: `filtered` as `name`, the image before as
    hdr_color_unblurred and the composite `out_tex` as hdr_color (a compute path that writes the
    composite itself calls this instead of :func:`composite`)."""
    frame.targets[name] = filtered
    frame.targets["hdr_color_unblurred"] = frame.targets["hdr_color"]
    frame.targets["hdr_color"] = out_tex
