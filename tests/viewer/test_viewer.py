"""The desktop viewer: a real window under Xvfb (subprocess), and its window-independent parts
(camera math, panel model, skinlab/scene/preset reload, inspector, ViewerCore) headless."""

import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from skinlab.declare import Field
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import TsdSettings
from skinlab.scene import transform as tf
from skinlab.scene.materials import PRINCIPLED_PARAMS, SSS_MODELS
from skinlab.scene.scenefile import ASSETS, DEFAULT_SCENE
from skinlab.viewer.camera import PITCH_LIMIT, OrbitCamera
from skinlab.viewer.core import SSS_CYCLE, ViewerCore, next_sss_model
from skinlab.viewer.inspector import FINAL, Inspector, View, auto_range, display_mode, fit_viewport, target_names
from skinlab.viewer.panel import (
    WIDGETS,
    PanelModel,
    angles_from_direction,
    clamp_value,
    direction_from_angles,
    medium_to_params,
    widget_for,
)
from skinlab.viewer.watch import Reloadable, preset_reloader, scene_reloader

ROOT = Path(__file__).resolve().parents[2]
SMALL = dict(shadow_size=256, technique=TsdSettings(size=64))


# -- Xvfb ----------------------------------------------------------------------------------------


def _xvfb_binary():
    exe = shutil.which("Xvfb")
    if exe is None and shutil.which("apt-get"):
        # tools/sysdeps.sh installs Xvfb with apt-get (as root or with passwordless sudo)
        subprocess.run(["bash", str(ROOT / "tools" / "sysdeps.sh")], capture_output=True, timeout=600)
        exe = shutil.which("Xvfb")
    return exe


