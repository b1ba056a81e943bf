"""Hot reload, headless: edit a copy of the shader library while frames render."""

import shutil
import time

import numpy as np
import pytest

from skinlab.gl.hot_reload import ShaderWatcher
from skinlab.gl.shader_source import SHADER_ROOT, ShaderLibrary
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.scene.scenefile import load_scene

SET = RenderSettings(64, 64, shadow_size=128, sss_model="none")  # the edit below changes plain diffuse


def wait_reload(watcher, timeout=5.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        res = watcher.poll()
        if res is not None:
            return res
        time.sleep(0.02)
    raise AssertionError("no reload happened")


@pytest.fixture()
def setup(ctx, tmp_path):
    root = tmp_path / "shaders"
    shutil.copytree(SHADER_ROOT, root)
    r = Renderer(ctx, ShaderLibrary(root=root))
    watcher = ShaderWatcher(r.programs, root, settle_s=0.05)
    yield root, r, watcher, load_scene()
    watcher.stop()


def test_edit_error_and_recovery(setup):
    root, r, watcher, scene = setup
    before = r.render(scene, SET).hdr
    lib = root / "lib" / "brdf.glsl"
    good_text = lib.read_text()
    # 1. change a function: diffuse twice as bright -> the image changes
    lib.write_text(good_text.replace("return fl * fv * INV_PI;", "return 2.0 * fl * fv * INV_PI;"))
    assert wait_reload(watcher) == []
    brighter = r.render(scene, SET).hdr
    assert brighter[..., :3].sum() > 1.3 * before[..., :3].sum()
    # 2. a syntax error: the last good program keeps rendering, the error names file and line
    broken = good_text.replace("float fd90 = 0.5", "float fd90 = = 0.5")
    line = next(i for i, l in enumerate(broken.splitlines(), 1) if "= = 0.5" in l)
    lib.write_text(broken)
    errors = wait_reload(watcher)
    assert errors and f"shaders/lib/brdf.glsl:{line}:" in str(errors[0]), str(errors[0])
    still = r.render(scene, SET).hdr
    assert np.array_equal(still, brighter)
    # 3. fix it: back to the original image
    lib.write_text(good_text)
    assert wait_reload(watcher) == []
    assert np.array_equal(r.render(scene, SET).hdr, before)


def test_only_dependent_programs_recompile_and_rapid_saves_settle(setup):
    root, r, watcher, scene = setup
    r.render(scene, SET)
    n_before = r.programs.compiles
    color = root / "lib" / "color.glsl"  # included by the tonemap pass only
    text = color.read_text()
    for i in range(20):  # many saves, some half-written
        color.write_text(text[: len(text) * (i + 1) // 20])
    color.write_text(text.replace("return clamp((x * (2.51", "return 0.5 * clamp((x * (2.51"))
    wait_reload(watcher)
    for _ in range(10):  # drain late events (bounded)
        time.sleep(0.1)
        watcher.poll()
    assert watcher.errors == []  # settled on the final, complete file
    assert r.programs.compiles - n_before <= 3  # the tonemap program, not the forward/shadow ones
    img = r.render(scene, SET).ldr
    assert img[..., :3].max() < 188  # tone-mapped output halved in linear: below sRGB(0.5) = 188
