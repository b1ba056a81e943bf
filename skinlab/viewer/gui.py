"""Dear ImGui (imgui-bundle) drawing of the overlay and the parameter panel.

Only drawing lives here: which widget a parameter gets, clamping and applying edits are in
``panel.py`` (PanelModel), so this module stays a thin translation of its state into widgets.
"""

from __future__ import annotations

import math
import time

import numpy as np
from imgui_bundle import imgui

from skinlab.render.registry import techniques
from skinlab.scene.materials import SSS_MODELS

from .core import ViewerCore
from .inspector import display_mode
from .panel import (
    angles_from_direction,
    direction_from_angles,
    render_widgets,
    sss_override_note,
    technique_value,
    technique_widgets,
    texture_text,
    widget_label,
)

RED = imgui.ImVec4(1.0, 0.45, 0.4, 1.0)
GREY = imgui.ImVec4(0.7, 0.7, 0.7, 1.0)
YELLOW = imgui.ImVec4(1.0, 0.85, 0.4, 1.0)


class Gui:
    on_save_scene = None  # set by the window: Ctrl+S's action

    def __init__(self, core: ViewerCore):
        self.core = core
        self.show_panel = True
        self._text: dict[str, str] = {}  # texture path fields being typed
        self.panel_rect: tuple[float, float, float, float] | None = None  # x, y (from the top), w, h

    def over_panel(self, x: float, y_from_top: float) -> bool:
        """Whether a point (window coordinates, y down) lies on the panel as last drawn. The window
        asks this for wheel events, which can arrive before Dear ImGui's next frame knows where the
        mouse is (so want_capture_mouse alone lets a slow frame's scroll zoom the camera too)."""
        if not self.show_panel or self.panel_rect is None:
            return False
        px, py, pw, ph = self.panel_rect
        return px <= x <= px + pw and py <= y_from_top <= py + ph

    # -- overlay: timings, errors, messages ---------------------------------------------------
    def overlay(self, ui_fps: float) -> None:
        core = self.core
        imgui.set_next_window_pos(imgui.ImVec2(6, 6), imgui.Cond_.always)
        imgui.set_next_window_bg_alpha(0.55)
        flags = (
            imgui.WindowFlags_.no_decoration
            | imgui.WindowFlags_.always_auto_resize
            | imgui.WindowFlags_.no_saved_settings
            | imgui.WindowFlags_.no_focus_on_appearing
            | imgui.WindowFlags_.no_nav
            | imgui.WindowFlags_.no_move
        )
        imgui.begin("overlay", None, flags)
        res = core.result
        if res is not None:
            t = res.timings
            imgui.text(f"frame {t.frame_ms:7.2f} ms, render call {res.cpu_ms:.1f} ms")
            for line in t.table().splitlines():  # the same table as skinlab render and demo print
                imgui.text(line)
            for p in res.plan.passes:  # kept from an earlier frame (skinlab/render/reuse.py)
                if p.reused_since is not None:
                    imgui.text_colored(GREY, f"  {p.name:<16} reused: inputs unchanged since frame {p.reused_since}")
        if core.waiting:  # the last complete frame is shown meanwhile
            imgui.text_colored(YELLOW, core.waiting)
        name, _ = core.current_target()
        s = core.settings
        imgui.text_colored(
            GREY,
            f"{s.width}x{s.height}  target: {name}  sss: {s.sss_model or 'per material'} ({s.technique_name})"
            f"  ui {ui_fps:4.0f} fps",
        )
        errors = core.errors()
        if errors:
            width = imgui.get_io().display_size.x
            imgui.push_text_wrap_pos(max(width - 460.0 if self.show_panel else width - 20.0, 200.0))
            for e in errors:
                imgui.text_colored(RED, e)
            imgui.pop_text_wrap_pos()
        now = time.monotonic()
        for when, level, text in core.log:
            if now - when < 6.0 and level != "error":
                imgui.text_colored(YELLOW, text)
        imgui.end()

    # -- the panel ------------------------------------------------------------------------------
    def panel(self) -> None:
        if not self.show_panel:
            return
        io = imgui.get_io()
        w = min(440.0, io.display_size.x * 0.5)  # room for a label and three number fields
        imgui.set_next_window_pos(imgui.ImVec2(io.display_size.x - w - 6, 6), imgui.Cond_.first_use_ever)
        imgui.set_next_window_size(imgui.ImVec2(w, io.display_size.y * 0.9), imgui.Cond_.first_use_ever)
        expanded, _ = imgui.begin("Skinlab (H hides)", None)
        pos, size = imgui.get_window_pos(), imgui.get_window_size()
        self.panel_rect = (pos.x, pos.y, size.x, size.y)
        if expanded:
            if self.core.waiting:  # slow work runs off this thread: say what the next frame waits on
                imgui.text_colored(YELLOW, self.core.waiting)
            self._render_section()
            self._inspector_section()
            self._scene_section()
            self._material_section()
            self._selected_light_section()
            self._light_section()
            self._environment_section()
        imgui.end()

    def _render_section(self) -> None:
        core = self.core
        if not imgui.collapsing_header("Render", imgui.TreeNodeFlags_.default_open):
            return
        options = ["per material", *SSS_MODELS]
        cur = core.settings.sss_model or "per material"
        if imgui.begin_combo("SSS model (M)", cur):
            for o in options:
                clicked, _ = imgui.selectable(o, o == cur)
                if clicked:
                    core.set_sss_model(None if o == "per material" else o)
            imgui.end_combo()
        cur = core.settings.technique_name
        if imgui.begin_combo("technique (T)", cur):
            for t in techniques():  # T skips the slow ones; here they are, marked
                text = f"{t.name}  ({t.slow})" if t.slow else t.name
                clicked, _ = imgui.selectable(f"{text}##{t.name}", t.name == cur)
                if imgui.is_item_hovered():
                    imgui.set_tooltip(t.description)
                if clicked:
                    core.set_technique(t.name)
            imgui.end_combo()
        self._technique_options()
        self._render_options()
        if imgui.button("Reset camera (R)"):
            core.reset_camera()
        imgui.same_line()
        if imgui.button("Save scene (Ctrl+S)") and self.on_save_scene is not None:
            self.on_save_scene()

    def _technique_options(self) -> None:
        """The current technique's settings (panel.technique_widgets: from its declaration)."""
        st = self.core.settings.technique
        self._option_widgets(technique_widgets(st), st, st.technique, self.core.set_technique_option)

    def _render_options(self) -> None:
        """The declared render settings (panel.render_widgets): supersampling, interreflection."""
        st = self.core.settings
        self._option_widgets(render_widgets(st), st, "render", self.core.set_render_option)

    def _option_widgets(self, widgets, st, scope: str, apply) -> None:
        core = self.core
        for w in widgets:
            label = f"{widget_label(w)}##{scope}"
            new = w.value
            if w.widget.endswith("_or_auto"):
                changed, auto = imgui.checkbox(f"{w.param} automatic##{scope}", w.value is None)
                new = None if auto else (w.value if w.value is not None else w.range[0])
            else:
                changed = False
            if new is not None:
                if w.widget.startswith("checkbox"):
                    c, new = imgui.checkbox(label, bool(new))
                elif w.widget.startswith("slider_int"):
                    c, new = imgui.slider_int(label, int(new), int(w.range[0]), int(w.range[1]))
                else:
                    c, new = imgui.slider_float(label, float(new), float(w.range[0]), float(w.range[1]))
                changed = changed or c
            if imgui.is_item_hovered():
                imgui.set_tooltip(w.doc)
            if changed:
                try:
                    apply(w.param, technique_value(st, w.param, new))
                except ValueError as exc:
                    core.note("error", str(exc))

    def _inspector_section(self) -> None:
        core = self.core
        if not imgui.collapsing_header("Pass inspector (P / Tab)", imgui.TreeNodeFlags_.default_open):
            return
        targets = core.targets()
        cur = core.inspector.resolve(targets) or "-"
        if imgui.begin_combo("target", cur):
            for n in core.inspector.names(targets):
                tex = targets[n]
                mode = display_mode(tex)
                label = f"{n}  {tex.size[0]}x{tex.size[1]} {mode or 'not viewable'}"
                clicked, _ = imgui.selectable(label, n == cur)
                if clicked:
                    core.inspector.current = n
            imgui.end_combo()
        if cur in targets:
            view = core.inspector.view(cur, targets[cur])
            mode = display_mode(targets[cur])
            if mode in ("color", "grey", "rg"):
                ch, v = imgui.slider_float("scale", view.scale, 1e-3, 1e4, "%.4g", imgui.SliderFlags_.logarithmic)
                if ch:
                    view.scale = v
                ch, v = imgui.input_float("offset", view.offset, 0.0, 0.0, "%.5g")
                if ch and math.isfinite(v):
                    view.offset = v
                if imgui.button("Auto range (N)"):
                    core.inspector.auto_range_now(targets)

    def _scene_section(self) -> None:
        panel = self.core.panel
        if not imgui.collapsing_header("Scene", imgui.TreeNodeFlags_.default_open):
            return
        imgui.text_colored(GREY, str(self.core.scene.source))
        for row in panel.tree():
            imgui.indent(8.0 * row.depth + 1.0)
            clicked, _ = imgui.selectable(f"{row.label}##{id(row.node)}", row.node is panel.selected)
            if clicked:
                panel.selected = row.node
            imgui.unindent(8.0 * row.depth + 1.0)

    def _material_section(self) -> None:
        panel = self.core.panel
        m = panel.material
        if m is None or not imgui.collapsing_header("Material", imgui.TreeNodeFlags_.default_open):
            return
        users = panel.material_users()
        imgui.text(f"'{m.name}' on {len(users)} node(s)")
        names = panel.preset_names()
        if names and imgui.begin_combo("Jensen preset", panel.applied_presets.get(id(m), "(choose)")):
            for n in names:
                clicked, _ = imgui.selectable(n, False)
                if clicked:
                    self._try(panel.apply_preset, n)
            imgui.end_combo()
        note = sss_override_note(m, self.core.settings.sss_model)
        if note:
            imgui.push_text_wrap_pos(0.0)
            imgui.text_colored(YELLOW, note)
            imgui.pop_text_wrap_pos()
        widgets = panel.widgets()
        # widgets leave room for the longest label, so no label is cut off at the panel's edge
        label_w = max((imgui.calc_text_size(widget_label(w)).x for w in widgets), default=0.0)
        imgui.push_item_width(-(label_w + imgui.get_style().item_inner_spacing.x + 4.0))
        for w in widgets:
            label = widget_label(w)
            if w.param == "sss_model" and note:
                label = f"{w.param} (M overrides)"
            if w.widget == "slider_float":
                ch, v = imgui.slider_float(label, float(w.value), w.range[0], w.range[1])
            elif w.widget == "color_edit3":  # linear values 0-1, as in the scene file
                ch, v = imgui.color_edit3(label, [float(x) for x in w.value], imgui.ColorEditFlags_.float)
            elif w.widget == "drag_float3":
                speed = max((w.range[1] - w.range[0]) * 1e-4, 1e-3)
                flags = imgui.SliderFlags_.logarithmic if w.logarithmic else 0
                ch, v = imgui.drag_float3(
                    label, [float(x) for x in w.value], speed, w.range[0], w.range[1], "%.3f", flags
                )
            elif w.widget == "drag_float2":
                speed = max((w.range[1] - w.range[0]) * 1e-5, 1e-3)
                ch, v = imgui.drag_float2(label, [float(x) for x in w.value], speed, w.range[0], w.range[1], "%.3f")
            elif w.widget == "combo":
                ch, v = False, w.value
                if imgui.begin_combo(label, str(w.value)):
                    for c in w.choices:
                        clicked, _ = imgui.selectable(c, c == w.value)
                        if clicked:
                            ch, v = True, c
                    imgui.end_combo()
            elif w.widget == "file_path":
                key = f"{id(m)}:{w.param}"
                text = self._text.get(key, texture_text(w.value))
                ch_text, text = imgui.input_text(label, text, imgui.InputTextFlags_.enter_returns_true)
                self._text[key] = text
                ch, v = ch_text, text
                if ch:
                    self._text.pop(key, None)
            else:  # widget_for() only returns the kinds above
                raise ValueError(f"parameter {w.param}: no drawing code for widget {w.widget!r}")
            if imgui.is_item_hovered() and (w.doc or w.widget == "file_path"):
                tip = w.doc
                if w.widget == "file_path":
                    tip += f"\n{w.value or 'no map'}\n(a name alone: next to the current map)"
                imgui.set_tooltip(tip)
            if ch:
                self._try(panel.edit, w.param, v)
        imgui.pop_item_width()
        if panel.error:
            imgui.push_text_wrap_pos(0.0)
            imgui.text_colored(RED, panel.error)
            imgui.pop_text_wrap_pos()

    def _light_section(self) -> None:
        panel = self.core.panel
        light = panel.key_light()
        if light is None or not imgui.collapsing_header("Key light", imgui.TreeNodeFlags_.default_open):
            return
        d = panel.light_direction()
        az, el = angles_from_direction(d)
        imgui.text(f"'{light.name}' ({light.kind}) travels {np.round(d, 3).tolist()}")
        ch1, az = imgui.slider_float("azimuth (deg)", az, -180.0, 180.0)
        ch2, el = imgui.slider_float("elevation (deg)", el, -89.0, 89.0)
        if ch1 or ch2:
            self._try(panel.set_light_direction, direction_from_angles(az, el))

    def _selected_light_section(self) -> None:
        """The light selected in the scene tree: colour, intensity, shadow and its kind's shape
        (panel.light_widgets)."""
        panel = self.core.panel
        light = panel.light
        if light is None or not imgui.collapsing_header("Light", imgui.TreeNodeFlags_.default_open):
            return
        imgui.text(f"'{light.name}' ({light.kind})")
        for w in panel.light_widgets():
            label = f"{widget_label(w)}##light"
            if w.widget == "checkbox":
                ch, v = imgui.checkbox(label, bool(w.value))
            elif w.widget == "color_edit3":
                ch, v = imgui.color_edit3(label, [float(x) for x in w.value], imgui.ColorEditFlags_.float)
            else:
                ch, v = imgui.slider_float(label, float(w.value), w.range[0], w.range[1])
            if imgui.is_item_hovered() and w.doc:
                imgui.set_tooltip(w.doc)
            if ch:
                self._try(panel.edit_light, w.param, v)

    def _environment_section(self) -> None:
        """The environment map: a bundled one or a file, its rotation, intensity and background."""
        panel = self.core.panel
        if not imgui.collapsing_header("Environment map", imgui.TreeNodeFlags_.default_open):
            return
        cur = panel.environment_name()
        if imgui.begin_combo("map##env", cur if len(cur) < 40 else "..." + cur[-37:]):
            for c in panel.environment_choices():
                clicked, _ = imgui.selectable(c, c == cur)
                if clicked:
                    self._try(panel.set_environment, c)
            imgui.end_combo()
        text = self._text.get("env:file", "")
        ch, text = imgui.input_text("file (.exr/.hdr)##env", text, imgui.InputTextFlags_.enter_returns_true)
        self._text["env:file"] = text
        if imgui.is_item_hovered():
            imgui.set_tooltip("an equirectangular linear HDR map, 2:1 (relative to the scene's folder); Enter loads it")
        if ch and text.strip():
            self._try(panel.set_environment, text)
        env = self.core.scene.environment
        if env.map is None:
            return
        ch, v = imgui.slider_float("rotation (deg)##env", float(env.rotation_deg), -180.0, 180.0)
        if ch:
            self._try(panel.set_environment_value, "rotation_deg", v)
        ch, v = imgui.slider_float(
            "intensity##env", float(env.intensity), 0.0, 8.0, "%.3f", imgui.SliderFlags_.logarithmic
        )
        if ch:
            self._try(panel.set_environment_value, "intensity", v)
        ch, v = imgui.checkbox("show background##env", bool(env.show_background))
        if ch:
            self._try(panel.set_environment_value, "show_background", v)

    def _try(self, fn, *args) -> None:
        try:
            fn(*args)
        except ValueError as exc:  # shown in red in the panel and overlay (panel.error)
            self.core.panel.error = str(exc)
