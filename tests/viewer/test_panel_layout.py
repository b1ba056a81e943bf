"""The viewer's panel drawn through Dear ImGui without a window (a context of its own, no backend):
label columns as wide as their labels, rows that stay put while the frame's state changes, controls
for exposure and every light, the inspector's pixel read-out and colour bar, and extreme aspect
ratios shown stretched rather than as a strip."""

from __future__ import annotations

import numpy as np
import pytest
from imgui_bundle import imgui

from skinlab.render.registry import techniques
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import TsdSettings
from skinlab.viewer import gui as gui_module
from skinlab.viewer.core import ViewerCore
from skinlab.viewer.inspector import View, colour_bar, fit_viewport, shown_aspect, shown_value, texel_at
from skinlab.viewer.panel import EXPOSURE, PanelModel

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def core(ctx):
    c = ViewerCore(ctx, None, RenderSettings(64, 64, shadow_size=256, technique=TsdSettings(size=64)), watch=False)
    c.render()
    yield c
    c.close()


@pytest.fixture()
def ui():
    imgui.create_context()
    gui_module.apply_style()
    io = imgui.get_io()
    io.set_ini_filename(None)  # no imgui.ini in the working folder
    io.display_size = imgui.ImVec2(960, 720)
    io.backend_flags |= imgui.BackendFlags_.renderer_has_textures  # no renderer: nothing is drawn
    yield io
    imgui.destroy_context()


def frame(gui, mouse=(100.0, 300.0)):
    io = imgui.get_io()
    io.mouse_pos = imgui.ImVec2(*mouse)
    imgui.new_frame()
    gui.overlay(60)
    gui.panel()
    imgui.render()
    return dict(gui_module.LAYOUT)


def test_rows_stay_put_when_the_frame_starts_waiting(core, ui, monkeypatch):
    """A frame being prepared used to add a line at the panel's top: a drag meant for roughness moved
    specular. Every row keeps its place whatever the frame's state."""
    gui = gui_module.Gui(core)
    frame(gui)
    before = frame(gui)
    monkeypatch.setattr(ViewerCore, "waiting", property(lambda self: "preparing the frame for 1.2 s: planning"))
    during = frame(gui)
    assert "material/roughness" in before and "material/specular" in before
    assert during == before


def test_panel_has_exposure_and_every_light(core, ui):
    gui = gui_module.Gui(core)
    layout = frame(gui)
    assert "render/exposure" in layout
    lights = core.panel.lights()
    assert [l.name for l in lights][:2] == ["key", "fill"] and lights[0] is core.panel.key_light()
    for l in lights:
        assert f"light{l.uid}/intensity" in layout and f"light{l.uid}/color (linear)" in layout
    # every declared render and technique setting has a row (its label whole in its column)
    for name in core.settings.panel_options():
        assert any(k.startswith(f"render/{name}") for k in layout), name


def test_exposure_and_light_edits_are_clamped_and_bump_the_version():
    from skinlab.scene.scenefile import load_scene

    panel = PanelModel(load_scene())
    v = panel.version
    assert panel.set_exposure(1e30) == EXPOSURE[1] and panel.scene.environment.exposure == EXPOSURE[1]
    assert panel.set_exposure(float("nan")) == EXPOSURE[1]
    fill = panel.lights()[1]
    assert panel.set_light_intensity(fill, -3) == 0.0 and panel.set_light_intensity(fill, 2.5) == 2.5
    assert np.allclose(panel.set_light_color(fill, [2.0, -1.0, 0.5]), [2.0, 0.0, 0.5])
    d = panel.set_light_direction([1.0, -1.0, 0.0], fill)
    assert np.allclose(fill.direction, d) and not np.allclose(panel.key_light().direction, d)
    assert panel.version > v
    with pytest.raises(ValueError, match="fill"):
        panel.set_light_color(fill, [1.0, float("nan"), 0.0])


