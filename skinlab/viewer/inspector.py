"""Pass inspector: show any target of the renderer's last frame in the window.

The renderer keeps the latest frame's textures in ``renderer.last_frame.targets`` (name ->
texture). Targets are listed generically (the final ``ldr_color`` first, then the others in
the order the passes produced them), so new passes' targets appear without code here. How a
texture is shown follows from its format:

* ``ldr``:   8-bit colour, already tone mapped and sRGB encoded: shown as is;
* ``color``: float RGB(A), linear: ``(v - offset) * scale``, then sRGB encoded (IEC 61966-2-1);
* ``grey``:  depth textures (comparison disabled through a sampler object) and one-channel float
             targets: ``(r - offset) * scale`` as grey;
* ``rg``:    two-channel float targets: ``(rg - offset) * scale`` in red and green.

Offset and scale start from the target's own value range (``auto_range``), and can be changed.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from skinlab.gl.state import gl_state

FINAL = "ldr_color"
MODES = {"ldr": 0, "color": 1, "grey": 2, "rg": 3}

_VS = """#version 330 core
in vec2 in_pos;
out vec2 v_uv;
void main() { v_uv = in_pos * 0.5 + 0.5; gl_Position = vec4(in_pos, 0.0, 1.0); }
"""

_FS = """#version 330 core
uniform sampler2D u_tex;
uniform int u_mode;
uniform float u_scale;
uniform float u_offset;
in vec2 v_uv;
out vec4 f_color;
// linear -> sRGB transfer function (IEC 61966-2-1:1999)
vec3 srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
void main() {
    vec4 t = texture(u_tex, v_uv);
    vec3 c;
    if (u_mode == 0) c = t.rgb;
    else if (u_mode == 1) c = srgb((t.rgb - u_offset) * u_scale);
    else if (u_mode == 2) c = vec3(clamp((t.r - u_offset) * u_scale, 0.0, 1.0));
    else c = vec3(clamp((t.rg - u_offset) * u_scale, 0.0, 1.0), 0.0);
    f_color = vec4(c, 1.0);
}
"""


def display_mode(texture) -> str | None:
    """How to show a texture, from its format; None when it cannot be shown (integer or
    multisampled textures, arrays, cube maps...)."""
    if not isinstance(texture, moderngl.Texture) or getattr(texture, "samples", 0):
        return None
    if getattr(texture, "depth", False):
        return "grey"
    dtype, n = texture.dtype, texture.components
    if dtype == "f1":
        return "ldr" if n >= 3 else ("grey" if n == 1 else "rg")
    if dtype not in ("f2", "f4"):
        return None
    return {1: "grey", 2: "rg"}.get(n, "color")


def target_names(targets: dict) -> list[str]:
    """The final image first, then every other target in the order it was produced."""
    names = [n for n in targets if n != FINAL]
    return ([FINAL] if FINAL in targets else []) + names


def read_texture(texture) -> np.ndarray:
    """(H, W, C) float32 (8-bit targets scaled to [0, 1]), row 0 at the top."""
    w, h = texture.size
    if getattr(texture, "depth", False):
        data, n = np.frombuffer(texture.read(), np.float32), 1
    else:
        n = texture.components
        dt = {"f1": np.uint8, "f2": np.float16, "f4": np.float32}[texture.dtype]
        data = np.frombuffer(texture.read(), dt)
        if texture.dtype == "f1":
            data = data / np.float32(255.0)
    return data.astype(np.float32).reshape(h, w, n)[::-1].copy()


def auto_range(pixels: np.ndarray, mode: str) -> tuple[float, float]:
    """(offset, scale) mapping the target's finite values onto [0, 1]. Depth ignores the cleared
    far plane (1.0); linear colour keeps offset 0 and maps the 99th percentile to 1."""
    v = pixels[..., :2] if mode == "rg" else pixels[..., :1] if mode == "grey" else pixels[..., :3]
    v = v[np.isfinite(v)]
    if mode == "ldr":
        return 0.0, 1.0
    if mode == "grey":
        inner = v[v < 1.0]
        v = inner if inner.size else v
    if v.size == 0:
        return 0.0, 1.0
    if mode == "color":
        top = float(np.percentile(v, 99.0))
        return 0.0, (1.0 / top if top > 0 else 1.0)
    lo, hi = float(v.min()), float(v.max())
    return lo, (1.0 / (hi - lo) if hi > lo else 1.0)


MAX_ASPECT = 4.0  # a target wider (or taller) than this is shown stretched to it: a 1024x10 one is no strip


def shown_aspect(tex_size: tuple[int, int]) -> tuple[float, float]:
    """(width / height as shown, the stretch of the shorter side: 1 when shown as it is)."""
    tw, th = tex_size
    if min(tw, th) <= 0:
        return 1.0, 1.0
    a = tw / th
    shown = min(max(a, 1.0 / MAX_ASPECT), MAX_ASPECT)
    return shown, max(a / shown, shown / a)


def fit_viewport(tex_size: tuple[int, int], win_size: tuple[int, int]) -> tuple[int, int, int, int]:
    """Largest viewport with the texture's aspect ratio (at most MAX_ASPECT : 1, see shown_aspect)
    centred in the window (letterbox)."""
    tw, th = tex_size
    ww, wh = win_size
    if min(tw, th, ww, wh) <= 0:
        return 0, 0, max(ww, 0), max(wh, 0)
    aspect, _ = shown_aspect(tex_size)
    s = min(ww / aspect, wh)
    w, h = max(1, round(aspect * s)), max(1, round(s))
    return (ww - w) // 2, (wh - h) // 2, w, h


def texel_at(viewport: tuple[int, int, int, int], tex_size: tuple[int, int], x: float, y: float):
    """(column, row from the top) of the texel shown at window point (x, y from the bottom, as GL's
    viewport), or None outside the shown target."""
    vx, vy, vw, vh = viewport
    u, v = (x - vx) / max(vw, 1), (y - vy) / max(vh, 1)
    if not (0.0 <= u < 1.0 and 0.0 <= v < 1.0):
        return None
    tw, th = tex_size
    return min(int(u * tw), tw - 1), min(int((1.0 - v) * th), th - 1)


def shown_value(values: np.ndarray, view: View, mode: str) -> np.ndarray:
    """The display colour (0-1 RGB) of raw texel values, as the inspector's shader maps them: a twin
    of _FS for the colour bar and the read-out."""
    v = np.asarray(values, np.float64)
    if mode == "ldr":
        return np.clip(v[..., :3], 0.0, 1.0)
    mapped = np.clip((v - view.offset) * view.scale, 0.0, 1.0)
    if mode == "grey":
        return np.repeat(mapped[..., :1], 3, axis=-1)
    if mode == "rg":
        return np.concatenate([mapped[..., :2], np.zeros(mapped.shape[:-1] + (1,))], axis=-1)
    from skinlab.scene.optics.color import srgb_encode

    return srgb_encode(mapped[..., :3])


def colour_bar(view: View, mode: str, n: int = 9) -> list[tuple[float, tuple[float, float, float]]]:
    """The values the display maps onto its range, offset to offset + 1/scale, with their display
    colours: n stops for the colour bar under the inspector's target."""
    top = view.offset + (1.0 / view.scale if view.scale else 1.0)
    if mode == "ldr":
        view, top = View(0.0, 1.0), 1.0
    stops = np.linspace(view.offset, top, n)
    cols = shown_value(np.repeat(stops[:, None], 3, axis=1), view, mode)
    return [(float(v), tuple(float(x) for x in c)) for v, c in zip(stops, cols)]


