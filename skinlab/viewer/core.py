"""The viewer without a window: scene, renderer, hot reload, camera, panel, inspector.

:class:`ViewerCore` owns everything that does not depend on pyglet or Dear ImGui, so the
reload and display logic runs (and is tested) on a headless EGL context as well as in the
window. All GL work happens on the thread that calls its methods.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections import deque
from pathlib import Path

import moderngl
import numpy as np

from skinlab.cache import computing
from skinlab.gl.hot_reload import ShaderWatcher
from skinlab.gl.shader_source import ShaderLibrary
from skinlab.render.prepare import FramePreparer
from skinlab.render.registry import get_technique, techniques
from skinlab.render.renderer import FrameResult, Renderer
from skinlab.render.settings import RenderSettings
from skinlab.scene.materials import SSS_MODELS

from .camera import OrbitCamera
from .inspector import FINAL, Inspector, display_mode, fit_viewport, texel_at
from .panel import PanelModel
from .watch import preset_reloader, scene_reloader

log = logging.getLogger("skinlab.view")

SSS_CYCLE: tuple[str | None, ...] = (None, *SSS_MODELS)


def next_sss_model(current: str | None, step: int = 1) -> str | None:
    """None (each material's own model) -> every model of skinlab.scene.materials.SSS_MODELS -> None."""
    i = SSS_CYCLE.index(current) if current in SSS_CYCLE else 0
    return SSS_CYCLE[(i + step) % len(SSS_CYCLE)]


def cycle_techniques() -> list[str]:
    """The registered techniques T goes through: all but the slow ones (Technique.slow: image
    references taking seconds per frame), which the panel's technique list offers, marked."""
    return [t.name for t in techniques() if not t.slow]


def next_technique(current: str, step: int = 1) -> str:
    """The technique T (shift+T) switches to; the cycle skips slow techniques."""
    names = cycle_techniques()
    if current not in names:
        return names[0 if step > 0 else -1]
    return names[(names.index(current) + step) % len(names)]


def window_title(scene) -> str:
    source = getattr(scene, "source", None)
    return f"Skinlab - {scene.name}" + (f" ({Path(source).name})" if source else "")


class ViewerCore:
    def __init__(
        self,
        ctx: moderngl.Context,
        scene_path=None,
        settings: RenderSettings | None = None,
        watch: bool = True,
        shader_root: Path | None = None,
        settle_s: float = 0.05,
        use_watchdog: bool = True,
        background: bool = False,
        edits=None,
        prepare=None,
    ):
        """``edits`` and ``prepare``: see skinlab/viewer/watch.py scene_reloader (the command line's
        scene options, applied on every reload)."""
        self.ctx = ctx
        self.settings = settings or RenderSettings()
        self._technique_settings: dict = {}  # technique name -> its settings when last left
        library = ShaderLibrary(root=Path(shader_root)) if shader_root else ShaderLibrary()
        if not library.root.is_dir():
            raise FileNotFoundError(f"--shader-dir: no such folder: {library.root}")
        self.renderer = Renderer(ctx, library)
        # background: scene reloads load on a worker thread (the window's loop keeps answering)
        self.scene_src = scene_reloader(  # raises on a bad file
            scene_path, settle_s, watch, use_watchdog, background, edits=edits, prepare=prepare
        )
        self.presets = preset_reloader(settle_s, watch, use_watchdog)
        self.shaders = (
            ShaderWatcher(self.renderer.programs, library.root, settle_s=settle_s, use_watchdog=use_watchdog)
            if watch
            else None
        )
        self.panel = PanelModel(self.scene, presets=lambda: self.presets.value)
        self._file_camera = self.scene.camera.world_matrix.copy()
        self.orbit = OrbitCamera.from_camera_node(self.scene.camera, self.scene.world_bounds())
        self.inspector = Inspector(ctx)
        self.result: FrameResult | None = None
        self.render_error: str | None = None
        self.frames = 0  # frames rendered successfully
        self.failed_frames = 0
        self.log: deque[tuple[float, str, str]] = deque(maxlen=8)  # (time, level, text) for the overlay
        self._seen_panel_version = -1
        self._dirty = True
        self.preparer = FramePreparer()
        self._steps = None  # the frame in progress (Renderer.frame_steps), None between frames
        self._steps_done = 0
        self._reloads = 0

    # -- state -----------------------------------------------------------------------------------
    @property
    def scene(self):
        return self.scene_src.value

    @property
    def title(self) -> str:
        """The window title: Skinlab, the scene's name and its file (follows scene reloads)."""
        return window_title(self.scene)

    def note(self, level: str, text: str) -> None:
        self.log.append((time.monotonic(), level, text))
        getattr(log, level if level in ("info", "warning", "error") else "info")(text)

    def invalidate(self) -> None:
        self._dirty = True

    @property
    def dirty(self) -> bool:
        """Whether render() has work: a change since the last frame, or a frame in progress."""
        return self._steps is not None or self._dirty or self.panel.version != self._seen_panel_version

    def errors(self) -> list[str]:
        """Everything currently wrong, each naming its file (shown in the overlay)."""
        out = []
        if self.shaders is not None and self.shaders.errors:
            out += [f"shader: {e}" for e in self.shaders.errors]
        if self.scene_src.error:
            out.append(f"scene: {self.scene_src.error}")
        if self.presets.error:
            out.append(f"presets: {self.presets.error}")
        if self.render_error:
            out.append(f"render: {self.render_error}")
        if self.panel.error:
            out.append(f"panel: {self.panel.error}")
        return out

    def set_size(self, width: int, height: int) -> None:
        width, height = int(width), int(height)
        if width < 1 or height < 1 or (width, height) == self.settings.size:
            return
        self.settings = dataclasses.replace(self.settings, width=width, height=height)
        self.invalidate()

    def cycle_sss_model(self, step: int = 1) -> str | None:
        return self.set_sss_model(next_sss_model(self.settings.sss_model, step))

    def set_sss_model(self, model: str | None) -> str | None:
        """None: each material's own model; else one of SSS_MODELS for every material."""
        self.settings = dataclasses.replace(self.settings, sss_model=model)  # validated again
        self.note("info", f"SSS model: {model or 'per material'}")
        self.invalidate()
        return model

    def cycle_technique(self, step: int = 1) -> str:
        """T: the next registered technique, skipping slow ones (chosen in the panel instead)."""
        return self.set_technique(next_technique(self.settings.technique_name, step))

    def set_technique(self, technique: str) -> str:
        """How subsurface scattering is rendered (a registered technique, skinlab/render/registry.py);
        each technique keeps the settings it had when the viewer last left it. A slow one is noted
        as a warning (the overlay shows it in yellow)."""
        slow = get_technique(technique).slow  # a clear error for an unknown name
        self._technique_settings[self.settings.technique_name] = self.settings.technique
        chosen = self._technique_settings.get(technique, technique)
        self.settings = dataclasses.replace(self.settings, technique=chosen)  # validated again
        self.note("warning" if slow else "info", f"SSS technique: {technique}" + (f" ({slow})" if slow else ""))
        self.invalidate()
        return technique

    def set_technique_option(self, name: str, value) -> object:
        """Change one setting of the current technique (checked against its declaration)."""
        opts = self.settings.technique.options()
        if name not in opts:
            raise ValueError(
                f"{self.settings.technique_name} setting {name!r}: unknown; its settings: {', '.join(opts) or 'none'}"
            )
        self.settings = dataclasses.replace(self.settings, technique=self.settings.technique.replace(**{name: value}))
        self.note("info", f"{self.settings.technique_name} {name}: {getattr(self.settings.technique, name)}")
        self.invalidate()
        return getattr(self.settings.technique, name)

    def set_render_option(self, name: str, value) -> object:
        """Change one render setting the panel offers (RenderSettings.panel_options(): supersample,
        bounces, ...), checked against its declaration."""
        opts = self.settings.panel_options()
        if name not in opts:
            raise ValueError(f"render setting {name!r}: unknown; the declared ones: {', '.join(opts)}")
        self.settings = dataclasses.replace(self.settings, **{name: value})  # validated again
        self.note("info", f"{name}: {getattr(self.settings, name)}")
        self.invalidate()
        return getattr(self.settings, name)

    def reset_camera(self) -> None:
        self.orbit.reset()
        self.invalidate()

    # -- hot reload --------------------------------------------------------------------------------
    def poll_reloads(self) -> bool:
        """Apply settled shader, scene and preset changes; True when the image may change."""
        changed = False
        if self.shaders is not None:
            res = self.shaders.poll()
            if res is not None:
                changed = True
                if res:
                    for e in res:
                        self.note("error", f"shader compile failed, keeping the last good program: {e}")
                else:
                    self.note("info", "shaders reloaded")
        state = self.scene_src.poll()
        if state == "reloaded":
            self._adopt_scene()
            changed = True
        elif state == "failed":
            self.note("error", f"scene reload failed, keeping the last good scene: {self.scene_src.error}")
        state = self.presets.poll()
        if state == "reloaded":
            done = self.panel.reapply_presets()
            self.note("info", "presets reloaded" + (f"; re-applied {', '.join(done)}" if done else ""))
            changed = True
        elif state == "failed":
            self.note("error", f"preset reload failed, keeping the last good presets: {self.presets.error}")
        if changed:
            self._reloads += 1
            self.invalidate()
        return changed

    def _adopt_scene(self) -> None:
        scene = self.scene
        # textures are cached by path in the renderer: drop the ones whose files changed
        changed = {p.resolve() for p in self.scene_src.last_changed}
        cache = self.renderer.resources.textures
        for key in [k for k in cache if Path(k[0]).resolve() in changed]:
            cache.pop(key).release()
        self.renderer.forget_reuse()  # a changed file the input keys cannot see (a texture's pixels)
        self.panel.set_scene(scene)
        cam = scene.camera.world_matrix.copy()
        if not np.allclose(cam, self._file_camera):  # the file's camera moved: follow it
            self.orbit = OrbitCamera.from_camera_node(scene.camera, scene.world_bounds())
        self._file_camera = cam
        self.note("info", f"scene reloaded: {scene.source}")

    # -- frames ------------------------------------------------------------------------------------
    def render(self, budget_s: float | None = None) -> bool:
        """Render one frame into the renderer's targets; errors are reported, never raised. True
        when a frame was completed.

        ``budget_s`` None: the whole frame now (headless use, tests). A number (the window's event
        loop): never work much longer than that per call, so that the window keeps answering - the
        frame's slow CPU work (profile fits, tables, rays, seams) runs on a worker thread first
        (skinlab/render/prepare.py) and its passes run a few per call; the caller calls again on
        its next turn (the core stays dirty) and shows the last complete frame meanwhile
        (:attr:`waiting` says on what)."""
        if self._steps is None:
            self._seen_panel_version = self.panel.version
            self._dirty = False
            if budget_s is not None and not self.preparer.ready(self.scene, self.settings, self._content_version()):
                self._dirty = True  # come back: the frame waits on its preparation
                return False
            self.orbit.apply(self.scene.camera)
            self._steps = self.renderer.frame_steps(self.scene, self.settings, readback=False)
            self._steps_done = 0
        deadline = None if budget_s is None else time.monotonic() + budget_s
        try:
            while True:
                next(self._steps)
                self._steps_done += 1
                if deadline is not None and time.monotonic() > deadline:
                    return False  # the rest on the next call
        except StopIteration as done:
            self.result = done.value
        except Exception as exc:  # a failing new shader variant, a bad value...: keep running
            self._steps = None
            msg = str(exc).strip() or exc.__class__.__name__
            if msg != self.render_error:
                self.note("error", f"frame failed: {msg}")
            self.render_error = msg
            self.failed_frames += 1
            return False
        self._steps = None
        if self.render_error:
            self.note("info", "frames render again")
        self.render_error = None
        self.frames += 1
        return True

    @property
    def waiting(self) -> str | None:
        """What the next frame waits on (shown in the overlay), None when it waits on nothing."""
        if self.scene_src.loading:
            return f"reloading the scene: {', '.join(computing()) or 'reading files'}"
        if self._steps is not None:
            return f"frame in progress: {self._steps_done} passes run"
        s = self.preparer.waiting_s
        if s is None:
            return None
        work = ", ".join(computing()) or "planning"
        return f"preparing the frame for {s:.1f} s: {work}"

    def _content_version(self) -> tuple:
        """Changes with every edit of what a frame shows apart from the camera: the panel's edits
        and the reloads (a reloaded scene is a new object; presets and shaders bump the panel or
        the program cache)."""
        return (self.panel.version, self.renderer.programs.generation, self._reloads)

    def targets(self) -> dict:
        frame = self.renderer.last_frame
        return dict(frame.targets) if frame is not None else {}

    def current_target(self):
        targets = self.targets()
        name = self.inspector.resolve(targets)
        return (name, targets[name]) if name is not None else (None, None)

    def readout(self, x: float, y: float, size: tuple[int, int]):
        """What the inspected target holds under window point (x, y from the bottom, framebuffer
        pixels) of a window of ``size``: (target, column, row from the top, raw values), or None off
        the target (the panel's pixel read-out)."""
        name, tex = self.current_target()
        if tex is None or display_mode(tex) is None:
            return None
        where = texel_at(fit_viewport(tex.size, size), tex.size, x, y)
        if where is None:
            return None
        values = self.inspector.texel((name, self.renderer.frame_number), tex, *where)
        return name, where[0], where[1], values

    def draw(self, framebuffer, size: tuple[int, int], background=(0.1, 0.1, 0.12)) -> str | None:
        """Show the inspected target in ``framebuffer`` (e.g. ``ctx.screen``), letterboxed."""
        framebuffer.use()
        self.ctx.viewport = (0, 0, *size)
        self.ctx.clear(*background, 1.0)
        name, tex = self.current_target()
        if tex is None:
            return None
        view = self.inspector.view(name, tex)
        if not self.inspector.draw(tex, view, fit_viewport(tex.size, size)):
            return None
        return name

    # -- screenshots -------------------------------------------------------------------------------
    def screenshot(self, path) -> Path:
        """PNG: the inspected target as displayed (no UI), at its own resolution. EXR: its raw
        linear values (the HDR radiance when the final tone-mapped image is inspected)."""
        from skinlab.image_output import image_format, write_image

        from .inspector import read_texture

        fmt = image_format(path)
        targets = self.targets()
        name = self.inspector.resolve(targets)
        if name is None:
            raise ValueError(f"{path}: no frame has been rendered yet ({self.render_error or 'no targets'})")
        if fmt == "png":
            pixels = self.inspector.render_image(targets[name], self.inspector.view(name, targets[name]))
        else:
            src = "hdr_color" if name == FINAL and "hdr_color" in targets else name
            pixels = read_texture(targets[src])
        out = write_image(path, pixels)
        self.note("info", f"screenshot: {Path(out).resolve()}")
        return Path(out)

    # -- the edited scene --------------------------------------------------------------------------
    def save_scene(self, path) -> Path:
        """The scene as it is now (materials edited in the panel, the orbited camera, the key light) as a
        scene file (skinlab/scene/scene_save.py); loading it gives the same materials, camera and lights."""
        from skinlab.scene.scene_save import save_scene

        self.orbit.apply(self.scene.camera)
        out = save_scene(self.scene, path)
        self.note("info", f"scene saved: {Path(out).resolve()}")
        return Path(out)

    def close(self) -> None:
        for w in (self.shaders, self.scene_src, self.presets):
            if w is not None:
                w.stop()
        self.inspector.release()
        self.renderer.release()
