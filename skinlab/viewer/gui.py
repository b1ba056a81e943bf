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
from .inspector import colour_bar, display_mode, shown_aspect
from .panel import (
    EXPOSURE,
    LIGHT_COLOR_MAX,
    LIGHT_INTENSITY,
    angles_from_direction,
    direction_from_angles,
    light_widgets,
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


def apply_style() -> None:
    """Slider grabs narrow and see-through, so a slider's digits stay readable under its handle."""
    style = imgui.get_style()
    style.grab_min_size = 6.0
    c = style.color_(imgui.Col_.slider_grab)
    style.set_color_(imgui.Col_.slider_grab, imgui.ImVec4(c.x, c.y, c.z, 0.45))
    c = style.color_(imgui.Col_.slider_grab_active)
    style.set_color_(imgui.Col_.slider_grab_active, imgui.ImVec4(c.x, c.y, c.z, 0.6))


LAYOUT: dict[str, float] = {}  # row label -> its top on screen in the last frame (tests check it stays put)


class Rows:
    """Rows of 'label | widget' in a two-column table: the label column as wide as its longest
    label, the widget column the rest. No label is cut off at the panel's edge and no widget (a
    long file name) runs into its label. Widgets drawn in a row take hidden labels ("##...")."""

    def __init__(self, table_id: str, labels):
        self.id = table_id
        self.width = max((imgui.calc_text_size(l).x for l in labels), default=0.0) + 8.0
        self.open = False

    def __enter__(self) -> Rows:
        self.open = imgui.begin_table(self.id, 2, imgui.TableFlags_.sizing_fixed_fit)
        if self.open:
            imgui.table_setup_column("label", imgui.TableColumnFlags_.width_fixed, self.width)
            imgui.table_setup_column("widget", imgui.TableColumnFlags_.width_stretch)
        return self

    def row(self, label: str, tip: str = "") -> None:
        imgui.table_next_row()
        imgui.table_next_column()
        LAYOUT[f"{self.id}/{label}"] = imgui.get_cursor_screen_pos().y
        imgui.align_text_to_frame_padding()
        imgui.text(label)
        if tip and imgui.is_item_hovered():
            imgui.set_tooltip(tip)
        imgui.table_next_column()
        imgui.set_next_item_width(-1.0)

    def __exit__(self, *exc) -> None:
        if self.open:
            imgui.end_table()


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
            # slow work runs off this thread: say what the next frame waits on. The line is always
            # there, so that it appearing cannot move the rows under a dragging mouse
            waiting = self.core.waiting
            imgui.text_colored(YELLOW if waiting else GREY, waiting or "frame up to date")
            self._render_section()
            self._inspector_section()
            self._scene_section()
            self._material_section()
            self._lights_section()
            self._environment_section()
        imgui.end()

    def _render_section(self) -> None:
        core = self.core
        if not imgui.collapsing_header("Render", imgui.TreeNodeFlags_.default_open):
            return
        tech, rend = technique_widgets(core.settings.technique), render_widgets(core.settings)
        labels = ["SSS model (M)", "technique (T)", "exposure"] + [self._option_label(w) for w in tech + rend]
        with Rows("render", labels) as rows:
            if not rows.open:
                return
            options = ["per material", *SSS_MODELS]
            cur = core.settings.sss_model or "per material"
            rows.row("SSS model (M)")
            if imgui.begin_combo("##sss_model", cur):
                for o in options:
                    clicked, _ = imgui.selectable(o, o == cur)
                    if clicked:
                        core.set_sss_model(None if o == "per material" else o)
                imgui.end_combo()
            cur = core.settings.technique_name
            rows.row("technique (T)")
            if imgui.begin_combo("##technique", cur):
                for t in techniques():  # T skips the slow ones; here they are, marked
                    text = f"{t.name}  ({t.slow})" if t.slow else t.name
                    clicked, _ = imgui.selectable(f"{text}##{t.name}", t.name == cur)
                    if imgui.is_item_hovered():
                        imgui.set_tooltip(t.description)
                    if clicked:
                        core.set_technique(t.name)
                imgui.end_combo()
            rows.row(
                "exposure", "linear multiplier on radiance before tone mapping (the scene's [environment] exposure)"
            )
            ch, v = imgui.slider_float(
                "##exposure", core.panel.exposure(), *EXPOSURE, "%.3g", imgui.SliderFlags_.logarithmic
            )
            if ch:
                core.panel.set_exposure(v)
            st = core.settings.technique
            self._option_rows(rows, tech, st, st.technique, core.set_technique_option)
            self._option_rows(rows, rend, core.settings, "render", core.set_render_option)
        if imgui.button("Reset camera (R)"):
            core.reset_camera()
        imgui.same_line()
        if imgui.button("Save scene (Ctrl+S)") and self.on_save_scene is not None:
            self.on_save_scene()

    @staticmethod
    def _option_label(w) -> str:
        return widget_label(w)

    def _option_rows(self, rows: Rows, widgets, st, scope: str, apply) -> None:
        """One row per declared setting (a technique's, or RenderSettings'): a checkbox, an integer or
        a number slider; a setting that may be automatic gets an 'auto' box before its slider."""
        core = self.core
        for w in widgets:
            rows.row(self._option_label(w), w.doc)
            new, changed = w.value, False
            if w.widget.endswith("_or_auto"):
                changed, auto = imgui.checkbox(f"auto##{scope}.{w.param}.auto", w.value is None)
                if imgui.is_item_hovered():
                    imgui.set_tooltip(w.doc)
                new = None if auto else (w.value if w.value is not None else w.range[0])
                imgui.same_line()
                imgui.set_next_item_width(-1.0)
            hidden = f"##{scope}.{w.param}"
            if new is not None or w.widget.endswith("_or_auto"):
                with_value = new if new is not None else (w.range[0] if w.range else 0)
                if new is None:
                    imgui.begin_disabled()
                if w.widget.startswith("checkbox"):
                    c, got = imgui.checkbox(hidden, bool(with_value))
                elif w.widget == "combo":
                    c, got = False, with_value
                    if imgui.begin_combo(hidden, str(with_value)):
                        for choice in w.choices:
                            clicked, _ = imgui.selectable(choice, choice == with_value)
                            if clicked:
                                c, got = True, choice
                        imgui.end_combo()
                elif w.widget.startswith("slider_int"):
                    c, got = imgui.slider_int(hidden, int(with_value), int(w.range[0]), int(w.range[1]))
                else:
                    c, got = imgui.slider_float(hidden, float(with_value), float(w.range[0]), float(w.range[1]))
                if new is None:
                    imgui.end_disabled()
                else:
                    new, changed = got, changed or c
            if imgui.is_item_hovered():
                imgui.set_tooltip(w.doc)
            if changed:
                try:
                    apply(w.param, technique_value(st, w.param, new))
                except ValueError as exc:
                    core.note("error", str(exc))

    def _inspector_section(self) -> None:
        """Target, scale, offset, auto range, the colour bar and the pixel under the mouse: every row
        is always there (greyed where the target has no such setting), so the layout never jumps."""
        core = self.core
        if not imgui.collapsing_header("Pass inspector (P / Tab)", imgui.TreeNodeFlags_.default_open):
            return
        targets = core.targets()
        cur = core.inspector.resolve(targets) or "-"
        tex = targets.get(cur)
        mode = display_mode(tex) if tex is not None else None
        view = core.inspector.view(cur, tex) if tex is not None else None
        with Rows("inspector", ["target", "scale", "offset", "pixel"]) as rows:
            if not rows.open:
                return
            rows.row("target")
            if imgui.begin_combo("##target", cur):
                for n in core.inspector.names(targets):
                    t = targets[n]
                    label = f"{n}  {t.size[0]}x{t.size[1]} {display_mode(t) or 'not viewable'}"
                    clicked, _ = imgui.selectable(label, n == cur)
                    if clicked:
                        core.inspector.current = n
                imgui.end_combo()
            ranged = view is not None and mode in ("color", "grey", "rg")
            imgui.begin_disabled(not ranged)
            rows.row("scale", "display = (value - offset) x scale ([ / ] halve / double)")
            ch, v = imgui.slider_float(
                "##scale", view.scale if ranged else 1.0, 1e-3, 1e4, "%.4g", imgui.SliderFlags_.logarithmic
            )
            if ch and ranged:
                view.scale = v
            rows.row("offset")
            ch, v = imgui.input_float("##offset", view.offset if ranged else 0.0, 0.0, 0.0, "%.5g")
            if ch and ranged and math.isfinite(v):
                view.offset = v
            imgui.end_disabled()
            rows.row("pixel", "the inspected target's raw values under the mouse")
            imgui.text(self._readout() or "(move the mouse over the image)")
        imgui.begin_disabled(not (view is not None and mode in ("color", "grey", "rg")))
        if imgui.button("Auto range (N)"):
            core.inspector.auto_range_now(targets)
        imgui.end_disabled()
        if tex is not None:
            stretch = shown_aspect(tex.size)[1]
            note = f"{tex.size[0]}x{tex.size[1]} {mode or 'not viewable'}"
            imgui.same_line()
            imgui.text_colored(GREY, note + (f", shown stretched {stretch:.3g} x" if stretch > 1.0 else ""))
        if view is not None and mode is not None:
            self._colour_bar(view, mode)

    def _readout(self) -> str:
        """'target (x, y): values' for the texel under the mouse, '' off the image or over the panel."""
        io = imgui.get_io()
        m = io.mouse_pos
        if not math.isfinite(m.x) or self.over_panel(m.x, m.y):
            return ""
        sx, sy = io.display_framebuffer_scale.x, io.display_framebuffer_scale.y
        size = (round(io.display_size.x * sx), round(io.display_size.y * sy))
        hit = self.core.readout(m.x * sx, (io.display_size.y - m.y) * sy, size)
        if hit is None:
            return ""
        name, col, row, values = hit
        return f"({col}, {row}): " + "  ".join(f"{float(v):.4g}" for v in np.atleast_1d(values))

    def _colour_bar(self, view, mode: str) -> None:
        """The display range as a bar of colours, its end values beneath (panel.colour_bar stops)."""
        stops = colour_bar(view, mode)
        draw = imgui.get_window_draw_list()
        p = imgui.get_cursor_screen_pos()
        width = max(imgui.get_content_region_avail().x, 40.0)
        height = imgui.get_frame_height() * 0.6
        step = width / (len(stops) - 1)
        for i in range(len(stops) - 1):
            a = imgui.get_color_u32(imgui.ImVec4(*stops[i][1], 1.0))
            b = imgui.get_color_u32(imgui.ImVec4(*stops[i + 1][1], 1.0))
            x0 = p.x + i * step
            draw.add_rect_filled_multi_color(imgui.ImVec2(x0, p.y), imgui.ImVec2(x0 + step, p.y + height), a, b, b, a)
        imgui.dummy(imgui.ImVec2(width, height))
        lo, hi = f"{stops[0][0]:.4g}", f"{stops[-1][0]:.4g}"
        imgui.text_colored(GREY, lo)
        imgui.same_line(max(width - imgui.calc_text_size(hi).x, imgui.calc_text_size(lo).x + 8.0))
        imgui.text_colored(GREY, hi)

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
        labels = [f"{w.param} (M overrides)" if w.param == "sss_model" and note else widget_label(w) for w in widgets]
        with Rows("material", labels) as rows:
            for w, label in zip(widgets, labels) if rows.open else ():
                tip = w.doc
                if w.widget == "file_path":
                    tip += f"\n{w.value or 'no map'}\n(a name alone: next to the current map)"
                rows.row(label, tip)
                hidden = f"##material.{w.param}"
                if w.widget == "slider_float":
                    ch, v = imgui.slider_float(hidden, float(w.value), w.range[0], w.range[1])
                elif w.widget == "color_edit3":  # linear values 0-1, as in the scene file
                    ch, v = imgui.color_edit3(hidden, [float(x) for x in w.value], imgui.ColorEditFlags_.float)
                elif w.widget == "drag_float3":
                    speed = max((w.range[1] - w.range[0]) * 1e-4, 1e-3)
                    flags = imgui.SliderFlags_.logarithmic if w.logarithmic else 0
                    ch, v = imgui.drag_float3(
                        hidden, [float(x) for x in w.value], speed, w.range[0], w.range[1], "%.3f", flags
                    )
                elif w.widget == "drag_float2":
                    speed = max((w.range[1] - w.range[0]) * 1e-5, 1e-3)
                    ch, v = imgui.drag_float2(
                        hidden, [float(x) for x in w.value], speed, w.range[0], w.range[1], "%.3f"
                    )
                elif w.widget == "combo":
                    ch, v = False, w.value
                    if imgui.begin_combo(hidden, str(w.value)):
                        for c in w.choices:
                            clicked, _ = imgui.selectable(c, c == w.value)
                            if clicked:
                                ch, v = True, c
                        imgui.end_combo()
                elif w.widget == "file_path":
                    key = f"{id(m)}:{w.param}"
                    text = self._text.get(key, texture_text(w.value))
                    ch_text, text = imgui.input_text(hidden, text, imgui.InputTextFlags_.enter_returns_true)
                    self._text[key] = text
                    ch, v = ch_text, text
                    if ch:
                        self._text.pop(key, None)
                else:  # widget_for() only returns the kinds above
                    raise ValueError(f"parameter {w.param}: no drawing code for widget {w.widget!r}")
                if imgui.is_item_hovered() and tip:
                    imgui.set_tooltip(tip)
                if ch:
                    self._try(panel.edit, w.param, v)
        if panel.error:
            imgui.push_text_wrap_pos(0.0)
            imgui.text_colored(RED, panel.error)
            imgui.pop_text_wrap_pos()

    def _lights_section(self) -> None:
        """Every light (the key light first, then the fill and the others): intensity, colour and,
        for a directional light, azimuth and elevation."""
        panel = self.core.panel
        lights = panel.lights()
        if not lights or not imgui.collapsing_header("Lights", imgui.TreeNodeFlags_.default_open):
            return
        for i, light in enumerate(lights):
            extra = [widget_label(w) for w in light_widgets(light) if w.param not in ("color", "intensity")]
            labels = ["intensity", "color (linear)", "azimuth (deg)", "elevation (deg)", *extra]
            title = f"{light.name} ({light.kind}{', key' if i == 0 else ''})##light{light.uid}"
            if not imgui.tree_node_ex(title, imgui.TreeNodeFlags_.default_open):
                continue
            with Rows(f"light{light.uid}", labels) as rows:
                if rows.open:
                    self._light_rows(rows, light)
            imgui.tree_pop()

    def _light_rows(self, rows: Rows, light) -> None:
        panel = self.core.panel
        declared = {w.param: w for w in light_widgets(light)}  # tooltips: the [[lights]] keys' meanings
        rows.row("intensity", declared["intensity"].doc)
        ch, v = imgui.slider_float(
            f"##intensity{light.uid}", float(light.intensity), *LIGHT_INTENSITY, "%.3g", imgui.SliderFlags_.logarithmic
        )
        if ch:
            panel.set_light_intensity(light, v)
        rows.row("color (linear)", declared["color"].doc)
        rgb = [float(x) for x in np.asarray(light.color, np.float64).reshape(-1)[:3]]
        flags = imgui.ColorEditFlags_.float | imgui.ColorEditFlags_.hdr
        ch, v = imgui.color_edit3(f"##color{light.uid}", rgb, flags)
        if ch:
            self._try(panel.set_light_color, light, np.clip(v, 0.0, LIGHT_COLOR_MAX))
        az, el = angles_from_direction(panel.light_direction(light))
        rows.row("azimuth (deg)", "where the light shines from, about +Y from +Z")
        ch1, az = imgui.slider_float(f"##azimuth{light.uid}", az, -180.0, 180.0)
        rows.row("elevation (deg)", "above the horizontal plane")
        ch2, el = imgui.slider_float(f"##elevation{light.uid}", el, -89.0, 89.0)
        if ch1 or ch2:
            self._try(panel.set_light_direction, direction_from_angles(az, el), light)
        for w in light_widgets(light):  # its shadow and what its kind has (panel.light_widgets)
            if w.param in ("color", "intensity"):
                continue
            rows.row(widget_label(w), w.doc)
            if w.widget == "checkbox":
                ch, v = imgui.checkbox(f"##{w.param}{light.uid}", bool(w.value))
            else:
                ch, v = imgui.slider_float(f"##{w.param}{light.uid}", float(w.value), w.range[0], w.range[1])
            if ch:
                self._try(panel.edit_light, w.param, v, light)

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
