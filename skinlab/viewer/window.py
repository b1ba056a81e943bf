"""The desktop window: pyglet for the window and input, moderngl on the window's GL context for
everything drawn, Dear ImGui (imgui-bundle's pyglet backend) for the overlay and the panel.

Mouse: left drag orbits around the camera target, right or middle drag (or shift + left) pans,
the wheel zooms. Keys: R reset camera, M / shift+M cycle the SSS model, T / shift+T cycle the
subsurface technique (the registry's order, skinlab/render/registry.py), P or Tab / shift+P
cycle the inspected target, [ and ] halve/double its display scale, N auto-ranges it,
S saves a PNG screenshot, shift+S an EXR, H hides the panel, Esc quits.

The loop renders a new frame only when something changed (camera, parameters, size, a
reload), or every iteration with ``continuous`` / ``frames``; between frames it redraws the UI
and sleeps, so an idle window costs little CPU on llvmpipe.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import sys
import time
from datetime import datetime
from pathlib import Path

from skinlab.render.settings import RenderSettings

log = logging.getLogger("skinlab.view")
# the most a turn of the event loop spends on a frame's passes before it answers events again (a
# slow frame is finished over several turns; its CPU preparation runs on a worker thread)
FRAME_SLICE_S = 0.05


class ViewerError(ValueError):
    """The viewer cannot start (no display, no GL 3.3): one clear line, exit status 2."""


def _select_pyopengl_platform() -> None:
    """imgui-bundle's OpenGL backend draws through PyOpenGL, which must use the window's GLX
    context; the CLI defaults PYOPENGL_PLATFORM to 'egl' for headless rendering."""
    want = "glx" if sys.platform.startswith("linux") else None
    if "OpenGL" in sys.modules:
        current = os.environ.get("PYOPENGL_PLATFORM")
        if want and current != want:
            raise ViewerError(
                f"PyOpenGL was already loaded for platform {current!r}; the viewer needs {want!r} "
                f"(start it in its own process: skinlab view)"
            )
        return
    if want:
        os.environ["PYOPENGL_PLATFORM"] = want
    else:
        os.environ.pop("PYOPENGL_PLATFORM", None)


class ViewerWindow:
    def __init__(
        self,
        scene_path=None,
        size=(960, 720),
        watch: bool = True,
        screenshot_dir="out/screenshots",
        shader_root=None,
        shadow_size: int | None = None,
        technique: str | None = None,
        settle_s: float = 0.05,
        continuous: bool = False,
        show_ui: bool = True,
        settings: RenderSettings | None = None,
        edits=None,
        prepare=None,
    ):
        """``settings`` (its size follows the window) replaces ``shadow_size`` and ``technique`` when given
        (without either: RenderSettings' declared defaults);
        ``edits`` and ``prepare``: the command line's scene options (skinlab/viewer/core.py ViewerCore)."""
        if sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
            raise ViewerError(
                "no X display (DISPLAY is not set); on a machine without a screen run it under "
                "Xvfb, e.g. `xvfb-run -a skinlab view`"
            )
        _select_pyopengl_platform()
        import moderngl
        import pyglet

        pyglet.options.dpi_scaling = "stretch"  # window and mouse in logical units, as imgui expects
        w, h = size
        try:
            config = pyglet.gl.Config(
                double_buffer=True, depth_size=24, major_version=3, minor_version=3, forward_compatible=True
            )
            self.window = pyglet.window.Window(w, h, caption="Skinlab", resizable=True, vsync=False, config=config)
        except Exception as exc:  # NoSuchDisplayException, NoSuchConfigException, ...
            raise ViewerError(
                f"cannot open a window with an OpenGL 3.3 core context on display {os.environ.get('DISPLAY')!r}: {exc}"
            ) from None
        self.window.switch_to()
        self.ctx = moderngl.create_context(require=330)
        from skinlab.gl.context import describe

        from .core import ViewerCore

        fw, fh = self.window.get_framebuffer_size()
        if settings is None:
            given = {"shadow_size": shadow_size, "technique": technique}
            settings = RenderSettings(**{k: v for k, v in given.items() if v is not None})
        settings = dataclasses.replace(settings, width=max(fw, 1), height=max(fh, 1))
        try:
            self.core = ViewerCore(
                self.ctx,
                scene_path,
                settings,
                watch=watch,
                shader_root=shader_root,
                settle_s=settle_s,
                background=True,
                edits=edits,
                prepare=prepare,
            )
        except BaseException:
            self.window.close()
            raise
        log.info("GL: %s", describe(self.ctx))
        self.window.set_caption(self.core.title)
        self.screenshot_dir = Path(screenshot_dir)
        self.continuous = continuous
        self.closed = False
        self._init_imgui(show_ui)
        self.window.push_handlers(self)  # ours first, imgui's on top (it never consumes events)
        if self.imgui_impl is not None:
            self.imgui_impl._attach_callbacks(self.window)
        self._ui_times: list[float] = []

    # -- imgui -------------------------------------------------------------------------------
    def _init_imgui(self, show_ui: bool) -> None:
        from imgui_bundle import imgui
        from imgui_bundle.python_backends import pyglet_backend

        from .gui import Gui, apply_style

        self.imgui = imgui
        imgui.create_context()
        apply_style()
        imgui.get_io().set_ini_filename(None)  # no imgui.ini in the working folder
        self.imgui_impl = pyglet_backend.create_renderer(self.window, attach_callbacks=False)
        self.gui = Gui(self.core)
        self.gui.on_save_scene = self.save_scene
        self.gui.show_panel = show_ui
        self.show_ui = show_ui

    def _wants(self, what: str) -> bool:
        io = self.imgui.get_io()
        return bool(getattr(io, what)) if self.show_ui else False

    # -- pyglet events -------------------------------------------------------------------------
    def on_close(self):
        self.closed = True
        return True  # EVENT_HANDLED: the loop releases GL objects first, then closes the window

    def on_resize(self, width, height):
        fw, fh = self.window.get_framebuffer_size()
        self.core.set_size(fw, fh)

    def on_mouse_drag(self, x, y, dx, dy, buttons, modifiers):
        import pyglet

        if self._wants("want_capture_mouse"):
            return
        mouse, key = pyglet.window.mouse, pyglet.window.key
        cam = self.core.scene.camera
        if buttons & (mouse.RIGHT | mouse.MIDDLE) or (buttons & mouse.LEFT and modifiers & key.MOD_SHIFT):
            self.core.orbit.pan(dx, dy, self.window.height, cam.yfov)
        elif buttons & mouse.LEFT:
            self.core.orbit.orbit(dx, dy)
        else:
            return
        self.core.invalidate()

    def on_mouse_scroll(self, x, y, scroll_x, scroll_y):
        # pyglet's y grows upwards, Dear ImGui's downwards
        if self._wants("want_capture_mouse") or self.gui.over_panel(x, self.window.height - y):
            return
        self.core.orbit.zoom(scroll_y)
        self.core.invalidate()

    def on_key_press(self, symbol, modifiers):
        import pyglet

        key = pyglet.window.key
        if self._wants("want_capture_keyboard") or self._wants("want_text_input"):
            return
        shift = bool(modifiers & key.MOD_SHIFT)
        core = self.core
        if symbol == key.R:
            core.reset_camera()
        elif symbol == key.M:
            core.cycle_sss_model(-1 if shift else 1)
        elif symbol == key.T:
            core.cycle_technique(-1 if shift else 1)
        elif symbol in (key.P, key.TAB):
            name = core.inspector.cycle(core.targets(), -1 if shift else 1)
            core.note("info", f"inspecting {name}")
        elif symbol == key.S and modifiers & key.MOD_CTRL:
            self.save_scene()
        elif symbol == key.S:
            self.save_screenshot("exr" if shift else "png")
        elif symbol == key.H:
            self.show_ui = not self.show_ui
            self.gui.show_panel = self.show_ui
        elif symbol in (key.BRACKETLEFT, key.BRACKETRIGHT):
            name, tex = core.current_target()
            if tex is not None:
                v = core.inspector.view(name, tex)
                v.scale *= 0.5 if symbol == key.BRACKETLEFT else 2.0
        elif symbol == key.N:
            core.inspector.auto_range_now(core.targets())

    # -- screenshots --------------------------------------------------------------------------
    def save_screenshot(self, fmt: str = "png", path=None) -> Path | None:
        if path is None:
            name, _ = self.core.current_target()
            stamp = datetime.now().strftime("%Y%m%d-%H%M%S-%f")[:-3]
            path = self.screenshot_dir / f"{self.core.scene.name}-{name}-{stamp}.{fmt}"
        try:
            return self.core.screenshot(path)
        except (OSError, ValueError) as exc:
            self.core.note("error", f"screenshot failed: {exc}")
            return None

    def save_scene(self, path=None) -> Path | None:
        """Ctrl+S: the edited scene as TOML beside the screenshots (skinlab/scene/scene_save.py)."""
        if path is None:
            stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
            path = self.screenshot_dir / f"{self.core.scene.name}-edited-{stamp}.toml"
        try:
            return self.core.save_scene(path)
        except (OSError, ValueError) as exc:
            self.core.note("error", f"saving the scene failed: {exc}")
            return None

    # -- the loop -----------------------------------------------------------------------------
    def step(self, force_render: bool = False) -> bool:
        """One iteration: events, reloads, maybe (part of) a frame, the display and the UI. True if a
        frame was completed (or failed) in this iteration."""
        import pyglet

        imgui = self.imgui
        pyglet.clock.tick()
        self.window.switch_to()
        self.window.dispatch_events()
        if self.closed:
            return False
        core = self.core
        if core.poll_reloads() and self.window.caption != core.title:
            self.window.set_caption(core.title)  # a reloaded scene may have a new name
        rendered = False
        fw, fh = self.window.get_framebuffer_size()
        if fw > 0 and fh > 0:
            core.set_size(fw, fh)
            if force_render or self.continuous or core.dirty:
                ended = core.frames + core.failed_frames
                core.render(budget_s=FRAME_SLICE_S)
                rendered = core.frames + core.failed_frames > ended  # a frame completed (or failed)
            core.draw(self.ctx.screen, (fw, fh))
            self.imgui_impl.process_inputs()
            imgui.new_frame()
            if self.show_ui:
                now = time.monotonic()
                self._ui_times = [t for t in self._ui_times if now - t < 1.0] + [now]
                self.gui.overlay(len(self._ui_times))
                self.gui.panel()
            imgui.render()
            _ = self.ctx.error  # drop moderngl's stale GL error flag: PyOpenGL checks glGetError after each call
            self.imgui_impl.render(imgui.get_draw_data())
            self.window.flip()
        return rendered

    def run(self, frames: int | None = None, screenshot=None) -> int:
        """Interactive until closed, or exactly ``frames`` frames then exit (writing ``screenshot``)."""
        attempts = 0
        try:
            while not self.closed:
                rendered = self.step(force_render=frames is not None)
                attempts += rendered
                if frames is not None and attempts >= frames:
                    break
                if not rendered and not self.continuous:
                    time.sleep(1 / 60)  # idle: keep the UI responsive without spinning
            if frames is not None:
                if self.core.render_error:
                    raise ValueError(f"the last frame failed: {self.core.render_error}")
                if screenshot:
                    out = self.core.screenshot(screenshot)
                    print(f"wrote {Path(out).resolve()}")
        finally:
            self.close()
        return 0

    def close(self) -> None:
        if getattr(self, "_closed_all", False):
            return
        self._closed_all = True
        try:
            self.imgui_impl.shutdown()
            self.imgui.destroy_context()
        except Exception as exc:  # shutting down: report, go on releasing
            log.debug("imgui shutdown: %s", exc)
        self.core.close()
        self.window.close()