@pytest.fixture(scope="module")
def xdisplay():
    exe = _xvfb_binary()
    if exe is None:
        pytest.skip(
            "Xvfb is not installed and tools/sysdeps.sh could not install it "
            "(needs apt-get as root or passwordless sudo)"
        )
    r, w = os.pipe()
    # -displayfd: Xvfb picks a free display number itself and writes it to the pipe when ready
    proc = subprocess.Popen(
        [exe, "-displayfd", str(w), "-screen", "0", "640x480x24", "-nolisten", "tcp"],
        pass_fds=(w,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    os.close(w)
    try:
        with os.fdopen(r) as fh:
            num = fh.readline().strip()
        if not num.isdigit():
            proc.kill()
            pytest.fail(f"Xvfb did not start: {proc.stderr.read().decode(errors='replace')[-2000:]}")
        yield f":{num}"
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()


def run_view(args, display, timeout=180):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "PYOPENGL_PLATFORM")}
    if display:
        env["DISPLAY"] = display
    return subprocess.run(
        [sys.executable, "-m", "skinlab.cli", "view", *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def test_view_window_renders_and_saves_screenshot(xdisplay, tmp_path):
    shot = tmp_path / "x.png"
    res = run_view(
        [
            str(DEFAULT_SCENE),
            "--frames",
            "3",
            "--screenshot",
            str(shot),
            "--size",
            "160x120",
            "--shadow-size",
            "512",
            "--tsd-size",
            "128",
            "--no-watch",
        ],
        xdisplay,
    )
    assert res.returncode == 0, res.stderr
    assert str(shot.resolve()) in res.stdout
    from skinlab.image_output import read_image

    img = read_image(shot)
    assert img.shape == (120, 160, 4)
    rgb = img[..., :3].astype(np.float64)
    assert rgb.std() > 10.0  # not a flat image
    background = rgb[0, 0]  # the head does not reach the top-left corner
    differs = np.abs(rgb - background).max(-1) > 12
    assert 0.15 < differs.mean() < 0.95, differs.mean()  # the head covers a good part, not all


def test_view_without_display_is_one_clear_line(tmp_path):
    res = run_view(["--frames", "1"], None, timeout=60)
    assert res.returncode == 2
    assert "no X display" in res.stderr and "Traceback" not in res.stderr


def test_view_rejects_bad_options_before_opening_a_window(xdisplay, tmp_path):
    res = run_view(["--frames", "1", "--screenshot", str(tmp_path / "a.jpg")], xdisplay, timeout=60)
    assert res.returncode == 2 and "a.jpg" in res.stderr and "expected .png or .exr" in res.stderr
    res = run_view([str(tmp_path / "missing.toml"), "--frames", "1"], xdisplay, timeout=60)
    assert res.returncode == 2 and "missing.toml" in res.stderr


# -- camera math -----------------------------------------------------------------------------------


def project(cam: OrbitCamera, point, w, h, yfov):
    view = np.linalg.inv(tf.compose(cam.eye, tf.look_at_rotation(cam.eye, cam.target), np.ones(3)))
    clip = tf.perspective(yfov, w / h, 0.1, 100.0) @ view @ np.append(point, 1.0)
    ndc = clip[:3] / clip[3]
    return np.array([(ndc[0] + 1) * w / 2, (ndc[1] + 1) * h / 2])


def test_orbit_keeps_target_and_distance_and_turns_the_right_way():
    cam = OrbitCamera.from_look_at([0, 0, 10], [0, 0, 0])
    assert np.allclose(cam.eye, [0, 0, 10]) and cam.distance == pytest.approx(10)
    cam.orbit(90 / math.degrees(cam.orbit_speed), 0)  # drag right by 90 degrees' worth
    assert np.allclose(cam.eye, [-10, 0, 0], atol=1e-9)  # camera went left: the scene turned right
    assert np.allclose(cam.target, 0) and np.linalg.norm(cam.eye - cam.target) == pytest.approx(10)
    cam.orbit(0, -1e6)  # drag far down: pitch stops short of the pole
    assert cam.pitch == pytest.approx(PITCH_LIMIT)
    assert np.linalg.norm(cam.eye - cam.target) == pytest.approx(10)
    right, up, fwd = cam.basis()
    assert np.allclose([right @ up, right @ fwd, up @ fwd], 0, atol=1e-12)


@pytest.mark.parametrize("dx,dy", [(37.0, 0.0), (0.0, -21.0), (15.0, 9.0)])
def test_pan_moves_target_depth_points_with_the_cursor(dx, dy):
    w, h, yfov = 320, 200, math.radians(40)
    cam = OrbitCamera.from_look_at([3, 2, 8], [0.5, 0.2, -1])
    before = project(cam, cam.target, w, h, yfov)
    anchor = cam.target.copy()
    dist = cam.distance
    cam.pan(dx, dy, h, yfov)
    after = project(cam, anchor, w, h, yfov)
    assert np.allclose(after - before, [dx, dy], atol=1e-6)  # the grabbed point follows the cursor
    assert cam.distance == pytest.approx(dist)


def test_zoom_is_geometric_and_clamped_and_reset_restores():
    cam = OrbitCamera.from_look_at([0, 0, 10], [0, 1, 0], zoom_factor=0.5, min_distance=1.0)
    start = (cam.eye.copy(), cam.target.copy())
    cam.zoom(1)
    assert cam.distance == pytest.approx(0.5 * math.hypot(10, 1))
    cam.zoom(-2)
    assert cam.distance == pytest.approx(2 * math.hypot(10, 1))
    cam.zoom(50)
    assert cam.distance == pytest.approx(1.0)
    cam.orbit(10, 5)
    cam.pan(4, 4, 100, 0.5)
    cam.reset()
    assert np.allclose(cam.eye, start[0]) and np.allclose(cam.target, start[1])


def test_orbit_from_scene_camera_looks_the_same_way():
    from skinlab.scene.scenefile import load_scene

    scene = load_scene()
    cam = OrbitCamera.from_camera_node(scene.camera, scene.world_bounds())
    fwd = -scene.camera.world_matrix[:3, 2]
    assert np.allclose(cam.eye, scene.camera.world_position, atol=1e-9)
    assert np.allclose(-cam.basis()[2], -fwd / np.linalg.norm(fwd), atol=1e-9)
    before = scene.camera.world_matrix.copy()
    cam.apply(scene.camera)
    assert np.allclose(scene.camera.world_matrix, before, atol=1e-9)


# -- panel model -------------------------------------------------------------------------------------


def test_every_declared_kind_has_a_widget_from_one_table():
    """Material parameters, render settings and every technique's settings get their widgets from the
    one table WIDGETS, and together use every kind it knows."""
    from skinlab.render.registry import techniques
    from skinlab.render.settings import RenderSettings

    declared = [*PRINCIPLED_PARAMS, *RenderSettings.panel_options().values()]
    declared += [f for t in techniques() for f in t.settings_type.options().values()]
    assert {p.kind for p in declared} == set(WIDGETS)  # the declarations use every kind the panel knows
    for p in declared:
        w = widget_for(p)
        assert w.widget == WIDGETS[p.kind] + ("_or_auto" if p.none else "") and w.param == p.name
        assert w.doc == p.help() and p.doc in w.doc  # the tooltip: the one meaning, values and default
        if p.kind in ("float", "color", "vec3", "vec2"):
            assert w.range == tuple(p.range)
        if p.kind == "choice":
            assert w.choices == p.choices and len(w.choices) > 1
    assert widget_for(Field("subsurface_radius", "vec3", (1, 1, 1), (0.0, 1000.0))).logarithmic
    with pytest.raises(ValueError, match="weird.*no panel widget for kind 'matrix'"):
        widget_for(Field("weird", "matrix", None))


def test_clamping_per_kind(tmp_path):
    pm = {p.name: p for p in PRINCIPLED_PARAMS}
    assert clamp_value(pm["roughness"], 3.0) == 1.0
    assert clamp_value(pm["roughness"], -1) == 0.0
    assert clamp_value(pm["roughness"], float("nan")) == pm["roughness"].default
    assert clamp_value(pm["base_color"], [1.5, -0.2, 0.3]) == (1.0, 0.0, 0.3)
    assert clamp_value(pm["subsurface_radius"], [2000, 1, -5]) == (1000.0, 1.0, 0.0)
    assert clamp_value(pm["subsurface_color"], 0.5) == (0.5, 0.5, 0.5)
    with pytest.raises(ValueError, match="base_color: expected 3 numbers"):
        clamp_value(pm["base_color"], [1, 2])
    with pytest.raises(ValueError, match="roughness: expected a number"):
        clamp_value(pm["roughness"], "rough")
    with pytest.raises(ValueError, match="sss_model: expected one of"):
        clamp_value(pm["sss_model"], "magic")
    assert clamp_value(pm["sss_model"], "dipole") == "dipole"
    with pytest.raises(ValueError, match="normal_map: texture file not found: .*nope.png"):
        clamp_value(pm["normal_map"], str(tmp_path / "nope.png"))
    img = tmp_path / "n.png"
    img.write_bytes(b"x")
    assert clamp_value(pm["normal_map"], str(img)) == img.resolve()
    assert clamp_value(pm["normal_map"], "  ") is None


def test_panel_edits_go_through_material_update_and_presets_map_media():
    from skinlab.scene.optics.media import preset
    from skinlab.scene.scenefile import load_scene

    scene = load_scene()
    panel = PanelModel(scene, presets=lambda: {"skin1": preset("skin1")})
    mat = panel.material
    assert mat is not None and panel.selected in scene.mesh_nodes()
    v0 = panel.version
    assert panel.edit("roughness", 7.0) == 1.0 and mat["roughness"] == 1.0
    assert panel.version > v0
    assert panel.edit("sss_model", "dipole") == "dipole" and mat["sss_model"] == "dipole"
    with pytest.raises(ValueError, match="unknown parameter 'glow'"):
        panel.edit("glow", 1)
    with pytest.raises(ValueError, match="sss_model: expected one of"):
        panel.edit("sss_model", "nope")
    assert "sss_model" in panel.error and mat["sss_model"] == "dipole"  # rejected edit changed nothing
    values = panel.apply_preset("skin1")
    m = preset("skin1")
    assert np.allclose(mat["subsurface_color"], np.clip(m.surface_albedo(), 0, 1))
    assert np.allclose(mat["subsurface_radius"], m.artist_radius_mm)
    assert values == medium_to_params(m)
    assert mat["subsurface_radius"][0] > mat["subsurface_radius"][2]  # red scatters furthest in skin
    with pytest.raises(ValueError, match="unknown material 'jam'"):
        panel.apply_preset("jam")
    # widgets reflect the current values
    ws = {w.param: w for w in panel.widgets()}
    assert ws["roughness"].value == 1.0 and ws["sss_model"].value == "dipole"
    # the tree lists every node with its kind; selecting by name
    labels = [r.label for r in panel.tree()]
    assert "key (light)" in labels and "camera (camera)" in labels
    assert panel.select("key").name == "key" and panel.material is None


def test_key_light_direction_round_trip():
    from skinlab.scene.scenefile import load_scene

    panel = PanelModel(load_scene())
    light = panel.key_light()
    assert light.name == "key"
    d = direction_from_angles(30.0, 40.0)
    got = panel.set_light_direction(d * 5)
    assert np.allclose(light.direction, got, atol=1e-9) and np.allclose(got, d / np.linalg.norm(d))
    assert np.allclose(angles_from_direction(light.direction), (30.0, 40.0), atol=1e-6)
    assert direction_from_angles(0, 89)[1] < -0.99  # a light overhead shines down
    with pytest.raises(ValueError, match="light direction"):
        panel.set_light_direction([0, 0, 0])


# -- scene and preset reload ----------------------------------------------------------------------------


def head_copy(tmp_path) -> Path:
    text = DEFAULT_SCENE.read_text().replace("../lee-perry-smith/", f"{ASSETS / 'lee-perry-smith'}/")
    p = tmp_path / "head.toml"
    p.write_text(text)
    return p


def wait_for(reloadable: Reloadable, want: str, timeout=5.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        state = reloadable.poll()
        if state == want:
            return
        assert state is None, f"expected {want}, got {state}: {reloadable.error}"
        time.sleep(0.02)
    raise AssertionError(f"no {want} within {timeout} s")


def test_scene_reload_keeps_last_good_and_recovers(tmp_path):
    path = head_copy(tmp_path)
    src = scene_reloader(path, settle_s=0.05)
    try:
        good = src.value
        assert good.environment.exposure == 1.0 and path.resolve() in src.watcher.paths
        assert any(p.name == "LeePerrySmith.glb" for p in src.watcher.paths)  # referenced files too
        text = path.read_text()
        path.write_text(text.replace("[camera]", "[camera\n"))  # broken TOML
        wait_for(src, "failed")
        assert src.value is good and "head.toml" in src.error and "not valid TOML" in src.error
        path.write_text(text.replace("[scene]", "[scene]\nbogus = 1"))  # valid TOML, bad key
        wait_for(src, "failed")
        assert src.value is good and "head.toml" in src.error and "bogus" in src.error
        path.write_text(text.replace("exposure = 1.0", "exposure = 2.5"))  # fixed
        wait_for(src, "reloaded")
        assert src.value is not good and src.value.environment.exposure == 2.5 and src.error is None
    finally:
        src.stop()


def test_rapid_half_written_saves_settle_on_the_final_file(tmp_path):
    path = head_copy(tmp_path)
    src = scene_reloader(path, settle_s=0.15)
    try:
        final = path.read_text().replace("exposure = 1.0", "exposure = 3.0")
        for i in range(1, 25):  # an editor writing in pieces, no pause
            path.write_text(final[: len(final) * i // 25])
        path.write_text(final)
        t0 = time.monotonic()
        outcomes = []
        while time.monotonic() - t0 < 5.0 and "reloaded" not in outcomes:
            outcomes.append(src.poll())
            time.sleep(0.02)
        t1 = time.monotonic()
        while time.monotonic() - t1 < 0.4:  # late events must not load anything else
            outcomes.append(src.poll())
            time.sleep(0.02)
        assert "reloaded" in outcomes and "failed" not in outcomes, outcomes  # never a partial file
        assert src.value.environment.exposure == 3.0 and src.error is None
    finally:
        src.stop()


def test_preset_file_reload(tmp_path, monkeypatch):
    from skinlab.scene.optics import media

    csv = tmp_path / "presets.csv"
    csv.write_text(media.PRESET_FILE.read_text())
    monkeypatch.setattr(media, "PRESET_FILE", csv)
    media.forget_presets()
    src = preset_reloader(settle_s=0.05)
    try:
        from skinlab.scene.scenefile import load_scene

        panel = PanelModel(load_scene(), presets=lambda: src.value)
        panel.apply_preset("skin1")
        before = panel.material["subsurface_radius"]
        csv.write_text(csv.read_text().replace("skin1,0.74,0.88,1.01", "skin1,0.37,0.44,0.505"))
        wait_for(src, "reloaded")
        assert panel.reapply_presets() == [f"{panel.material.name}: skin1"]
        after = panel.material["subsurface_radius"]
        assert all(a > b for a, b in zip(after, before))  # less scattering -> longer paths
        good = src.value
        csv.write_text(csv.read_text().replace("skin1,0.37", "skin1,zero"))
        wait_for(src, "failed")
        assert src.value is good and "presets.csv" in src.error
    finally:
        src.stop()
        monkeypatch.undo()
        media.forget_presets()


# -- inspector and core (headless EGL) ----------------------------------------------------------------------


def test_display_modes_and_layout(ctx):
    assert display_mode(ctx.texture((2, 2), 4, dtype="f1")) == "ldr"
    assert display_mode(ctx.texture((2, 2), 4, dtype="f4")) == "color"
    assert display_mode(ctx.texture((2, 2), 3, dtype="f2")) == "color"
    assert display_mode(ctx.texture((2, 2), 1, dtype="f4")) == "grey"
    assert display_mode(ctx.texture((2, 2), 2, dtype="f2")) == "rg"
    assert display_mode(ctx.depth_texture((2, 2))) == "grey"
    assert display_mode(ctx.texture((2, 2), 1, dtype="u1")) is None
    assert display_mode("not a texture") is None
    assert target_names({"a": 1, FINAL: 2, "b": 3}) == [FINAL, "a", "b"]
    assert fit_viewport((100, 50), (200, 200)) == (0, 50, 200, 100)
    assert fit_viewport((64, 64), (300, 100)) == (100, 0, 100, 100)
    off, scale = auto_range(np.array([[[0.5], [0.7]], [[1.0], [0.6]]], np.float32), "grey")
    assert off == pytest.approx(0.5) and scale == pytest.approx(5.0)  # far plane (1.0) ignored


def test_depth_texture_shown_as_grey_without_touching_its_compare_mode(ctx):
    vals = np.linspace(0.2, 0.8, 8, dtype=np.float32).reshape(1, 8).repeat(2, 0)
    tex = ctx.depth_texture((8, 2), data=vals.tobytes())
    tex.compare_func = "<="
    ins = Inspector(ctx)
    img = ins.render_image(tex, View(offset=0.2, scale=1 / 0.6, auto=False))
    got = img[::-1, :, 0].astype(np.float64) / 255.0  # back to bottom-up rows
    assert np.allclose(got, (vals - 0.2) / 0.6, atol=1.5 / 255)  # depth values, not comparisons
    assert tex.compare_func == "<="
    ins.release()


@pytest.fixture()
def core(ctx, tmp_path):
    shaders = tmp_path / "shaders"
    from skinlab.gl.shader_source import SHADER_ROOT

    shutil.copytree(SHADER_ROOT, shaders)
    c = ViewerCore(ctx, head_copy(tmp_path), RenderSettings(64, 48, **SMALL), shader_root=shaders, settle_s=0.05)
    yield c, shaders
    c.close()


def test_core_renders_every_target_and_screenshots(core, ctx, tmp_path):
    c, _ = core
    assert c.render() and c.errors() == []
    targets = c.targets()
    assert {"ldr_color", "hdr_color", "depth"} <= set(targets)
    fbo = ctx.simple_framebuffer((96, 64), components=4)
    seen = []
    for _ in range(len(targets)):
        name = c.draw(fbo, (96, 64))
        img = np.frombuffer(fbo.read(components=4), np.uint8).reshape(64, 96, 4)
        if display_mode(targets[name]) is not None:
            assert img[..., :3].std() > 2.0, f"{name} looks blank"
        seen.append(name)
        c.inspector.cycle(c.targets())
    assert sorted(seen) == sorted(targets) and seen[0] == FINAL
    png = c.screenshot(tmp_path / "s.png")
    exr = c.screenshot(tmp_path / "s.exr")
    from skinlab.image_output import read_image

    assert read_image(png).shape == (48, 64, 4)
    hdr = read_image(exr)
    assert hdr.shape == (48, 64, 4) and hdr[..., :3].max() > 0.05  # linear radiance, not 8-bit
    with pytest.raises(ValueError, match="unsupported image extension"):
        c.screenshot(tmp_path / "s.bmp")


def test_core_orbit_runs_only_the_view_dependent_passes(core):
    c, _ = core
    c.set_technique_option("size", 256)  # wide enough for the skin's blurs
    assert c.render()
    first = set(c.result.plan.ran())
    assert {"shadow[key]", "tsd_irradiance[LeePerrySmith]", "forward", "tonemap"} <= first
    for _ in range(3):  # while a person orbits, the view-independent passes keep their results
        c.orbit.orbit(25, 4)
        assert c.render()
        assert c.result.plan.ran() == ["forward", "tonemap"], c.result.plan.explain()
        assert "tsd_irradiance[LeePerrySmith]" in c.result.plan.reused()
    c.scene.find("key").color = np.array([1.0, 0.8, 0.6])  # a light's colour: the irradiance again
    assert c.render()
    ran = c.result.plan.ran()
    assert "tsd_irradiance[LeePerrySmith]" in ran and "shadow[key]" not in ran
    c.set_technique("ssss")  # screen-space SSS: its blur is view-dependent and runs every frame
    c.render()
    c.orbit.orbit(25, 0)
    c.render()
    assert c.result.plan.ran() == ["forward", "ssss_blur", "tonemap"]


def test_core_settings_follow_size_and_sss_cycle(core):
    c, _ = core
    c.render()
    c.set_size(80, 40)
    assert c.dirty and c.settings.size == (80, 40)
    c.render()
    assert c.targets()["ldr_color"].size == (80, 40)
    seen = [c.settings.sss_model]
    for _ in range(len(SSS_CYCLE)):
        seen.append(c.cycle_sss_model())
    assert seen == [None, *SSS_MODELS, None]
    assert next_sss_model("pbd") is None and next_sss_model(None, -1) == "pbd"
    # T cycles the technique; the frame plan follows (screen-space SSS has its blur pass)
    assert c.settings.technique_name == "tsd"
    assert c.cycle_technique() == "ssss" and c.dirty  # T skips the slow exact reference
    c.render()
    assert {"ssss_diffuse", "ssss_blurred"} <= set(c.targets())
    assert c.cycle_technique(-1) == "tsd"
    assert c.set_technique("exact") == "exact"  # from the panel; the overlay says it is slow
    assert "a frame may take seconds" in c.log[-1][2] and c.log[-1][1] == "warning"
    # the panel edits the current technique's own settings; each technique keeps its own
    assert c.set_technique("tsd") == "tsd" and c.settings.technique.size == 64
    assert c.set_technique_option("gaussians", 3) == 3 and c.settings.technique.gaussians == 3
    with pytest.raises(ValueError, match=r"tsd setting gaussians: expected an integer in \[1, 6\], got 9"):
        c.set_technique_option("gaussians", 9)
    with pytest.raises(ValueError, match="tsd setting 'taps_x': unknown"):
        c.set_technique_option("taps_x", 9)
    c.set_technique("ssss")
    c.set_technique("tsd")
    assert c.settings.technique.gaussians == 3 and c.settings.technique.size == 64


def test_core_shows_shader_errors_and_keeps_rendering(core):
    c, shaders = core
    assert c.render()
    before = np.frombuffer(c.targets()["ldr_color"].read(), np.uint8).copy()
    frag = shaders / "passes" / "tonemap.frag"
    good = frag.read_text()
    broken = good.replace("void main() {", "void main() {\n    float x = = 1.0;")
    line = next(i for i, l in enumerate(broken.splitlines(), 1) if "= = 1.0" in l)
    frag.write_text(broken)
    t0 = time.monotonic()
    while not c.poll_reloads() and time.monotonic() - t0 < 5:
        time.sleep(0.02)
    errs = c.errors()
    assert errs and f"shaders/passes/tonemap.frag:{line}:" in errs[0], errs
    assert c.render()  # the last good program still renders
    assert np.array_equal(np.frombuffer(c.targets()["ldr_color"].read(), np.uint8), before)
    frag.write_text(good)
    t0 = time.monotonic()
    while not c.poll_reloads() and time.monotonic() - t0 < 5:
        time.sleep(0.02)
    assert c.errors() == []


def test_core_scene_reload_keeps_camera_and_renders_new_scene(core):
    c, _ = core
    c.render()
    path = Path(c.scene.source)
    old = c.scene
    c.orbit.orbit(40, 0)
    eye = c.orbit.eye.copy()
    path.write_text(path.read_text().replace("[[lights]]", "[[lights]\n", 1))
    t0 = time.monotonic()
    while not c.scene_src.error and time.monotonic() - t0 < 5:
        c.poll_reloads()
        time.sleep(0.02)
    assert c.scene is old and any("head.toml" in e for e in c.errors())
    assert c.render()  # last good scene renders
    fixed = path.read_text().replace("[[lights]\n", "[[lights]]", 1)
    path.write_text(fixed.replace("exposure = 1.0", "exposure = 0.25"))
    t0 = time.monotonic()
    while c.scene is old and time.monotonic() - t0 < 5:
        c.poll_reloads()
        time.sleep(0.02)
    assert c.scene is not old and c.scene.environment.exposure == 0.25 and c.errors() == []
    assert np.allclose(c.orbit.eye, eye)  # same file camera: the user's view is kept
    assert c.render()


def test_core_reloads_a_changed_texture_file(ctx, tmp_path):
    from PIL import Image

    tex = tmp_path / "col.png"
    Image.new("RGB", (64, 64), (230, 230, 230)).save(tex)
    scene = head_copy(tmp_path)
    scene.write_text(scene.read_text().replace(f"{ASSETS / 'lee-perry-smith'}/Map-COL.jpg", str(tex)))
    c = ViewerCore(ctx, scene, RenderSettings(64, 48, **SMALL), settle_s=0.05)
    try:
        assert tex.resolve() in c.scene_src.watcher.paths
        assert c.render()
        bright = np.frombuffer(c.targets()["ldr_color"].read(), np.uint8).reshape(48, 64, 4)[..., :3].mean()
        Image.new("RGB", (64, 64), (20, 20, 20)).save(tex)  # same path, darker pixels
        t0 = time.monotonic()
        while not c.poll_reloads() and time.monotonic() - t0 < 5:
            time.sleep(0.02)
        assert c.errors() == [] and c.render()
        dark = np.frombuffer(c.targets()["ldr_color"].read(), np.uint8).reshape(48, 64, 4)[..., :3].mean()
        assert dark < bright - 10  # the renderer's cached texture was replaced
    finally:
        c.close()


def test_render_settings_widgets_come_from_the_declaration(core):
    """The panel's render settings (interreflection, supersampling) come from RenderSettings'
    declarations, and the core applies a widget's value (checked)."""
    from skinlab.render.settings import RenderSettings
    from skinlab.viewer.panel import render_widgets, technique_value

    c, _ = core
    ws = {w.param: w for w in render_widgets(c.settings)}
    assert list(ws) == list(RenderSettings.panel_options())
    assert ws["bounces"].widget == "slider_int" and ws["bounces"].range == (0.0, 8.0)
    assert "default: 2 bounces" in ws["bounces"].doc and "rays per vertex" in ws["bounce_rays"].doc
    assert c.set_render_option("bounces", technique_value(c.settings, "bounces", 0)) == 0
    assert c.render()
    assert not any(n.startswith("bounce") for n in c.result.plan.names())
    assert c.set_render_option("bounces", technique_value(c.settings, "bounces", 9.4)) == 8
    with pytest.raises(ValueError, match="render setting 'width'"):
        c.set_render_option("width", 10)
    with pytest.raises(ValueError, match="render setting bounces"):
        c.set_render_option("bounces", -1)


def test_technique_settings_widgets_come_from_the_declaration():
    from skinlab.render.techniques.ssss import SsssSettings
    from skinlab.viewer.panel import technique_value, technique_widgets

    st = TsdSettings(size=64)
    ws = {w.param: w for w in technique_widgets(st)}
    assert list(ws) == list(TsdSettings.options())  # one widget per declared setting, in order
    assert ws["size"].widget == "slider_int" and ws["size"].range == (16.0, 8192.0) and ws["size"].value == 64
    assert ws["taps"].widget == "slider_int_or_auto" and ws["taps"].value is None
    assert ws["albedo_mix"].widget == "slider_float" and ws["translucency"].widget == "checkbox"
    assert "irradiance texels per side" in ws["size"].doc and "default: 512" in ws["size"].doc
    # values from a widget are made valid: clamped, rounded, odd where the setting wants odd
    assert technique_value(st, "size", 1e9) == 8192 and technique_value(st, "size", 3.4) == 16
    assert technique_value(st, "taps", 8) == 9 and technique_value(st, "taps", 31.6) == 31
    assert technique_value(st, "taps", None) is None and technique_value(st, "albedo_mix", -1) == 0.0
    assert technique_value(SsssSettings(), "taps", 64) == 63
    for name, w in ws.items():  # and every such value is accepted by the settings class
        v = technique_value(st, name, w.range[1] if w.range else w.value)
        assert getattr(st.replace(**{name: v}), name) == v


def test_panel_labels_texture_fields_and_m_override_note(tmp_path):
    from skinlab.scene.materials import Material
    from skinlab.viewer.panel import resolve_texture_input, sss_override_note, texture_text, widget_label

    labels = {p.name: widget_label(widget_for(p)) for p in PRINCIPLED_PARAMS}
    assert labels["subsurface_radius"] == "subsurface_radius (mm)"
    assert labels["base_color"] == "base_color (linear RGB)" and labels["roughness"] == "roughness"
    assert texture_text(Path("/very/long/absolute/folder/Map-COL.jpg")) == "Map-COL.jpg"
    assert texture_text(None) == ""
    cur = tmp_path / "maps" / "a.png"
    assert resolve_texture_input("b.png", cur, tmp_path) == str(tmp_path / "maps" / "b.png")
    assert resolve_texture_input("t/b.png", None, tmp_path) == str(tmp_path / "t" / "b.png")
    assert resolve_texture_input(str(tmp_path / "x.png"), cur, None) == str(tmp_path / "x.png")
    assert resolve_texture_input("  ", cur, tmp_path) == ""
    m = Material("skin", {"sss_model": "burley"})
    assert sss_override_note(m, None) is None
    assert "'dipole'" in sss_override_note(m, "dipole") and "'burley' is not used" in sss_override_note(m, "dipole")


def test_panel_texture_edit_by_file_name_resolves_next_to_the_current_map(tmp_path):
    import shutil

    from skinlab.scene.scenefile import load_scene

    scene = load_scene()
    panel = PanelModel(scene)
    current = panel.material["normal_map"]
    assert current is not None
    # a bare name that exists next to the current map is taken from there, not from the working folder
    assert panel.edit("normal_map", current.name) == current
    other = tmp_path / "other.png"
    shutil.copy(current, other)
    assert panel.edit("normal_map", str(other)) == other.resolve()
    with pytest.raises(ValueError, match="normal_map: texture file not found: .*missing.png"):
        panel.edit("normal_map", "missing.png")


def test_technique_cycle_skips_slow_techniques_and_title_names_the_scene():
    from skinlab.render.registry import get_technique, technique_names
    from skinlab.scene.scenefile import load_scene
    from skinlab.viewer.core import cycle_techniques, next_technique, window_title

    cycle = cycle_techniques()
    assert get_technique("exact").slow and "exact" not in cycle
    assert set(cycle) == {n for n in technique_names() if not get_technique(n).slow} and "tsd" in cycle
    seen, t = [], "tsd"
    for _ in range(len(cycle)):
        t = next_technique(t)
        seen.append(t)
    assert "exact" not in seen and seen[-1] == "tsd" and sorted(seen) == sorted(cycle)
    assert next_technique("exact") == cycle[0]
    assert next_technique("tsd", -1) == cycle[cycle.index("tsd") - 1]
    assert window_title(load_scene()) == "Skinlab - head (head.toml)"


def test_wheel_over_the_panel_is_decided_by_where_the_panel_was_drawn():
    from skinlab.viewer.gui import Gui

    gui = Gui(core=None)
    assert not gui.over_panel(10, 10)  # not drawn yet
    gui.panel_rect = (600.0, 6.0, 340.0, 500.0)
    assert gui.over_panel(700, 100) and gui.over_panel(600, 6) and gui.over_panel(940, 506)
    assert not gui.over_panel(599, 100) and not gui.over_panel(700, 507)
    gui.show_panel = False
    assert not gui.over_panel(700, 100)


def test_viewer_opens_a_mesh_file_directly(ctx, tmp_path):
    obj = tmp_path / "quad.obj"
    obj.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n")
    c = ViewerCore(ctx, obj, RenderSettings(32, 32, **SMALL), watch=False)
    try:
        assert c.render() and c.errors() == [] and c.title == "Skinlab - quad (quad.obj)"
        assert c.panel.material is not None and c.panel.key_light().name == "key"
    finally:
        c.close()


RESPONSIVE_SCRIPT = r"""
import sys, time
from skinlab.scene.optics import media
from skinlab.viewer.window import ViewerWindow

real = media.pbd_total
def slow_pbd_total(*a, **k):  # the long work a new medium's albedo table is, made certain to be long
    time.sleep(0.4)
    return real(*a, **k)
media.pbd_total = slow_pbd_total

w = ViewerWindow(sys.argv[1], size=(160, 120), watch=False, shadow_size=256, technique="tsd")
core = w.core
while core.frames < 1:  # the first frame (it waits on its own preparation too)
    w.step()
core.panel.apply_preset("marble")  # a new medium: its profile and albedo tables are made on a worker
shown, handled, steps_waiting = w.show_ui, False, 0
while core.frames < 2:
    w.step()
    if core.waiting and core.waiting.startswith("preparing"):
        steps_waiting += 1
        if not handled:  # an event arrives while the work runs: the window answers it at once
            w.window.dispatch_event("on_key_press", __import__("pyglet").window.key.H, 0)
            handled = w.show_ui != shown
    time.sleep(0.01)
print(steps_waiting, handled, core.render_error, core.result.plan.explain().count("tsd"))
w.close()
"""


def test_window_keeps_answering_while_a_preset_is_prepared(xdisplay, tmp_path):
    """A preset's slow work (here made slow on purpose) runs off the window's thread: the loop turns
    many times meanwhile and a key pressed during it takes effect before the new frame exists."""
    script = tmp_path / "responsive.py"
    script.write_text(RESPONSIVE_SCRIPT)
    env = {k: v for k, v in os.environ.items() if k != "PYOPENGL_PLATFORM"}
    env.update(DISPLAY=xdisplay, SKINLAB_CACHE_DIR="off")
    r = subprocess.run(
        [sys.executable, str(script), str(DEFAULT_SCENE)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    steps, handled, error, tsd_lines = r.stdout.split()[-4:]
    assert int(steps) >= 5 and handled == "True" and error == "None" and int(tsd_lines) > 0, r.stdout


def test_the_viewer_saves_the_edited_scene_as_toml(ctx, tmp_path):
    from skinlab.scene.scenefile import load_scene

    obj = tmp_path / "quad.obj"
    obj.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n")
    c = ViewerCore(ctx, obj, RenderSettings(32, 32, **SMALL), watch=False)
    try:
        c.panel.edit("roughness", 0.2)
        c.panel.edit("subsurface_color", [0.1, 0.7, 0.3])
        c.orbit.yaw += 0.5
        saved = c.save_scene(tmp_path / "saved.toml")
        back = load_scene(saved)
        assert back.mesh_nodes()[0].material.values == c.panel.material.values
        assert np.allclose(back.camera.world_matrix, c.scene.camera.world_matrix, atol=1e-9)
    finally:
        c.close()


# -- lights and the environment map in the panel ----------------------------------------------------


def test_panel_light_widgets_per_kind_and_clamped_edits():
    from skinlab.scene.graph import LightNode, Scene
    from skinlab.viewer.panel import light_widgets

    s = Scene("s")
    spot = s.add(LightNode("spot", "spot", inner_deg=20.0, outer_deg=30.0))
    rect = s.add(LightNode("rect", "rect", width=2.0, height=1.0))
    sun = s.add(LightNode("sun", "directional"))
    names = lambda l: [w.param for w in light_widgets(l)]  # noqa: E731
    assert names(spot) == ["color", "intensity", "cast_shadow", "inner_deg", "outer_deg"]
    assert names(rect)[3:] == ["width", "height"] and names(sun)[3:] == ["angular_radius_deg"]
    panel = PanelModel(s)
    panel.selected = spot
    v0 = panel.version
    assert panel.edit_light("inner_deg", 50.0) == 50.0 and spot.outer_deg == 50.0  # the cone stays valid
    assert panel.edit_light("outer_deg", 200.0) == 90.0  # clamped into its range
    assert panel.version > v0
    panel.selected = sun
    panel.edit_light("angular_radius_deg", 2.0)
    assert math.isclose(sun.angular_radius, math.radians(2.0))
    with pytest.raises(ValueError, match="'sun'.*radius"):
        panel.edit_light("radius", 1.0)
    panel.selected = rect
    panel.edit_light("width", 0.0)  # clamped to the slider's smallest size, never 0
    assert rect.width > 0
    # a spot or rect key light aims at the origin from where the key-light sliders put it
    rect.name = "key"
    panel.set_light_direction(direction_from_angles(20.0, 30.0))
    assert np.allclose(rect.direction, -rect.world_position / np.linalg.norm(rect.world_position))


def test_panel_environment_map_pick_rotate_intensity_background(tmp_path):
    from skinlab.scene.envmap import bundled_maps, write_map
    from skinlab.scene.scenefile import load_scene
    from skinlab.viewer.panel import ENV_NONE

    panel = PanelModel(load_scene())
    env = panel.scene.environment
    ambient = env.ambient.copy()
    assert panel.environment_name() == ENV_NONE
    assert {"studio", "city"} <= set(panel.environment_choices())
    panel.set_environment("studio")
    assert env.map == bundled_maps()["studio"] and not env.ambient.any()
    assert panel.set_environment_value("rotation_deg", 270.0) == -90.0
    assert panel.set_environment_value("intensity", -3.0) == 0.0
    assert panel.set_environment_value("show_background", True) is True
    good = write_map(tmp_path / "mine.exr", np.ones((8, 16, 3), np.float32))
    panel.set_environment(str(good))
    assert panel.environment_name() == str(good) and str(good) in panel.environment_choices()
    bad = write_map(tmp_path / "square.exr", np.ones((8, 8, 3), np.float32))
    with pytest.raises(ValueError, match="square.exr.*twice as wide"):
        panel.set_environment(str(bad))
    assert env.map == good and "square.exr" in panel.error  # the last good map stays
    panel.set_environment(ENV_NONE)
    assert env.map is None and np.allclose(env.ambient, ambient)


def test_core_renders_a_turning_environment_map_reusing_what_does_not_depend_on_it(core):
    c, _ = core
    c.set_technique_option("size", 256)  # wide enough for the skin's blurs: a texture-space irradiance pass
    c.panel.set_environment("courtyard")  # no sources: no shadow map of its own
    assert c.render()
    assert "environment" in c.result.plan.names()
    c.panel.set_environment_value("rotation_deg", 45.0)
    assert c.render()
    ran, reused = set(c.result.plan.ran()), set(c.result.plan.reused())
    assert {"environment", "shadow[key]"} <= reused and not any(n.startswith("tsd_stretch") for n in ran)
    assert any(n.startswith("tsd_irradiance") for n in ran), c.result.plan.explain()
    c.panel.set_environment(ENV_NONE_NAME)
    assert c.render() and "environment" not in c.result.plan.names()


ENV_NONE_NAME = "(none)"