@dataclass
class View:
    offset: float = 0.0
    scale: float = 1.0
    auto: bool = True  # not yet ranged: range it when first shown


class Inspector:
    """Which target is shown, how, and the GL to draw it."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.current = FINAL
        self.views: dict[str, View] = {}
        self.prog = ctx.program(vertex_shader=_VS, fragment_shader=_FS)
        self.vbo = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], dtype="f4").tobytes())
        self.vao = ctx.vertex_array(self.prog, [(self.vbo, "2f", "in_pos")])
        # a sampler object overrides the texture's own state (e.g. a shadow map's comparison
        # mode) without changing what the renderer set on it
        self.sampler = ctx.sampler(
            filter=(moderngl.LINEAR, moderngl.LINEAR), repeat_x=False, repeat_y=False, compare_func=""
        )
        self._fbo = None
        self._pixels: tuple | None = None  # (key, array): the last target read for the read-out

    def texel(self, key, texture, column: int, row: int) -> np.ndarray:
        """Raw values of one texel (row 0 at the top); the target is read once per ``key`` (its name
        and the frame number), so hovering costs no read per mouse move."""
        if self._pixels is None or self._pixels[0] != key:
            self._pixels = (key, read_texture(texture))
        return self._pixels[1][row, column]

    # -- choosing ----------------------------------------------------------------------------
    def names(self, targets: dict) -> list[str]:
        return target_names(targets)

    def resolve(self, targets: dict) -> str | None:
        """The current target, falling back to the final image when it no longer exists."""
        if self.current in targets:
            return self.current
        names = self.names(targets)
        return names[0] if names else None

    def cycle(self, targets: dict, step: int = 1) -> str | None:
        names = self.names(targets)
        if not names:
            return None
        cur = self.resolve(targets)
        i = names.index(cur) if cur in names else 0
        self.current = names[(i + step) % len(names)]
        return self.current

    def view(self, name: str, texture=None) -> View:
        v = self.views.setdefault(name, View())
        if v.auto and texture is not None:
            mode = display_mode(texture)
            if mode is not None:
                v.offset, v.scale = auto_range(read_texture(texture), mode)
            v.auto = False
        return v

    def auto_range_now(self, targets: dict) -> View | None:
        name = self.resolve(targets)
        if name is None:
            return None
        self.views.pop(name, None)
        return self.view(name, targets[name])

    # -- drawing -----------------------------------------------------------------------------
    def draw(self, texture, view: View, viewport: tuple[int, int, int, int]) -> bool:
        """Draw into the currently bound framebuffer's ``viewport``; False if not displayable."""
        mode = display_mode(texture)
        if mode is None:
            return False
        self.ctx.viewport = viewport
        texture.use(0)
        self.sampler.use(0)
        try:
            self.prog["u_tex"].value = 0
            self.prog["u_mode"].value = MODES[mode]
            self.prog["u_scale"].value = float(view.scale)
            self.prog["u_offset"].value = float(view.offset)
            with gl_state(self.ctx):  # nothing enabled (the panel's drawing may have left blending on)
                self.vao.render(moderngl.TRIANGLES)
        finally:
            self.sampler.clear(0)  # the renderer's passes rely on the textures' own state
        return True

    def render_image(self, texture, view: View) -> np.ndarray:
        """The displayed mapping of ``texture`` at its own resolution: (H, W, 4) uint8, top row first."""
        size = texture.size
        if self._fbo is None or self._fbo.size != size:
            if self._fbo is not None:
                self._fbo.release()
            self._fbo = self.ctx.simple_framebuffer(size, components=4)
        self._fbo.use()
        self._fbo.clear(0.0, 0.0, 0.0, 1.0)
        if not self.draw(texture, view, (0, 0, *size)):
            raise ValueError(f"target cannot be displayed (format {texture.dtype} x{texture.components})")
        data = np.frombuffer(self._fbo.read(components=4), np.uint8).reshape(size[1], size[0], 4)
        return data[::-1].copy()

    def release(self) -> None:
        for o in (self.vao, self.vbo, self.prog, self.sampler, self._fbo):
            if o is not None:
                o.release()