def test_pixel_readout_reads_the_texel_under_the_mouse(core, ui):
    name, tex = core.current_target()
    size = (960, 720)
    vx, vy, vw, vh = fit_viewport(tex.size, size)
    x, y = vx + 0.25 * vw, vy + 0.75 * vh  # a quarter in, a quarter down from the top
    got = core.readout(x, y, size)
    assert got is not None and got[0] == name
    _, col, row, values = got
    assert (col, row) == (tex.size[0] // 4, tex.size[1] // 4)
    from skinlab.viewer.inspector import read_texture

    assert np.allclose(values, read_texture(tex)[row, col])
    assert core.readout(vx - 5, y, size) is None  # beside the image
    text = gui_module.Gui(core)
    frame(text, mouse=(x, size[1] - y))
    assert text._readout().startswith(f"({col}, {row}): ")


def test_colour_bar_spans_the_display_range():
    view = View(offset=0.5, scale=2.0)
    stops = colour_bar(view, "grey", n=5)
    assert [v for v, _ in stops] == pytest.approx([0.5, 0.625, 0.75, 0.875, 1.0])
    assert stops[0][1] == (0.0, 0.0, 0.0) and stops[-1][1] == (1.0, 1.0, 1.0)
    col = colour_bar(View(0.0, 1.0), "color", n=3)
    assert col[1][1][0] == pytest.approx(shown_value(np.array([0.5, 0.5, 0.5]), View(0.0, 1.0), "color")[0])
    assert col[1][1][0] > 0.7  # sRGB encoded: linear 0.5 shows as 0.735


def test_a_very_wide_target_is_shown_stretched_not_as_a_strip():
    assert shown_aspect((1024, 10)) == (4.0, pytest.approx(25.6))
    assert fit_viewport((1024, 10), (800, 600)) == (0, 200, 800, 200)
    assert fit_viewport((64, 64), (300, 100)) == (100, 0, 100, 100)  # ordinary ones as they are
    assert texel_at((0, 200, 800, 200), (1024, 10), 799.5, 399.5) == (1023, 0)


def test_viewer_docs_name_every_technique_the_t_key_reaches():
    text = (ROOT / "docs" / "viewer.md").read_text()
    row = next(line for line in text.splitlines() if line.startswith("| T / Shift+T"))
    for t in techniques():
        assert f"`{t.name}`" in row, t.name


def test_each_light_kind_gets_its_shape_rows_and_edits_reach_the_light(core, ui):
    """A spot's cone, a rect's size, a sphere's radius and every light's shadow have rows under that
    light (panel.light_widgets, drawn in the per-light rows); an edit through the panel reaches the
    light it names, clamped, and a spot's inner angle never passes its outer one."""
    from skinlab.scene.graph import LightNode

    added = [
        LightNode("spot1", "spot", intensity=2.0, inner_deg=20.0, outer_deg=35.0),
        LightNode("panel1", "rect", intensity=1.0, width=0.5, height=0.25),
        LightNode("bulb1", "sphere", intensity=1.0, radius=0.1),
    ]
    for light in added:
        light.translation = np.array([0.0, 2.0, 3.0])
        core.scene.add(light)
    try:
        layout = frame(gui_module.Gui(core))
        spot, rect, sphere = added
        rows = {
            spot: ("inner_deg", "outer_deg", "cast_shadow"),
            rect: ("width", "height", "cast_shadow"),
            sphere: ("radius", "cast_shadow"),
        }
        for light, names in rows.items():
            for name in names:
                assert any(k.startswith(f"light{light.uid}/{name}") for k in layout), (light.name, name, layout)
        panel = core.panel
        assert panel.edit_light("inner_deg", 60.0, spot) == 60.0 and spot.outer_deg == 60.0  # the cone widened
        assert panel.edit_light("radius", -1.0, sphere) > 0.0  # clamped into its slider's range
        assert panel.edit_light("cast_shadow", True, rect) is True and rect.cast_shadow
    finally:
        core.scene.root.children[:] = [n for n in core.scene.root.children if n not in added]
